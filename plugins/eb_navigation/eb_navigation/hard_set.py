"""A whole harder task set: ``eb tasks generate env=navigation difficulty=hard seed=N`` (:func:`generate_level`).

Three passes, all seeded by ``seed``:

1. scene slot by slot, a room, its target and look-alikes and its starts (:func:`eb_navigation.hard.draw_scene`),
   each start refused when it would lift a blind policy or one of the cheaper feedback-only agents above ``cap``
   tasks of its subset;
2. :func:`repair` moves the starts that would lift any agent of :data:`~eb_navigation.baselines.CHECK_AGENTS`
   (side-step-first guesses, the core audit's feedback policies) above the cap;
3. :func:`seal` leaves no start that ANY of the 10,948 blind policies or of those agents solves: such a start moves
   to a clean one in its room, and a slot whose room has none left is drawn again (same kind, target type and
   long_horizon side). A blind or feedback-only player then solves no shipped task, so no sample of them either
   (``eb audit --quick`` plays 20 per subset).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

from eb_navigation.baselines import CHECK_AGENTS, blind_successes, rule_agent_successes
from eb_navigation.geometry import AgentState, bearing_to
from eb_navigation.hard import (
    DIFFICULTIES,
    HARD_TYPES,
    LEVELS,
    SEED_BASE,
    Level,
    Tally,
    _hidden,
    _pick,
    _Start,
    _visible,
    draw_scene,
    scene_tasks,
)
from eb_navigation.room import KINDS, NavRoom
from eb_navigation.tasks import SUBSETS

__all__ = ["SEAL_TRIES", "generate_level", "repair", "seal"]


def _start_of(room: NavRoom, entry: dict[str, Any], agents: dict[str, Any]) -> _Start:
    free = room.free_space(room.extra_ids)
    s = AgentState.from_pose(entry["start"]["x"], entry["start"]["y"], entry["start"]["yaw"])
    xy = (float(entry["target"]["position"][0]), float(entry["target"]["position"][1]))
    return _Start(s, int(entry["oracle_steps"]), blind_successes(free, s, xy),
                  np.array(list(rule_agent_successes(free, s, xy, agents=agents).values()), dtype=bool))


def repair(tasks: list[dict[str, Any]], level: Level, cap: int, rng: np.random.Generator, vis: Any | None,
           progress: bool = False) -> list[dict[str, Any]]:
    """Move the starts that would lift a blind policy or any of :data:`CHECK_AGENTS` above ``cap`` tasks of their
    subset (at least 5 % of the subset's tasks: the goal the set is held to); the rooms, targets and wording stay,
    a repaired in-view start may have the target up to 45 degrees off, 2-4.5 m away. Returns the entries."""
    from eb_navigation.tasks import NavTaskSpec

    cap = max(cap, int(0.05 * sum(t["subset"] == "base" for t in tasks) + 1e-9))
    rooms: dict[int, NavRoom] = {}
    groups = {"plain": "base", "visual_appearance": "visual_appearance", "long_horizon": "long_horizon"}
    by_id = {t["id"]: t for t in tasks}
    for part, subset in groups.items():
        entries = [t for t in tasks if t["subset"] == subset]
        starts = []
        for e in entries:
            key = int(e["scene"]["seed"])
            if key not in rooms:
                spec = NavTaskSpec.model_validate(e)
                rooms[key] = NavRoom(spec.scene.kind, spec.scene.seed, [x.spec() for x in spec.extra_objects],
                                     spec.scene.clutter)
            starts.append(_start_of(rooms[key], e, CHECK_AGENTS))
        stuck: set[int] = set()
        for _round in range(2 * len(entries)):
            blind = np.sum([s.blind for s in starts], axis=0)
            rules = np.sum([s.rules for s in starts], axis=0)
            over_b, over_r = blind > cap, rules > cap
            bad = [k for k, s in enumerate(starts) if ((s.blind & over_b).any() or (s.rules & over_r).any())
                   and k not in stuck]
            if not bad:
                break
            k = bad[0]
            e, room = entries[k], rooms[int(entries[k]["scene"]["seed"])]
            slot = e["id"].rsplit("_", 1)[1]
            tally = Tally(cap)
            others = [s for j, s in enumerate(starts) if j != k]
            tally.blind = np.sum([s.blind for s in others], axis=0).astype(np.int32)
            tally.rules = np.sum([s.rules for s in others], axis=0).astype(np.int32)
            pick = _replacement(part, e, room, by_id, starts[k].state, level, tally, rng, vis)
            if pick is None:
                if progress:
                    print(f"repair: no admissible start for {e['id']}", file=sys.stderr, flush=True)
                stuck.add(k)
                continue
            starts[k] = pick
            new = {"x": pick.state.x, "y": pick.state.y, "yaw": pick.state.yaw_deg, "tilt": 0}
            names = [e["id"]] if part != "plain" else [f"{s}_{slot}" for s in
                                                       ("base", "common_sense", "complex_instruction")]
            for name in names:
                by_id[name]["start"], by_id[name]["oracle_steps"] = dict(new), pick.plan
            if progress:
                print(f"repair: moved the start of {', '.join(names)}", file=sys.stderr, flush=True)
    return tasks


def _replacement(part: str, e: dict[str, Any], room: NavRoom, by_id: dict[str, dict[str, Any]], now: AgentState,
                 level: Level, tally: Tally, rng: np.random.Generator, vis: Any | None, strict: bool = False
                 ) -> _Start | None:
    """Another start for the task ``e`` (of ``part``) in its room, under the rules of a repaired start: a
    long_horizon start keeps its side (left, right, behind) and stays 2+ actions longer than base; an in-view start
    may have the target up to 45 degrees off, 2-4.5 m away, and stays 2+ actions shorter than long_horizon."""
    target = room.get(e["target"]["id"])
    looks = [o.id for o in room.objects if o.type == target.type and o.id != target.id]
    lo, hi = level.distance
    slot = e["id"].rsplit("_", 1)[1]
    if part == "long_horizon":
        base_plan = by_id[f"base_{slot}"]["oracle_steps"]
        b = bearing_to(now, (target.x, target.y))
        sector = "behind" if abs(b) > 135 else "left" if b > 0 else "right"
        return _pick(room, target, lo, hi + 1.0, base_plan + 2, level.lh_max_plan, sector, level, tally, rng,
                     lambda c: _hidden(room, c, target.id, vis), limit=400, agents=CHECK_AGENTS, strict=strict)
    lh_plan = by_id[f"long_horizon_{slot}"]["oracle_steps"]
    avoid = None
    if part == "visual_appearance":
        p = by_id[f"base_{slot}"]["start"]
        avoid = AgentState.from_pose(p["x"], p["y"], p["yaw"])
    top = level.max_plan if part == "visual_appearance" else max(min(level.max_plan, lh_plan - 2), 12)
    return _pick(room, target, lo - 0.5, hi + 1.0, 6, top, "wide", level, tally, rng,
                 lambda c: _visible(room, c, target.id, looks, level, vis), limit=400, avoid=avoid,
                 agents=CHECK_AGENTS, strict=strict)


_PARTS = {"plain": ("base", "common_sense", "complex_instruction"), "visual_appearance": ("visual_appearance",),
          "long_horizon": ("long_horizon",)}
SEAL_TRIES = 300
"""Rooms :func:`seal` draws for a slot whose room has no start left that no blind agent solves."""


def _room_of(entry: dict[str, Any]) -> NavRoom:
    from eb_navigation.tasks import NavTaskSpec

    spec = NavTaskSpec.model_validate(entry)
    return NavRoom(spec.scene.kind, spec.scene.seed, [x.spec() for x in spec.extra_objects], spec.scene.clutter)


def seal(tasks: list[dict[str, Any]], level: Level, rng: np.random.Generator, vis: Any | None,
         progress: bool = False) -> list[dict[str, Any]]:
    """The last pass: no task keeps a start that any blind policy (all 10,948) or any of :data:`CHECK_AGENTS`
    (the core audit's feedback policies among them) solves. Such a start moves to a clean one in the same room
    (the rules of :func:`repair`); a slot whose room has none left is drawn again (same kind, target type and
    long_horizon side; a new room, fresh wording). Returns the entries (in place where possible)."""
    by_id = {t["id"]: t for t in tasks}
    slots = sorted({t["id"].rsplit("_", 1)[1] for t in tasks})
    for slot in slots:
        room = _room_of(by_id[f"base_{slot}"])
        for part, names in _PARTS.items():
            e = by_id[f"{names[0]}_{slot}"]
            now = _start_of(room, e, CHECK_AGENTS)
            if not (now.blind.any() or now.rules.any()):
                continue
            pick = _replacement(part, e, room, by_id, now.state, level, Tally(None), rng, vis, strict=True)
            if pick is None:
                _redraw(slot, tasks, by_id, level, rng, vis, progress)
                break
            for name in names:
                by_id[f"{name}_{slot}"]["start"] = {"x": pick.state.x, "y": pick.state.y,
                                                   "yaw": pick.state.yaw_deg, "tilt": 0}
                by_id[f"{name}_{slot}"]["oracle_steps"] = pick.plan
            if progress:
                print(f"seal: moved the start of {', '.join(f'{n}_{slot}' for n in names)}", file=sys.stderr,
                      flush=True)
    return tasks


def _redraw(slot: str, tasks: list[dict[str, Any]], by_id: dict[str, dict[str, Any]], level: Level,
            rng: np.random.Generator, vis: Any | None, progress: bool) -> None:
    """Replace the five tasks of ``slot`` (in place) by those of a fresh room whose every start is clean."""
    old = {s: by_id[f"{s}_{slot}"] for s in SUBSETS}
    kind, type_name = old["base"]["scene"]["kind"], old["base"]["target"]["type"]
    lh = old["long_horizon"]
    s = AgentState.from_pose(lh["start"]["x"], lh["start"]["y"], lh["start"]["yaw"])
    b = bearing_to(s, (lh["target"]["position"][0], lh["target"]["position"][1]))
    sector = "behind" if abs(b) > 135 else "left" if b > 0 else "right"
    taken = {int(t["scene"]["seed"]) for t in tasks}
    wording: dict[str, dict[str, int]] = {}
    for t in tasks:
        if t["id"].rsplit("_", 1)[1] != slot:
            used = wording.setdefault(t["subset"], {})
            used[t["instruction"]] = used.get(t["instruction"], 0) + 1
            k = "#" + str(int(t["template"].rsplit(".", 1)[1]))
            used[k] = used.get(k, 0) + 1
    for attempt in range(SEAL_TRIES):
        seed = SEED_BASE + int(rng.integers(0, 100_000))
        if seed in taken:
            continue
        tallies = {p: Tally(None) for p in _PARTS}
        sc = draw_scene(kind, seed, type_name, level, rng, tallies, vis, sector, strict=True)
        if sc is None:
            continue
        for entry in scene_tasks(sc, int(slot), rng, wording):
            old[entry["subset"]].clear()
            old[entry["subset"]].update(entry)
        if progress:
            print(f"seal: slot {slot} drawn again ({kind} seed {seed}, {sc.target.colour} {type_name}, after "
                  f"{attempt + 1} room(s))", file=sys.stderr, flush=True)
        return
    raise RuntimeError(f"seal: no {kind} room with a {type_name} gives slot {slot} starts that no blind agent "
                       f"solves in {SEAL_TRIES} rooms; try another seed")


_SECTORS = ("left", "behind", "right")


def generate_level(level: str = "hard", seed: int = 0, scenes: int = 60, out: str | None = None,
                   cap: int | None = None, progress: bool = True) -> str:
    """Write a ``level`` task set: ``<out>/<subset>.json`` for the five subsets, ``scenes`` tasks each."""
    from eb_navigation.tasks import write_subset_files
    from eb_navigation.visibility import Visibility

    if level not in LEVELS:
        raise ValueError(f"unknown difficulty {level!r}; allowed: {', '.join(DIFFICULTIES)}")
    lv = LEVELS[level]
    scenes = int(scenes)
    if scenes < 1:
        raise ValueError(f"scenes must be at least 1, got {scenes}")
    cap = max(1, int(0.034 * scenes)) if cap is None else int(cap)
    rng = np.random.default_rng([int(seed), 0x4A4D, DIFFICULTIES.index(level)])
    tallies = {p: Tally(cap) for p in ("plain", "visual_appearance", "long_horizon")}
    wording: dict[str, dict[str, int]] = {}
    tasks: list[dict[str, Any]] = []
    vis = Visibility()
    try:
        for slot in range(scenes):
            kind = KINDS[slot % 3]  # kitchens, living rooms, bedrooms (bathrooms are too small for the clutter)
            type_name = HARD_TYPES[(slot // 3) % len(HARD_TYPES)]
            sector = _SECTORS[slot % len(_SECTORS)]
            sc = None
            for attempt in range(400):
                if attempt and attempt % 40 == 0:  # this type runs dry here: the next one
                    type_name = HARD_TYPES[(HARD_TYPES.index(type_name) + 1) % len(HARD_TYPES)]
                if attempt and attempt % 120 == 0:
                    kind = KINDS[(KINDS.index(kind) + 1) % 3]
                room_seed = SEED_BASE + int(rng.integers(0, 100_000))
                sc = draw_scene(kind, room_seed, type_name, lv, rng, tallies, vis, sector)
                if sc is not None:
                    break
            if sc is None:
                raise RuntimeError(f"could not make a {level} {kind} scene for slot {slot}; try another seed")
            for part, st in sc.starts.items():
                tallies[part].add(st)
            tasks.extend(scene_tasks(sc, slot, rng, wording))
            if progress:
                print(f"{level} slot {slot + 1}/{scenes}: {kind} seed {sc.room.seed}, {sc.target.colour} "
                      f"{sc.target.type} after {attempt + 1} room(s)", file=sys.stderr, flush=True)
    finally:
        vis.close()
    try:
        tasks = repair(tasks, lv, cap, np.random.default_rng([int(seed), 0x4A4D, DIFFICULTIES.index(level), 1]),
                       vis, progress)
        tasks = seal(tasks, lv, np.random.default_rng([int(seed), 0x4A4D, DIFFICULTIES.index(level), 2]), vis,
                     progress)
    finally:
        vis.close()
    gen = {"function": "eb_navigation.generate:generate", "difficulty": level, "seed": int(seed),
           "scenes": scenes, "cap": cap}
    paths = write_subset_files(Path(out or f"navigation_{level}"), tasks, gen)
    steps = [t["oracle_steps"] for t in tasks]
    return (f"wrote {len(tasks)} {level} tasks ({scenes} scenes x {len(SUBSETS)} subsets) to "
            f"{', '.join(str(p) for p in paths[:1])} ...; oracle steps {min(steps)}-{max(steps)}, "
            f"mean {np.mean(steps):.1f}")
