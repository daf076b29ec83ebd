"""Import MuJoCo after choosing an offscreen GL backend (an adapter over ``eb_scenekit.gl``).

The scene kit's :func:`eb_scenekit.gl.select_gl_backend` probes EGL then OSMesa and fails with the
package to install. If the scene kit is not installed we fall back to ``MUJOCO_GL=egl`` (what works on
the project's machines) unless the user chose a backend already.
"""

from __future__ import annotations

import os

try:  # pragma: no branch
    from eb_scenekit.gl import select_gl_backend
except ImportError:  # the scene kit is optional for this plugin
    def select_gl_backend() -> str:
        os.environ.setdefault("MUJOCO_GL", "egl")
        if os.environ["MUJOCO_GL"] in ("egl", "osmesa"):
            os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
        return os.environ["MUJOCO_GL"]

select_gl_backend()

import mujoco  # noqa: E402

__all__ = ["mujoco", "select_gl_backend"]
