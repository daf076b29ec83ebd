"""Difficulty figures of EB-Navigation's task sets, classic against hard (a Markdown table on stdout).

    python plugins/eb_navigation/scripts/difficulty.py            # both shipped sets, every task
    python plugins/eb_navigation/scripts/difficulty.py --per-subset 12   # a quicker sample
    python plugins/eb_navigation/scripts/difficulty.py --slack [--task-dir DIR]  # budget and blind play, geometry

Per set and subset:

* target pixels: the target's share of the first image (a 128 x 128 segmentation of the start view; the
  500 x 500 equivalent in brackets), median over the tasks whose subset promises the target in view;
* same type in view: other objects of the target's type visible in the first image (mean), and the share of tasks
  with at least one;
* objects in view: every object with at least 5 pixels in the first image (mean), a clutter measure;
* plan: the oracle's optimal plan length (mean);
* text-only rule agent: an agent given ``ablation=text_state``'s scene text (what is in view, how far, which way)
  and the instruction: it looks for an in-view object named by the instruction's words (type name, with the
  colour when the instruction gives one), steps toward it (forward when it is ahead, sideways when it is to a
  side, forward again after a side step), turns left when nothing matches; share of tasks solved in 20 steps.
  The scene text is the env's own (rendered at 64 x 64: the in-view test does not depend on the resolution);
* noise p50: the closed-loop expert with each action replaced by a random one with probability p; the p at
  which success falls to half of its p = 0 value (linear interpolation over p = 0, 0.1, ..., 0.9).
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
from collections import defaultdict

import numpy as np
from eb_navigation.env import NavigationEnv, build_room
from eb_navigation.geometry import AgentState
from eb_navigation.hard_words import HARD_ALT_NAMES
from eb_navigation.instructions import colour_word, display_name
from eb_navigation.tasks import SUBSETS, load_taskset, spec_of
from eb_navigation.visibility import VIS_SIZE
from eb_scenekit.objects import CATALOGUE

MAX_STEPS = 20
NOISE = tuple(round(0.1 * k, 1) for k in range(10))


def _sample(taskset: str, per_subset: int | None):
    tasks = NavigationEnv.load_tasks(taskset=taskset)
    if per_subset is None:
        return tasks
    by = defaultdict(list)
    for t in tasks:
        by[t.subset].append(t)
    return [t for s in SUBSETS for t in by[s][:: max(1, len(by[s]) // per_subset)][:per_subset]]


def _views(tasks) -> dict[str, dict[str, float]]:
    """Target pixels, same-type objects and all objects in the first view (segmentation)."""
    from eb_navigation.scene import RoomScene

    out: dict[str, dict[str, float]] = {}
    scene, key = None, None
    try:
        for task in tasks:
            spec = spec_of(task)
            k = (spec.scene.kind, spec.scene.seed, spec.scene.clutter, spec.extra_objects)
            if k != key:
                if scene is not None:
                    scene.close()
                room = build_room(spec)
                scene, key = RoomScene(room, VIS_SIZE, VIS_SIZE), k
            scene.show_extras(frozenset(e.id for e in spec.extra_objects))
            scene.set_agent(AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw))
            seg = scene.object_map()
            ids, counts = np.unique(seg[seg >= 0], return_counts=True)
            seen = {room.objects[int(i)].id: int(c) for i, c in zip(ids, counts) if c >= 5}
            same = [o for o in room.objects if o.type == spec.target.type and o.id != spec.target.id
                    and o.id in seen]
            out[task.id] = {"target": int((seg == room.index[spec.target.id]).sum()), "same": len(same),
                            "objects": len(seen)}
    finally:
        if scene is not None:
            scene.close()
    return out


_ENTRY = re.compile(r"^(an? )?(?P<name>.+?) about [0-9.]+ m away, (?P<where>.+)$")
_TYPE_NAMES = sorted({display_name(t) for t in CATALOGUE}, key=len, reverse=True)
_NAMES = {display_name(t): (display_name(t), alt) for t, alt in HARD_ALT_NAMES.items()}  # "trash can" or "bin"
_COLOUR_WORDS = sorted({colour_word(c) for t in CATALOGUE.values() for c in t.colors}, key=len, reverse=True)


def _split(name: str) -> tuple[str, str]:
    """``"red watering can"`` -> ``("red", "watering can")``."""
    for n in _TYPE_NAMES:
        if name == n or name.endswith(" " + n):
            return name[: -len(n)].strip(), n
    return "", name


def _text_agent(env: NavigationEnv, task) -> bool:
    """The text-only rule agent of the module docstring."""
    words = task.instruction.lower()
    colour_named = any(re.search(rf"\b{re.escape(c.lower())}\b", words) for c in _COLOUR_WORDS)
    obs = env.reset(task, 0)
    last_side, steps = None, 0
    while steps < MAX_STEPS:
        action = 5
        for part in obs.text.split(". ")[0].removeprefix("In view: ").split("; "):
            m = _ENTRY.match(part.strip().rstrip("."))
            if not m:
                continue
            colour, noun = _split(m["name"])
            if not any(re.search(rf"\b{re.escape(n.lower())}\b", words) for n in _NAMES.get(noun, (noun,))):
                continue
            if colour_named and colour.lower() not in words:
                continue
            where = m["where"]
            action = 0 if ("ahead" in where or "slightly" in where) else 3 if "left" in where else 2
            break
        if action in (2, 3) and last_side == action:
            action = 0
        r = env.step(action)
        steps += 1
        last_side = action if action in (2, 3) and r.action_success else None
        if not r.done and not r.action_success and action == 0 and steps < MAX_STEPS:
            r = env.step(3)  # blocked ahead: side-step and try again
            steps += 1
        if r.done:
            return r.task_success
        obs = r.observation
    return False


def _noise_curve(tasks, seed: int = 0) -> dict[float, float]:
    env = NavigationEnv(render=False)
    rng = np.random.default_rng(seed)
    out = {}
    for p in NOISE:
        wins = 0
        for task in tasks:
            env.reset(task, 0)
            for _ in range(MAX_STEPS):
                a = int(rng.integers(8)) if rng.random() < p else (env.expert_plan() or [0])[0]
                r = env.step(a)
                if r.done:
                    wins += int(r.task_success)
                    break
        out[p] = wins / len(tasks)
    env.close()
    return out


def _p50(curve: dict[float, float]) -> float:
    ps = sorted(curve)
    half = curve[ps[0]] / 2
    for a, b in zip(ps, ps[1:]):
        if curve[b] <= half:
            ya, yb = curve[a], curve[b]
            return a + (b - a) * ((ya - half) / (ya - yb) if ya != yb else 0.0)
    return float("nan")


def measure(taskset: str, per_subset: int | None) -> list[dict[str, str]]:
    tasks = _sample(taskset, per_subset)
    print(f"{taskset}: {len(tasks)} tasks: first views ...", file=sys.stderr, flush=True)
    views = _views(tasks)
    env = NavigationEnv(resolution=64)  # rendered: the scene text lists what the camera really sees
    print(f"{taskset}: text-only rule agent ...", file=sys.stderr, flush=True)
    text_wins = {t.id: _text_agent(env, t) for t in tasks}
    env.close()
    rows = []
    for s in SUBSETS:
        sub = [t for t in tasks if t.subset == s]
        print(f"{taskset}: noise curve {s} ...", file=sys.stderr, flush=True)
        curve = _noise_curve(sub)
        px = [views[t.id]["target"] for t in sub]
        share = statistics.median(px) / VIS_SIZE**2
        rows.append({
            "set": taskset, "subset": s, "tasks": str(len(sub)),
            "target px": ("0 (out of view)" if s == "long_horizon" else
                          f"{100 * share:.2f} % (~{share * 500 * 500:,.0f} px of 500x500)"),
            "same type in view": (f"{np.mean([views[t.id]['same'] for t in sub]):.2f} "
                                  f"({100 * np.mean([views[t.id]['same'] > 0 for t in sub]):.0f} % of tasks)"),
            "objects in view": f"{np.mean([views[t.id]['objects'] for t in sub]):.1f}",
            "optimal plan": f"{np.mean([t.metadata['oracle_steps'] for t in sub]):.1f}",
            "text-only rule agent": f"{100 * np.mean([text_wins[t.id] for t in sub]):.1f} %",
            "noise p50": f"{_p50(curve):.2f}",
        })
    return rows


def slack(taskset: str, task_dir: str | None = None) -> list[dict[str, str]]:
    """Per subset, on the geometry (every task): the expert's plan, the starts with at least 7 of the 20 steps to
    spare, the starts with a floor object lower than 0.5 m on the straight way to the target
    (:func:`eb_navigation.hard.clear_corridor`), the in-view starts that show a look-alike nearer the middle of the
    view than the target, and the most that any one of the 10,948 blind policies and of the feedback-only agents
    of ``CHECK_AGENTS`` solves."""
    from eb_navigation.baselines import BLIND_POLICIES, CHECK_AGENTS, blind_successes, rule_agent_successes
    from eb_navigation.hard import clear_corridor, lookalike_first

    specs = load_taskset(taskset, task_dir)
    rooms: dict = {}
    rows = []
    for s in SUBSETS:
        sub = [t for t in specs if t.subset == s]
        plans = [t.oracle_steps for t in sub]
        blind, agents, corridor, first = [], [], 0, 0
        for t in sub:
            key = (t.scene.kind, t.scene.seed, t.scene.clutter, t.extra_objects)
            room = rooms.get(key) or rooms.setdefault(key, build_room(t))
            free = room.free_space(room.extra_ids)
            start = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
            xy = t.target.position[:2]
            blind.append(blind_successes(free, start, xy))
            agents.append(list(rule_agent_successes(free, start, xy, agents=CHECK_AGENTS).values()))
            target = room.get(t.target.id)
            corridor += not clear_corridor(room, start, target)
            looks = [o for o in room.objects if o.type == target.type and o.id != target.id]
            first += s != "long_horizon" and lookalike_first(start, target, looks)
        b, a = np.sum(blind, axis=0), np.sum(agents, axis=0)
        names = list(CHECK_AGENTS)
        rows.append({
            "set": taskset if task_dir is None else task_dir, "subset": s,
            "expert plan mean (max)": f"{np.mean(plans):.1f} ({max(plans)})",
            ">= 7 steps of slack": f"{sum(p <= 13 for p in plans)} / {len(sub)}",
            "low object on the straight way": f"{corridor} / {len(sub)}",
            "look-alike nearer the middle": "-" if s == "long_horizon" else f"{first} / {len(sub)}",
            "worst blind policy": f"{int(b.max())} / {len(sub)} (`{BLIND_POLICIES[int(np.argmax(b))].name}`)",
            "blind policies solving any": f"{int((b > 0).sum())}",
            "worst feedback-only agent": f"{int(a.max())} / {len(sub)} ({names[int(np.argmax(a))]})",
        })
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-subset", type=int, default=None, help="tasks per subset (default: all)")
    ap.add_argument("--sets", default="classic,hard")
    ap.add_argument("--slack", action="store_true", help="plan slack, corridor objects and blind play instead")
    ap.add_argument("--task-dir", default=None, help="with --slack: a folder of per-subset files to measure")
    args = ap.parse_args(argv)
    if args.slack:
        rows = [r for ts in args.sets.split(",") for r in slack(ts, args.task_dir if ts == "hard" else None)]
    else:
        rows = [r for ts in args.sets.split(",") for r in measure(ts, args.per_subset)]
    cols = list(rows[0])
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for r in rows:
        print("| " + " | ".join(r[c] for c in cols) + " |")


if __name__ == "__main__":
    main()
