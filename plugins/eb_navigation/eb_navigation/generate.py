"""The task generator: ``eb tasks generate env=navigation seed=0 scenes=60 out=...``.

For each scene slot (kinds in turn: kitchen, living room, bedroom, bathroom; the next kind after
:data:`KIND_ATTEMPTS` rooms without success) it draws room seeds for the scene kit's
:func:`~eb_scenekit.rooms.generate_room` until one gives good tasks, then writes one task per subset:

* base, common_sense, complex_instruction: one start ``min_distance``..``max_distance`` metres from a target
  whose type occurs once in the room, the target within 40 degrees of straight ahead and clearly visible
  (checked by rendering a segmentation image); the three subsets differ only in the instruction;
* long_horizon: another start in the same room with the target behind the agent (out of view) and an oracle
  plan at least :data:`LONG_HORIZON_EXTRA` actions longer than base's;
* visual_appearance: the room plus one or two objects of the target's type in clearly different colours against
  the walls, its own start with the target and a look-alike in view, the target named only by colour and shape.

Blind-policy rejection (issue 12): a start is taken only if no blind baseline would profit from it. For every
candidate start the generator runs, on the geometry alone (:mod:`eb_navigation.baselines`), all 10,948 blind
constant-action policies (always forward; turn once or twice, then a fixed cycle of up to 4 actions) and the
feedback-only rule agents, and keeps per subset how many tasks each of them solves; a start that would lift any
blind policy above ``blind_cap`` tasks (default 4 % of the scenes) or any rule agent above ``rule_cap`` (10 %)
is refused. Among the admissible starts the one with the shortest oracle plan and the fewest blind successes
wins. Tasks are written room by room, so a run in file order compiles each room once.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from eb_scenekit.objects import get_type

from eb_navigation.baselines import BLIND_POLICIES, RULE_AGENTS, blind_successes, plan_lengths, rule_agent_successes
from eb_navigation.geometry import STEP, AgentState, FreeSpace, bearing_to
from eb_navigation.instructions import COMMON_SENSE_TYPES, SHAPES, instruction_for
from eb_navigation.room import KINDS, ExtraSpec, NavObject, NavRoom, colour_distance, probe
from eb_navigation.tasks import FORMAT, SUBSETS, TASK_FILE_FORMAT, TASK_FILE_VERSION
from eb_navigation.visibility import Visibility

__all__ = ["GENERATOR_VERSION", "TARGETS_BY_KIND", "audit_form", "generate"]

from eb_navigation.placement import (  # noqa: F401  (re-exported: the generator's rules and pieces)
    GENERATOR_VERSION,
    TARGETS_BY_KIND,
    MIN_VISIBLE_PIXELS,
    MIN_DISTRACTOR_PIXELS,
    MAX_START_BEARING,
    MIN_BEHIND_BEARING,
    LONG_HORIZON_EXTRA,
    LONG_HORIZON_MAX_DISTANCE,
    MIN_COLOUR_DISTANCE,
    MIN_DISTRACTOR_DISTANCE,
    KIND_ATTEMPTS,
    _VIS_TRIES,
    _wall_pose,
    _twin_colours,
    _place_lookalikes,
    _pose_dict,
    _target_dict,
    _extra_dict,
)


@dataclass
class _Tally:
    """How many tasks of one subset each blind policy and each rule agent solves so far."""

    blind: np.ndarray
    rules: np.ndarray

    @classmethod
    def empty(cls) -> "_Tally":
        return cls(np.zeros(len(BLIND_POLICIES), dtype=np.int32), np.zeros(len(RULE_AGENTS), dtype=np.int32))

    def add(self, cand: "_Candidate") -> None:
        self.blind += cand.blind
        self.rules += cand.rules


@dataclass
class _Candidate:
    state: AgentState
    plan: int
    blind: np.ndarray
    rules: np.ndarray

    def admissible(self, tally: _Tally, blind_cap: int, rule_cap: int) -> bool:
        if self.blind.any() and int(tally.blind[self.blind].max()) + 1 > blind_cap:
            return False
        return not (self.rules.any() and int(tally.rules[self.rules].max()) + 1 > rule_cap)

    def score(self, tally: _Tally) -> float:
        crowd = int(tally.blind[self.blind].max()) + 1 if self.blind.any() else 0
        return self.plan + 3.0 * int(self.rules.sum()) + 3.0 * crowd + float(self.blind.sum()) / 100.0


def _candidates(free: FreeSpace, target: NavObject, lo: float, hi: float, min_plan: int, max_plan: int,
                behind: bool, tally: _Tally, blind_cap: int, rule_cap: int) -> list[_Candidate]:
    """Admissible starts (``behind``: target behind the agent), best first."""
    xy = (target.x, target.y)
    lengths = plan_lengths(free, xy)
    out = []
    for (i, j, h), n in lengths.items():
        if not min_plan <= n <= max_plan:
            continue
        if not lo - 1e-9 <= math.hypot(i * STEP - target.x, j * STEP - target.y) <= hi + 1e-9:
            continue
        s = AgentState(i, j, h)
        b = abs(bearing_to(s, xy))
        if (b < MIN_BEHIND_BEARING) if behind else (b > MAX_START_BEARING):
            continue
        blind = blind_successes(free, s, xy)
        if blind.any() and int(tally.blind[blind].max()) + 1 > blind_cap:
            continue
        rules = np.array(list(rule_agent_successes(free, s, xy).values()), dtype=bool)
        cand = _Candidate(s, n, blind, rules)
        if cand.admissible(tally, blind_cap, rule_cap):
            out.append(cand)
    out.sort(key=lambda c: (c.score(tally), c.state.i, c.state.j, c.state.heading))
    return out


def _pick_visible(room: NavRoom, target: NavObject, cands: Sequence[_Candidate], vis: Visibility,
                  distractors: Sequence[str] = ()) -> _Candidate | None:
    for cand in cands[:_VIS_TRIES]:
        if vis.pixels(room, cand.state, target.id) < MIN_VISIBLE_PIXELS:
            continue
        if distractors and max(vis.pixels(room, cand.state, d) for d in distractors) < MIN_DISTRACTOR_PIXELS:
            continue
        return cand
    return None


def _pick_hidden(room: NavRoom, target: NavObject, cands: Sequence[_Candidate], vis: Visibility
                 ) -> _Candidate | None:
    for cand in cands[:_VIS_TRIES]:
        if vis.pixels(room, cand.state, target.id) == 0:
            return cand
    return None


def _visual_task(room: NavRoom, base_target: NavObject, lo: float, hi: float, max_steps: int, vis: Visibility,
                 rng: np.random.Generator, tally: _Tally, blind_cap: int, rule_cap: int
                 ) -> tuple[NavObject, _Candidate, list[ExtraSpec]] | None:
    """The visual task of a room: the base target if it can have look-alikes, else another object of the room."""
    counts = room.counts()
    others = [o for o in room.objects if o.id != base_target.id and o.type in SHAPES and counts[o.type] == 1
              and o.on_floor and _twin_colours(o)]
    rng.shuffle(others)
    for target in [base_target, *others[:3]]:
        extras = _place_lookalikes(room, target, rng)
        if extras is None:
            continue
        vroom = NavRoom(room.kind, room.seed, extras)
        free = vroom.free_space(vroom.extra_ids)
        cands = _candidates(free, target, lo, hi, 1, max_steps, False, tally, blind_cap, rule_cap)
        cand = _pick_visible(vroom, target, cands, vis, [e.id for e in extras])
        if cand is not None:
            return target, cand, extras
    return None


def generate(seed: int = 0, scenes: int = 60, min_distance: float = 2.5, max_distance: float = 3.5,
             out: str | None = None, max_oracle_steps: int = 15, blind_cap: int | None = None,
             rule_cap: int | None = None, progress: bool = False, split: str = "test", n: int | None = None,
             start: int = 0, slots: Sequence[int] | None = None, difficulty: str = "classic") -> str:
    """Write a navigation task file with ``5 * scenes`` tasks; return a one-line summary.

    ``split=train|val n=N [start=K] out=PATH`` writes tasks ``K .. K+N-1`` of a generated training split instead
    (disjoint from the shipped test tasks; :mod:`eb_navigation.splits`) as one task file, for ``eb run
    env=navigation env.params.task_file=<file>``.

    Args:
        seed: master seed (room seeds, starts and instruction wording all follow from it).
        scenes: number of distinct rooms; each gives one task per subset.
        min_distance / max_distance: horizontal start-to-target distance range of the visible-target subsets.
        out: output path (default ``navigation_tasks.json`` in the working directory).
        max_oracle_steps: longest oracle plan allowed (long_horizon: 2 more).
        blind_cap: most tasks per subset any blind constant-action policy may solve (default: 4 % of ``scenes``,
            at least 2).
        rule_cap: most tasks per subset any feedback-only rule agent may solve (default: 10 % of ``scenes``,
            at least 2).
        progress: print one line per finished room.
        slots: make only these scene slots of ``0 .. scenes-1`` (their kinds and target types as in the full
            file; rooms and starts are drawn afresh), e.g. an even spread for ``eb audit``'s fresh form.
        difficulty: ``classic`` (this generator), ``medium`` or ``hard`` (:mod:`eb_navigation.hard`: small
            targets with look-alikes in cluttered rooms; ``out`` is then a folder of per-subset files, progress
            goes to stderr). With ``split=train|val`` it sets the difficulty of the split's tasks.
    """
    from eb_navigation.hard import DIFFICULTIES

    if difficulty not in DIFFICULTIES:
        raise ValueError(f"unknown difficulty {difficulty!r}; allowed: {', '.join(DIFFICULTIES)}")
    if split != "test":
        from eb_navigation.splits import SPLITS, write_split

        if split not in SPLITS:
            raise ValueError(f"unknown split {split!r}; allowed: test (the shipped tasks), {', '.join(SPLITS)}")
        if n is None or int(n) < 1 or not out:
            raise ValueError(f"split={split} needs n=<tasks, >= 1> and out=<file.json or folder> (the shipped task "
                             f"file holds the test split only)")
        if int(start) < 0:
            raise ValueError(f"start must be >= 0, got {start}")
        paths = write_split(str(out), split, int(n), int(start), difficulty=difficulty)
        level = "" if difficulty == "classic" else f"{difficulty} "
        return f"wrote {int(n)} {level}{split} tasks ({int(start)}..{int(start) + int(n) - 1}) to {paths[0]}"
    if difficulty != "classic":
        from eb_navigation.hard_set import generate_level

        return generate_level(difficulty, seed=int(seed), scenes=int(scenes), out=out, progress=True)
    seed, scenes = int(seed), int(scenes)
    lo, hi = float(min_distance), float(max_distance)
    if scenes < 1:
        raise ValueError(f"scenes must be at least 1, got {scenes}; pass e.g. scenes=60")
    if not 1.0 < lo <= hi:
        raise ValueError(f"need 1.0 < min_distance <= max_distance (metres), got {lo} and {hi}")
    max_oracle_steps = int(max_oracle_steps)
    blind_cap = max(2, int(0.04 * scenes)) if blind_cap is None else int(blind_cap)
    rule_cap = max(2, int(0.10 * scenes)) if rule_cap is None else int(rule_cap)
    path = Path(out) if out else Path("navigation_tasks.json")
    rng = np.random.default_rng([seed, GENERATOR_VERSION])
    vis = Visibility()
    tasks: list[dict[str, Any]] = []
    used: set[tuple[str, int]] = set()
    tally = {s: _Tally.empty() for s in ("plain", "visual_appearance", "long_horizon")}
    wording: dict[str, dict[str, int]] = {s: {} for s in SUBSETS}
    try:
        for slot in (range(scenes) if slots is None else [int(x) for x in slots]):
            kind = KINDS[slot % len(KINDS)]
            wanted = TARGETS_BY_KIND[kind][(slot // len(KINDS)) % len(TARGETS_BY_KIND[kind])]
            made = None
            for attempt in range(4 * KIND_ATTEMPTS):
                if attempt and attempt % KIND_ATTEMPTS == 0:  # this kind of room has run dry: try the next
                    kind = KINDS[(KINDS.index(kind) + 1) % len(KINDS)]
                room_seed = int(rng.integers(0, 100_000))
                if (kind, room_seed) in used:
                    continue
                room = NavRoom(kind, room_seed)
                counts = room.counts()
                names = [wanted] if attempt < 60 else list(TARGETS_BY_KIND[kind])
                options = [o for o in room.objects if o.type in names and counts[o.type] == 1
                           and o.type in COMMON_SENSE_TYPES]
                if not options:
                    continue
                target = options[int(rng.integers(len(options)))]
                free = room.free_space()
                base = _pick_visible(room, target, _candidates(free, target, lo, hi, 1, max_oracle_steps, False,
                                                               tally["plain"], blind_cap, rule_cap), vis)
                if base is None:
                    continue
                lh = _pick_hidden(room, target, _candidates(
                    free, target, lo, hi + LONG_HORIZON_MAX_DISTANCE, base.plan + LONG_HORIZON_EXTRA,
                    max_oracle_steps + 2, True, tally["long_horizon"], blind_cap, rule_cap), vis)
                if lh is None:
                    continue
                visual = _visual_task(room, target, lo, hi, max_oracle_steps, vis, rng, tally["visual_appearance"],
                                      blind_cap, rule_cap)
                if visual is None:
                    continue
                made = (room, target, base, lh, visual)
                break
            if progress:
                print(f"slot {slot}: {kind} seed {room_seed} after {attempt + 1} rooms", flush=True)
            if made is None:
                raise RuntimeError(f"could not make a {kind} task for slot {slot}: no room met the rules; try "
                                   f"another seed, a wider distance range or a larger blind_cap")
            room, target, base, lh, (v_target, v_cand, extras) = made
            used.add((kind, room.seed))
            tally["plain"].add(base)
            tally["long_horizon"].add(lh)
            tally["visual_appearance"].add(v_cand)
            other_types = sorted({o.type for o in room.objects if o.type != target.type and o.on_floor})
            other = other_types[int(rng.integers(len(other_types)))] if other_types else None
            scene = {"kind": kind, "seed": room.seed}
            n = slot

            def task(subset: str, t: NavObject, cand: _Candidate, extra: Sequence[ExtraSpec] = ()) -> dict[str, Any]:
                text, template = instruction_for(subset, t.type, t.colour, rng, other, wording[subset])
                return {"id": f"{subset}_{n:03d}", "subset": subset, "instruction": text, "template": template,
                        "scene": scene, "start": _pose_dict(cand.state), "target": _target_dict(t),
                        "extra_objects": [_extra_dict(e) for e in extra], "oracle_steps": cand.plan}

            tasks.append(task("base", target, base))
            tasks.append(task("common_sense", target, base))
            tasks.append(task("complex_instruction", target, base))
            tasks.append(task("visual_appearance", v_target, v_cand, extras))
            tasks.append(task("long_horizon", target, lh))
    finally:
        vis.close()
    assert [t["subset"] for t in tasks[:5]] == list(SUBSETS)
    from eb_scenekit import __version__ as scenekit_version

    doc = {
        "format": TASK_FILE_FORMAT,
        "version": TASK_FILE_VERSION,
        "generator": {"function": "eb_navigation.generate:generate", "generator_version": GENERATOR_VERSION,
                      "scenekit_version": scenekit_version, "seed": seed, "scenes": scenes, "min_distance": lo,
                      "max_distance": hi, "max_oracle_steps": max_oracle_steps, "blind_cap": blind_cap,
                      "rule_cap": rule_cap, **({"slots": [int(x) for x in slots]} if slots is not None else {})},
        "tasks": tasks,
    }
    FORMAT.parse(doc, path)  # the core's validation before anything is written
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ",\n".join("  " + json.dumps(t, separators=(", ", ": ")) for t in tasks)
    head = json.dumps({k: v for k, v in doc.items() if k != "tasks"}, indent=1)[:-2]
    tmp = path.with_name(path.name + ".tmp")  # one task per line (the classic file's layout), renamed into place
    tmp.write_text(head + ',\n "tasks": [\n' + lines + "\n ]\n}\n", encoding="utf-8")
    tmp.replace(path)
    steps_all = [t["oracle_steps"] for t in tasks]
    return (f"wrote {len(tasks)} tasks ({len(tasks) // len(SUBSETS)} scenes x {len(SUBSETS)} subsets) to {path}; "
            f"oracle steps {min(steps_all)}-{max(steps_all)}, mean {np.mean(steps_all):.1f}")


def audit_form(out: str, seed: int, per_subset: int, difficulty: str = "classic") -> str:
    """A fresh form of ``per_subset`` tasks per subset for ``eb audit``'s parallel-forms probe: the scene slots
    at an even spread of the shipped file's 60 (so kinds and target types are spread as there), with the blind
    and rule-agent caps scaled to the smaller file. Written as one task file at ``out`` (a harder ``difficulty``:
    a folder of per-subset files, ``per_subset`` scenes of that level)."""
    if difficulty != "classic":
        from eb_navigation.hard_set import generate_level

        return generate_level(difficulty, seed=int(seed), scenes=max(1, int(per_subset)), out=out, progress=False)
    full = 60
    k = max(1, min(int(per_subset), full))
    return generate(seed=seed, scenes=full, out=out, slots=[(i * full) // k for i in range(k)],
                    blind_cap=max(1, round(2 * k / full)), rule_cap=max(1, round(6 * k / full)))
