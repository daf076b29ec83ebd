"""Import MuJoCo only after an offscreen GL backend has been chosen (``MUJOCO_GL`` is read at import time)."""

from eb_scenekit.gl import import_mujoco

mujoco = import_mujoco()

__all__ = ["mujoco"]
