"""Import MuJoCo only after an offscreen GL backend has been chosen (``MUJOCO_GL`` is read at import time)."""

from eb_scenekit.gl import select_gl_backend

select_gl_backend()

import mujoco  # noqa: E402  (must follow the backend choice)

__all__ = ["mujoco"]
