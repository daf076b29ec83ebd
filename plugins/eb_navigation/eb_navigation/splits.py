"""Generated ``train`` and ``val`` splits of EB-Navigation, kept apart from the shipped test tasks.

Task ``i`` of a split is fixed by ``(split, i)``: its subset is ``SUBSETS[i % 5]`` and everything else is drawn
from a NumPy stream seeded by a SHA-256 of ``"navigation:<split>:<i>"``. Room seeds are drawn from
:data:`SEED_RANGE` (10,000,000 and up), far above the test generator's range (0..99,999) and the visual
in-context examples' rooms (100,000+), and a draw whose ``(kind, seed)`` is a shipped task's room is refused
anyway; so is a draw whose instruction is a shipped instruction word for word (the templates' least used
non-test wording is asked for first, so this is rare).

What the split keeps from the test generator (:mod:`eb_navigation.generate`): the room kinds and target types,
the start-distance and bearing rules per subset (2.5-3.5 m, target within 40 degrees ahead; long_horizon: target
at least 100 degrees off, up to 4.5 m, plan at least 2 actions longer than the shortest start of that room),
the look-alike placement of visual_appearance and the instruction templates. What it drops, to stay lazy
(well under a second per task): the rendered visibility check (the split checks the target's bearing, not
occlusion) and, for ``train``, the blind-policy / rule-agent filters. ``val`` keeps a per-task form of the
latter: of up to :data:`VAL_CANDIDATES` admissible starts it takes the one the fewest blind constant-action
policies solve. Every task is checked closed loop: the expert's shortest plan, stepped on the free space, must
end within 1 m of the target inside the step budget.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from eb_core.env import Task
from eb_core.taskfile import split_rng

__all__ = ["SEED_RANGE", "SPLITS", "split_tasks", "take_room", "test_keys", "write_split"]

SPLITS = ("train", "val")
SEED_RANGE = (10_000_000, 2**31 - 1)
"""Room seeds of the generated splits (the shipped tasks use 0..99,999, the visual examples 100,000+)."""
VAL_CANDIDATES = 8
"""Starts whose blind-policy successes ``val`` compares (``train`` takes a random admissible start)."""
MIN_DISTANCE, MAX_DISTANCE = 2.5, 3.5
MAX_ORACLE_STEPS = 15
MAX_TRIES = 300


@lru_cache(maxsize=4)
def test_keys(task_file: str | None = None) -> tuple[frozenset[tuple[str, int]], frozenset[str]]:
    """Rooms ``(kind, seed)`` and instructions of the shipped (or ``task_file``) test tasks."""
    from eb_navigation.tasks import load_task_file

    tasks = load_task_file(task_file).tasks
    return frozenset((t.scene.kind, t.scene.seed) for t in tasks), frozenset(t.instruction for t in tasks)


def _stream(split: str, index: int) -> np.random.Generator:
    """The random stream of split task ``index``: the core's :func:`~eb_core.taskfile.split_rng` for navigation."""
    return split_rng("navigation", split, index)


def _expert_solves(free: Any, state: Any, xy: tuple[float, float], budget: int) -> bool:
    """Closed loop on the geometry: replan from the current pose after every step, as the oracle model does."""
    from eb_navigation.geometry import SUCCESS_DISTANCE, distance_to

    for _ in range(budget):
        if distance_to(state, xy) <= SUCCESS_DISTANCE + 1e-9:
            return True
        plan = free.shortest_plan(state, xy)
        if not plan:
            return False
        state, ok, _reason = free.apply(state, int(plan[0]))
        if not ok:
            return False
    return distance_to(state, xy) <= SUCCESS_DISTANCE + 1e-9


def _one(split: str, index: int, rooms: frozenset[tuple[str, int]], instructions: frozenset[str]) -> Task:
    from eb_navigation.baselines import blind_successes, plan_lengths
    from eb_navigation.placement import (
        LONG_HORIZON_EXTRA,
        LONG_HORIZON_MAX_DISTANCE,
        MAX_START_BEARING,
        MIN_BEHIND_BEARING,
        TARGETS_BY_KIND,
        _extra_dict,
        _place_lookalikes,
        _pose_dict,
        _target_dict,
    )
    from eb_navigation.geometry import STEP, AgentState, bearing_to
    from eb_navigation.instructions import COMMON_SENSE_TYPES, instruction_for
    from eb_navigation.room import KINDS, NavRoom
    from eb_navigation.tasks import SUBSETS, NavTaskSpec

    subset = SUBSETS[index % len(SUBSETS)]
    rng = _stream(split, index)
    behind = subset == "long_horizon"
    for _ in range(MAX_TRIES):
        kind = KINDS[int(rng.integers(len(KINDS)))]
        seed = int(rng.integers(*SEED_RANGE))
        if (kind, seed) in rooms:
            continue
        room = NavRoom(kind, seed)
        counts = room.counts()
        options = [o for o in room.objects if o.type in TARGETS_BY_KIND[kind] and counts[o.type] == 1
                   and o.type in COMMON_SENSE_TYPES]
        if not options:
            continue
        target = options[int(rng.integers(len(options)))]
        extras: list[Any] = []
        if subset == "visual_appearance":
            extras = _place_lookalikes(room, target, rng) or []
            if not extras:
                continue
            room = NavRoom(kind, seed, extras)
        free = room.free_space(room.extra_ids)
        xy = (target.x, target.y)
        lengths = plan_lengths(free, xy)
        hi = MAX_DISTANCE + (LONG_HORIZON_MAX_DISTANCE if behind else 0.0)
        min_plan, max_plan = 1, MAX_ORACLE_STEPS + (2 if behind else 0)
        if behind:  # longer than the room's shortest visible-target start, as the test generator asks
            ahead = [n for (i, j, h), n in lengths.items() if n >= 1
                     and MIN_DISTANCE - 1e-9 <= math.hypot(i * STEP - xy[0], j * STEP - xy[1]) <= MAX_DISTANCE + 1e-9
                     and abs(bearing_to(AgentState(i, j, h), xy)) <= MAX_START_BEARING]
            min_plan = (min(ahead) if ahead else 1) + LONG_HORIZON_EXTRA
        cands = []
        for (i, j, h), n in sorted(lengths.items()):
            if not min_plan <= n <= max_plan:
                continue
            if not MIN_DISTANCE - 1e-9 <= math.hypot(i * STEP - xy[0], j * STEP - xy[1]) <= hi + 1e-9:
                continue
            s = AgentState(i, j, h)
            b = abs(bearing_to(s, xy))
            if (b < MIN_BEHIND_BEARING) if behind else (b > MAX_START_BEARING):
                continue
            cands.append((s, n))
        if not cands:
            continue
        order = [int(k) for k in rng.permutation(len(cands))]
        if split == "val":
            picked = order[:VAL_CANDIDATES]
            blind = [int(blind_successes(free, cands[k][0], xy).sum()) for k in picked]
            state, plan = cands[picked[int(np.argmin(blind))]]
        else:
            state, plan = cands[order[0]]
        if not _expert_solves(free, state, xy, plan + 2):
            continue
        others = sorted({o.type for o in room.objects if o.type != target.type and o.on_floor})
        other = others[int(rng.integers(len(others)))] if others else None
        used = {text: 10**6 for text in instructions}  # the least-used wording is then never a test one
        text, template = instruction_for(subset, target.type, target.colour, rng, other, used)
        if text in instructions:
            continue
        spec = NavTaskSpec.model_validate({
            "id": f"{split}_{subset}_{index:06d}", "subset": subset, "instruction": text, "template": template,
            "scene": {"kind": kind, "seed": seed}, "start": _pose_dict(state), "target": _target_dict(target),
            "extra_objects": [_extra_dict(e) for e in extras], "oracle_steps": plan})
        _keep_room(room)
        return spec.to_task()
    raise RuntimeError(f"navigation {split} task {index}: no valid draw in {MAX_TRIES} tries (a generator bug)")


_ROOMS: OrderedDict[tuple[Any, ...], Any] = OrderedDict()
ROOMS_KEPT = 4
"""Rooms the generator built for its latest tasks, kept for the reset that usually follows (``take_room``)."""


def _keep_room(room: Any) -> None:
    _ROOMS[(room.kind, room.seed, tuple(room.extras), room.clutter)] = room
    while len(_ROOMS) > ROOMS_KEPT:
        _ROOMS.popitem(last=False)


def take_room(kind: str, seed: int, extras: tuple[Any, ...], clutter: int | None = None) -> Any:
    """The room the generator just built and checked a task in, if it is the room ``(kind, seed, extras)``; each
    room is handed out once (the env then owns it), else None. A train reset right after drawing its task then
    skips laying out the same room a second time."""
    from eb_navigation.room import CLUTTER

    return _ROOMS.pop((kind, int(seed), tuple(extras), CLUTTER if clutter is None else int(clutter)), None)


def _one_level(split: str, index: int, difficulty: str, rooms: frozenset[tuple[str, int]]) -> Task:
    """Task ``index`` of a generated split at a harder level (:mod:`eb_navigation.hard`): the level's rooms,
    targets, look-alikes and start rules, without the rendered visibility check (bearing only) and without the
    per-file blind caps; checked closed loop like the classic split tasks."""
    from eb_navigation.hard import HARD_TYPES, LEVELS, Tally, draw_scene, scene_tasks
    from eb_navigation.geometry import AgentState
    from eb_navigation.room import KINDS
    from eb_navigation.tasks import SUBSETS, NavTaskSpec

    subset = SUBSETS[index % len(SUBSETS)]
    part = {"visual_appearance": "visual_appearance", "long_horizon": "long_horizon"}.get(subset, "plain")
    rng = _stream(f"{split}:{difficulty}", index)
    level = LEVELS[difficulty]
    for _ in range(MAX_TRIES):
        kind = KINDS[int(rng.integers(3))]
        seed = int(rng.integers(*SEED_RANGE))
        if (kind, seed) in rooms:
            continue
        type_name = HARD_TYPES[int(rng.integers(len(HARD_TYPES)))]
        sector = ("left", "behind", "right")[int(rng.integers(3))]
        sc = draw_scene(kind, seed, type_name, level, rng, {part: Tally(None)}, None, sector, parts=(part,))
        if sc is None:
            continue
        st = sc.starts[part]
        if not _expert_solves(sc.room.free_space(sc.room.extra_ids), st.state, (sc.target.x, sc.target.y),
                              st.plan + 2):
            continue
        entry = scene_tasks(sc, index, rng, {}, subsets=(subset,), id_prefix=f"{split}_{difficulty}_")[0]
        entry["id"] = f"{split}_{difficulty}_{subset}_{index:06d}"
        _keep_room(sc.room)
        assert isinstance(st.state, AgentState)
        return NavTaskSpec.model_validate(entry).to_task()
    raise RuntimeError(f"navigation {difficulty} {split} task {index}: no valid draw in {MAX_TRIES} tries")


_recent = lru_cache(maxsize=512)(_one)
_recent_level = lru_cache(maxsize=512)(_one_level)
"""The last 512 tasks made in this process: drawing and checking a task again (a reset of the same seed, a group
of rollouts from one task, ``options={"task_id": ...}``) is a dictionary look-up. Callers get deep copies."""


def split_tasks(split: str, start: int, count: int, task_file: str | None = None, difficulty: str = "classic",
                **_: Any) -> list[Task]:
    """Tasks ``start .. start + count - 1`` of the generated ``split`` (``train`` or ``val``) at ``difficulty``
    (``classic``, ``medium`` or ``hard``: a curriculum for trainers)."""
    if split not in SPLITS:
        raise ValueError(f"navigation: unknown split {split!r}; generated splits are {', '.join(SPLITS)} "
                         f"('test' is the shipped task file: load_tasks())")
    if start < 0 or count < 0:
        raise ValueError(f"navigation: split_tasks needs start >= 0 and count >= 0, got start={start}, count={count}")
    if difficulty not in ("classic", "medium", "hard"):
        raise ValueError(f"navigation: unknown difficulty {difficulty!r}; allowed: classic, medium, hard")
    rooms, instructions = test_keys(task_file)
    if difficulty != "classic":
        return [_recent_level(split, i, difficulty, rooms).model_copy(deep=True) for i in range(start, start + count)]
    return [_recent(split, i, rooms, instructions).model_copy(deep=True) for i in range(start, start + count)]


def write_split(out: str, split: str, n: int, start: int = 0, difficulty: str = "classic") -> list[Path]:
    """Write tasks ``start .. start + n - 1`` of ``split`` as one task file at ``out`` (a ``.json`` path, or a
    folder that gets ``navigation_<split>.json``), so that ``eb run env=navigation env.params.task_file=<file>``
    evaluates on them. Returns a one-line summary."""
    from eb_navigation.placement import GENERATOR_VERSION
    from eb_navigation.tasks import FORMAT

    path = Path(out)
    if path.suffix != ".json":
        path = path / f"navigation_{split}.json"
    tasks = [{"id": t.id, "subset": t.subset, "instruction": t.instruction, **t.metadata}
             for t in split_tasks(split, start, n, difficulty=difficulty)]
    generator = {"function": "eb_navigation.splits:split_tasks", "generator_version": GENERATOR_VERSION,
                 "split": split, "start": start, "n": n,
                 **({"difficulty": difficulty} if difficulty != "classic" else {})}
    return [FORMAT.write(path, tasks, generator=generator)]
