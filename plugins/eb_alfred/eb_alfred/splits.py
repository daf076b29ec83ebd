"""Generated ``train`` and ``val`` splits of EB-ALFRED, kept apart from the shipped test tasks.

Task ``i`` of a split is fixed by ``(split, i)``: its subset is ``SUBSETS[i % 6]``, its task type and every
random choice come from a stream named ``eb-alfred-split/<split>/<i>``, and its scene seeds are drawn from that
stream in ``[2**40, 2**41)`` -- the test generator numbers its scenes ``1000 * (subset + 1) + 100000 * seed + k``,
far below. The candidate is made by the test generator's own draw (:func:`eb_alfred.draw.make_one`; same rooms,
goals, instruction templates, oracle step ranges), but symbolically only: the render checks the test files get for
``spatial_awareness`` and ``visual_appearance`` (every referred thing visible in an image, :func:`image_problems`)
and the long-horizon plan-length spread are skipped, so a train task may name a relation that is hard to see.
A draw is refused (and drawn again) when its furniture layout or its full scene is one of a shipped task, or its
instruction is a shipped instruction word for word, and it is kept only when the expert's plan, played on the
symbolic world, reaches the goal.

``difficulty=medium|hard`` (or ``taskset=hard`` in a run) draws from :func:`eb_alfred.hard.make_hard` instead, from
the stream ``eb-alfred-split/<difficulty>/<split>/<i>``, kept apart from the classic and the hard test tasks: a
curriculum from classic through medium to hard.
"""

from __future__ import annotations

import random
from functools import lru_cache
from pathlib import Path
from typing import Any

from eb_core.env import Task
from eb_core.taskfile import SplitSource

__all__ = ["SPLITS", "layout_key", "scene_key", "split_tasks", "test_keys", "write_split"]

SPLITS = ("train", "val")
#: Scene seeds of split tasks lie in [SEED_BASE, 2 * SEED_BASE); the test generator's are far below.
SEED_BASE = 2**40
_TRIES = 3000


def layout_key(scene: dict[str, Any]) -> tuple[Any, ...]:
    """The room and its furniture along the walls (type and slot of everything standing in the room)."""
    return (scene["room"], tuple(sorted((o["type"], o.get("slot")) for o in scene["objects"]
                                        if o.get("parent") is None)))


def scene_key(scene: dict[str, Any]) -> tuple[Any, ...]:
    """The whole starting scene: every object with its place and state."""
    return (scene["room"], tuple(sorted(tuple(sorted((k, str(v)) for k, v in o.items())) for o in scene["objects"])))


@lru_cache(maxsize=4)
def test_keys(task_dir: str | None = None) -> tuple[frozenset[Any], frozenset[Any], frozenset[str], frozenset[int]]:
    """Layouts, scenes, instructions and scene seeds of the shipped (or ``task_dir``) test tasks."""
    from eb_alfred.tasks import load_all

    recs = load_all(Path(task_dir) if task_dir else None)
    scenes = [r.scene.model_dump(exclude_defaults=True) for r in recs]
    return (frozenset(layout_key(s) for s in scenes), frozenset(scene_key(s) for s in scenes),
            frozenset(r.instruction for r in recs), frozenset(r.scene_seed for r in recs))


def _solves(rec: dict[str, Any]) -> bool:
    """The expert's plan, played action by action on the symbolic world, reaches the goal."""
    from eb_alfred.goals import evaluate
    from eb_alfred.oracle import expert_plan
    from eb_alfred.world import World

    world = World.from_scene(rec["scene"])
    plan = expert_plan(world, rec["goal"])
    if plan is None:
        return False
    for action in plan:
        ok, _ = world.step(action)
        if not ok:
            return False
    return evaluate(rec["goal"], world)[0]


def _one(split: str, index: int, keys: tuple[Any, ...], difficulty: str = "classic") -> Task:
    from eb_alfred.draw import LONG_ROOMS
    from eb_alfred.goals import GOAL_KINDS
    from eb_alfred.hard import KINDS, maker
    from eb_alfred.tasks import SUBSETS, TaskRecord

    draw = maker(difficulty)
    layouts, scenes, instructions, seeds = keys
    subset = SUBSETS[index % len(SUBSETS)]
    kinds = [k for k in GOAL_KINDS if (subset != "long_horizon" or k in LONG_ROOMS)
             and (difficulty == "classic" or k in KINDS)]
    stream = f"eb-alfred-split/{split}/{index}" if difficulty == "classic" else \
        f"eb-alfred-split/{difficulty}/{split}/{index}"
    rng = random.Random(stream)
    kind = kinds[rng.randrange(len(kinds))]
    for attempt in range(_TRIES):
        if attempt and attempt % 200 == 0:  # a type that keeps failing in this stream: try another
            kind = kinds[rng.randrange(len(kinds))]
        seed = SEED_BASE + rng.randrange(SEED_BASE)
        if seed in seeds:
            continue
        rec = draw(subset, kind, seed, rng, None)
        if rec is None or rec["instruction"] in instructions:
            continue
        if layout_key(rec["scene"]) in layouts or scene_key(rec["scene"]) in scenes or not _solves(rec):
            continue
        rec = TaskRecord.model_validate({"id": f"{split}_{subset}_{index:06d}", "subset": subset, **rec})
        meta = {"task_type": rec.task_type, "goal": rec.goal.plain(),
                "scene": rec.scene.model_dump(exclude_defaults=True), "scene_seed": rec.scene_seed,
                "oracle_steps": rec.oracle_steps, "notes": rec.notes, "template": rec.template, "split": split}
        if difficulty != "classic":
            meta["difficulty"] = difficulty
        return Task(id=rec.id, subset=subset, instruction=rec.instruction, metadata=meta)
    raise RuntimeError(f"alfred {split} task {index}: no valid draw in {_TRIES} tries (a generator bug)")


SOURCE: SplitSource[Task] = SplitSource("alfred", _one, splits=SPLITS)
"""The core's split source around :func:`_one`: the last 512 tasks made in this process are kept, so drawing and
checking a task again (a reset of the same seed, a group of rollouts from one task, ``options={"task_id": ...}``)
is a look-up. Callers get deep copies."""


def split_tasks(split: str, start: int, count: int, task_dir: str | None = None, difficulty: str = "classic",
                **_: Any) -> list[Task]:
    """Tasks ``start .. start + count - 1`` of the generated ``split`` (``train`` or ``val``) at generator level
    ``difficulty`` (classic, medium, hard: a curriculum). Classic splits stay apart from the classic test tasks;
    the harder levels from the classic and the hard ones."""
    from eb_alfred.draw import DIFFICULTIES

    if difficulty not in DIFFICULTIES:
        raise ValueError(f"alfred: unknown difficulty {difficulty!r}; allowed: {', '.join(DIFFICULTIES)}")
    SOURCE.check(split, start, count)
    keys = test_keys(task_dir) if difficulty == "classic" or task_dir else _all_test_keys()
    return SOURCE.tasks(split, start, count, keys=keys, difficulty=difficulty)


@lru_cache(maxsize=1)
def _all_test_keys() -> tuple[frozenset[Any], ...]:
    """The keys of every shipped test set (classic and hard) together."""
    from eb_alfred.tasks import TASKSETS, taskset_dir

    parts = [test_keys(None)] + [test_keys(str(taskset_dir(t))) for t in TASKSETS[1:]
                                 if (taskset_dir(t) / "base.json").is_file()]
    return tuple(frozenset().union(*(p[i] for p in parts)) for i in range(4))


def write_split(out: str, split: str, n: int, start: int = 0, difficulty: str = "classic") -> list[Path]:
    """Write tasks ``start .. start + n - 1`` of ``split`` as task files (one per subset) into the folder ``out``,
    so that ``eb run env=alfred env.params.task_file=<out>`` evaluates on them. Every subset gets a file (empty
    when ``n`` is small), since the loader reads all six. Returns the paths written."""
    from eb_alfred.tasks import FILE_FORMAT, SUBSETS

    folder = Path(out)
    tasks = split_tasks(split, start, n, difficulty=difficulty)
    written = []
    generator: dict[str, Any] = {"function": "eb_alfred.splits:write_split", "split": split, "start": start, "n": n}
    if difficulty != "classic":
        generator["difficulty"] = difficulty
    for subset in SUBSETS:
        mine = [{"id": t.id, "subset": t.subset, "instruction": t.instruction,
                 **{k: v for k, v in t.metadata.items() if k not in ("split", "difficulty")}}
                for t in tasks if t.subset == subset]
        written.append(FILE_FORMAT.write(folder / f"{subset}.json", mine, generator=generator, subset=subset))
    return written
