"""Pieces the classic generator (:mod:`eb_navigation.generate`) and the generated splits
(:mod:`eb_navigation.splits`) share: rules and constants, look-alike placement, the task-file dictionaries. A
module of its own, so that neither of the two imports the other."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from eb_scenekit.objects import get_type

from eb_navigation.geometry import AgentState
from eb_navigation.instructions import SHAPES
from eb_navigation.room import ExtraSpec, NavObject, NavRoom, colour_distance, probe

GENERATOR_VERSION = 3

#: Target types per room kind (scene kit names), in the order slots of that kind cycle through them.
TARGETS_BY_KIND: dict[str, tuple[str, ...]] = {
    "kitchen": ("Fridge", "Microwave", "Stove", "Sink", "GarbageCan", "DiningTable"),
    "living_room": ("Television", "Sofa", "ArmChair", "FloorLamp", "HousePlant", "Bookshelf"),
    "bedroom": ("Desk", "Dresser", "FloorLamp", "Bookshelf", "GarbageCan", "HousePlant"),
    "bathroom": ("Toilet", "Bathtub", "WashingMachine", "Sink", "GarbageCan", "HousePlant"),
}
MIN_VISIBLE_PIXELS = 80
"""Target pixels (in a 128 x 128 segmentation of the first view) for the target to count as clearly visible."""
MIN_DISTRACTOR_PIXELS = 40
MAX_START_BEARING = 40.0
"""The target's centre must be within this many degrees of straight ahead at a start where it is promised in view."""
MIN_BEHIND_BEARING = 100.0
"""A long_horizon start has the target at least this far from straight ahead (and out of view in the render)."""
LONG_HORIZON_EXTRA = 2
"""A long_horizon oracle plan is at least this many actions longer than the base plan of the same room."""
LONG_HORIZON_MAX_DISTANCE = 1.0
"""A long_horizon start may be up to this much farther than ``max_distance``."""
MIN_COLOUR_DISTANCE = 0.62
"""Look-alikes differ from the target (and each other) by at least this much in RGB: black vs white or silver,
grey vs white, red vs beige... never white vs stainless steel or cream (which look alike in a render)."""
MIN_DISTRACTOR_DISTANCE = 1.8
"""Distractor centres stand at least this far from the target's centre (metres)."""
KIND_ATTEMPTS = 150
"""Rooms of one kind tried for a slot before the slot moves on to the next kind (small bathrooms run dry first:
their few starts are open floor that blind policies solve)."""
_VIS_TRIES = 12

def _wall_pose(room: NavRoom, type_name: str, rng: np.random.Generator, taken: list, keep_clear: list
               ) -> tuple[float, float, float] | None:
    """A pose with the object's back against a wall, clear of furniture, the door, windows and ``keep_clear``."""
    shell = room.layout.room
    t = get_type(type_name)
    hx, hy = room.size[0] / 2, room.size[1] / 2
    d = shell.door
    c, along, normal = shell.wall_frame(d.wall)
    p = c + along * d.offset + normal * 0.5
    door = probe(type_name, float(p[0]), float(p[1]), math.degrees(math.atan2(normal[1], normal[0])))
    door = replace(door, half_extents=(0.55, d.width / 2 + 0.3))
    windows = []
    if t.height > 1.1:
        for w in shell.windows:
            c, along, normal = shell.wall_frame(w.wall)
            p = c + along * w.offset + normal * 0.3
            win = probe(type_name, float(p[0]), float(p[1]), math.degrees(math.atan2(normal[1], normal[0])))
            windows.append(replace(win, half_extents=(0.3, w.width / 2)))
    walls = ("north", "south", "east", "west")
    for _ in range(40):
        wall = walls[int(rng.integers(4))]
        c, along, normal = shell.wall_frame(wall)
        lim = shell.wall_length(wall) / 2 - t.half_extents[1] - 0.05
        if lim <= 0:
            continue
        off = float(rng.uniform(-lim, lim))
        p = c + along * off + normal * (t.half_extents[0] + 0.03)
        x, y = round(float(p[0]), 3), round(float(p[1]), 3)
        yaw = round(math.degrees(math.atan2(normal[1], normal[0])), 1)
        cand = probe(type_name, x, y, yaw)
        x0, y0, x1, y1 = cand.aabb()
        if x0 < -hx or x1 > hx or y0 < -hy or y1 > hy:
            continue
        if cand.overlaps(door) or any(cand.overlaps(w) for w in windows):
            continue
        if any(cand.overlaps(o, 0.05) for o in taken) or any(cand.overlaps(k) for k in keep_clear):
            continue
        return x, y, yaw
    return None



def _twin_colours(target: NavObject) -> list[str]:
    t = get_type(target.type)
    return [c for c in t.colors if colour_distance(c, target.colour) >= MIN_COLOUR_DISTANCE]


def _place_lookalikes(room: NavRoom, target: NavObject, rng: np.random.Generator) -> list[ExtraSpec] | None:
    """One or two same-type objects in clearly different colours against the walls, away from the target."""
    others = _twin_colours(target)
    if not others or target.type not in SHAPES or not target.on_floor:
        return None
    floor = [o for o in room.layout.objects if o.parent is None and o.mount != "wall"]
    keep_clear = [replace(probe(target.type, target.x, target.y, 0.0), half_extents=(1.3, 1.3))]
    for _attempt in range(8):
        n = 2 if rng.random() < 0.5 and len(others) > 1 else 1
        order = [others[int(k)] for k in rng.permutation(len(others))]
        colours = [order[0]] + [c for c in order[1:] if colour_distance(c, order[0]) >= MIN_COLOUR_DISTANCE][: n - 1]
        extras: list[ExtraSpec] = []
        taken = list(floor)
        for k, colour in enumerate(colours):
            pose = _wall_pose(room, target.type, rng, taken, keep_clear)
            if pose is None or math.hypot(pose[0] - target.x, pose[1] - target.y) < MIN_DISTRACTOR_DISTANCE:
                break
            extras.append(ExtraSpec(f"{target.type}_{k + 2}", target.type, colour, *pose))
            taken.append(probe(target.type, *pose))
        if len(extras) == len(colours):
            return extras
    return None


def _pose_dict(s: AgentState) -> dict[str, Any]:
    return {"x": s.x, "y": s.y, "yaw": s.yaw_deg, "tilt": s.tilt}


def _target_dict(t: NavObject) -> dict[str, Any]:
    return {"id": t.id, "type": t.type, "colour": t.colour, "position": [round(v, 4) for v in t.centre]}


def _extra_dict(e: ExtraSpec) -> dict[str, Any]:
    return {"id": e.id, "type": e.type, "colour": e.colour, "x": e.x, "y": e.y, "yaw": e.yaw}
