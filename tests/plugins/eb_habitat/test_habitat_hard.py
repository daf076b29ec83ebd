"""The hard EB-Habitat task set: shipped files, generator knob, goal rules, expert, blind players, rendering."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from eb_habitat.blind import blind_guess, blind_sweep, text_rule_agent
from eb_habitat.catalog import HARD_COLORS
from eb_habitat.env import HabitatEnv
from eb_habitat.goals import PredicateError, parse_predicate
from eb_habitat.hard import near_hues
from eb_habitat.make import generate
from eb_habitat.skills import skill_id
from eb_habitat.tasks import SUBSETS, TaskFileError, load_task_file, spec_of, taskset_dir

from eb_core.env import Task

HARD = HabitatEnv.load_tasks(taskset="hard")
BY_SUBSET = {s: [t for t in HARD if t.subset == s] for s in SUBSETS}


def _sample(n: int) -> list[Task]:
    return [t for s in SUBSETS for t in BY_SUBSET[s][:: 50 // n][:n]]


def test_shipped_hard_set_has_the_classic_subsets_and_counts() -> None:
    assert {s: len(ts) for s, ts in BY_SUBSET.items()} == {s: 50 for s in SUBSETS}
    assert len({t.id for t in HARD}) == 300
    classic = HabitatEnv.load_tasks()
    assert {t.instruction for t in classic}.isdisjoint(t.instruction for t in HARD)


def test_regenerating_hard_with_seed_0_gives_the_shipped_files(tmp_path: Path) -> None:
    written = generate(out=str(tmp_path), seed=0, difficulty="hard")
    assert len(written) == 6
    for path in written:
        shipped = taskset_dir("hard") / Path(path).name
        assert json.loads(Path(path).read_text()) == json.loads(shipped.read_text())


def test_medium_and_other_seeds_give_fresh_forms(tmp_path: Path) -> None:
    medium = load_task_file(generate(out=str(tmp_path / "m"), seed=3, per_subset=5, subset="base",
                                     difficulty="medium")[0])
    hard = load_task_file(generate(out=str(tmp_path / "h"), seed=3, per_subset=5, subset="base",
                                   difficulty="hard")[0])
    assert len(medium) == len(hard) == 5
    assert {t.instruction for t in hard}.isdisjoint(t.instruction for t in BY_SUBSET["base"])
    # medium: fewer look-alikes of the target's type than hard
    def same_type(t: Task) -> int:
        spec = spec_of(t)
        mover = spec.goal[0].split()[1]
        kind = spec.instances()[mover]
        return sum(o.type == kind for o in spec.objects)
    assert max(map(same_type, medium)) < min(map(same_type, hard))
    with pytest.raises(ValueError, match="unknown difficulty 'extreme'; allowed: classic, medium, hard"):
        generate(out=str(tmp_path), difficulty="extreme")


def test_every_hard_goal_protects_every_other_object_and_picks_the_mover_once() -> None:
    for t in HARD:
        spec = spec_of(t)
        movers = {g.split()[1] for g in spec.goal if g.startswith(("(on ", "(inside "))}
        untouched = {g[len("(untouched "):-1] for g in spec.goal if g.startswith("(untouched ")}
        once = {g[len("(once "):-1] for g in spec.goal if g.startswith("(once ")}
        assert movers and once == movers, t.id
        assert untouched == set(spec.instances()) - movers, t.id
        assert re.search(r"(nothing|anything) else|every other object", t.instruction), t.id
        assert re.search(r"only once|just once|second pick-up", t.instruction), t.id
        assert all(not any(p.name in ("untouched", "once") for p in group) for group in spec.subgoal_predicates())


def test_look_alikes_have_colours_of_their_own_and_a_near_hue_one_stands_right_of_the_object() -> None:
    """Five instances in five colours; in most tasks one of them, in a near hue (yellow beside orange), stands on
    the object's own surface to its right, so ``pick up`` (the leftmost) still takes the object."""
    paired = 0
    tasks = BY_SUBSET["base"] + BY_SUBSET["visual_appearance"]
    for t in tasks:
        spec = spec_of(t)
        mover = next(o for o in spec.objects if o.name == spec.goal[0].split()[1])
        twins = [o for o in spec.objects if o.type == mover.type]
        assert len(twins) == len({o.color for o in twins}) == 5, t.id
        assert all(o.color in HARD_COLORS[o.type] for o in twins), t.id
        beside = [o for o in twins if o.at == mover.at and o is not mover]
        assert all(o.slot > mover.slot for o in beside), t.id  # the object is the leftmost of its kind there
        assert len(beside) <= 1, t.id
        if beside:
            assert beside[0].color in near_hues(mover.type, mover.color), t.id
            paired += 1
    assert paired >= 0.6 * len(tasks)


def test_long_horizon_objects_each_have_a_near_hue_look_alike_beside_them() -> None:
    for t in BY_SUBSET["long_horizon"]:
        spec = spec_of(t)
        for g in spec.goal:
            if g.startswith(("(on ", "(inside ")):
                mover = next(o for o in spec.objects if o.name == g.split()[1])
                beside = [o for o in spec.objects if o.type == mover.type and o.at == mover.at and o is not mover]
                assert [o.color in near_hues(mover.type, mover.color) and o.slot > mover.slot
                        for o in beside] == [True], t.id


def test_untouched_and_once_take_a_name_not_a_type() -> None:
    with pytest.raises(PredicateError, match="instance name"):
        parse_predicate("(untouched ?mug)")
    with pytest.raises(PredicateError, match="not in the scene"):
        parse_predicate("(once mug_9)", {"mug_1": "mug"})


@pytest.mark.parametrize("task", _sample(4), ids=lambda t: t.id)
def test_expert_solves_open_and_closed_loop(task: Task) -> None:
    env = HabitatEnv(render=False)
    env.reset(task, 0)
    plan = env.expert_plan()
    assert plan is not None and len(plan) == task.metadata["oracle_steps"]
    results = [env.step(a) for a in plan]
    assert results[-1].task_success and all(r.action_success for r in results)
    env.reset(task, 0)
    for _ in range(30):
        r = env.step(env.expert_plan()[0])
        if r.done:
            break
    assert r.task_success


def test_a_wrong_pick_is_final_even_when_put_back() -> None:
    task = BY_SUBSET["base"][0]
    spec = spec_of(task)
    mover = next(o for o in spec.objects if o.name == spec.goal[0].split()[1])
    twin = next(o for o in spec.objects if o.type == mover.type and o.name != mover.name)
    env = HabitatEnv(render=False)
    env.reset(task, 0)
    env.step(skill_id("navigate", twin.at))  # look-alikes lie on surfaces or in containers that start open
    picked = env.step(skill_id("pick", twin.type))
    assert picked.action_success and twin.color in picked.feedback
    assert env.step(skill_id("place", twin.at)).action_success
    assert env.expert_plan() is None  # no plan reaches the goal any more
    assert env.expert_reason == (f"(untouched {twin.name}) no longer holds: {twin.name} was picked up at all, "
                                 f"which the task forbids")
    assert f"(untouched {twin.name})" in env.step(skill_id("navigate", mover.at)).info["unmet_goals"]


def test_the_object_cannot_be_tried_at_one_receptacle_after_another() -> None:
    task = BY_SUBSET["base"][1]
    spec = spec_of(task)
    mover = next(o for o in spec.objects if o.name == spec.goal[0].split()[1])
    dest = spec.goal[0].split()[2].rstrip(")")
    env0 = spec.world()
    wrong = next(k for k in ("sofa", "desk", "tv_stand", "brown_table") if k not in (dest, mover.at)
                 and env0.free_slot(k) is not None and mover.type not in {it.type for it in env0.items_at(k)})
    env = HabitatEnv(render=False)
    env.reset(task, 0)
    env.step(skill_id("navigate", mover.at))
    assert env.step(skill_id("pick", mover.type)).action_success
    env.step(skill_id("navigate", wrong))
    assert env.step(skill_id("place", wrong)).action_success
    assert env.step(skill_id("pick", mover.type)).action_success
    env.step(skill_id("navigate", dest))
    r = env.step(skill_id("place", dest))
    assert r.action_success and not r.task_success
    assert r.info["unmet_goals"] == [f"(once {mover.name})"]


def test_blind_players_stay_at_or_below_five_percent_per_subset() -> None:
    for subset, tasks in BY_SUBSET.items():
        n = len(tasks) * 6  # 300 episodes each: one seeded episode per task scatters too much around ~2 %
        guess = sum(blind_guess(t, s) for t in tasks for s in range(6))
        sweep = sum(blind_sweep(t, s) for t in tasks for s in range(6))
        assert guess <= 0.05 * n and sweep <= 0.05 * n, (subset, guess, sweep)


def test_blind_players_do_solve_classic_tasks() -> None:
    """The players are not broken: the classic set lets them through (the problem issue 25 names)."""
    classic = [t for t in HabitatEnv.load_tasks() if t.subset == "base"]
    assert sum(blind_guess(t) for t in classic) > 20  # 29 of 50
    assert sum(text_rule_agent(t) for t in classic) > 30  # 42 of 50


def test_hard_train_split_is_drawn_at_the_knob_and_kept_apart() -> None:
    tasks = HabitatEnv.split_tasks("train", 0, 6, taskset="hard", render=False)
    assert [t.subset for t in tasks] == list(SUBSETS)
    assert all(any(g.startswith("(untouched ") for g in t.metadata["goal"]) for t in tasks)
    classic = HabitatEnv.split_tasks("train", 0, 6, render=False)
    assert not any(any(g.startswith("(untouched ") for g in t.metadata["goal"]) for t in classic)
    medium = HabitatEnv.split_tasks("train", 0, 1, render=False, difficulty="medium")
    assert medium[0].instruction != tasks[0].instruction
    shipped = {t.instruction for t in HARD}
    assert not shipped & {t.instruction for t in tasks}


def test_unknown_taskset_is_one_clear_line() -> None:
    with pytest.raises(ValueError, match="unknown taskset 'nightmare'; shipped sets are classic, hard"):
        HabitatEnv.load_tasks(taskset="nightmare")


def test_a_hard_file_with_a_colour_the_type_lacks_is_refused(tmp_path: Path) -> None:
    doc = json.loads((taskset_dir("hard") / "base.json").read_text())
    doc["tasks"][0]["metadata"]["objects"][0]["color"] = "gold"
    bad = tmp_path / "base.json"
    bad.write_text(json.dumps(doc))
    with pytest.raises(TaskFileError, match=r"base-00.*color.*'gold' is not a colour of"):
        load_task_file(bad)


@pytest.mark.parametrize("subset", ["spatial_relationship", "visual_appearance"])
def test_target_and_landmark_are_in_view_where_the_agent_stands(subset: str) -> None:
    """Rendered: at the object's receptacle the object shows, and at the destination the landmark (or, for a
    named destination, nothing blocks the place)."""
    env = HabitatEnv(render=True)
    try:
        task = BY_SUBSET[subset][0]
        spec = spec_of(task)
        mover = spec.goal[0].split()[1]
        src = next(o.at for o in spec.objects if o.name == mover)
        env.reset(task, 0)
        obs = env.step(skill_id("navigate", src)).observation
        if spec_of(task).world().is_open(src):
            assert mover in {o.name for o in obs.objects if o.box is not None}
        if subset == "visual_appearance":
            dest = spec.goal[0].split()[2].rstrip(")")
            obs = env.step(skill_id("navigate", dest)).observation
            types = {o.type for o in obs.objects if o.box is not None}
            assert types  # the landmark lies there
    finally:
        env.close()


def test_generating_a_form_reports_progress_on_stderr(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    generate(out=str(tmp_path), seed=7, per_subset=10, subset="long_horizon", difficulty="hard")
    err = capsys.readouterr().err
    assert "habitat hard long_horizon: 10/10 tasks" in err
    assert len(load_task_file(tmp_path / "long_horizon.json")) == 10


def test_first_branch_probe_reads_the_colour_of_a_hard_conditional() -> None:
    from eb_habitat.audit import _first_branch, conditional_first_branch

    tasks = BY_SUBSET["complex_instruction"]
    cond = [t for t in tasks if ".if_" in t.metadata["template"]]
    assert cond and conditional_first_branch(tasks, {}).passed
    broken = []
    for t in cond:  # make the first-named branch the answer every time
        kind, color = _first_branch(t.instruction)
        first = next(o["name"] for o in t.metadata["objects"] if o["type"] == kind and o["color"] == color)
        meta = json.loads(json.dumps(t.metadata))
        meta["goal"][0] = f"(on {first} {meta['goal'][0].split()[2]}"
        broken.append(t.model_copy(update={"metadata": meta}))
    assert not conditional_first_branch(broken, {}).passed
