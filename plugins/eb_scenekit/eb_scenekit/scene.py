"""Build MJCF household scenes in code: a room shell, catalogue objects, cameras and a movable agent camera.

``SceneBuilder`` keeps a record of every placed object (:class:`SceneObject`), writes a self-contained MJCF
string (all textures are MuJoCo builtins, all meshes inline vertex lists, so nothing is read from disk) and
compiles it. The same calls always produce the same XML string, byte for byte.
"""

from __future__ import annotations

import copy
import math
import threading
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from eb_scenekit._mjcf import El

if TYPE_CHECKING:
    from mujoco import MjData, MjModel  # MuJoCo ships no type information: to the checker these are Any
from eb_scenekit.objects import CATALOGUE, ObjectType, _rpy_quat, get_type, material_assets

__all__ = [
    "INSTANCES_TEXT",
    "CEILING_GROUP",
    "AGENT_GROUP",
    "WALL_HEIGHT",
    "WALL_THICKNESS",
    "Opening",
    "RoomKind",
    "RoomShell",
    "SceneBuilder",
    "SceneObject",
    "compile_model",
    "forward_without_contacts",
    "lookat_xyaxes",
    "set_agent_pose",
]

RoomKind = Literal["kitchen", "living_room", "bedroom", "bathroom"]
Wall = Literal["north", "south", "east", "west"]
WALLS: tuple[Wall, ...] = ("north", "south", "east", "west")
"""The four walls, in the order rooms are built and furnished."""

INSTANCES_TEXT = "eb_scenekit_instances"
"""Name of the MJCF custom text that lists object instance names (used by the renderer for segmentation)."""
CEILING_GROUP = 3
"""Geom group of the ceiling; the renderer hides it for cameras above the ceiling (overhead views)."""
AGENT_GROUP = 4
"""Geom group of agent markers (hidden unless a render asks for it)."""
WALL_HEIGHT = 2.6
WALL_THICKNESS = 0.1


@dataclass(frozen=True)
class SceneObject:
    """One placed object instance, as recorded by :class:`SceneBuilder`."""

    name: str
    """Instance name, e.g. ``"Apple_1"``; prefix of all its geom/body/joint names."""
    type: str
    """Catalogue type name, e.g. ``"Apple"``."""
    category: str
    color: str
    """Colour variant name (``"custom"`` for an explicit RGB)."""
    position: tuple[float, float, float]
    """World position of the base centre (metres)."""
    yaw: float
    """World yaw in degrees (the object's front is its local +x)."""
    half_extents: tuple[float, float]
    """Footprint half size along the object's local x and y, scaled (metres)."""
    height: float
    """Height, scaled (metres)."""
    scale: float = 1.0
    parent: str | None = None
    """Instance name of the receptacle it stands on/in, or None (floor/wall)."""
    surface: str | None = None
    """Name of the parent's surface it was put on/in."""
    inside: bool = False
    """True if it is inside the parent (fridge, cabinet, bowl) rather than on top."""
    mount: str = "surface"
    movable: bool = False
    shape: str | None = None
    """Shape variant name (see :attr:`eb_scenekit.ObjectType.shapes`), or None for the default look."""

    def corners(self, margin: float = 0.0) -> np.ndarray:
        """The 4 world (x, y) corners of the footprint, grown by ``margin``."""
        hx, hy = self.half_extents[0] + margin, self.half_extents[1] + margin
        c, s = math.cos(math.radians(self.yaw)), math.sin(math.radians(self.yaw))
        local = np.array([[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]])
        rot = np.array([[c, -s], [s, c]])
        return local @ rot.T + np.array(self.position[:2])

    def aabb(self, margin: float = 0.0) -> tuple[float, float, float, float]:
        """World axis-aligned footprint box (xmin, ymin, xmax, ymax)."""
        c = self.corners(margin)
        return float(c[:, 0].min()), float(c[:, 1].min()), float(c[:, 0].max()), float(c[:, 1].max())

    def overlaps(self, other: SceneObject, margin: float = 0.0) -> bool:
        """Whether the two footprints (oriented rectangles, grown by ``margin``) intersect (separating axes)."""
        a, b = self.corners(margin), other.corners(margin)
        for poly in (a, b):
            for i in range(4):
                edge = poly[(i + 1) % 4] - poly[i]
                axis = np.array([-edge[1], edge[0]])
                pa, pb = a @ axis, b @ axis
                if pa.max() <= pb.min() + 1e-9 or pb.max() <= pa.min() + 1e-9:
                    return False
        return True


@dataclass(frozen=True)
class Opening:
    """A door or window on a wall: ``offset`` is the centre along the wall from the wall's middle (metres)."""

    wall: Wall
    offset: float
    width: float
    bottom: float
    top: float


@dataclass(frozen=True)
class RoomShell:
    """The room around the objects: floor size, walls, door, window and materials used."""

    kind: RoomKind
    size: tuple[float, float]
    """Interior size along x and y (metres); the room spans [-x/2, x/2] × [-y/2, y/2]."""
    height: float
    door: Opening
    windows: tuple[Opening, ...]
    floor_material: str
    wall_rgb: tuple[float, float, float]

    def wall_frame(self, wall: Wall) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centre of the wall's inner face at z=0, unit vector along the wall, inward normal)."""
        hx, hy = self.size[0] / 2, self.size[1] / 2
        if wall == "north":
            return np.array([0.0, hy]), np.array([1.0, 0.0]), np.array([0.0, -1.0])
        if wall == "south":
            return np.array([0.0, -hy]), np.array([1.0, 0.0]), np.array([0.0, 1.0])
        if wall == "east":
            return np.array([hx, 0.0]), np.array([0.0, 1.0]), np.array([-1.0, 0.0])
        return np.array([-hx, 0.0]), np.array([0.0, 1.0]), np.array([1.0, 0.0])

    def wall_length(self, wall: Wall) -> float:
        return self.size[0] if wall in ("north", "south") else self.size[1]


def lookat_xyaxes(pos: Sequence[float], target: Sequence[float]) -> tuple[float, ...]:
    """MJCF ``xyaxes`` of a camera at ``pos`` looking at ``target`` with world z up."""
    f = np.asarray(target, float) - np.asarray(pos, float)
    f /= np.linalg.norm(f)
    up = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.999 else np.array([0.0, 1.0, 0.0])
    x = np.cross(f, up)
    x /= np.linalg.norm(x)
    y = np.cross(-f, x)
    return tuple(float(v) for v in (*x, *y))


def _agent_quat(yaw: float, pitch: float) -> tuple[float, float, float, float]:
    # body +x is the viewing direction; positive pitch looks up
    return _rpy_quat(0.0, -pitch, yaw)


def set_agent_pose(model: MjModel, data: MjData, name: str, pos: Sequence[float], yaw: float = 0.0,
                   pitch: float = 0.0) -> None:
    """Move an agent camera added with :meth:`SceneBuilder.add_agent_camera` (no recompile).

    Args:
        pos: (x, y) keeps the current eye height, or (x, y, z) for the eye position.
        yaw: heading in degrees (0 looks along +x, 90 along +y).
        pitch: degrees, positive looks up.
    """
    from eb_scenekit._mujoco import mujoco

    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
    if bid < 0 or model.body_mocapid[bid] < 0:
        raise KeyError(f"no agent camera body {name!r} in the model")
    mid = model.body_mocapid[bid]
    p = list(pos)
    if len(p) == 2:
        p.append(float(data.mocap_pos[mid][2]))
    # same rounding as the MJCF writer, so a pose set here renders exactly like the same pose written in XML
    data.mocap_pos[mid] = np.round(np.asarray(p, float), 4)
    q = np.round(np.asarray(_agent_quat(yaw, pitch)), 4)
    data.mocap_quat[mid] = q / np.linalg.norm(q)
    mujoco.mj_forward(model, data)


_FLOORS = {
    "kitchen": ("tile", ((0.9, 0.9, 0.88), (0.72, 0.74, 0.76)), 0.3),
    "bathroom": ("tile", ((0.95, 0.95, 0.96), (0.55, 0.7, 0.85)), 0.2),
    "living_room": ("planks", ((0.62, 0.45, 0.3), (0.56, 0.4, 0.26)), 0.0),
    "bedroom": ("planks", ((0.72, 0.56, 0.4), (0.66, 0.5, 0.35)), 0.0),
}
_WALLS = {
    "kitchen": ((0.95, 0.93, 0.85), (0.9, 0.94, 0.9), (0.96, 0.95, 0.93)),
    "bathroom": ((0.88, 0.93, 0.96), (0.95, 0.95, 0.95), (0.93, 0.9, 0.86)),
    "living_room": ((0.93, 0.88, 0.78), (0.86, 0.9, 0.86), (0.92, 0.92, 0.9)),
    "bedroom": ((0.84, 0.88, 0.95), (0.93, 0.87, 0.88), (0.95, 0.92, 0.85)),
}
_RUGS = ((0.65, 0.2, 0.18), (0.2, 0.3, 0.55), (0.55, 0.5, 0.4), (0.3, 0.45, 0.35))


class SceneBuilder:
    """Accumulate a room, objects, lights and cameras; write MJCF with :meth:`to_xml`, compile with :meth:`build`.

    Angles are degrees; lengths metres; the room is centred on the origin with the floor at z = 0.
    """

    def __init__(self, name: str = "eb_scene", offscreen: tuple[int, int] = (1024, 1024), fovy: float = 60.0,
                 shadows: bool = False, antialias: int = 4) -> None:
        """
        Args:
            name: MJCF model name.
            offscreen: offscreen buffer size; renders up to this size work (>= 1024 for the 700x700 ablation).
            fovy: vertical field of view of free cameras (model cameras set their own).
            shadows: let the main ceiling light cast shadows (prettier, about 3-4x slower on a CPU renderer).
            antialias: MSAA samples (0 = off: fastest, jagged edges).
        """
        self.name = name
        self.offscreen = offscreen
        self.fovy = fovy
        self.shadows = bool(shadows)
        self.antialias = int(antialias)
        self.objects: list[SceneObject] = []
        self.room: RoomShell | None = None
        self._assets: dict[str, El] = {}
        self._world: list[El] = []
        self._lights: list[El] = []
        self._cameras: list[El] = []
        self._counts: dict[str, int] = {}
        self._by_name: dict[str, SceneObject] = {}
        self._reserved: set[str] = {"room", "world"}
        self._types: dict[str, ObjectType] = {}
        for el in material_assets():
            self._assets[str(el.attrs["name"])] = el

    # ------------------------------------------------------------------ room

    def add_room(self, kind: RoomKind, size_xy: tuple[float, float], seed: int = 0, *,
                 door: tuple[Wall, float] | None = None, windows: Sequence[tuple[Wall, float]] | None = None,
                 rug: tuple[float, float] | None = None, height: float = WALL_HEIGHT) -> RoomShell:
        """Add floor, four walls, a door, window(s), a ceiling with lamps and the lights.

        Args:
            kind: decides floor and wall materials (tiles for kitchen/bathroom, wood planks otherwise).
            size_xy: interior size (metres).
            seed: picks the wall colour and, if not given, the door and window positions.
            door: (wall, offset along the wall from its middle); default: random.
            windows: list of (wall, offset); default: one window on a wall other than the door's.
            rug: (half x, half y) of a rug in the middle of the floor, or None.
        """
        if self.room is not None:
            raise ValueError("this scene already has a room")
        if kind not in _FLOORS:
            raise ValueError(f"unknown room kind {kind!r}; available: {sorted(_FLOORS)}")
        rng = np.random.default_rng([sum(map(ord, kind)), int(seed)])
        sx, sy = float(size_xy[0]), float(size_xy[1])
        walls: list[Wall] = ["north", "south", "east", "west"]
        wall_rgb = _WALLS[kind][int(rng.integers(len(_WALLS[kind])))]

        def length(w: Wall) -> float:
            return sx if w in ("north", "south") else sy

        if door is None:
            dw: Wall = walls[int(rng.integers(4))]
            lim = length(dw) / 2 - 0.65
            door = (dw, float(np.round(rng.uniform(-lim, lim), 2)))
        door_op = Opening(door[0], float(door[1]), 0.9, 0.0, 2.05)
        if windows is None:
            others = [w for w in walls if w != door_op.wall]
            ww = others[int(rng.integers(len(others)))]
            lim = max(length(ww) / 2 - 1.0, 0.0)
            windows = [(ww, float(np.round(rng.uniform(-lim, lim), 2)))]
        win_ops = tuple(Opening(w, float(o), 1.2, 0.95, 2.05) for w, o in windows)
        self.room = RoomShell(kind, (sx, sy), height, door_op, win_ops, f"eb_floor_{kind}", wall_rgb)
        self._room_assets(kind, sx, sy)
        self._room_geoms(self.room, rng, rug)
        return self.room

    def _room_assets(self, kind: str, sx: float, sy: float) -> None:
        style, (c1, c2), tile = _FLOORS[kind]
        if style == "tile":
            self._add_asset(El("texture", {"name": f"eb_tex_floor_{kind}", "type": "2d", "builtin": "checker",
                                           "width": 512, "height": 512, "rgb1": c1, "rgb2": c2, "mark": "edge",
                                           "markrgb": (0.5, 0.5, 0.5)}))
            rep = (sx / (2 * tile), sy / (2 * tile))
        else:
            self._add_asset(El("texture", {"name": f"eb_tex_floor_{kind}", "type": "2d", "builtin": "checker",
                                           "width": 512, "height": 512, "rgb1": c1, "rgb2": c2, "mark": "random",
                                           "random": 0.03, "markrgb": (0.45, 0.32, 0.2)}))
            rep = (sx / 2.4, sy / 0.36)
        self._add_asset(El("material", {"name": f"eb_floor_{kind}", "texture": f"eb_tex_floor_{kind}",
                                        "texrepeat": rep, "specular": 0.3, "shininess": 0.4, "reflectance": 0.0}))
        self._add_asset(El("material", {"name": "eb_wall", "specular": 0.05, "shininess": 0.05}))
        self._add_asset(El("material", {"name": "eb_window", "specular": 0.9, "shininess": 1.0,
                                        "emission": 0.55}))

    def _room_geoms(self, room: RoomShell, rng: np.random.Generator, rug: tuple[float, float] | None) -> None:
        sx, sy = room.size
        hx, hy, h, t = sx / 2, sy / 2, room.height, WALL_THICKNESS
        w = self._world
        w.append(El("geom", {"name": "room/floor", "type": "plane", "size": (hx, hy, 0.1),
                             "material": room.floor_material, "rgba": (1, 1, 1, 1)}))
        wall_rgba = (*room.wall_rgb, 1.0)
        sides: tuple[tuple[Wall, tuple[float, float, float], tuple[float, float, float]], ...] = (
            ("north", (0, hy + t / 2, h / 2), (hx + t, t / 2, h / 2)),
            ("south", (0, -hy - t / 2, h / 2), (hx + t, t / 2, h / 2)),
            ("east", (hx + t / 2, 0, h / 2), (t / 2, hy, h / 2)),
            ("west", (-hx - t / 2, 0, h / 2), (t / 2, hy, h / 2)))
        for name, pos, half in sides:
            w.append(El("geom", {"name": f"room/wall_{name}", "type": "box", "pos": pos, "size": half,
                                 "material": "eb_wall", "rgba": wall_rgba}))
            centre, along, normal = room.wall_frame(name)
            length = room.wall_length(name)
            p = centre + normal * 0.008
            w.append(El("geom", {"name": f"room/baseboard_{name}", "type": "box", "pos": (p[0], p[1], 0.05),
                                 "size": (abs(along[0]) * length / 2 + 0.008 * abs(normal[0]),
                                          abs(along[1]) * length / 2 + 0.008 * abs(normal[1]), 0.05),
                                 "material": "eb_glossy", "rgba": (0.96, 0.96, 0.95, 1), "contype": 0,
                                 "conaffinity": 0}))
        self._opening_geoms(room.door, "door")
        for i, win in enumerate(room.windows):
            self._opening_geoms(win, f"window_{i}" if i else "window")
        if rug is not None:
            col = _RUGS[int(rng.integers(len(_RUGS)))]
            w.append(El("geom", {"name": "room/rug", "type": "box", "pos": (0, 0, 0.004),
                                 "size": (rug[0], rug[1], 0.004), "material": "eb_fabric",
                                 "rgba": (*col, 1), "contype": 0, "conaffinity": 0}))
            w.append(El("geom", {"name": "room/rug_border", "type": "box", "pos": (0, 0, 0.003),
                                 "size": (rug[0] + 0.06, rug[1] + 0.06, 0.003), "material": "eb_fabric",
                                 "rgba": (0.9, 0.85, 0.7, 1), "contype": 0, "conaffinity": 0}))
        # ceiling and ceiling lamps (group 3: hidden in overhead renders)
        w.append(El("geom", {"name": "room/ceiling", "type": "box", "pos": (0, 0, h + 0.025),
                             "size": (hx + t, hy + t, 0.025), "material": "eb_matte",
                             "rgba": (0.97, 0.97, 0.96, 1), "group": CEILING_GROUP, "contype": 0,
                             "conaffinity": 0}))
        lamps = [(0.0, 0.0)] if max(sx, sy) < 4.2 else (
            [(-sx / 4, 0.0), (sx / 4, 0.0)] if sx >= sy else [(0.0, -sy / 4), (0.0, sy / 4)])
        for i, (lx, ly) in enumerate(lamps):
            w.append(El("geom", {"name": f"room/ceiling_lamp_{i}", "type": "cylinder", "pos": (lx, ly, h - 0.02),
                                 "size": (0.22, 0.02), "material": "eb_glow", "rgba": (1, 0.98, 0.92, 1),
                                 "group": CEILING_GROUP, "contype": 0, "conaffinity": 0}))
            self._lights.append(El("light", {"name": f"room/ceiling_light_{i}", "pos": (lx, ly, h - 0.1),
                                             "dir": (0, 0, -1), "directional": False,
                                             "diffuse": (0.42 / len(lamps) ** 0.5,) * 3, "specular": (0.1,) * 3,
                                             "cutoff": 55 if self.shadows else 80, "exponent": 1,
                                             "castshadow": self.shadows and i == 0,
                                             "attenuation": (1, 0, 0)}))
        # daylight through the window, with shadows
        win = room.windows[0] if room.windows else room.door
        _, _, normal = room.wall_frame(win.wall)
        d = (float(normal[0]) * 0.6 + 0.2, float(normal[1]) * 0.6 + 0.15, -1.0)
        self._lights.insert(0, El("light", {"name": "room/sun", "directional": True, "pos": (0, 0, h + 2),
                                            "dir": d, "diffuse": (0.3, 0.3, 0.28), "specular": (0.15,) * 3,
                                            "castshadow": False}))

    def _opening_geoms(self, op: Opening, tag: str) -> None:
        assert self.room is not None
        centre, along, normal = self.room.wall_frame(op.wall)
        c = centre + along * op.offset
        zc, hz = (op.bottom + op.top) / 2, (op.top - op.bottom) / 2
        hw = op.width / 2
        w = self._world

        def box(part: str, off_along: float, depth: float, z: float, half_along: float, half_depth: float,
                half_z: float, mat: str, rgba: tuple[float, ...]) -> None:
            p = c + along * off_along + normal * depth
            size = (abs(along[0]) * half_along + abs(normal[0]) * half_depth,
                    abs(along[1]) * half_along + abs(normal[1]) * half_depth, half_z)
            w.append(El("geom", {"name": f"room/{tag}_{part}", "type": "box", "pos": (p[0], p[1], z),
                                 "size": size, "material": mat, "rgba": rgba, "contype": 0, "conaffinity": 0}))

        trim = (0.97, 0.97, 0.96, 1.0)
        if tag == "door":
            box("panel", 0, 0.012, zc, hw, 0.012, hz, "eb_wood", (0.6, 0.42, 0.26, 1))
            for k, zz in enumerate((0.55, 1.45)):
                box(f"inset_{k}", 0, 0.026, zz, hw - 0.12, 0.003, 0.35, "eb_wood", (0.54, 0.37, 0.22, 1))
            box("frame_l", -hw - 0.04, 0.015, zc + 0.02, 0.04, 0.015, hz + 0.02, "eb_glossy", trim)
            box("frame_r", hw + 0.04, 0.015, zc + 0.02, 0.04, 0.015, hz + 0.02, "eb_glossy", trim)
            box("frame_t", 0, 0.015, op.top + 0.04, hw + 0.08, 0.015, 0.04, "eb_glossy", trim)
            p = c + along * (hw - 0.09) + normal * 0.05
            w.append(El("geom", {"name": "room/door_handle", "type": "sphere", "pos": (p[0], p[1], 1.0),
                                 "size": (0.03,), "material": "eb_metal", "rgba": (0.85, 0.75, 0.4, 1),
                                 "contype": 0, "conaffinity": 0}))
        else:
            box("pane", 0, 0.004, zc, hw, 0.004, hz, "eb_window", (0.62, 0.82, 0.98, 1))
            box("frame_l", -hw - 0.03, 0.025, zc, 0.035, 0.025, hz + 0.06, "eb_glossy", trim)
            box("frame_r", hw + 0.03, 0.025, zc, 0.035, 0.025, hz + 0.06, "eb_glossy", trim)
            box("frame_t", 0, 0.025, op.top + 0.03, hw, 0.025, 0.03, "eb_glossy", trim)
            box("sill", 0, 0.05, op.bottom - 0.03, hw + 0.1, 0.05, 0.03, "eb_glossy", trim)
            box("mullion", 0, 0.02, zc, 0.02, 0.02, hz, "eb_glossy", trim)
            box("transom", 0, 0.02, op.bottom + 0.68 * (op.top - op.bottom), hw, 0.02, 0.02, "eb_glossy", trim)

    def add_studio(self, floor_rgb: tuple[float, float, float] = (0.72, 0.71, 0.68), half_size: float = 10.0) -> None:
        """A plain floor and lights without walls: the minimal scene for showing single objects."""
        self._add_asset(El("texture", {"name": "eb_tex_sky", "type": "skybox", "builtin": "gradient",
                                       "width": 256, "height": 256, "rgb1": (0.85, 0.9, 0.97),
                                       "rgb2": (0.55, 0.6, 0.68)}))
        self._world.append(El("geom", {"name": "room/floor", "type": "plane", "size": (half_size, half_size, 0.1),
                                       "material": "eb_matte", "rgba": (*floor_rgb, 1)}))
        self._lights.append(El("light", {"name": "room/key", "pos": (2, -2, 4), "dir": (-0.45, 0.45, -0.8),
                                         "directional": True, "diffuse": (0.5, 0.5, 0.5),
                                         "castshadow": self.shadows}))
        self._lights.append(El("light", {"name": "room/fill", "pos": (-2, 2, 4), "dir": (0.4, -0.3, -0.8),
                                         "directional": True, "diffuse": (0.2, 0.2, 0.2), "castshadow": False}))

    def add_static_geom(self, name: str, gtype: str, pos: Sequence[float], size: Sequence[float],
                        rgba: Sequence[float] = (0.9, 0.88, 0.82, 1.0), material: str = "eb_matte") -> None:
        """A plain fixed geom (a backdrop wall, a platform). Name it ``"room/..."`` so that segmentation treats it
        as structure (background)."""
        self._world.append(El("geom", {"name": name, "type": gtype, "pos": tuple(pos), "size": tuple(size),
                                       "material": material, "rgba": tuple(rgba)}))

    # ------------------------------------------------------------------ objects

    def _auto_name(self, type_name: str) -> str:
        n = self._counts.get(type_name, 0)
        while True:
            n += 1
            name = f"{type_name}_{n}"
            if name not in self._by_name:
                self._counts[type_name] = n
                return name

    def register_type(self, otype: ObjectType) -> ObjectType:
        """Make a world's own object type available to :meth:`add_object` of this builder (and of no other).

        The type follows the catalogue's conventions (see :class:`~eb_scenekit.objects.Parts`); its name must
        not clash with a catalogue type or another registered one. Registering the same object again is a no-op.
        """
        name = otype.name
        if not name or "/" in name or " " in name:
            raise ValueError(f"object type names must be non-empty without '/' or spaces: {name!r}")
        if self._types.get(name) is otype:
            return otype
        if name in CATALOGUE:
            raise ValueError(f"{name!r} is a catalogue type: give your own type another name")
        if name in self._types:
            raise ValueError(f"another object type named {name!r} is already registered with this builder")
        self._types[name] = otype
        return otype

    def object_type(self, name: str) -> ObjectType:
        """A type registered with :meth:`register_type`, else the catalogue's; an unknown name lists both."""
        if name in self._types:
            return self._types[name]
        if name in CATALOGUE or not self._types:
            return get_type(name)
        raise KeyError(f"unknown object type {name!r}; registered here: {', '.join(self._types)}; catalogue: "
                       f"{', '.join(CATALOGUE)}")

    def object(self, name: str) -> SceneObject:
        """The placed object with this instance name."""
        try:
            return self._by_name[name]
        except KeyError:
            raise KeyError(f"no object {name!r} in the scene; placed: {', '.join(self._by_name)}") from None

    def add_object(self, type_name: str, instance_name: str | None = None,
                   pos: Sequence[float] = (0.0, 0.0), yaw: float = 0.0, color: str | Sequence[float] | None = None,
                   scale: float = 1.0, parent: str | None = None, *, surface: str | None = None,
                   movable: bool | None = None, open: Mapping[str, float] | float | None = None,
                   shape: str | None = None) -> SceneObject:
        """Place one catalogue object (or one of a type added with :meth:`register_type`).

        Args:
            type_name: catalogue name, e.g. ``"Mug"``, or the name of a registered type.
            instance_name: unique name (no ``/``); default ``"<Type>_<n>"`` (``"Mug_1"``, ``"Mug_2"`` ...).
            pos: without ``parent``: world (x, y) or (x, y, z) of the base centre (z defaults to 0, or 1.25 for
                wall-mounted types). With ``parent``: (dx, dy[, dz]) offset on the parent's surface, in the
                parent's frame, from the surface centre.
            yaw: degrees; relative to the parent's yaw when ``parent`` is given.
            color: a colour variant name of the type, or an (r, g, b) triple; default: the type's first variant.
            scale: uniform size factor.
            parent: instance name of a receptacle to put this object on/in.
            surface: which surface of the parent (default: its first, e.g. a fridge's bottom shelf, a table top).
            movable: add a free joint (default: the type's ``movable``).
            open: initial open fraction (0 closed .. 1 open) of all articulated parts, or per part.
            shape: a shape variant of the type (``"tall"``, ``"square"`` ...; see ``ObjectType.shapes``).

        Returns:
            The recorded :class:`SceneObject`.
        """
        otype = self.object_type(type_name)
        name = instance_name or self._auto_name(type_name)
        if name in self._by_name or name in self._reserved or "/" in name or " " in name:
            raise ValueError(f"instance name {name!r} is taken or invalid (no '/' or spaces)")
        color_name, _ = otype.color_rgb(color if color is None or isinstance(color, str) else tuple(color))
        p = [float(v) for v in pos]
        inside = False
        surf_name: str | None = None
        if parent is not None:
            par = self.object(parent)
            ptype = self.object_type(par.type)
            surf = ptype.surface(surface)
            surf_name = surf.name
            inside = surf.inside
            dx, dy = (p + [0.0, 0.0])[:2]
            dz = p[2] if len(p) > 2 else 0.0
            lx = (surf.center[0] + dx / par.scale) * par.scale
            ly = (surf.center[1] + dy / par.scale) * par.scale
            c, s = math.cos(math.radians(par.yaw)), math.sin(math.radians(par.yaw))
            world = (par.position[0] + c * lx - s * ly, par.position[1] + s * lx + c * ly,
                     par.position[2] + surf.z * par.scale + dz)
            wyaw = par.yaw + yaw
        else:
            z = p[2] if len(p) > 2 else (1.25 if otype.mount == "wall" else 0.0)
            world = (p[0], p[1], z)
            wyaw = yaw
        world = (round(world[0], 4), round(world[1], 4), round(world[2], 4))
        wyaw = round(((wyaw + 180.0) % 360.0) - 180.0, 4)
        mov = otype.movable if movable is None else bool(movable)
        rgb = color if color is None or isinstance(color, str) else tuple(float(v) for v in color)
        st = otype.shape_stretch(shape)
        body, _ = otype.build(name, world, wyaw, rgb, scale, mov, open, self._assets, shape=shape)
        self._world.append(body)
        obj = SceneObject(name=name, type=otype.name, category=otype.category, color=color_name,
                          position=world, yaw=wyaw,
                          half_extents=(otype.half_extents[0] * scale * st[0], otype.half_extents[1] * scale * st[1]),
                          height=otype.height * scale * st[2], scale=float(scale), parent=parent, surface=surf_name,
                          inside=inside, mount=otype.mount, movable=mov, shape=shape)
        self.objects.append(obj)
        self._by_name[name] = obj
        return obj

    # ------------------------------------------------------------------ cameras and lights

    def add_camera(self, name: str, pos: Sequence[float], xyaxes: Sequence[float] | None = None,
                   lookat: Sequence[float] | None = None, fovy: float = 60.0) -> str:
        """Add a fixed named camera, oriented by ``xyaxes`` or by a point to look at."""
        if xyaxes is not None and lookat is None:
            axes = tuple(xyaxes)
        elif lookat is not None and xyaxes is None:
            axes = lookat_xyaxes(pos, lookat)
        else:
            raise ValueError("give exactly one of xyaxes or lookat")
        self._cameras.append(El("camera", {"name": name, "pos": tuple(pos), "xyaxes": axes, "fovy": fovy}))
        return name

    def add_agent_camera(self, name: str = "agent", pos: Sequence[float] = (0.0, 0.0), yaw: float = 0.0,
                         pitch: float = 0.0, height: float = 1.5, fovy: float = 60.0, marker: bool = True) -> str:
        """Add a first-person camera on a mocap body, moved later with :func:`set_agent_pose` (no recompile).

        The body and the camera are both called ``name``. ``marker`` adds a small body shape (geom group
        ``AGENT_GROUP``, hidden unless a render shows that group) for overhead views.
        """
        p = (float(pos[0]), float(pos[1]), float(pos[2]) if len(pos) > 2 else height)
        body = El("body", {"name": name, "mocap": True, "pos": p, "quat": _agent_quat(yaw, pitch)})
        body.add("camera", name=name, pos=(0, 0, 0), xyaxes=(0, -1, 0, 0, 0, 1), fovy=fovy)
        if marker:
            body.add("geom", name=f"{name}/marker", type="capsule", fromto=(0, 0, -p[2] + 0.25, 0, 0, -0.25),
                     size=(0.18,), rgba=(0.1, 0.6, 0.95, 1), group=AGENT_GROUP, contype=0, conaffinity=0)
            body.add("geom", name=f"{name}/nose", type="box", pos=(0.2, 0, -0.25), size=(0.08, 0.05, 0.05),
                     rgba=(0.95, 0.3, 0.1, 1), group=AGENT_GROUP, contype=0, conaffinity=0)
        self._cameras.append(body)
        self._reserved.add(name)
        return name

    def add_light(self, name: str, pos: Sequence[float], direction: Sequence[float] = (0, 0, -1),
                  diffuse: float = 0.3, directional: bool = False, castshadow: bool = False) -> None:
        """Add an extra light (MuJoCo renders at most 8 lights in total, the headlight included)."""
        self._lights.append(El("light", {"name": name, "pos": tuple(pos), "dir": tuple(direction),
                                         "diffuse": (diffuse,) * 3, "directional": directional,
                                         "castshadow": castshadow}))

    # ------------------------------------------------------------------ output

    def _add_asset(self, el: El) -> None:
        self._assets.setdefault(str(el.attrs["name"]), el)

    def _extent(self) -> tuple[float, tuple[float, float, float]]:
        """Half diagonal and centre of the room (or of the placed objects), for MuJoCo's ``<statistic>``."""
        if self.room is not None:
            sx, sy = self.room.size
            return round(max(math.hypot(sx, sy, self.room.height) / 2, 1.0), 3), (0.0, 0.0, self.room.height / 2)
        if not self.objects:
            return 1.0, (0.0, 0.0, 0.0)
        pts = np.array([o.position for o in self.objects])
        lo, hi = pts.min(axis=0) - 1.0, pts.max(axis=0) + 1.0
        c = (lo + hi) / 2
        return (round(max(float(np.linalg.norm(hi - lo)) / 2, 1.0), 3),
                (round(float(c[0]), 3), round(float(c[1]), 3), round(float(c[2]), 3)))

    def to_xml(self) -> str:
        """The complete MJCF document (deterministic: same calls, same string)."""
        root = El("mujoco", {"model": self.name})
        root.add("compiler", angle="degree", autolimits=True)
        root.add("option", timestep=0.004, cone="elliptic", impratio=10)
        root.add("size", memory="64M")
        vis = root.add("visual")
        vis.add("global", offwidth=self.offscreen[0], offheight=self.offscreen[1], fovy=self.fovy)
        vis.add("quality", shadowsize=2048, offsamples=self.antialias)
        vis.add("headlight", ambient=(0.38, 0.38, 0.38), diffuse=(0.28, 0.28, 0.28), specular=(0.05, 0.05, 0.05))
        extent, centre = self._extent()
        vis.add("map", znear=0.004, zfar=40, haze=0.0, shadowclip=1.5)
        vis.add("rgba", haze=(0.85, 0.88, 0.92, 1))
        # fixing the extent keeps the near clip plane (znear * extent) at about 1-2 cm in a room
        root.add("statistic", extent=extent, center=centre)
        asset = root.add("asset")
        for el in self._assets.values():
            asset.append(el)
        world = root.add("worldbody")
        for el in self._lights:
            world.append(el)
        for el in self._world:
            world.append(el)
        for el in self._cameras:
            world.append(el)
        custom = root.add("custom")
        custom.add("text", name=INSTANCES_TEXT, data=" ".join(o.name for o in self.objects) or "none")
        return root.to_string() + "\n"

    def build(self) -> tuple[MjModel, MjData]:
        """Compile the scene: returns ``(mujoco.MjModel, mujoco.MjData)`` after one ``mj_forward`` (without
        collision detection: :func:`forward_without_contacts`)."""
        from eb_scenekit._mujoco import mujoco

        model = compile_model(self.to_xml())
        data = mujoco.MjData(model)
        forward_without_contacts(model, data)
        return model, data


MODEL_CACHE_SIZE = 4
"""Compiled models :func:`compile_model` keeps per process (the most recently used ones)."""
MODEL_CACHE_BYTES = 48_000_000
"""...and at most this many bytes of them (always the newest one): an EB-Manipulation model with the Panda's
visual meshes is ~33 MB, a household room 2-5 MB."""
_MODELS: OrderedDict[tuple[object, ...], tuple[MjModel, int]] = OrderedDict()
_MODELS_LOCK = threading.Lock()


def compile_model(xml: str, assets: Mapping[str, bytes] | None = None) -> MjModel:
    """``mujoco.MjModel.from_xml_string(xml, assets)``, compiled once per process for a recently seen document.

    A reset of a task that was reset a moment ago (a group of rollouts from one state, a repeated episode, the
    same task in another env of the process) gets a copy of the model compiled then: about 1 ms instead of 0.05-0.2
    s. The copy is a separate model (changing its colours or flags leaves the cached one alone) with the same
    numbers, so it renders and simulates exactly like a fresh compile. The key is the document and each asset's
    name, size and hash; at most :data:`MODEL_CACHE_SIZE` models and :data:`MODEL_CACHE_BYTES` are kept.
    """
    from eb_scenekit._mujoco import mujoco

    files = tuple(sorted((name, len(data), hash(data)) for name, data in (assets or {}).items()))
    key = (xml, files)
    with _MODELS_LOCK:
        entry = _MODELS.get(key)
        if entry is not None:
            _MODELS.move_to_end(key)
    if entry is None:
        model = mujoco.MjModel.from_xml_string(xml, assets=dict(assets)) if assets else \
            mujoco.MjModel.from_xml_string(xml)
        entry = (model, int(mujoco.mj_sizeModel(model)))
        with _MODELS_LOCK:
            _MODELS[key] = entry
            while len(_MODELS) > 1 and (len(_MODELS) > MODEL_CACHE_SIZE
                                        or sum(size for _, size in _MODELS.values()) > MODEL_CACHE_BYTES):
                _MODELS.popitem(last=False)
    return copy.copy(entry[0])


def forward_without_contacts(model: MjModel, data: MjData) -> None:
    """``mj_forward`` with collision detection switched off for this one call (the model's flags are restored).

    Poses, cameras and lights come out exactly as from a full ``mj_forward``; only the contact list and the
    constraint forces are left empty. A freshly built scene parks its movable objects together out of sight, and
    detecting the thousands of contacts between them took up to 0.7 s of a reset; the next ``mj_step`` detects
    contacts anew, so a simulation started from here is the same.
    """
    from eb_scenekit._mujoco import mujoco

    flags = model.opt.disableflags
    model.opt.disableflags = flags | int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    try:
        mujoco.mj_forward(model, data)
    finally:
        model.opt.disableflags = flags

