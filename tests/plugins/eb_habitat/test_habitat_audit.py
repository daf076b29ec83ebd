"""Habitat's audit probes: the shipped tasks pass; a deliberately broken task set fails each probe."""

from __future__ import annotations

import copy

from eb_core.audit import AuditProbe
from eb_core.env import Task
from eb_habitat.audit import (
    FIRST_BRANCH_LIMIT,
    WORD_MATCH_LIMIT,
    conditional_first_branch,
    word_guess,
    word_matching_score,
    word_matching_spatial,
)
from eb_habitat.env import HabitatEnv


def _tasks() -> list[Task]:
    return HabitatEnv.load_tasks()


def _with(task: Task, **changes) -> Task:
    data = task.model_dump()
    data.update(changes)
    return Task(**data)


def registered_probes(env: str) -> list:
    """The world's audit probes as ``eb audit`` finds them: through ``EnvSpec.audit_probes``."""
    from eb_core.plugins import Registry
    from eb_core.specs import load_entry_point

    return list(load_entry_point(Registry.create().get("env", env).audit_probes)())


def test_the_spec_names_the_probes() -> None:
    probes = registered_probes("habitat")
    assert [p.name for p in probes] == ["word_matching_spatial", "conditional_first_branch"]
    assert all(isinstance(p, AuditProbe) and p.description for p in probes)


def test_word_matcher_reads_fixed_positions() -> None:
    guess = word_guess("Put the lemon in the drawer to the right of the sink.")
    assert guess is not None and guess.type_key == "lemon" and guess.targets == ("right_drawer",)
    guess = word_guess("Move the banana from the sofa to the counter that sits above the left drawer.")
    assert guess is not None and guess.targets == ("left_counter",)
    assert word_guess("Move the leftmost object on the desk to the sofa.") is None


def test_shipped_spatial_tasks_pass_the_word_matching_probe() -> None:
    res = word_matching_spatial(_tasks(), {})
    assert res.passed, res.value
    assert res.rows and sum(r["tasks"] for r in res.rows) == 50


def test_word_matching_probe_fails_on_fixed_position_tasks() -> None:
    """Spatial tasks that name a receptacle by a position that is the same in every apartment: the matcher solves
    them without an image, so the probe must fail."""
    tasks = _tasks()
    spatial = [t for t in tasks if t.subset == "spatial_relationship"]
    broken = []
    for i, t in enumerate(spatial[:20]):
        meta = copy.deepcopy(t.metadata)
        obj = meta["objects"][0]
        target = "right_drawer" if obj["at"] != "right_drawer" else "left_drawer"
        side = target.split("_")[0]
        meta["goal"] = [f"(inside ?{obj['type']} {target})"]
        meta["subgoals"] = [[f"(holding ?{obj['type']})"], meta["goal"]]
        name = obj["type"].replace("_", " ").replace("rubiks", "Rubik's").replace("skillet", "frying pan")
        text = f"Put the {name} in the drawer to the {side} of the sink."
        broken.append(_with(t, id=f"spatial-broken-{i}", instruction=text, metadata=meta))
    assert sum(word_matching_score(t) for t in broken) >= 0.9 * len(broken)
    res = word_matching_spatial(broken + spatial[20:], {})
    assert not res.passed
    assert float(res.value.split()[0]) > 100 * WORD_MATCH_LIMIT
    assert res.failing_tasks and res.failing_tasks[0].startswith("spatial-broken-")


def test_shipped_conditionals_pass_and_one_sided_ones_fail() -> None:
    tasks = _tasks()
    assert conditional_first_branch(tasks, {}).passed
    # Make every conditional's answer its first branch: swap the goal object to the first-named one.
    from eb_habitat.audit import _first_branch_type  # the probe's own reading of the instruction

    broken = []
    for t in tasks:
        if t.subset == "complex_instruction" and ".if_" in t.metadata["template"]:
            first = _first_branch_type(t.instruction)
            meta = copy.deepcopy(t.metadata)
            target = meta["goal"][0].split()[-1]
            pred = meta["goal"][0].split()[0]
            meta["goal"] = [f"{pred} ?{first} {target}"]
            meta["subgoals"] = [[f"(holding ?{first})"], meta["goal"]]
            broken.append(_with(t, metadata=meta))
    assert broken
    res = conditional_first_branch(broken, {})
    assert not res.passed and float(res.value.split()[0]) > 100 * FIRST_BRANCH_LIMIT


def test_audit_form_is_the_start_of_a_full_draw(tmp_path) -> None:
    from eb_habitat.generate import audit_form, generate_subset

    audit_form(str(tmp_path / "form"), seed=9, per_subset=3)
    fresh = HabitatEnv.load_tasks(task_dir=str(tmp_path / "form"))
    subsets = {t.subset for t in fresh}
    assert len(fresh) == 3 * len(subsets) == 18
    full = generate_subset("base", n=5, seed=9)
    assert [t.instruction for t in fresh if t.subset == "base"] == [t["instruction"] for t in full[:3]]
