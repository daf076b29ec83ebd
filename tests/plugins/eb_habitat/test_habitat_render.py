"""Rendering: the MuJoCo apartment draws the symbolic state (real EGL/OSMesa rendering, a few tasks only)."""

from __future__ import annotations

import numpy as np
import pytest

from eb_core.testing import EnvConformanceSuite
from eb_habitat.env import HabitatEnv
from eb_habitat.plugin import SUBSETS
from eb_habitat.skills import skill_id
from eb_habitat.tasks import TaskSpec


class TestHabitatConformanceRendered(EnvConformanceSuite):
    env_class = "eb_habitat.env:HabitatEnv"
    env_params = {"render": True, "resolution": 160}
    expect_subsets = SUBSETS
    sample_size = 2


def _spec() -> TaskSpec:
    return TaskSpec.model_validate({
        "apartment": 1, "template": "test",
        "objects": [
            {"name": "apple_1", "type": "apple", "color": "red", "at": "fridge", "slot": 0},
            {"name": "mug_1", "type": "mug", "color": "blue", "at": "sofa", "slot": 0},
            {"name": "toy_airplane_1", "type": "toy_airplane", "color": "yellow", "at": "sofa", "slot": 2},
            {"name": "pitcher_1", "type": "pitcher", "color": "blue", "at": "left_drawer", "slot": 1},
        ],
        "open": [], "goal": ["(on ?apple desk)"], "subgoals": [["(holding ?apple)"], ["(on ?apple desk)"]],
        "oracle_steps": 5,
    })


@pytest.fixture(scope="module")
def env():
    from eb_core.env import Task

    env = HabitatEnv(resolution=200, multi_view=True)
    task = Task(id="render-test", subset="base", instruction="Put the apple on the desk.",
                metadata=_spec().model_dump())
    env.reset(task, 0)
    yield env
    env.close()


def test_sofa_view_shows_its_objects_left_to_right(env) -> None:
    obs = env.step(skill_id("navigate", "sofa")).observation
    img = obs.images["first_person"]
    assert img.shape == (200, 200, 3) and img.dtype == np.uint8
    assert set(obs.images) == {"first_person", "overhead"}
    boxes = {o.name: o.box for o in obs.objects}
    assert set(boxes) == {"mug_1", "toy_airplane_1"}
    assert boxes["mug_1"] is not None and boxes["toy_airplane_1"] is not None
    assert boxes["mug_1"][2] < boxes["toy_airplane_1"][0], "slot 0 must be left of slot 2 in the image"


def test_opening_the_fridge_changes_the_view_and_reveals_the_apple(env) -> None:
    closed = env.step(skill_id("navigate", "fridge")).observation
    assert closed.objects == []
    opened = env.step(skill_id("open", "fridge")).observation
    assert [o.name for o in opened.objects] == ["apple_1"] and opened.objects[0].box is not None
    assert opened.objects[0].is_target
    diff = np.abs(opened.images["first_person"].astype(int) - closed.images["first_person"].astype(int))
    assert diff.mean() > 5, "an open fridge must look different from a closed one"
    env.step(skill_id("close", "fridge"))


def test_drawer_contents_show_only_when_open(env) -> None:
    env.step(skill_id("navigate", "left_drawer"))
    shut = env._renderer.boxes()
    out = env.step(skill_id("open", "left_drawer"))
    assert "pitcher_1" not in shut and "pitcher_1" in env._renderer.boxes()
    assert out.observation.objects[0].name == "pitcher_1"


def test_held_object_is_drawn_in_front_of_the_camera(env) -> None:
    env.step(skill_id("navigate", "sofa"))
    r = env.step(skill_id("pick", "toy_airplane"))
    assert r.action_success
    assert "toy_airplane_1" in env._renderer.boxes()
    env.step(skill_id("place", "sofa"))


def test_each_apartment_builds_and_renders_every_receptacle() -> None:
    """Every receptacle view of every apartment shows something (no camera inside a wall)."""
    from eb_habitat.catalog import RECEPTACLES
    from eb_habitat.render import ApartmentRenderer

    renderer = ApartmentRenderer(96)
    try:
        for apartment in range(3):
            spec = _spec().model_copy(update={"apartment": apartment})
            renderer.load(spec)
            world = spec.world()
            for r in [None, *RECEPTACLES]:
                world.agent_at = None if r is None else r.key
                img = renderer.render(world)["first_person"]
                assert img.std() > 10, (apartment, r)
    finally:
        renderer.close()


def test_bench_step_times_keys() -> None:
    from eb_habitat.bench import step_times

    out = step_times(3, resolution=64)
    assert {"step_s", "raw_render_s", "ratio", "reset_s"} <= set(out) and out["n"] == 3
    assert out["step_s"] > 0 and out["raw_render_s"] > 0 and out["reset_s"] > 0


def test_layouts_build_the_kitchen_rows_and_chairs_the_tasks_describe() -> None:
    """What spatial.layout instructions rely on holds in the built apartments: the kitchen row order differs in
    every apartment (left to right = increasing x for a row along the north wall), the counters flank the sink,
    and the chair named in KITCHEN_SIDE_CHAIR is the one nearer to the kitchen row."""
    import math

    from eb_habitat.catalog import FRIDGE_END, KITCHEN_ROWS, KITCHEN_SIDE_CHAIR
    from eb_habitat.render import LAYOUTS

    assert len(set(KITCHEN_ROWS)) == len(KITCHEN_ROWS) == len(LAYOUTS)
    for apt, layout in enumerate(LAYOUTS):
        f = layout.furniture
        row = sorted(KITCHEN_ROWS[apt], key=lambda k: f[k].pos[0])
        assert tuple(row) == KITCHEN_ROWS[apt], apt
        assert f["left_counter"].pos[0] < f["sink"].pos[0] < f["right_counter"].pos[0]
        assert (f["fridge"].pos[0] < f["sink"].pos[0]) == (FRIDGE_END[apt] == "left")
        kx = sum(f[k].pos[0] for k in KITCHEN_ROWS[apt]) / 5
        ky = f["sink"].pos[1]
        dist = {c: math.hypot(f[c].pos[0] - kx, f[c].pos[1] - ky) for c in ("left_chair", "right_chair")}
        assert min(dist, key=dist.get) == KITCHEN_SIDE_CHAIR[apt], (apt, dist)
        half = layout.size[0] / 2
        assert all(abs(f[k].pos[0]) + 0.4 < half for k in KITCHEN_ROWS[apt]), apt  # inside the room
