"""``eb plan``: how many tasks and repeats a measurement needs, and what it would cost.

    eb plan env=navigation target=width:10                  # a 95 % interval 10 points wide (full width)
    eb plan env=alfred subset=base target=diff:15           # detect a 15-point gap between two models (80 % power)
    eb plan env=habitat target=diff:8 from=runs/habitat/gpt-4o/none/default   # rates, noise and cost of a past run

The arithmetic is docs/statistics.md's ("How big a difference can be seen", "Worked example"), with
:func:`eb_core.stats.min_detectable_difference`'s normal approximation. Two sources of noise: the spread of
per-task success between tasks (``between``, which only more tasks reduce) and the within-task variance of one
episode's outcome (``within``, which repeats reduce too). With ``from=RUN`` both come from the run (``within``
only when it has repeats; otherwise it is 0: a model at temperature 0 repeats itself); without a run the rate is
50 % (the widest case) and all variance is between tasks. A difference between two models on the same tasks has
per-task variance ``tau2 + 2 within / repeats``, where ``tau2 = discordant - 2 within`` and ``discordant`` (the
share of tasks one model solves and the other does not, default 25 %) can be given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from eb_core.stats import LEVEL, _z

__all__ = ["Noise", "noise_from_run", "plan_rows", "simulate_width"]


@dataclass(frozen=True)
class Noise:
    rate: float
    """Success rate (0..1)."""
    between: float
    """Variance of the per-task success probability across tasks."""
    within: float
    """Mean within-task variance of one episode's outcome."""
    cost_per_episode: float | None = None
    """USD per episode (from a past run)."""
    tokens_per_episode: float | None = None
    source: str = "assumed"

    @property
    def total(self) -> float:
        return self.between + self.within


def noise_from_run(run_dir: str | Path) -> Noise:
    """Rate, variance components and cost per episode of a finished run."""
    from eb_core.records import RunFiles

    eps = [e for e in RunFiles(run_dir).load_episodes() if e.status == "ok"]
    if not eps:
        raise ValueError(f"{run_dir}: no finished episodes to learn rates from; give a run with results")
    by_task: dict[str, list[float]] = {}
    for e in eps:
        by_task.setdefault(e.task_id, []).append(1.0 if e.success else 0.0)
    means = np.array([np.mean(v) for v in by_task.values()])
    reps = [v for v in by_task.values() if len(v) >= 2]
    within = float(np.mean([np.var(v, ddof=1) for v in reps])) if reps else 0.0
    r = float(np.mean([len(v) for v in by_task.values()]))
    between = max(float(np.var(means, ddof=1)) - within / r, 0.0) if len(means) > 1 else 0.25
    cost = float(np.mean([e.cost_usd for e in eps]))
    tokens = float(np.mean([e.prompt_tokens + e.completion_tokens for e in eps]))
    return Noise(rate=float(means.mean()), between=between, within=within, cost_per_episode=cost,
                 tokens_per_episode=tokens, source=f"{len(by_task)} tasks of {run_dir}")


def _variance(noise: Noise, kind: str, repeats: int, discordant: float) -> float:
    """Variance of one task's contribution (a rate: its mean over repeats; a paired gap: the difference)."""
    if kind == "width":
        return noise.between + noise.within / repeats
    tau2 = max(discordant - 2 * noise.within, 0.0)
    return tau2 + 2 * noise.within / repeats


def plan_rows(noise: Noise, kind: str, target: float, available: int, *, repeats: tuple[int, ...] = (1, 2, 3, 5),
              discordant: float = 0.25, level: float = LEVEL, power: float = 0.8) -> list[dict[str, Any]]:
    """For each repeat count: tasks needed for the target, and what all ``available`` tasks achieve."""
    if kind not in ("width", "diff"):
        raise ValueError(f"target kind must be width or diff, got {kind!r}")
    if not 0 < target < 1:
        raise ValueError(f"target must be between 0 and 100 points, got {target * 100:g}")
    za = _z(level)
    zb = _z(2 * power - 1)
    rows = []
    for r in repeats:
        v = _variance(noise, kind, r, discordant)
        if kind == "width":  # full width 2 z sqrt(v / n) <= target
            need = math.ceil(4 * za * za * v / (target * target)) if v > 0 else 1
            reach = 2 * za * math.sqrt(v / available) if available else float("inf")
        else:  # (z_a + z_b) sqrt(v / n) <= target
            need = math.ceil((za + zb) ** 2 * v / (target * target)) if v > 0 else 1
            reach = (za + zb) * math.sqrt(v / available) if available else float("inf")
        episodes = need * r * (2 if kind == "diff" else 1)
        cost = None if noise.cost_per_episode is None else episodes * noise.cost_per_episode
        rows.append({"repeats": r, "tasks_needed": need, "feasible": need <= available, "episodes": episodes,
                     "with_all_tasks": reach, "cost_usd": cost})
    return rows


def simulate_width(rate_per_task: np.ndarray, repeats: int, n_sims: int = 4000, seed: int = 0) -> float:
    """Monte-Carlo check of the width plan: the full width (``2 z sd``) of the simulated sampling distribution of
    the mean success over ``len(rate_per_task)`` tasks drawn with replacement from the population
    ``rate_per_task``, each played ``repeats`` times (Bernoulli outcomes)."""
    rng = np.random.default_rng(seed)
    n = len(rate_per_task)
    p = rng.choice(rate_per_task, size=(n_sims, n), replace=True)
    outcomes = rng.random((n_sims, n, repeats)) < p[:, :, None]
    means = outcomes.mean(axis=(1, 2))
    return float(2 * _z(LEVEL) * means.std(ddof=1))


# -- the command -----------------------------------------------------------------------------------


def _parse(argv: list[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    for arg in argv:
        key, sep, value = arg.partition("=")
        if not sep:
            raise ValueError(f"unexpected argument {arg!r}; eb plan takes key=value arguments, e.g. "
                             f"`eb plan env=navigation target=width:10`")
        out[key] = value
    allowed = {"env", "subset", "target", "from", "taskset", "repeats", "rate", "discordant", "power"}
    bad = sorted(set(out) - allowed)
    if bad:
        raise ValueError(f"unknown key {bad[0]!r}; eb plan takes {', '.join(sorted(allowed))}")
    return out


def _target(text: str) -> tuple[str, float]:
    kind, _, amount = text.partition(":")
    if kind not in ("width", "diff") or not amount:
        raise ValueError(f"target={text!r}: say width:<points> (a 95 % interval that wide) or diff:<points> (a gap "
                         f"to detect with 80 % power), e.g. target=width:10")
    try:
        value = float(amount.rstrip("%"))
    except ValueError:
        raise ValueError(f"target={text!r}: {amount!r} is not a number of points") from None
    return kind, value / 100.0


def _available(env: str, subset: str | None) -> tuple[int, str]:
    from eb_core.plugins import Registry

    specs = Registry.create().envs
    if env not in specs:
        raise ValueError(f"unknown env {env!r}; available: {', '.join(sorted(specs))}")
    subsets = specs[env].subsets
    if subset is None:
        return sum(subsets.values()), "all subsets"
    if subset not in subsets:
        raise ValueError(f"unknown subset {subset!r} for env {env!r}; available: {', '.join(subsets)}")
    return subsets[subset], f"subset {subset}"


def cmd_plan(argv: list[str]) -> int:
    import sys

    try:
        args = _parse(list(argv))
        if "env" not in args or "target" not in args:
            raise ValueError("eb plan needs env=<world> and target=width:<points>|diff:<points>, e.g. "
                             "`eb plan env=navigation target=width:10`")
        kind, target = _target(args["target"])
        available, scope = _available(args["env"], args.get("subset"))
        if "from" in args:
            noise = noise_from_run(args["from"])
        else:
            p = float(args.get("rate", "50").rstrip("%")) / 100
            noise = Noise(rate=p, between=p * (1 - p), within=0.0, source=f"assumed rate {p:.0%}, no repeat noise")
        repeats = tuple(int(x) for x in args.get("repeats", "1,2,3,5").split(","))
        discordant = float(args.get("discordant", "25").rstrip("%")) / 100
        power = float(args.get("power", "80").rstrip("%")) / 100
        rows = plan_rows(noise, kind, target, available, repeats=repeats, discordant=discordant, power=power)
    except ValueError as exc:
        print(f"eb plan: {exc}", file=sys.stderr)
        return 2
    what = (f"a 95 % interval {target * 100:g} points wide" if kind == "width"
            else f"a {target * 100:g}-point difference between two models on the same tasks ({power:.0%} power, "
                 f"{discordant:.0%} discordant tasks)")
    print(f"eb plan: {args['env']} ({scope}, {available} tasks{', taskset ' + args['taskset'] if 'taskset' in args else ''})"
          f" -- {what}")
    print(f"noise: success {noise.rate:.1%}, between-task variance {noise.between:.3f}, within-task "
          f"{noise.within:.3f} ({noise.source})")
    head = f"{'repeats':>8}{'tasks needed':>14}{'feasible':>10}{'episodes':>10}{'with all tasks':>16}{'cost USD':>10}"
    print(head)
    for r in rows:
        cost = "-" if r["cost_usd"] is None else f"{r['cost_usd']:.2f}"
        label = "width" if kind == "width" else "detectable"
        print(f"{r['repeats']:>8}{r['tasks_needed']:>14}{'yes' if r['feasible'] else 'NO':>10}{r['episodes']:>10}"
              f"{r['with_all_tasks'] * 100:>12.1f} pts{cost:>10}  ({label} with all {available})")
    if not any(r["feasible"] for r in rows):
        print(f"no repeat count reaches the target on {available} tasks: pool subsets or worlds, or generate more "
              f"tasks (`eb tasks generate`), or aim for a wider target", file=sys.stderr)
    if noise.cost_per_episode is None:
        print("cost: give from=RUN (a past run of the model) to price the plan", file=sys.stderr)
    return 0
