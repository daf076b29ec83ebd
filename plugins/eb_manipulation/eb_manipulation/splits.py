"""Generated ``train`` and ``val`` splits of EB-Manipulation, kept apart from the shipped test tasks.

Task ``i`` of a split is fixed by ``(split, i)``: its (subset, family) is ``COMBOS[i % 19]`` (the 19 pairs the
shipped file has, in file order), ``k = i // 19`` picks the stacking mode / wiping direction as ``k`` does in
:func:`eb_manipulation.generate.make_task`, and the layout is drawn by the same family builders from a scene seed
drawn, one per attempt, from the core's stream of the task (:func:`eb_core.taskfile.split_rng` of
``("manipulation", split, i)``; ``manipulation/d<level>`` for the harder levels). The shipped file seeds from
``SeedSequence([seed, subset, family, k, attempt])`` instead. A draw is refused, and the next
attempt drawn, when its scene seed or object layout is one of a shipped task, its instruction is a shipped
instruction word for word, or the scripted expert does not solve it closed loop (first action of each plan,
then re-plan) within the 15-step budget, checked in the physics-only simulator (no rendering).

``val`` keeps the shipped file's filters (open-loop and closed-loop oracle both solve); ``train`` drops the
open-loop check and only requires the closed-loop expert (about half the simulation per task). Tasks are served
by the core's :class:`~eb_core.taskfile.SplitSource` and written as core task files
(:data:`eb_manipulation.tasks.FORMAT`); split files of the older envelope (``format: 2``) still load.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from eb_core.env import Task
from eb_core.taskfile import SplitSource, split_rng

__all__ = ["COMBOS", "SPLITS", "layout_key", "split_tasks", "test_keys", "write_split"]

SPLITS = ("train", "val")
SPLIT_VERSION = "s2"
"""s1 hashed a seed per attempt from ``eb-manipulation-split/s1/<split>/<i>/<attempt>``; s2 draws them from the core's
:func:`~eb_core.taskfile.split_rng` stream."""
MAX_ATTEMPTS = 200


def _combos() -> tuple[tuple[str, str], ...]:
    from eb_manipulation.families import SUBSET_FAMILIES, SUBSETS

    return tuple((s, f) for s in SUBSETS for f in SUBSET_FAMILIES[s])


COMBOS = _combos()


def layout_key(metadata: dict[str, Any]) -> tuple[Any, ...]:
    """What makes two starting scenes the same: every object's kind, shape, colour and place (rounded to 1 mm)."""
    return tuple(sorted((o["kind"], o.get("shape"), o.get("colour"), round(float(o["x"]), 3),
                         round(float(o["y"]), 3)) for o in metadata["objects"]))


@lru_cache(maxsize=4)
def test_keys(task_file: str | None = None) -> tuple[frozenset[int], frozenset[Any], frozenset[str]]:
    """Scene seeds, layouts and instructions of the shipped (or ``task_file``) test tasks."""
    from eb_manipulation.tasks import load_task_file

    if task_file == "hard":
        from eb_manipulation.tasks import HARD_TASK_FILE

        tasks = load_task_file(HARD_TASK_FILE) if HARD_TASK_FILE.exists() else []
    else:
        tasks = load_task_file(task_file)
    return (frozenset(int(t.metadata["scene_seed"]) for t in tasks), frozenset(layout_key(t.metadata) for t in tasks),
            frozenset(t.instruction for t in tasks))


def _scene_seeds(split: str, index: int, level: int = 0) -> np.random.Generator:
    """The stream task ``index`` of ``split`` draws its scene seeds from (one per attempt); harder levels draw from
    their own stream."""
    return split_rng("manipulation" if not level else f"manipulation/d{level}", split, index)


def _one(split: str, index: int, keys: tuple[frozenset[int], frozenset[Any], frozenset[str]], level: int = 0) -> Task:
    from eb_manipulation.draw import draft_task, scene_metadata, verify_task
    from eb_manipulation.families import _Retry
    from eb_manipulation.spec import SceneSpec

    seeds, layouts, instructions = keys
    subset, family = COMBOS[index % len(COMBOS)]
    k = index // len(COMBOS)
    stream = _scene_seeds(split, index, level)
    for attempt in range(MAX_ATTEMPTS):
        scene_seed = int(stream.integers(2**32))
        if scene_seed in seeds:
            continue
        try:
            draft = draft_task(np.random.default_rng(scene_seed), family, subset, k, level)
        except _Retry:
            continue
        if draft.instruction in instructions:
            continue
        scene = SceneSpec(family=family, variant=draft.variant, scene_seed=scene_seed, objects=tuple(draft.objects),
                          goal=draft.goal, target_ids=draft.target_ids, template=draft.template)
        entry: dict[str, Any] = {"id": f"{split}_{subset}_{family}_{index:06d}", "subset": subset,
                                 "instruction": draft.instruction, "metadata": scene_metadata(scene)}
        if layout_key(entry["metadata"]) in layouts:
            continue
        ok, steps = verify_task(entry, closed_loop=True)
        if not ok:
            continue
        if split == "val":
            ok, steps = verify_task(entry)
            if not ok:
                continue
        entry["metadata"]["oracle_steps"] = steps
        entry["metadata"]["attempt"] = attempt
        return Task(**entry)
    raise RuntimeError(f"manipulation {split} task {index}: no valid draw in {MAX_ATTEMPTS} tries (a generator bug)")


SOURCE: SplitSource[Task] = SplitSource("manipulation", _one, splits=SPLITS)
"""The core's split source around :func:`_one`: the last 512 tasks made in this process are kept, so drawing and
checking a task again (a reset of the same seed, a group of rollouts from one task, ``options={"task_id": ...}``)
is a look-up. Callers get deep copies."""


def split_tasks(split: str, start: int, count: int, task_file: str | None = None, difficulty: str | int = "classic",
                **_: Any) -> list[Task]:
    """Tasks ``start .. start + count - 1`` of the generated ``split`` (``train`` or ``val``) at a difficulty
    (``classic``, ``medium``, ``hard``: a curriculum for trainers). Harder splits stay apart from both shipped sets."""
    from eb_manipulation.draw import level_of

    level = level_of(difficulty)
    SOURCE.check(split, start, count)
    keys = test_keys(task_file) if level == 0 or task_file is not None else _union(test_keys(None), test_keys("hard"))
    return SOURCE.tasks(split, start, count, keys=keys, level=level)


def _union(a: tuple[frozenset, ...], b: tuple[frozenset, ...]) -> tuple[frozenset, ...]:
    return tuple(x | y for x, y in zip(a, b))


def write_split(out: str, split: str, n: int, start: int = 0, difficulty: str | int = "classic") -> list[Path]:
    """Write tasks ``start .. start + n - 1`` of ``split`` as one task file ``out`` (a ``.json`` path, or a folder
    that gets ``manipulation_<split>.json``), so that ``eb run env=manipulation env.params.task_file=<file>``
    evaluates on them. Returns the paths written (one)."""
    from eb_manipulation.draw import LEVELS, level_of
    from eb_manipulation.tasks import FORMAT

    path = Path(out)
    if path.suffix != ".json":
        path = path / f"manipulation_{split}.json"
    level = level_of(difficulty)
    tasks = split_tasks(split, start, n, difficulty=level)
    name = {v: k for k, v in LEVELS.items()}[level]
    return [FORMAT.write(path, tasks, generator={"name": "eb_manipulation.splits:write_split", "version": SPLIT_VERSION,
                                                 "split": split, "start": start, "n": n, "difficulty": name,
                                                 "verified": True, "count": len(tasks)})]
