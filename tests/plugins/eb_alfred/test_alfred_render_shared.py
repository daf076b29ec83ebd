"""Envs of one process share one GL pool (context, framebuffers, scene buffer): images stay byte-identical."""

from __future__ import annotations

import numpy as np
import pytest

from eb_alfred import render as alfred_render
from eb_alfred.env import AlfredEnv


def _episode_frames(env: AlfredEnv, task, steps: int) -> list[tuple[np.ndarray, list]]:
    """Reset and the first ``steps`` expert actions: (image, object boxes) after each."""
    obs = env.reset(task, 0)
    out = [(obs.images["first_person"], [(o.name, o.box) for o in obs.objects])]
    for a in (env.expert_plan() or [])[:steps]:
        o = env.step(a).observation
        out.append((o.images["first_person"], [(x.name, x.box) for x in o.objects]))
    return out


def _private(task, steps: int) -> list[tuple[np.ndarray, list]]:
    env = AlfredEnv(render=True, resolution=96)
    env.reset(task, 0)
    env._renderer.shared_gl = False  # every later load builds a private SceneRenderer
    try:
        return _episode_frames(env, task, steps)
    finally:
        env.close()


@pytest.mark.parametrize("cache", ["0", "default"])
def test_shared_pool_gives_identical_images_interleaved(cache: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """With the GL context cache off every frame rebuilds the pooled context for the other scene; with it on (the
    default) the second env draws with a context of its own. Either way the pixels are a private renderer's."""
    from eb_scenekit import pool

    if cache == "default":
        monkeypatch.delenv(pool.CACHE_ENV, raising=False)
    else:
        monkeypatch.setenv(pool.CACHE_ENV, cache)
    tasks = AlfredEnv.load_tasks()
    a, b = tasks[0], next(t for t in tasks if t.metadata["scene"] != tasks[0].metadata["scene"])
    steps = 4
    want_a, want_b = _private(a, steps), _private(b, steps)

    ea, eb = AlfredEnv(render=True, resolution=96), AlfredEnv(render=True, resolution=96)
    before = alfred_render.shared_gl_stats()
    try:
        # interleave: reset both, then alternate steps, so the pooled renderer switches scene on every frame
        obs_a, obs_b = ea.reset(a, 0), eb.reset(b, 0)
        got_a = [(obs_a.images["first_person"], [(o.name, o.box) for o in obs_a.objects])]
        got_b = [(obs_b.images["first_person"], [(o.name, o.box) for o in obs_b.objects])]
        plan_a, plan_b = ea.expert_plan()[:steps], eb.expert_plan()[:steps]
        for i in range(steps):
            for env, plan, got in ((ea, plan_a, got_a), (eb, plan_b, got_b)):
                if i < len(plan):
                    o = env.step(plan[i]).observation
                    got.append((o.images["first_person"], [(x.name, x.box) for x in o.objects]))
        stats = alfred_render.shared_gl_stats()
        assert stats["users"] == 2
        if cache == "0":
            assert stats["rebinds"] - before["rebinds"] >= 2 * steps  # the pool really switched scenes
        else:  # one env on the shared context, the other on its own cached one: no rebuilds
            assert stats["rebinds"] == before["rebinds"] and pool.pool_stats()["cached_live"] == 1
        assert stats["live"] == 1  # one pooled renderer for both envs and both sizes (image, half-size boxes)
    finally:
        ea.close()
        eb.close()
    assert alfred_render.shared_gl_stats()["live"] == 0  # the last close frees the pool
    for got, want in ((got_a, want_a), (got_b, want_b)):
        assert len(got) == len(want)
        for (img, boxes), (img0, boxes0) in zip(got, want):
            assert img.shape == img0.shape and np.array_equal(img, img0)
            assert boxes == boxes0
    # the two episodes do look different (the comparison above is not between blank frames)
    assert not np.array_equal(got_a[0][0], got_b[0][0])
