"""Blind policies, rule agents and all-starts plan lengths on hand-made rooms (what the generator relies on)."""

from __future__ import annotations

import numpy as np
from eb_scenekit.rooms import RoomLayout
from eb_scenekit.scene import SceneBuilder

from eb_navigation.baselines import (
    BLIND_POLICIES,
    RULE_AGENTS,
    blind_policy,
    blind_successes,
    plan_lengths,
    policy_name,
    rule_agent_successes,
)
from eb_navigation.geometry import AgentState, FreeSpace


def _room(*objects: tuple[str, float, float, float], w: float = 5.0, d: float = 4.0) -> FreeSpace:
    b = SceneBuilder()
    b.add_room("living_room", (w, d), seed=0)
    for type_name, x, y, yaw in objects:
        b.add_object(type_name, None, (x, y), yaw=yaw)
    return FreeSpace.from_layout(RoomLayout("living_room", 0, b, (w, d)))


def _index(prefix: tuple[int, ...], cycle: tuple[int, ...]) -> int:
    return BLIND_POLICIES.index(blind_policy(prefix, cycle))


def test_policy_set_covers_the_audits_kinds() -> None:
    assert len(BLIND_POLICIES) == len(set(BLIND_POLICIES)) == 10_948
    assert blind_policy((), (0,)) in BLIND_POLICIES and blind_policy((5,), (0,)) in BLIND_POLICIES
    assert blind_policy((), (0, 0)) not in BLIND_POLICIES  # a repeat of (0,)
    assert blind_policy((), (0, 0, 3, 2)) in BLIND_POLICIES
    assert policy_name(blind_policy((5,), (0, 0, 3))) == "turnL, then (fwd fwd left)*"
    assert blind_policy((4,), (0, 3)).actions(6) == [4, 0, 3, 0, 3, 0]


def test_open_floor_straight_ahead_is_solved_blind_and_a_wall_of_furniture_stops_it() -> None:
    s, target = AgentState(-8, 0, 0), (1.25, 0.0)  # 3.25 m straight ahead
    open_floor = blind_successes(_room(), s, target)
    assert open_floor[_index((), (0,))] and not open_floor[_index((), (1,))]
    assert open_floor[_index((4, 4), (1,))]  # turn around, walk backward
    blocked = blind_successes(_room(("Sofa", -0.5, 0.0, 0.0)), s, target)  # a sofa across the way
    assert not blocked[_index((), (0,))]
    assert blocked.sum() < open_floor.sum()


def test_blind_results_match_stepping_the_free_space() -> None:
    free = _room(("Bookshelf", 0.0, 0.0, 0.0))
    s, target = AgentState(-6, -2, 0), (1.5, 0.5)
    got = blind_successes(free, s, target)
    goal = free.goal_cells(target)
    rng = np.random.default_rng(0)
    for k in rng.choice(len(BLIND_POLICIES), 300, replace=False):
        state, solved = s, False
        for a in BLIND_POLICIES[k].actions():
            state, _, _ = free.apply(state, a)
            solved |= bool(goal[state.i - free.i0, state.j - free.j0])
        assert solved == got[k], policy_name(BLIND_POLICIES[k])


def test_plan_lengths_equal_the_oracles_bfs() -> None:
    free = _room(("Bookshelf", 0.0, 0.0, 0.0), ("ArmChair", 1.5, 1.2, 180.0))
    target = (1.75, -1.0)
    lengths = plan_lengths(free, target)
    rng = np.random.default_rng(1)
    keys = list(lengths)
    for k in rng.choice(len(keys), 60, replace=False):
        i, j, h = keys[k]
        assert lengths[keys[k]] == len(free.shortest_plan(AgentState(i, j, h), target))


def test_rule_agents_react_to_bumps() -> None:
    free = _room(("Bookshelf", -0.5, 0.0, 0.0))  # a narrow block across the way
    s, target = AgentState(-8, 0, 0), (1.25, 0.0)
    assert free.shortest_plan(s, target)[:1] != [0] or not blind_successes(free, s, target)[_index((), (0,))]
    got = rule_agent_successes(free, s, target)
    assert set(got) == set(RULE_AGENTS)
    assert not got["forward, turn right on a bump"]  # turns away from the target at the sofa
    assert got["forward, step left on a bump"] or got["forward, step right on a bump"]  # side-steps past it
