"""Front and wrist images: RGB from MuJoCo, detection boxes from its segmentation, overlays drawn with Pillow.

The front image carries what the original shows: a red X/Y/Z frame at the robot base (the origin of the
workspace's reference frame drawn in the scene) and, for each listed object, a box with its index.
"""

from __future__ import annotations

import hashlib
import math
import threading
from collections import OrderedDict
from functools import lru_cache
from typing import Any

import numpy as np
from eb_scenekit.gl import import_mujoco
from PIL import Image, ImageDraw, ImageFont

from eb_manipulation.scene import ROBOT_BASE

mujoco = import_mujoco()  # the GL backend is chosen before MuJoCo is imported

from eb_scenekit import pool  # noqa: E402 - imports MuJoCo

__all__ = ["BOX_COLOURS", "SKY_HIDDEN", "SceneRenderer", "draw_axes", "draw_boxes", "project"]

#: Box outline colours by object index (cycled). One neutral white for every box and tag, drawn with a thin dark
#: edge: a tag of its own colour was read as the colour of the object it labels (issue 25).
BOX_COLOURS = ((250, 250, 250),)
BOX_EDGE = (20, 20, 20)
SKY_HIDDEN = frozenset({"front"})
"""Cameras that never see the sky: the front camera looks down (the top of its view points about 23 degrees
below the horizon) at the table, the floor and the back wall, which cover every pixel. Their colour images are
drawn without the skybox pass; the pixels are the same (tested)."""
AXIS_LENGTH = 0.15
AXIS_RED = (230, 20, 20)


REUSE_FRAMES = True
"""Default of :attr:`SceneRenderer.reuse_frames` (tests of the GL pool switch it off so that every frame draws)."""
FIRST_FRAMES = 12
"""How many first passes (colour or segmentation, one camera each) of recent renderers a process keeps for resets
of the same task: 0.75 MB (colour) or 0.25 MB (segmentation) each at 500 px."""
_FIRST: OrderedDict[tuple, Any] = OrderedDict()
_FIRST_LOCK = threading.Lock()


def _copy(x):
    return tuple(a.copy() for a in x) if isinstance(x, tuple) else x.copy()


@lru_cache(maxsize=8)
def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow without FreeType
        return ImageFont.load_default()


class SceneRenderer:
    """Renders named cameras of one model; call :meth:`close` when done.

    ``pooled`` (default) borrows the thread's pooled ``mujoco.Renderer`` (:mod:`eb_scenekit.pool`): the envs of
    a process share one GL context and framebuffer set, with byte-identical images; False keeps a private one
    (None: pooled unless ``EB_SCENEKIT_PRIVATE_GL=1``).

    Frame reuse (``reuse_frames``, on by default): a colour or segmentation pass of a camera whose inputs (every
    joint position, the geoms' world poses and colours) are bit for bit those of this renderer's previous pass of
    that camera returns a copy of that pass instead of drawing (an action that failed moves nothing); the kept
    passes cost about 1 MB per renderer at 500 px (1.75 MB with the wrist view). With
    ``scene_key`` (the scene's MJCF, as the world passes it) the first passes of a renderer are also kept in a
    small per-process cache (:data:`FIRST_FRAMES` entries), so a reset of a task that was reset a moment ago (a
    group of rollouts from one state) draws nothing. Either way the pixels are the ones a draw would give.
    """

    def __init__(self, model, resolution: int, pooled: bool | None = None, scene_key: str | None = None):
        self.model = model
        self.size = resolution
        self.pooled = pool.default_pooled() if pooled is None else bool(pooled)
        self._token = pool.register(self) if self.pooled else None
        self._own = None if self.pooled else mujoco.Renderer(model, resolution, resolution)
        self._closed = False
        self.reuse_frames = REUSE_FRAMES
        self.frames_drawn = 0
        self.frames_reused = 0
        self._scene_key = hashlib.sha1(scene_key.encode()).hexdigest() if scene_key is not None else None
        self._last: dict[tuple[str, str], tuple[bytes, Any]] = {}

    # --- frame reuse ------------------------------------------------------------------------------------
    def _inputs(self, data) -> bytes:
        """What a pass of this model reads that can change during an episode, as bytes."""
        m = self.model
        return b"".join((data.qpos.tobytes(), data.geom_xpos.tobytes(), data.geom_xmat.tobytes(),
                         m.geom_rgba.tobytes()))

    def _cached(self, kind: str, camera: str, data, draw):
        if not self.reuse_frames:
            self.frames_drawn += 1
            return draw()
        inputs = self._inputs(data)
        last = self._last.get((kind, camera))
        hit = last[1] if last is not None and last[0] == inputs else None
        first_key = None
        if hit is None and self._scene_key is not None:
            first_key = (self._scene_key, self.size, kind, camera, inputs)
            with _FIRST_LOCK:
                hit = _FIRST.get(first_key)
                if hit is not None:
                    _FIRST.move_to_end(first_key)
        if hit is not None:
            self.frames_reused += 1
            self._last[(kind, camera)] = (inputs, hit)
            return _copy(hit)
        out = draw()
        self.frames_drawn += 1
        kept = _copy(out)
        if first_key is not None and last is None:  # this renderer's first pass of that camera
            with _FIRST_LOCK:
                _FIRST[first_key] = kept
                while len(_FIRST) > FIRST_FRAMES:
                    _FIRST.popitem(last=False)
        self._last[(kind, camera)] = (inputs, kept)
        return out

    @property
    def _r(self):
        if self._closed:
            raise RuntimeError("this SceneRenderer is closed")
        if self._own is not None:
            return self._own
        return pool.borrow(self._token, self.model, self.size, self.size)

    def rgb(self, data, camera: str) -> np.ndarray:
        """(H, W, 3) colour image of a named camera."""
        return self._cached("rgb", camera, data, lambda: self._draw_rgb(data, camera))

    def _draw_rgb(self, data, camera: str) -> np.ndarray:
        r = self._r
        r.update_scene(data, camera)
        if camera not in SKY_HIDDEN:
            return r.render().copy()
        flags = r.scene.flags
        sky = int(mujoco.mjtRndFlag.mjRND_SKYBOX)
        was = flags[sky]
        flags[sky] = 0  # never visible from this camera: the same pixels without drawing it
        try:
            return r.render().copy()
        finally:
            flags[sky] = was

    def segmentation(self, data, camera: str) -> np.ndarray:
        """(H, W) array of geom ids (-1 where no geom)."""
        segid, objid = self._segment(data, camera)
        return objid[segid]

    def _segment(self, data, camera: str) -> tuple[np.ndarray, np.ndarray]:
        """One segmentation pass: ``(segid + 1 per pixel (H, W), top row first; geom id of each segid + 1, -1 for
        the background and for anything that is not a geom)``. The same pass as ``mujoco.Renderer``'s segmentation
        mode, decoded without its per-pixel (object id, object type) table."""
        return self._cached("segmentation", camera, data, lambda: self._draw_segment(data, camera))

    def _draw_segment(self, data, camera: str) -> tuple[np.ndarray, np.ndarray]:
        r = self._r
        r.update_scene(data, camera)
        scn = r.scene
        flags = scn.flags.copy()
        scn.flags[int(mujoco.mjtRndFlag.mjRND_SEGMENT)] = 1
        scn.flags[int(mujoco.mjtRndFlag.mjRND_IDCOLOR)] = 1
        buf = np.empty((r.height, r.width, 3), dtype=np.uint8)
        try:
            if r._gl_context:
                r._gl_context.make_current()
            mujoco.mjr_render(r._rect, scn, r._mjr_context)
            mujoco.mjr_readPixels(buf, None, r._rect, r._mjr_context)
        finally:
            np.copyto(scn.flags, flags)
        n = scn.ngeom
        objid = np.full(n + 2, -1, dtype=np.int64)
        geom = int(mujoco.mjtObj.mjOBJ_GEOM)
        for g in scn.geoms[:n]:
            if g.segid != -1 and g.objtype == geom:
                objid[g.segid + 1] = g.objid
        if n + 1 <= 255:  # one byte per pixel holds every id (a kept frame stays small)
            return buf[::-1, :, 0].copy(), objid  # GL rows run bottom-up
        segid = buf[::-1, :, 0].astype(np.int32)
        segid |= buf[::-1, :, 1].astype(np.int32) << 8
        segid |= buf[::-1, :, 2].astype(np.int32) << 16
        return segid, objid

    def boxes(self, data, camera: str, groups: dict[str, set[int]]) -> dict[str, tuple[int, int, int, int]]:
        """Pixel box (x0, y0, x1, y1) of each named geom group that is visible (at least 4 pixels)."""
        return self.boxes_and_pixels(data, camera, groups)[0]

    def boxes_and_pixels(self, data, camera: str, groups: dict[str, set[int]]
                         ) -> tuple[dict[str, tuple[int, int, int, int]], np.ndarray]:
        """:meth:`boxes`, and the (H, W) map of which group each pixel shows: its index in ``groups``' order, -1
        for none (what the clear tag layout keeps its tags off, :mod:`eb_manipulation.tags`)."""
        segid, objid = self._segment(data, camera)
        keys = list(groups)
        label = np.full(len(objid), -1, dtype=np.int16)  # segid + 1 -> index of its group in ``keys``
        for k, key in enumerate(keys):
            for g in groups[key]:
                label[objid == g] = k
        pix = label[segid]
        if (label < 0).all():
            return {}, pix
        counts = np.bincount(pix.ravel() + 1, minlength=len(keys) + 1)
        out: dict[str, tuple[int, int, int, int]] = {}
        for k, key in enumerate(keys):
            if counts[k + 1] < 4:
                continue
            mask = pix == k
            ys = np.flatnonzero(mask.any(axis=1))
            xs = np.flatnonzero(mask.any(axis=0))
            out[key] = (int(xs[0]), int(ys[0]), int(xs[-1]), int(ys[-1]))
        return out, pix

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._last.clear()
        if self._token is not None:
            pool.release(self._token)
        if self._own is not None:
            try:
                self._own.close()
            except Exception:
                pass


def project(model, data, camera: str, points: np.ndarray, size: int) -> np.ndarray:
    """Pixel coordinates (N, 2) of world points seen by a MuJoCo camera (square image of ``size``)."""
    cam = model.camera(camera).id
    pos = data.cam_xpos[cam]
    R = data.cam_xmat[cam].reshape(3, 3)
    f = (size / 2) / math.tan(math.radians(model.cam_fovy[cam]) / 2)
    pc = (np.asarray(points) - pos) @ R  # camera frame: x right, y up, looking along -z
    depth = np.maximum(-pc[:, 2], 1e-6)
    u = size / 2 + f * pc[:, 0] / depth
    v = size / 2 - f * pc[:, 1] / depth
    return np.stack([u, v], axis=1)


def draw_axes(img: Image.Image, model, data, camera: str = "front") -> None:
    """A red X/Y/Z frame at the robot base, arrows labelled with their axis names."""
    size = img.size[0]
    o = np.array(ROBOT_BASE) + np.array([0.0, 0.0, 0.002])
    pts = np.array([o, o + [AXIS_LENGTH, 0, 0], o + [0, AXIS_LENGTH, 0], o + [0, 0, AXIS_LENGTH]])
    uv = project(model, data, camera, pts, size)
    draw = ImageDraw.Draw(img)
    width = max(2, size // 160)
    font = _font(max(11, size // 30))
    for k, name in enumerate("XYZ", start=1):
        (x0, y0), (x1, y1) = uv[0], uv[k]
        draw.line([(x0, y0), (x1, y1)], fill=AXIS_RED, width=width)
        ang = math.atan2(y1 - y0, x1 - x0)
        head = max(6, size // 60)
        for da in (2.6, -2.6):
            draw.line([(x1, y1), (x1 + head * math.cos(ang + da), y1 + head * math.sin(ang + da))], fill=AXIS_RED,
                      width=width)
        tx, ty = x1 + 6 * math.cos(ang), y1 + 6 * math.sin(ang)
        draw.text((tx, ty), name, fill=AXIS_RED, font=font, anchor="mm", stroke_width=1, stroke_fill=(255, 255, 255))


def draw_boxes(img: Image.Image, boxes: list[tuple[str, tuple[int, int, int, int]]]
               ) -> dict[str, tuple[int, int, int, int]]:
    """Detection boxes with index tags above each box's top-left corner (the classic overlay): ``boxes`` is a list
    of (label, (x0, y0, x1, y1)). Returns each tag's rectangle (inclusive)."""
    tags: dict[str, tuple[int, int, int, int]] = {}
    draw = ImageDraw.Draw(img)
    size = img.size[0]
    width = max(1, size // 250)
    font = _font(max(10, size // 34))
    for label, (x0, y0, x1, y1) in boxes:
        colour = BOX_COLOURS[(int(label) - 1) % len(BOX_COLOURS)] if label.isdigit() else BOX_COLOURS[0]
        draw.rectangle([x0 - 1 - width, y0 - 1 - width, x1 + 1 + width, y1 + 1 + width], outline=BOX_EDGE, width=1)
        draw.rectangle([x0 - 1, y0 - 1, x1 + 1, y1 + 1], outline=colour, width=width)
        tb = draw.textbbox((0, 0), label, font=font)
        tw, th = tb[2] - tb[0], tb[3] - tb[1]
        pad = 2
        tx0 = x0 - 1
        ty0 = y0 - th - 2 * pad - 1
        if ty0 < 0:
            ty0 = y1 + 2
        draw.rectangle([tx0, ty0, tx0 + tw + 2 * pad, ty0 + th + 2 * pad], fill=colour, outline=BOX_EDGE)
        draw.text((tx0 + pad - tb[0], ty0 + pad - tb[1]), label, fill=(0, 0, 0), font=font)
        tags[label] = (tx0, ty0, tx0 + tw + 2 * pad, ty0 + th + 2 * pad)
    return tags
