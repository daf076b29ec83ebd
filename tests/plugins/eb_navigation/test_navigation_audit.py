"""Navigation's audit probes pass on the shipped tasks and fail on deliberately broken ones; the blind table."""

from __future__ import annotations

import json
from collections import defaultdict

import numpy as np
import pytest

from eb_core.audit import AuditProbe
from eb_core.env import Task
from eb_navigation.audit import MAX_RULE_AGENT_RATE, target_visible_probe, text_only_rule_agent_probe
from eb_navigation.baselines import BLIND_POLICIES, blind_successes, policy_name
from eb_navigation.env import NavigationEnv, build_room
from eb_navigation.geometry import AgentState, bearing_to, distance_to
from eb_navigation.tasks import SUBSETS, spec_of


@pytest.fixture(scope="module")
def tasks() -> list[Task]:
    return NavigationEnv.load_tasks()


def _with_start(task: Task, x: float, y: float, yaw: int) -> Task:
    meta = json.loads(json.dumps(task.metadata))
    meta["start"].update(x=x, y=y, yaw=yaw)
    return Task(id=task.id, subset=task.subset, instruction=task.instruction, metadata=meta)


def _easy_start(task: Task) -> Task:
    """The same task moved to a start facing the target across open floor: a forward walk solves it."""
    spec = spec_of(task)
    room = build_room(spec)
    free = room.free_space(room.extra_ids)
    xy = spec.target.position[:2]
    for i, j in free.free_cells():
        for h in range(4):
            s = AgentState(i, j, h)
            if not (1.6 <= distance_to(s, xy) <= 2.5 and abs(bearing_to(s, xy)) < 5):
                continue
            plan = free.shortest_plan(s, xy)
            if plan and set(plan) == {0}:  # straight ahead, nothing in the way
                return _with_start(task, s.x, s.y, s.yaw_deg)
    raise LookupError(task.id)


def registered_probes(env: str) -> list:
    """The world's audit probes as ``eb audit`` finds them: through ``EnvSpec.audit_probes``."""
    from eb_core.plugins import Registry
    from eb_core.specs import load_entry_point

    return list(load_entry_point(Registry.create().get("env", env).audit_probes)())


def test_probes_are_named_by_the_spec() -> None:
    probes = registered_probes("navigation")
    assert [p.name for p in probes] == ["text_only_rule_agent", "target_visible_at_start"]
    assert all(isinstance(p, AuditProbe) and p.description for p in probes)


def test_rule_agent_probe_passes_on_the_shipped_tasks(tasks) -> None:
    res = text_only_rule_agent_probe(tasks, {})
    assert res.passed, res.value
    assert {r["subset"] for r in res.rows} == set(SUBSETS)
    assert all(r["solved"] <= MAX_RULE_AGENT_RATE * r["tasks"] for r in res.rows)


def test_rule_agent_probe_fails_when_starts_face_the_target_across_open_floor(tasks) -> None:
    broken = []
    for t in tasks[:40]:
        if t.subset == "base":
            try:
                broken.append(_easy_start(t))
            except LookupError:
                continue
    assert len(broken) >= 3
    res = text_only_rule_agent_probe(broken, {})
    assert not res.passed and set(res.failing_tasks) <= {t.id for t in broken} and res.failing_tasks


def test_visibility_probe_passes_on_a_sample_of_every_subset(tasks) -> None:
    sample = [t for t in tasks if int(t.id.rsplit("_", 1)[1]) % 15 == 0]  # 4 rooms x 5 subsets, rendered
    res = target_visible_probe(sample, {})
    assert res.passed, (res.value, res.failing_tasks)
    assert {r["subset"] for r in res.rows} == set(SUBSETS)


def test_visibility_probe_fails_when_the_target_is_not_where_the_subset_promises(tasks) -> None:
    by_id = {t.id: t for t in tasks}
    base = by_id["base_000"]
    s = base.metadata["start"]
    turned = _with_start(base, s["x"], s["y"], (s["yaw"] + 180) % 360)  # target behind: not "in view"
    lh = by_id["long_horizon_000"]
    shown = Task(id="long_horizon_000", subset="long_horizon", instruction=lh.instruction,
                 metadata={**base.metadata})  # long_horizon starting where base starts: target in view
    res = target_visible_probe([turned, shown, by_id["common_sense_001"]], {})
    assert not res.passed and res.failing_tasks == ["base_000", "long_horizon_000"]


def _blind_table(tasks) -> dict[str, np.ndarray]:
    rooms, solved = {}, defaultdict(list)
    for t in tasks:
        spec = spec_of(t)
        key = (spec.scene.kind, spec.scene.seed, spec.extra_objects)
        room = rooms.get(key) or rooms.setdefault(key, build_room(spec))
        s = AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw)
        solved[t.subset].append(blind_successes(room.free_space(room.extra_ids), s, spec.target.position[:2]))
    return {k: np.mean(v, axis=0) for k, v in solved.items()}


def test_every_blind_constant_action_policy_solves_at_most_5_percent_per_subset(tasks) -> None:
    """All 10,948 blind policies (prefix of 0-2 turns, then a cycle of up to 4 actions) on the geometry."""
    rates = _blind_table(tasks)
    for subset, r in rates.items():
        worst = int(np.argmax(r))
        assert r[worst] <= 0.05, f"{subset}: {policy_name(BLIND_POLICIES[worst])} solves {100 * r[worst]:.1f} %"


def test_the_blind_table_fails_on_the_broken_starts(tasks) -> None:
    broken = []
    for t in tasks[:40]:
        if t.subset == "base":
            try:
                broken.append(_easy_start(t))
            except LookupError:
                continue
    assert len(broken) >= 3
    forward = next(k for k, p in enumerate(BLIND_POLICIES) if p.prefix == () and p.cycle == (0,))
    assert _blind_table(broken)["base"][forward] == 1.0


def test_audit_form_draws_spread_scene_slots_with_scaled_caps(tmp_path) -> None:
    from eb_navigation.generate import audit_form

    out = tmp_path / "form.json"
    audit_form(str(out), seed=11, per_subset=2)
    doc = json.loads(out.read_text())
    gen = doc["generator"]
    assert gen["slots"] == [0, 30] and gen["blind_cap"] == 1 and gen["rule_cap"] == 1 and gen["seed"] == 11
    fresh = NavigationEnv.load_tasks(task_file=str(out))
    assert sorted(t.id for t in fresh if t.subset == "base") == ["base_000", "base_030"]
    assert {t.subset for t in fresh} == set(SUBSETS) and len(fresh) == 2 * len(SUBSETS)
    # slot 30 is a room of the kind and target type slot 30 of the full file has (kinds cycle, then targets)
    from eb_navigation.generate import TARGETS_BY_KIND
    from eb_navigation.room import KINDS

    slot30 = next(t for t in fresh if t.id == "base_030")
    kind = KINDS[30 % len(KINDS)]
    assert spec_of(slot30).scene.kind == kind
    assert spec_of(slot30).target.type == TARGETS_BY_KIND[kind][(30 // len(KINDS)) % len(TARGETS_BY_KIND[kind])]
