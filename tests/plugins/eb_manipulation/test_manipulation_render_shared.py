"""Manipulation envs of one process share one GL pool (context, framebuffers, scene buffer): front and wrist
images and detection boxes stay byte-identical."""

from __future__ import annotations

import contextlib
import functools

import pytest

from eb_manipulation import render as manip_render
from eb_manipulation.env import ManipulationEnv
from eb_scenekit.pool import check_pooled_matches_private


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
