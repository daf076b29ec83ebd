"""A navigation room: a scene kit room plus a task's extra objects, with the free space the agent walks on.

The room itself comes from :func:`eb_scenekit.rooms.generate_room` (``kind``, ``seed``): furniture, appliances,
clutter, a door and a window, all from the scene kit's object catalogue. A visual_appearance task adds one or
two objects of its target's type in other colours (:class:`ExtraSpec`), placed with the kit's
:class:`~eb_scenekit.scene.SceneBuilder`. Nothing here imports MuJoCo: geometry-only runs (``render: false``)
and the task generator's geometric checks never start a renderer.

Frame: the room is centred on the origin (the kit's convention), floor at ``z = 0``; the agent's lattice point
``(i, j)`` is at ``(0.25 i, 0.25 j)``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from eb_scenekit.objects import COLORS, get_type
from eb_scenekit.rooms import RoomLayout, generate_room
from eb_scenekit.scene import SceneObject

from eb_navigation.geometry import AGENT_RADIUS, GRID_RESOLUTION, FreeSpace

__all__ = ["ANTIALIAS", "CLUTTER", "KINDS", "ExtraSpec", "NavObject", "NavRoom", "colour_distance", "probe"]

KINDS: tuple[str, ...] = ("kitchen", "living_room", "bedroom", "bathroom")
CLUTTER = 8
"""Small objects the kit puts on the furniture (``generate_room(..., clutter=CLUTTER)``)."""
ANTIALIAS = 0
"""MSAA samples of the compiled rooms: 0 keeps a 500 x 500 render near 35 ms on the CPU rasteriser."""


@dataclass(frozen=True)
class ExtraSpec:
    """An object a task adds to the generated room, standing on the floor."""

    id: str
    type: str
    colour: str
    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class NavObject:
    """What navigation needs to know about one object of the room."""

    id: str
    type: str
    colour: str
    centre: tuple[float, float, float]
    on_floor: bool
    """Stands on the floor (furniture, appliances, plants) rather than on other furniture or a wall."""

    @property
    def x(self) -> float:
        return self.centre[0]

    @property
    def y(self) -> float:
        return self.centre[1]


def _nav_object(o: SceneObject) -> NavObject:
    centre = (round(o.position[0], 4), round(o.position[1], 4), round(o.position[2] + o.height / 2, 4))
    return NavObject(o.name, o.type, o.color, centre, o.parent is None and o.mount != "wall")


def colour_distance(a: str, b: str) -> float:
    """Euclidean distance of two kit colour names in RGB (0..~1.7); distractors differ by at least 0.35."""
    return float(np.linalg.norm(np.subtract(COLORS[a], COLORS[b])))


class NavRoom:
    """The kit room of ``(kind, seed)`` with ``extras`` added (``clutter``: small things the kit puts on the
    furniture; the classic tasks use :data:`CLUTTER`, the hard ones more).

    One room (and one compiled model) serves every task of a scene: the tasks without extras see the room with
    the extras hidden (:meth:`free_space` and :meth:`visible_objects` leave them out too).
    """

    def __init__(self, kind: str, seed: int, extras: Sequence[ExtraSpec] = (), clutter: int = CLUTTER) -> None:
        if kind not in KINDS:
            raise ValueError(f"unknown room kind {kind!r}; available: {', '.join(KINDS)}")
        self.kind, self.seed, self.clutter = kind, int(seed), int(clutter)
        self.layout: RoomLayout = generate_room(kind, self.seed, clutter=self.clutter, antialias=ANTIALIAS)
        self._base_grid = self.layout.free_space(GRID_RESOLUTION, AGENT_RADIUS)
        self.extras: tuple[ExtraSpec, ...] = tuple(extras)
        for e in self.extras:
            self.layout.builder.add_object(e.type, e.id, (e.x, e.y), yaw=e.yaw, color=e.colour)
        self.objects: tuple[NavObject, ...] = tuple(_nav_object(o) for o in self.layout.objects)
        self.index = {o.id: k for k, o in enumerate(self.objects)}
        self._free: dict[frozenset[str], FreeSpace] = {}
        self.has_agent_camera = False
        """Set by :class:`~eb_navigation.scene.RoomScene` once it has added the agent camera to the builder."""

    @property
    def size(self) -> tuple[float, float]:
        return self.layout.size

    @property
    def extra_ids(self) -> frozenset[str]:
        return frozenset(e.id for e in self.extras)

    def get(self, obj_id: str) -> NavObject:
        return self.objects[self.index[obj_id]]

    def counts(self, present: Iterable[str] = ()) -> dict[str, int]:
        """How many objects of each type are in the room (with the extras ``present``)."""
        out: dict[str, int] = {}
        keep = set(present)
        for o in self.objects:
            if o.id in self.extra_ids and o.id not in keep:
                continue
            out[o.type] = out.get(o.type, 0) + 1
        return out

    def visible_objects(self, present: Iterable[str] = ()) -> list[int]:
        """Indices of the objects in the room for a task whose extras are ``present`` (the others are hidden)."""
        keep = set(present)
        return [k for k, o in enumerate(self.objects) if o.id not in self.extra_ids or o.id in keep]

    def free_space(self, present: Iterable[str] = ()) -> FreeSpace:
        """Where the agent can stand with none or all of the extras present (the kit's occupancy grid)."""
        key = frozenset(present) & self.extra_ids
        if key and key != self.extra_ids:
            raise ValueError("a room's extras are either all present or all absent")
        fs = self._free.get(key)
        if fs is None:
            grid = self.layout.free_space(GRID_RESOLUTION, AGENT_RADIUS) if key else self._base_grid
            fs = self._free[key] = FreeSpace(grid, self.size, GRID_RESOLUTION)
        return fs


def probe(type_name: str, x: float, y: float, yaw: float) -> SceneObject:
    """A footprint-only :class:`SceneObject` of a type at a pose (to test overlaps before placing it)."""
    t = get_type(type_name)
    return SceneObject(name="_probe", type=type_name, category=t.category, color="", position=(x, y, 0.0), yaw=yaw,
                       half_extents=t.half_extents, height=t.height)
