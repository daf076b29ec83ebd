"""Front and wrist images: RGB from MuJoCo, detection boxes from its segmentation, overlays drawn with Pillow.

The front image carries what the original shows: a red X/Y/Z frame at the robot base (the origin of the
workspace's reference frame drawn in the scene) and, for each listed object, a box with its index.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from eb_scenekit.gl import import_mujoco

from eb_manipulation.scene import ROBOT_BASE

mujoco = import_mujoco()  # the GL backend is chosen before MuJoCo is imported

from eb_scenekit import pool  # noqa: E402 - imports MuJoCo

__all__ = ["BOX_COLOURS", "SceneRenderer", "draw_axes", "draw_boxes", "project"]

#: Box outline colours by object index (cycled); none of them is the axes' red.
BOX_COLOURS = (
    (255, 214, 0), (0, 190, 255), (255, 110, 200), (60, 220, 90), (255, 150, 30),
    (170, 120, 255), (0, 235, 200), (250, 250, 250),
)
AXIS_LENGTH = 0.15
AXIS_RED = (230, 20, 20)


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
    """

    def __init__(self, model, resolution: int, pooled: bool | None = None):
        self.model = model
        self.size = resolution
        self.pooled = pool.default_pooled() if pooled is None else bool(pooled)
        self._token = pool.register(self) if self.pooled else None
        self._own = None if self.pooled else mujoco.Renderer(model, resolution, resolution)
        self._closed = False

    @property
    def _r(self):
        if self._closed:
            raise RuntimeError("this SceneRenderer is closed")
        if self._own is not None:
            return self._own
        return pool.borrow(self._token, self.model, self.size, self.size)

    def rgb(self, data, camera: str) -> np.ndarray:
        r = self._r
        r.update_scene(data, camera)
        return r.render().copy()

    def segmentation(self, data, camera: str) -> np.ndarray:
        """(H, W) array of geom ids (-1 where no geom)."""
        r = self._r
        r.enable_segmentation_rendering()
        try:
            r.update_scene(data, camera)
            seg = r.render().copy()
        finally:
            r.disable_segmentation_rendering()
        ids = seg[..., 0].astype(np.int64)
        ids[seg[..., 1] != int(mujoco.mjtObj.mjOBJ_GEOM)] = -1
        return ids

    def boxes(self, data, camera: str, groups: dict[str, set[int]]) -> dict[str, tuple[int, int, int, int]]:
        """Pixel box (x0, y0, x1, y1) of each named geom group that is visible."""
        ids = self.segmentation(data, camera)
        out: dict[str, tuple[int, int, int, int]] = {}
        for key, geoms in groups.items():
            mask = np.isin(ids, list(geoms))
            if mask.sum() < 4:
                continue
            ys, xs = np.nonzero(mask)
            out[key] = (int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max()))
        return out

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if self._token is not None:
            pool.release(self._token)
        if self._own is not None:
            try:
                self._own.close()
            except Exception:  # noqa: BLE001 - GL teardown at interpreter exit may already be gone
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


def draw_boxes(img: Image.Image, boxes: list[tuple[str, tuple[int, int, int, int]]]) -> None:
    """Detection boxes with index tags: ``boxes`` is a list of (label, (x0, y0, x1, y1))."""
    draw = ImageDraw.Draw(img)
    size = img.size[0]
    width = max(1, size // 250)
    font = _font(max(10, size // 34))
    for label, (x0, y0, x1, y1) in boxes:
        colour = BOX_COLOURS[(int(label) - 1) % len(BOX_COLOURS)] if label.isdigit() else BOX_COLOURS[0]
        draw.rectangle([x0 - 1, y0 - 1, x1 + 1, y1 + 1], outline=colour, width=width)
        tb = draw.textbbox((0, 0), label, font=font)
        tw, th = tb[2] - tb[0], tb[3] - tb[1]
        pad = 2
        tx0 = x0 - 1
        ty0 = y0 - th - 2 * pad - 1
        if ty0 < 0:
            ty0 = y1 + 2
        draw.rectangle([tx0, ty0, tx0 + tw + 2 * pad, ty0 + th + 2 * pad], fill=colour)
        draw.text((tx0 + pad - tb[0], ty0 + pad - tb[1]), label, fill=(0, 0, 0), font=font)
