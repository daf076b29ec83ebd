"""Import MuJoCo only after an offscreen GL backend has been chosen (``MUJOCO_GL`` is read at import time)."""

from typing import TYPE_CHECKING

from eb_scenekit.gl import import_mujoco

if TYPE_CHECKING:
    import mujoco  # the checker sees the module itself (MuJoCo ships no type information: its names are Any)
else:
    mujoco = import_mujoco()

__all__ = ["mujoco"]
