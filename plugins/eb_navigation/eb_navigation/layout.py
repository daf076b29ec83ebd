"""Procedural rooms: a furnished, cluttered room of one of four kinds from ``(kind, seed)``.

A :class:`Layout` is plain data (room size, wall and floor look, placed objects, wall decor) made
deterministically from the kind and the seed. Everything else is derived from it: the MuJoCo model
(:mod:`eb_navigation.mjcf`), the free-space grid the agent moves on and the oracle plans over
(:mod:`eb_navigation.geometry`). Pure Python + numpy; no MuJoCo.

Frame: the room spans ``x in [0, width]``, ``y in [0, depth]``, floor at ``z = 0``. An object's yaw is
a number of quarter turns counter-clockwise; at yaw 0 its front faces ``+y``.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, replace
from typing import Iterable, Literal

import numpy as np

from eb_navigation.catalogue import get_type

__all__ = ["KINDS", "LAYOUT_VERSION", "Decor", "Layout", "Placed", "generate_layout", "place_extra"]

#: Bump when a change to this module or the catalogue changes the room a ``(kind, seed)`` gives.
LAYOUT_VERSION = 1

Kind = Literal["kitchen", "living_room", "bedroom", "bathroom"]
KINDS: tuple[str, ...] = ("kitchen", "living_room", "bedroom", "bathroom")

WALL_HEIGHT = 2.6
_FRONT = {0: (0.0, 1.0), 1: (-1.0, 0.0), 2: (0.0, -1.0), 3: (1.0, 0.0)}
"""Direction the object's front faces, per yaw."""
_WALL_YAW = {0: 0, 1: 1, 2: 2, 3: 3}
"""Wall index -> yaw of an object standing against it (south y=0, east x=W, north y=D, west x=0)."""

Box = tuple[float, float, float, float]


@dataclass(frozen=True)
class Placed:
    """One object in a room."""

    id: str
    """Unique instance id, e.g. ``fridge_1``."""
    type: str
    colour: str
    x: float
    y: float
    z: float = 0.0
    """Height of the object's base (0 on the floor, the host's top for things standing on furniture)."""
    yaw: int = 0
    on: str | None = None
    """Id of the furniture this object stands on, if any."""
    variant: int = 0
    """Seed for the object's own random details (book colours, leaf angles)."""

    @property
    def size(self) -> tuple[float, float, float]:
        w, d, h = get_type(self.type).size
        return (d, w, h) if self.yaw % 2 else (w, d, h)

    @property
    def footprint(self) -> Box:
        sx, sy, _ = self.size
        return (self.x - sx / 2, self.y - sy / 2, self.x + sx / 2, self.y + sy / 2)

    @property
    def centre(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z + self.size[2] / 2)

    @property
    def obstacle(self) -> bool:
        return self.on is None and get_type(self.type).obstacle

    def to_dict(self) -> dict:
        return {"id": self.id, "type": self.type, "colour": self.colour, "x": self.x, "y": self.y, "z": self.z,
                "yaw": self.yaw, "on": self.on, "variant": self.variant}


@dataclass(frozen=True)
class Decor:
    """A flat thing on a wall: ``door``, ``window`` or ``painting``."""

    kind: str
    wall: int
    along: float
    """Centre position along the wall (x for south/north walls, y for east/west)."""
    bottom: float
    width: float
    height: float
    colour: tuple[float, float, float] = (0.5, 0.5, 0.5)


@dataclass(frozen=True)
class Layout:
    kind: str
    seed: int
    width: float
    depth: float
    wall_rgb: tuple[float, float, float]
    floor: tuple[str, tuple[float, float, float], tuple[float, float, float]]
    """Floor style (``tiles`` or ``planks``) and its two colours."""
    objects: tuple[Placed, ...]
    decor: tuple[Decor, ...] = ()

    def get(self, obj_id: str) -> Placed:
        for o in self.objects:
            if o.id == obj_id:
                return o
        raise KeyError(f"no object {obj_id!r} in {self.kind} scene {self.seed}")

    def obstacles(self) -> list[Box]:
        return [o.footprint for o in self.objects if o.obstacle]

    def with_objects(self, extra: Iterable[Placed]) -> "Layout":
        return replace(self, objects=self.objects + tuple(extra))


# ----------------------------------------------------------------------------------------------------


def _overlaps(a: Box, b: Box, margin: float = 0.0) -> bool:
    return a[0] < b[2] + margin and b[0] < a[2] + margin and a[1] < b[3] + margin and b[1] < a[3] + margin


class _Placer:
    """Rejection sampling of furniture against walls, in the open and on top of other furniture."""

    def __init__(self, kind: str, width: float, depth: float, rng: np.random.Generator,
                 objects: Iterable[Placed] = ()) -> None:
        self.kind, self.W, self.D, self.rng = kind, width, depth, rng
        self.objects: list[Placed] = []
        self.solid: list[Box] = []
        self.reserved: list[Box] = []
        self.counts: dict[str, int] = {}
        self.surface_use: dict[str, list[Box]] = {}
        for o in objects:
            self._add(o, clearance=0.0)

    # -- bookkeeping
    def _new_id(self, type_name: str) -> str:
        n = self.counts.get(type_name, 0) + 1
        self.counts[type_name] = n
        return f"{type_name}_{n}"

    def _add(self, obj: Placed, clearance: float) -> Placed:
        self.objects.append(obj)
        base, _, num = obj.id.rpartition("_")
        if num.isdigit():
            self.counts[base] = max(self.counts.get(base, 0), int(num))
        if obj.obstacle:
            self.solid.append(obj.footprint)
            if clearance > 0:
                self.reserved.append(self._front_zone(obj, clearance))
        return obj

    def _front_zone(self, obj: Placed, depth: float) -> Box:
        fx, fy = _FRONT[obj.yaw % 4]
        x0, y0, x1, y1 = obj.footprint
        if fx > 0:
            return (x1, y0, x1 + depth, y1)
        if fx < 0:
            return (x0 - depth, y0, x0, y1)
        if fy > 0:
            return (x0, y1, x1, y1 + depth)
        return (x0, y0 - depth, x1, y0)

    def fits(self, box: Box, margin: float = 0.05, front: Box | None = None) -> bool:
        x0, y0, x1, y1 = box
        if x0 < -1e-9 or y0 < -1e-9 or x1 > self.W + 1e-9 or y1 > self.D + 1e-9:
            return False
        if any(_overlaps(box, s, margin) for s in self.solid):
            return False
        if any(_overlaps(box, r, -0.01) for r in self.reserved):
            return False
        if front is not None and any(_overlaps(front, s, -0.01) for s in self.solid):
            return False
        return True

    # -- placement
    def reserve(self, box: Box) -> None:
        self.reserved.append(box)

    def against_wall(self, type_name: str, colour: str | None = None, wall: int | None = None,
                     along: float | None = None, clearance: float = 0.6, gap: float = 0.03,
                     tries: int = 60, margin: float = 0.05) -> Placed | None:
        t = get_type(type_name)
        w, d, _ = t.size
        for _ in range(tries):
            s = int(self.rng.integers(4)) if wall is None else wall
            length = self.W if s in (0, 2) else self.D
            if length < w + 0.1:
                continue
            a = float(self.rng.uniform(w / 2 + 0.05, length - w / 2 - 0.05)) if along is None else along
            if s == 0:
                x, y = a, d / 2 + gap
            elif s == 2:
                x, y = a, self.D - d / 2 - gap
            elif s == 3:
                x, y = d / 2 + gap, a
            else:
                x, y = self.W - d / 2 - gap, a
            obj = Placed(self._new_id(type_name), type_name, colour or self._colour(type_name), round(x, 3),
                         round(y, 3), 0.0, _WALL_YAW[s], variant=int(self.rng.integers(1 << 30)))
            front = self._front_zone(obj, clearance) if clearance > 0 else None
            if self.fits(obj.footprint, margin, front):
                return self._add(obj, clearance)
            self.counts[type_name] -= 1
            if along is not None and wall is not None:
                return None
        return None

    def in_open(self, type_name: str, colour: str | None = None, region: Box | None = None,
                yaw: int | None = None, margin: float = 0.55, tries: int = 60) -> Placed | None:
        """Free-standing, at least ``margin`` from everything else (so the agent can walk around)."""
        t = get_type(type_name)
        for _ in range(tries):
            q = int(self.rng.integers(4)) if yaw is None else yaw
            w, d = (t.size[1], t.size[0]) if q % 2 else (t.size[0], t.size[1])
            rx0, ry0, rx1, ry1 = region or (0.0, 0.0, self.W, self.D)
            lo_x, hi_x = max(rx0, 0.0) + w / 2 + 0.05, min(rx1, self.W) - w / 2 - 0.05
            lo_y, hi_y = max(ry0, 0.0) + d / 2 + 0.05, min(ry1, self.D) - d / 2 - 0.05
            if lo_x > hi_x or lo_y > hi_y:
                return None
            x, y = float(self.rng.uniform(lo_x, hi_x)), float(self.rng.uniform(lo_y, hi_y))
            obj = Placed(self._new_id(type_name), type_name, colour or self._colour(type_name), round(x, 3),
                         round(y, 3), 0.0, q, variant=int(self.rng.integers(1 << 30)))
            if self.fits(obj.footprint, margin):
                return self._add(obj, 0.0)
            self.counts[type_name] -= 1
        return None

    def at(self, type_name: str, x: float, y: float, yaw: int, colour: str | None = None,
           margin: float = 0.05, clearance: float = 0.0, ignore_reserved: bool = False) -> Placed | None:
        obj = Placed(self._new_id(type_name), type_name, colour or self._colour(type_name), round(x, 3), round(y, 3),
                     0.0, yaw % 4, variant=int(self.rng.integers(1 << 30)))
        saved = self.reserved
        if ignore_reserved:
            self.reserved = []
        try:
            ok = self.fits(obj.footprint, margin)
        finally:
            self.reserved = saved
        if ok:
            return self._add(obj, clearance)
        self.counts[type_name] -= 1
        return None

    def decal(self, type_name: str, x: float, y: float, yaw: int, colour: str | None = None) -> Placed:
        """A flat thing on the floor (a rug): never an obstacle, so nothing is checked but the walls."""
        obj = Placed(self._new_id(type_name), type_name, colour or self._colour(type_name), round(x, 3), round(y, 3),
                     0.0, yaw % 4, variant=int(self.rng.integers(1 << 30)))
        x0, y0, x1, y1 = obj.footprint
        obj = replace(obj, x=round(min(max(x, (x1 - x0) / 2 + 0.05), self.W - (x1 - x0) / 2 - 0.05), 3),
                      y=round(min(max(y, (y1 - y0) / 2 + 0.05), self.D - (y1 - y0) / 2 - 0.05), 3))
        return self._add(obj, 0.0)

    def on_top(self, type_name: str, host: Placed, colour: str | None = None, tries: int = 30,
               toward_front: bool = True) -> Placed | None:
        """Stand a small object on ``host``'s top, facing the same way as the host."""
        t = get_type(type_name)
        ht = get_type(host.type)
        if ht.surface is None:
            return None
        top_h = ht.surface
        w, d = (t.size[1], t.size[0]) if host.yaw % 2 else (t.size[0], t.size[1])
        hx0, hy0, hx1, hy1 = host.footprint
        used = self.surface_use.setdefault(host.id, [])
        for _ in range(tries):
            x = float(self.rng.uniform(hx0 + w / 2 + 0.03, max(hx0 + w / 2 + 0.03, hx1 - w / 2 - 0.03)))
            y = float(self.rng.uniform(hy0 + d / 2 + 0.03, max(hy0 + d / 2 + 0.03, hy1 - d / 2 - 0.03)))
            if toward_front:  # push it to the host's front edge
                fx, fy = _FRONT[host.yaw % 4]
                if fx:
                    x = (hx1 - w / 2 - 0.04) if fx > 0 else (hx0 + w / 2 + 0.04)
                if fy:
                    y = (hy1 - d / 2 - 0.04) if fy > 0 else (hy0 + d / 2 + 0.04)
            box = (x - w / 2, y - d / 2, x + w / 2, y + d / 2)
            if any(_overlaps(box, u, 0.05) for u in used):
                continue
            used.append(box)
            obj = Placed(self._new_id(type_name), type_name, colour or self._colour(type_name), round(x, 3),
                         round(y, 3), top_h, host.yaw, on=host.id, variant=int(self.rng.integers(1 << 30)))
            return self._add(obj, 0.0)
        return None

    def _colour(self, type_name: str) -> str:
        cols = get_type(type_name).colours
        return cols[int(self.rng.integers(len(cols)))]

    def facing_point(self, obj_type: str, px: float, py: float, dist: float, side: int,
                     colour: str | None = None) -> Placed | None:
        """Put ``obj_type`` ``dist`` metres from (px, py) on ``side`` (a yaw), turned to face the point."""
        fx, fy = _FRONT[(side + 2) % 4]  # direction from the point to the object
        x, y = px - fx * dist, py - fy * dist
        return self.at(obj_type, x, y, side, colour)


# ----------------------------------------------------------------------------------------------------

_WALLS = {
    "kitchen": [(0.86, 0.78, 0.56), (0.70, 0.80, 0.68), (0.66, 0.76, 0.86), (0.88, 0.70, 0.58)],
    "living_room": [(0.82, 0.74, 0.60), (0.68, 0.78, 0.70), (0.64, 0.72, 0.84), (0.84, 0.68, 0.64)],
    "bedroom": [(0.76, 0.70, 0.86), (0.88, 0.74, 0.64), (0.66, 0.78, 0.86), (0.80, 0.80, 0.66)],
    "bathroom": [(0.62, 0.80, 0.86), (0.72, 0.84, 0.74), (0.84, 0.74, 0.80), (0.68, 0.72, 0.86)],
}
_FLOORS = {
    "kitchen": [("tiles", (0.80, 0.80, 0.77), (0.68, 0.68, 0.66)), ("tiles", (0.78, 0.70, 0.58), (0.68, 0.58, 0.48)),
                ("tiles", (0.80, 0.80, 0.80), (0.60, 0.60, 0.63))],
    "living_room": [("planks", (0.62, 0.45, 0.28), (0.56, 0.40, 0.24)), ("planks", (0.75, 0.60, 0.42), (0.70, 0.55, 0.38)),
                    ("planks", (0.45, 0.32, 0.22), (0.40, 0.28, 0.19))],
    "bedroom": [("planks", (0.70, 0.54, 0.36), (0.64, 0.49, 0.32)), ("planks", (0.78, 0.70, 0.58), (0.72, 0.64, 0.52)),
                ("planks", (0.55, 0.40, 0.28), (0.50, 0.36, 0.25))],
    "bathroom": [("tiles", (0.92, 0.92, 0.94), (0.80, 0.84, 0.88)), ("tiles", (0.75, 0.82, 0.88), (0.65, 0.72, 0.80)),
                 ("tiles", (0.88, 0.86, 0.82), (0.72, 0.70, 0.66))],
}
_SIZES = {"kitchen": (4.6, 6.4), "living_room": (5.2, 7.0), "bedroom": (4.6, 6.2), "bathroom": (4.0, 5.2)}
_PAINT = [(0.75, 0.25, 0.2), (0.2, 0.4, 0.7), (0.9, 0.7, 0.2), (0.3, 0.6, 0.4), (0.55, 0.3, 0.6)]


def _stream(kind: str, seed: int) -> np.random.Generator:
    return np.random.default_rng([zlib.crc32(kind.encode()), int(seed), LAYOUT_VERSION])


def _q(v: float) -> float:
    return round(v * 4) / 4


def generate_layout(kind: str, seed: int) -> Layout:
    """The room for ``(kind, seed)``; the same arguments always give the same room."""
    if kind not in KINDS:
        raise ValueError(f"unknown room kind {kind!r}; known: {', '.join(KINDS)}")
    rng = _stream(kind, seed)
    lo, hi = _SIZES[kind]
    W = _q(float(rng.uniform(lo, hi)))
    D = _q(float(rng.uniform(lo, hi)))
    p = _Placer(kind, W, D, rng)
    decor: list[Decor] = []

    # A door with a walkway in front of it.
    door_wall = int(rng.integers(4))
    length = W if door_wall in (0, 2) else D
    door_at = float(rng.uniform(0.8, length - 0.8))
    decor.append(Decor("door", door_wall, door_at, 0.0, 0.9, 2.05, (0.45, 0.3, 0.18)))
    p.reserve(_wall_zone(door_wall, door_at, 1.0, 1.0, W, D))

    {"kitchen": _kitchen, "living_room": _living, "bedroom": _bedroom, "bathroom": _bathroom}[kind](p, rng)

    # Windows and paintings on stretches of wall without tall furniture.
    for kind_d, n, bottom, height, wmin, wmax in (("window", 1 + int(rng.integers(2)), 0.95, 1.2, 0.9, 1.4),
                                                  ("painting", 1 + int(rng.integers(2)), 1.35, 0.55, 0.5, 0.9)):
        for _ in range(n):
            for _try in range(20):
                s = int(rng.integers(4))
                length = W if s in (0, 2) else D
                wd = float(rng.uniform(wmin, wmax))
                a = float(rng.uniform(wd / 2 + 0.2, length - wd / 2 - 0.2))
                if _decor_free(s, a, wd, bottom, p.objects, decor, W, D):
                    colour = (0.62, 0.78, 0.92) if kind_d == "window" else _PAINT[int(rng.integers(len(_PAINT)))]
                    decor.append(Decor(kind_d, s, round(a, 3), bottom, round(wd, 3), height, colour))
                    break

    walls = _WALLS[kind]
    floors = _FLOORS[kind]
    return Layout(kind=kind, seed=int(seed), width=W, depth=D, wall_rgb=walls[int(rng.integers(len(walls)))],
                  floor=floors[int(rng.integers(len(floors)))], objects=tuple(p.objects), decor=tuple(decor))


def _wall_zone(wall: int, along: float, width: float, depth: float, W: float, D: float) -> Box:
    if wall == 0:
        return (along - width / 2, 0.0, along + width / 2, depth)
    if wall == 2:
        return (along - width / 2, D - depth, along + width / 2, D)
    if wall == 3:
        return (0.0, along - width / 2, depth, along + width / 2)
    return (W - depth, along - width / 2, W, along + width / 2)


def _decor_free(wall: int, along: float, width: float, bottom: float, objects: list[Placed], decor: list[Decor],
                W: float, D: float) -> bool:
    for d in decor:
        if d.wall == wall and abs(d.along - along) < (d.width + width) / 2 + 0.15:
            return False
    zone = _wall_zone(wall, along, width + 0.1, 0.8, W, D)
    for o in objects:
        if o.size[2] + o.z > bottom - 0.05 and _overlaps(o.footprint, zone):
            return False
    return True


# -- room recipes ---------------------------------------------------------------------------------------


def _maybe(p: _Placer, rng: np.random.Generator, prob: float, fn, *args, **kwargs):
    if rng.random() < prob:
        return fn(*args, **kwargs)
    return None


def _kitchen(p: _Placer, rng: np.random.Generator) -> None:
    # A run of units along one wall: fridge at one end, then counters and the stove.
    wall = int(rng.integers(4))
    length = p.W if wall in (0, 2) else p.D
    units = ["counter", "stove", "sink_counter"]
    rng.shuffle(units)
    units = ["fridge"] + list(units)
    if rng.random() < 0.5:
        units.reverse()
    cab_col = ["white", "cream", "grey", "teal", "navy"][int(rng.integers(5))]
    widths = [get_type(u).size[0] for u in units]
    total = sum(widths) + 0.02 * len(units)
    placed_counters: list[Placed] = []
    spill: list[str] = []
    if total <= length - 0.1:
        a = float(rng.uniform(0.05, length - total - 0.05)) if rng.random() < 0.5 else 0.05
        for u, w in zip(units, widths):
            colour = cab_col if "counter" in u else None
            obj = p.against_wall(u, colour, wall=wall, along=a + w / 2, clearance=0.7)
            if obj is None:
                spill.append(u)
            elif "counter" in u:
                placed_counters.append(obj)
            a += w + 0.02
    else:
        spill = units
    for u in spill:  # whatever did not fit goes on another wall
        obj = p.against_wall(u, cab_col if "counter" in u else None, clearance=0.7)
        if obj is not None and "counter" in u:
            placed_counters.append(obj)
    if placed_counters:
        host = [c for c in placed_counters if c.type != "sink_counter"] or placed_counters
        p.on_top("microwave", host[int(rng.integers(len(host)))])
    # Dining table with chairs.
    table = p.in_open("dining_table", margin=0.9, region=(0.9, 0.9, p.W - 0.9, p.D - 0.9))
    if table is not None:
        _chairs_around(p, rng, table, int(rng.integers(2, 5)))
    p.against_wall("plant", clearance=0.4)
    _maybe(p, rng, 0.7, p.against_wall, "trash_can", clearance=0.0)
    _maybe(p, rng, 0.5, p.in_open, "stool", margin=0.6)
    _maybe(p, rng, 0.4, p.against_wall, "boxes", clearance=0.0)
    _maybe(p, rng, 0.3, p.in_open, "ball", margin=0.6)
    if rng.random() < 0.5:
        p.decal("small_rug", float(rng.uniform(1.0, p.W - 1.0)), float(rng.uniform(0.8, p.D - 0.8)), int(rng.integers(2)))


def _chairs_around(p: _Placer, rng: np.random.Generator, table: Placed, n: int) -> None:
    colour = p._colour("chair")
    sides = [0, 1, 2, 3]
    rng.shuffle(sides)
    tx, ty = table.x, table.y
    sx, sy, _ = table.size
    for side in sides[:n]:
        # chair at the table's side, front facing the table
        if side == 0:  # south of the table, facing +y
            p.at("chair", tx, ty - sy / 2 - 0.25, 0, colour, margin=0.0)
        elif side == 2:
            p.at("chair", tx, ty + sy / 2 + 0.25, 2, colour, margin=0.0)
        elif side == 3:  # west of the table, facing +x
            p.at("chair", tx - sx / 2 - 0.25, ty, 3, colour, margin=0.0)
        else:
            p.at("chair", tx + sx / 2 + 0.25, ty, 1, colour, margin=0.0)


def _living(p: _Placer, rng: np.random.Generator) -> None:
    stand = p.against_wall("tv_stand", clearance=1.0)
    if stand is not None:
        p.on_top("tv", stand, toward_front=False)
        fx, fy = _FRONT[stand.yaw]
        dist = float(rng.uniform(2.4, 3.2))
        sofa = p.at("sofa", stand.x + fx * dist, stand.y + fy * dist, (stand.yaw + 2) % 4, margin=0.05, clearance=0.3)
        if sofa is None:
            sofa = p.against_wall("sofa", clearance=0.8)
        if sofa is not None:
            mid = ((stand.x + sofa.x) / 2, (stand.y + sofa.y) / 2)
            p.decal("rug", mid[0], mid[1], sofa.yaw)
            ct = p.at("coffee_table", sofa.x + _FRONT[sofa.yaw][0] * 1.0, sofa.y + _FRONT[sofa.yaw][1] * 1.0,
                      sofa.yaw, margin=0.05)
            if ct is not None and rng.random() < 0.6:
                p.on_top("laptop", ct, toward_front=False)
            # an armchair to one side, turned toward the middle
            side = (sofa.yaw + (1 if rng.random() < 0.5 else 3)) % 4
            fx2, fy2 = _FRONT[side]
            p.at("armchair", mid[0] - fx2 * 1.7, mid[1] - fy2 * 1.7, side, margin=0.1)
    else:
        p.against_wall("sofa", clearance=0.8)
    p.against_wall("bookshelf", clearance=0.6)
    p.against_wall("floor_lamp", clearance=0.3)
    p.against_wall("plant", clearance=0.3)
    _maybe(p, rng, 0.6, p.in_open, "ball", margin=0.6)
    _maybe(p, rng, 0.5, p.against_wall, "armchair", clearance=0.6)
    _maybe(p, rng, 0.5, p.against_wall, "boxes", clearance=0.0)
    _maybe(p, rng, 0.4, p.against_wall, "plant", clearance=0.3)
    if not any(o.type == "laptop" for o in p.objects):
        desk = _maybe(p, rng, 0.5, p.against_wall, "desk", clearance=0.7)
        if desk is not None:
            p.on_top("laptop", desk)


def _bedroom(p: _Placer, rng: np.random.Generator) -> None:
    bed = p.against_wall("bed", clearance=0.0, gap=0.02)
    if bed is not None:
        # keep both long sides walkable
        sx, sy, _ = bed.size
        x0, y0, x1, y1 = bed.footprint
        if bed.yaw % 2 == 0:
            p.reserve((x0 - 0.7, y0, x0, y1))
            p.reserve((x1, y0, x1 + 0.7, y1))
        else:
            p.reserve((x0, y0 - 0.7, x1, y0))
            p.reserve((x0, y1, x1, y1 + 0.7))
        # nightstands at the head end
        fx, fy = _FRONT[bed.yaw]
        hx, hy = bed.x - fx * (bed.size[1 if bed.yaw % 2 == 0 else 0] / 2 - 0.22), bed.y - fy * (
            bed.size[1 if bed.yaw % 2 == 0 else 0] / 2 - 0.22)
        for sgn in (-1, 1):
            if rng.random() < 0.8:  # nightstands may stand at the head end of the walkways
                ox, oy = (sgn * (0.75 + 0.27), 0.0) if bed.yaw % 2 == 0 else (0.0, sgn * (0.75 + 0.27))
                p.at("nightstand", hx + ox, hy + oy, bed.yaw, margin=0.0, ignore_reserved=True)
    p.against_wall("wardrobe", clearance=0.7)
    desk = p.against_wall("desk", clearance=0.7)
    if desk is not None:
        fx, fy = _FRONT[desk.yaw]
        p.at("chair", desk.x + fx * 0.6, desk.y + fy * 0.6, (desk.yaw + 2) % 4, margin=0.0, ignore_reserved=True)
        if rng.random() < 0.75:
            p.on_top("laptop", desk)
    _maybe(p, rng, 0.6, p.against_wall, "dresser", clearance=0.6)
    _maybe(p, rng, 0.7, p.in_open, "teddy_bear", margin=0.6)
    _maybe(p, rng, 0.5, p.against_wall, "floor_lamp", clearance=0.3)
    _maybe(p, rng, 0.5, p.in_open, "ball", margin=0.6)
    _maybe(p, rng, 0.5, p.against_wall, "plant", clearance=0.3)
    _maybe(p, rng, 0.5, p.against_wall, "laundry_basket", clearance=0.0)
    if rng.random() < 0.6:
        p.decal("rug", float(rng.uniform(1.2, p.W - 1.2)), float(rng.uniform(1.0, p.D - 1.0)), int(rng.integers(2)))


def _bathroom(p: _Placer, rng: np.random.Generator) -> None:
    p.against_wall("bathtub", clearance=0.7, gap=0.01)
    p.against_wall("toilet", clearance=0.6)
    p.against_wall("vanity", clearance=0.7)
    _maybe(p, rng, 0.8, p.against_wall, "washing_machine", clearance=0.7)
    _maybe(p, rng, 0.6, p.against_wall, "towel_rack", clearance=0.0)
    _maybe(p, rng, 0.6, p.against_wall, "laundry_basket", clearance=0.0)
    _maybe(p, rng, 0.6, p.against_wall, "plant", clearance=0.3)
    _maybe(p, rng, 0.5, p.against_wall, "trash_can", clearance=0.0)
    if rng.random() < 0.6:
        p.decal("small_rug", float(rng.uniform(1.0, p.W - 1.0)), float(rng.uniform(0.8, p.D - 0.8)), int(rng.integers(2)))
    _maybe(p, rng, 0.3, p.in_open, "ball", margin=0.6)


def place_extra(layout: Layout, type_name: str, colour: str, rng: np.random.Generator,
                avoid: Iterable[Box] = (), host_types: tuple[str, ...] = ()) -> Placed | None:
    """Add one more object of ``type_name`` to an existing room (visual-appearance distractors).

    Floor objects go against a wall or in the open; objects that stand on furniture go on a free
    spot of a host of one of ``host_types``. ``avoid`` are areas to keep clear (the start, the target).
    """
    p = _Placer(layout.kind, layout.width, layout.depth, rng, layout.objects)
    for box in avoid:
        p.reserve(box)
    t = get_type(type_name)
    if not t.obstacle:  # stands on furniture
        hosts = [o for o in layout.objects if o.type in host_types]
        order = list(range(len(hosts)))
        rng.shuffle(order)
        for k in order:
            for o in layout.objects:  # mark what already stands on this host
                if o.on == hosts[k].id:
                    p.surface_use.setdefault(o.on, []).append(o.footprint)
            obj = p.on_top(type_name, hosts[k], colour)
            if obj is not None:
                return obj
        return None
    obj = p.against_wall(type_name, colour, clearance=0.5)
    if obj is None:
        obj = p.in_open(type_name, colour, margin=0.5)
    return obj
