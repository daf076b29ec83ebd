"""eb-scenekit: the household scene kit shared by every EmbodiedBench world.

Procedural MuJoCo rooms, a catalogue of household objects, and one offscreen renderer with RGB, depth,
instance segmentation and 2-D boxes. Import order matters only in one place: anything that imports MuJoCo goes
through :mod:`eb_scenekit._mujoco`, which picks the GL backend first (see :func:`select_gl_backend`).
"""

from eb_scenekit.gl import RenderBackendError, import_mujoco, select_gl_backend
from eb_scenekit.objects import (
    CATALOGUE,
    COLORS,
    Builder,
    ObjectType,
    Parts,
    Surface,
    articulated_joints,
    get_open,
    get_type,
    object_types,
    set_object_pose,
    set_open,
    set_powered,
    shade,
    surface_position,
)
from eb_scenekit import _catalogue  # noqa: F401  (its builders register themselves into CATALOGUE)
from eb_scenekit.rooms import ROOM_KINDS, RoomLayout, generate_room
from eb_scenekit.scene import RoomShell, SceneBuilder, SceneObject, lookat_xyaxes, set_agent_pose

__version__ = "0.1.0"

__all__ = [
    "Builder",
    "CATALOGUE",
    "COLORS",
    "ObjectType",
    "Parts",
    "ROOM_KINDS",
    "RenderBackendError",
    "RoomLayout",
    "RoomShell",
    "SceneBuilder",
    "SceneObject",
    "SceneRenderer",
    "Surface",
    "articulated_joints",
    "camera_from_eye",
    "contact_sheet",
    "free_camera",
    "generate_room",
    "get_open",
    "get_type",
    "import_mujoco",
    "lookat_xyaxes",
    "object_types",
    "save_png",
    "select_gl_backend",
    "set_agent_pose",
    "set_object_pose",
    "set_open",
    "set_powered",
    "shade",
    "surface_position",
    "__version__",
]


def __getattr__(name: str) -> object:
    # the renderer imports MuJoCo (after choosing a GL backend): load it on first use, so that importing the
    # catalogue or generating room layouts stays cheap and works without OpenGL
    if name in ("SceneRenderer", "camera_from_eye", "contact_sheet", "free_camera", "save_png"):
        from eb_scenekit import render

        return getattr(render, name)
    raise AttributeError(f"module 'eb_scenekit' has no attribute {name!r}")
