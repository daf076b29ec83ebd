"""Manipulation envs of one process share one GL pool (context, framebuffers, scene buffer): front and wrist
images and detection boxes stay byte-identical."""

from __future__ import annotations

import contextlib
import functools

import pytest

from eb_manipulation import render as manip_render
from eb_manipulation.env import ManipulationEnv
from eb_scenekit.checks import check_pooled_matches_private


def test_shared_pool_gives_identical_images_interleaved(monkeypatch: pytest.MonkeyPatch) -> None:
    tasks = ManipulationEnv.load_tasks()
    a = tasks[0]
    b = next(t for t in tasks if t.subset != a.subset)

    monkeypatch.setattr(manip_render, "REUSE_FRAMES", False)  # every frame is drawn, so the pool's switches are tested

    @contextlib.contextmanager
    def private():
        with monkeypatch.context() as m:
            m.setattr(manip_render, "SceneRenderer", functools.partial(manip_render.SceneRenderer, pooled=False))
            yield

    check_pooled_matches_private(lambda: ManipulationEnv(resolution=128, multi_view=True), private, a, b, steps=2)


def test_every_task_draws_with_one_gl_context(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every rendered scene declares the same meshes, textures and materials, so the pooled renderer gives all
    tasks one GL context: resets after the first make none (no new context, no rebuild)."""
    from eb_scenekit import pool

    # every reset draws (a frame an earlier test of this process drew the same could otherwise be reused)
    monkeypatch.setattr(manip_render, "REUSE_FRAMES", False)

    tasks = ManipulationEnv.load_tasks()
    picked = [next(t for t in tasks if t.subset == s) for s in dict.fromkeys(t.subset for t in tasks)]
    env = ManipulationEnv(resolution=96)
    try:
        env.reset(picked[0], 0)
        first = pool.render_assets(pool.thread_renderer().model)
        before = pool.pool_stats()
        for task in picked[1:]:
            env.reset(task, 0)
            r = pool.thread_renderer()
            assert r is not None and pool.render_assets(r.model) == first, task.id
        after = pool.pool_stats()
        assert after["contexts"] == before["contexts"] and after["rebinds"] == before["rebinds"]
        assert after["cached"] == before["cached"] and after["shared"] - before["shared"] == len(picked) - 1
    finally:
        env.close()
