"""A whole harder task set: ``eb tasks generate env=navigation difficulty=hard seed=N`` (:func:`generate_level`).

Scene slot by slot (all draws seeded by ``seed``): a room, its target and look-alikes and its starts
(:func:`eb_navigation.hard.draw_scene`). Every start is checked on the geometry against all 10,948 blind
constant-action policies and the feedback-only agents of :data:`~eb_navigation.baselines.CHECK_AGENTS` (the core
audit's feedback policies among them), and one that would lift any of them above ``cap`` tasks of its subset (5 %
of the scenes: 3 of 60; and one of the 20 slots that ``eb audit --quick`` plays: :data:`AUDIT_SAMPLE`) is never
taken, nor is one with a floor object lower than 0.5 m on its straight way to the
target (:func:`eb_navigation.hard.clear_corridor`), nor an in-view start whose first image leaves out something on
that way (:func:`eb_navigation.hard.way_seen`). Among the rest the generator takes the shortest expert plan,
preferring one that no blind policy or agent solves, and one that shows a look-alike nearer the middle of the view
than the target. A slot whose room gives no such starts draws another
room (after 40 rooms the next target type, after 120 the next room kind, at most :data:`MAX_ROOMS`).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from eb_core.audit.contract import sample_positions
from eb_navigation.baselines import CHECK_AGENTS
from eb_navigation.hard import DIFFICULTIES, HARD_TYPES, LEVELS, SEED_BASE, Tally, draw_scene, scene_tasks
from eb_navigation.room import KINDS
from eb_navigation.tasks import SUBSETS

__all__ = ["AUDIT_SAMPLE", "MAX_RATE", "MAX_ROOMS", "OPEN_WAY_SETS", "audit_sample", "generate_level"]

MAX_RATE = 0.05
"""The most any one blind policy or feedback-only agent may solve of a subset (the issue's rule, 5 %)."""
AUDIT_SAMPLE = 20
"""Tasks per subset that ``eb audit --quick`` plays (``eb_core.audit.setup``: ``quick_per_subset``, a seeded random
sample, the same slots in every subset: :func:`eb_core.audit.contract.sample_positions`).
The same rule holds on them: at most 5 % of them (one) solved by any one policy or agent, so that the solved tasks
(which the first slots take, while the tallies are empty) do not crowd into the audit's sample."""


class _Joint(Tally):
    """The subset's tally and the audit sample's tally at once: a start must pass both caps, and counts in both."""

    def __init__(self, *parts: Tally) -> None:
        super().__init__(min(t.cap for t in parts if t.cap is not None))
        self.parts = parts

    def admits(self, st: Any) -> bool:
        return all(t.admits(st) for t in self.parts)

    def add(self, st: Any) -> None:
        for t in self.parts:
            t.add(st)


def audit_sample(scenes: int, k: int = AUDIT_SAMPLE) -> set[int]:
    """The slots ``eb audit --quick`` plays, at its default seed, of a ``scenes``-task subset (all of them when
    there are no more); the same slots in every subset."""
    return set(sample_positions(scenes, k, seed=0))


_SECTORS = ("left", "behind", "right")
MAX_ROOMS = 2400
"""Rooms a slot may draw before the generator gives up (it was 400; the shipped set never needed that many). With
the open-way rule on (``open_way=True``) the in-view starts whose first moves meet nothing low are those a
feedback agent ("forward, step left on a bump") solves most often, so a slot may need several hundred rooms
before one fits under the 5 % caps (up to 678 in a trial)."""


OPEN_WAY_SETS = ("hard",)
"""Levels whose task sets (the shipped files, ``eb tasks generate ... difficulty=hard seed=N`` and the audit's fresh
form) are drawn with the open-way rule on (:attr:`eb_navigation.hard.Level.open_way`; session 10): the first moves
of every start meet nothing the images have not shown, and few feedback-only agents solve a start. The train and
val splits draw the level as it is (no rendered checks, no caps)."""


def generate_level(level: str = "hard", seed: int = 0, scenes: int = 60, out: str | None = None,
                   cap: int | None = None, progress: bool = True, open_way: bool | None = None) -> str:
    """Write a ``level`` task set: ``<out>/<subset>.json`` for the five subsets, ``scenes`` tasks each. ``open_way``:
    the open-way rule on or off (:attr:`eb_navigation.hard.Level.open_way`); None = on for :data:`OPEN_WAY_SETS`."""
    from eb_navigation.tasks import write_subset_files
    from eb_navigation.visibility import Visibility

    if level not in LEVELS:
        raise ValueError(f"unknown difficulty {level!r}; allowed: {', '.join(DIFFICULTIES)}")
    if open_way is None:
        open_way = level in OPEN_WAY_SETS
    lv = replace(LEVELS[level], open_way=bool(open_way))
    scenes = int(scenes)
    if scenes < 1:
        raise ValueError(f"scenes must be at least 1, got {scenes}")
    cap = max(1, int(MAX_RATE * scenes + 1e-9)) if cap is None else int(cap)
    rng = np.random.default_rng([int(seed), 0x4A4D, DIFFICULTIES.index(level)])
    tallies = {p: Tally(cap) for p in ("plain", "visual_appearance", "long_horizon")}
    sample_cap = max(1, int(MAX_RATE * min(scenes, AUDIT_SAMPLE) + 1e-9))
    sampled = {p: Tally(sample_cap) for p in tallies}
    in_sample = audit_sample(scenes)
    wording: dict[str, dict[str, int]] = {}
    tasks: list[dict[str, Any]] = []
    vis = Visibility()
    try:
        for slot in range(scenes):
            kind = KINDS[slot % 3]  # kitchens, living rooms, bedrooms (bathrooms are too small for the clutter)
            type_name = HARD_TYPES[(slot // 3) % len(HARD_TYPES)]
            sector = _SECTORS[slot % len(_SECTORS)]
            use = {p: _Joint(t, sampled[p]) if slot in in_sample else t for p, t in tallies.items()}
            sc = None
            for attempt in range(MAX_ROOMS):
                if attempt and attempt % 40 == 0:  # this type runs dry here: the next one
                    type_name = HARD_TYPES[(HARD_TYPES.index(type_name) + 1) % len(HARD_TYPES)]
                if attempt and attempt % 120 == 0:
                    kind = KINDS[(KINDS.index(kind) + 1) % 3]
                room_seed = SEED_BASE + int(rng.integers(0, 100_000))
                sc = draw_scene(kind, room_seed, type_name, lv, rng, use, vis, sector, agents=CHECK_AGENTS)
                if sc is not None:
                    break
            if sc is None:
                raise RuntimeError(f"could not make a {level} {kind} scene for slot {slot}; try another seed")
            for part, st in sc.starts.items():
                use[part].add(st)
            tasks.extend(scene_tasks(sc, slot, rng, wording))
            if progress:
                print(f"{level} slot {slot + 1}/{scenes}: {kind} seed {sc.room.seed}, {sc.target.colour} "
                      f"{sc.target.type} after {attempt + 1} room(s); plans "
                      f"{', '.join(f'{p} {st.plan}' for p, st in sc.starts.items())}", file=sys.stderr, flush=True)
    finally:
        vis.close()
    gen = {"function": "eb_navigation.generate:generate", "difficulty": level, "seed": int(seed),
           "scenes": scenes, "cap": cap}
    paths = write_subset_files(Path(out or f"navigation_{level}"), tasks, gen)
    steps = [t["oracle_steps"] for t in tasks]
    return (f"wrote {len(tasks)} {level} tasks ({scenes} scenes x {len(SUBSETS)} subsets) to "
            f"{', '.join(str(p) for p in paths[:1])} ...; oracle steps {min(steps)}-{max(steps)}, "
            f"mean {np.mean(steps):.1f}")
