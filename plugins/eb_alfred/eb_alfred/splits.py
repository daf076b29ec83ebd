"""Generated ``train`` and ``val`` splits of EB-ALFRED, kept apart from the shipped test tasks.

Task ``i`` of a split is fixed by ``(split, i)``: its subset is ``SUBSETS[i % 6]``, its task type and every
random choice come from a stream named ``eb-alfred-split/<split>/<i>``, and its scene seeds are drawn from that
stream in ``[2**40, 2**41)`` -- the test generator numbers its scenes ``1000 * (subset + 1) + 100000 * seed + k``,
far below. The candidate is made by the test generator's own ``_make_one`` (same rooms, goals, instruction
templates, oracle step ranges), but symbolically only: the render checks the test files get for
``spatial_awareness`` and ``visual_appearance`` (every referred thing visible in an image, :func:`image_problems`)
and the long-horizon plan-length spread are skipped, so a train task may name a relation that is hard to see.
A draw is refused (and drawn again) when its furniture layout or its full scene is one of a shipped task, or its
instruction is a shipped instruction word for word, and it is kept only when the expert's plan, played on the
symbolic world, reaches the goal.
"""

from __future__ import annotations

import random
from functools import lru_cache
from typing import Any

from eb_core.env import Task

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
    from pathlib import Path

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


def _one(split: str, index: int, keys: tuple[Any, ...]) -> Task:
    from eb_alfred.generate import LONG_ROOMS, _make_one
    from eb_alfred.goals import GOAL_KINDS
    from eb_alfred.tasks import SUBSETS, TaskRecord

    layouts, scenes, instructions, seeds = keys
    subset = SUBSETS[index % len(SUBSETS)]
    kinds = [k for k in GOAL_KINDS if subset != "long_horizon" or k in LONG_ROOMS]
    rng = random.Random(f"eb-alfred-split/{split}/{index}")
    kind = kinds[rng.randrange(len(kinds))]
    for attempt in range(_TRIES):
        if attempt and attempt % 200 == 0:  # a type that keeps failing in this stream: try another
            kind = kinds[rng.randrange(len(kinds))]
        seed = SEED_BASE + rng.randrange(SEED_BASE)
        if seed in seeds:
            continue
        rec = _make_one(subset, kind, seed, rng, None)
        if rec is None or rec["instruction"] in instructions:
            continue
        if layout_key(rec["scene"]) in layouts or scene_key(rec["scene"]) in scenes or not _solves(rec):
            continue
        rec = TaskRecord.model_validate({"id": f"{split}_{subset}_{index:06d}", "subset": subset, **rec})
        return Task(id=rec.id, subset=subset, instruction=rec.instruction,
                    metadata={"task_type": rec.task_type, "goal": rec.goal.plain(),
                              "scene": rec.scene.model_dump(exclude_defaults=True), "scene_seed": rec.scene_seed,
                              "oracle_steps": rec.oracle_steps, "notes": rec.notes, "template": rec.template,
                              "split": split})
    raise RuntimeError(f"alfred {split} task {index}: no valid draw in {_TRIES} tries (a generator bug)")


_recent = lru_cache(maxsize=512)(_one)
"""The last 512 tasks made in this process: drawing and checking a task again (a reset of the same seed, a group
of rollouts from one task, ``options={"task_id": ...}``) is a dictionary look-up. Callers get deep copies."""


def split_tasks(split: str, start: int, count: int, task_dir: str | None = None, **_: Any) -> list[Task]:
    """Tasks ``start .. start + count - 1`` of the generated ``split`` (``train`` or ``val``)."""
    if split not in SPLITS:
        raise ValueError(f"alfred: unknown split {split!r}; generated splits are {', '.join(SPLITS)} "
                         f"('test' is the shipped tasks: load_tasks())")
    if start < 0 or count < 0:
        raise ValueError(f"alfred: split_tasks needs start >= 0 and count >= 0, got start={start}, count={count}")
    keys = test_keys(task_dir)
    return [_recent(split, i, keys).model_copy(deep=True) for i in range(start, start + count)]


def write_split(out: str, split: str, n: int, start: int = 0) -> list[str]:
    """Write tasks ``start .. start + n - 1`` of ``split`` as task files (one per subset) into the folder ``out``,
    so that ``eb run env=alfred env.params.task_dir=<out>`` evaluates on them. Every subset gets a file (empty
    when ``n`` is small), since the loader reads all six. Returns the paths written."""
    import json
    from pathlib import Path

    from eb_alfred.tasks import FORMAT, SUBSETS, VERSION

    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    tasks = split_tasks(split, start, n)
    written = []
    for subset in SUBSETS:
        mine = [{"id": t.id, "subset": t.subset, "instruction": t.instruction,
                 **{k: v for k, v in t.metadata.items() if k != "split"}} for t in tasks if t.subset == subset]
        doc = {"format": FORMAT, "version": VERSION, "subset": subset,
               "generator": {"function": "eb_alfred.splits:write_split", "split": split, "start": start, "n": n},
               "tasks": mine}
        path = folder / f"{subset}.json"
        path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
        written.append(str(path))
    return written
