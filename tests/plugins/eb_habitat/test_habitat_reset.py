"""Resets across apartments: a new scene is drawn before the old one is closed, the same scene is not rebuilt,
and every first image is the one a fresh env draws."""

from __future__ import annotations

import numpy as np

from eb_habitat.env import HabitatEnv, _scene_key
from eb_habitat.tasks import spec_of


def test_resets_across_scenes_give_the_images_of_fresh_envs_and_reuse_a_scene_they_hold() -> None:
    tasks = HabitatEnv.load_tasks()
    a = tasks[0]
    b = next(t for t in tasks if _scene_key(spec_of(t)) != _scene_key(spec_of(a)))
    same = next((t for t in tasks if t.id != a.id and _scene_key(spec_of(t)) == _scene_key(spec_of(a))), None)
    env = HabitatEnv(resolution=96)
    try:
        first_a = env.reset(a, 0).images["first_person"].copy()
        renderer_a = env._renderer  # noqa: SLF001 - the test looks inside on purpose
        first_b = env.reset(b, 0).images["first_person"].copy()
        assert env._renderer is not renderer_a  # noqa: SLF001 - another scene, another renderer
        again_a = env.reset(a, 0).images["first_person"].copy()
        held = env._renderer  # noqa: SLF001
        env.reset(same or a, 0)
        assert env._renderer is held  # noqa: SLF001 - the scene it holds is reused, not rebuilt
    finally:
        env.close()
    assert not np.array_equal(first_a, first_b)
    assert np.array_equal(again_a, first_a)
    fresh = HabitatEnv(resolution=96)
    try:
        assert np.array_equal(fresh.reset(b, 0).images["first_person"], first_b)
    finally:
        fresh.close()
