"""Rendering with the scene kit (real MuJoCo, a few tasks only: each reset compiles a room)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from eb_core.testing import EnvConformanceSuite

from eb_alfred.env import AlfredEnv


class TestAlfredConformanceRendered(EnvConformanceSuite):
    env_class = "eb_alfred.env:AlfredEnv"
    env_params = {"render": True, "resolution": 128}
    sample_size = 1


@pytest.fixture(scope="module")
def env():
    e = AlfredEnv(render=True, resolution=160)
    yield e
    e.close()


def _task(tid: str):
    return next(t for t in AlfredEnv.load_tasks() if t.id == tid)


def test_views_follow_the_state(env) -> None:
    """Finding, opening, holding: each visible change gives a different first-person image."""
    from eb_alfred.world import World

    def opens(t) -> bool:  # a base task whose expert plan opens something (a door or drawer swings)
        if t.subset != "base":
            return False
        env_sym = AlfredEnv(render=False)
        env_sym.reset(t, 0)
        acts = env_sym.action_space().actions
        return any(acts[a].startswith("open the") for a in env_sym.expert_plan() or [])

    task = next(t for t in AlfredEnv.load_tasks() if opens(t))
    obs = env.reset(task, 0)
    held: set[str] = set()
    assert obs.primary == "first_person" and obs.images["first_person"].shape == (160, 160, 3)
    frames = [obs.images["first_person"]]
    names = env.action_space().actions
    boxes_seen = set()
    for a in env.expert_plan():
        r = env.step(a)
        frames.append(r.observation.images["first_person"])
        boxes_seen |= {o.name for o in r.observation.objects}
        if env.world.held is not None:
            held.add(env.world.held)
        if names[a].startswith("open the"):
            # the door swings open: the view changes although the agent did not move
            assert not np.array_equal(frames[-1], frames[-2])
    assert r.task_success
    assert held and held <= boxes_seen  # everything the agent carried was seen with a box
    assert World.from_scene(task.metadata["scene"]).objects.keys() >= held
    # the held apple is drawn in the lower right of the view
    assert env.world.held is None


def test_held_object_is_drawn(env) -> None:
    task = _task("base_00")
    env.reset(task, 0)
    names = env.action_space().actions
    plan = env.expert_plan()
    before = None
    for a in plan:
        r = env.step(a)
        if names[a].startswith("find"):
            before = r.observation.images["first_person"]
        if names[a].startswith("pick up"):
            after = r.observation.images["first_person"]
            lower_right = (slice(80, 160), slice(80, 160))
            assert np.abs(after[lower_right].astype(int) - before[lower_right].astype(int)).sum() > 0
            held = [o for o in r.observation.objects if o.name == env.world.held]
            assert held and held[0].box[0] >= 40  # right half-ish of the image
            break


def test_symbolic_mode_never_imports_mujoco() -> None:
    code = (
        "import sys\n"
        "from eb_alfred.env import AlfredEnv\n"
        "env = AlfredEnv(render=False)\n"
        "t = AlfredEnv.load_tasks()[0]\n"
        "env.reset(t, 0)\n"
        "for a in env.expert_plan(): env.step(a)\n"
        "assert 'mujoco' not in sys.modules, 'mujoco was imported'\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "ok" in out.stdout, out.stderr


def test_every_type_is_drawn_by_a_kit_type_and_the_catalogue_is_left_untouched(env) -> None:
    from eb_scenekit import CATALOGUE

    from eb_alfred.catalog import TYPES
    from eb_alfred.render import _PARTS_OF, KIT

    assert set(TYPES) == set(KIT) | set(_PARTS_OF)
    assert {kit for kit, _ in KIT.values()} <= set(CATALOGUE)
    before = dict(CATALOGUE)
    env.reset(_task("base_01"), 0)
    assert CATALOGUE == before


def test_bench_step_times_keys() -> None:
    from eb_alfred.bench import step_times

    out = step_times(3, resolution=64)
    assert {"step_s", "raw_render_s", "ratio", "reset_s", "symbolic_step_s"} <= set(out) and out["n"] == 3
    assert out["step_s"] > 0 and out["raw_render_s"] > 0 and out["reset_s"] > 0


def _two_of(type_name: str, first: dict, second: dict) -> dict:
    """A tiny kitchen scene with two instances of ``type_name`` on one counter."""
    return {"room": "kitchen", "objects": [
        {"name": "CounterTop", "type": "CounterTop", "slot": 0},
        {"name": "Cabinet", "type": "Cabinet", "slot": 1},
        {"name": type_name, "type": type_name, "parent": "CounterTop", **first},
        {"name": f"{type_name}_2", "type": type_name, "parent": "CounterTop", **second}]}


@pytest.mark.parametrize("type_name,a,b,axis", [("Mug", "tall", "short", 2), ("Vase", "tall", "short", 2),
                                                 ("Book", "thick", "thin", 2), ("Bowl", "deep", "shallow", 2),
                                                 ("Statue", "tall", "short", 2), ("Plate", "round", "square", None)])
def test_every_shape_word_changes_the_drawn_mesh(type_name: str, a: str, b: str, axis) -> None:
    from eb_alfred.catalog import TYPES
    from eb_alfred.render import AlfredRenderer
    from eb_alfred.world import World

    assert {a, b} == set(TYPES[type_name].shapes)
    r = AlfredRenderer(96)
    try:
        w = World.from_scene(_two_of(type_name, {"shape": a}, {"shape": b}))
        r.load(w)
        r.render(w)
        la, lb = r.looks(type_name), r.looks(f"{type_name}_2")
    finally:
        r.close()
    assert la["rgb"] == lb["rgb"]  # same colour: only the shape differs
    if axis is None:  # round vs square: different geoms, not just a size change
        assert la["geom_kinds"] != lb["geom_kinds"]
    else:
        assert la["size"][axis] > 1.4 * lb["size"][axis]


def test_dirt_darkens_but_keeps_the_named_colour() -> None:
    import colorsys

    from eb_alfred.catalog import COLORS
    from eb_alfred.render import AlfredRenderer
    from eb_alfred.world import World

    r = AlfredRenderer(96)
    try:
        w = World.from_scene(_two_of("Mug", {"color": "red", "is_dirty": True}, {"color": "red"}))
        r.load(w)
        r.render(w)
        dirty, clean = r.looks("Mug")["rgb"], r.looks("Mug_2")["rgb"]
    finally:
        r.close()
    assert sum(dirty) < 0.85 * sum(clean)  # dirty is visibly darker
    hue = lambda c: colorsys.rgb_to_hsv(*c)[0]  # noqa: E731
    assert abs(hue(dirty) - hue(clean)) < 0.02 and abs(hue(clean) - hue(COLORS["red"])) < 0.02
