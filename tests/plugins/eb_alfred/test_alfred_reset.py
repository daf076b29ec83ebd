"""Resets keep the process's GL context (no new renderer per task) and still give each task its own first image."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from eb_alfred.env import AlfredEnv


@pytest.fixture()
def renderers_made(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Counts ``mujoco.Renderer`` objects (each one is a new GL context) made while the test runs."""
    made: list[int] = []
    real = mujoco.Renderer

    def counting(*args, **kwargs):  # type: ignore[no-untyped-def]
        made.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(mujoco, "Renderer", counting)
    return made


def _three_scenes() -> list:
    tasks = AlfredEnv.load_tasks()
    picked, seen = [], []
    for t in tasks:
        if t.metadata["scene"] not in seen:
            seen.append(t.metadata["scene"])
            picked.append(t)
        if len(picked) == 3:
            return picked
    raise AssertionError("fewer than three ALFRED scenes")


def test_resets_reuse_one_gl_context_and_give_the_images_of_fresh_envs(renderers_made: list[int]) -> None:
    tasks = _three_scenes()
    env = AlfredEnv(render=True, resolution=96)
    try:
        firsts = [env.reset(t, 0).images["first_person"].copy() for t in tasks]
        again = env.reset(tasks[0], 0).images["first_person"]
    finally:
        env.close()
    assert len(renderers_made) == 1  # four resets over three scenes, one GL context
    assert not np.array_equal(firsts[0], firsts[1])
    assert np.array_equal(again, firsts[0])
    fresh = AlfredEnv(render=True, resolution=96)
    try:
        assert np.array_equal(fresh.reset(tasks[2], 0).images["first_person"], firsts[2])
    finally:
        fresh.close()


def test_a_renderer_told_to_keep_its_own_gl_keeps_it_across_resets(renderers_made: list[int]) -> None:
    tasks = _three_scenes()
    env = AlfredEnv(render=True, resolution=96)
    try:
        env.reset(tasks[0], 0)
        env._renderer.shared_gl = False  # noqa: SLF001 - how test_render_shared asks for private renderers
        for t in tasks[1:]:
            env.reset(t, 0)
            assert env._renderer.shared_gl is False  # noqa: SLF001
    finally:
        env.close()
    assert len(renderers_made) >= 3  # the pooled one, then private renderers (per image size) per later reset
