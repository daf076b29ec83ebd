"""The MuJoCo apartment that draws the symbolic world: ReplicaCAD-style open-plan layouts built with the scene kit.

This is the only module of eb_habitat that imports MuJoCo (through :mod:`eb_scenekit`). It is an adapter: the
room shell, the furniture and ten object types come from the kit; the other YCB-style objects are our own types
(:mod:`eb_habitat._ycb`), registered with each apartment's ``SceneBuilder``. Nothing is simulated: after every
step the renderer moves the objects to their receptacle slots (or into the agent's hand), sets door and drawer
joints, puts the first-person camera in front of the receptacle the agent stands at, and renders.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from eb_scenekit import SceneBuilder, get_type, set_agent_pose, set_open, surface_position
from eb_scenekit.gl import import_mujoco
from eb_scenekit.render import SceneRenderer, camera_from_eye
from eb_habitat._mirror import MIRRORED, mirrored_type
from eb_habitat._ycb import KIT_TYPES, kit_or_ycb
from eb_habitat.catalog import COLORS, KITCHEN_ROWS, N_APARTMENTS, RECEPTACLES, WIDE_CAPACITY
from eb_habitat.world import HAND

if TYPE_CHECKING:
    from eb_habitat.tasks import TaskSpec
    from eb_habitat.world import World

mujoco = import_mujoco()

__all__ = ["ApartmentRenderer", "LAYOUTS", "Layout"]

AGENT = "agent"
OBJECT_SCALE = 1.2
"""Small objects are drawn a little larger than life so that they read at 500 x 500 from a metre away."""
EYE_HEIGHT = 1.35
"""Camera height of the robot's head (metres)."""
FOVY = 62.0


# -- layouts ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Place:
    kit_type: str
    pos: tuple[float, float]
    yaw: float
    color: str | tuple[float, float, float]


@dataclass(frozen=True)
class Layout:
    """One apartment: room size and seed, where each receptacle's furniture stands, and decoration."""

    size: tuple[float, float]
    seed: int
    furniture: dict[str, Place]
    """Instance name -> placement. Receptacle keys name their furniture; drawers live in the counters."""
    decor: tuple[tuple[str, str, tuple[float, ...], float, str, str | None], ...]
    """(kit type, instance, pos, yaw, colour, parent) of things that are not receptacles."""
    start_eye: tuple[float, float, float]
    start_target: tuple[float, float, float]


_BROWN = COLORS["brown"][:3]
_SINK_WORKTOP = (0.31, 0.025)
"""The kit's sink unit is 5 cm shallower than a counter: it stands flush with the counter fronts, and a strip of
worktop fills the gap to the wall behind it: (distance of the strip's centre behind the sink's origin, half
depth), metres."""


#: Half widths (metres, along the row) of the kitchen row's pieces, and the gap between neighbours.
_ROW_HALF_WIDTH = {"fridge": 0.38, "cabinet": 0.3, "left_counter": 0.6, "sink": 0.3, "right_counter": 0.6}
_ROW_GAP = 0.015
_ROW_PIECES = {"fridge": ("Fridge", 0.38), "cabinet": ("Cabinet", 0.25), "left_counter": ("CounterTop", 0.33),
               "sink": ("Sink", 0.355), "right_counter": ("CounterTop", 0.33)}
"""Kit type and distance of the piece's centre from the wall, per kitchen receptacle."""


def _kitchen(x0: float, ywall: float, counter: str, fridge: str, row: tuple[str, ...]) -> dict[str, Place]:
    """The kitchen row along a north wall, ``row`` from left to right as seen facing it (``KITCHEN_ROWS``);
    ``x0`` is the centre of the leftmost piece."""
    out: dict[str, Place] = {}
    x = x0
    for i, key in enumerate(row):
        if i:
            x += _ROW_HALF_WIDTH[row[i - 1]] + _ROW_HALF_WIDTH[key] + _ROW_GAP
        kit_type, depth = _ROW_PIECES[key]
        if key in ("fridge", "cabinet") and i > row.index("sink"):
            kit_type += MIRRORED  # hinged on the right: its door opens away from the counters
        out[key] = Place(kit_type, (round(x, 3), ywall - depth), -90, fridge if key == "fridge" else counter)
    return out


def _living(cx: float, ysouth: float, sofa: str, coffee: str, tv: str) -> dict[str, Place]:
    """Sofa against the south wall facing north, coffee table in front, TV stand facing it, brown side table."""
    return {
        "sofa": Place("Sofa", (cx, ysouth + 0.47), 90, sofa),
        "coffee_table": Place("CoffeeTable", (cx, ysouth + 1.6), 90, coffee),
        "tv_stand": Place("TVStand", (cx, ysouth + 3.3), -90, tv),
        "brown_table": Place("Table", (cx + 1.45, ysouth + 0.5), 90, _BROWN),
    }


def _dining(cx: float, cy: float, table: str, chairs: str) -> dict[str, Place]:
    """Dining table with its long side facing south, a chair at each end."""
    return {
        "dining_table": Place("DiningTable", (cx, cy), -90, table),
        "left_chair": Place("Chair", (cx - 1.15, cy), 0, chairs),
        "right_chair": Place("Chair", (cx + 1.15, cy), 180, chairs),
    }


def _decor(living_x: float, ysouth: float, plant: tuple[float, float], painting: tuple[float, float, float, float]):
    """TV on the stand, lamp on the desk, a floor lamp by the sofa, a plant, two paintings."""
    return (
        ("Television", "decor_tv", (-0.08, 0.0), 0.0, "black", "tv_stand"),
        ("DeskLamp", "decor_lamp", (-0.15, 0.45), 0.0, "black", "desk"),
        ("FloorLamp", "decor_floor_lamp", (living_x - 1.35, ysouth + 0.35), 0.0, "cream", None),
        ("HousePlant", "decor_plant", plant, 0.0, "terracotta", None),
        ("Painting", "decor_painting", (living_x, ysouth + 0.05, 1.55), 90.0, "gold", None),
        ("Painting", "decor_painting_2", painting[:3], painting[3], "wood", None),
    )


def _layout0() -> Layout:
    ysouth, ywall = -3.5, 3.5
    desk = Place("Desk", (4.13, -1.9), 180, "oak")
    furniture = {**_kitchen(-4.08, ywall, "white", "white", KITCHEN_ROWS[0]),
                 **_living(-2.6, ysouth, "gray", "oak", "walnut"),
                 **_dining(1.7, 0.9, "white", "black"), "desk": desk}
    decor = _decor(-2.6, ysouth, (4.1, 3.1), (4.45, -1.9, 1.6, 180.0))
    return Layout((9.0, 7.0), 3, furniture, decor, (0.3, -2.6, 1.6), (-1.2, 1.5, 0.7))


def _layout1() -> Layout:
    ysouth, ywall = -3.5, 3.5
    desk = Place("Desk", (-4.13, -2.0), 0, "white")
    furniture = {**_kitchen(0.4, ywall, "wood", "silver", KITCHEN_ROWS[1]),
                 **_living(1.9, ysouth, "blue", "white", "black"),
                 **_dining(-2.2, 1.0, "oak", "wood"), "desk": desk}
    decor = _decor(1.9, ysouth, (-4.1, 3.1), (-4.45, -2.0, 1.6, 0.0))
    return Layout((9.0, 7.0), 11, furniture, decor, (-0.4, -2.5, 1.6), (1.5, 1.8, 0.7))


def _layout2() -> Layout:
    ysouth, ywall = -3.75, 3.75
    desk = Place("Desk", (3.9, ywall - 0.34), -90, "white")
    furniture = {**_kitchen(-4.58, ywall, "gray", "black", KITCHEN_ROWS[2]),
                 **_living(2.6, ysouth, "green", "white", "white"),
                 **_dining(-1.9, -1.4, "white", "white"), "desk": desk}
    decor = _decor(2.6, ysouth, (-4.6, -3.3), (3.9, ywall - 0.05, 1.75, -90.0))
    return Layout((10.0, 7.5), 23, furniture, decor, (0.9, -2.9, 1.6), (-1.0, 1.6, 0.7))


LAYOUTS: tuple[Layout, ...] = (_layout0(), _layout1(), _layout2())
assert len(LAYOUTS) == N_APARTMENTS


# -- receptacle geometry -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Slots:
    """Where the slots of a receptacle are, in the furniture's local frame."""

    instance: str
    part: str | None
    """The articulation that opens it (``door``, ``drawer``), or None."""
    points: tuple[tuple[str, float, float], ...]
    """(surface name or ``drawer``, local x offset, local y offset) per slot, slot 0 leftmost."""
    view: tuple[float, float, float, float, float]
    """(distance, eye height, target local x, target local y, target z) of the first-person view."""
    view_dir: float = 0.0
    """Extra turn (degrees, in the furniture frame) of the side the agent views from; 0 = from the front."""
    lay_tall: bool = False
    """Lay tall objects on their side (drawers are shallow; things in a sink lie down)."""


def _row(surface: str, n: int, half_width: float, dx: float = 0.0) -> tuple[tuple[str, float, float], ...]:
    if n == 1:
        return ((surface, dx, 0.0),)
    return tuple((surface, dx, -half_width + 2 * half_width * i / (n - 1)) for i in range(n))


_DRAWER_FRONT = 0.0725
"""Objects in a counter drawer stand this far in front of the centre of its floor: in the part that comes out."""

_GEOMETRY: dict[str, _Slots] = {
    "left_counter": _Slots("left_counter", None, _row("top", 4, 0.42, 0.02), (0.95, EYE_HEIGHT, 0.0, 0.0, 0.9)),
    "right_counter": _Slots("right_counter", None, _row("top", 4, 0.42, 0.02), (0.95, EYE_HEIGHT, 0.0, 0.0, 0.9)),
    "sink": _Slots("sink", None, _row("basin", 2, 0.1), (0.7, 1.6, 0.02, 0.0, 0.8), lay_tall=True),
    "fridge": _Slots("fridge", "door", _row("shelf_2", 2, 0.13) + _row("shelf_1", 2, 0.13),
                     (1.8, 1.45, 0.0, 0.0, 0.9)),
    "left_drawer": _Slots("left_counter", "drawer", _row("drawer", 3, 0.16, _DRAWER_FRONT),
                          (0.62, 1.45, 0.42, -0.3, 0.66), lay_tall=True),
    "right_drawer": _Slots("right_counter", "drawer", _row("drawer", 3, 0.16, _DRAWER_FRONT),
                           (0.62, 1.45, 0.42, -0.3, 0.66), lay_tall=True),
    "cabinet": _Slots("cabinet", "door", _row("shelf", 2, 0.11) + _row("interior", 2, 0.11),
                      (1.15, 1.25, 0.0, 0.0, 0.45)),
    "sofa": _Slots("sofa", None, _row("seat", 3, 0.5), (1.25, EYE_HEIGHT, 0.0, 0.0, 0.45)),
    "tv_stand": _Slots("tv_stand", None, _row("top", 3, 0.48, 0.08), (1.15, EYE_HEIGHT, 0.0, 0.0, 0.55)),
    "coffee_table": _Slots("coffee_table", None, _row("top", 3, 0.33), (1.05, EYE_HEIGHT, 0.0, 0.0, 0.4)),
    "dining_table": _Slots("dining_table", None, _row("top", 4, 0.55, 0.12), (1.25, EYE_HEIGHT, 0.0, 0.0, 0.76)),
    "left_chair": _Slots("left_chair", None, _row("seat", 1, 0.0), (1.0, EYE_HEIGHT, 0.0, 0.0, 0.5), view_dir=-90),
    "right_chair": _Slots("right_chair", None, _row("seat", 1, 0.0), (1.0, EYE_HEIGHT, 0.0, 0.0, 0.5), view_dir=90),
    "brown_table": _Slots("brown_table", None, _row("top", 3, 0.24), (1.0, EYE_HEIGHT, 0.0, 0.0, 0.76)),
    "desk": _Slots("desk", None, _row("top", 3, 0.38, 0.08), (1.05, EYE_HEIGHT, 0.0, 0.0, 0.76)),
}
assert set(_GEOMETRY) == {r.key for r in RECEPTACLES}


def _staggered(surface: str, n: int, half_width: float, dx: float, depth: float
               ) -> tuple[tuple[str, float, float], ...]:
    """``n`` slots left to right, every other one ``depth`` metres nearer the viewer (two depths, so neighbours
    stand close without merging)."""
    return tuple((surface, dx + (depth if i % 2 else -depth), -half_width + 2 * half_width * i / (n - 1))
                 for i in range(n))


#: Hard sets (version 7): the slots of the long surfaces in a wide task (:data:`~eb_habitat.catalog.WIDE_CAPACITY`);
#: the other receptacles keep :data:`_GEOMETRY`.
_WIDE_POINTS: dict[str, tuple[tuple[str, float, float], ...]] = {
    "left_counter": _staggered("top", 9, 0.46, 0.0, 0.14),
    "right_counter": _staggered("top", 9, 0.46, 0.0, 0.14),
    "dining_table": _staggered("top", 9, 0.62, 0.08, 0.13),
    "tv_stand": _staggered("top", 7, 0.52, 0.06, 0.07),
    "sofa": _staggered("seat", 7, 0.6, 0.0, 0.07),
}
assert all(len(p) == WIDE_CAPACITY[k] for k, p in _WIDE_POINTS.items()) and set(_WIDE_POINTS) == set(WIDE_CAPACITY)


def _slot_point(key: str, slot: int, wide: bool) -> tuple[str, float, float]:
    return (_WIDE_POINTS[key] if wide and key in _WIDE_POINTS else _GEOMETRY[key].points)[slot]

#: Extra yaw (degrees) per object type so that long things show their profile to the camera.
_YAW = {"skillet": 90.0, "toy_airplane": 60.0, "spatula": 70.0, "pitcher": -60.0, "mug": -30.0,
        "banana": 20.0, "hammer": 15.0, "bleach_bottle": -20.0}


#: Turn (degrees) of a mug whose handle must point to one side as the agent faces it (hard sets, version 6): the kit
#: mug's handle sticks out along its local +y, which is the camera's right when the mug faces the camera, so 0
#: shows it in profile to the right and 180 to the left (each side reads in full, never hidden behind the body).
HANDLE_YAW = {"right": 0.0, "left": 180.0}


def _rot(yaw_deg: float, x: float, y: float) -> tuple[float, float]:
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    return c * x - s * y, s * x + c * y


def _yaw_quat(yaw_deg: float) -> tuple[float, float, float, float]:
    h = math.radians(yaw_deg) / 2
    return (math.cos(h), 0.0, 0.0, math.sin(h))


def _qmul(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


#: Objects taller than this (metres, drawn size) lie on their side in a drawer or the sink.
DRAWER_CLEARANCE = 0.13


def _lying(type_key: str, pos: tuple[float, float, float], front_yaw: float,
           quat: tuple[float, ...]) -> tuple[tuple[float, float, float], tuple[float, ...]]:
    """Lay a tall object on its side, lengthwise from back to front, on the drawer (or basin) floor."""
    t = kit_or_ycb(type_key)
    height = t.height * OBJECT_SCALE
    if height <= DRAWER_CLEARANCE:
        return pos, quat
    hx, hy = (h * OBJECT_SCALE for h in t.half_extents)
    s = math.sqrt(0.5)
    if hx <= hy:  # on its back: its front face (local +x) looks up, its top points away from the viewer
        q = _qmul(_yaw_quat(front_yaw), (s, 0.0, -s, 0.0))
        lift, along = hx, height / 2
    else:  # on its side: its local y axis points down, its top towards the viewer
        q = _qmul(_yaw_quat(front_yaw - 90.0), (s, -s, 0.0, 0.0))
        lift, along = hy, -height / 2
    fx, fy = _rot(front_yaw, along, 0.0)
    return (pos[0] + fx, pos[1] + fy, pos[2] + lift), q


def _worktop_behind(b: SceneBuilder, sink: Place) -> None:
    """A strip of worktop between the back of the sink unit and the wall, level with the counters' worktops."""
    back, half_depth = _SINK_WORKTOP
    x, y = _rot(sink.yaw, -back, 0.0)
    half_width = get_type(sink.kit_type).half_extents[1]
    along_x = abs(math.cos(math.radians(sink.yaw))) > 0.5  # the unit's depth runs along world x
    size = (half_depth, half_width, 0.02) if along_x else (half_width, half_depth, 0.02)
    b.add_static_geom("room/sink_worktop", "box", (sink.pos[0] + x, sink.pos[1] + y, 0.9), size,
                      rgba=(0.8, 0.79, 0.76, 1.0), material="eb_stone")


def _furniture_type(kit_type: str):
    """The kit type of a piece of furniture, or our mirrored version of one (:mod:`eb_habitat._mirror`)."""
    if kit_type.endswith(MIRRORED):
        return mirrored_type(kit_type.removesuffix(MIRRORED))
    return get_type(kit_type)


def _kit_color(kit_type: str, color: str) -> str | tuple[float, float, float]:
    """A kit type's own variant when it has one of that name, else our RGB for the colour."""
    variants = get_type(kit_type).colors
    name = color.replace(" ", "_")
    if name in variants:
        return name
    return COLORS[color][:3]


# -- renderer ------------------------------------------------------------------------------------------------------


class ApartmentRenderer:
    """Builds the MuJoCo apartment of a task and renders the first-person (and overhead) view of a world state."""

    def __init__(self, resolution: int = 500, multi_view: bool = False) -> None:
        self.resolution = int(resolution)
        self.multi_view = multi_view
        self._key: tuple | None = None
        self._model = None
        self._data = None
        self._renderer: SceneRenderer | None = None
        self._furniture: dict[str, tuple[tuple[float, float, float], float]] = {}
        self._qpos_adr: dict[str, int] = {}
        self._boxes: dict[str, tuple[int, int, int, int]] = {}
        self._positions: dict[str, tuple[float, float, float]] = {}
        self._camera: tuple[np.ndarray, np.ndarray] | None = None

    # -- building ---------------------------------------------------------------------------------------------

    def scene_xml(self, spec: TaskSpec) -> str:
        """The complete MJCF of the task's apartment with all its objects (deterministic)."""
        layout = LAYOUTS[spec.apartment]
        b = SceneBuilder(f"eb_habitat_apartment_{spec.apartment}", offscreen=(self.resolution, self.resolution),
                         fovy=FOVY)
        b.add_room("living_room", layout.size, seed=layout.seed, door=("south", 0.0),
                   windows=[("east", 0.4), ("west", 0.9)], rug=None)
        for name, place in layout.furniture.items():
            if place.kit_type.endswith(MIRRORED):
                b.register_type(mirrored_type(place.kit_type.removesuffix(MIRRORED)))
            b.add_object(place.kit_type, name, pos=place.pos, yaw=place.yaw, color=place.color)
        _worktop_behind(b, layout.furniture["sink"])
        self._furniture = {so.name: (so.position, so.yaw) for so in b.objects}
        for kit_type, name, pos, yaw, color, parent in layout.decor:
            b.add_object(kit_type, name, pos=pos, yaw=yaw, color=color, parent=parent)
        b.add_agent_camera(AGENT, pos=layout.start_eye, fovy=FOVY)
        for o in spec.objects:
            otype = kit_or_ycb(o.type)
            if o.type in KIT_TYPES:
                color: str | tuple[float, ...] = _kit_color(otype.name, o.color)
            else:
                b.register_type(otype)
                color = COLORS[o.color][:3]
            b.add_object(otype.name, o.name, pos=(0.0, 0.0, -5.0), color=color, scale=OBJECT_SCALE, movable=True)
        return b.to_xml()

    def load(self, spec: TaskSpec) -> None:
        """Build (or reuse) the apartment of ``spec``: one compile per distinct scene."""
        key = (spec.apartment, tuple((o.name, o.type, o.color) for o in spec.objects))
        if key == self._key:
            return
        self.close()
        xml = self.scene_xml(spec)
        self._model = mujoco.MjModel.from_xml_string(xml)
        self._data = mujoco.MjData(self._model)
        mujoco.mj_forward(self._model, self._data)
        self._renderer = SceneRenderer(self._model, self._data, self.resolution, self.resolution)
        self._qpos_adr = {}
        for o in spec.objects:
            j = mujoco.mj_name2id(self._model, mujoco.mjtObj.mjOBJ_JOINT, f"{o.name}/free")
            self._qpos_adr[o.name] = int(self._model.jnt_qposadr[j])
        self._key = key

    # -- poses ----------------------------------------------------------------------------------------------

    def _local_to_world(self, instance: str, x: float, y: float, z: float) -> tuple[float, float, float]:
        (px, py, pz), yaw = self._furniture[instance]
        dx, dy = _rot(yaw, x, y)
        return px + dx, py + dy, pz + z

    def slot_position(self, key: str, slot: int, wide: bool = False) -> tuple[float, float, float]:
        """World position of slot ``slot`` of receptacle ``key`` in the current joint state (things in a drawer
        come out with it); ``wide``: a hard task's wide surfaces (:data:`_WIDE_POINTS`)."""
        g = _GEOMETRY[key]
        surface, dx, dy = _slot_point(key, slot, wide)
        s = _furniture_type(self._kit_type(g.instance)).surface(surface)
        x, y, z = surface_position(self._model, self._data, g.instance, s, offset=(dx, dy))
        return float(x), float(y), float(z)

    def _kit_type(self, instance: str) -> str:
        assert self._key is not None
        return LAYOUTS[self._key[0]].furniture[instance].kit_type

    def view(self, key: str | None) -> tuple[np.ndarray, np.ndarray]:
        """(eye, target) of the first-person camera at receptacle ``key`` (None: the starting spot)."""
        assert self._key is not None
        layout = LAYOUTS[self._key[0]]
        if key is None:
            return np.array(layout.start_eye), np.array(layout.start_target)
        g = _GEOMETRY[key]
        dist, eye_h, tx, ty, tz = g.view
        target = np.array(self._local_to_world(g.instance, tx, ty, 0.0))
        target[2] = tz
        _, yaw = self._furniture[g.instance]
        ex, ey = _rot(yaw + g.view_dir, dist, 0.0)
        eye = np.array([target[0] + ex, target[1] + ey, eye_h])
        return eye, target

    def _object_yaw(self, view_yaw: float, type_key: str, handle: str | None = None) -> float:
        if handle is not None:
            return view_yaw + 180.0 + HANDLE_YAW[handle]
        return view_yaw + 180.0 + _YAW.get(type_key, 0.0)

    def pose(self, world: World) -> None:
        """Set doors, drawers, the camera and every object from the symbolic ``world``."""
        m, d = self._model, self._data
        for r in RECEPTACLES:
            if r.articulated:
                g = _GEOMETRY[r.key]
                set_open(m, d, g.instance, 1.0 if r.key in world.opened else 0.0, part=g.part)
        eye, target = self.view(world.agent_at)
        fwd = target - eye
        yaw = math.degrees(math.atan2(fwd[1], fwd[0]))
        pitch = math.degrees(math.atan2(fwd[2], math.hypot(fwd[0], fwd[1])))
        set_agent_pose(m, d, AGENT, tuple(eye), yaw=yaw, pitch=pitch)
        self._camera = (eye, target)
        f = fwd / np.linalg.norm(fwd)
        right = np.cross(f, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, f)
        self._positions = {}
        for it in world.items.values():
            if it.loc == HAND:
                p = eye + f * 0.75 + right * 0.3 - up * 0.3
                pos, oyaw = tuple(float(v) for v in p), self._object_yaw(yaw, it.type)
                quat = _yaw_quat(oyaw)
            else:
                pos = self.slot_position(it.loc, it.slot, world.wide)
                g = _GEOMETRY[it.loc]
                _, fyaw = self._furniture[g.instance]
                oyaw = self._object_yaw(fyaw + g.view_dir + 180.0, it.type, it.handle)
                quat = _yaw_quat(oyaw)
                if g.lay_tall:
                    pos, quat = _lying(it.type, pos, fyaw + g.view_dir, quat)
            adr = self._qpos_adr[it.name]
            d.qpos[adr:adr + 3] = pos
            d.qpos[adr + 3:adr + 7] = quat
            self._positions[it.name] = tuple(float(v) for v in pos)
        mujoco.mj_forward(m, d)

    # -- images ---------------------------------------------------------------------------------------------

    def render(self, world: World) -> dict[str, np.ndarray]:
        """First-person RGB (and the overhead view when ``multi_view``) of ``world``; boxes are kept for
        :meth:`boxes`."""
        if self._renderer is None:
            raise RuntimeError("ApartmentRenderer.render() before load()")
        self.pose(world)
        images = {"first_person": self._renderer.rgb(AGENT)}
        self._boxes = {}
        if world.visible_items() or world.held is not None:  # the segmentation pass only matters with objects
            seg = self._renderer.segmentation(AGENT)
            self._boxes = {k: v for k, v in self._renderer.boxes_from_segmentation(seg, min_pixels=12).items()
                           if k in world.items}
        if self.multi_view:
            assert self._key is not None
            sx, sy = LAYOUTS[self._key[0]].size
            dist = (max(sx, sy) / 2 + 0.5) / math.tan(math.radians(FOVY / 2))
            cam = camera_from_eye((0.0, -0.01, dist), (0.0, 0.0, 0.0))
            images["overhead"] = self._renderer.rgb(cam, show_agents=True)
        return images

    def visible_shares(self, world: World, names: list[str]) -> dict[str, tuple[int, float]]:
        """Per object of ``names`` in the first-person view of ``world``: (its visible pixels, the share of its
        pixels that no other object covers, i.e. visible pixels over the pixels it shows when it is the only small
        object in the scene). Hard sets (version 7) refuse a counted object that others hide."""
        if self._renderer is None:
            raise RuntimeError("ApartmentRenderer.visible_shares() before load()")
        m, d = self._model, self._data
        self.pose(world)
        index = self._renderer.instance_names
        seg = self._renderer.segmentation(AGENT)
        full = {n: int((seg == index.index(n)).sum()) for n in names}
        saved = d.qpos.copy()
        out: dict[str, tuple[int, float]] = {}
        for n in names:
            for other, adr in self._qpos_adr.items():
                if other != n:
                    d.qpos[adr + 2] = -5.0
            mujoco.mj_forward(m, d)
            alone = int((self._renderer.segmentation(AGENT) == index.index(n)).sum())
            out[n] = (full[n], full[n] / alone if alone else 0.0)
            d.qpos[:] = saved
        mujoco.mj_forward(m, d)
        return out

    def boxes(self) -> dict[str, tuple[int, int, int, int]]:
        """Pixel boxes of the objects visible in the last first-person render."""
        return dict(self._boxes)

    def positions(self) -> dict[str, tuple[float, float, float]]:
        """World positions (metres) of the objects after the last render."""
        return dict(self._positions)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
        self._renderer = None
        self._model = self._data = None
        self._key = None

