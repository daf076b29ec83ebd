"""Task generator: seeded layouts, our instruction templates, oracle-verified, written as a versioned file.

``eb tasks generate env=manipulation out=tasks.json seed=0`` calls :func:`generate`. For every
(subset, family, k) it draws a layout from a seeded RNG, writes the instruction, and (unless
``verify=False``) runs the scripted oracle in the simulator; a layout the oracle cannot solve within the
15-step budget is redrawn with the next attempt number, so every shipped task is solvable.

The shipped file ``eb_manipulation/tasks/manipulation_v2.json`` is ``generate(seed=0)``.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from eb_manipulation.draw import LEVELS, MAX_ORACLE_STEPS, draft_task, scene_metadata, verify_task
from eb_manipulation.draw import level_of as _level
from eb_manipulation.families import (  # noqa: F401 - re-exported for callers of the old module layout
    _FAMILY_FN,
    FAMILY_ORDER,
    PER_FAMILY,
    REGION_X,
    REGION_Y,
    SUBSET_FAMILIES,
    SUBSETS,
    _Retry,
)
from eb_manipulation.spec import HARD_SLACK, TASK_FORMAT, SceneSpec

__all__ = ["FAMILY_ORDER", "SUBSET_FAMILIES", "TASKS_VERSION", "audit_form", "generate", "make_task",
           "verify_task"]

TASKS_VERSION = "v2"
DEFAULT_OUT = Path(__file__).parent / "tasks" / f"manipulation_{TASKS_VERSION}.json"


def task_id(subset: str, family: str, k: int) -> str:
    return f"{subset}_{family}_{k:02d}"

def make_task(seed: int, subset: str, family: str, k: int, attempt: int, level: int = 0) -> dict[str, Any]:
    """One task as a dict (``id``, ``subset``, ``instruction``, ``metadata``), without verification.

    ``level`` is the difficulty (0 classic, 1 medium, 2 hard); levels above 0 seed from their own namespace."""
    entropy = [seed, SUBSETS.index(subset), FAMILY_ORDER.index(family), k, attempt] + ([7000 + level] if level else [])
    scene_seed = int(np.random.SeedSequence(entropy).generate_state(1)[0])
    rng = np.random.default_rng(scene_seed)
    draft = draft_task(rng, family, subset, k, level)
    scene = SceneSpec(family=family, variant=draft.variant, scene_seed=scene_seed, objects=tuple(draft.objects),
                      goal=draft.goal, target_ids=draft.target_ids, template=draft.template)
    return {"id": task_id(subset, family, k), "subset": subset, "instruction": draft.instruction,
            "metadata": scene_metadata(scene)}



def generate(out: str | Path | None = None, seed: int = 0, verify: bool = True, per_family: int = PER_FAMILY,
             subsets: list[str] | tuple[str, ...] | str | None = None, max_attempts: int | None = None,
             quiet: bool = False, split: str = "test", n: int | None = None, start: int = 0,
             difficulty: str | int = "classic") -> Path | str | list[Path]:
    """Generate the task file and return its path.

    Args:
        out: Where to write; default: the package's ``tasks/manipulation_v2.json``.
        seed: Master seed; every task's scene seed derives from it.
        verify: Run the oracle on every task, open and closed loop, and redraw layouts it cannot solve.
        per_family: Tasks per (subset, family); 12 gives the paper's 228.
        subsets: Restrict to some subsets (a name or a list).
        split: ``train`` or ``val`` writes tasks ``start .. start + n - 1`` of a generated training split instead
            (disjoint from the shipped tasks; :mod:`eb_manipulation.splits`) to ``out`` (a ``.json`` file or a
            folder), for ``eb run env=manipulation env.params.task_file=<file>``.
        difficulty: ``classic`` (the paper's scenes; the shipped classic file), ``medium`` or ``hard`` (or 0, 1,
            2): more objects, look-alikes in near shades, "only" conditions, multi-hop spatial references
            (:mod:`eb_manipulation.hard`). Without ``out``, ``hard`` with seed 0 rewrites the shipped hard file and
            any other seed or level writes ``manipulation_<difficulty>_seed<N>.json`` in the current folder.
            Progress goes to stderr.
    """
    level = _level(difficulty)
    if split != "test":
        return _write_split(out, split, n, start, level)
    if max_attempts is None:
        max_attempts = 40 if level == 0 else 300
    out_path = _out_path(out, level, seed, difficulty)
    chosen = _chosen(subsets)
    tasks: list[dict[str, Any]] = []
    t0 = time.time()
    for subset in chosen:
        seen: set[str] = set()  # every instruction of a subset is different
        for family in SUBSET_FAMILIES[subset]:
            tasks += [_solvable(seed, subset, family, k, level, max_attempts, verify, seen) for k in range(per_family)]
            if not quiet:
                print(f"  {subset:<13} {family:<7} {per_family} tasks  ({time.time() - t0:.0f}s)", flush=True,
                      file=sys.stderr if level else sys.stdout)
    _write(out_path, tasks, level, seed, verify)
    if not quiet:
        name = {v: k for k, v in LEVELS.items()}.get(level, str(level))
        what = f"{len(tasks)} tasks ({name})" if level else f"{len(tasks)} tasks"
        print(f"wrote {what} to {out_path}", file=sys.stderr if level else sys.stdout)
    return out_path


def _write_split(out: str | Path | None, split: str, n: int | None, start: int, level: int) -> list[Path]:
    """``generate(split=train|val)``: tasks ``start .. start + n - 1`` of a generated split, to ``out``."""
    from eb_manipulation.splits import SPLITS, write_split

    if split not in SPLITS:
        raise ValueError(f"unknown split {split!r}; allowed: test (the shipped tasks), {', '.join(SPLITS)}")
    if n is None or int(n) < 1 or out is None:
        raise ValueError(f"split={split} needs n=<tasks, >= 1> and out=<file.json or folder> (the shipped "
                         f"task file holds the test split only)")
    return write_split(str(out), split, int(n), int(start), difficulty=level)


def _out_path(out: str | Path | None, level: int, seed: int, difficulty: str | int) -> Path:
    """Where a test-split file goes: ``out``, else the shipped file of its set (classic; hard seed 0), else a fresh
    form's own name in the current folder (it never overwrites a shipped file)."""
    if out is not None:
        return Path(out)
    if level == 0:
        return DEFAULT_OUT
    if level == LEVELS["hard"] and seed == 0:
        from eb_manipulation.tasks import HARD_TASK_FILE

        return HARD_TASK_FILE
    return Path.cwd() / f"manipulation_{difficulty}_seed{seed}.json"


def _chosen(subsets: list[str] | tuple[str, ...] | str | None) -> tuple[str, ...]:
    chosen = SUBSETS if subsets is None else ((subsets,) if isinstance(subsets, str) else tuple(subsets))
    unknown = [s for s in chosen if s not in SUBSETS]
    if unknown:
        raise ValueError(f"unknown subsets {unknown}; known: {list(SUBSETS)}")
    return tuple(chosen)


def _solvable(seed: int, subset: str, family: str, k: int, level: int, max_attempts: int, verify: bool,
              seen: set[str]) -> dict[str, Any]:
    """The first draw of (subset, family, k) whose instruction is new in ``seen`` and (``verify``) that the expert
    solves open and closed loop within the budget; its instruction is added to ``seen``."""
    for attempt in range(max_attempts):
        try:
            task = make_task(seed, subset, family, k, attempt, level)
        except _Retry:
            continue
        if task["instruction"] in seen:
            continue
        if verify:
            budget = MAX_ORACLE_STEPS - (HARD_SLACK if level >= 2 else 0)
            ok, steps = verify_task(task, max_steps=budget)
            if not ok or not verify_task(task, max_steps=budget, closed_loop=True)[0]:
                continue
            task["metadata"]["oracle_steps"] = steps
        seen.add(task["instruction"])
        task["metadata"]["attempt"] = attempt
        return task
    raise RuntimeError(f"could not make a solvable task for {subset}/{family}/{k}")


def _write(out_path: Path, tasks: list[dict[str, Any]], level: int, seed: int, verify: bool) -> None:
    """Write a test-split file: the core envelope for the harder levels, the classic file's own (format 2)."""
    out_path.parent.mkdir(parents=True, exist_ok=True)
    if level:
        from eb_manipulation.tasks import FORMAT

        name = {v: k for k, v in LEVELS.items()}.get(level, str(level))
        FORMAT.write(out_path, tasks, generator={"name": "eb_manipulation.generate:generate", "seed": seed,
                                                 "difficulty": name, "verified": bool(verify), "count": len(tasks)})
        return
    doc = {"format": TASK_FORMAT, "version": TASKS_VERSION, "generator": "eb_manipulation.generate:generate",
           "seed": seed, "verified": bool(verify), "count": len(tasks), "tasks": tasks}
    out_path.write_text(json.dumps(doc, indent=1) + "\n")


def audit_form(out: str, seed: int, per_subset: int, difficulty: str | int = "classic") -> Path:
    """A fresh form for ``eb audit``'s parallel-forms probe: about ``per_subset`` tasks per subset (the same number
    of each family, ``ceil(per_subset / families)``), verified like the shipped file, as one task file at ``out``,
    at a ``difficulty`` (``eb audit taskset=hard`` asks for ``hard``). Each task's scene follows from (seed, subset,
    family, index) alone, so these are the first tasks per family of a full file drawn with ``seed``."""
    import tempfile

    tasks: list[dict[str, Any]] = []
    doc: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="eb-manip-form-") as tmp:
        for subset in SUBSETS:
            per_family = max(1, math.ceil(int(per_subset) / len(SUBSET_FAMILIES[subset])))
            part = generate(out=Path(tmp) / f"{subset}.json", seed=seed, per_family=per_family, subsets=[subset],
                            quiet=True, difficulty=difficulty)
            doc = json.loads(Path(str(part)).read_text())
            tasks += doc["tasks"]
    if _level(difficulty):
        doc["tasks"] = tasks
        doc["generator"] = {**doc.get("generator", {}), "count": len(tasks)}
    else:
        doc.update(count=len(tasks), tasks=tasks)
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc, indent=1) + "\n")
    return path
