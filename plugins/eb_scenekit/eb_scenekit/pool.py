"""One pooled ``mujoco.Renderer`` per thread, shared by every scene drawn on that thread.

A private ``mujoco.Renderer`` holds a GL context, an ``MjrContext`` (offscreen framebuffers, uploaded meshes
and textures, fonts, a shadow map) and an ``MjvScene``: about 110 MB with Mesa's llvmpipe. A worker process
that drives many episodes in flight (``runner.concurrency``) or many gym environments runs all their env work
on one thread, so their scenes can take turns with one GL context and one ``MjvScene`` instead of one set per
env and image size.

What stays per scene is the ``MjrContext`` (the model's meshes and textures on the GL side, 4-25 MB): each scene
that borrows the pool gets one of its own, made on its first draw and kept until it is released, while their
estimated sizes fit the thread's cache (``EB_SCENEKIT_GL_CACHE_MB``, default 256 MB per thread; 0 turns the
cache off). Scenes beyond the cache share one more context that is rebuilt whenever another model draws with
it (a "rebind": 10-45 ms plus a slower first draw, which is what the cache saves on every step of an env that
takes turns with others). Every image size draws into the same offscreen buffer with its own viewport, as a
private renderer of that size does, so images are byte-identical to those of private renderers whichever
context a scene draws with (tests/plugins/*/test_*render_shared.py check it in every world, with and without
the cache).

The pool belongs to a thread (a GL context is current on one thread at a time) and is freed when the last
user closes or is garbage-collected. Users are any objects that call :func:`borrow` with themselves and
:func:`release` when done (:class:`eb_scenekit.render.SceneRenderer`, the manipulation world's renderer).
"""

from __future__ import annotations

import atexit
import hashlib
import itertools
import os
import threading
import weakref
from typing import Any

import numpy as np

from eb_scenekit._mujoco import mujoco

__all__ = ["CACHE_ENV", "PRIVATE_GL_ENV", "borrow", "cache_budget_mb", "context_mb", "default_pooled",
           "check_pooled_matches_private", "episode_frames", "pool_stats", "register", "release", "render_assets", "thread_renderer"]

PRIVATE_GL_ENV = "EB_SCENEKIT_PRIVATE_GL"
"""Set to 1 to give every renderer that does not say otherwise its own GL state (as before the pool): a
comparison or an escape hatch; images are the same either way."""

CACHE_ENV = "EB_SCENEKIT_GL_CACHE_MB"
"""Megabytes of per-scene ``MjrContext`` each thread's pool may keep (default :data:`DEFAULT_CACHE_MB`; 0 = none:
every scene but one rebuilds the shared context when it draws after another)."""
DEFAULT_CACHE_MB = 256


def default_pooled() -> bool:
    """Whether renderers use the pool unless told otherwise (yes, unless ``EB_SCENEKIT_PRIVATE_GL=1``)."""
    return os.environ.get(PRIVATE_GL_ENV, "") not in ("1", "true", "yes")


def cache_budget_mb() -> float:
    """The per-thread cache budget now: ``EB_SCENEKIT_GL_CACHE_MB`` or :data:`DEFAULT_CACHE_MB`."""
    raw = os.environ.get(CACHE_ENV, "").strip()
    if not raw:
        return float(DEFAULT_CACHE_MB)
    try:
        value = float(raw)
    except ValueError:
        value = -1.0
    if value < 0:
        raise ValueError(f"{CACHE_ENV}={raw!r} is not a number of megabytes >= 0; unset it for the default "
                         f"({DEFAULT_CACHE_MB}) or set e.g. {CACHE_ENV}=512 (0 turns the GL context cache off)")
    return value


def context_mb(model: Any) -> float:
    """Estimated memory of an ``MjrContext`` for ``model`` (what the cache counts): multisampled and resolved
    offscreen colour + depth buffers, the shadow map if a light casts shadows, mipmapped RGBA textures and the
    mesh triangles (position, normal, texture coordinate). Measured resident growth per context with llvmpipe is
    within ~30 % of it (benchmarks/gym_throughput.py prints both)."""
    g, q = model.vis.global_, model.vis.quality
    px = int(g.offwidth) * int(g.offheight)
    offscreen = px * 8 * max(1, int(q.offsamples)) + px * 8
    shadows = bool(model.nlight) and bool(np.any(model.light_castshadow))
    shadow = int(q.shadowsize) ** 2 * 4 if shadows else 0
    tex = int(np.sum(model.tex_width.astype(np.int64) * model.tex_height)) * 4 * 4 // 3 if model.ntex else 0
    mesh = int(model.nmeshface) * 3 * 8 * 4
    return (offscreen + shadow + tex + mesh + (1 << 20)) / (1 << 20)  # + fonts


class _Ctx:
    """An ``MjrContext`` and the scenes (tokens) that draw with it: scenes whose models have the same render
    assets (:func:`render_assets`) draw with one context."""

    __slots__ = ("ctx", "mb", "assets", "users")

    def __init__(self, ctx: Any, mb: float, assets: bytes, users: set[int]) -> None:
        self.ctx, self.mb, self.assets, self.users = ctx, mb, assets, users


class _Slot:
    """One thread's pool: the renderer (GL context, ``MjvScene``), the shared context and the cached ones."""

    def __init__(self, renderer: Any, token: int, assets: bytes) -> None:
        self.renderer = renderer
        self.thread = threading.get_ident()
        # rebuilt for whichever scene without a cached context draws next
        self.shared: _Ctx | None = _Ctx(renderer._mjr_context, 0.0, assets, {token})
        self.own: dict[int, _Ctx] = {}  # token -> its cached context (scenes with the same assets share one)
        self.own_mb = 0.0
        self.current: int | None = token  # the user whose model the renderer is set up for
        self.dead: list[Any] = []  # contexts released on another thread: freed here at the next borrow

    def entries(self) -> list[_Ctx]:
        return list({id(e): e for e in self.own.values()}.values())

    def contexts(self) -> list[Any]:
        return [*([self.shared.ctx] if self.shared else []), *(e.ctx for e in self.entries()), *self.dead]


_POOL: dict[int, _Slot] = {}
"""Thread id -> that thread's pool."""
_USERS: dict[int, Any] = {}
"""Token -> weak reference to a live user."""
_TOKENS = itertools.count(1)
_STATS = {"contexts": 0, "switches": 0, "rebinds": 0, "cached": 0, "shared": 0}
_ASSETS: dict[int, bytes] = {}
"""Token -> digest of its model's render assets (made at its first draw)."""
_LOCK = threading.RLock()  # re-entrant: a finalizer may release a user while this thread holds it
_EXIT_HOOK = False


def pool_stats() -> dict[str, Any]:
    """Counters of this process's pool: ``live`` pooled renderers (one per thread that draws), ``users`` (live
    scenes borrowing them), GL ``contexts`` made, ``switches`` (a draw for another scene than the last one),
    ``rebinds`` (the shared context rebuilt for another model),
    ``cached`` (per-scene contexts made), ``shared`` (times a scene drew with a context made for another scene
    with the same render assets instead of a new one), ``cached_live`` and ``cached_mb`` (cached contexts held
    now, estimated MB)."""
    with _LOCK:
        slots = list(_POOL.values())
        return {"live": len(slots), "users": len(_USERS), **_STATS,
                "cached_live": sum(len(s.entries()) for s in slots),
                "cached_mb": round(sum(s.own_mb for s in slots), 1)}


def register(user: object) -> int:
    """Make ``user`` a user of the pool; returns its token for :func:`borrow` / :func:`release`. When the user is
    garbage-collected without :func:`release`, it is released then."""
    token = next(_TOKENS)
    _USERS[token] = weakref.ref(user)
    weakref.finalize(user, release, token)
    return token


def release(token: int) -> None:
    """The user with ``token`` is done: its cached context is freed (on its thread: now, else at that thread's
    next draw); the last user to go frees the pool (its GL contexts)."""
    if _USERS.pop(token, None) is None:
        return
    here = threading.get_ident()
    with _LOCK:
        _ASSETS.pop(token, None)
        for slot in _POOL.values():
            if slot.shared is not None:
                slot.shared.users.discard(token)  # with no users left, the next scene takes it over
            if slot.current == token:
                slot.current = None
            own = slot.own.pop(token, None)
            if own is None:
                continue
            own.users.discard(token)
            if own.users:  # other scenes with the same assets still draw with it
                continue
            slot.own_mb -= own.mb
            if slot.thread == here and slot.renderer._gl_context:
                slot.renderer._gl_context.make_current()
                _free_context(slot, own.ctx)
                _give_back()
            else:
                slot.dead.append(own.ctx)
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
    slot = _POOL.get(key)
    if slot is None:
        with _no_unused_shadow_map(model):
            r = mujoco.Renderer(model, height=h, width=w)
        with _LOCK:
            _POOL[key] = slot = _Slot(r, token, _assets_of(token, model))
            _STATS["contexts"] += 1
        if not _EXIT_HOOK:  # after the first GL context exists: runs before MuJoCo's own exit hook
            atexit.register(_free_pool)
            _EXIT_HOOK = True
    elif slot.current != token:
        _switch(slot, token, model)
    _set_size(slot.renderer, w, h)
    return slot.renderer


def _set_size(r: Any, w: int, h: int) -> None:
    if (r._width, r._height) != (w, h):
        # every size draws into the same offscreen buffer (offwidth x offheight), as a private renderer of that
        # size would: only the viewport differs, so one renderer serves the image and a smaller boxes pass
        r._width, r._height = w, h
        r._rect = mujoco.MjrRect(0, 0, w, h)


def thread_renderer(width: int | None = None, height: int | None = None) -> Any | None:
    """This thread's pooled ``mujoco.Renderer`` as the last draw left it (its ``MjvScene`` holds that draw's
    geoms and camera), at ``width`` x ``height`` if given; None when this thread has not drawn through the pool.
    For benchmarks that time a raw render of the scene an env just drew (benchmarks/gym_throughput.py)."""
    slot = _POOL.get(threading.get_ident())
    if slot is None or slot.renderer._mjr_context is None:  # (the last scene drawn has been closed since)
        return None
    r = slot.renderer
    if width is not None or height is not None:
        _set_size(r, int(width or r.width), int(height or r.height))
    return r


def _switch(slot: _Slot, token: int, model: Any) -> None:
    """Set the slot's renderer up for ``token``'s ``model``: its cached context, a new cached context when the
    budget has room, else the shared context (rebuilt unless it already holds this model)."""
    r = slot.renderer
    if r._gl_context:
        r._gl_context.make_current()
    _STATS["switches"] += 1
    with _LOCK:
        dead, slot.dead = slot.dead, []
    for ctx in dead:
        _free_context(slot, ctx)
    if dead:
        _give_back()
    entry = slot.own.get(token)
    if entry is None and slot.shared is not None and token in slot.shared.users:
        entry = slot.shared
    if entry is None:
        assets = _assets_of(token, model)
        same = [e for e in slot.entries() if e.assets == assets]
        if same:  # a cached context made for a scene with the same meshes, textures and buffers
            entry = same[0]
            with _LOCK:
                entry.users.add(token)
                slot.own[token] = entry
                _STATS["shared"] += 1
        elif slot.shared is not None and slot.shared.assets == assets:
            entry = slot.shared
            entry.users.add(token)
            _STATS["shared"] += 1
        elif slot.shared is not None and not slot.shared.users:  # its scenes are gone: take it over
            entry = _rebuild_shared(slot, token, model, assets)
        else:
            need = context_mb(model)
            if slot.own_mb + need <= cache_budget_mb():
                entry = _Ctx(_new_context(model), need, assets, {token})
                with _LOCK:
                    slot.own[token] = entry
                    slot.own_mb += need
                    _STATS["cached"] += 1
            else:  # the scenes drawing with the shared context now get it back (rebuilt) at their next draw
                entry = _rebuild_shared(slot, token, model, assets)
    ctx = entry.ctx
    _set_model(r, model)
    r._mjr_context = ctx
    mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN.value, ctx)
    slot.current = token


def _rebuild_shared(slot: _Slot, token: int, model: Any, assets: bytes) -> _Ctx:
    if slot.shared is not None:
        if slot.renderer._mjr_context is slot.shared.ctx:
            slot.renderer._mjr_context = None
        slot.shared.ctx.free()
    slot.shared = _Ctx(_new_context(model), 0.0, assets, {token})
    _STATS["rebinds"] += 1
    return slot.shared


def _assets_of(token: int, model: Any) -> bytes:
    digest = _ASSETS.get(token)
    if digest is None:
        digest = _ASSETS[token] = render_assets(model)
    return digest


_PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
_TEXROLE_RGB = int(mujoco.mjtTextureRole.mjTEXROLE_RGB)


def render_assets(model: Any, hulls: bool = False) -> bytes:
    """A digest (SHA-1) of everything of ``model`` that ``mjr_makeContext`` reads -- buffer sizes and samples,
    the shadow map, line width, fog, extent and map settings, sphere/cylinder resolution, textures, the texture
    bindings of textured materials, plane grids, meshes with their normals and texture coordinates, height
    fields, skins -- except, unless ``hulls``, the meshes' convex hulls: MuJoCo computes those only for meshes
    that collide, and draws them only with the ``mjVIS_CONVEXHULL`` visual flag, which no renderer that borrows
    this pool turns on. Two models with the same digest get identical contexts, so scenes whose
    models differ only in poses, colours, geoms without meshes or bodies share one (all of a world's scenes,
    when it declares the same assets in every scene). ~4 ms for a model with the Franka's 136k-triangle
    meshes, made once per scene."""
    m = model
    g, q, mp = m.vis.global_, m.vis.quality, m.vis.map
    shadows = bool(m.nlight) and bool(np.any(m.light_castshadow))
    planes = np.nonzero(np.asarray(m.geom_type) == _PLANE)[0]
    plane_mats = np.asarray(m.geom_matid)[planes]
    texid = np.asarray(m.mat_texid).reshape(int(m.nmat), int(mujoco.mjtTextureRole.mjNTEXROLE))
    textured = np.nonzero(texid[:, _TEXROLE_RGB] >= 0)[0]
    h = hashlib.sha1()
    h.update(repr((int(g.offwidth), int(g.offheight), float(g.linewidth), int(q.offsamples),
                   int(q.shadowsize) if shadows else 1, int(q.numquads), int(q.numslices), int(q.numstacks),
                   float(mp.shadowclip), float(mp.shadowscale), float(mp.fogstart), float(mp.fogend),
                   float(mp.zfar), float(m.stat.extent), tuple(float(x) for x in m.vis.rgba.fog),
                   int(m.nmesh), int(m.ntex), int(m.nhfield), int(m.nskin), int(m.nflex))).encode())
    arrays = [m.tex_type, m.tex_width, m.tex_height, m.tex_nchannel, getattr(m, "tex_colorspace", None),
              m.tex_adr, m.tex_data, textured, texid[textured], np.asarray(m.mat_texuniform)[textured],
              np.asarray(m.mat_texrepeat)[textured], np.asarray(m.geom_size)[planes], plane_mats,
              np.asarray(m.mat_texrepeat)[plane_mats[plane_mats >= 0]],
              m.mesh_vertadr, m.mesh_normaladr, m.mesh_texcoordadr, m.mesh_faceadr, m.mesh_facenum,
              m.mesh_graphadr if hulls else None, m.mesh_vert, m.mesh_normal, m.mesh_texcoord, m.mesh_face,
              m.mesh_facenormal, m.mesh_facetexcoord, m.mesh_graph if hulls else None, m.hfield_size,
              m.hfield_nrow, m.hfield_ncol, m.hfield_adr,
              m.hfield_data, m.skin_texcoordadr, m.skin_vertnum, m.skin_texcoord, m.skin_facenum,
              m.skin_faceadr, m.skin_face]
    for a in arrays:
        if a is None:
            h.update(b"-")
            continue
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        if a.size:
            h.update(a.data)  # the array's own bytes (a contiguous buffer)
    return h.digest()


def _new_context(model: Any) -> Any:
    with _no_unused_shadow_map(model):
        ctx = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150.value)
    ctx.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
    return ctx


def _free_context(slot: _Slot, ctx: Any) -> None:
    """Free ``ctx`` (the slot's GL context is current); never the one the renderer holds now."""
    if slot.renderer._mjr_context is ctx:
        slot.renderer._mjr_context = None
    if slot.shared is not None and slot.shared.ctx is ctx:
        slot.shared = None
    ctx.free()


_TRIM: list[Any] = []


def _give_back() -> None:
    """Hand freed heap pages back to the OS (glibc's ``malloc_trim``; elsewhere nothing). Without it the 10-40 MB
    of a freed context stay resident as fragmented heap, and a worker whose scenes come and go (episodes in
    flight: a new scene per episode) grows by about that much per turnover (16 ALFRED scenes reset 4 times in one
    process: 681 MB without, 587 MB with)."""
    if not _TRIM:
        try:
            import ctypes

            _TRIM.append(ctypes.CDLL(None).malloc_trim)
        except (OSError, AttributeError):
            _TRIM.append(None)
    if _TRIM[0] is not None:
        _TRIM[0](0)


def _set_model(r: Any, model: Any) -> None:
    """Point the renderer's ``MjvScene`` at another compiled model."""
    old = r._model
    if old is not model and not (_skinless(old) and _skinless(model)):
        r._scene = None  # free the old scene's geom buffer before allocating the new one
        r._scene = mujoco.MjvScene(model=model, maxgeom=10000)
    # else: the scene's buffers depend on the model only through skins and flexes; keep it (mjv_updateScene
    # refills it every frame), which saves building ~10,000 geom wrappers per switch
    r._model = model


def _free_pool() -> None:
    with _LOCK:
        slots = list(_POOL.values())
        _POOL.clear()
    here = threading.get_ident()
    for slot in slots:
        r = slot.renderer
        if r._gl_context and slot.thread == here:
            r._gl_context.make_current()
        # (a GL context current on another thread cannot be made current here; as mujoco.Renderer.close does,
        # the contexts are freed anyway: their GL objects go with the GL context)
        for ctx in slot.contexts():
            if ctx is not None and ctx is not r._mjr_context:
                ctx.free()
        r.close()


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


def _skinless(model: Any) -> bool:
    return int(model.nskin) == 0 and int(model.nflex) == 0
