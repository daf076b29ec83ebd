"""The task generator: ``eb tasks generate env=navigation seed=0 scenes=60 min_distance=2.5 out=...``.

For each scene slot (kinds in turn: kitchen, living room, bedroom, bathroom) it draws room seeds for the scene
kit's :func:`~eb_scenekit.rooms.generate_room` until one gives a good task: a target whose type occurs once in
the room, a start pose ``min_distance``..``max_distance`` metres away (horizontally) facing it, the target
clearly visible in the first view (checked by rendering a segmentation image), and an oracle plan of at most
``max_oracle_steps`` actions. From that base task it derives the other four subsets:

* common_sense and complex_instruction: same room, start and target, rewritten instruction;
* long_horizon: the same start turned by 180 degrees (the target must be out of view);
* visual_appearance: the room plus one or two objects of the target's type in clearly different colours
  against the walls, the target named only by colour and shape (when the base target cannot have a twin, as a
  TV on its stand or a microwave on a counter, another object of the same room becomes the visual target).

Every task's oracle plan is at most ``max_oracle_steps`` long (15 by default). Tasks are written room by room
(base, common_sense, complex_instruction, visual_appearance, long_horizon of room 0, then room 1 ...), so a run
in file order compiles each room once.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from eb_scenekit.objects import get_type

from eb_navigation.geometry import STEP, AgentState, FreeSpace, bearing_to
from eb_navigation.instructions import COMMON_SENSE_TYPES, SHAPES, instruction_for
from eb_navigation.room import KINDS, ExtraSpec, NavObject, NavRoom, colour_distance, probe
from eb_navigation.tasks import SUBSETS, TASK_FILE_FORMAT, TASK_FILE_VERSION

__all__ = ["GENERATOR_VERSION", "TARGETS_BY_KIND", "generate"]

GENERATOR_VERSION = 2

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
"""The target's centre must be within this many degrees of straight ahead at a base start."""
MIN_COLOUR_DISTANCE = 0.35
"""Distractors differ from the target (and each other) by at least this much in RGB."""
MIN_DISTRACTOR_DISTANCE = 1.8
"""Distractor centres stand at least this far from the target's centre (metres)."""
_VIS_SIZE = 128


class _Visibility:
    """Counts an object's pixels in the first-person view (low-resolution segmentation; two rooms kept)."""

    def __init__(self) -> None:
        self._scenes: list[tuple[NavRoom, Any]] = []

    def pixels(self, room: NavRoom, state: AgentState, obj_id: str) -> int:
        scene = next((sc for r, sc in self._scenes if r is room), None)
        if scene is None:
            from eb_navigation.scene import RoomScene

            scene = RoomScene(room, _VIS_SIZE, _VIS_SIZE)
            self._scenes.append((room, scene))
            if len(self._scenes) > 2:
                self._scenes.pop(0)[1].close()
        scene.set_agent(state)
        return int((scene.object_map() == room.index[obj_id]).sum())

    def close(self) -> None:
        for _, scene in self._scenes:
            scene.close()
        self._scenes.clear()


def _facing(ij: tuple[int, int], target_xy: tuple[float, float]) -> int:
    return min(range(4), key=lambda h: abs(bearing_to(AgentState(ij[0], ij[1], h), target_xy)))


def _starts(free: FreeSpace, target: NavObject, lo: float, hi: float, rng: np.random.Generator
            ) -> list[tuple[int, int]]:
    out = [(i, j) for i, j in free.free_cells()
           if lo - 1e-9 <= math.hypot(i * STEP - target.x, j * STEP - target.y) <= hi + 1e-9]
    rng.shuffle(out)
    return out


def _find_start(room: NavRoom, free: FreeSpace, target: NavObject, lo: float, hi: float, max_steps: int,
                vis: _Visibility, rng: np.random.Generator, need_behind: bool = True
                ) -> tuple[AgentState, int, int] | None:
    """A start facing the target (clearly visible, plan <= max_steps) whose 180-degree turn hides it."""
    xy = (target.x, target.y)
    for ij in _starts(free, target, lo, hi, rng)[:60]:
        s = AgentState(ij[0], ij[1], _facing(ij, xy))
        if abs(bearing_to(s, xy)) > MAX_START_BEARING:
            continue
        plan = free.shortest_plan(s, xy)
        if plan is None or len(plan) > max_steps:
            continue
        back = replace(s, heading=(s.heading + 2) % 4)
        if need_behind:
            plan_back = free.shortest_plan(back, xy)
            if plan_back is None or len(plan_back) > max_steps:
                continue
        if vis.pixels(room, s, target.id) < MIN_VISIBLE_PIXELS:
            continue
        if need_behind:
            if vis.pixels(room, back, target.id) > 0:
                continue
            return s, len(plan), len(plan_back)
        return s, len(plan), -1
    return None


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


def _visual_variant(room: NavRoom, target: NavObject, start: AgentState, max_steps: int, vis: _Visibility,
                    rng: np.random.Generator) -> tuple[NavRoom, list[ExtraSpec], int] | None:
    """One or two same-type objects in other colours against the walls, not blocking the oracle."""
    t = get_type(target.type)
    others = [c for c in t.colors if colour_distance(c, target.colour) >= MIN_COLOUR_DISTANCE]
    if not others or target.type not in SHAPES or not target.on_floor:
        return None
    floor = [o for o in room.layout.objects if o.parent is None and o.mount != "wall"]
    keep_clear = [replace(probe(target.type, start.x, start.y, 0.0), half_extents=(0.55, 0.55)),
                  replace(probe(target.type, target.x, target.y, 0.0), half_extents=(1.3, 1.3))]
    for _attempt in range(12):
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
        if len(extras) != len(colours):
            continue
        vroom = NavRoom(room.kind, room.seed, extras)
        free = vroom.free_space(vroom.extra_ids)
        if not free.is_free(start.i, start.j):
            continue
        plan = free.shortest_plan(start, (target.x, target.y))
        if plan is None or len(plan) > max_steps:
            continue
        if vis.pixels(vroom, start, target.id) < MIN_VISIBLE_PIXELS:
            continue
        if max(vis.pixels(vroom, start, e.id) for e in extras) < MIN_DISTRACTOR_PIXELS:
            continue
        return vroom, extras, len(plan)
    return None


def _visual_task(room: NavRoom, free: FreeSpace, target: NavObject, start: AgentState, lo: float, hi: float,
                 max_steps: int, vis: _Visibility, rng: np.random.Generator
                 ) -> tuple[NavObject, AgentState, list[ExtraSpec], int] | None:
    found = _visual_variant(room, target, start, max_steps, vis, rng)
    if found is not None:
        return target, start, found[1], found[2]
    counts = room.counts()
    others = [o for o in room.objects if o.id != target.id and o.type in SHAPES and counts[o.type] == 1
              and o.on_floor]
    rng.shuffle(others)
    for other in others[:3]:
        got = _find_start(room, free, other, lo, hi, max_steps, vis, rng, need_behind=False)
        if got is None:
            continue
        found = _visual_variant(room, other, got[0], max_steps, vis, rng)
        if found is not None:
            return other, got[0], found[1], found[2]
    return None


def _pose_dict(s: AgentState) -> dict[str, Any]:
    return {"x": s.x, "y": s.y, "yaw": s.yaw_deg, "tilt": s.tilt}


def _target_dict(t: NavObject) -> dict[str, Any]:
    return {"id": t.id, "type": t.type, "colour": t.colour, "position": [round(v, 4) for v in t.centre]}


def _extra_dict(e: ExtraSpec) -> dict[str, Any]:
    return {"id": e.id, "type": e.type, "colour": e.colour, "x": e.x, "y": e.y, "yaw": e.yaw}


def generate(seed: int = 0, scenes: int = 60, min_distance: float = 2.5, max_distance: float = 3.0,
             out: str | None = None, max_oracle_steps: int = 15) -> str:
    """Write a navigation task file with ``5 * scenes`` tasks; return a one-line summary.

    Args:
        seed: master seed (room seeds, starts and instruction wording all follow from it).
        scenes: number of distinct rooms; each gives one task per subset.
        min_distance / max_distance: horizontal start-to-target distance range, metres.
        out: output path (default ``navigation_tasks.json`` in the working directory).
        max_oracle_steps: longest oracle plan allowed for any task.
    """
    seed, scenes = int(seed), int(scenes)
    lo, hi = float(min_distance), float(max_distance)
    if scenes < 1:
        raise ValueError("scenes must be at least 1")
    if not 1.0 < lo <= hi:
        raise ValueError("need 1.0 < min_distance <= max_distance (metres)")
    max_oracle_steps = int(max_oracle_steps)
    path = Path(out) if out else Path("navigation_tasks.json")
    rng = np.random.default_rng([seed, GENERATOR_VERSION])
    vis = _Visibility()
    tasks: list[dict[str, Any]] = []
    used: set[tuple[str, int]] = set()
    try:
        for slot in range(scenes):
            kind = KINDS[slot % len(KINDS)]
            wanted = TARGETS_BY_KIND[kind][(slot // len(KINDS)) % len(TARGETS_BY_KIND[kind])]
            made = None
            for attempt in range(400):
                room_seed = int(rng.integers(0, 100_000))
                if (kind, room_seed) in used:
                    continue
                room = NavRoom(kind, room_seed)
                counts = room.counts()
                names = [wanted] if attempt < 100 else list(TARGETS_BY_KIND[kind])
                candidates = [o for o in room.objects if o.type in names and counts[o.type] == 1
                              and o.type in COMMON_SENSE_TYPES]
                if not candidates:
                    continue
                target = candidates[int(rng.integers(len(candidates)))]
                free = room.free_space()
                found = _find_start(room, free, target, lo, hi, max_oracle_steps, vis, rng)
                if found is None:
                    continue
                start, steps, steps_back = found
                visual = _visual_task(room, free, target, start, lo, hi, max_oracle_steps, vis, rng)
                if visual is None:
                    continue
                made = (room, target, start, steps, steps_back, visual)
                break
            if made is None:
                raise RuntimeError(f"could not make a {kind} task for slot {slot} (try other distances)")
            room, target, start, steps, steps_back, (v_target, v_start, extras, steps_visual) = made
            used.add((kind, room.seed))
            other_types = sorted({o.type for o in room.objects if o.type != target.type and o.on_floor})
            other = other_types[int(rng.integers(len(other_types)))] if other_types else None
            scene = {"kind": kind, "seed": room.seed}
            common = {"scene": scene, "target": _target_dict(target)}
            n = slot

            def task(subset: str, instruction: str, **fields: Any) -> dict[str, Any]:
                return {"id": f"{subset}_{n:03d}", "subset": subset, "instruction": instruction, **fields}

            plain = {**common, "start": _pose_dict(start), "extra_objects": [], "oracle_steps": steps}
            tasks.append(task("base", instruction_for("base", target.type, target.colour, rng), **plain))
            tasks.append(task("common_sense", instruction_for("common_sense", target.type, target.colour, rng),
                              **plain))
            tasks.append(task("complex_instruction", instruction_for("complex_instruction", target.type,
                                                                     target.colour, rng, other), **plain))
            tasks.append(task("visual_appearance", instruction_for("visual_appearance", v_target.type,
                                                                   v_target.colour, rng),
                              scene=scene, target=_target_dict(v_target), start=_pose_dict(v_start),
                              extra_objects=[_extra_dict(e) for e in extras], oracle_steps=steps_visual))
            back = replace(start, heading=(start.heading + 2) % 4)
            tasks.append(task("long_horizon", instruction_for("long_horizon", target.type, target.colour, rng),
                              **{**common, "start": _pose_dict(back), "extra_objects": [],
                                 "oracle_steps": steps_back}))
    finally:
        vis.close()
    assert [t["subset"] for t in tasks[:5]] == list(SUBSETS)
    from eb_scenekit import __version__ as scenekit_version

    doc = {
        "format": TASK_FILE_FORMAT,
        "version": TASK_FILE_VERSION,
        "generator": {"function": "eb_navigation.generate:generate", "generator_version": GENERATOR_VERSION,
                      "scenekit_version": scenekit_version, "seed": seed, "scenes": scenes, "min_distance": lo,
                      "max_distance": hi, "max_oracle_steps": max_oracle_steps},
        "tasks": tasks,
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ",\n".join("  " + json.dumps(t, separators=(", ", ": ")) for t in tasks)
    head = json.dumps({k: v for k, v in doc.items() if k != "tasks"}, indent=1)[:-2]
    path.write_text(head + ',\n "tasks": [\n' + lines + "\n ]\n}\n", encoding="utf-8")
    steps_all = [t["oracle_steps"] for t in tasks]
    return (f"wrote {len(tasks)} tasks ({scenes} scenes x {len(SUBSETS)} subsets) to {path}; "
            f"oracle steps {min(steps_all)}-{max(steps_all)}, mean {np.mean(steps_all):.1f}")
