"""Difficulty figures of the classic and the hard task set, side by side (docs/hard_tasks/manipulation.md).

    python plugins/eb_manipulation/scripts/difficulty.py [--every N] [--noise] [--out table.md]

Per set and subset (every N-th task, default all):

* target px: the target's box area in the first 500 x 500 front image (pixels);
* same-type / look-alikes: loose objects of the target's kind and shape besides it / those of them in a shade of
  the target's confusable group or with its colour on another shape (for wiping: areas, and areas of a near shade);
* plan: the expert's env steps (the task file's ``oracle_steps``);
* rule agent: share solved by the text-only rule agent (:mod:`eb_manipulation.audit`; under ``ablation=text_state``
  this world's text is the same coordinate list a blind model gets), 3 seeded episodes per task;
* guesser / guesser+retry: a blind player with perfect motor skills that knows every object's role from its height
  and guesses the instruction's objects at random (the expert executes the guess), once / trying the next guess after
  each failed one until the 15 steps run out (what a blind frontier model did on the classic set);
* noise p50: the noisy expert (re-asked after every action, each action replaced with probability p by a uniformly
  random 7-D action): the p at which success falls to half, by linear interpolation over p = 0, 0.2, ... 1.
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import zlib
from collections import defaultdict

import numpy as np

os.environ.setdefault("MUJOCO_GL", "egl")

from eb_manipulation.audit import run_blind_agent  # noqa: E402
from eb_manipulation.env import ManipulationEnv  # noqa: E402
from eb_manipulation.oracle import NoPlan, expert_plan, state_of_world  # noqa: E402
from eb_manipulation.shapes import colours_confusable  # noqa: E402
from eb_manipulation.spec import DIRECTIONS, SceneSpec  # noqa: E402
from eb_manipulation.tasks import load_task_file, scene_of  # noqa: E402
from eb_manipulation.templates import DIRECTION_COMMON, DIRECTION_TEXT  # noqa: E402

MAX_STEPS = 15
NOISE = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)


def _main_target(scene: SceneSpec) -> str:
    g = scene.goal
    return g.area_id if g.family == "wipe" else (g.order[-1] if g.family == "stack" else g.target_id)


def counts(scene: SceneSpec) -> tuple[int, int]:
    t = scene.get(_main_target(scene))
    peers = [o for o in scene.objects if o.id != t.id and o.kind == t.kind and (o.shape == t.shape or t.kind == "area")]
    alike = [o for o in scene.objects if o.id != t.id and o.kind == t.kind and o.colour and t.colour
             and ((o.shape == t.shape and colours_confusable(o.colour, t.colour)) or
                  (o.colour == t.colour and o.shape != t.shape))]
    return len(peers), len(alike)


def _guesses(scene: SceneSpec, rng: random.Random, instruction: str = "") -> list[SceneSpec]:
    """Goals a blind player could guess (roles known from heights), in a random order. A hard sorter's hole turns
    cannot be read from text: each guess also guesses the turns. A hard wipe whose direction is the arrow
    printed on the area: each guess is an area and one of the four directions."""
    g = scene.goal
    shapes = [o.id for o in scene.objects if o.kind == "shape"]
    out = []
    if g.family == "pick":
        conts = [o.id for o in scene.objects if o.kind == "container"]
        pairs = [(s, c) for s in shapes for c in conts]
        rng.shuffle(pairs)
        out = [g.model_copy(update={"target": s, "container": c, "keep_still": ()}) for s, c in pairs]
    elif g.family == "sorter" and g.also:  # hard: two shapes, in order
        pairs = [(s, t) for s in shapes for t in shapes if s != t]
        rng.shuffle(pairs)
        out = [g.model_copy(update={"target": s, "also": (t,), "keep_still": ()}) for s, t in pairs]
    elif g.family == "sorter":
        cands = list(shapes)
        rng.shuffle(cands)
        out = [g.model_copy(update={"target": s, "keep_still": ()}) for s in cands]
    elif g.family == "stack":
        for _ in range(20):
            out.append(g.model_copy(update={"order": tuple(rng.sample(shapes, len(g.order))), "keep_still": ()}))
    else:
        areas = [o for o in scene.objects if o.kind == "area"]
        named = any(t in instruction for t in (*DIRECTION_TEXT.values(), *DIRECTION_COMMON.values()))
        if named or not instruction:
            pairs = [(a.id, g.direction) for a in areas]
        else:  # hard: the direction is the area's arrow, which only the image shows
            pairs = [(a.id, d) for a in areas for d in DIRECTIONS]
        rng.shuffle(pairs)
        out = [g.model_copy(update={"area": a, "direction": d, "keep_still": ()}) for a, d in pairs]
    objects = scene.objects
    if any(o.hole_yaws for o in objects):
        def turned(o):
            if not o.hole_yaws:
                return o
            return o.model_copy(update={"hole_yaws": tuple(rng.uniform(-180, 180) for _ in o.holes)})
        return [scene.model_copy(update={"goal": goal, "objects": tuple(turned(o) for o in objects)}) for goal in out]
    return [scene.model_copy(update={"goal": goal}) for goal in out]


def guesser(env: ManipulationEnv, task, retry: bool, seed: int) -> bool:
    env.reset(task, 0)
    world = env._world
    rng = random.Random(zlib.crc32(f"{task.id}/{seed}".encode()))
    steps = 0
    for fake in _guesses(scene_of(task), rng, task.instruction):
        for _ in range(MAX_STEPS):
            if steps >= MAX_STEPS:
                return False
            try:
                plan = expert_plan(fake, state_of_world(world))
            except NoPlan:
                break
            except ValueError:  # a shape that fits no hole: a blind player finds out only by moving it
                if scene_of(task).goal.keep_still:
                    return False
                break
            if not plan:
                break
            r = env.step(plan[0])
            steps += 1
            if r.done:
                return r.task_success
        if not retry:
            return False
    return False


def noisy(env: ManipulationEnv, task, p: float, seed: int) -> bool:
    env.reset(task, 0)
    rng = np.random.default_rng(zlib.crc32(f"{task.id}/{p}/{seed}".encode()))
    for _ in range(MAX_STEPS):
        plan = env.expert_plan()
        if rng.random() < p or not plan:
            action = [int(rng.integers(0, 101)), int(rng.integers(0, 101)), int(rng.integers(0, 101)),
                      int(rng.integers(0, 121)), int(rng.integers(0, 121)), int(rng.integers(0, 121)),
                      int(rng.integers(0, 2))]
        else:
            action = list(plan[0])
        r = env.step(action)
        if r.done:
            return r.task_success
    return False


def p50(curve: list[float]) -> float:
    top = curve[0]
    for (p0, s0), (p1, s1) in zip(zip(NOISE, curve), zip(NOISE[1:], curve[1:])):
        if s1 <= top / 2 <= s0:
            return p0 + (p1 - p0) * ((s0 - top / 2) / (s0 - s1) if s0 != s1 else 0.0)
    return 1.0


def measure(taskset: str, every: int, noise: bool) -> dict[str, dict[str, float]]:
    tasks = load_task_file(taskset=taskset)[::every]
    sim = ManipulationEnv(render=False)
    cam = ManipulationEnv(render=True)
    rows: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    for i, task in enumerate(tasks):
        scene = scene_of(task)
        row = rows[task.subset]
        obs = cam.reset(task, 0)
        target = _main_target(scene)
        label = cam._label(target) if target in cam._order else None
        box = next((o.box for o in obs.objects if o.name == label and o.box), None)
        row["target px"].append(float((box[2] - box[0]) * (box[3] - box[1])) if box else 0.0)
        peers, alike = counts(scene)
        row["same-type"].append(peers)
        row["look-alikes"].append(alike)
        row["plan"].append(float(task.metadata.get("oracle_steps") or 0))
        row["rule agent"].append(np.mean([run_blind_agent(sim, task, r) for r in range(3)]))
        row["guesser"].append(np.mean([guesser(sim, task, False, r) for r in range(3)]))
        row["guesser+retry"].append(np.mean([guesser(sim, task, True, r) for r in range(3)]))
        if noise:
            for p in NOISE:
                row[f"noise {p}"].append(float(noisy(sim, task, p, 0)))
        print(f"{taskset} {i + 1}/{len(tasks)} {task.id}", file=sys.stderr, flush=True)
    sim.close()
    cam.close()
    out: dict[str, dict[str, float]] = {}
    for subset, row in rows.items():
        out[subset] = {k: float(np.mean(v)) for k, v in row.items()}
        if noise:
            out[subset]["noise p50"] = p50([out[subset][f"noise {p}"] for p in NOISE])
    return out


def table(results: dict[str, dict[str, dict[str, float]]]) -> str:
    cols = ["target px", "same-type", "look-alikes", "plan", "rule agent", "guesser", "guesser+retry", "noise p50"]
    lines = ["| set | subset | " + " | ".join(cols) + " |", "|---|---|" + "---|" * len(cols)]
    for name, res in results.items():
        for subset, r in res.items():
            cells = []
            for c in cols:
                if c not in r:
                    cells.append("–")
                elif c in ("rule agent", "guesser", "guesser+retry"):
                    cells.append(f"{100 * r[c]:.1f} %")
                elif c == "target px":
                    cells.append(f"{r[c]:.0f}")
                else:
                    cells.append(f"{r[c]:.2f}")
            lines.append(f"| {name} | {subset} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--every", type=int, default=1, help="measure every N-th task")
    ap.add_argument("--noise", action="store_true", help="also the noise curve (6 episodes more per task)")
    ap.add_argument("--sets", default="classic,hard")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    results = {s: measure(s, a.every, a.noise) for s in a.sets.split(",")}
    text = table(results)
    print(text)
    if a.out:
        with open(a.out, "w") as fh:
            fh.write(text + "\n")


if __name__ == "__main__":
    main()
