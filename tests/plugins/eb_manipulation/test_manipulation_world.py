"""Physics rules of the world: the two-finger grasp rule, falling and settling, sorter holes, wiping."""

from __future__ import annotations

import numpy as np
import pytest

from eb_manipulation.actions import angle_to_bin, bin_to_pos, pos_to_bin
from eb_manipulation.scene import TABLE_TOP
from eb_manipulation.spec import GoalSpec, ObjectSpec, SceneSpec
from eb_manipulation.world import World, wipe_coverage


def _act(x, y, z, yaw=0.0, open_=1):
    return (pos_to_bin(x, "x"), pos_to_bin(y, "y"), pos_to_bin(z, "z"), 120, 60, angle_to_bin(yaw), open_)


@pytest.fixture()
def world() -> World:
    scene = SceneSpec(
        family="pick", variant="pick_cube_shape", scene_seed=0,
        objects=(ObjectSpec(id="cube", kind="shape", shape="cube", colour="red", x=0.15, y=0.0),
                 ObjectSpec(id="star", kind="shape", shape="star", colour="blue", x=0.15, y=0.2, yaw=20),
                 ObjectSpec(id="box", kind="container", colour="white", x=0.05, y=-0.22)),
        goal=GoalSpec(family="pick", target="cube", container="box"))
    return World(scene, render_meshes=False)


def test_objects_rest_on_the_table_after_reset(world: World) -> None:
    z = world.body_pos("cube")[2]
    assert abs(z - (TABLE_TOP + 0.0225)) < 0.002


def test_grasp_needs_both_fingers(world: World) -> None:
    # fingers closing along x just beside the cube never touch it: nothing is held, the cube stays put
    before = world.body_pos("cube")
    assert world.execute(_act(0.15, 0.065, 0.775, yaw=90)).ok
    out = world.execute(_act(0.15, 0.065, 0.775, yaw=90, open_=0))
    assert out.ok and out.failure == "grasp" and world.held is None and "not holding anything" in out.feedback
    assert np.linalg.norm(world.body_pos("cube") - before) < 0.002
    # open again, go to the cube's centre, close: both fingers touch it and it is held
    world.execute(_act(0.15, 0.065, 0.85, yaw=90))
    world.execute(_act(0.15, 0.0, 0.85))
    world.execute(_act(0.15, 0.0, 0.775))
    out = world.execute(_act(0.15, 0.0, 0.775, open_=0))
    assert world.held == "cube" and out.refs == {"obj": "cube"}


def test_held_object_follows_and_falls_when_released(world: World) -> None:
    for a in (_act(0.15, 0.0, 0.85), _act(0.15, 0.0, 0.775), _act(0.15, 0.0, 0.775, open_=0),
              _act(0.15, 0.0, 0.95, open_=0)):
        assert world.execute(a).ok
    assert world.body_pos("cube")[2] > TABLE_TOP + 0.15
    world.execute(_act(0.25, 0.0, 0.95, open_=1))  # release 20 cm above the table
    p = world.body_pos("cube")
    assert world.held is None
    assert abs(p[2] - (TABLE_TOP + 0.0225)) < 0.004  # fell and came to rest on the table
    assert abs(p[0] - bin_to_pos(pos_to_bin(0.25, "x"), "x")) < 0.03


def test_dropping_into_the_container_solves_pick(world: World) -> None:
    for a in (_act(0.15, 0.0, 0.85), _act(0.15, 0.0, 0.775), _act(0.15, 0.0, 0.775, open_=0),
              _act(0.15, 0.0, 0.9, open_=0), _act(0.05, -0.22, 0.86, open_=0)):
        assert world.execute(a).ok
    assert world.evaluate() == (False, 0.0)
    world.execute(_act(0.05, -0.22, 0.86, open_=1))
    assert world.evaluate() == (True, 1.0)


def test_path_through_an_object_is_refused(world: World) -> None:
    # pick the cube up, then try to put it down inside the star
    for a in (_act(0.15, 0.0, 0.85), _act(0.15, 0.0, 0.775), _act(0.15, 0.0, 0.775, open_=0)):
        world.execute(a)
    before = world.arm.q()
    out = world.execute(_act(0.15, 0.2, 0.775, open_=0))
    assert not out.ok and out.refs.get("obj") == "star"
    assert np.allclose(world.arm.q(), before)


def test_wipe_coverage_needs_the_named_direction() -> None:
    area = ObjectSpec(id="a", kind="area", colour="red", x=0.1, y=0.0, size=(0.12, 0.22))
    forward = [[(0.1, y) for y in np.linspace(-0.12, 0.12, 25)]]
    backward = [[(0.1, y) for y in np.linspace(0.12, -0.12, 25)]]
    half = [[(0.1, y) for y in np.linspace(-0.12, 0.0, 13)]]
    off_area = [[(0.3, y) for y in np.linspace(-0.12, 0.12, 25)]]
    assert wipe_coverage(area, "left_to_right", forward) == 1.0
    assert wipe_coverage(area, "left_to_right", backward) < 0.2
    assert wipe_coverage(area, "right_to_left", backward) == 1.0
    assert 0.3 < wipe_coverage(area, "left_to_right", half) < 1.0
    assert wipe_coverage(area, "left_to_right", off_area) == 0.0
