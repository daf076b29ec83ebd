"""Offscreen rendering of a navigation scene: one GL context per env, one MuJoCo context per scene.

Creating ``mujoco.Renderer`` costs a GL context (~0.1-0.25 s); we keep one GL context for the env's
life and only rebuild the cheap ``MjrContext`` when the scene changes. A step renders the
first-person RGB image once at full size and a segmentation image into a small corner of the same
framebuffer (for object boxes and the text description), reusing the same ``mjvScene``.
"""

from __future__ import annotations

import numpy as np

from eb_navigation._gl import mujoco

__all__ = ["SceneRenderer"]


class SceneRenderer:
    """RGB + low-resolution segmentation for one model at a time."""

    def __init__(self, resolution: int, seg_resolution: int | None = None) -> None:
        self.resolution = int(resolution)
        self.seg_resolution = int(seg_resolution or max(64, self.resolution // 4))
        self._gl = None
        self._con = None
        self._scn = None
        self._model = None
        self._opt = mujoco.MjvOption()
        self._cam = mujoco.MjvCamera()
        self._cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._pert = mujoco.MjvPerturb()
        self._rgb = np.empty((self.resolution, self.resolution, 3), np.uint8)
        self._seg = np.empty((self.seg_resolution, self.seg_resolution, 3), np.uint8)

    def load(self, model: "mujoco.MjModel") -> None:
        if self._gl is None:
            from mujoco import gl_context

            self._gl = gl_context.GLContext(self.resolution, self.resolution)
        self._gl.make_current()
        if self._con is not None:
            self._con.free()
        if model.vis.global_.offwidth < self.resolution or model.vis.global_.offheight < self.resolution:
            raise ValueError("model offscreen buffer is smaller than the render resolution")
        self._con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._con)
        self._scn = mujoco.MjvScene(model, maxgeom=max(1000, 2 * model.ngeom + 50))
        self._model = model

    def render(self, data: "mujoco.MjData", camera: str, groups: tuple[int, ...] = (0, 1),
               segmentation: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
        """RGB image (H, W, 3) and, if asked, a segmentation map ``(s, s)`` of geom ids (-1 = nothing)."""
        model = self._model
        assert model is not None and self._con is not None and self._scn is not None, "load() a model first"
        self._gl.make_current()
        for g in range(6):
            self._opt.geomgroup[g] = 1 if g in groups else 0
        self._cam.fixedcamid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        scn = self._scn
        mujoco.mjv_updateScene(model, data, self._opt, self._pert, self._cam, mujoco.mjtCatBit.mjCAT_ALL, scn)
        rect = mujoco.MjrRect(0, 0, self.resolution, self.resolution)
        mujoco.mjr_render(rect, scn, self._con)
        mujoco.mjr_readPixels(self._rgb, None, rect, self._con)
        rgb = np.flipud(self._rgb).copy()
        seg = None
        if segmentation:
            scn.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 1
            scn.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 1
            try:
                srect = mujoco.MjrRect(0, 0, self.seg_resolution, self.seg_resolution)
                mujoco.mjr_render(srect, scn, self._con)
                mujoco.mjr_readPixels(self._seg, None, srect, self._con)
            finally:
                scn.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
                scn.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
            raw = np.flipud(self._seg).astype(np.int32)
            segid = raw[..., 0] + (raw[..., 1] << 8) + (raw[..., 2] << 16) - 1
            ngeom = scn.ngeom
            lut = np.full(ngeom + 1, -1, np.int32)
            for k in range(ngeom):
                g = scn.geoms[k]
                if g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
                    lut[k] = g.objid
            segid = np.where((segid >= 0) & (segid < ngeom), segid, ngeom)
            seg = lut[segid]
        return rgb, seg

    def close(self) -> None:
        if self._con is not None:
            try:
                if self._gl is not None:
                    self._gl.make_current()
                self._con.free()
            except Exception:  # pragma: no cover - GL teardown at interpreter exit
                pass
            self._con = None
        if self._gl is not None:
            try:
                self._gl.free()
            except Exception:  # pragma: no cover
                pass
            self._gl = None
        self._scn = None
        self._model = None
