"""The task generator: ``eb tasks generate env=navigation seed=0 scenes=60 min_distance=2.5 out=...``.

For each scene slot (kinds in turn: kitchen, living room, bedroom, bathroom) it draws room seeds until
one gives a good task: a recognisable target whose type occurs once in the room, a start pose
``min_distance``..``max_distance`` metres away (horizontally) facing the target, the target visible in
the first view (checked by rendering a segmentation image), and an oracle plan of at most
``max_oracle_steps`` actions. From that base task it derives the other four subsets:

* common_sense and complex_instruction: same room, start and target, rewritten instruction;
* long_horizon: the same start turned by 180 degrees (the target must be out of view);
* visual_appearance: the room plus one or two objects of the target's type in other colours, the
  target named only by colour and shape (when the base target has no room for a same-type twin, as
  with a TV on its stand, another object of the same room becomes the visual target).

Every shipped task is solved by the oracle within 20 steps (base ones within ``max_oracle_steps``).
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from eb_navigation.catalogue import TARGET_TYPES, get_type
from eb_navigation.geometry import STEP, AgentState, FreeSpace, bearing_to
from eb_navigation.instructions import instruction_for
from eb_navigation.layout import KINDS, LAYOUT_VERSION, Layout, Placed, generate_layout, place_extra
from eb_navigation.tasks import SUBSETS, TASK_FILE_FORMAT

__all__ = ["GENERATOR_VERSION", "generate", "TARGETS_BY_KIND"]

GENERATOR_VERSION = 1

#: Target types per room kind, in the order slots of that kind cycle through them.
TARGETS_BY_KIND: dict[str, tuple[str, ...]] = {
    "kitchen": ("fridge", "microwave", "stove", "plant", "fridge", "stove", "microwave", "ball"),
    "living_room": ("tv", "sofa", "armchair", "floor_lamp", "plant", "ball", "laptop"),
    "bedroom": ("bed", "teddy_bear", "laptop", "floor_lamp", "wardrobe", "ball", "plant"),
    "bathroom": ("toilet", "bathtub", "washing_machine", "plant", "toilet", "bathtub", "washing_machine"),
}
#: Where a second copy of a surface object can stand (visual-appearance distractors).
HOSTS = {"microwave": ("counter", "long_counter"), "laptop": ("desk", "coffee_table", "dining_table"),
         "tv": ()}
MIN_VISIBLE_PIXELS = 45
"""Target pixels (in a 128 x 128 segmentation of the first view) for the target to count as visible."""
MAX_START_BEARING = 40.0
"""The target's centre must be within this many degrees of straight ahead at a base start."""


class _Visibility:
    """Counts an object's pixels in the first-person view (low resolution segmentation)."""

    def __init__(self) -> None:
        from eb_navigation.render import SceneRenderer

        self.renderer = SceneRenderer(128, seg_resolution=128)
        self._key = None
        self._scene = None

    def pixels(self, layout: Layout, state: AgentState, obj_id: str) -> int:
        from eb_navigation.scene import NavScene

        key = (layout.kind, layout.seed, layout.objects)
        if key != self._key:
            self._scene = NavScene(layout, 128)
            self.renderer.load(self._scene.model)
            self._key = key
        scene = self._scene
        assert scene is not None
        scene.set_agent(state)
        _, seg = self.renderer.render(scene.data, "first_person", segmentation=True)
        assert seg is not None
        index = [o.id for o in layout.objects].index(obj_id)
        obj = np.where(seg >= 0, scene.geom_object[np.clip(seg, 0, None)], -1)
        return int((obj == index).sum())

    def close(self) -> None:
        self.renderer.close()


def _facing(state_ij: tuple[int, int], target_xy: tuple[float, float]) -> int:
    best, best_abs = 0, 1e9
    for h in range(4):
        b = abs(bearing_to(AgentState(state_ij[0], state_ij[1], h), target_xy))
        if b < best_abs:
            best, best_abs = h, b
    return best


def _starts(free: FreeSpace, target: Placed, lo: float, hi: float, rng: np.random.Generator) -> list[tuple[int, int]]:
    cells = free.free_cells()
    ii, jj = np.nonzero(cells)
    d = np.hypot(ii * STEP - target.x, jj * STEP - target.y)
    ok = (d >= lo - 1e-9) & (d <= hi + 1e-9)
    out = [(int(i), int(j)) for i, j in zip(ii[ok], jj[ok])]
    rng.shuffle(out)
    return out


def _pose_dict(s: AgentState) -> dict[str, Any]:
    return {"x": s.x, "y": s.y, "yaw": s.yaw_deg, "tilt": s.tilt}


def _target_dict(t: Placed) -> dict[str, Any]:
    return {"id": t.id, "type": t.type, "colour": t.colour, "position": [round(v, 4) for v in t.centre]}


def _find_start(layout: Layout, free: FreeSpace, target: Placed, lo: float, hi: float, max_steps: int,
                vis: _Visibility, rng: np.random.Generator, need_behind: bool = True
                ) -> tuple[AgentState, int, int] | None:
    """A start facing the target (visible, plan <= max_steps) whose 180-degree turn hides it."""
    for ij in _starts(free, target, lo, hi, rng)[:60]:
        s = AgentState(ij[0], ij[1], _facing(ij, (target.x, target.y)))
        if abs(bearing_to(s, (target.x, target.y))) > MAX_START_BEARING:
            continue
        plan = free.shortest_plan(s, (target.x, target.y))
        if plan is None or len(plan) > max_steps:
            continue
        if vis.pixels(layout, s, target.id) < MIN_VISIBLE_PIXELS:
            continue
        if need_behind:
            back = replace(s, heading=(s.heading + 2) % 4)
            plan_back = free.shortest_plan(back, (target.x, target.y))
            if plan_back is None or len(plan_back) > min(20, max_steps + 3):
                continue
            if vis.pixels(layout, back, target.id) > 0:
                continue
            return s, len(plan), len(plan_back)
        return s, len(plan), -1
    return None


def _visual_variant(layout: Layout, target: Placed, start: AgentState, max_steps: int, vis: _Visibility,
                    rng: np.random.Generator) -> tuple[list[Placed], int] | None:
    """One or two same-type objects in other colours, away from the target, not blocking the oracle."""
    t = get_type(target.type)
    others = [c for c in t.colours if c != target.colour]
    if not others or target.type in ("tv",):
        return None
    hosts = HOSTS.get(target.type, ())
    keep_clear = [(start.x - 0.5, start.y - 0.5, start.x + 0.5, start.y + 0.5),
                  (target.x - 1.2, target.y - 1.2, target.x + 1.2, target.y + 1.2)]
    for _attempt in range(12):
        n = 2 if rng.random() < 0.5 else 1
        colours = list(rng.choice(others, size=min(n, len(others)), replace=False))
        extras: list[Placed] = []
        current = layout
        for c in colours:
            obj = place_extra(current, target.type, str(c), rng, avoid=keep_clear, host_types=hosts)
            if obj is None:
                break
            if math.hypot(obj.x - target.x, obj.y - target.y) < 2.0:
                break
            extras.append(obj)
            current = current.with_objects([obj])
        if len(extras) != len(colours):
            continue
        free = FreeSpace(current)
        if not free.is_free(start.i, start.j):
            continue
        plan = free.shortest_plan(start, (target.x, target.y))
        if plan is None or len(plan) > max_steps:
            continue
        if vis.pixels(current, start, target.id) < MIN_VISIBLE_PIXELS:
            continue
        if not any(vis.pixels(current, start, e.id) > 0 for e in extras):
            continue  # a distractor nobody can see does not test anything
        return extras, len(plan)
    return None


def _visual_task(layout: Layout, free: FreeSpace, target: Placed, start: AgentState, counts: dict[str, int],
                 lo: float, hi: float, max_steps: int, vis: _Visibility, rng: np.random.Generator
                 ) -> tuple[Placed, AgentState, list[Placed], int] | None:
    """The visual-appearance task of a room: the base target with distractors if that works, else another
    target of the room (things on furniture, like a TV, rarely have room for a same-type twin)."""
    found = _visual_variant(layout, target, start, max_steps, vis, rng)
    if found is not None:
        return target, start, found[0], found[1]
    others = [o for o in layout.objects if o.id != target.id and o.type in TARGET_TYPES and counts[o.type] == 1
              and o.obstacle]
    rng.shuffle(others)
    for other in others[:3]:
        got = _find_start(layout, free, other, lo, hi, max_steps, vis, rng, need_behind=False)
        if got is None:
            continue
        found = _visual_variant(layout, other, got[0], max_steps, vis, rng)
        if found is not None:
            return other, got[0], found[0], found[1]
    return None


def generate(seed: int = 0, scenes: int = 60, min_distance: float = 2.5, max_distance: float = 3.0,
             out: str | None = None, max_oracle_steps: int = 15) -> str:
    """Write a navigation task file with ``5 * scenes`` tasks; return a one-line summary.

    Args:
        seed: master seed (room seeds, starts and instruction wording all follow from it).
        scenes: number of distinct rooms; each gives one task per subset.
        min_distance / max_distance: horizontal start-to-target distance range, metres.
        out: output path (default ``navigation_tasks.json`` in the working directory).
        max_oracle_steps: longest oracle plan allowed for a base task (long_horizon may use 3 more, max 20).
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
    by_subset: dict[str, list[dict[str, Any]]] = {s: [] for s in SUBSETS}
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
                layout = generate_layout(kind, room_seed)
                counts: dict[str, int] = {}
                for o in layout.objects:
                    counts[o.type] = counts.get(o.type, 0) + 1
                names = [wanted] if attempt < 150 else list(TARGETS_BY_KIND[kind])
                candidates = [o for o in layout.objects if o.type in names and counts[o.type] == 1
                              and o.type in TARGET_TYPES]
                if not candidates:
                    continue
                target = candidates[int(rng.integers(len(candidates)))]
                free = FreeSpace(layout)
                found = _find_start(layout, free, target, lo, hi, max_oracle_steps, vis, rng)
                if found is None:
                    continue
                start, steps, steps_back = found
                visual = _visual_task(layout, free, target, start, counts, lo, hi, max_oracle_steps, vis, rng)
                if visual is None:
                    continue
                made = (layout, target, start, steps, steps_back, visual)
                break
            if made is None:
                raise RuntimeError(f"could not make a {kind} task for slot {slot} (try other distances)")
            layout, target, start, steps, steps_back, (v_target, v_start, extras, steps_visual) = made
            used.add((kind, layout.seed))
            other_types = sorted({o.type for o in layout.objects if o.type != target.type and o.obstacle})
            other = other_types[int(rng.integers(len(other_types)))] if other_types else None
            scene = {"kind": kind, "seed": layout.seed}
            common = {"scene": scene, "target": _target_dict(target)}
            n = len(by_subset["base"])
            by_subset["base"].append({"id": f"base_{n:03d}", "subset": "base",
                                      "instruction": instruction_for("base", target.type, target.colour, rng),
                                      **common, "start": _pose_dict(start), "extra_objects": [],
                                      "oracle_steps": steps})
            by_subset["common_sense"].append({"id": f"common_sense_{n:03d}", "subset": "common_sense",
                                              "instruction": instruction_for("common_sense", target.type,
                                                                             target.colour, rng),
                                              **common, "start": _pose_dict(start), "extra_objects": [],
                                              "oracle_steps": steps})
            by_subset["complex_instruction"].append({"id": f"complex_instruction_{n:03d}",
                                                     "subset": "complex_instruction",
                                                     "instruction": instruction_for("complex_instruction", target.type,
                                                                                    target.colour, rng, other),
                                                     **common, "start": _pose_dict(start), "extra_objects": [],
                                                     "oracle_steps": steps})
            by_subset["visual_appearance"].append({"id": f"visual_appearance_{n:03d}", "subset": "visual_appearance",
                                                   "instruction": instruction_for("visual_appearance", v_target.type,
                                                                                  v_target.colour, rng),
                                                   "scene": scene, "target": _target_dict(v_target),
                                                   "start": _pose_dict(v_start),
                                                   "extra_objects": [e.to_dict() for e in extras],
                                                   "oracle_steps": steps_visual})
            back = replace(start, heading=(start.heading + 2) % 4)
            by_subset["long_horizon"].append({"id": f"long_horizon_{n:03d}", "subset": "long_horizon",
                                              "instruction": instruction_for("long_horizon", target.type,
                                                                             target.colour, rng),
                                              **common, "start": _pose_dict(back), "extra_objects": [],
                                              "oracle_steps": steps_back})
    finally:
        vis.close()
    tasks = [t for s in SUBSETS for t in by_subset[s]]
    doc = {
        "format": TASK_FILE_FORMAT,
        "version": 1,
        "layout_version": LAYOUT_VERSION,
        "generator": {"function": "eb_navigation.generate:generate", "generator_version": GENERATOR_VERSION,
                      "seed": seed, "scenes": scenes, "min_distance": lo, "max_distance": hi,
                      "max_oracle_steps": max_oracle_steps},
        "tasks": tasks,
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ",\n".join("  " + json.dumps(t, separators=(", ", ": ")) for t in tasks)
    head = json.dumps({k: v for k, v in doc.items() if k != "tasks"}, indent=1)[:-2]
    path.write_text(head + ',\n "tasks": [\n' + lines + "\n ]\n}\n", encoding="utf-8")
    steps_all = [t["oracle_steps"] for t in tasks]
    return (f"wrote {len(tasks)} tasks ({scenes} scenes x {len(SUBSETS)} subsets) to {path}; "
            f"oracle steps {min(steps_all)}-{max(steps_all)}, mean {np.mean(steps_all):.1f}")
