"""Difficulty figures of EB-Habitat's task sets, classic against hard (docs/hard_tasks/habitat.md).

    MUJOCO_GL=egl python plugins/eb_habitat/scripts/difficulty.py [--sets classic hard] [--render-per-subset N]
        [--noise-per-subset N] [--seeds N] [--no-render]

Per set and subset:
* target area: the share of the first image (the start, in the middle of the apartment) that the goal's object
  covers, and of the view after ``navigate to`` its receptacle (and ``open`` if it is closed); pixel counts of the
  segmentation at 500 x 500, median over a sample (for a goal that accepts any instance of a type, the largest);
* same-type: instances of the object's type in the apartment (mean), and look-alikes -- instances of its type the
  goal does not accept, and objects of a related type in its colour (a red cup for the red mug,
  ``hard.CONFUSERS``) -- visible in the view at the object's receptacle (mean, same sample);
* plan: the expert's optimal plan length (mean of ``oracle_steps``); search: ``search_steps`` (a seeing agent
  with memory) and ``stateless_search_steps`` (one without, as the benchmark's planner), mean and longest;
* text rule / blind guess / blind sweep / random: success of the players of :mod:`eb_habitat.blind` (random: a
  uniformly random skill each step), with the benchmark's 30 steps and 10 failures, ``--seeds`` episodes a task;
* noise p50: the noise level at which the closed-loop expert, each action replaced by a random skill with that
  probability, falls to half success (``eb_core.stats.p50`` on 0, 0.1, ..., 0.9; ``--noise-per-subset`` tasks).
"""

from __future__ import annotations

import argparse
import random
import statistics
import sys
from collections import defaultdict
from typing import Any

from eb_habitat.blind import MAX_FAILURES, MAX_STEPS, blind_guess, blind_sweep, text_rule_agent
from eb_habitat.env import HabitatEnv
from eb_habitat.hard import CONFUSERS, search_steps, stateless_search_steps
from eb_habitat.skills import SKILLS, skill_id
from eb_habitat.tasks import SUBSETS, spec_of

from eb_core.env import Task
from eb_core.stats import p50

NOISE = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)


def _targets(task: Task) -> tuple[list[str], str]:
    """The instances the goal accepts for its first move, and their type."""
    spec = spec_of(task)
    first = next(p for p in spec.goal_predicates() if p.name in ("on", "inside"))
    kinds = spec.instances()
    arg = first.args[0]
    kind = kinds.get(arg, arg.lstrip("?"))
    return ([arg] if arg in kinds else [n for n, k in kinds.items() if k == kind]), kind


def _pixels(env: HabitatEnv) -> dict[str, int]:
    """Segmentation pixel count of every object in the current first-person view."""
    import numpy as np
    from eb_habitat.render import AGENT

    r = env._renderer._renderer  # the scene kit's renderer behind the apartment
    seg = r.segmentation(AGENT)
    counts = np.bincount(seg.ravel(), minlength=len(r.instance_names))
    return {r.instance_names[i]: int(c) for i, c in enumerate(counts) if i and c}


def _views(tasks: list[Task]) -> dict[str, tuple[float, float, int, int]]:
    """task id -> (target area at the start, target area at its receptacle, same-type instances, look-alikes in
    view at its receptacle)."""
    env = HabitatEnv(render=True)
    total = env.resolution ** 2
    out = {}
    try:
        for task in tasks:
            targets, kind = _targets(task)
            spec = spec_of(task)
            env.reset(task, 0)
            first = _pixels(env)
            src = next(o.at for o in spec.objects if o.name == targets[0])
            env.step(skill_id("navigate", src))
            if not spec.world().is_open(src):
                env.step(skill_id("open", src))
            there = _pixels(env)
            same = [o.name for o in spec.objects if o.type == kind]
            colors = {o.color for o in spec.objects if o.name in targets}
            related = [o.name for o in spec.objects if o.type in CONFUSERS.get(kind, ()) and o.color in colors]
            others = [n for n in same + related if n not in targets and there.get(n, 0) > 0]
            out[task.id] = (max(first.get(n, 0) for n in targets) / total,
                            max(there.get(n, 0) for n in targets) / total, len(same), len(others))
    finally:
        env.close()
    return out


def search_then_plan(task: Task) -> int:
    """:func:`eb_habitat.hard.search_steps` of a task (a seeing agent that looks before it acts)."""
    m = task.metadata
    return search_steps(m["objects"], m["open"], m["goal"], task.instruction, m["template"], wide=bool(m.get("wide")))


def stateless(task: Task) -> int | None:
    """:func:`eb_habitat.search.stateless_search_steps` of a task (a seeing agent without memory); None when no
    such agent solves it, or the goal takes any instance of a type (the classic set)."""
    m = task.metadata
    return stateless_search_steps(m["objects"], m["open"], m["goal"], task.instruction, m["template"],
                                  wide=bool(m.get("wide")))


def _random_episode(task: Task, seed: int) -> bool:
    env = HabitatEnv(render=False)
    env.reset(task, seed)
    rng = random.Random(f"habitat-random/{task.id}/{seed}")
    fails = 0
    for _ in range(MAX_STEPS):
        r = env.step(rng.randrange(len(SKILLS)))
        fails += not r.action_success
        if r.done or fails >= MAX_FAILURES:
            break
    return r.task_success


def _noisy_episode(env: HabitatEnv, task: Task, noise: float) -> bool:
    coin, draws = random.Random(f"habitat-noise/{task.id}"), random.Random(f"habitat-noise-action/{task.id}")
    env.reset(task, 0)
    fails = 0
    for _ in range(MAX_STEPS):
        u, rand = coin.random(), draws.randrange(len(SKILLS))
        plan = env.expert_plan()
        if u >= noise and not plan:
            return False
        r = env.step(rand if u < noise else plan[0])
        fails += not r.action_success
        if r.done or fails >= MAX_FAILURES:
            break
    return r.task_success


def figures(tasks: list[Task], render_n: int, noise_n: int, seeds: int) -> dict[str, dict[str, Any]]:
    by: dict[str, list[Task]] = defaultdict(list)
    for t in tasks:
        by[t.subset].append(t)
    views = {} if render_n <= 0 else _views([t for s in SUBSETS for t in by[s][:: max(1, 50 // render_n)][:render_n]])
    env = HabitatEnv(render=False)
    out: dict[str, dict[str, Any]] = {}
    for s in SUBSETS:
        ts = by[s]
        v = [views[t.id] for t in ts if t.id in views]
        curve = []
        for p in NOISE:
            sample = ts[:noise_n]
            curve.append((p, sum(_noisy_episode(env, t, p) for t in sample) / len(sample)))
        out[s] = {
            "tasks": len(ts),
            "area_start": statistics.median(x[0] for x in v) * 100 if v else None,
            "area_there": statistics.median(x[1] for x in v) * 100 if v else None,
            "same_type": statistics.mean(len(_same(t)) for t in ts),
            "lookalikes_in_view": statistics.mean(x[3] for x in v) if v else None,
            "plan": statistics.mean(t.metadata["oracle_steps"] for t in ts),
            "search": statistics.mean(map(search_then_plan, ts)),
            "search_max": max(map(search_then_plan, ts)),
            "stateless": statistics.mean(sl) if (sl := [x for x in map(stateless, ts) if x is not None]) else None,
            "stateless_max": max(sl) if sl else None,
            "text_rule": sum(map(text_rule_agent, ts)) / len(ts) * 100,
            "blind_guess": sum(blind_guess(t, k) for t in ts for k in range(seeds)) / (len(ts) * seeds) * 100,
            "blind_sweep": sum(blind_sweep(t, k) for t in ts for k in range(seeds)) / (len(ts) * seeds) * 100,
            "random": sum(_random_episode(t, k) for t in ts for k in range(seeds)) / (len(ts) * seeds) * 100,
            "noise_p50": p50(curve),
        }
        print(f"habitat difficulty: {s} done", file=sys.stderr, flush=True)
    return out


def _same(task: Task) -> list[str]:
    _, kind = _targets(task)
    return [o.name for o in spec_of(task).objects if o.type == kind]


ROWS = (
    ("tasks", "tasks", "{:.0f}"),
    ("area_start", "target area in the first image (median % of pixels)", "{:.3f}"),
    ("area_there", "target area at its receptacle (median %)", "{:.2f}"),
    ("same_type", "same-type instances in the apartment (mean)", "{:.1f}"),
    ("lookalikes_in_view", "look-alikes in view at the target's receptacle (mean)", "{:.1f}"),
    ("plan", "optimal plan (mean steps)", "{:.1f}"),
    ("search", "search in catalogue order, then plan (mean steps)", "{:.1f}"),
    ("search_max", "the same, longest task (budget 30)", "{:.0f}"),
    ("stateless", "search without memory, acting on each view (mean steps)", "{:.1f}"),
    ("stateless_max", "the same, longest task (budget 30)", "{:.0f}"),
    ("text_rule", "text-only rule agent (ablation=text_state)", "{:.0f} %"),
    ("blind_guess", "blind guess", "{:.1f} %"),
    ("blind_sweep", "blind sweep (reads the pick feedback)", "{:.1f} %"),
    ("random", "random", "{:.1f} %"),
    ("noise_p50", "noise p50", "{:.2f}"),
)


def table(results: dict[str, dict[str, dict[str, Any]]]) -> str:
    sets = list(results)
    head = "| figure (" + " / ".join(sets) + ") | " + " | ".join(SUBSETS) + " |"
    lines = [head, "|---" * (len(SUBSETS) + 1) + "|"]
    for key, label, fmt in ROWS:
        cells = []
        for s in SUBSETS:
            vals = [results[name][s][key] for name in sets]
            cells.append(" / ".join("-" if v is None else fmt.format(v) for v in vals))
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sets", nargs="+", default=["classic", "hard"])
    ap.add_argument("--render-per-subset", type=int, default=10)
    ap.add_argument("--noise-per-subset", type=int, default=20)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--no-render", action="store_true")
    args = ap.parse_args(argv)
    results = {}
    for name in args.sets:
        tasks = HabitatEnv.load_tasks(taskset=name)
        print(f"habitat difficulty: {name} ({len(tasks)} tasks)", file=sys.stderr, flush=True)
        results[name] = figures(tasks, 0 if args.no_render else args.render_per_subset, args.noise_per_subset,
                                args.seeds)
    print(table(results))


if __name__ == "__main__":
    main()
