"""The world's audit probe: a blind rule agent (instruction + coordinates + feedback) must do badly."""

from __future__ import annotations

import copy

from eb_core.env import Task
from eb_manipulation.audit import BLIND_THRESHOLD, BlindRuleAgent, blind_rule_agent_probe
from eb_manipulation.env import ManipulationEnv


def _coordinate_task(task: Task) -> Task:
    """A deliberately broken pick task: the instruction names the target and the container by where they are,
    which the coordinate list alone answers (the leftmost shape, the container nearest the camera)."""
    meta = copy.deepcopy(task.metadata)
    shapes = [o for o in meta["objects"] if o["kind"] == "shape"]
    boxes = [o for o in meta["objects"] if o["kind"] == "container"]
    target = min(shapes, key=lambda o: o["y"])
    box = max(boxes, key=lambda o: o["x"])
    meta["goal"].update(target=target["id"], container=box["id"])
    meta["target_ids"] = [target["id"], box["id"]]
    return Task(id=task.id + "_broken", subset=task.subset, metadata=meta,
                instruction="Put the leftmost object into the container nearest the camera.")


def test_the_agent_reads_only_text() -> None:
    agent = BlindRuleAgent(seed=0)
    listing = {"object 1": [40, 20, 17], "object 2": [30, 45, 21], "object 3": [45, 60, 17], "object 4": [60, 70, 21]}
    plan = agent.plan("Put the leftmost object into the container nearest the camera.", listing)
    assert plan[0][:2] == (40, 20) and plan[-1][:2] == (60, 70) and plan[-1][6] == 1


def test_probe_fails_on_coordinate_recoverable_instructions() -> None:
    tasks = [t for t in ManipulationEnv.load_tasks() if t.metadata["family"] == "pick"][:8]
    broken = [_coordinate_task(t) for t in tasks]
    result = blind_rule_agent_probe(broken, {}, repeats=1)
    assert not result.passed
    assert float(result.value.split()[0]) > 100 * BLIND_THRESHOLD
    assert result.failing_tasks and all(t.endswith("_broken") for t in result.failing_tasks)


def test_probe_passes_on_shipped_spatial_tasks() -> None:
    """The subset whose words the agent can use most (sampled: every second task, one episode each)."""
    tasks = [t for t in ManipulationEnv.load_tasks() if t.subset == "spatial"][::2]
    result = blind_rule_agent_probe(tasks, {}, repeats=1)
    assert result.passed, result


def test_audit_form_writes_a_small_verified_form_with_every_family(tmp_path) -> None:
    import json

    from eb_manipulation.generate import SUBSET_FAMILIES, audit_form

    path = audit_form(str(tmp_path / "form.json"), seed=5, per_subset=2)
    doc = json.loads(path.read_text())
    fresh = ManipulationEnv.load_tasks(task_file=str(path))
    assert doc["count"] == len(fresh) == sum(len(f) for f in SUBSET_FAMILIES.values())  # one task per family
    assert doc["seed"] == 5 and doc["verified"] is True
    for subset, families in SUBSET_FAMILIES.items():
        assert sorted(t.id for t in fresh if t.subset == subset) == sorted(f"{subset}_{f}_00" for f in families)
