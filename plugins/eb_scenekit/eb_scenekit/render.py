"""Offscreen rendering of scenekit models: RGB, depth, instance segmentation, 2-D boxes, PNG and contact sheets.

One :class:`SceneRenderer` keeps one ``mujoco.Renderer`` per image size and switches it between RGB, depth and
segmentation, so a world can render every step without re-allocating GL contexts. Cameras are model camera
names/ids or a ``mujoco.MjvCamera`` (see :func:`free_camera`), so a moving viewpoint needs no recompile.
"""

from __future__ import annotations

import atexit
import math
import weakref
from collections.abc import Sequence
from pathlib import Path
from typing import Union

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from eb_scenekit import pool
from eb_scenekit._mujoco import mujoco
from eb_scenekit.scene import AGENT_GROUP, CEILING_GROUP, INSTANCES_TEXT

__all__ = ["REUSE_FRAMES", "SceneRenderer", "draw_inputs", "free_camera", "camera_from_eye", "save_png", "contact_sheet", "Camera"]

Camera = Union[str, int, mujoco.MjvCamera]
"""A model camera name or id, or a free ``mujoco.MjvCamera``."""


def free_camera(lookat: Sequence[float], distance: float, azimuth: float, elevation: float) -> mujoco.MjvCamera:
    """A free ``MjvCamera`` orbiting ``lookat`` (degrees; negative elevation looks down). Uses the model fovy."""
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = lookat
    cam.distance = float(distance)
    cam.azimuth = float(azimuth)
    cam.elevation = float(elevation)
    return cam


def camera_from_eye(eye: Sequence[float], target: Sequence[float]) -> mujoco.MjvCamera:
    """A free ``MjvCamera`` at ``eye`` looking at ``target``."""
    d = np.asarray(target, float) - np.asarray(eye, float)
    dist = float(np.linalg.norm(d))
    az = math.degrees(math.atan2(d[1], d[0]))
    el = math.degrees(math.asin(max(-1.0, min(1.0, d[2] / dist))))
    return free_camera(target, dist, az, el)


def _free_camera_pos(cam: mujoco.MjvCamera) -> np.ndarray:
    az, el = math.radians(cam.azimuth), math.radians(cam.elevation)
    fwd = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    return np.asarray(cam.lookat, float) - cam.distance * fwd


_LIVE: weakref.WeakSet[SceneRenderer] = weakref.WeakSet()
_EXIT_HOOK = False

REUSE_FRAMES = True
"""Default of :attr:`SceneRenderer.reuse_frames` (the GL pool's interleaving check switches it off so that every
frame draws)."""
_KEPT_FRAMES = 6
"""Frames a renderer keeps for reuse (one per camera, size and kind of image asked for most recently)."""


def draw_inputs(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, ...]:
    """Everything of ``model`` and ``data`` that a draw reads and that can change after compiling: the poses
    kinematics computed (geoms, bodies, cameras, lights, sites), colours, materials, sizes, groups and mesh ids
    of geoms, lights, camera field of view, sites, and the visual settings. Textures and meshes are fixed at
    compile time (a world that changed those at run time would have to turn frame reuse off)."""
    m, d = model, data
    vis = np.array([m.vis.map.znear, m.vis.map.zfar, m.stat.extent, m.vis.headlight.active,
                    *m.vis.headlight.ambient, *m.vis.headlight.diffuse, *m.vis.headlight.specular])
    return (d.geom_xpos, d.geom_xmat, d.xpos, d.xmat, d.cam_xpos, d.cam_xmat, d.light_xpos, d.light_xdir,
            d.site_xpos, d.site_xmat, m.geom_rgba, m.geom_matid, m.geom_dataid, m.geom_size, m.geom_group,
            m.geom_type, m.mat_rgba, m.mat_emission, m.mat_specular, m.mat_shininess, m.mat_reflectance,
            m.mat_texid, m.light_active, m.light_castshadow, m.light_ambient, m.light_diffuse, m.light_specular,
            m.light_attenuation, m.light_cutoff, m.light_exponent, m.light_type, m.light_intensity, m.cam_fovy,
            m.site_rgba, m.site_size, m.site_group, vis)


def _close_all() -> None:
    # Free GL contexts before MuJoCo's own exit hook terminates the EGL display (atexit runs last-in first-out,
    # and this hook is registered after the first context exists), so unclosed renderers exit quietly.
    for r in list(_LIVE):
        r.close()


class SceneRenderer:
    """Render one compiled scene (``model``, ``data``) from named or free cameras.

    Segmentation maps every pixel to an instance index: 0 is background (room structure, agent markers, empty),
    ``i`` (1-based) is ``instance_names[i]``. The instance list comes from the scene's ``eb_scenekit_instances``
    text; for models not built by :class:`~eb_scenekit.scene.SceneBuilder` every geom-name prefix before ``/``
    counts as an instance.

    Frame reuse (:attr:`reuse_frames`, on unless ``REUSE_FRAMES`` says otherwise): a colour, depth or segmentation
    image asked for again with the same camera, size and options while nothing a draw reads has changed
    (:func:`draw_inputs`: a failed action moves nothing) is a copy of the last one, without a pass
    (:attr:`frames_drawn` / :attr:`frames_reused` count). The pixels are those a new pass would give.

    Args:
        model, data: a compiled model and its data (call ``mj_forward`` after changing ``qpos``/mocap poses).
        width, height: default image size; individual calls may ask for another size.
        show_ceiling: ``None`` hides the ceiling only for cameras above it (overhead views); True/False forces.
        pooled: borrow the thread's pooled ``mujoco.Renderer`` (:mod:`eb_scenekit.pool`: one GL context and
            framebuffer set for every scene drawn on the thread, byte-identical images, ~100 MB less per scene);
            False = private renderers, one per image size; None = pooled unless ``EB_SCENEKIT_PRIVATE_GL=1``.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, width: int = 500, height: int = 500,
                 show_ceiling: bool | None = None, pooled: bool | None = None) -> None:
        self.model = model
        self.data = data
        self.width = int(width)
        self.height = int(height)
        self.show_ceiling = show_ceiling
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        self.reuse_frames = REUSE_FRAMES
        self.frames_drawn = 0
        self.frames_reused = 0
        self._frames: dict[tuple, tuple[tuple[np.ndarray, ...], np.ndarray]] = {}
        self.pooled = pool.default_pooled() if pooled is None else bool(pooled)
        self._pool_token: int | None = pool.register(self) if self.pooled else None
        names = self._read_instances()
        self.instance_names: list[str] = [""] + names
        """Index -> instance name; index 0 is background ("")."""
        self.instance_ids: dict[str, int] = {n: i for i, n in enumerate(self.instance_names) if i}
        """Instance name -> index in segmentation maps."""
        self._geom_to_inst = np.zeros(model.ngeom + 1, dtype=np.int32)  # last slot: background (-1)
        for g in range(model.ngeom):
            gname = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            self._geom_to_inst[g] = self.instance_ids.get(gname.split("/", 1)[0], 0)
        self._ceiling_z = self._find_ceiling_z()
        _LIVE.add(self)

    def _read_instances(self) -> list[str]:
        tid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_TEXT, INSTANCES_TEXT)
        if tid >= 0:
            adr, size = self.model.text_adr[tid], self.model.text_size[tid]
            raw = bytes(self.model.text_data[adr:adr + size - 1]).decode()
            return [n for n in raw.split() if n != "none"]
        seen: dict[str, None] = {}
        for g in range(self.model.ngeom):
            gname = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            if "/" in gname and not gname.startswith("room/"):
                seen.setdefault(gname.split("/", 1)[0], None)
        return list(seen)

    def _find_ceiling_z(self) -> float | None:
        gid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "room/ceiling")
        if gid < 0:
            return None
        return float(self.model.geom_pos[gid][2] - self.model.geom_size[gid][2])

    # ------------------------------------------------------------------ plumbing

    def _renderer(self, width: int | None, height: int | None) -> mujoco.Renderer:
        key = (int(width or self.width), int(height or self.height))
        if self.pooled:
            if self._pool_token is None:
                raise RuntimeError("this SceneRenderer is closed")
            return pool.borrow(self._pool_token, self.model, key[0], key[1])
        r = self._renderers.get(key)
        if r is None:
            global _EXIT_HOOK
            r = mujoco.Renderer(self.model, height=key[1], width=key[0])
            self._renderers[key] = r
            if not _EXIT_HOOK:
                atexit.register(_close_all)
                _EXIT_HOOK = True
        return r

    def _camera_pos(self, camera: Camera) -> np.ndarray:
        if isinstance(camera, mujoco.MjvCamera):
            return _free_camera_pos(camera)
        cid = camera if isinstance(camera, int) else mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA,
                                                                        str(camera))
        if cid < 0:
            names = [mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(self.model.ncam)]
            raise KeyError(f"no camera {camera!r}; cameras in the model: {names}")
        return np.asarray(self.data.cam_xpos[cid])

    def _option(self, camera: Camera, show_agents: bool) -> mujoco.MjvOption:
        opt = mujoco.MjvOption()
        show = self.show_ceiling
        if show is None:
            show = self._ceiling_z is None or self._camera_pos(camera)[2] < self._ceiling_z
        opt.geomgroup[CEILING_GROUP] = 1 if show else 0
        opt.geomgroup[AGENT_GROUP] = 1 if show_agents else 0
        return opt

    def _update(self, r: mujoco.Renderer, camera: Camera, show_agents: bool) -> None:
        opt = self._option(camera, show_agents)
        cam = camera if isinstance(camera, (mujoco.MjvCamera, int)) else str(camera)
        r.update_scene(self.data, camera=cam, scene_option=opt)

    # ------------------------------------------------------------------ images

    def _frame_key(self, kind: str, camera: Camera, width: int | None, height: int | None,
                   show_agents: bool) -> tuple:
        if isinstance(camera, mujoco.MjvCamera):
            cam: tuple = (int(camera.type), int(camera.fixedcamid), int(camera.trackbodyid), tuple(camera.lookat),
                          float(camera.distance), float(camera.azimuth), float(camera.elevation),
                          int(camera.orthographic))
        else:
            cam = (camera,)
        return (kind, cam, int(width or self.width), int(height or self.height), bool(show_agents),
                self.show_ceiling)

    def _reused(self, key: tuple) -> np.ndarray | None:
        """A copy of the frame kept under ``key`` if nothing a draw reads has changed since it was drawn."""
        if not self.reuse_frames:
            return None
        kept = self._frames.get(key)
        if kept is None:
            return None
        if not all(np.array_equal(a, b) for a, b in zip(kept[0], draw_inputs(self.model, self.data))):
            return None
        self.frames_reused += 1
        return kept[1].copy()

    def _keep(self, key: tuple, image: np.ndarray) -> np.ndarray:
        self.frames_drawn += 1
        if self.reuse_frames:
            self._frames.pop(key, None)
            self._frames[key] = (tuple(np.array(a, copy=True) for a in draw_inputs(self.model, self.data)),
                                 image.copy())
            while len(self._frames) > _KEPT_FRAMES:
                self._frames.pop(next(iter(self._frames)))
        return image

    def rgb(self, camera: Camera, width: int | None = None, height: int | None = None,
            show_agents: bool = False) -> np.ndarray:
        """An ``H x W x 3`` uint8 colour image. ``show_agents`` draws agent markers (for overhead views)."""
        key = self._frame_key("rgb", camera, width, height, show_agents)
        hit = self._reused(key)
        if hit is not None:
            return hit
        r = self._renderer(width, height)
        self._update(r, camera, show_agents)
        return self._keep(key, r.render().copy())

    def depth(self, camera: Camera, width: int | None = None, height: int | None = None) -> np.ndarray:
        """An ``H x W`` float32 depth image in metres (distance along the view axis)."""
        key = self._frame_key("depth", camera, width, height, False)
        hit = self._reused(key)
        if hit is not None:
            return hit
        r = self._renderer(width, height)
        r.enable_depth_rendering()
        try:
            self._update(r, camera, False)
            return self._keep(key, r.render().astype(np.float32, copy=True))
        finally:
            r.disable_depth_rendering()

    def segmentation(self, camera: Camera, width: int | None = None, height: int | None = None) -> np.ndarray:
        """An ``H x W`` int32 map of instance indices (0 = background; see :attr:`instance_names`)."""
        key = self._frame_key("segmentation", camera, width, height, False)
        hit = self._reused(key)
        if hit is not None:
            return hit
        r = self._renderer(width, height)
        r.enable_segmentation_rendering()
        try:
            self._update(r, camera, False)
            seg = r.render()
        finally:
            r.disable_segmentation_rendering()
        objid, objtype = seg[..., 0], seg[..., 1]
        geom = np.where(objtype == int(mujoco.mjtObj.mjOBJ_GEOM), objid, -1)
        return self._keep(key, self._geom_to_inst[geom])  # -1 indexes the background slot

    def boxes(self, camera: Camera, min_pixels: int = 20, width: int | None = None,
              height: int | None = None) -> dict[str, tuple[int, int, int, int]]:
        """Pixel boxes ``(x0, y0, x1, y1)`` (inclusive) of instances with at least ``min_pixels`` visible pixels."""
        seg = self.segmentation(camera, width, height)
        return self.boxes_from_segmentation(seg, min_pixels)

    def boxes_from_segmentation(self, seg: np.ndarray, min_pixels: int = 20) -> dict[str, tuple[int, int, int, int]]:
        """Same as :meth:`boxes` for a segmentation map you already have."""
        counts = np.bincount(seg.ravel(), minlength=len(self.instance_names))
        out: dict[str, tuple[int, int, int, int]] = {}
        for idx in np.nonzero(counts >= max(int(min_pixels), 1))[0]:
            if idx == 0:
                continue
            mask = seg == idx
            rows = np.nonzero(mask.any(axis=1))[0]
            cols = np.nonzero(mask.any(axis=0))[0]
            out[self.instance_names[idx]] = (int(cols[0]), int(rows[0]), int(cols[-1]), int(rows[-1]))
        return out

    def visible_pixels(self, camera: Camera, width: int | None = None, height: int | None = None) -> dict[str, int]:
        """Number of visible pixels per instance (instances with none are left out)."""
        seg = self.segmentation(camera, width, height)
        counts = np.bincount(seg.ravel(), minlength=len(self.instance_names))
        return {self.instance_names[i]: int(counts[i]) for i in np.nonzero(counts)[0] if i}

    # ------------------------------------------------------------------ lifetime

    def close(self) -> None:
        """Free the GL contexts (safe to call twice)."""
        if self._pool_token is not None:
            pool.release(self._pool_token)
            self._pool_token = None
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()
        self._frames.clear()

    def __enter__(self) -> SceneRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def save_png(path: str | Path, rgb: np.ndarray) -> Path:
    """Write an ``H x W x 3`` uint8 image as PNG (deterministic bytes); creates parent folders."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.ascontiguousarray(rgb)).save(p, format="PNG", optimize=True)
    return p


def contact_sheet(images: Sequence[np.ndarray], labels: Sequence[str] | None = None, cols: int = 4,
                  pad: int = 4, label_height: int = 16, background: tuple[int, int, int] = (255, 255, 255)
                  ) -> np.ndarray:
    """Tile images (all the same size) into one labelled sheet; labels use Pillow's default font."""
    if not images:
        raise ValueError("contact_sheet needs at least one image")
    labels = list(labels) if labels is not None else [""] * len(images)
    if len(labels) != len(images):
        raise ValueError(f"{len(images)} images but {len(labels)} labels")
    h, w = images[0].shape[:2]
    cols = max(1, min(cols, len(images)))
    rows = math.ceil(len(images) / cols)
    lh = label_height if any(labels) else 0
    sheet = Image.new("RGB", (cols * (w + pad) + pad, rows * (h + lh + pad) + pad), background)
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default()
    for i, (img, label) in enumerate(zip(images, labels)):
        r, c = divmod(i, cols)
        x, y = pad + c * (w + pad), pad + r * (h + lh + pad)
        sheet.paste(Image.fromarray(np.ascontiguousarray(img[..., :3])), (x, y + lh))
        if label:
            draw.text((x + 2, y + 2), label, fill=(0, 0, 0), font=font)
    return np.asarray(sheet)
