"""The pooled-renderer check every world's ``tests/plugins/<world>/test_<world>_render_shared.py`` runs: envs
drawing through the pool (:mod:`eb_scenekit.pool`) give the same images and boxes, byte for byte, as envs with
private renderers, even when their frames interleave. Its own module so that the pool and the scene renderer
(:mod:`eb_scenekit.render`, which the check switches to draw every frame) do not import each other."""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from eb_scenekit.pool import CACHE_ENV, pool_stats

__all__ = ["check_pooled_matches_private", "episode_frames"]


def _snap(obs: Any) -> tuple[dict[str, bytes], list]:
    return ({k: np.ascontiguousarray(v).tobytes() for k, v in sorted(obs.images.items())},
            [(o.name, o.box) for o in obs.objects])


def episode_frames(env: Any, task: Any, steps: int) -> list[tuple[dict[str, bytes], list]]:
    """Reset and the first ``steps`` expert actions, played alone: (images, object boxes) after each."""
    out = [_snap(env.reset(task, 0))]
    for a in (env.expert_plan() or [])[:steps]:
        out.append(_snap(env.step(a).observation))
    return out


def check_pooled_matches_private(make_env: Any, private: Any, task_a: Any, task_b: Any, steps: int = 3) -> None:
    """``make_env()`` builds a pooled env; inside ``with private():`` it builds envs with private renderers.
    Scene renderers' frame reuse is off meanwhile, so that every frame is drawn (and switches the pool)."""
    from eb_scenekit import render

    saved, render.REUSE_FRAMES = render.REUSE_FRAMES, False
    try:
        _check_pooled_matches_private(make_env, private, task_a, task_b, steps)
    finally:
        render.REUSE_FRAMES = saved


def _check_pooled_matches_private(make_env: Any, private: Any, task_a: Any, task_b: Any, steps: int) -> None:
    with private():
        ref = []
        for task in (task_a, task_b):
            env = make_env()
            try:
                ref.append(episode_frames(env, task, steps))
            finally:
                env.close()
        assert pool_stats()["users"] == 0, "a private renderer registered with the pool"
    for cache in ("0", None):  # every draw rebuilds the shared context; then the second env's own context
        got = _interleaved(make_env, task_a, task_b, steps, cache)
        for g, want in zip(got, ref):
            assert len(g) == len(want) > 1
            for (imgs, boxes), (imgs0, boxes0) in zip(g, want):
                assert imgs.keys() == imgs0.keys() and all(imgs[k] == imgs0[k] for k in imgs)
                assert boxes == boxes0
    assert got[0][0][0] != got[1][0][0]  # the two episodes look different: not blank frames compared


def _interleaved(make_env: Any, task_a: Any, task_b: Any, steps: int, cache: str | None) -> list[list[Any]]:
    """Two pooled envs stepped in turn (so the pooled renderer switches model on every frame), with
    ``EB_SCENEKIT_GL_CACHE_MB=cache`` (None: the default budget)."""
    saved = os.environ.pop(CACHE_ENV, None)
    if cache is not None:
        os.environ[CACHE_ENV] = cache
    try:
        ea, eb = make_env(), make_env()
        before = pool_stats()
        try:
            got = [[_snap(ea.reset(task_a, 0))], [_snap(eb.reset(task_b, 0))]]
            plans = [(ea.expert_plan() or [])[:steps], (eb.expert_plan() or [])[:steps]]
            for i in range(steps):
                for k, env in enumerate((ea, eb)):
                    if i < len(plans[k]):
                        got[k].append(_snap(env.step(plans[k][i]).observation))
            stats = pool_stats()
            assert stats["live"] == 1 and stats["users"] >= 2  # one GL context for both envs, every size and view
            assert stats["switches"] - before["switches"] >= 2 * min(len(p) for p in plans)
            if cache == "0":  # every switch rebuilds the shared context, unless both scenes have the same assets
                assert stats["cached_live"] == 0
                assert (stats["rebinds"] - before["rebinds"] >= 2 * min(len(p) for p in plans)
                        or stats["shared"] > before["shared"])
            else:  # the second env draws with a context of its own (or the first's, same assets): no rebuilds
                assert stats["rebinds"] == before["rebinds"]
                assert stats["cached_live"] >= 1 or stats["shared"] > before["shared"]
        finally:
            ea.close()
            eb.close()
        assert pool_stats()["live"] == 0  # the last close frees the pool
    finally:
        os.environ.pop(CACHE_ENV, None)
        if saved is not None:
            os.environ[CACHE_ENV] = saved
    return got
