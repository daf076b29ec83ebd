"""Probes of the expert: it solves every task in closed loop, and its success falls as its actions are randomised."""

from __future__ import annotations

from collections import Counter
from typing import Any

from eb_core.audit.contract import ProbeResult
from eb_core.audit.playing import _Job, play_jobs
from eb_core.audit.contract import EpisodeOutcome
from eb_core.audit.setup import NOISE_LEVELS, AuditSetup, _by_subset, _listed, _pct
from eb_core.env import Task
from eb_core.stats import p50, rise_z

__all__ = ["probe_closed_loop", "probe_noise_curve"]

P50_WARN = 0.8
RISE_Z = 3.09  # one-sided p < 0.001 for each pair of noise levels


def _curve_key(params_key: str, noise: float, repeat: int) -> tuple[Any, ...]:
    return ("curve", noise, repeat) if not params_key else ("curve", params_key, noise, repeat)


def _curve_outcomes(setup: AuditSetup, levels: list[tuple[float, int]], tasks: list[Task] | None = None,
                    params_key: str = "") -> dict[tuple[float, int], dict[str, EpisodeOutcome]]:
    """Noisy-expert outcomes per (noise, repeat) and task, played in one batch and cached on the setup (so the
    noise curve, the closed loop and the parallel forms share episodes). ``params_key`` is the JSON of another
    form's env params (empty: the tasks under audit)."""
    tasks = setup.sampled_tasks() if tasks is None else tasks
    todo = [_Job(t, noise=noise, repeat=rep, params=params_key) for noise, rep in levels for t in tasks
            if t.id not in setup._cache.get(_curve_key(params_key, noise, rep), {})]
    for job, out in zip(todo, play_jobs(setup, todo)):
        setup._cache.setdefault(_curve_key(params_key, job.noise, job.repeat), {})[job.task.id] = out
    return {lv: {t.id: setup._cache[_curve_key(params_key, *lv)][t.id] for t in tasks} for lv in levels}


def probe_closed_loop(setup: AuditSetup) -> ProbeResult:
    outcomes = _curve_outcomes(setup, [(0.0, 0)], setup.episode_tasks())[(0.0, 0)]
    failed = [(tid, o) for tid, o in outcomes.items() if not o.success]
    rows = [{"task": tid, "end": o.end, "steps": o.steps, "detail": o.detail[:100]} for tid, o in failed[:10]]
    ends = Counter(o.end for _, o in failed)
    n = len(outcomes)
    value = f"{_pct((n - len(failed)) / n if n else 1.0)} ({n - len(failed)}/{n})"
    if failed:
        value += "; failures: " + ", ".join(f"{k} {v}" for k, v in ends.most_common())
    return ProbeResult(name="closed_loop_oracle", passed=not failed, value=value,
                       threshold=f"100 % within max_steps={setup.max_steps}",
                       failing_tasks=_listed(tid for tid, _ in failed), rows=rows)


def probe_noise_curve(setup: AuditSetup) -> ProbeResult:
    tasks = setup.sampled_tasks()
    groups = _by_subset(tasks)
    reps = 1 if setup.quick else setup.curve_repeats
    wins: dict[float, Counter[str]] = {p: Counter() for p in NOISE_LEVELS}  # p -> task id -> successes
    levels = [(p, r) for p in NOISE_LEVELS for r in range(reps)]
    for (p, _), outcomes in _curve_outcomes(setup, levels, tasks).items():
        for tid, o in outcomes.items():
            wins[p][tid] += int(o.success)
    rows, rises, warns, failing = [], [], [], []
    p50s = {}
    for subset, ts in groups.items():
        n = len(ts) * reps
        succ = {p: sum(wins[p][t.id] for t in ts) for p in NOISE_LEVELS}
        curve = [(p, succ[p] / n) for p in NOISE_LEVELS]
        for i, lo in enumerate(NOISE_LEVELS):
            for hi in NOISE_LEVELS[i + 1:]:
                z = rise_z((succ[lo], n), (succ[hi], n))
                if z > RISE_Z:
                    rises.append(f"{subset}: {_pct(succ[lo] / n)} at p={lo} -> {_pct(succ[hi] / n)} at p={hi}")
                    failing += [t.id for t in ts if wins[hi][t.id] > wins[lo][t.id]]
        half = p50(curve)
        p50s[subset] = half
        if half is None or half > P50_WARN:
            warns.append(f"{subset} (p50 {'> 1' if half is None else f'{half:.2f}'})")
        row: dict[str, Any] = {"subset": subset}
        row.update({f"p={p:g}": f"{100 * s:.0f}" for p, s in curve})
        row["p50"] = "> 1" if half is None else f"{half:.2f}"
        rows.append(row)
    rises = list(dict.fromkeys(rises))
    p50_text = ", ".join(f"{s} {'>1' if v is None else f'{v:.2f}'}" for s, v in p50s.items())
    value = f"p50: {p50_text}"
    if rises:
        value = "success rises with noise: " + "; ".join(rises[:3]) + f" | {value}"
    warning = (f"p50 > {P50_WARN} (the subset tells models apart poorly): " + ", ".join(warns)) if warns else None
    return ProbeResult(name="noise_curve", passed=not rises, value=value,
                       threshold=f"no rise with p beyond noise (z > {RISE_Z}); warn p50 > {P50_WARN}",
                       failing_tasks=_listed(failing), warning=warning, rows=rows)

