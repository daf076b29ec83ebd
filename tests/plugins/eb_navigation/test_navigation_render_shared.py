"""Navigation envs of one process share one GL pool (context, framebuffers, scene buffer): images stay
byte-identical."""

from __future__ import annotations

import contextlib
import functools

import pytest

from eb_navigation import scene as nav_scene
from eb_navigation.env import NavigationEnv
from eb_scenekit.checks import check_pooled_matches_private
from eb_scenekit.render import SceneRenderer


def test_shared_pool_gives_identical_images_interleaved(monkeypatch: pytest.MonkeyPatch) -> None:
    tasks = NavigationEnv.load_tasks()
    a = tasks[0]
    b = next(t for t in tasks if t.metadata["scene"] != a.metadata["scene"])

    @contextlib.contextmanager
    def private():
        with monkeypatch.context() as m:
            m.setattr(nav_scene, "SceneRenderer", functools.partial(SceneRenderer, pooled=False))
            yield

    check_pooled_matches_private(lambda: NavigationEnv(resolution=96, multi_view=True), private, a, b)
