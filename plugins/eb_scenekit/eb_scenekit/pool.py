"""One pooled ``mujoco.Renderer`` per thread, shared by every scene drawn on that thread.

A private ``mujoco.Renderer`` holds a GL context, an ``MjrContext`` (offscreen framebuffers, uploaded meshes
and textures, fonts, a shadow map) and an ``MjvScene``: about 110 MB with Mesa's llvmpipe. A worker process
that drives many episodes in flight (``runner.concurrency``) runs all their env work on one thread, so their
scenes can take turns with one set of GL state instead of one set per env and image size. When a scene asks
for the pooled renderer and it was last set up for another model, the model-dependent parts are rebuilt for
the new model (a fresh ``MjrContext`` in the same GL context); every image size draws into the same
offscreen buffer with its own viewport, as a private renderer of that size does, so images are byte-identical
to those of private renderers (tests/plugins/*/test_*render_shared.py check it in every world).

The pool belongs to a thread (a GL context is current on one thread at a time) and is freed when the last
user closes or is garbage-collected. Users are any objects that call :func:`borrow` with themselves and
:func:`release` when done (:class:`eb_scenekit.render.SceneRenderer`, the manipulation world's renderer).
"""

from __future__ import annotations

import atexit
import itertools
import os
import threading
import weakref
from typing import Any

import numpy as np

from eb_scenekit._mujoco import mujoco

__all__ = ["PRIVATE_GL_ENV", "borrow", "default_pooled", "check_pooled_matches_private", "episode_frames", "pool_stats", "register", "release"]

PRIVATE_GL_ENV = "EB_SCENEKIT_PRIVATE_GL"
"""Set to 1 to give every renderer that does not say otherwise its own GL state (as before the pool): a
comparison or an escape hatch; images are the same either way."""


def default_pooled() -> bool:
    """Whether renderers use the pool unless told otherwise (yes, unless ``EB_SCENEKIT_PRIVATE_GL=1``)."""
    return os.environ.get(PRIVATE_GL_ENV, "") not in ("1", "true", "yes")


_POOL: dict[int, Any] = {}
"""Thread id -> the mujoco.Renderer shared by the scenes drawn on that thread (at every image size)."""
_BOUND: dict[int, int] = {}
"""Thread id -> token of the user whose model the pooled renderer is currently set up for."""
_USERS: dict[int, Any] = {}
"""Token -> weak reference to a live user."""
_TOKENS = itertools.count(1)
_STATS = {"contexts": 0, "rebinds": 0}
_EXIT_HOOK = False


def pool_stats() -> dict[str, int]:
    """Counters of this process's pool: ``live`` pooled renderers (one per thread that draws), ``users`` (live
    scenes borrowing them), GL ``contexts`` made and ``rebinds`` (switches of a pooled renderer to another model)."""
    return {"live": len(_POOL), "users": len(_USERS), **_STATS}


def register(user: object) -> int:
    """Make ``user`` a user of the pool; returns its token for :func:`borrow` / :func:`release`. When the user is
    garbage-collected without :func:`release`, it is released then."""
    token = next(_TOKENS)
    _USERS[token] = weakref.ref(user)
    weakref.finalize(user, release, token)
    return token


def release(token: int) -> None:
    """The user with ``token`` is done; the last one to go frees the pool (its GL contexts)."""
    if _USERS.pop(token, None) is None:
        return
    for key, bound in list(_BOUND.items()):
        if bound == token:
            del _BOUND[key]  # the next user rebinds (this user's model may be gone)
    if not _USERS:
        _free_pool()


def borrow(token: int, model: Any, width: int, height: int) -> Any:
    """The calling thread's pooled ``mujoco.Renderer``, set up for ``model`` at ``width`` x ``height``.

    Valid until the next :func:`borrow` on this thread (by any user): update the scene and render right away.
    """
    global _EXIT_HOOK
    if token not in _USERS:
        raise RuntimeError("this renderer is closed (or was never registered with eb_scenekit.pool)")
    w, h = int(width), int(height)
    off = (int(model.vis.global_.offwidth), int(model.vis.global_.offheight))
    if w > off[0] or h > off[1]:
        raise ValueError(f"image size {w}x{h} is larger than this scene's offscreen buffer {off[0]}x{off[1]}; "
                         f"ask for at most {off[0]}x{off[1]} or build the scene with a larger `offscreen`")
    key = threading.get_ident()
    r = _POOL.get(key)
    if r is None:
        with _no_unused_shadow_map(model):
            r = mujoco.Renderer(model, height=h, width=w)
        _POOL[key] = r
        _STATS["contexts"] += 1
        if not _EXIT_HOOK:  # after the first GL context exists: runs before MuJoCo's own exit hook
            atexit.register(_free_pool)
            _EXIT_HOOK = True
    elif _BOUND.get(key) != token:
        _rebind(r, model)
        _STATS["rebinds"] += 1
    _BOUND[key] = token
    if (r._width, r._height) != (w, h):
        # every size draws into the same offscreen buffer (offwidth x offheight), as a private renderer of that
        # size would: only the viewport differs, so one renderer serves the image and a smaller boxes pass
        r._width, r._height = w, h
        r._rect = mujoco.MjrRect(0, 0, w, h)
    return r


def _free_pool() -> None:
    for r in list(_POOL.values()):
        r.close()
    _POOL.clear()
    _BOUND.clear()


class _no_unused_shadow_map:
    """While an ``MjrContext`` is made for a model none of whose lights casts shadows, ask for a 1-pixel shadow
    map instead of ``vis.quality.shadowsize`` (2048: a 16 MB depth texture that no pass would ever draw or
    read, allocated again on every rebind). The images do not change: the shadow pass runs only for lights
    that cast shadows."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self.saved: int | None = None

    def __enter__(self) -> None:
        m = self.model
        if m.nlight == 0 or not m.light_castshadow.any():
            self.saved = int(m.vis.quality.shadowsize)
            m.vis.quality.shadowsize = 1

    def __exit__(self, *exc: object) -> None:
        if self.saved is not None:
            self.model.vis.quality.shadowsize = self.saved


def _rebind(r: Any, model: Any) -> None:
    """Point a pooled ``mujoco.Renderer`` at another compiled model (same GL context, fresh model resources)."""
    if r._gl_context:
        r._gl_context.make_current()
    r._mjr_context.free()
    r._mjr_context = None
    old = r._model
    if not (_skinless(old) and _skinless(model)):
        r._scene = None  # free the old scene's geom buffer before allocating the new one
        r._scene = mujoco.MjvScene(model=model, maxgeom=10000)
    # else: the scene's buffers depend on the model only through skins and flexes; keep it (mjv_updateScene
    # refills it every frame), which saves building ~10,000 geom wrappers per switch
    r._model = model
    with _no_unused_shadow_map(model):
        r._mjr_context = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150.value)
    mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN.value, r._mjr_context)
    r._mjr_context.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR


def _skinless(model: Any) -> bool:
    return int(model.nskin) == 0 and int(model.nflex) == 0


# ---------------------------------------------------------------------------------------------- checker
# What every world's tests/plugins/<world>/test_<world>_render_shared.py runs: envs drawing through the pool give the same
# images and boxes, byte for byte, as envs with private renderers, even when their frames interleave.

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
    """``make_env()`` builds a pooled env; inside ``with private():`` it builds envs with private renderers."""
    with private():
        ref = []
        for task in (task_a, task_b):
            env = make_env()
            try:
                ref.append(episode_frames(env, task, steps))
            finally:
                env.close()
        assert pool_stats()["users"] == 0, "a private renderer registered with the pool"
    ea, eb = make_env(), make_env()
    before = pool_stats()
    try:
        got = [[_snap(ea.reset(task_a, 0))], [_snap(eb.reset(task_b, 0))]]
        plans = [(ea.expert_plan() or [])[:steps], (eb.expert_plan() or [])[:steps]]
        for i in range(steps):  # alternate: the pooled renderer switches scene on every frame
            for k, env in enumerate((ea, eb)):
                if i < len(plans[k]):
                    got[k].append(_snap(env.step(plans[k][i]).observation))
        stats = pool_stats()
        assert stats["live"] == 1 and stats["users"] >= 2  # one GL context for both envs, every size and view
        assert stats["rebinds"] - before["rebinds"] >= 2 * min(len(p) for p in plans)
    finally:
        ea.close()
        eb.close()
    assert pool_stats()["live"] == 0  # the last close frees the pool
    for g, want in zip(got, ref):
        assert len(g) == len(want) > 1
        for (imgs, boxes), (imgs0, boxes0) in zip(g, want):
            assert imgs.keys() == imgs0.keys() and all(imgs[k] == imgs0[k] for k in imgs)
            assert boxes == boxes0
    assert got[0][0][0] != got[1][0][0]  # the two episodes look different: not blank frames compared
