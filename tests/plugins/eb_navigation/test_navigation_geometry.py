"""Moves, turns, tilts, collisions and the BFS oracle on hand-made scene kit rooms (no rendering)."""

from __future__ import annotations

import numpy as np
import pytest
from eb_scenekit.rooms import RoomLayout
from eb_scenekit.scene import SceneBuilder

from eb_navigation.geometry import ACTION_NAMES, STEP, AgentState, FreeSpace, bearing_to, distance_to


def _room(*objects: tuple[str, float, float, float], w: float = 4.0, d: float = 4.0) -> FreeSpace:
    """A bare kit room of w x d metres (centred on the origin) with ``(type, x, y, yaw)`` objects."""
    b = SceneBuilder()
    b.add_room("living_room", (w, d), seed=0)
    for type_name, x, y, yaw in objects:
        b.add_object(type_name, None, (x, y), yaw=yaw)
    return FreeSpace.from_layout(RoomLayout("living_room", 0, b, (w, d)))


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
    free = _room()
    s = AgentState(0, 0, heading)
    new, ok, _ = free.apply(s, action)
    assert ok and (new.i - s.i, new.j - s.j) == delta and new.heading == heading


def test_turns_and_tilt_limits() -> None:
    free = _room()
    s = AgentState(0, 0, 0)
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
    # a sofa (footprint 0.9 x 2.0 m at yaw 90: x -1..1, y 0.55..1.45) in a 4 x 4 m room
    free = _room(("Sofa", 0.0, 1.0, 90.0))
    s = AgentState(-7, 0, 2)  # x = -1.75, facing -x toward the west wall (agent radius 0.2)
    _, ok, reason = free.apply(s, 0)
    assert not ok and reason == "blocked"
    below = AgentState(0, -2, 1)  # (0, -0.5) facing +y toward the sofa
    assert not free.is_free(0, 2)
    steps = 0
    while free.apply(below, 0)[1]:
        below = free.apply(below, 0)[0]
        steps += 1
    assert steps == 3 and below.y == 0.25  # one more step would leave 0.05 m < the agent's radius


def test_free_space_is_the_kits_grid() -> None:
    free = _room(("Sofa", 0.0, 1.0, 90.0))
    cells = free.free_cells()
    assert (0, 0) in cells and (0, 4) not in cells
    xs = [i * STEP for i, _ in cells]
    assert min(xs) >= -2.0 + 0.2 - 1e-9 and max(xs) <= 2.0 - 0.2 + 1e-9
    # every clear move is clear at every grid cell under it
    grid = free.grid
    for i, j in cells:
        if free.can_move(i, j, 1, 0):
            for t in np.linspace(0, STEP, 6):
                gi = int(np.floor((i * STEP + t + 2.0) / free.resolution + 1e-9))
                assert grid[gi, int(np.floor((j * STEP + 2.0) / free.resolution + 1e-9))]


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
    free = _room(("Bookshelf", 0.0, 0.0, 0.0), w=5.0, d=4.0)  # 0.32 x 0.9 m block in the middle
    s = AgentState(-6, 0, 0)  # (-1.5, 0) facing +x, shelf straight ahead
    target = (2.0, 0.0)
    plan = free.shortest_plan(s, target)
    assert plan is not None and plan
    for a in plan:
        s, ok, _ = free.apply(s, a)
        assert ok, "the oracle never bumps into things"
    assert distance_to(s, target) <= 1.0


def test_oracle_none_when_unreachable_and_empty_when_there() -> None:
    free = _room()
    assert free.shortest_plan(AgentState(0, 0, 0), (0.2, 0.0)) == []
    assert free.shortest_plan(AgentState(0, 0, 0), (40.0, 40.0)) is None
