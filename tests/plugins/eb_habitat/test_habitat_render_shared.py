"""Habitat envs of one process share one GL pool (context, framebuffers, scene buffer): images stay byte-identical."""

from __future__ import annotations

import contextlib
import functools

import pytest

from eb_habitat import render as habitat_render
from eb_habitat.env import HabitatEnv
from eb_scenekit.checks import check_pooled_matches_private
from eb_scenekit.render import SceneRenderer


def test_shared_pool_gives_identical_images_interleaved(monkeypatch: pytest.MonkeyPatch) -> None:
    tasks = HabitatEnv.load_tasks()
    a = tasks[0]
    b = next(t for t in tasks if t.metadata != a.metadata and t.subset != a.subset)

    @contextlib.contextmanager
    def private():
        with monkeypatch.context() as m:
            m.setattr(habitat_render, "SceneRenderer", functools.partial(SceneRenderer, pooled=False))
            yield

    check_pooled_matches_private(lambda: HabitatEnv(resolution=96, multi_view=True), private, a, b)
