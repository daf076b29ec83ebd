"""The hard EB-Habitat task set: shipped files, generator knob, goal rules, expert, blind players, rendering."""

from __future__ import annotations

import json
import re
from collections import Counter
from collections.abc import Callable
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


def _object_and_blocker(t: Task) -> tuple[object, object | None, str | None]:
    """(the object a one-object task moves, the look-alike in its way or None, where that one must go)."""
    spec = spec_of(t)
    moves = [g[1:-1].split()[1:] for g in spec.goal if g.startswith(("(on ", "(inside "))]
    names = {o.name: o for o in spec.objects}
    if len(moves) == 1:
        return names[moves[0][0]], None, None
    (blocker, aside), (mover, _) = moves
    return names[mover], names[blocker], aside


def test_look_alikes_have_colours_of_their_own_and_a_near_hue_one_stands_beside_the_object() -> None:
    """Five instances in five colours; in most tasks one of them, in a near hue (yellow beside orange), stands on
    the object's own surface: to its right (``pick up``, the leftmost, still takes the object), or to its left,
    in the way, when the goal moves it first (version 5)."""
    paired = 0
    tasks = BY_SUBSET["base"] + BY_SUBSET["visual_appearance"]
    for t in tasks:
        spec = spec_of(t)
        mover, blocker, _ = _object_and_blocker(t)
        twins = [o for o in spec.objects if o.type == mover.type]
        handled = mover.handle is not None  # version 6: a same-colour mug with its handle the other way
        assert len(twins) == len({o.color for o in twins}) + handled == 5, t.id
        assert all(o.color in HARD_COLORS[o.type] for o in twins), t.id
        beside = [o for o in twins if o.at == mover.at and o.name != mover.name]
        assert len(beside) <= 1, t.id
        if beside:  # left of the object only when the goal moves it out of the way
            assert (beside[0] == blocker) == (beside[0].slot < mover.slot), t.id
            if handled:
                assert beside[0].color == mover.color and {beside[0].handle, mover.handle} == {"left", "right"}, t.id
            else:
                assert beside[0].color in near_hues(mover.type, mover.color), t.id
            paired += 1
    assert paired >= 0.55 * len(tasks)  # 58 of 100 at seed 0


IN_THE_WAY_SUBSETS = ("base", "common_sense", "visual_appearance")


def test_in_the_way_the_look_alike_left_of_the_object_goes_to_the_named_receptacle_first() -> None:
    """Version 5: every one-object task of base, common_sense, visual_appearance and complex_instruction's stories
    and negations says that a look-alike left of the object (the same type in another colour) must first go to
    a named receptacle. In 30-75 % of a subset (version 7: base 36 of 50) one stands there (its near hue) and the
    goal moves it there, once;
    in the rest nothing of the type stands left of the object, and the goal moves the object alone. The clause
    never names the look-alike's colour, and the object is not the leftmost of its kind exactly when one is in
    the way."""
    from eb_habitat.catalog import RECEPTACLES

    for subset in (*IN_THE_WAY_SUBSETS, "complex_instruction"):
        tasks = [t for t in BY_SUBSET[subset] if ".in_the_way." in t.metadata["template"]]
        if subset != "complex_instruction":
            assert len(tasks) == 50, subset
        else:
            assert {t.metadata["template"].split(".")[2] for t in tasks} == {"story", "negation", "story_count"}
            assert len(tasks) >= 15
        blocked = 0
        for t in tasks:
            spec = spec_of(t)
            mover, blocker, aside = _object_and_blocker(t)
            left = [o for o in spec.objects if o.type == mover.type and o.at == mover.at and o.slot < mover.slot]
            clause = next(c for c in re.split(r"(?<=[.?]) ", t.instruction) if re.search("to its left|left of it", c))
            named = [r.key for r in RECEPTACLES if f"the {r.name.lower()}" in clause.lower()]
            assert named, t.id
            if blocker is None:
                assert not left, t.id
                continue
            blocked += 1
            assert left == [blocker] and aside == named[-1] and f"(once {blocker.name})" in spec.goal, t.id
            assert not re.search(rf"\b{blocker.color}\b", clause), t.id
        assert 0.3 * len(tasks) <= blocked <= 0.75 * len(tasks), (subset, blocked)  # version 7: base 36 of 50


def test_a_stateless_agent_walks_straight_back_after_moving_a_look_alike_out_of_the_way() -> None:
    """The view that shows the look-alike in the way shows the object right of it, so one plan moves the
    look-alike to the named receptacle and walks back for the object: the bound is shorter than a walk that
    starts again from the first receptacle, which it would be without the clause's template."""
    from eb_habitat.search import stateless_search_steps

    shorter = 0
    for t in BY_SUBSET["base"]:
        if _object_and_blocker(t)[1] is None:
            continue
        m = t.metadata
        args = (m["objects"], m["open"], m["goal"], t.instruction)
        wide = bool(m.get("wide"))
        back = stateless_search_steps(*args, m["template"], wide=wide)
        restart = stateless_search_steps(*args, m["template"].replace(".in_the_way.", ".way."), wide=wide)
        assert back is not None and restart is not None and back <= restart, t.id
        shorter += back < restart
    assert shorter >= 10


def _gathering(t: Task) -> tuple[list, list, str]:
    """(movers, the other objects of the gathered types, the instruction's colour) of a long_horizon task."""
    from eb_habitat.hard import GATHER_GROUPS, NEAR_HUES

    spec = spec_of(t)
    names = {g.split()[1] for g in spec.goal if g.startswith(("(on ", "(inside "))}
    movers = [o for o in spec.objects if o.name in names]
    first = t.instruction.split(".")[0]
    group = next(g for g in sorted(GATHER_GROUPS, key=len, reverse=True)
                 if any(re.search(rf"\b{w}\b", first) for w in GATHER_GROUPS[g][:2]))
    assert {o.type for o in movers} <= set(group), t.id
    colors = [c for c in NEAR_HUES if re.search(rf"\b{c}\b", first)]
    assert len(colors) == 1, t.id
    rest = [o for o in spec.objects if o.type in group and o.name not in names]
    return movers, rest, colors[0]


def test_long_horizon_gathers_every_object_of_a_colour_without_saying_how_many() -> None:
    """Quantified gathering (version 4; long_horizon, and complex_instruction's "every ... except ..." share): 2-4
    objects qualify by colour (or by not having it), on 2-3 receptacles;
    the number is never said; every qualifying object is reachable (left of the others of its type there); a
    look-alike that must stay stands beside one of them and others stand alone elsewhere, near hues among them."""
    numbers = re.compile(r"\b(two|three|four|five|\d)\b", re.I)
    negated = 0
    every_except = [t for t in BY_SUBSET["complex_instruction"] if ".gather_not." in t.metadata["template"]]
    assert 5 <= len(every_except) <= 15  # complex_instruction's "every ... except ..." share
    for t in BY_SUBSET["long_horizon"] + every_except:
        assert ".gather" in t.metadata["template"] and not numbers.search(t.instruction), t.id
        if t.subset == "complex_instruction":
            assert len(_gathering(t)[0]) <= 3 and t.metadata["oracle_steps"] <= 12, t.id
        movers, rest, color = _gathering(t)
        negated += t.subset == "long_horizon" and ".gather_not." in t.metadata["template"]
        if ".gather_not." in t.metadata["template"]:
            assert all(o.color != color for o in movers) and all(o.color == color for o in rest), t.id
            assert any(o.color in near_hues(o.type, color) for o in movers), t.id
        else:
            assert all(o.color == color for o in movers) and all(o.color != color for o in rest), t.id
            assert sum(o.color in near_hues(o.type, color) for o in rest) >= 3, t.id
        assert 2 <= len(movers) <= 4 and 2 <= len({o.at for o in movers}) <= 3, t.id
        assert len({g.split()[2] for g in spec_of(t).goal if g.startswith("(on ")}) == 1, t.id
        for o in movers:  # left of every look-alike of its type there
            assert all(r.slot > o.slot for r in rest if r.at == o.at and r.type == o.type), t.id
        at_movers = {o.at for o in movers}
        assert any(r.at in at_movers for r in rest), t.id
        assert sum(r.at not in at_movers for r in rest) >= 3, t.id
    assert 0.2 * 50 <= negated <= 0.5 * 50


def test_gatherings_of_one_type_hold_its_look_alike_type_in_a_colour_that_qualifies() -> None:
    """Version 5 (long_horizon): "every red mug" has a red cup on a surface with a qualifying mug ("every mug that
    is not yellow": a cup of another colour), so the type is judged beside the colour, in one view; the
    look-alike type is never a mover."""
    from eb_habitat.catalog import allowed_colors
    from eb_habitat.hard import CONFUSERS

    seen = 0
    for t in BY_SUBSET["long_horizon"]:
        movers, rest, color = _gathering(t)
        types = {o.type for o in movers} | {o.type for o in rest}
        if len(types) != 1 or CONFUSERS[next(iter(types))][0] in types:
            continue
        twin = CONFUSERS[next(iter(types))][0]
        negated = ".gather_not." in t.metadata["template"]
        if not any((c != color) == negated for c in allowed_colors(twin)):
            continue  # no plate is orange: "every orange bowl" has no look-alike that could qualify
        twins = [o for o in spec_of(t).objects if o.type == twin]
        assert twins and all((o.color != color) == negated for o in twins), t.id
        assert any(o.at in {m.at for m in movers} for o in twins), t.id
        seen += 1
    assert seen >= 15


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
    task = next(t for t in BY_SUBSET["base"] if _object_and_blocker(t)[1] is None)
    spec = spec_of(task)
    mover = next(o for o in spec.objects if o.name == spec.goal[0].split()[1])
    twin = next(o for o in spec.objects if o.type == mover.type and o.at != mover.at)
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
    task = next(t for t in BY_SUBSET["base"] if _object_and_blocker(t)[1] is None)
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
            dest = [g for g in spec.goal if g.startswith("(on ")][-1].split()[2].rstrip(")")  # after any look-alike
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


def _landmark_place(t: Task) -> str:
    """Where the landmark of a counting conditional lies ("the green plate" in "the furniture holding the green
    plate")."""
    spec = spec_of(t)
    for o in spec.objects:
        name = o.type.replace("_", " ")
        if re.search(rf"(?:Find|holding|with) the {o.color} {name}\b", t.instruction):
            return o.at
    raise AssertionError(f"{t.id}: no landmark named")


def _counted(t: Task) -> tuple[str, int]:
    """The counted type of a counting task and the number the instruction asks for."""
    text = t.instruction
    m = (re.search(r"hold (?P<name>[a-z ]+?)s\. .* exactly (?P<n>two|three) of them", text)  # "Several surfaces ..."
         or re.search(r"exactly (?P<n>two|three) (?P<name>[a-z ]+?)s\b", text)
         or re.search(r"Count the (?P<name>[a-z ]+?)s ", text))
    assert m is not None, t.id
    number, name = m.groupdict().get("n") or "two", m.group("name")
    kind = next(o.type for o in spec_of(t).objects if o.type.replace("_", " ") == name)
    return kind, {"two": 2, "three": 3}[number]


def _named_place(t: Task) -> str:
    """The receptacle a counting conditional names as its other branch."""
    from eb_habitat.catalog import RECEPTACLES

    return next(r.key for r in RECEPTACLES if f"the {r.name.lower()}" in t.instruction.lower())


def test_first_branch_probe_reads_the_destination_of_a_counting_conditional() -> None:
    """Both branches move the same object, one "there" (the landmark's place), the other to the receptacle the
    instruction names; the ``.named_first.`` templates name that one first. Answers that always follow the first
    branch, or always "there", must fail the probe."""
    from eb_habitat.audit import conditional_first_branch

    tasks = BY_SUBSET["complex_instruction"]
    cond = [t for t in tasks if ".if_count." in t.metadata["template"]]
    assert len(cond) >= 6 and conditional_first_branch(tasks, {}).passed

    def answered(place: Callable[[Task], str]) -> list[Task]:
        out = []
        for t in cond:
            meta = json.loads(json.dumps(t.metadata))
            meta["goal"][0] = f"(on {meta['goal'][0].split()[1]} {place(t)})"
            out.append(t.model_copy(update={"metadata": meta}))
        return out

    first = answered(lambda t: _named_place(t) if ".named_first." in t.metadata["template"] else _landmark_place(t))
    assert conditional_first_branch(first, {}).value.startswith("100")
    assert not conditional_first_branch(first, {}).passed
    there_first = sum(".named_first." not in t.metadata["template"] for t in cond)
    assert (there_first / len(cond) > 0.65) == (not conditional_first_branch(answered(_landmark_place), {}).passed)


def test_counting_conditionals_pay_the_named_branch_in_few_tasks() -> None:
    """A blind player reaches the named receptacle without looking, so that branch is the answer in about a
    quarter of the conditionals (at least one); the order of the branches still says nothing (either comes first,
    and the first-named one answers half, within one)."""
    from eb_habitat.hard import NAMED_ANSWER_SHARE

    cond = [t for t in BY_SUBSET["complex_instruction"] if ".if_count." in t.metadata["template"]]
    named = [t for t in cond if spec_of(t).goal[0].split()[2].rstrip(")") == _named_place(t)]
    assert 1 <= len(named) <= max(1, NAMED_ANSWER_SHARE * len(cond))
    assert {".named_first." in t.metadata["template"] for t in cond} == {True, False}
    first = sum((t in named) == (".named_first." in t.metadata["template"]) for t in cond)
    assert abs(2 * first - len(cond)) <= 1


def test_counting_conditionals_the_count_beside_the_landmark_decides() -> None:
    """Exactly two of the counted type beside the landmark sends the object there, one sends it to the named
    receptacle; a look-alike landmark holds the other count, so a misread colour flips the branch."""
    from eb_habitat.catalog import receptacle

    cond = [t for t in BY_SUBSET["complex_instruction"] if ".if_count." in t.metadata["template"]]
    answers = set()
    for t in cond:
        spec = spec_of(t)
        kind, _ = _counted(t)
        there = _landmark_place(t)
        dest = spec.goal[0].split()[2].rstrip(")")
        count = sum(o.type == kind and o.at == there for o in spec.objects)
        assert count in (1, 2), t.id
        if count == 2:
            assert dest == there, t.id
        else:
            assert dest != there and receptacle(dest).name.lower() in t.instruction.lower(), t.id
        answers.add(count)
        lm_kind = next(o.type for o in spec.objects if o.at == there and o.type != kind)
        others = {o.at for o in spec.objects if o.type == lm_kind} - {there}
        flip = [o for o in spec.objects if o.type == lm_kind and o.at in others
                and sum(p.type == kind and p.at == o.at for p in spec.objects) == 3 - count]
        lm_color = next(o.color for o in spec.objects if o.type == lm_kind and o.at == there)
        near = near_hues(lm_kind, lm_color)
        assert flip and (not near or any(o.color in near for o in flip)), t.id
    assert answers == {1, 2}


def test_counting_destinations_hold_exactly_the_number_and_decoys_do_not() -> None:
    """"The furniture that holds exactly two cups" (spatial_relationship since version 5; base in versions 3-6):
    the destination holds exactly that many of the type and nothing else (nothing hides what is counted), two decoy
    surfaces hold one more or one fewer (or one fewer beside an object of the look-alike type: a mug among cups),
    and no other receptacle holds the type."""
    from eb_habitat.hard import CONFUSERS

    count_tasks = [t for t in BY_SUBSET["spatial_relationship"] if t.metadata["template"].endswith(".count")]
    assert len(count_tasks) >= 15  # version 5: a relation, then a count (spatial)
    for t in count_tasks:
        spec = spec_of(t)
        kind, n = _counted(t)
        dest = _object_and_blocker(t)[0]
        dest = next(g for g in spec.goal if g.startswith(f"(on {dest.name} "))[1:-1].split()[2]
        here = sorted(o.type for o in spec.objects if o.at == dest)
        decoys = {o.at for o in spec.objects if o.type == kind} - {dest}
        assert len(decoys) == 2, t.id
        if here != [kind] * n:  # version 5: two of the type and one of its look-alike type (two cups, a mug)
            assert n == 2 and sorted(here) == sorted([kind, kind, CONFUSERS[kind][0]]), t.id
        for at in decoys:
            there = [o.type for o in spec.objects if o.at == at]
            twins = [k for k in there if k in CONFUSERS[kind]]
            assert there.count(kind) != n and len(there) == there.count(kind) + len(twins), t.id
            if here == [kind] * n:
                assert there.count(kind) in (n - 1, n + 1), t.id
                assert len(twins) <= 1 and (not twins or there.count(kind) == n - 1), t.id
            else:
                assert (there.count(kind), len(twins)) in ((1, 1), (3, 0), (1, 2)), t.id


def test_every_hard_task_is_within_the_stateless_bound() -> None:
    """A seeing agent without memory (the benchmark's planner with ``chat_history=False``) solves every shipped
    hard task within 28 of the 30 steps, walking the receptacle list forward and backward (a task is not kept for
    lying early in the list); the agent with memory within 26."""
    from eb_habitat.hard import MAX_SEARCH_STEPS, MAX_STATELESS_STEPS
    from eb_habitat.search import search_steps, stateless_search_steps

    for t in HARD:
        m = t.metadata
        args = (m["objects"], m["open"], m["goal"], t.instruction, m["template"])
        wide = bool(m.get("wide"))
        for reverse in (False, True):
            steps = stateless_search_steps(*args, reverse=reverse, wide=wide)
            assert steps is not None and m["oracle_steps"] <= steps <= MAX_STATELESS_STEPS, (t.id, reverse)
            assert m["oracle_steps"] <= search_steps(*args, reverse=reverse, wide=wide) <= MAX_SEARCH_STEPS, (t.id,
                                                                                                          reverse)


def test_no_gathering_gives_its_objects_to_a_blind_walker_in_list_order() -> None:
    from eb_habitat.search import first_met

    for t in BY_SUBSET["long_horizon"]:
        m = t.metadata
        assert not first_met(m["objects"], m["goal"]) and not first_met(m["objects"], m["goal"], reverse=True)


def _cups(first: str = "red") -> list[dict]:
    second = "orange" if first == "red" else "red"
    return [{"name": "cup_1", "type": "cup", "color": "red", "at": "left_counter", "slot": 0 if first == "red" else 1},
            {"name": "cup_2", "type": "cup", "color": "orange", "at": "left_counter",
             "slot": 1 if second == "orange" else 0},
            {"name": "cup_3", "type": "cup", "color": "red", "at": "sofa", "slot": 0},
            {"name": "cup_4", "type": "cup", "color": "orange", "at": "desk", "slot": 0}]


GATHER_GOAL = ["(on cup_1 coffee_table)", "(on cup_3 coffee_table)", "(once cup_1)", "(once cup_3)",
               "(untouched cup_2)", "(untouched cup_4)"]


def test_gathering_bounds_walk_every_receptacle_opening_the_closed_ones() -> None:
    """"Bring every red cup to the coffee table": the agent does not know there are two, so it walks the list
    (opening the four closed containers) until the last is placed; without memory it walks back to look again
    after every delivery."""
    from eb_habitat.search import gather_steps, search_steps, stateless_search_steps

    text = "Bring every red cup to the coffee table."
    args = (_cups(), [], GATHER_GOAL, text, "hard.long.gather.0")
    # forward: left counter, pick, coffee table, place, back (1-5); right counter, sink, 4 x (navigate, open)
    # (6-15); sofa, pick, coffee table, place (16-19)
    assert stateless_search_steps(*args) == 19
    assert search_steps(*args) == 18  # with memory: no walk back to the left counter, nothing is left there
    # backward: desk .. sofa (8), pick, coffee table, place, back (9-12); 4 x (navigate, open), sink, right and
    # left counter (13-23), pick, coffee table, place (24-26)
    assert stateless_search_steps(*args, reverse=True) == 26
    assert search_steps(*args, reverse=True) == 25
    assert stateless_search_steps(_cups(), ["fridge", "cabinet"], GATHER_GOAL, text, "hard.long.gather.0") == 17
    # the orange cup left of the red one: ``pick up the cup`` would take it, no agent can gather without it
    assert gather_steps(_cups("orange"), [], GATHER_GOAL) is None


def test_first_met_is_what_a_blind_walker_in_list_order_takes() -> None:
    from eb_habitat.search import first_met

    objects = [{"name": "mug_1", "type": "mug", "color": "red", "at": "sofa", "slot": 0},
               {"name": "mug_2", "type": "mug", "color": "blue", "at": "desk", "slot": 0},
               {"name": "mug_3", "type": "mug", "color": "pink", "at": "desk", "slot": 1}]
    assert first_met(objects, ["(on mug_1 desk)"]) and not first_met(objects, ["(on mug_1 desk)"], reverse=True)
    assert first_met(objects, ["(on mug_2 sofa)"], reverse=True)
    assert not first_met(objects, ["(on mug_3 sofa)"], reverse=True)  # mug_2 is left of it: pick up takes mug_2


def test_a_named_branch_is_known_only_at_the_landmark_that_decides() -> None:
    """In a counting conditional the named receptacle is the answer only once the agent, holding the object, has
    seen the count beside the landmark: it walks to the landmark first (a blind walk straight to the named
    receptacle is no plan of a seeing agent)."""
    from eb_habitat.search import search_steps, stateless_search_steps

    objects = [{"name": "mug_1", "type": "mug", "color": "red", "at": "left_counter", "slot": 0},
               {"name": "bowl_1", "type": "bowl", "color": "blue", "at": "sofa", "slot": 0},
               {"name": "cup_1", "type": "cup", "color": "white", "at": "sofa", "slot": 1}]
    goal = ["(on mug_1 desk)", "(once mug_1)", "(untouched bowl_1)", "(untouched cup_1)"]
    text = "Count the cups on the piece of furniture with the blue bowl. Exactly two: the red mug goes there. " \
           "Any other number: the red mug goes on the desk."
    plain = stateless_search_steps(objects, [], goal, text, "hard.base.0")
    assert plain == 1 + 1 + 1 + 1  # navigate, pick, navigate to the named desk, place
    # navigate, pick, walk again (left counter to sofa: 8 receptacles, 4 of them opened), then the desk
    assert stateless_search_steps(objects, [], goal, text, "hard.complex.if_count.2") == 2 + 7 + 4 + 2
    assert search_steps(objects, [], goal, text, "hard.complex.if_count.2") > search_steps(objects, [], goal, text)


def _scene(mug_at: str, bowl_at: str) -> tuple[list[dict[str, object]], list[str]]:
    objects = [{"name": "mug_1", "type": "mug", "color": "red", "at": mug_at, "slot": 0},
               {"name": "bowl_1", "type": "bowl", "color": "blue", "at": bowl_at, "slot": 0}]
    return objects, [f"(on mug_1 {bowl_at})", "(once mug_1)", "(untouched bowl_1)"]


def test_stateless_agent_starts_its_walk_again_after_a_pick() -> None:
    """Mug on the desk (last in catalogue order), bowl on the right counter (second): with memory the agent walks
    to 15 receptacles and opens 4 containers (19), then picks, walks back and places (22); without memory it
    picks at the desk and walks again from the left counter (20 + 2 + place = 23). The other way round it picks
    on the left counter at once and finds the bowl on its second walk."""
    from eb_habitat.search import search_steps, stateless_search_steps

    text = "Put the red mug beside the blue bowl."
    objects, goal = _scene("desk", "right_counter")
    assert search_steps(objects, [], goal, text) == 22
    assert stateless_search_steps(objects, [], goal, text) == 23
    objects, goal = _scene("left_counter", "desk")
    assert stateless_search_steps(objects, [], goal, text) == 1 + 1 + 14 + 4 + 1  # nav, pick, walk on, opens, place
    assert stateless_search_steps(objects, ["fridge", "cabinet"], goal, text) == 1 + 1 + 14 + 2 + 1


def test_stateless_agent_walks_straight_to_a_named_receptacle() -> None:
    from eb_habitat.search import stateless_search_steps

    objects, _ = _scene("sofa", "desk")
    goal = ["(on mug_1 left_chair)", "(once mug_1)", "(untouched bowl_1)"]
    # 8 navigations and 4 opens to reach the sofa, then pick, navigate, place
    assert stateless_search_steps(objects, [], goal, "Put the red mug on the left chair.") == 8 + 4 + 3


def test_a_witness_on_another_receptacle_cannot_be_acted_on_without_memory() -> None:
    """Version 2's conditionals ("if the mug beside the red bowl is yellow, bring the orange mug there"): the view
    that decides is not the view where the object is picked up."""
    from eb_habitat.search import stateless_search_steps

    objects, goal = _scene("sofa", "desk")
    text = "If the mug beside the blue bowl is red, bring the red mug there."
    assert stateless_search_steps(objects, [], goal, text, "hard.complex.if_beside.0") is None
    assert stateless_search_steps(objects, [], goal, text, "hard.complex.if_count.0") is not None


def test_generator_refuses_a_task_above_the_stateless_bound(monkeypatch: pytest.MonkeyPatch) -> None:
    import random

    from eb_habitat import hard

    def kept(bound: int | None) -> int:
        monkeypatch.setattr(hard, "stateless_search_steps", lambda *a, **k: bound)
        rng, n = random.Random(5), 0
        for i in range(40):
            try:
                n += hard.draw("base", rng, "hard", i) is not None
            except hard._Reject:
                pass
        return n

    assert kept(hard.MAX_STATELESS_STEPS) > 0
    assert kept(hard.MAX_STATELESS_STEPS + 1) == 0
    assert kept(None) == 0


HANDLE_SUBSETS = ("base", "common_sense", "complex_instruction", "visual_appearance")


def test_a_mug_is_told_from_its_same_colour_twin_only_by_its_handle() -> None:
    """Version 6: in about half of base, common_sense, visual_appearance (and a third of complex_instruction) the
    object is a mug whose instruction names its colour and the side its handle points to; beside it on the same
    surface stands the one other mug of that colour, its handle the other way (left of it, in the way, in some).
    The instruction's side is the object's; no other object has a handle's side; the twin's pick feedback reads
    the same, so only the image tells them apart."""
    for subset in HANDLE_SUBSETS:
        handled = 0
        for t in BY_SUBSET[subset]:
            spec = spec_of(t)
            sides = [o for o in spec.objects if o.handle is not None]
            if not sides:
                assert "handle points" not in t.instruction and "pointing to the" not in t.instruction, t.id
                continue
            handled += 1
            mover, _, _ = _object_and_blocker(t)
            twin = next(o for o in sides if o.name != mover.name)
            assert len(sides) == 2 and mover.type == twin.type == "mug", t.id
            assert (twin.at, twin.color) == (mover.at, mover.color) and twin.handle != mover.handle, t.id
            assert re.search(rf"\b{mover.color}\b[^.]*pointing? to the {mover.handle} as you face it", t.instruction) \
                or re.search(rf"\b{mover.color}\b[^.]*handle points to the {mover.handle} as you face it",
                             t.instruction), t.id
            others = [o for o in spec.objects if o.type == "mug" and o.color == mover.color]
            assert len(others) == 2, t.id
        low = 0.25 if subset == "complex_instruction" else 0.3  # version 7: common_sense 17
        assert low * 50 <= handled <= 0.6 * 50, (subset, handled)


def test_a_handle_on_anything_but_a_mug_on_a_surface_is_refused(tmp_path: Path) -> None:
    data = json.loads((taskset_dir("hard") / "base.json").read_text())
    obj = data["tasks"][0]["metadata"]["objects"][0]
    obj["handle"] = "left"
    obj["type"], obj["name"] = "bowl", "bowl_9"
    bad = tmp_path / "base.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(TaskFileError, match=r"objects\[0\]\.handle"):
        load_task_file(bad)


def test_the_handle_is_drawn_on_the_side_the_file_says_and_is_in_view() -> None:
    """Real rendering: at the object's receptacle, in the 500 px view the model gets, each of the two mugs shows
    its handle (the segmentation mask is wider on the handle's side of the body by several pixels), on the side the
    task file names; checked on one task per subset and receptacle kind."""
    import numpy as np
    from eb_habitat.render import AGENT, ApartmentRenderer

    renderer = ApartmentRenderer(500)
    seen: set[str] = set()
    checked = 0
    for t in (t for s in HANDLE_SUBSETS for t in BY_SUBSET[s]):
        spec = spec_of(t)
        mugs = [o for o in spec.objects if o.handle is not None]
        if not mugs or mugs[0].at in seen:
            continue
        seen.add(mugs[0].at)
        renderer.load(spec)
        world = spec.world()
        world.agent_at = mugs[0].at
        renderer.render(world)
        assert renderer._renderer is not None
        seg = renderer._renderer.segmentation(AGENT)
        names = renderer._renderer.instance_names
        for o in mugs:
            mask = seg == names.index(o.name)
            cols = np.nonzero(mask.any(axis=0))[0]
            assert mask.sum() > 800, (t.id, o.name)  # in view, not hidden
            body_left_of_centre = np.nonzero(mask)[1].mean() - (cols[0] + cols[-1]) / 2
            assert (body_left_of_centre > 1.0) if o.handle == "left" else (body_left_of_centre < -1.0), (t.id, o.name)
        checked += 1
        if checked == 6:
            break
    renderer.close()
    assert checked == 6


def test_no_handle_pair_stands_on_furniture_of_its_colour() -> None:
    """A blue handle on the blue sofa barely shows at 500 px: the clash table is exactly the receptacles whose
    furniture has a mug colour, and no shipped pair stands on one in its colour."""
    from eb_habitat.catalog import RECEPTACLES
    from eb_habitat.hard import HANDLE_CLASHES, HANDLE_COLORS
    from eb_habitat.render import LAYOUTS

    surfaces = [r.key for r in RECEPTACLES if r.kind == "surface"]
    clashes = {(a, k): lay.furniture[k].color for a, lay in enumerate(LAYOUTS) for k in surfaces
               if k in lay.furniture and lay.furniture[k].color in HANDLE_COLORS}
    assert clashes == HANDLE_CLASHES
    for t in HARD:
        spec = spec_of(t)
        for o in spec.objects:
            if o.handle is not None:
                assert HANDLE_CLASHES.get((spec.apartment, o.at)) != o.color, t.id


# -- version 7: counting five to eight on wide surfaces --------------------------------------------------------------

_WORDS = {"five": 5, "six": 6, "seven": 7, "eight": 8}
WIDE_SUBSETS = ("base", "common_sense", "complex_instruction", "visual_appearance")


def _wide_count(t: Task) -> tuple[str, int, str]:
    """(counted type, number asked for, destination) of a version-7 counting task."""
    from eb_habitat.catalog import object_type
    from eb_habitat.hard import COUNT_LOOKS, COUNT_USES, WIDE_COUNTED

    spec = spec_of(t)
    m = re.search(r"exactly (five|six|seven|eight)\b", t.instruction)
    assert m is not None, t.id
    words = {y: (object_type(y).name + "s", COUNT_USES[y], COUNT_LOOKS[y]) for y in WIDE_COUNTED}
    kind = next(y for y, w in words.items() if any(f"{m.group(1)} {p}" in t.instruction or f"hold {p}." in
                                                   t.instruction for p in w))
    obj = _object_and_blocker(t)[0]
    dest = next(g for g in spec.goal if g.startswith(f"(on {obj.name} "))[1:-1].split()[2]
    return kind, _WORDS[m.group(1)], dest


def test_wide_counting_destinations_hold_five_to_eight_among_shape_twins_beside_near_counts() -> None:
    """Version 7: "the furniture that holds exactly seven bowls" (in base, common_sense by use, visual_appearance by
    looks, complex_instruction's stories) -- a wide task whose destination holds exactly n (5-8) of the counted type
    and one or two of its shape twin (plates among bowls; none where the surface has no room left) and nothing
    else; two other wide surfaces hold one fewer
    and one more, two more, or two fewer (version 8: the destination holds the fewest, the middle or the most with
    equal chances), with twins; no other receptacle holds the counted type."""
    from eb_habitat.catalog import WIDE_CAPACITY
    from eb_habitat.hard import WIDE_COUNTED

    per_subset = {}
    ranks: Counter[str] = Counter()
    for s in WIDE_SUBSETS:
        tasks = [t for t in BY_SUBSET[s] if t.metadata.get("wide")]
        per_subset[s] = len(tasks)
        for t in tasks:
            spec = spec_of(t)
            kind, n, dest = _wide_count(t)
            twin = WIDE_COUNTED[kind]
            here = [o.type for o in spec.objects if o.at == dest]
            assert 5 <= n <= 8 and dest in WIDE_CAPACITY, t.id
            assert here.count(kind) == n and here.count(twin) <= 2 and len(here) == n + here.count(twin), t.id
            assert here.count(twin) >= 1 or n + 1 == WIDE_CAPACITY[dest], t.id  # no twin only where it has no room
            assert len(here) < WIDE_CAPACITY[dest], t.id  # a free slot: a failed place tells nothing
            decoys = {o.at for o in spec.objects if o.type == kind} - {dest}
            counts = sorted(sum(o.type == kind and o.at == at for o in spec.objects) for at in decoys)
            assert counts in ([n - 1, n + 1], [n + 1, n + 2], [n - 2, n - 1]), (t.id, n, counts)
            ranks["fewest" if n < counts[0] else "most" if n > counts[1] else "middle"] += 1
            assert all(at in WIDE_CAPACITY for at in decoys), t.id
            for at in decoys:
                assert {o.type for o in spec.objects if o.at == at} <= {kind, twin}, t.id
    assert all(n >= 15 for n in per_subset.values()), per_subset  # seed 0: 22, 23, 20, 17
    # no rank gives the destination away (version 7 held the middle count in 66 of 82)
    assert min(ranks.values()) >= 0.2 * sum(ranks.values()) and len(ranks) == 3, ranks


def test_every_counted_object_is_uncovered_in_the_view_where_it_is_counted() -> None:
    """Real rendering and segmentation, at 500 px: in every shipped wide task of one subset, every object on a
    surface where a count is made shows at least COUNT_MIN_PIXELS pixels, and at least COUNT_MIN_SHARE of the
    pixels it shows when alone (objects stand close and in two depths, but none merges into another)."""
    from eb_habitat.hard import COUNT_MIN_PIXELS, COUNT_MIN_SHARE, counted_surfaces
    from eb_habitat.render import ApartmentRenderer

    renderer = ApartmentRenderer(500)
    checked = 0
    for t in [t for t in BY_SUBSET["base"] if t.metadata.get("wide")][:12]:
        spec = spec_of(t)
        renderer.load(spec)
        world = spec.world()
        surfaces = counted_surfaces(spec.objects)
        assert len(surfaces) == 3, t.id
        for key in surfaces:
            world.agent_at = key
            shares = renderer.visible_shares(world, [o.name for o in spec.objects if o.at == key])
            assert len(shares) >= 5
            for name, (px, share) in shares.items():
                assert px >= COUNT_MIN_PIXELS and share >= COUNT_MIN_SHARE, (t.id, key, name, px, share)
                checked += 1
    renderer.close()
    assert checked >= 12 * 3 * 5


def test_a_counted_object_hidden_behind_another_makes_the_draw_unfair() -> None:
    """The generator's fairness check sees occlusion: a flat tuna can right behind a tall soda can on a wide
    counter is covered, and the draw is refused; spread apart, the same objects pass."""
    from eb_habitat.hard import counted_views_fair

    def entry(slots: list[int]) -> dict:
        objs = [{"name": f"soda_can_{i + 1}", "type": "soda_can", "color": "red", "at": "left_counter", "slot": s}
                for i, s in enumerate(slots[:-1])]
        objs.append({"name": "tuna_can_1", "type": "tuna_can", "color": "blue", "at": "left_counter",
                     "slot": slots[-1]})
        objs.append({"name": "bowl_1", "type": "bowl", "color": "red", "at": "desk", "slot": 0})
        goal = ["(on bowl_1 left_counter)"]
        return {"metadata": {"apartment": 0, "template": "test", "objects": objs, "open": [], "goal": goal,
                             "subgoals": [goal], "oracle_steps": 4, "wide": True}}

    # even slots stand further back, odd ones nearer: the can in slot 1 stands in front of the flat tin in slot 0
    assert counted_views_fair(entry([0, 2, 4, 6, 8]))
    assert not counted_views_fair(entry([1, 3, 5, 7, 0]))
    # and leaves no renderer behind in the shared GL pool (one left there broke the pool tests of other worlds
    # that ran later in the same process)
    from eb_scenekit.pool import pool_stats

    assert pool_stats()["users"] == 0


def test_wide_slots_are_refused_in_a_task_that_is_not_wide(tmp_path: Path) -> None:
    """Slot 6 of the left counter exists only in a wide (hard, version 7) task: elsewhere one clear line."""
    doc = json.loads((taskset_dir("hard") / "base.json").read_text())
    task = next(t for t in doc["tasks"] if t["metadata"].get("wide"))
    big = next(o for o in task["metadata"]["objects"] if o["slot"] >= 4)
    task["metadata"].pop("wide")
    doc["tasks"] = [task]
    path = tmp_path / "base.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(TaskFileError, match=f"slot {big['slot']} but the .* has [34] slot"):
        load_task_file(path)


def test_no_counted_object_stands_on_furniture_of_its_colour() -> None:
    """A blue cup on the blue sofa barely stands out at 500 px: counted objects and their twins never take the
    furniture's colour (the clash table above), nor white, black, silver or gray -- except a twin whose type has
    one colour only (the tuna can: blue label, silver top, yellow band, which shows on the blue sofa) -- and two
    objects in neighbouring slots never share a colour (two red mugs half in front of each other read as one)."""
    from eb_habitat.catalog import allowed_colors
    from eb_habitat.hard import COUNT_COLORS_OUT, HANDLE_CLASHES, counted_surfaces

    checked = 0
    for t in (t for s in WIDE_SUBSETS for t in BY_SUBSET[s] if t.metadata.get("wide")):
        spec = spec_of(t)
        for key in counted_surfaces(spec.objects):
            row = sorted((o for o in spec.objects if o.at == key), key=lambda o: o.slot)
            for a, b in zip(row, row[1:]):  # neighbours stand half in front of each other: never one colour
                assert b.slot != a.slot + 1 or a.color != b.color, (t.id, a.name, b.name)
            for o in spec.objects:
                if o.at == key and len(allowed_colors(o.type)) > 1:
                    assert o.color not in COUNT_COLORS_OUT, (t.id, o.name)
                    assert HANDLE_CLASHES.get((spec.apartment, key)) != o.color, (t.id, o.name)
                    checked += 1
    assert checked > 500


def test_complex_instruction_follows_its_family_schedule_at_every_seed_and_size() -> None:
    """Version 8: complex_instruction's families are a fixed schedule, not shares that rejection reweights (its
    counting stories were 10, 16 and 22 of 50 at seeds 0-2): the shipped file holds exactly COMPLEX_FAMILIES, and a
    fresh form of any size holds them scaled, in a seeded order."""
    import random

    from eb_habitat.hard import COMPLEX_FAMILIES, family_schedule

    def family(template: str) -> str:
        kind = template.split(".")[2]
        return {"story_count": "count", "if_count": "conditional", "gather_not": "gather",
                "negation": "story"}.get(kind, kind)

    shipped = Counter(family(t.metadata["template"]) for t in BY_SUBSET["complex_instruction"])
    assert shipped == COMPLEX_FAMILIES
    for n in (20, 50, 7):
        drawn = family_schedule(random.Random(n), n)
        assert len(drawn) == n and set(drawn) <= set(COMPLEX_FAMILIES)
        for f, k in COMPLEX_FAMILIES.items():
            assert abs(drawn.count(f) - k * n / 50) < 1, (n, f, drawn.count(f))
    assert family_schedule(random.Random(1), 50) != family_schedule(random.Random(2), 50)
    assert Counter(family_schedule(random.Random(1), 50)) == COMPLEX_FAMILIES
