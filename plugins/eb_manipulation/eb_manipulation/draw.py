"""Drawing one task at a difficulty level and checking it with the expert (shared by the generator and the splits).

``difficulty`` is the generator's knob: ``classic`` (level 0, :mod:`eb_manipulation.families`), ``medium`` (1) and
``hard`` (2, :mod:`eb_manipulation.hard`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from eb_manipulation.families import FAMILY_FN, _Draft
from eb_manipulation.hard import build
from eb_manipulation.spec import SceneSpec

__all__ = ["LEVELS", "MAX_ORACLE_STEPS", "draft_task", "level_of", "scene_metadata", "verify_task"]

MAX_ORACLE_STEPS = 15
LEVELS = {"classic": 0, "medium": 1, "hard": 2}
"""The difficulty knob: ``difficulty=classic|medium|hard`` (or the level number)."""


def level_of(difficulty: str | int) -> int:
    if isinstance(difficulty, int) or str(difficulty).isdigit():
        level = int(difficulty)
        if level in LEVELS.values():
            return level
    elif str(difficulty) in LEVELS:
        return LEVELS[str(difficulty)]
    raise ValueError(f"manipulation: unknown difficulty {difficulty!r}; allowed: classic, medium, hard (or 0, 1, 2). "
                     f"Fix: difficulty=hard")


def draft_task(rng: np.random.Generator, family: str, subset: str, k: int, level: int = 0) -> _Draft:
    """A draft of ``family`` from ``rng``: the classic builders at level 0, :mod:`eb_manipulation.hard` above."""
    if level <= 0:
        return FAMILY_FN[family](rng, subset, k)
    return build(family, rng, subset, k, level)


def scene_metadata(scene: SceneSpec) -> dict[str, Any]:
    """A scene as task-file JSON; an empty ``keep_still`` or ``hole_yaws``, a false ``flush`` and a missing
    ``arrow`` are left out, so classic entries keep their old form."""
    meta = scene.model_dump(mode="json")
    if not meta["goal"]["keep_still"]:
        del meta["goal"]["keep_still"]
    for key in ("flush", "also"):
        if not meta["goal"][key]:
            del meta["goal"][key]
    for obj in meta["objects"]:
        if not obj["hole_yaws"]:
            del obj["hole_yaws"]
        for key in ("arrow", "height"):
            if obj[key] is None:
                del obj[key]
    return meta


def verify_task(task: dict[str, Any], max_steps: int = MAX_ORACLE_STEPS, closed_loop: bool = False) -> tuple[bool, int]:
    """Run the oracle in the simulator: the whole plan, re-planning after a failed action (as the oracle model
    does), or with ``closed_loop`` only the first action of each plan before asking again.

    Returns (solved within ``max_steps`` env steps, steps used).
    """
    from eb_manipulation.oracle import NoPlan, expert_plan, state_of_world
    from eb_manipulation.world import World

    scene = SceneSpec.model_validate(task["metadata"])
    world = World(scene, render_meshes=False)
    steps = 0
    while steps < max_steps:
        try:
            plan = expert_plan(scene, state_of_world(world))
        except NoPlan:
            return False, steps
        if not plan:
            return False, steps
        for action in plan[:1] if closed_loop else plan:
            outcome = world.execute(action)
            steps += 1
            solved, _ = world.evaluate()
            if solved:
                return True, steps
            if not outcome.ok or steps >= max_steps:
                break
    return False, steps
