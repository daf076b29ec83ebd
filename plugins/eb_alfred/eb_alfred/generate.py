"""The task generator: scene seeds -> the six versioned task files (``eb tasks generate env=alfred``).

Candidates come from :func:`eb_alfred.draw.make_one`; this module walks scene seeds per subset, keeps task types
in turn, drops repeated instructions, spreads long-horizon plan lengths and writes the files through the core's
task-file format. ``difficulty=classic|medium|hard`` selects how the scenes and instructions are made
(:mod:`eb_alfred.hard`); the output is deterministic for a given ``seed`` and difficulty.
"""

from __future__ import annotations

import random
import sys
from pathlib import Path
from typing import Any

from eb_alfred.draw import DIFFICULTIES, LONG_ROOMS, STEP_RANGE, image_problems, make_one, propose_goal  # noqa: F401
from eb_alfred.goals import GOAL_KINDS
from eb_alfred.tasks import FILE_FORMAT, SUBSETS, TASK_DIR

__all__ = ["audit_form", "generate", "make_tasks", "propose_goal", "image_problems"]

_make_one = make_one  # the old private name, kept for callers outside the package


def _views_factory() -> tuple[Any, Any]:
    """A ``views_for(world)`` callable sharing one offscreen renderer, and its closer."""
    from eb_alfred.audit import Views
    from eb_alfred.render import AlfredRenderer

    renderer = AlfredRenderer(250)
    return (lambda world: Views(world, renderer)), renderer.close


def make_tasks(subset: str, seed: int = 0, n: int = 50, render_checks: bool = True,
               difficulty: str = "classic", progress: bool = False) -> list[dict[str, Any]]:
    """``n`` tasks of ``subset``, task types in turn, deterministic for ``seed`` and ``difficulty``.

    ``render_checks`` renders each candidate to check that what the instruction refers to can be seen (classic:
    spatial_awareness and visual_appearance; harder levels: every subset); it needs MuJoCo. ``progress`` prints a
    line per kept task to stderr.
    """
    from eb_alfred.hard import KINDS, maker

    draw = maker(difficulty)
    classic = difficulty == "classic"
    rng = random.Random(f"eb-alfred/{seed}/{subset}" if classic else f"eb-alfred/{difficulty}/{seed}/{subset}")
    base_seed = 1000 * (SUBSETS.index(subset) + 1) + 100_000 * seed + (0 if classic else 50_000)
    tasks: list[dict[str, Any]] = []
    scene_seed = base_seed
    count = {k: 0 for k in GOAL_KINDS}
    misses = {k: 0 for k in GOAL_KINDS}
    views_for, close = (None, lambda: None)
    if render_checks and (subset in ("spatial_awareness", "visual_appearance") or not classic):
        views_for, close = _views_factory()
    seen_text: set[str] = set()
    try:
        while len(tasks) < n:
            # The task type with the fewest tasks so far (types that keep failing are given up on).
            open_kinds = [k for k in GOAL_KINDS if misses[k] < (400 if classic else 3000)
                          and (subset != "long_horizon" or k in LONG_ROOMS) and (classic or k in KINDS)]
            if not open_kinds:
                raise RuntimeError(f"could not generate {n} {subset} tasks (got {len(tasks)})")
            kind = min(open_kinds, key=lambda k: (count[k], GOAL_KINDS.index(k)))
            scene_seed += 1
            rec = draw(subset, kind, scene_seed, rng, views_for)
            if rec is None or rec["instruction"] in seen_text:
                misses[kind] += 1
                continue
            if subset == "long_horizon" and _too_common(rec, tasks):
                misses[kind] += 1
                continue
            seen_text.add(rec["instruction"])
            misses[kind] = 0
            count[kind] += 1
            tasks.append({"id": f"{subset}_{len(tasks):02d}", "subset": subset, **rec})
            if progress:
                print(f"alfred {difficulty} {subset}: {len(tasks)}/{n} (scene seed {scene_seed})", file=sys.stderr,
                      flush=True)
    finally:
        close()
    return tasks


def _too_common(rec: dict[str, Any], tasks: list[dict[str, Any]]) -> bool:
    """Spread long-horizon plan lengths: no plan length in more than a third of the tasks."""
    k = len(tasks) + 1
    same_len = sum(t["oracle_steps"] == rec["oracle_steps"] for t in tasks)
    return same_len + 1 > max(2, int(0.34 * k) + 1)


def generate(out: str | None = None, seed: int = 0, n: int | None = None, subset: str | None = None,
             split: str = "test", start: int = 0, difficulty: str = "classic") -> list[Path]:
    """Write task files. ``out``: a directory (one ``<subset>.json`` each) or a ``.json`` path with ``subset``.

    Defaults to the package's own folder of the level (``tasks/`` for classic, ``tasks/hard/`` for hard: the
    shipped, versioned files; ``n`` tasks per subset, 50 by default); other levels need ``out``.
    ``difficulty=classic|medium|hard`` picks the generator level (:mod:`eb_alfred.hard`). ``split=train|val n=N
    [start=K] out=DIR`` writes tasks ``K .. K+N-1`` of a generated training split instead (disjoint from the
    shipped test tasks; :mod:`eb_alfred.splits`), at the same ``difficulty`` (a curriculum). Progress goes to
    stderr.
    """
    if difficulty not in DIFFICULTIES:
        raise ValueError(f"unknown difficulty {difficulty!r}; allowed: {', '.join(DIFFICULTIES)}")
    if split != "test":
        from eb_alfred.splits import SPLITS, write_split

        if split not in SPLITS:
            raise ValueError(f"unknown split {split!r}; allowed: test (the shipped tasks), {', '.join(SPLITS)}")
        if not n or out is None:
            raise ValueError(f"split={split} needs n=<tasks, >= 1> and out=<folder> (the shipped tasks/ folder "
                             f"holds the test split only)")
        return write_split(str(out), split, int(n), int(start), difficulty=difficulty)
    n = 50 if n is None else n
    subsets = [subset] if subset else list(SUBSETS)
    for s in subsets:
        if s not in SUBSETS:
            raise ValueError(f"unknown subset {s!r}; choose from {', '.join(SUBSETS)}")
    if out is None and difficulty == "medium":
        raise ValueError("difficulty=medium ships no task files; give out=<folder>")
    target = Path(out) if out else (TASK_DIR if difficulty == "classic" else TASK_DIR / difficulty)
    if target.suffix == ".json" and len(subsets) != 1:
        raise ValueError("writing a single .json file needs subset=<name>")
    written = []
    for s in subsets:
        path = target if target.suffix == ".json" else target / f"{s}.json"
        generator: dict[str, Any] = {"function": "eb_alfred.generate:generate", "seed": seed, "n": n}
        if difficulty != "classic":
            generator["difficulty"] = difficulty
        tasks = make_tasks(s, seed=seed, n=n, difficulty=difficulty, progress=True)
        written.append(FILE_FORMAT.write(path, tasks, generator=generator, subset=s))
    return written


def audit_form(out: str, seed: int, per_subset: int, difficulty: str = "classic") -> list[Path]:
    """A fresh form of ``per_subset`` tasks per subset (a folder at ``out``, render checks included) for ``eb
    audit``'s parallel-forms probe, at ``difficulty`` (``taskset=hard`` audits pass ``hard``). Subsets are drawn
    independently and task types in turn, so the sample keeps the full file's mix."""
    return generate(out=out, seed=seed, n=per_subset, difficulty=difficulty)


if __name__ == "__main__":  # python -m eb_alfred.generate [difficulty]
    for p in generate(difficulty=sys.argv[1] if len(sys.argv) > 1 else "classic"):
        print("wrote", p)
