"""Moves, turns, tilts, collisions and the BFS oracle on hand-made rooms (no rendering)."""

from __future__ import annotations

import pytest

from eb_navigation.geometry import ACTION_NAMES, AgentState, FreeSpace, bearing_to, distance_to
from eb_navigation.layout import Layout, Placed

FLOOR = ("planks", (0.6, 0.4, 0.3), (0.5, 0.3, 0.2))


def _room(*objects: Placed, w: float = 4.0, d: float = 4.0) -> Layout:
    return Layout("living_room", 0, w, d, (0.9, 0.9, 0.9), FLOOR, tuple(objects))


def test_eight_actions_with_our_names() -> None:
    assert len(ACTION_NAMES) == 8
    assert ACTION_NAMES[0] == "Move forward by 0.25 meters"
    assert "right" in ACTION_NAMES[4] and "left" in ACTION_NAMES[5]
    assert "up" in ACTION_NAMES[6] and "down" in ACTION_NAMES[7]


@pytest.mark.parametrize(
    ("heading", "action", "delta"),
    [(0, 0, (1, 0)), (0, 1, (-1, 0)), (0, 2, (0, -1)), (0, 3, (0, 1)), (1, 0, (0, 1)), (1, 2, (1, 0)),
     (2, 0, (-1, 0)), (3, 3, (1, 0))],
)
def test_moves_are_relative_to_heading(heading: int, action: int, delta: tuple[int, int]) -> None:
    free = FreeSpace(_room())
    s = AgentState(8, 8, heading)
    new, ok, _ = free.apply(s, action)
    assert ok and (new.i - s.i, new.j - s.j) == delta and new.heading == heading


def test_turns_and_tilt_limits() -> None:
    free = FreeSpace(_room())
    s = AgentState(8, 8, 0)
    assert free.apply(s, 4)[0].heading == 3  # right = clockwise
    assert free.apply(s, 5)[0].heading == 1
    up, ok, _ = free.apply(s, 6)
    assert ok and up.tilt == 30
    _, ok, reason = free.apply(up, 6)
    assert not ok and reason == "tilt_max"
    down = s
    for _ in range(2):
        down, ok, _ = free.apply(down, 7)
        assert ok
    assert down.tilt == -60
    _, ok, reason = free.apply(down, 7)
    assert not ok and reason == "tilt_min"


def test_walls_and_furniture_block() -> None:
    sofa = Placed("sofa_1", "sofa", "red", 2.0, 3.0, 0.0, 2)  # footprint x 1..3, y 2.55..3.45
    free = FreeSpace(_room(sofa))
    s = AgentState(1, 8, 2)  # x = 0.25, facing -x toward the wall
    _, ok, reason = free.apply(s, 0)
    assert not ok and reason == "blocked"
    below = AgentState(8, 8, 1)  # (2.0, 2.0) facing +y toward the sofa
    assert not free.is_free(8, 10)
    steps = 0
    while free.apply(below, 0)[1]:
        below = free.apply(below, 0)[0]
        steps += 1
    assert steps == 1 and below.y == 2.25  # a second step would leave 0.05 m < the agent's radius


def test_start_pose_must_be_on_grid() -> None:
    assert AgentState.from_pose(1.25, 0.5, 270).heading == 3
    with pytest.raises(ValueError, match="grid"):
        AgentState.from_pose(1.3, 0.5, 0)
    with pytest.raises(ValueError, match="multiple of 90"):
        AgentState.from_pose(1.25, 0.5, 45)


def test_bearing_and_distance() -> None:
    s = AgentState(4, 4, 0)  # (1, 1) facing +x
    assert bearing_to(s, (2.0, 1.0)) == pytest.approx(0.0)
    assert bearing_to(s, (1.0, 2.0)) == pytest.approx(90.0)  # left is positive
    assert bearing_to(s, (1.0, 0.0)) == pytest.approx(-90.0)
    assert distance_to(s, (4.0, 5.0)) == pytest.approx(5.0)


def test_oracle_goes_around_an_obstacle() -> None:
    wall_of_shelves = Placed("bookshelf_1", "bookshelf", "brown", 2.0, 2.0, 0.0, 1)  # 0.34 x 0.9 block
    free = FreeSpace(_room(wall_of_shelves, w=5.0, d=4.0))
    s = AgentState(2, 8, 0)  # (0.5, 2.0) facing +x, shelf straight ahead
    target = (4.0, 2.0)
    plan = free.shortest_plan(s, target)
    assert plan is not None and plan
    for a in plan:
        s, ok, _ = free.apply(s, a)
        assert ok, "the oracle never bumps into things"
    assert distance_to(s, target) <= 1.0


def test_oracle_none_when_unreachable_and_empty_when_there() -> None:
    free = FreeSpace(_room())
    assert free.shortest_plan(AgentState(8, 8, 0), (2.2, 2.0)) == []
    assert free.shortest_plan(AgentState(8, 8, 0), (40.0, 40.0)) is None
