"""The hard task set (``taskset=hard``): its files, its promises, blind play, the oracle, and the classic set pinned."""

from __future__ import annotations

import hashlib
import math
import random
import re
from collections import Counter, defaultdict
from pathlib import Path

import eb_navigation
import numpy as np
import pytest
from eb_navigation.baselines import (
    BLIND_POLICIES,
    HARD_RULE_AGENTS,
    MAX_STEPS,
    REACTIVE_ON_FAIL,
    REACTIVE_RULE_AGENTS,
    SIDESTEP_RULE_AGENTS,
    blind_successes,
    plan_lengths,
    rule_agent_successes,
)
from eb_navigation.env import NavigationEnv, build_room
from eb_navigation.geometry import AgentState, bearing_to
from eb_navigation.hard import (
    CHECK_AGENTS,
    HARD_TYPES,
    LEVELS,
    MIN_COLOUR_DISTANCE,
    MIN_LOOKALIKE_GAP,
    WALL_BAND,
    blockers_seen,
    clear_corridor,
    lookalike_first,
    not_in_pocket,
    open_way,
    way_blockers,
    way_objects,
    way_seen,
    wide_enough,
    wide_space,
)
from eb_navigation.hard_set import AUDIT_SAMPLE, MAX_RATE, audit_sample
from eb_navigation.hard_words import HARD_COLOUR_WORDS, hard_colour_word
from eb_navigation.room import ExtraSpec, colour_distance
from eb_navigation.tasks import (
    DEFAULT_TASK_FILE,
    HARD_DIR,
    SUBSETS,
    TaskFileError,
    load_task_file,
    load_taskset,
    spec_of,
)
from eb_scenekit.objects import get_type

from eb_core.planner import PlannerConfig
from eb_core.taskfile import TaskFileError as CoreTaskFileError
from eb_core.taskfile import task_set_digest

CLASSIC_FILE_SHA256 = "cc21c96a5369e4ce3da7802eda0810e930189ac32f4c6b9480bd31cd73a79f36"
CLASSIC_TASKS_DIGEST = "fd8b8664512ca5b10095c64d3e187b48822da98b22c45f8a6ac39757e3a7f60c"


@pytest.fixture(scope="module")
def hard():
    return load_taskset("hard")


@pytest.fixture(scope="module")
def vis():
    """One 128 x 128 visibility renderer for the rendered checks of this module, closed at its end."""
    from eb_navigation.visibility import Visibility

    v = Visibility()
    yield v
    v.close()


@pytest.fixture(scope="module")
def rooms(hard):
    out = {}
    for t in hard:
        key = (t.scene.kind, t.scene.seed, t.scene.clutter, t.extra_objects)
        if key not in out:
            out[key] = build_room(t)
    return lambda t: out[(t.scene.kind, t.scene.seed, t.scene.clutter, t.extra_objects)]


def test_classic_file_and_tasks_are_pinned() -> None:
    assert hashlib.sha256(DEFAULT_TASK_FILE.read_bytes()).hexdigest() == CLASSIC_FILE_SHA256
    assert task_set_digest(load_task_file().tasks) == CLASSIC_TASKS_DIGEST
    assert task_set_digest(load_taskset("classic")) == CLASSIC_TASKS_DIGEST
    assert [t.id for t in NavigationEnv.load_tasks()] == [t.id for t in load_task_file().tasks]
    assert "clutter" not in NavigationEnv.load_tasks()[0].metadata["scene"]  # classic metadata as before


def test_one_task_file_error_and_unknown_taskset() -> None:
    assert TaskFileError is CoreTaskFileError
    with pytest.raises(ValueError, match="unknown taskset 'expert'; available: classic, hard"):
        NavigationEnv.load_tasks(taskset="expert")


def test_hard_files_shape(hard) -> None:
    assert sorted(p.name for p in HARD_DIR.glob("*.json")) == sorted(f"{s}.json" for s in SUBSETS)
    assert len(hard) == 300 and Counter(t.subset for t in hard) == {s: 60 for s in SUBSETS}
    tasks = NavigationEnv.load_tasks(taskset="hard")
    assert [t.id for t in tasks] == [t.id for t in hard]
    assert not {(t.scene.kind, t.scene.seed) for t in hard} & {(t.scene.kind, t.scene.seed)
                                                                for t in load_task_file().tasks}
    for s in SUBSETS:
        texts = [t.instruction for t in hard if t.subset == s]
        assert len(set(texts)) == 60 if s != "long_horizon" else len(set(texts)) >= 50, s


def test_targets_are_small_with_lookalikes_told_apart_by_colour(hard, rooms) -> None:
    level = LEVELS["hard"]
    for t in hard:
        assert t.target.type in HARD_TYPES and t.scene.clutter == level.clutter, t.id
        room = rooms(t)
        looks = [o for o in room.objects if o.type == t.target.type and o.id != t.target.id]
        assert len(looks) >= level.lookalikes[0], t.id
        for o in looks:
            assert colour_distance(o.colour, t.target.colour) >= MIN_COLOUR_DISTANCE - 1e-9, (t.id, o.id)
            if o.id in {e.id for e in t.extra_objects}:
                assert math.hypot(o.x - t.target.position[0], o.y - t.target.position[1]) >= MIN_LOOKALIKE_GAP, t.id
        assert hard_colour_word(t.target.type, t.target.colour) in t.instruction, t.id
        if t.subset == "complex_instruction":  # a look-alike is named, by another colour
            assert sum(hard_colour_word(o.type, o.colour) in t.instruction for o in looks) >= 1, t.id


def test_starts_no_pocket_and_long_horizon_direction_must_be_found(hard, rooms) -> None:
    sides = Counter()
    level = LEVELS["hard"]
    for t in hard:
        room = rooms(t)
        free = room.free_space(room.extra_ids)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        assert not_in_pocket(free, s), t.id
        assert t.oracle_steps <= (level.lh_max_plan if t.subset == "long_horizon" else level.max_plan), t.id
        b = bearing_to(s, t.target.position[:2])
        if t.subset == "long_horizon":
            assert abs(b) >= LEVELS["hard"].lh_min_bearing, t.id
            sides["behind" if abs(b) > 135 else "left" if b > 0 else "right"] += 1
        else:
            assert abs(b) <= 45.0, t.id
    assert min(sides.values()) >= 12 and sides["behind"] <= 30, sides  # not "exactly behind" every time


def test_no_blind_policy_or_feedback_only_agent_solves_more_than_5_percent_of_a_subset(hard, rooms) -> None:
    """The issue's rule, on all 300 tasks: no one of the 10,948 blind constant-action policies and no one of the
    feedback-only agents (the core audit's 8 feedback policies among them) solves more than 5 % of any subset
    (3 of 60), nor more than 5 % (one) of the 20 tasks per subset that ``eb audit --quick`` plays. The generator
    (``eb_navigation.hard_set.generate_level``) never takes a start that would break either."""
    blind: dict[str, list[np.ndarray]] = defaultdict(list)
    agents: dict[str, list[list[bool]]] = defaultdict(list)
    for t in hard:
        room = rooms(t)
        free = room.free_space(room.extra_ids)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        blind[t.subset].append(blind_successes(free, s, t.target.position[:2]))
        solved = rule_agent_successes(free, s, t.target.position[:2], agents=CHECK_AGENTS)
        agents[t.subset].append(list(solved.values()))
    assert set(CHECK_AGENTS) >= {*HARD_RULE_AGENTS, *SIDESTEP_RULE_AGENTS, *REACTIVE_RULE_AGENTS}
    over = {}
    for subset in SUBSETS:
        b, a = np.sum(blind[subset], axis=0), np.sum(agents[subset], axis=0)
        cap = int(MAX_RATE * len(blind[subset]) + 1e-9)
        over |= {(subset, BLIND_POLICIES[k].name): int(b[k]) for k in np.flatnonzero(b > cap)}
        over |= {(subset, name): int(n) for name, n in zip(CHECK_AGENTS, a) if n > cap}
        picked = sorted(audit_sample(len(blind[subset])))
        assert len(picked) == AUDIT_SAMPLE
        b = np.sum([blind[subset][i] for i in picked], axis=0)
        a = np.sum([agents[subset][i] for i in picked], axis=0)
        over |= {(subset, "audit sample", BLIND_POLICIES[k].name): int(b[k]) for k in np.flatnonzero(b > 1)}
        over |= {(subset, "audit sample", name): int(n) for name, n in zip(CHECK_AGENTS, a) if n > 1}
    assert cap == 3 and not over, over


def test_plans_leave_slack_and_no_low_object_stands_in_the_way(hard, rooms) -> None:
    """The expert's plans leave room in the 20-step budget (in-view subsets: max <= 14, mean <= 12 on the subsets
    that share base's start and <= 12.1 on visual_appearance, whose start must differ from base's; long_horizon:
    mean <= 15, max <= 16); on NO start does a floor object lower than 0.5 m stand on the straight way to the
    target (it drops below the untilted view near it: a stateless agent walks into it; the set before held 22-29
    of 60 such starts per subset), and at least a third of the in-view starts show a look-alike nearer the middle
    of the view than the target, so "walk at what is ahead" goes to the wrong one."""
    by: dict[str, list] = defaultdict(list)
    for t in hard:
        by[t.subset].append(t)
    for subset, ts in by.items():
        plans = [t.oracle_steps for t in ts]
        mean_cap, max_cap = {"long_horizon": (15, 16), "visual_appearance": (12.1, 14)}.get(subset, (12, 14))
        assert np.mean(plans) <= mean_cap and max(plans) <= max_cap, (subset, np.mean(plans), max(plans))
        blocked, first = [], 0
        for t in ts:
            room = rooms(t)
            s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
            target = room.get(t.target.id)
            if not clear_corridor(room, s, target):
                blocked.append(t.id)
            first += lookalike_first(s, target, [o for o in room.objects if o.type == t.target.type and o != target])
        assert not blocked, (subset, blocked)
        if subset != "long_horizon":
            assert first >= len(ts) // 3, (subset, first)


# Two starts of the hard set as shipped before the rule (main at 9c65849), each lost by a stateless calibration
# player that walked into low floor things on the straight way: two vases 1.45 m ahead (seen in the first image,
# gone from it near them) and an ottoman 0.6 m ahead after the turn toward the target.
_OLD_OFFENDERS = [
    {"id": "base_004", "subset": "base", "instruction": "Make your way to the yellow watering can.",
     "template": "base.04", "scene": {"kind": "living_room", "seed": 256580, "clutter": 20},
     "start": {"x": -0.25, "y": -1.25, "yaw": 90, "tilt": 0},
     "target": {"id": "WateringCan_14", "type": "WateringCan", "colour": "yellow",
                "position": [0.496, 1.402, 0.115]},
     "extra_objects": [
         {"id": "WateringCan_14", "type": "WateringCan", "colour": "yellow", "x": 0.496, "y": 1.402, "yaw": 17.0},
         {"id": "WateringCan_12", "type": "WateringCan", "colour": "green", "x": -1.114, "y": -1.057, "yaw": 164.0},
         {"id": "WateringCan_11", "type": "WateringCan", "colour": "blue", "x": 2.323, "y": -0.93, "yaw": 185.0},
         {"id": "WateringCan_13", "type": "WateringCan", "colour": "blue", "x": -2.393, "y": 1.101, "yaw": 86.0},
         {"id": "Vase_31", "type": "Vase", "colour": "white", "x": -0.155, "y": 0.248, "yaw": 72.0},
         {"id": "Vase_32", "type": "Vase", "colour": "blue", "x": 0.332, "y": 0.073, "yaw": 89.0},
         {"id": "Chair_33", "type": "Chair", "colour": "black", "x": -2.384, "y": 0.289, "yaw": 8.0}],
     "oracle_steps": 10},
    {"id": "long_horizon_007", "subset": "long_horizon",
     "instruction": "Get yourself within arm's reach of the white teddy bear.", "template": "long_horizon.05",
     "scene": {"kind": "living_room", "seed": 280010, "clutter": 20},
     "start": {"x": -1.75, "y": 0.75, "yaw": 180, "tilt": 0},
     "target": {"id": "TeddyBear_11", "type": "TeddyBear", "colour": "white", "position": [1.348, 0.35, 0.16]},
     "extra_objects": [
         {"id": "TeddyBear_11", "type": "TeddyBear", "colour": "white", "x": 1.348, "y": 0.35, "yaw": -1.0},
         {"id": "TeddyBear_12", "type": "TeddyBear", "colour": "brown", "x": -1.365, "y": 1.991, "yaw": 256.0},
         {"id": "Ottoman_31", "type": "Ottoman", "colour": "green", "x": -1.151, "y": 0.51, "yaw": 165.0},
         {"id": "LaundryHamper_32", "type": "LaundryHamper", "colour": "brown", "x": 0.164, "y": 0.961,
          "yaw": -13.0},
         {"id": "HousePlant_33", "type": "HousePlant", "colour": "terracotta", "x": 1.918, "y": 0.996, "yaw": 186.0},
         {"id": "WateringCan_34", "type": "WateringCan", "colour": "blue", "x": -0.971, "y": -0.844, "yaw": -3.0},
         {"id": "WateringCan_35", "type": "WateringCan", "colour": "green", "x": -0.424, "y": 1.38, "yaw": 174.0}],
     "oracle_steps": 14},
]


@pytest.mark.parametrize("entry", _OLD_OFFENDERS, ids=lambda e: e["id"])
def test_the_generator_refuses_an_old_offending_start(entry) -> None:
    """The rule catches the starts that cost a stateless player its task (the low things are named by the rule),
    and ``_pick`` on the same room never offers such a start; the start it takes instead has a clear way."""
    from eb_navigation.hard import Tally, _pick
    from eb_navigation.tasks import NavTaskSpec

    t = NavTaskSpec.model_validate(entry)
    room = build_room(t)
    target = room.get(t.target.id)
    s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
    low = {o.id for o in way_objects(room, s, target) if 2 * o.centre[2] < 0.5}
    assert not clear_corridor(room, s, target)
    assert low == ({"Vase_31", "Vase_32"} if t.id == "base_004" else {"Ottoman_31"}), low
    lv = LEVELS["hard"]
    looks = [o for o in room.objects if o.type == target.type and o.id != target.id]
    sector = "ahead" if t.subset == "base" else "any"
    lo, hi = lv.distance
    seen: list = []
    pick = _pick(room, target, looks, lo, hi + 1.0, 6, 16, sector, lv, Tally(None), np.random.default_rng(0),
                 lambda c: seen.append(c.state) or False, agents=CHECK_AGENTS)
    assert pick is None and seen and s not in seen  # every start offered to the rendered check
    assert all(clear_corridor(room, c, target) for c in seen)


def test_the_open_way_knob_draws_only_open_starts() -> None:
    """With the level's ``open_way`` on (on for the shipped hard set since session 10: see
    docs/hard_tasks/navigation.md), every start of a drawn scene has an open way for its first moves, a way a 0.5 m
    body fits, and everything within reach of its routes in the view facing the target (rendered)."""
    from dataclasses import replace

    from eb_navigation.hard import Tally, draw_scene
    from eb_navigation.visibility import Visibility

    assert not LEVELS["hard"].open_way
    lv = replace(LEVELS["hard"], open_way=True)
    rng = np.random.default_rng(4)
    vis = Visibility()
    try:
        sc = None
        for k in range(60):
            sc = draw_scene("living_room", 920_000 + k, "Vase", lv, rng,
                            {p: Tally(None) for p in ("plain", "visual_appearance", "long_horizon")}, vis, "left")
            if sc is not None:
                break
        assert sc is not None
        target = sc.target
        wide = plan_lengths(wide_space(sc.room), (target.x, target.y))
        for st in sc.starts.values():
            assert open_way(sc.room, st.state, target) and wide_enough(wide, st.state, st.plan)
            assert blockers_seen(sc.room, st.state, target, vis)
    finally:
        vis.close()


def test_the_open_way_knob_draws_starts_few_feedback_agents_solve(monkeypatch) -> None:
    """With ``open_way`` on (geometry only): the target stands at least ``TARGET_WALL_GAP`` from every wall, the
    extra floor things lower than ``WAY_TOP`` stand along the walls, and no start is one that more than
    ``OPEN_MAX_SOLVERS`` feedback-only agents solve, even with no cap -- while the same room with the knob off
    offers a start that more of them solve (open starts are what "forward, step left on a bump" solves)."""
    from dataclasses import replace

    import eb_navigation.hard as hard_module
    from eb_navigation.hard import OPEN_MAX_SOLVERS, TARGET_WALL_GAP, WAY_TOP, Tally, _pick, draw_scene

    lv = replace(LEVELS["hard"], open_way=True)
    rng = np.random.default_rng(2)
    sc, k = None, 0
    for k in range(120):
        sc = draw_scene("living_room", 930_000 + k, "Vase", lv, rng,
                        {p: Tally(None) for p in ("plain", "visual_appearance", "long_horizon")}, None, "left",
                        agents=CHECK_AGENTS)
        if sc is not None:
            break
    assert sc is not None, k
    room, target = sc.room, sc.target
    hx, hy = room.size[0] / 2, room.size[1] / 2
    assert min(hx - abs(target.x), hy - abs(target.y)) >= TARGET_WALL_GAP - 1e-9
    for e in room.extras:
        typ = get_type(e.type)
        if e.type != target.type and typ.height < WAY_TOP:
            assert min(hx - abs(e.x), hy - abs(e.y)) - max(typ.half_extents) - 0.05 <= WALL_BAND + 1e-3, e.id
    free = room.free_space(room.extra_ids)
    for st in sc.starts.values():
        solved = rule_agent_successes(free, st.state, (target.x, target.y), agents=CHECK_AGENTS)
        assert sum(solved.values()) <= OPEN_MAX_SOLVERS and int(st.rules.sum()) == sum(solved.values())
    # the same room without the agent rule (open way only, no cap): its best start is one more agents solve
    monkeypatch.setattr(hard_module, "OPEN_MAX_SOLVERS", 10 ** 6)
    monkeypatch.setattr(hard_module, "OPEN_SOLVER_COST", 0)
    off = _pick(room, target, sc.lookalikes, *lv.distance, 6, lv.max_plan, "ahead", lv, Tally(None),
                np.random.default_rng(0), lambda c: True, agents=CHECK_AGENTS)
    assert off is not None and int(off.rules.sum()) > OPEN_MAX_SOLVERS


# Two starts of the hard set as shipped at ba1a4da, lost by stateless calibration players in session 8 on low
# things they could not see: base_004's first forward moves under a low side table, complex_instruction_034 boxed
# in beside a plant and a hamper.
_PLAYED_LOSSES = [
    {"id": "base_004", "subset": "base", "instruction": "Walk over to the red watering can and stop next to it.",
     "template": "base.01", "scene": {"kind": "living_room", "seed": 236491, "clutter": 20},
     "start": {"x": -1.25, "y": -0.25, "yaw": 0, "tilt": 0},
     "target": {"id": "WateringCan_12", "type": "WateringCan", "colour": "red",
                "position": [1.673, -1.132, 0.115]},
     "extra_objects": [
         {"id": "WateringCan_12", "type": "WateringCan", "colour": "red", "x": 1.673, "y": -1.132, "yaw": 16.0},
         {"id": "WateringCan_13", "type": "WateringCan", "colour": "green", "x": -1.185, "y": -0.812, "yaw": 187.0},
         {"id": "WateringCan_11", "type": "WateringCan", "colour": "yellow", "x": 1.918, "y": 1.019, "yaw": 81.0},
         {"id": "Box_31", "type": "Box", "colour": "brown", "x": 2.08, "y": 1.972, "yaw": 260.0},
         {"id": "LaundryHamper_32", "type": "LaundryHamper", "colour": "tan", "x": 0.025, "y": -0.936, "yaw": 256.0},
         {"id": "SideTable_33", "type": "SideTable", "colour": "oak", "x": -0.699, "y": 0.004, "yaw": 100.0}],
     "oracle_steps": 13},
    {"id": "complex_instruction_034", "subset": "complex_instruction",
     "instruction": "The brown laundry hamper belongs to my neighbour and she is picking it up later. The white "
                    "laundry hamper is ours: stand next to it until I call you.",
     "template": "complex_instruction.01", "scene": {"kind": "living_room", "seed": 254349, "clutter": 20},
     "start": {"x": -1.0, "y": 1.0, "yaw": 270, "tilt": 0},
     "target": {"id": "LaundryHamper_11", "type": "LaundryHamper", "colour": "white",
                "position": [0.43, -0.483, 0.31]},
     "extra_objects": [
         {"id": "LaundryHamper_11", "type": "LaundryHamper", "colour": "white", "x": 0.43, "y": -0.483, "yaw": 90.0},
         {"id": "LaundryHamper_13", "type": "LaundryHamper", "colour": "brown", "x": -1.882, "y": -1.69,
          "yaw": 183.0},
         {"id": "LaundryHamper_14", "type": "LaundryHamper", "colour": "brown", "x": -1.526, "y": 0.651,
          "yaw": 290.0},
         {"id": "Ottoman_31", "type": "Ottoman", "colour": "beige", "x": 2.203, "y": -0.344, "yaw": 105.0},
         {"id": "TeddyBear_32", "type": "TeddyBear", "colour": "tan", "x": -2.238, "y": -0.471, "yaw": 280.0},
         {"id": "BasketBall_33", "type": "BasketBall", "colour": "orange", "x": -2.505, "y": -1.966, "yaw": 99.0},
         {"id": "HousePlant_34", "type": "HousePlant", "colour": "white", "x": -0.488, "y": 0.157, "yaw": 189.0}],
     "oracle_steps": 7},
]


@pytest.mark.parametrize("entry", _PLAYED_LOSSES, ids=lambda e: e["id"])
def test_open_way_refuses_the_starts_players_lost(entry) -> None:
    """``open_way`` closes each of them and ``way_blockers`` names the low things within reach of the routes (none
    of them lower than 0.5 m on the straight line, so the session-8 rule let them pass); ``_pick`` on the same
    room, with the level's ``open_way`` on, offers only starts with an open way."""
    from dataclasses import replace

    from eb_navigation.hard import Tally, _pick
    from eb_navigation.tasks import NavTaskSpec

    t = NavTaskSpec.model_validate(entry)
    room = build_room(t)
    target = room.get(t.target.id)
    s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
    assert clear_corridor(room, s, target) and not open_way(room, s, target)
    expected = {"base_004": {"WateringCan_13", "LaundryHamper_32", "SideTable_33"},
                "complex_instruction_034": {"HousePlant_34", "LaundryHamper_14"}}[t.id]
    assert expected <= set(way_blockers(room, s, target)), way_blockers(room, s, target)
    near = {"base_004": {"WateringCan_13", "SideTable_33"},
            "complex_instruction_034": {"HousePlant_34", "LaundryHamper_14"}}[t.id]
    assert set(way_blockers(room, s, target, near=True)) == near
    lv = replace(LEVELS["hard"], open_way=True)
    looks = [o for o in room.objects if o.type == target.type and o.id != target.id]
    seen: list = []
    pick = _pick(room, target, looks, *lv.distance, 6, lv.max_plan, "ahead", lv, Tally(None),
                 np.random.default_rng(0), lambda c: seen.append(c.state) or False, agents=CHECK_AGENTS)
    assert pick is None and s not in seen
    assert all(open_way(room, c, target) for c in seen)


def test_hard_colour_words_match_the_render() -> None:
    """Every (type, colour) a hard instruction can name, rendered at 500 x 500 from 2 m in one room: the median
    HSV of its pixels fits its word (a "white" thing is bright and grey-free, "light grey" and "grey" are
    colourless and darker, a hue word has its hue); the word of the "white" laundry hamper, whose wicker
    renders grey (value about 0.64), is "light grey" (``HARD_COLOUR_WORDS``)."""
    import colorsys

    from eb_navigation.room import NavRoom
    from eb_navigation.scene import RoomScene

    hues = {"blue": 0.62, "green": 0.35, "red": 0.0, "yellow": 0.14, "brown": 0.08, "tan": 0.1, "pink": 0.96,
            "terracotta": 0.04, "beige": 0.11}
    kind, seed, spot = "living_room", 200011, None
    free = NavRoom(kind, seed, (), 20).free_space()
    for i, j in sorted(free.free_cells(), key=lambda c: abs(c[0]) + abs(c[1])):
        if all(free.is_free(i + k, j) for k in range(9)):
            spot = (i, j)
            break
    assert spot is not None
    bad = {}
    for type_name in HARD_TYPES:
        for colour in get_type(type_name).colors:
            room = NavRoom(kind, seed, [ExtraSpec("X_1", type_name, colour, (spot[0] + 8) * 0.25, spot[1] * 0.25,
                                                  0.0)], 20)
            scene = RoomScene(room, 500, 500)
            try:
                scene.set_agent(AgentState(spot[0], spot[1], 0))
                rgb, mask = scene.first_person(), scene.object_map() == room.index["X_1"]
            finally:
                scene.close()
            rows = np.flatnonzero(mask.any(axis=1))
            if type_name == "HousePlant":  # the colour is the pot's: the lower third, under the leaves
                mask[: rows[0] + 2 * (rows[-1] - rows[0]) // 3] = False
            h, sat, v = np.median([colorsys.rgb_to_hsv(*p) for p in rgb[mask].astype(float) / 255], axis=0)
            word = hard_colour_word(type_name, colour)
            if word == "white":
                ok = sat <= 0.1 and v >= 0.75
            elif word in ("grey", "light grey"):
                ok = sat <= 0.1 and (0.55 <= v < 0.75 if word == "light grey" else 0.3 <= v < 0.55)
            elif word == "black":
                ok = v <= 0.15
            else:
                ok = sat >= 0.25 and min(abs(h - hues[word]), 1 - abs(h - hues[word])) <= 0.04
            if not ok:
                bad[(type_name, colour, word)] = (round(h, 2), round(sat, 2), round(v, 2))
    assert not bad, bad
    assert HARD_COLOUR_WORDS == {("LaundryHamper", "white"): "light grey"}


def test_first_images_show_everything_on_the_way(hard, rooms, vis) -> None:
    """Rendered (128 x 128 segmentation): on every fifth in-view start every floor object on the straight way
    ahead (taller ones; low ones are refused) shows in the first image, so nothing the agent walks into first is
    out of the picture."""
    for t in [t for t in hard if t.subset != "long_horizon" and int(t.id[-3:]) % 5 == 0]:
        room = rooms(t)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        assert way_seen(room, s, room.get(t.target.id), vis), t.id


def test_low_extra_floor_things_stand_along_the_walls(hard, rooms) -> None:
    """The 3-5 extra floor things (not the target or its look-alikes): those lower than 0.5 m stand in the band
    along the walls, so the middle of the room keeps starts with a clear way; taller ones may stand anywhere."""
    for t in [t for t in hard if t.subset == "base"]:
        room = rooms(t)
        hx, hy = room.size[0] / 2, room.size[1] / 2
        extra = [e for e in t.extra_objects if e.type != t.target.type]
        assert len(extra) <= 5, t.id
        for e in extra:
            typ = get_type(e.type)
            r = max(typ.half_extents) + 0.05
            if typ.height < 0.5:
                assert min(hx - abs(e.x), hy - abs(e.y)) - r <= WALL_BAND + 1e-3, (t.id, e.id)


def test_start_ranking_prefers_short_unsolved_and_respects_the_cap() -> None:
    """``_pick`` on one room (geometry only): with no cap it takes a start no longer than any unsolved admissible
    one; with a cap of 0 it never takes a start that a blind policy or agent solves; a low object put on the
    straight way is seen by ``clear_corridor``."""
    from eb_navigation.hard import Tally, _pick, draw_scene
    from eb_navigation.room import NavRoom

    lv = LEVELS["hard"]
    rng = np.random.default_rng(5)
    picks: dict = {}
    for k in range(40):  # the first room that has an unsolved start with a clear way
        sc = draw_scene("living_room", 910_000 + k, "Vase", lv, rng,
                        {p: Tally(None) for p in ("plain", "visual_appearance", "long_horizon")}, None, "left")
        if sc is None:
            continue
        room, target = sc.room, sc.target
        picks = {cap: _pick(room, target, sc.lookalikes, *lv.distance, 6, lv.max_plan, "ahead", lv, Tally(cap),
                            np.random.default_rng(0), lambda c: True, agents=CHECK_AGENTS) for cap in (None, 0)}
        if picks[0] is not None:
            break
    free = room.free_space(room.extra_ids)
    xy = (target.x, target.y)
    assert picks[None] is not None and picks[0] is not None
    assert all(clear_corridor(room, p.state, target) for p in picks.values())  # never a low thing on the way
    clean = picks[0]
    assert not clean.blind.any() and not clean.rules.any()
    assert picks[None].plan <= clean.plan + 2  # a solved start wins only when it is shorter by the cost
    assert not blind_successes(free, clean.state, xy).any()
    assert not any(rule_agent_successes(free, clean.state, xy, agents=CHECK_AGENTS).values())
    s = clean.state
    mid = ((s.x + target.x) / 2, (s.y + target.y) / 2)
    blocked = NavRoom(room.kind, room.seed, [*room.extras, ExtraSpec("TeddyBear_99", "TeddyBear", "white", *mid, 0.0)],
                      room.clutter)
    assert not clear_corridor(blocked, s, blocked.get(target.id))


def test_the_core_feedback_policies_play_as_their_geometry_twins() -> None:
    """The generator checks the core audit's ``feedback_policies`` on the geometry (REACTIVE_RULE_AGENTS): played
    through the env, each solves exactly the tasks its geometry twin solves (classic tasks some of them solve,
    and hard ones)."""
    from eb_core.audit.blind import ReactivePolicy, _ranked_actions, feedback_policies
    from eb_core.audit.playing import play

    env = NavigationEnv(render=False)
    classic = NavigationEnv.load_tasks()
    picked = [t for t in classic if t.subset == "complex_instruction"][:12] + _sample(1)
    try:
        env.reset(picked[0], 0)
        names = list(env.action_space().actions)
        ranked = _ranked_actions({"t": env.action_space()}, random.Random(0))
        policies = [p for p in feedback_policies(ranked) if isinstance(p, ReactivePolicy)]
        assert len(policies) == len(REACTIVE_ON_FAIL) == 8
        twins = {tuple(names.index(a) for a in p.on_fail): p for p in policies}
        assert set(twins) == set(REACTIVE_ON_FAIL.values())
        wins = 0
        for task in picked:
            spec = spec_of(task)
            room = build_room(spec)
            free = room.free_space(room.extra_ids)
            start = AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw)
            geometry = rule_agent_successes(free, start, spec.target.position[:2], agents=REACTIVE_RULE_AGENTS)
            for name, on_fail in REACTIVE_ON_FAIL.items():
                pol = twins[on_fail]
                out = play(env, task, pol.policy(task), max_steps=MAX_STEPS, max_invalid_actions=None, seed=0)
                assert out.success == geometry[name], (task.id, pol.name)
                wins += out.success
        assert wins >= 1  # the comparison covers successes, not only failures
    finally:
        env.close()


def _sample(n_per_subset: int = 3):
    tasks = NavigationEnv.load_tasks(taskset="hard")
    by = defaultdict(list)
    for t in tasks:
        by[t.subset].append(t)
    return [t for s in SUBSETS for t in by[s][:: 60 // n_per_subset][:n_per_subset]]


@pytest.mark.parametrize("closed_loop", [False, True])
def test_oracle_solves_a_sample_open_and_closed_loop(closed_loop: bool) -> None:
    env = NavigationEnv(render=False)
    try:
        for task in _sample():
            env.reset(task, 0)
            plan = env.expert_plan()
            assert plan is not None and len(plan) == task.metadata["oracle_steps"], task.id
            done = False
            for _ in range(MAX_STEPS):
                a = (env.expert_plan() or [0])[0] if closed_loop else plan.pop(0)
                r = env.step(a)
                assert r.action_success, task.id
                if r.done:
                    done = r.task_success
                    break
            assert done, task.id
    finally:
        env.close()


def test_random_agent_rarely_succeeds() -> None:
    env = NavigationEnv(render=False)
    rng = np.random.default_rng(0)
    wins = 0
    tasks = _sample(6)
    for task in tasks:
        env.reset(task, 0)
        for _ in range(MAX_STEPS):
            if env.step(int(rng.integers(8))).done:
                wins += 1
                break
    env.close()
    assert wins <= 1


def test_first_views_show_target_and_a_lookalike(hard, vis) -> None:
    for t in [t for t in hard if t.id.endswith(("_000", "_031"))]:
        room = build_room(t)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        px = vis.pixels(room, s, t.target.id)
        if t.subset == "long_horizon":
            assert px == 0, t.id
        else:
            assert px >= LEVELS["hard"].min_target_pixels, t.id


def test_hard_splits_are_deterministic_and_solvable() -> None:
    a = NavigationEnv.split_tasks("val", 0, 5, taskset="hard")
    b = NavigationEnv.split_tasks("val", 0, 5, taskset="hard")
    assert [t.model_dump() for t in a] == [t.model_dump() for t in b]
    assert [t.subset for t in a] == list(SUBSETS) and all(t.metadata["scene"]["clutter"] == 20 for t in a)
    classic = NavigationEnv.split_tasks("val", 0, 1)
    assert "clutter" not in classic[0].metadata["scene"]
    env = NavigationEnv(render=False)
    for task in a:
        env.reset(task, 0)
        plan = env.expert_plan()
        assert plan is not None and len(plan) <= MAX_STEPS - 2
    env.close()


def test_language_only_prompt_speaks_of_no_camera_or_image() -> None:
    from eb_core.config import EnvConfig
    from eb_core.planner import VLMPlanner

    env = NavigationEnv(render=False)
    task = NavigationEnv.load_tasks()[0]
    obs = env.reset(task, 0)
    texts = {}
    for blind in (True, False):
        planner = VLMPlanner(PlannerConfig(language_only=blind),
                             EnvConfig(name="navigation", max_steps=20, default_n_shot=0))
        planner.reset(task, env.prompt_parts(), env.action_space(), obs)
        texts[blind] = planner.prompt_text(obs)
    env.close()
    head = lambda text: text.split("## Action list")[0] + text.split("## Guidelines")[1].split("## Your task")[0]
    assert "camera" not in head(texts[True]).lower() and "image" not in head(texts[True]).lower()
    assert "camera" in head(texts[False]).lower() and "image" in head(texts[False]).lower()
    for text in texts.values():  # both say how success is measured and that a failure drops the plan
        assert "centre of your body to the centre of the target" in text and "the rest of your plan is dropped" in text
        assert "The episode ends after 20 actions in all, failed ones included." in text  # the step budget
    conf = (Path(eb_navigation.__file__).parent / "conf" / "env" / "navigation.yaml").read_text()
    assert re.search(r"^max_steps: 20$", conf, re.M) and MAX_STEPS == 20  # the budget the prompt states


@pytest.mark.parametrize("level", ["medium", "hard"])
def test_levels_draw_scenes_with_their_knobs(level: str) -> None:
    """One room per level on the geometry (no rendering): the level's clutter, look-alikes and start rules."""
    from eb_navigation.hard import Tally, draw_scene

    lv = LEVELS[level]
    rng = np.random.default_rng(3)
    sc = None
    for k in range(40):
        sc = draw_scene("living_room", 900_000 + k, "GarbageCan", lv, rng,
                        {p: Tally(None) for p in ("plain", "visual_appearance", "long_horizon")}, None, "left")
        if sc is not None:
            break
    assert sc is not None and sc.room.clutter == lv.clutter
    assert lv.lookalikes[0] <= len(sc.lookalikes)
    assert all(colour_distance(o.colour, sc.target.colour) >= MIN_COLOUR_DISTANCE for o in sc.lookalikes)
    free = sc.room.free_space(sc.room.extra_ids)
    lh = sc.starts["long_horizon"]
    assert 0 < bearing_to(lh.state, (sc.target.x, sc.target.y)) <= 135  # "left" asked for
    assert lh.plan >= sc.starts["plain"].plan + 2 and lh.plan <= lv.lh_max_plan
    assert all(not_in_pocket(free, st.state) for st in sc.starts.values())
    assert sc.starts["plain"].plan <= lv.max_plan


def test_generate_rejects_an_unknown_difficulty(tmp_path) -> None:
    from eb_navigation.generate import generate

    with pytest.raises(ValueError, match="unknown difficulty 'extreme'; allowed: classic, medium, hard"):
        generate(difficulty="extreme", out=str(tmp_path / "x"))


def test_every_shipped_start_has_an_open_way_and_few_feedback_agents_solve_it(hard, rooms, vis) -> None:
    """Session 10: the shipped hard set is drawn with the open-way rule on (``hard_set.OPEN_WAY_SETS``). On every
    start, nothing lower than ``WAY_TOP`` stands within reach of the first metre of the forward and sideways routes
    to the target, a body 5 cm wider on each side still gets there within two actions of the expert, the target
    stands ``TARGET_WALL_GAP`` or more from the walls, and at most ``OPEN_MAX_SOLVERS`` feedback-only agents solve
    it; everything within reach of the routes shows in the view facing the target (rendered, on a sample). Session
    9's shipped set broke the open way on most starts (the low side tables and plants players walked into)."""
    from eb_navigation.baselines import plan_lengths
    from eb_navigation.hard import OPEN_MAX_SOLVERS, TARGET_WALL_GAP
    from eb_navigation.hard_set import OPEN_WAY_SETS
    assert "hard" in OPEN_WAY_SETS
    wides: dict[int, dict] = {}
    closed = []
    for t in hard:
        room = rooms(t)
        target = room.get(t.target.id)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        wide = wides.setdefault(id(room), plan_lengths(wide_space(room), (target.x, target.y)))
        if not (open_way(room, s, target) and wide_enough(wide, s, t.oracle_steps)):
            closed.append(t.id)
        hx, hy = room.size[0] / 2, room.size[1] / 2
        assert min(hx - abs(target.x), hy - abs(target.y)) >= TARGET_WALL_GAP - 1e-9, t.id
        free = room.free_space(room.extra_ids)
        solved = rule_agent_successes(free, s, (target.x, target.y), agents=CHECK_AGENTS)
        assert sum(solved.values()) <= OPEN_MAX_SOLVERS, (t.id, [k for k, v in solved.items() if v])
    assert not closed, closed
    for t in hard[::25]:
        room = rooms(t)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        assert blockers_seen(room, s, room.get(t.target.id), vis), t.id


def test_every_shipped_long_horizon_target_shows_once_the_player_turns_toward_it(hard, rooms, vis) -> None:
    """Session 11: a long_horizon start hides the target from the first image, and the player finds its direction
    by turning. Turned toward it, the target shows at least what an in-view start promises (``min_target_pixels``
    at 128 px). A calibration player lost long_horizon_041 of session 10's set, whose white teddy bear showed
    5 pixels behind a red chair from every heading of the start; 17 of that set's 60 showed fewer than 15."""
    from eb_navigation.hard import found_by_turning
    level = LEVELS["hard"]
    long = [t for t in hard if t.subset == "long_horizon"]
    assert len(long) == 60
    shown = {}
    for t in long:
        room = rooms(t)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        assert vis.pixels(room, s, t.target.id) == 0, t.id  # out of the first image
        shown[t.id] = found_by_turning(room, s, room.get(t.target.id), level, vis)
    assert all(shown.values()), sorted(k for k, v in shown.items() if not v)


def test_a_type_and_colour_drawn_more_than_ten_times_still_gets_new_instructions() -> None:
    """base and long_horizon have ten templates; the session 11 regeneration drew eleven white trash cans among
    its 60 base targets, and two got the same words. The second everyday name (``HARD_ALT_NAMES``) gives ten more,
    and the first ten are the words they were before."""
    from eb_navigation.hard_words import HARD_ALT_NAMES, hard_instruction
    from eb_navigation.instructions import display_name

    for subset in ("base", "long_horizon"):
        for type_name in HARD_TYPES:
            used: dict[str, int] = {}
            rng = np.random.default_rng(7)
            texts = [hard_instruction(subset, type_name, "white", "blue", rng, used)[0] for _ in range(20)]
            assert len(set(texts)) == 20, (subset, type_name)
            name, alt = display_name(type_name), HARD_ALT_NAMES[type_name]
            assert all(name in t and alt not in t.replace(name, "") for t in texts[:10]), texts
            assert all(alt in t and name not in t.replace(alt, "") for t in texts[10:]), texts
    from eb_navigation.hard_words import HARD_ALT_SHAPES, HARD_SHAPES

    for type_name in HARD_TYPES:  # visual_appearance: only a repeat takes the other shape words
        used = {}
        rng = np.random.default_rng(7)
        texts = [hard_instruction("visual_appearance", type_name, "white", "blue", rng, used)[0] for _ in range(11)]
        assert all(HARD_SHAPES[type_name] in t for t in texts[:10]) and HARD_ALT_SHAPES[type_name] in texts[10]
        assert len(set(texts)) == 11, texts
