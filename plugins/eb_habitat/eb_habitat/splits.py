"""Generated ``train`` and ``val`` splits of EB-Habitat, kept apart from the shipped test tasks.

Task ``i`` of a split is fixed by ``(split, i)``: its subset is ``SUBSETS[i % 6]`` and it is drawn by the same
template builders as the shipped files, from a random stream named ``eb-habitat-split/<generator>/<split>/<i>``
(the shipped files draw from ``eb-habitat/<generator>/<seed>/<subset>``, so no stream is shared). A draw is
refused (and the stream drawn again) when its scene -- the apartment with every object's place and the open
receptacles -- is the scene of a shipped task, or its instruction is a shipped instruction word for word.
``difficulty=medium|hard`` (or ``taskset=hard`` in a run) draws with :mod:`eb_habitat.hard` instead, from the
stream ``eb-habitat-split/<difficulty>/<generator>/<split>/<i>``, and stays apart from the classic and the hard
test tasks alike (a curriculum: classic, then medium, then hard).
The apartments themselves are the three layouts of the catalog: train, val and test share them (as the
original's training set shares its scenes); what differs is the arrangement and the task.
"""

from __future__ import annotations

import random
from functools import lru_cache
from pathlib import Path
from typing import Any

from eb_core.env import Task
from eb_core.taskfile import SplitSource

__all__ = ["SPLITS", "scene_key", "split_tasks", "test_keys", "write_split"]

SPLITS = ("train", "val")


def scene_key(metadata: dict[str, Any]) -> tuple[Any, ...]:
    """What makes two tasks' starting scenes the same: apartment, object placements, open receptacles."""
    objects = tuple(sorted((o["name"], o["type"], o.get("color"), o["at"], o.get("slot")) for o in metadata["objects"]))
    return (metadata["apartment"], objects, tuple(sorted(metadata.get("open", ()))))


@lru_cache(maxsize=4)
def test_keys(task_dir: str | None = None, taskset: str = "classic") -> tuple[frozenset[tuple[Any, ...]],
                                                                              frozenset[str]]:
    """Scene keys and instructions of the shipped test tasks of ``taskset`` (or of ``task_dir``)."""
    from eb_habitat.tasks import load_tasks

    tasks = load_tasks(task_dir, taskset=taskset)
    return frozenset(scene_key(t.metadata) for t in tasks), frozenset(t.instruction for t in tasks)


def _all_test_keys() -> tuple[frozenset[tuple[Any, ...]], frozenset[str]]:
    """Scene keys and instructions of every shipped test set (classic and hard)."""
    from eb_habitat.tasks import TASKSETS

    parts = [test_keys(None, t) for t in TASKSETS]
    return frozenset().union(*(p[0] for p in parts)), frozenset().union(*(p[1] for p in parts))


def _one(split: str, index: int, scenes: frozenset[Any], instructions: frozenset[str],
         difficulty: str = "classic") -> Task:
    from eb_habitat.generate import BUILDERS, GENERATOR_VERSION, _finish, _Reject
    from eb_habitat.hard import draw
    from eb_habitat.tasks import SUBSETS

    subset = SUBSETS[index % len(SUBSETS)]
    stream = f"eb-habitat-split/{GENERATOR_VERSION}/{split}/{index}" if difficulty == "classic" else \
        f"eb-habitat-split/{difficulty}/{GENERATOR_VERSION}/{split}/{index}"
    rng = random.Random(stream)
    for _ in range(2000):
        try:
            entry = _finish(BUILDERS[subset](rng), subset, index) if difficulty == "classic" else \
                draw(subset, rng, difficulty, index)
        except _Reject:
            continue
        if entry is None or entry["instruction"] in instructions or scene_key(entry["metadata"]) in scenes:
            continue
        return Task(id=f"{split}-{subset}-{index:06d}", subset=subset, instruction=entry["instruction"],
                    metadata=entry["metadata"])
    raise RuntimeError(f"habitat {split} task {index}: no valid draw in 2000 tries (a generator bug)")


SOURCE: SplitSource[Task] = SplitSource("habitat", _one, splits=SPLITS)
"""The core's split source around :func:`_one`: the last 512 tasks made in this process are kept, so drawing and
checking a task again (a reset of the same seed, a group of rollouts from one task, ``options={"task_id": ...}``)
is a look-up. Callers get deep copies."""


def split_tasks(split: str, start: int, count: int, task_dir: str | None = None, difficulty: str = "classic",
                **_: Any) -> list[Task]:
    """Tasks ``start .. start + count - 1`` of the generated ``split`` (``train`` or ``val``) at ``difficulty``
    (classic, medium, hard: a curriculum)."""
    from eb_habitat.hard import DIFFICULTIES

    if difficulty not in DIFFICULTIES:
        raise ValueError(f"habitat: unknown difficulty {difficulty!r}; allowed: {', '.join(DIFFICULTIES)}")
    SOURCE.check(split, start, count)
    scenes, instructions = test_keys(task_dir) if difficulty == "classic" or task_dir else _all_test_keys()
    if difficulty == "classic":  # the classic call as before (same memo keys, same tasks)
        return SOURCE.tasks(split, start, count, scenes=scenes, instructions=instructions)
    return SOURCE.tasks(split, start, count, scenes=scenes, instructions=instructions, difficulty=difficulty)


def write_split(out: str, split: str, n: int, start: int = 0, difficulty: str = "classic") -> list[Path]:
    """Write tasks ``start .. start + n - 1`` of ``split`` as task files (one per subset) into the folder ``out``,
    so that ``eb run env=habitat env.params.task_file=<out>`` evaluates on them. Returns the paths written."""
    from eb_habitat.generate import GENERATOR_VERSION
    from eb_habitat.tasks import FILE_FORMAT, SUBSETS

    folder = Path(out)
    tasks = split_tasks(split, start, n, difficulty=difficulty)
    written = []
    for subset in SUBSETS:
        mine = [t.model_dump() for t in tasks if t.subset == subset]
        if not mine:
            continue
        generator = {"name": "eb_habitat.splits", "version": GENERATOR_VERSION, "seed": 0, "split": split,
                     "start": start, "n": n}
        if difficulty != "classic":
            generator["difficulty"] = difficulty
        written.append(FILE_FORMAT.write(folder / f"{subset}.json", mine, generator=generator, subset=subset))
    return written
