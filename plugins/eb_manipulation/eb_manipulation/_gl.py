"""Import MuJoCo after choosing an offscreen GL backend (``MUJOCO_GL`` is read at import time).

Uses the shared scene kit's probe (EGL, then OSMesa, then a clear error) when it is installed; otherwise
falls back to EGL unless the user already set ``MUJOCO_GL``.
"""

from __future__ import annotations

import os

try:  # the shared scene kit, when installed
    from eb_scenekit.gl import select_gl_backend as _select
except ImportError:  # pragma: no cover - depends on what is installed
    def _select() -> str:
        os.environ.setdefault("MUJOCO_GL", "egl")
        if os.environ["MUJOCO_GL"] == "egl":
            os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
        return os.environ["MUJOCO_GL"]

_select()

import mujoco  # noqa: E402

__all__ = ["mujoco"]
