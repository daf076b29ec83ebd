"""Difficulty figures of EB-ALFRED's task sets, classic against hard (docs/hard_tasks/alfred.md).

    MUJOCO_GL=egl python plugins/eb_alfred/scripts/difficulty.py [--sets classic hard] [--per-subset N]
        [--noise-per-subset N] [--render-per-subset N] [--no-render] [--quick]

Per set and subset:
* target area: the share of the first (start) image the goal's object covers (median over tasks; for a goal that
  accepts several instances, the largest of them), rendered at 250 x 250; and the same after the ``find`` (and
  ``open``) that brings it into view;
* same-type: instances of the object's type in the room, and look-alikes (instances the goal does not accept)
  visible in the first image (means);
* plan: the expert's optimal plan length (mean of ``oracle_steps``);
* text rule / blind guess / blind sweep / random: success of the players of :mod:`eb_alfred.blind`;
* noise p50: the noise level at which the noisy expert's success falls to half (``eb_core.audit.p50`` on the
  curve over 0, 0.1, ..., 0.7; a sample of tasks per subset).
"""

from __future__ import annotations

import argparse
import random
import statistics
import sys
from collections import defaultdict
from typing import Any

from eb_core.audit import p50

from eb_alfred.blind import guess_episode, noisy_expert_episode, random_episode, sweep_episode, text_rule_episode
from eb_alfred.goals import matches
from eb_alfred.tasks import SUBSETS, load_all
from eb_alfred.world import World

NOISE = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7)


def _areas(recs: list[Any]) -> dict[str, tuple[float, float, int, int]]:
    """task id -> (target area in the first image, after the find that brings it into view, same-type instances
    in the room, look-alikes in the first image)."""
    from eb_alfred.audit import Views
    from eb_alfred.render import AlfredRenderer

    renderer = AlfredRenderer(250)
    out = {}
    try:
        for r in recs:
            scene, goal = r.scene.model_dump(exclude_defaults=True), r.goal.plain()
            w = World.from_scene(scene)
            renderer.load(w)
            renderer.render(w)
            seen = renderer.visible_fraction(w, 250)
            ref = goal["object"]
            xt = w.objects[ref["instance"]].type if "instance" in ref else ref["type"]
            same = w.of_type(xt)
            targets = [n for n in same if matches(w, ref, n)]
            others = [n for n in same if n not in targets and seen.get(n, 0.0) > 0]
            found = max(Views(w, renderer).area(n) for n in targets)
            out[r.id] = (max(seen.get(n, 0.0) for n in targets), found, len(same), len(others))
            print(f"rendered {r.id}", file=sys.stderr, flush=True) if len(out) % 50 == 0 else None
    finally:
        renderer.close()
    return out


def _guess_odds(scene: dict[str, Any], goal: dict[str, Any]) -> float:
    """The chance that one blind choice among the instances of the wanted types is right (1 for a goal any
    instance satisfies)."""
    from math import comb

    w = World.from_scene(scene)
    p = 1.0
    for role in ("object", "receptacle", "movable"):
        ref = goal.get(role)
        if not ref:
            continue
        kind = w.objects[ref["instance"]].type if "instance" in ref else ref["type"]
        names = w.of_type(kind)
        good = [n for n in names if matches(w, ref, n)]
        if role == "object" and goal["kind"] == "pick_two_and_place":
            p *= comb(len(good), 2) / comb(len(names), 2) if len(names) >= 2 else 1.0
        else:
            p *= len(good) / len(names)
    return p


def _sample(recs: list[Any], k: int) -> list[Any]:
    by: dict[str, list[Any]] = defaultdict(list)
    for r in recs:
        by[r.subset].append(r)
    return [r for s in SUBSETS for r in by[s][:: max(1, len(by[s]) // max(k, 1))][:k]]


def figures(taskset: str, per_subset: int, noise_per_subset: int, render_per_subset: int) -> dict[str, dict[str, str]]:
    recs = _sample(load_all(taskset=taskset), per_subset)
    areas = _areas(_sample(recs, render_per_subset)) if render_per_subset else {}
    rows: dict[str, dict[str, Any]] = defaultdict(lambda: defaultdict(list))
    for r in recs:
        scene, goal = r.scene.model_dump(exclude_defaults=True), r.goal.plain()
        row = rows[r.subset]
        rng = random.Random(f"difficulty:{r.id}")
        row["plan"].append(r.oracle_steps)
        row["expected"].append(_guess_odds(scene, goal))
        row["text"].append(text_rule_episode(scene, goal, r.instruction))
        row["guess"].append(guess_episode(scene, goal, rng))
        row["sweep"].append(sweep_episode(scene, goal, rng))
        row["random"].append(random_episode(scene, goal, rng))
        if r.id in areas:
            a, found, same, others = areas[r.id]
            row["area"].append(a)
            row["found"].append(found)
            row["same"].append(same)
            row["others"].append(others)
    for r in _sample(recs, noise_per_subset):
        scene, goal = r.scene.model_dump(exclude_defaults=True), r.goal.plain()
        for p in NOISE:
            rows[r.subset][f"noise{p}"].append(noisy_expert_episode(scene, goal, p, random.Random(f"n:{r.id}:{p}")))
    out: dict[str, dict[str, str]] = {}
    for s in SUBSETS:
        row = rows[s]
        if not row["plan"]:
            continue
        curve = [(p, statistics.mean(row[f"noise{p}"])) for p in NOISE if row[f"noise{p}"]]
        half = p50([(p, v / curve[0][1] if curve[0][1] else 0.0) for p, v in curve]) if curve else None
        out[s] = {
            "tasks": str(len(row["plan"])),
            "target area (median % of image)": f"{100 * statistics.median(row['area']):.2f}" if row["area"] else "-",
            "target area after its find (median %)":
                f"{100 * statistics.median(row['found']):.2f}" if row["found"] else "-",
            "same-type in room (mean)": f"{statistics.mean(row['same']):.1f}" if row["same"] else "-",
            "look-alikes in first image (mean)": f"{statistics.mean(row['others']):.1f}" if row["others"] else "-",
            "optimal plan (mean steps)": f"{statistics.mean(row['plan']):.1f}",
            "text-only rule agent": f"{100 * statistics.mean(row['text']):.0f} %",
            "blind guess, expected (1 / choices)": f"{100 * statistics.mean(row['expected']):.1f} %",
            "blind guess": f"{100 * statistics.mean(row['guess']):.0f} %",
            "blind sweep (reacts to feedback)": f"{100 * statistics.mean(row['sweep']):.0f} %",
            "random": f"{100 * statistics.mean(row['random']):.0f} %",
            "noise p50": "> 0.7" if curve and half is None else (f"{half:.2f}" if half is not None else "-"),
        }
    return out


def table(results: dict[str, dict[str, dict[str, str]]]) -> str:
    """One row per figure, one column per subset; each cell lists the sets' values in order (classic / hard)."""
    sets = list(results)
    keys = list(next(iter(next(iter(results.values())).values())))
    subsets = [s for s in SUBSETS if any(s in results[t] for t in sets)]
    lines = [f"| figure ({' / '.join(sets)}) | " + " | ".join(subsets) + " |", "|---|" + "---|" * len(subsets)]
    for k in keys:
        cells = [" / ".join(results[t].get(s, {}).get(k, "-") for t in sets) for s in subsets]
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _parse(md: str) -> dict[str, dict[str, dict[str, str]]]:
    """Read back a one-set table printed by :func:`table` (to merge runs made at different times)."""
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in md.splitlines() if line.startswith("|")]
    head, body = rows[0], rows[2:]
    name = head[0][head[0].index("(") + 1: head[0].index(")")]
    out: dict[str, dict[str, str]] = {s: {} for s in head[1:]}
    for row in body:
        for s, v in zip(head[1:], row[1:]):
            out[s][row[0]] = v
    return {name: out}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", nargs="*", default=["classic", "hard"])
    ap.add_argument("--per-subset", type=int, default=50)
    ap.add_argument("--noise-per-subset", type=int, default=10)
    ap.add_argument("--render-per-subset", type=int, default=50, help="tasks per subset for the image figures")
    ap.add_argument("--no-render", action="store_true", help="skip the image figures (no MuJoCo)")
    ap.add_argument("--quick", action="store_true", help="2 tasks per subset, no rendering (a smoke run)")
    ap.add_argument("--merge", nargs="*", default=[], help="tables printed earlier for one set each, to put first")
    args = ap.parse_args(argv)
    if args.quick:
        args.per_subset, args.noise_per_subset, args.no_render = 2, 1, True
    results: dict[str, dict[str, dict[str, str]]] = {}
    for path in args.merge:
        results.update(_parse(open(path, encoding="utf-8").read()))
    for t in args.sets:
        results[t] = figures(t, args.per_subset, args.noise_per_subset,
                             0 if args.no_render else min(args.render_per_subset, args.per_subset))
    print(table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
