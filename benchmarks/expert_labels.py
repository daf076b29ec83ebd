"""What does ``runner.expert_labels=true`` cost?

With expert labels on, every executed action first asks the world's expert for a plan from the current state
(``env.expert_plan()``) and logs its first action as ``expert_action`` in steps.jsonl. This plays the same
episodes twice through the real runner (``eb_core.runner.run``, one process), labels off then on, and prints
the wall-time ratio on / off per world, how many actions were labelled, the expert's time per label, and
whether the labelled run took exactly the same actions with the same feedback (asking must not change the world).

The agent is the ``random`` baseline (so the expert is asked from the varied states a weak model reaches)
or ``--model oracle``.

Usage::

    python benchmarks/expert_labels.py [--env habitat] [--limit 10] [--model random] [--render true|false] [--repeats 2]
    python benchmarks/expert_labels.py --quick   # a few seconds (what tests/benchmarks runs)
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path


def _play(overrides: list[str], run_dir: Path) -> tuple[float, list[dict]]:
    from eb_core.compose import compose
    from eb_core.config import validate_config
    from eb_core.runner import run

    cfg_dict = compose(overrides)
    cfg = validate_config(cfg_dict)
    t0 = time.perf_counter()
    run(cfg, run_dir, cfg_dict=cfg_dict)
    wall = time.perf_counter() - t0
    actions = []
    for steps in run_dir.glob("**/steps.jsonl"):
        for line in steps.read_text().splitlines():
            actions += json.loads(line)["actions"]
    return wall, actions


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", default="habitat")
    ap.add_argument("--limit", type=int, default=10)
    ap.add_argument("--model", default="random")
    ap.add_argument("--render", default=None, choices=["true", "false"],
                    help="env.params.render, for the worlds that have it (default: the world's own)")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="a few seconds: 1 episode, 1 repeat, no rendering (checks that the "
                    "benchmark runs; its figures mean little)")
    a = ap.parse_args(argv)
    if a.quick:
        a.limit, a.repeats, a.render = 1, 1, a.render or "false"
    base = [f"env={a.env}", f"model={a.model}", f"limit={a.limit}", "runner.quiet=true",
            "runner.save_images=false"] + ([f"env.params.render={a.render}"] if a.render else [])
    walls: dict[bool, list[float]] = {False: [], True: []}
    with tempfile.TemporaryDirectory() as tmp:
        _play(base + ["++runner.expert_labels=false"], Path(tmp) / "warm-up")  # imports, first scene builds
        for rep in range(a.repeats):  # alternate, keep the fastest of each (least disturbed by other load)
            for labels in (False, True):
                wall, acts = _play(base + [f"++runner.expert_labels={str(labels).lower()}"],
                                   Path(tmp) / f"{labels}-{rep}")
                walls[labels].append(wall)
                if labels:
                    acts_on = acts
                else:
                    acts_off = acts
    off, on = min(walls[False]), min(walls[True])
    # Asking the expert must not change the episode: the same seeded agent takes the same actions.
    same = [(x["action"], x["feedback"]) for x in acts_off] == [(x["action"], x["feedback"]) for x in acts_on]
    labelled = [x for x in acts_on if "expert_action" in x]
    missing = sum(1 for x in labelled if x["expert_action"] is None)
    per_label = (on - off) / len(labelled) * 1000 if labelled else float("nan")
    print(f"env={a.env} model={a.model} render={a.render or 'default'} episodes={a.limit}")
    print(f"  labels off: {off:7.2f} s, {len(acts_off)} actions")
    print(f"  labels on : {on:7.2f} s, {len(acts_on)} actions, {len(labelled)} labelled "
          f"({missing} with no expert action)")
    print(f"  cost ratio on/off: {on / off:.2f}  (~{per_label:.1f} ms per label)")
    print(f"  episodes unchanged by labelling: {'yes' if same else 'NO (the expert changes the world state)'}")


if __name__ == "__main__":
    main()
