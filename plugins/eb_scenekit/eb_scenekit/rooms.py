"""Procedural furnished rooms: kitchen, living room, bedroom, bathroom.

``generate_room(kind, seed)`` puts furniture against the walls (kitchen units in a row, a bed with night
stands, a sofa facing a TV, a desk with its chair ...), keeps the door and a walkable floor free, then puts small
objects on tables, counters, shelves and sometimes inside fridges and cabinets. Everything is drawn from one
seeded generator and rounded to millimetres, so the same (kind, seed) gives the same XML string byte for byte.
The returned :class:`RoomLayout` also answers navigation questions with an occupancy grid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from eb_scenekit.objects import get_type
from eb_scenekit.scene import WALLS, RoomKind, RoomShell, SceneBuilder, SceneObject, Wall

if TYPE_CHECKING:
    from mujoco import MjData, MjModel  # MuJoCo ships no type information: to the checker these are Any

__all__ = ["ROOM_KINDS", "RoomLayout", "generate_room"]

ROOM_KINDS: tuple[RoomKind, ...] = ("kitchen", "living_room", "bedroom", "bathroom")
_TALL = 1.1  # objects taller than this may not stand in front of a window

_SIZES = {
    "kitchen": ((4.2, 5.0), (3.8, 4.6)),
    "living_room": ((4.6, 5.6), (4.0, 5.0)),
    "bedroom": ((4.0, 4.8), (3.8, 4.6)),
    "bathroom": ((3.0, 3.6), (2.8, 3.3)),
}

# small objects per room kind: type -> receptacle types it may go on/in
_CLUTTER: dict[str, dict[str, tuple[str, ...]]] = {
    "kitchen": {
        "Apple": ("CounterTop", "DiningTable", "Table", "Fridge", "Bowl"), "Banana": ("CounterTop", "DiningTable",
                                                                                     "Table"),
        "Orange": ("CounterTop", "DiningTable", "Table", "Fridge"), "Bread": ("CounterTop", "DiningTable", "Table"),
        "Tomato": ("CounterTop", "Fridge", "DiningTable", "Table"), "Potato": ("CounterTop", "Fridge", "Table"),
        "Lettuce": ("CounterTop", "Fridge", "DiningTable"), "Egg": ("CounterTop", "Fridge", "DiningTable"),
        "WineBottle": ("CounterTop", "DiningTable", "Table", "Fridge"),
        "Mug": ("CounterTop", "DiningTable", "Table", "Cabinet", "Microwave"),
        "Cup": ("CounterTop", "DiningTable", "Table", "Cabinet"), "Bowl": ("CounterTop", "DiningTable", "Table"),
        "Plate": ("CounterTop", "DiningTable", "Table"), "Pot": ("Stove", "CounterTop"),
        "Pan": ("Stove", "CounterTop"), "Kettle": ("Stove", "CounterTop"), "Knife": ("CounterTop", "DiningTable"),
        "Spatula": ("CounterTop",), "Sponge": ("Sink", "CounterTop"), "SoapBottle": ("CounterTop",),
        "Vase": ("DiningTable", "Table"),
    },
    "living_room": {
        "RemoteControl": ("CoffeeTable", "Sofa", "TVStand", "ArmChair"), "Book": ("CoffeeTable", "Bookshelf",
                                                                                "SideTable", "Shelf"),
        "Vase": ("CoffeeTable", "SideTable", "TVStand", "Shelf"), "Laptop": ("CoffeeTable", "Sofa"),
        "CellPhone": ("CoffeeTable", "Sofa", "SideTable"), "KeyChain": ("CoffeeTable", "SideTable", "Shelf"),
        "Candle": ("CoffeeTable", "SideTable", "Shelf", "Bookshelf"), "Pillow": ("Sofa", "ArmChair"),
        "TeddyBear": ("Sofa", "ArmChair"), "Mug": ("CoffeeTable", "SideTable"), "Bowl": ("CoffeeTable",),
        "Box": ("Shelf",), "AlarmClock": ("SideTable", "Shelf", "Bookshelf"), "Apple": ("CoffeeTable",),
    },
    "bedroom": {
        "Pillow": ("Bed",), "TeddyBear": ("Bed", "Dresser"), "Book": ("Desk", "SideTable", "Bed", "Bookshelf",
                                                                      "Shelf"),
        "CellPhone": ("SideTable", "Desk", "Bed"), "Laptop": ("Desk", "Bed"), "KeyChain": ("Dresser", "Desk",
                                                                                          "SideTable"),
        "Pen": ("Desk",), "Mug": ("Desk", "SideTable"), "Candle": ("Dresser", "SideTable", "Shelf"),
        "Box": ("Dresser", "Shelf"), "RemoteControl": ("Bed", "Dresser", "SideTable"),
        "Vase": ("Dresser", "Shelf"), "AlarmClock": ("SideTable", "Desk", "Dresser"),
    },
    "bathroom": {
        "SoapBottle": ("Shelf", "Cabinet", "WashingMachine", "Bathtub"), "Towel": ("Shelf", "Cabinet",
                                                                                  "WashingMachine"),
        "Sponge": ("Bathtub", "Sink", "Shelf"), "Candle": ("Shelf", "Cabinet"), "Cup": ("Shelf", "Cabinet"),
        "Basket": ("WashingMachine", "Shelf"), "Vase": ("Shelf", "Cabinet"), "Book": ("Shelf",),
    },
}


@dataclass
class RoomLayout:
    """A generated room: its builder (add cameras/agents before building), objects, size and free floor space."""

    kind: RoomKind
    seed: int
    builder: SceneBuilder
    size: tuple[float, float]
    """Interior size (x, y) in metres; the room spans [-x/2, x/2] × [-y/2, y/2], floor at z = 0."""

    @property
    def objects(self) -> list[SceneObject]:
        """Every placed object (furniture, appliances, small objects, wall pictures)."""
        return self.builder.objects

    @property
    def room(self) -> RoomShell:
        assert self.builder.room is not None
        return self.builder.room

    @property
    def xml(self) -> str:
        """The MJCF of the current builder state."""
        return self.builder.to_xml()

    def build(self) -> tuple[MjModel, MjData]:
        """Compile: ``(mujoco.MjModel, mujoco.MjData)``."""
        return self.builder.build()

    def object(self, name: str) -> SceneObject:
        return self.builder.object(name)

    def objects_of_type(self, type_name: str) -> list[SceneObject]:
        return [o for o in self.objects if o.type == type_name]

    def children(self, name: str) -> list[SceneObject]:
        """Objects standing on or inside the given receptacle instance."""
        return [o for o in self.objects if o.parent == name]

    # ------------------------------------------------------------------ occupancy grid

    def grid_shape(self, resolution: float = 0.05) -> tuple[int, int]:
        return (int(math.ceil(self.size[0] / resolution - 1e-9)), int(math.ceil(self.size[1] / resolution - 1e-9)))

    def world_to_grid(self, x: float, y: float, resolution: float = 0.05) -> tuple[int, int]:
        """Grid cell ``(i, j)`` (x index, y index) containing world point (x, y)."""
        nx, ny = self.grid_shape(resolution)
        i = int(math.floor((x + self.size[0] / 2) / resolution))
        j = int(math.floor((y + self.size[1] / 2) / resolution))
        return min(max(i, 0), nx - 1), min(max(j, 0), ny - 1)

    def grid_to_world(self, i: int, j: int, resolution: float = 0.05) -> tuple[float, float]:
        """World (x, y) of the centre of grid cell ``(i, j)``."""
        return (-self.size[0] / 2 + (i + 0.5) * resolution, -self.size[1] / 2 + (j + 0.5) * resolution)

    def free_space(self, resolution: float = 0.05, agent_radius: float = 0.2) -> np.ndarray:
        """Boolean grid ``[i, j]`` (x index, y index): True where a disc of ``agent_radius`` fits on the floor.

        Blocked: within ``agent_radius`` of a wall or of the footprint of anything standing on the floor.
        Cell centres are given by :meth:`grid_to_world`.
        """
        return _free_grid(self.size, [o for o in self.objects if o.parent is None and o.mount != "wall"],
                          resolution, agent_radius)

    def reachable_space(self, start: Sequence[float], resolution: float = 0.05, agent_radius: float = 0.2
                        ) -> np.ndarray:
        """Free cells connected (4-neighbour) to the cell of world point ``start``."""
        free = self.free_space(resolution, agent_radius)
        return _flood(free, self.world_to_grid(start[0], start[1], resolution))

    def entrance(self, depth: float = 0.7) -> tuple[float, float, float]:
        """A pose ``(x, y, yaw_deg)`` just inside the door, facing the middle of the room."""
        d = self.room.door
        centre, along, normal = self.room.wall_frame(d.wall)
        p = centre + along * d.offset + normal * depth
        yaw = math.degrees(math.atan2(-p[1], -p[0]))
        return round(float(p[0]), 3), round(float(p[1]), 3), round(yaw, 2)


def _free_grid(size: tuple[float, float], obstacles: Sequence[SceneObject], res: float,
               radius: float) -> np.ndarray:
    nx, ny = int(math.ceil(size[0] / res - 1e-9)), int(math.ceil(size[1] / res - 1e-9))
    xs = -size[0] / 2 + (np.arange(nx) + 0.5) * res
    ys = -size[1] / 2 + (np.arange(ny) + 0.5) * res
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    free = (np.abs(gx) <= size[0] / 2 - radius) & (np.abs(gy) <= size[1] / 2 - radius)
    for o in obstacles:
        c, s = math.cos(math.radians(o.yaw)), math.sin(math.radians(o.yaw))
        dx, dy = gx - o.position[0], gy - o.position[1]
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        ex = np.maximum(np.abs(lx) - o.half_extents[0], 0.0)
        ey = np.maximum(np.abs(ly) - o.half_extents[1], 0.0)
        free &= ex * ex + ey * ey >= radius * radius
    return free


def _flood(free: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    reach = np.zeros_like(free)
    if not free[start]:
        return reach
    reach[start] = True
    while True:
        grown = reach.copy()
        grown[1:, :] |= reach[:-1, :]
        grown[:-1, :] |= reach[1:, :]
        grown[:, 1:] |= reach[:, :-1]
        grown[:, :-1] |= reach[:, 1:]
        grown &= free
        if (grown == reach).all():
            return reach
        reach = grown


# ---------------------------------------------------------------------------------------------------------------
# the generator


class _Planner:
    """Places furniture against walls while keeping the door clear and the free floor connected."""

    def __init__(self, b: SceneBuilder, room: RoomShell, rng: np.random.Generator) -> None:
        self.b = b
        self.room = room
        self.rng = rng
        d = room.door
        centre, along, normal = room.wall_frame(d.wall)
        p = centre + along * d.offset + normal * 0.5
        self.door_zone = _probe("door", p, math.degrees(math.atan2(normal[1], normal[0])), 0.5, d.width / 2 + 0.25)
        self.door_cell_xy = centre + along * d.offset + normal * 0.55
        self.floor: list[SceneObject] = []

    def _ok(self, cand: SceneObject, tall: bool, margin: float = 0.03, ignore: Sequence[SceneObject] = ()) -> bool:
        hx, hy = self.room.size[0] / 2, self.room.size[1] / 2
        x0, y0, x1, y1 = cand.aabb()
        if x0 < -hx - 1e-6 or x1 > hx + 1e-6 or y0 < -hy - 1e-6 or y1 > hy + 1e-6:
            return False
        if cand.overlaps(self.door_zone):
            return False
        ignored = {id(o) for o in ignore}
        if any(cand.overlaps(o, margin) for o in self.floor if id(o) not in ignored):
            return False
        if tall:
            for w in self.room.windows:
                centre, along, normal = self.room.wall_frame(w.wall)
                p = centre + along * w.offset + normal * 0.3
                if cand.overlaps(_probe("window", p, 0.0, 0.3 * abs(normal[0]) + w.width / 2 * abs(along[0]),
                                        0.3 * abs(normal[1]) + w.width / 2 * abs(along[1]))):
                    return False
        # the free floor must stay in one piece (reachable from the door)
        res, radius = 0.1, 0.22
        floor = self.floor + [cand]
        free = _free_grid(self.room.size, floor, res, radius)
        i = int((self.door_cell_xy[0] + self.room.size[0] / 2) / res)
        j = int((self.door_cell_xy[1] + self.room.size[1] / 2) / res)
        i, j = min(max(i, 0), free.shape[0] - 1), min(max(j, 0), free.shape[1] - 1)
        reach = _flood(free, (i, j))
        return bool(reach.sum() >= 0.92 * free.sum() and reach.sum() > 0)

    def wall_slot(self, type_name: str, wall: Wall, t: float, gap: float = 0.02) -> tuple[float, float, float]:
        """(x, y, yaw) of an object with its back against ``wall`` at offset ``t`` along it."""
        ot = get_type(type_name)
        centre, along, normal = self.room.wall_frame(wall)
        p = centre + along * t + normal * (ot.half_extents[0] + gap)
        yaw = math.degrees(math.atan2(normal[1], normal[0]))
        return round(float(p[0]), 3), round(float(p[1]), 3), round(yaw, 1)

    def try_place(self, type_name: str, x: float, y: float, yaw: float, name: str | None = None,
                  color: str | None = None, ignore: Sequence[SceneObject] = ()) -> SceneObject | None:
        ot = get_type(type_name)
        cand = _probe(type_name, (x, y), yaw, *ot.half_extents)
        if not self._ok(cand, ot.height > _TALL, ignore=ignore):
            return None
        if color is None:
            color = list(ot.colors)[int(self.rng.integers(len(ot.colors)))]
        obj = self.b.add_object(type_name, name, (x, y), yaw=yaw, color=color)
        self.floor.append(obj)
        return obj

    def against_wall(self, type_name: str, walls: Sequence[Wall] | None = None, tries: int = 40,
                     color: str | None = None) -> SceneObject | None:
        ot = get_type(type_name)
        walls = list(walls) if walls else ["north", "south", "east", "west"]
        for _ in range(tries):
            wall = walls[int(self.rng.integers(len(walls)))]
            lim = self.room.wall_length(wall) / 2 - ot.half_extents[1] - 0.03
            if lim < 0:
                continue
            t = round(float(self.rng.uniform(-lim, lim)), 3)
            obj = self.try_place(type_name, *self.wall_slot(type_name, wall, t), color=color)
            if obj is not None:
                return obj
        return None

    def run(self, types: Sequence[str], tries: int = 30) -> list[SceneObject]:
        """Place a row of units side by side against one wall (a kitchen run); returns what was placed."""
        walls: list[Wall] = ["north", "south", "east", "west"]
        widths = [2 * get_type(t).half_extents[1] for t in types]
        total = sum(widths)
        for _ in range(tries):
            wall = walls[int(self.rng.integers(4))]
            length = self.room.wall_length(wall)
            if total > length - 0.06:
                continue
            start = round(float(self.rng.uniform(-length / 2 + 0.03, length / 2 - 0.03 - total)), 3)
            placed: list[SceneObject] = []
            t = start
            ok = True
            for typ, w in zip(types, widths):
                x, y, yaw = self.wall_slot(typ, wall, t + w / 2)
                ot = get_type(typ)
                cand = _probe(typ, (x, y), yaw, *ot.half_extents)
                if not self._ok(cand, ot.height > _TALL, margin=0.0):
                    ok = False
                    break
                self.floor.append(cand)
                placed.append(cand)
                t += w + 0.005
            for cand in placed:
                self.floor.remove(cand)
            if ok:
                color = None
                out = []
                for cand in placed:
                    ot = get_type(cand.type)
                    if color is None or color not in ot.colors:
                        color = list(ot.colors)[int(self.rng.integers(len(ot.colors)))]
                    obj = self.b.add_object(cand.type, None, cand.position[:2], yaw=cand.yaw, color=color)
                    self.floor.append(obj)
                    out.append(obj)
                return out
        return []

    def in_front_of(self, anchor: SceneObject, type_name: str, distance: float, facing: Literal["toward", "away"],
                    lateral: float = 0.0, color: str | None = None, tuck: bool = False) -> SceneObject | None:
        """Place an object ``distance`` metres in front of ``anchor``'s front (e.g. a chair at a desk)."""
        ot = get_type(type_name)
        a = math.radians(anchor.yaw)
        fwd = np.array([math.cos(a), math.sin(a)])
        side = np.array([-math.sin(a), math.cos(a)])
        p = np.array(anchor.position[:2]) + fwd * (anchor.half_extents[0] + distance + ot.half_extents[0]) \
            + side * lateral
        yaw = anchor.yaw + (180.0 if facing == "toward" else 0.0)
        yaw = ((yaw + 180.0) % 360.0) - 180.0
        return self.try_place(type_name, round(float(p[0]), 3), round(float(p[1]), 3), round(yaw, 1), color=color,
                              ignore=[anchor] if tuck else [])

    def beside(self, anchor: SceneObject, type_name: str, side: int, gap: float = 0.08) -> SceneObject | None:
        """Place an object next to ``anchor`` along the same wall (side = +1 left / -1 right of its front)."""
        ot = get_type(type_name)
        a = math.radians(anchor.yaw)
        fwd = np.array([math.cos(a), math.sin(a)])
        lat = np.array([-math.sin(a), math.cos(a)])
        p = np.array(anchor.position[:2]) - fwd * (anchor.half_extents[0] - ot.half_extents[0]) \
            + lat * side * (anchor.half_extents[1] + gap + ot.half_extents[1])
        return self.try_place(type_name, round(float(p[0]), 3), round(float(p[1]), 3), anchor.yaw)


def _probe(type_name: str, xy: Sequence[float] | np.ndarray, yaw: float, hx: float, hy: float) -> SceneObject:
    return SceneObject(name="_probe", type=type_name, category="", color="", position=(float(xy[0]), float(xy[1]), 0.0),
                       yaw=float(yaw), half_extents=(float(hx), float(hy)), height=0.0)


def _put_on(b: SceneBuilder, rng: np.random.Generator, type_name: str, parent: SceneObject,
            surface: str | None = None, tries: int = 25, color: str | None = None,
            yaw: float | None = None) -> SceneObject | None:
    """Put a small object at a random free spot of a receptacle's surface; None if it does not fit."""
    ot, pt = get_type(type_name), get_type(parent.type)
    surf = pt.surface(surface)
    if surf.clearance is not None and ot.height > surf.clearance * parent.scale:
        return None
    siblings = [o for o in b.objects if o.parent == parent.name and o.surface == surf.name]
    for _ in range(tries):
        rel = yaw if yaw is not None else round(float(rng.choice([0.0, 90.0, 180.0, -90.0]) +
                                                      rng.uniform(-20, 20)), 1)
        r = math.radians(rel)
        ex = abs(math.cos(r)) * ot.half_extents[0] + abs(math.sin(r)) * ot.half_extents[1]
        ey = abs(math.sin(r)) * ot.half_extents[0] + abs(math.cos(r)) * ot.half_extents[1]
        mx, my = surf.half_extents[0] * parent.scale - ex, surf.half_extents[1] * parent.scale - ey
        if mx < 0 or my < 0:
            if surf.inside and mx > -0.03 and my > -0.03:  # a bowl may take an apple that overhangs a little
                mx, my = max(mx, 0.0), max(my, 0.0)
            else:
                return None
        dx = round(float(rng.uniform(-mx, mx)), 3)
        dy = round(float(rng.uniform(-my, my)), 3)
        a = math.radians(parent.yaw)
        lx, ly = surf.center[0] * parent.scale + dx, surf.center[1] * parent.scale + dy
        wx = parent.position[0] + math.cos(a) * lx - math.sin(a) * ly
        wy = parent.position[1] + math.sin(a) * lx + math.cos(a) * ly
        cand = _probe(type_name, (wx, wy), parent.yaw + rel, *ot.half_extents)
        if any(cand.overlaps(s, 0.01) for s in siblings):
            continue
        if color is None:
            color = list(ot.colors)[int(rng.integers(len(ot.colors)))]
        return b.add_object(type_name, None, (dx, dy), yaw=rel, color=color, parent=parent.name, surface=surf.name)
    return None


def _painting(b: SceneBuilder, planner: _Planner, rng: np.random.Generator) -> SceneObject | None:
    room = planner.room
    ot = get_type("Painting")
    blocked_walls = {planner.room.door.wall} | {w.wall for w in room.windows}
    walls = [w for w in WALLS if w not in blocked_walls] or list(WALLS)
    for _ in range(30):
        wall = walls[int(rng.integers(len(walls)))]
        lim = room.wall_length(wall) / 2 - ot.half_extents[1] - 0.2
        if lim <= 0:
            continue
        t = round(float(rng.uniform(-lim, lim)), 3)
        x, y, yaw = planner.wall_slot("Painting", wall, t, gap=0.0)
        cand = _probe("Painting", (x, y), yaw, 0.3, ot.half_extents[1])
        if any(cand.overlaps(o) and o.height > 1.2 for o in planner.floor):
            continue
        if cand.overlaps(planner.door_zone):
            continue
        color = list(ot.colors)[int(rng.integers(len(ot.colors)))]
        return b.add_object("Painting", None, (x, y, 1.3), yaw=yaw, color=color)
    return None


def _floor_extra(planner: _Planner, types: Sequence[str]) -> None:
    for t in types:
        planner.against_wall(t, tries=25)


def _kitchen(b: SceneBuilder, p: _Planner, rng: np.random.Generator) -> None:
    run1 = ["Fridge", "CounterTop", "Stove"] if rng.uniform() < 0.5 else ["Stove", "CounterTop", "Fridge"]
    placed = p.run(run1) or p.run(["Fridge", "Stove"]) or []
    if not placed:
        p.against_wall("Fridge")
        p.against_wall("Stove")
    run2 = ["CounterTop", "Sink", "CounterTop"] if rng.uniform() < 0.5 else ["Sink", "CounterTop"]
    if not p.run(run2):
        p.run(["Sink", "CounterTop"]) or p.against_wall("Sink")
    if rng.uniform() < 0.6:
        p.against_wall("Cabinet")
    counters = [o for o in b.objects if o.type == "CounterTop"]
    # a table in the middle, chairs around it
    table_type = "DiningTable" if min(p.room.size) > 4.0 else "Table"
    for _ in range(30):
        x = round(float(rng.uniform(-0.6, 0.6)), 3)
        y = round(float(rng.uniform(-0.6, 0.6)), 3)
        yaw = float(rng.choice([0.0, 90.0]))
        table = p.try_place(table_type, x, y, yaw)
        if table is not None:
            break
    else:
        table = None
    if table is not None:
        chair_color = list(get_type("Chair").colors)[int(rng.integers(4))]
        for side in (1, -1):
            for lateral in ((-0.35, 0.35) if table_type == "DiningTable" else (0.0,)):
                _chair_at(p, table, side, lateral, chair_color)
    _floor_extra(p, ["GarbageCan"])
    # appliances on the counters
    for app in ("Microwave", "Toaster" if rng.uniform() < 0.5 else "CoffeeMachine"):
        for c in rng.permutation(len(counters)) if counters else []:
            if _put_on(b, rng, app, counters[int(c)], yaw=0.0) is not None:
                break


def _chair_at(p: _Planner, table: SceneObject, side: int, lateral: float, color: str) -> SceneObject | None:
    # chairs stand along the table's long (y) sides, facing it
    a = math.radians(table.yaw)
    fwd = np.array([math.cos(a), math.sin(a)]) * side
    lat = np.array([-math.sin(a), math.cos(a)])
    ot = get_type("Chair")
    pos = np.array(table.position[:2]) + fwd * (table.half_extents[0] + ot.half_extents[0] - 0.08) + lat * lateral
    yaw = math.degrees(math.atan2(-fwd[1], -fwd[0]))
    return p.try_place("Chair", round(float(pos[0]), 3), round(float(pos[1]), 3), round(yaw, 1), color=color,
                       ignore=[table])


def _against_wall_with_room(p: _Planner, type_name: str, side_space: float) -> SceneObject | None:
    """Against a wall, leaving ``side_space`` metres free on both sides along the wall when possible."""
    ot = get_type(type_name)
    walls: list[Wall] = ["north", "south", "east", "west"]
    for _ in range(40):
        wall = walls[int(p.rng.integers(4))]
        lim = p.room.wall_length(wall) / 2 - ot.half_extents[1] - side_space
        if lim < 0:
            continue
        t = round(float(p.rng.uniform(-lim, lim)), 3)
        obj = p.try_place(type_name, *p.wall_slot(type_name, wall, t))
        if obj is not None:
            return obj
    return p.against_wall(type_name)


def _living_room(b: SceneBuilder, p: _Planner, rng: np.random.Generator) -> None:
    sofa = _against_wall_with_room(p, "Sofa", 0.5)
    if sofa is not None:
        p.in_front_of(sofa, "CoffeeTable", 0.4, "away")
        # TV on the opposite wall, facing the sofa
        a = math.radians(sofa.yaw)
        opposite: dict[Wall, Wall] = {"north": "south", "south": "north", "east": "west", "west": "east"}
        wall = _wall_facing(p.room, (math.cos(a), math.sin(a)))
        ot = get_type("TVStand")
        lim = p.room.wall_length(opposite[wall]) / 2 - ot.half_extents[1] - 0.05
        along_sofa = sofa.position[0] if opposite[wall] in ("north", "south") else sofa.position[1]
        tv = None
        for t in (along_sofa, *[float(v) for v in rng.uniform(-lim, lim, 12)]):
            if abs(t) <= lim:
                tv = p.try_place("TVStand", *p.wall_slot("TVStand", opposite[wall], round(t, 3)))
                if tv is not None:
                    break
        if tv is None:
            tv = p.against_wall("TVStand")
        if tv is not None:
            _put_on(b, rng, "Television", tv, yaw=0.0)
        side = p.beside(sofa, "SideTable", int(rng.choice([-1, 1])))
        if side is not None:
            _put_on(b, rng, "DeskLamp", side, yaw=0.0)
    p.against_wall("ArmChair")
    p.against_wall("Bookshelf")
    if rng.uniform() < 0.6:
        p.against_wall("Shelf")
    _floor_extra(p, ["FloorLamp", "HousePlant"] + (["Basket"] if rng.uniform() < 0.5 else []))


def _bedroom(b: SceneBuilder, p: _Planner, rng: np.random.Generator) -> None:
    bed = _against_wall_with_room(p, "Bed", 0.55)
    if bed is not None:
        for side in (1, -1):
            st = p.beside(bed, "SideTable", side)
            if st is not None:
                _put_on(b, rng, "DeskLamp" if side == 1 else "AlarmClock", st, yaw=0.0)
    desk = p.against_wall("Desk")
    if desk is not None:
        p.in_front_of(desk, "Chair", -0.15, "toward", lateral=-0.15, tuck=True)
    p.against_wall("Dresser")
    p.against_wall("Bookshelf" if rng.uniform() < 0.5 else "Shelf")
    _floor_extra(p, ["FloorLamp", "GarbageCan"] + (["BasketBall"] if rng.uniform() < 0.6 else ["HousePlant"]))


def _bathroom(b: SceneBuilder, p: _Planner, rng: np.random.Generator) -> None:
    p.against_wall("Bathtub")
    p.against_wall("Toilet")
    p.against_wall("Sink")
    p.against_wall("WashingMachine")
    p.against_wall("Shelf" if rng.uniform() < 0.5 else "Cabinet")
    _floor_extra(p, ["GarbageCan"] + (["HousePlant"] if rng.uniform() < 0.5 else []))


def _wall_facing(room: RoomShell, direction: Sequence[float]) -> Wall:
    """The wall whose inward normal is most opposite to ``direction`` (i.e. the wall an object with this front
    direction stands against)."""
    best: Wall = "north"
    score = -2.0
    for w in WALLS:
        _, _, n = room.wall_frame(w)
        s = float(n[0] * direction[0] + n[1] * direction[1])
        if s > score:
            best, score = w, s
    return best


_FURNISH = {"kitchen": _kitchen, "living_room": _living_room, "bedroom": _bedroom, "bathroom": _bathroom}


def generate_room(kind: RoomKind, seed: int, clutter: int = 8, *, shadows: bool = False,
                  antialias: int = 4) -> RoomLayout:
    """Generate a furnished room.

    Args:
        kind: ``"kitchen"``, ``"living_room"``, ``"bedroom"`` or ``"bathroom"``.
        seed: any integer; the same (kind, seed, clutter) always gives the same XML.
        clutter: how many small objects to put on/in the furniture (fewer if they do not fit).
        shadows, antialias: rendering options passed to :class:`~eb_scenekit.scene.SceneBuilder`.

    Returns:
        A :class:`RoomLayout` whose builder also has an ``"overhead"`` camera looking straight down.
    """
    if kind not in _FURNISH:
        raise ValueError(f"unknown room kind {kind!r}; available: {', '.join(ROOM_KINDS)}")
    rng = np.random.default_rng([ROOM_KINDS.index(kind) + 1, int(seed), 0x5CE7E])
    (x0, x1), (y0, y1) = _SIZES[kind]
    size = (round(float(rng.uniform(x0, x1)), 2), round(float(rng.uniform(y0, y1)), 2))
    b = SceneBuilder(name=f"{kind}_{seed}", shadows=shadows, antialias=antialias)
    rug = None
    if kind in ("living_room", "bedroom"):
        rug = (round(size[0] * 0.22, 2), round(size[1] * 0.18, 2))
    room = b.add_room(kind, size, seed=int(rng.integers(1 << 30)), rug=rug)
    planner = _Planner(b, room, rng)
    _FURNISH[kind](b, planner, rng)
    if kind != "bathroom" or rng.uniform() < 0.5:
        _painting(b, planner, rng)
    # small objects on the furniture
    pool = _CLUTTER[kind]
    counts: dict[str, int] = {}
    placed = 0
    attempts = 0
    while placed < clutter and attempts < clutter * 8:
        attempts += 1
        typ = list(pool)[int(rng.integers(len(pool)))]
        if counts.get(typ, 0) >= 2:
            continue
        parents = [o for o in b.objects if o.type in pool[typ] and get_type(o.type).receptacle and o.parent is None
                   or (o.type in pool[typ] and o.type in ("Bowl", "Microwave"))]
        if not parents:
            continue
        parent = parents[int(rng.integers(len(parents)))]
        # surfaces carried by a drawer are left empty: a closed drawer would hide whatever is put in it
        surfaces = [s for s in get_type(parent.type).surfaces if s.part is None]
        # mostly on top; sometimes inside (fridge shelves, cabinets, microwave)
        on_top = [s for s in surfaces if not s.inside]
        inside = [s for s in surfaces if s.inside]
        if parent.type == "Fridge":
            surf = inside[int(rng.integers(len(inside)))]
        elif on_top and (not inside or rng.uniform() < 0.8):
            surf = on_top[int(rng.integers(len(on_top)))]
        else:
            surf = inside[int(rng.integers(len(inside)))]
        obj = _put_on(b, rng, typ, parent, surf.name)
        if obj is not None:
            placed += 1
            counts[typ] = counts.get(typ, 0) + 1
    half = max(size) / 2
    b.add_camera("overhead", (0.0, 0.0, round(half / math.tan(math.radians(22.5)) + 0.6, 3)),
                 xyaxes=(1, 0, 0, 0, 1, 0), fovy=45)
    return RoomLayout(kind=kind, seed=int(seed), builder=b, size=size)
