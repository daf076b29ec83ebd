"""Uncertainty for benchmark scores: intervals, between-repeat spread and paired comparisons (numpy only).

A run is a matrix of outcomes, one row per task and one column per repeat (``runner.repeats``). The
quantity we estimate is the mean over the task population of a task's expected score, so the unit that is
resampled is the *task*: a cluster bootstrap draws tasks with replacement and keeps each drawn task's
repeats together. ``docs/statistics.md`` explains the choices:

* success rate, one repeat: the Wilson score interval (binomial outcomes, close to exact coverage);
* everything else (subgoal rates, success with repeats): percentile cluster bootstrap over tasks;
* paired comparison of two runs on the same tasks: McNemar's exact test with one repeat each,
  otherwise a paired bootstrap over tasks; the interval of the difference is a paired bootstrap;
* task-set audits (``eb audit``, ``docs/audit.md``): the noise curve's p50 and rise test, and the parallel-forms
  permutation test with the difference it can detect.

Every bootstrap uses a fixed seed, so the same files always give the same numbers.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = [
    "BOOTSTRAP_SAMPLES",
    "BOOTSTRAP_SEED",
    "LEVEL",
    "bootstrap_weights",
    "clopper_pearson",
    "mcnemar_interval",
    "cluster_bootstrap_interval",
    "describe_interval",
    "detectable_difference",
    "mcnemar_exact",
    "min_detectable_difference",
    "outcome_matrix",
    "p50",
    "paired_comparison",
    "permutation_p_value",
    "rate_interval",
    "repeat_sd",
    "rise_z",
    "wilson_interval",
]

LEVEL = 0.95
"""Confidence level of every interval."""
BOOTSTRAP_SAMPLES = 2000
"""Bootstrap resamples per interval."""
BOOTSTRAP_SEED = 20250
"""Fixed RNG seed: the same episodes always give the same intervals."""
_Z = 1.959963984540054  # standard normal quantile for a two-sided 95 % interval


def _z(level: float) -> float:
    if abs(level - 0.95) < 1e-12:
        return _Z
    # Acklam-free route: invert erf with Newton steps (only used for other levels).
    target = (1 + level) / 2
    x = 0.0
    for _ in range(60):
        cdf = 0.5 * (1 + math.erf(x / math.sqrt(2)))
        x -= (cdf - target) / (math.exp(-x * x / 2) / math.sqrt(2 * math.pi))
    return x


def wilson_interval(successes: Any, n: Any, level: float = LEVEL) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval for ``successes`` out of ``n`` (arrays broadcast; ``n == 0`` gives 0..1)."""
    k = np.asarray(successes, dtype=float)
    n_ = np.asarray(n, dtype=float)
    z = _z(level)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(n_ > 0, k / np.where(n_ > 0, n_, 1), 0.0)
        denom = 1 + z * z / np.where(n_ > 0, n_, 1)
        centre = (p + z * z / (2 * np.where(n_ > 0, n_, 1))) / denom
        half = z * np.sqrt(p * (1 - p) / np.where(n_ > 0, n_, 1) + z * z / (4 * np.where(n_ > 0, n_, 1) ** 2)) / denom
    lo = np.where((n_ > 0) & (k > 0), np.clip(centre - half, 0.0, 1.0), 0.0)  # exact ends at 0/n and n/n
    hi = np.where((n_ > 0) & (k < n_), np.clip(centre + half, 0.0, 1.0), 1.0)
    return lo, hi


def bootstrap_weights(n_tasks: int, n_boot: int = BOOTSTRAP_SAMPLES, seed: int = BOOTSTRAP_SEED) -> np.ndarray:
    """``(n_boot, n_tasks)`` resampling weights: how often each task is drawn, divided by ``n_tasks``.

    A bootstrap mean is then one matrix product, and many runs (or many simulated runs) share the draws.
    """
    rng = np.random.default_rng(seed)
    counts = rng.multinomial(n_tasks, np.full(n_tasks, 1.0 / n_tasks), size=n_boot)
    return counts / float(n_tasks)


def cluster_bootstrap_interval(task_means: Any, level: float = LEVEL, n_boot: int = BOOTSTRAP_SAMPLES,
                               seed: int = BOOTSTRAP_SEED) -> tuple[np.ndarray, np.ndarray]:
    """Percentile interval of the mean of per-task scores, resampling tasks.

    ``task_means`` is ``(n_tasks,)`` or ``(batch, n_tasks)``; each task's value is the mean of its repeats
    (so repeats travel with their task). Returns ``(lo, hi)`` shaped like the batch.
    """
    x = np.asarray(task_means, dtype=float)
    n = x.shape[-1]
    if n == 0:
        return np.zeros(x.shape[:-1]), np.ones(x.shape[:-1])
    w = bootstrap_weights(n, n_boot, seed)
    boot = x @ w.T  # (..., n_boot)
    alpha = (1 - level) / 2
    lo, hi = np.quantile(boot, [alpha, 1 - alpha], axis=-1)
    return lo, hi


def outcome_matrix(values: dict[str, dict[int, float]]) -> tuple[list[str], np.ndarray]:
    """Task ids (sorted) and a ``(tasks, repeats)`` matrix from ``{task_id: {repeat: value}}`` (missing = NaN).

    Sorting makes every interval independent of the order in which episodes finished (workers, resume)."""
    ids = sorted(values)
    n_rep = max((max(r) + 1 for r in values.values() if r), default=0)
    m = np.full((len(ids), max(1, n_rep)), np.nan)
    for i, tid in enumerate(ids):
        for r, v in values[tid].items():
            m[i, r] = v
    return ids, m


def _task_means(m: np.ndarray) -> np.ndarray:
    m = np.asarray(m, dtype=float)
    if m.ndim == 1:
        m = m[:, None]
    keep = ~np.all(np.isnan(m), axis=1)
    return np.nanmean(m[keep], axis=1) if keep.any() else np.zeros(0)


def repeat_sd(m: Any) -> float | None:
    """Standard deviation (n-1) between the per-repeat means of a ``(tasks, repeats)`` matrix.

    Only repeats that every task has are used; ``None`` with fewer than two such repeats.
    """
    m = np.asarray(m, dtype=float)
    if m.ndim != 2 or m.shape[0] == 0:
        return None
    full = [j for j in range(m.shape[1]) if not np.isnan(m[:, j]).any()]
    if len(full) < 2:
        return None
    return float(np.std(m[:, full].mean(axis=0), ddof=1))


def rate_interval(m: Any, binary: bool, level: float = LEVEL) -> dict[str, Any]:
    """Point estimate and interval of a score from its ``(tasks, repeats)`` outcome matrix.

    Returns ``{"mean", "ci_low", "ci_high", "ci_method", "tasks", "repeats", "repeat_sd"}``. Binary
    outcomes with one repeat per task use Wilson; the rest use the cluster bootstrap over tasks. A
    bootstrap has no spread when every task scored the same 0 or 1; the interval then falls back to
    Wilson over tasks, which still says how far a 60/60 is from certain.
    """
    m = np.asarray(m, dtype=float)
    if m.ndim == 1:
        m = m[:, None]
    means = _task_means(m)
    n = int(means.size)
    reps = int(np.max(np.sum(~np.isnan(m), axis=1))) if m.size else 0
    out: dict[str, Any] = {"mean": float(means.mean()) if n else 0.0, "tasks": n, "repeats": reps,
                           "repeat_sd": repeat_sd(m)}
    if n == 0:
        out.update(ci_low=None, ci_high=None, ci_method=None)
        return out
    degenerate = bool(np.all(means == means[0]))
    if (binary and reps <= 1) or (degenerate and means[0] in (0.0, 1.0)):
        lo, hi = wilson_interval(float(means.sum()), n, level)
        method = "wilson"
    else:
        lo, hi = cluster_bootstrap_interval(means, level)
        method = "cluster-bootstrap"
    out.update(ci_low=float(lo), ci_high=float(hi), ci_method=method)
    return out


def mcnemar_exact(a: Any, b: Any) -> float:
    """Two-sided exact McNemar p-value for paired binary outcomes ``a`` and ``b`` (one per task)."""
    a_ = np.asarray(a, dtype=bool)
    b_ = np.asarray(b, dtype=bool)
    only_a = int(np.sum(a_ & ~b_))
    only_b = int(np.sum(~a_ & b_))
    n = only_a + only_b
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, k) for k in range(min(only_a, only_b) + 1))
    return min(1.0, 2 * tail / 2 ** n)


def _binom_cdf(k: int, n: int, p: float) -> float:
    """P(X <= k) for X ~ Bin(n, p), summed in log space (stable for the n of a benchmark)."""
    if p <= 0.0:
        return 1.0
    if p >= 1.0:
        return 1.0 if k >= n else 0.0
    lp, lq = math.log(p), math.log1p(-p)
    terms = [math.lgamma(n + 1) - math.lgamma(i + 1) - math.lgamma(n - i + 1) + i * lp + (n - i) * lq
             for i in range(k + 1)]
    top = max(terms)
    return min(1.0, math.exp(top) * sum(math.exp(t - top) for t in terms))


def clopper_pearson(k: int, n: int, level: float = LEVEL) -> tuple[float, float]:
    """The exact (Clopper-Pearson) interval of a binomial proportion ``k / n``: the proportions that two
    one-sided exact tests at ``(1 - level) / 2`` each do not reject."""
    if n <= 0:
        return 0.0, 1.0
    alpha = (1 - level) / 2

    def solve(f: Any) -> float:  # f is increasing in p on [0, 1]; find f(p) = 0 by bisection
        lo, hi = 0.0, 1.0
        for _ in range(60):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
        return (lo + hi) / 2

    low = 0.0 if k == 0 else solve(lambda p: (1 - _binom_cdf(k - 1, n, p)) - alpha)
    high = 1.0 if k == n else solve(lambda p: alpha - _binom_cdf(k, n, p))
    return low, high


def mcnemar_interval(only_a: int, only_b: int, n_tasks: int, level: float = LEVEL) -> tuple[float, float]:
    """An exact interval for B - A on paired binary outcomes that agrees with :func:`mcnemar_exact`.

    B - A = q (2 pi - 1), with q the share of discordant tasks and pi the share of them that B solved. pi gets
    the Clopper-Pearson interval McNemar's exact test inverts (so the interval holds 0 exactly when the test is
    not significant) and q its own Clopper-Pearson interval; the interval is the range of q (2 pi - 1) over both.
    """
    n = only_a + only_b
    if n == 0:
        return 0.0, 0.0
    pi_lo, pi_hi = clopper_pearson(only_b, n, level)
    q_lo, q_hi = clopper_pearson(n, n_tasks, level)
    corners = [q * (2 * pi - 1) for q in (q_lo, q_hi) for pi in (pi_lo, pi_hi)]
    return min(corners), max(corners)


def paired_comparison(a: Any, b: Any, binary: bool = True, level: float = LEVEL) -> dict[str, Any]:
    """Compare run B with run A on the same tasks (rows aligned; columns are repeats, NaN = missing).

    ``diff`` is B minus A. One method per comparison, so its interval and its test always agree: McNemar's
    exact test with :func:`mcnemar_interval` when both runs have one repeat of a binary score, else a paired
    bootstrap over tasks (percentile interval and its two-sided p-value). ``method`` names it.
    """
    a_m = np.asarray(a, dtype=float)
    b_m = np.asarray(b, dtype=float)
    a_m = a_m[:, None] if a_m.ndim == 1 else a_m
    b_m = b_m[:, None] if b_m.ndim == 1 else b_m
    if a_m.shape[0] != b_m.shape[0]:
        raise ValueError("paired runs must have the same tasks, in the same order")
    keep = ~(np.all(np.isnan(a_m), axis=1) | np.all(np.isnan(b_m), axis=1))
    a_m, b_m = a_m[keep], b_m[keep]
    n = int(a_m.shape[0])
    out: dict[str, Any] = {"tasks": n}
    if n == 0:
        out.update(a=None, b=None, diff=None, ci_low=None, ci_high=None, p_value=None, test=None,
                   significant=False)
        return out
    ma, mb = np.nanmean(a_m, axis=1), np.nanmean(b_m, axis=1)
    d = mb - ma
    reps_a = int(np.max(np.sum(~np.isnan(a_m), axis=1)))
    reps_b = int(np.max(np.sum(~np.isnan(b_m), axis=1)))
    if binary and reps_a == 1 and reps_b == 1:
        sa, sb = ma > 0.5, mb > 0.5
        p = mcnemar_exact(sa, sb)
        lo, hi = mcnemar_interval(int(np.sum(sa & ~sb)), int(np.sum(~sa & sb)), n, level)
        test = "mcnemar-exact"
    else:
        boot = bootstrap_weights(n) @ d
        alpha = (1 - level) / 2
        lo, hi = (float(x) for x in np.quantile(boot, [alpha, 1 - alpha]))
        if np.all(d == 0):
            p = 1.0
        else:
            p = float(min(1.0, 2 * min(np.mean(boot <= 0), np.mean(boot >= 0))))
        test = "paired-bootstrap"
    out.update(a=float(ma.mean()), b=float(mb.mean()), diff=float(d.mean()), ci_low=float(lo), ci_high=float(hi),
               p_value=float(p), test=test, significant=bool(p < 1 - level))
    return out


def min_detectable_difference(n_tasks: int, variance_per_task: float, level: float = LEVEL,
                              power: float = 0.8) -> float:
    """Smallest true difference a two-sided test at ``level`` finds with probability ``power``.

    ``variance_per_task`` is the variance of one task's contribution to the difference (e.g. ``2p(1-p)``
    for two independent success rates, the discordance rate for two models on the same tasks).
    """
    z_a = _z(level)
    z_b = _z(2 * power - 1)
    return (z_a + z_b) * math.sqrt(variance_per_task / n_tasks)


def describe_interval(block: dict[str, Any], key: str) -> str:
    """``"45.0 [39.5, 50.6]"`` (percent) for ``block[key]`` and its ``key + "_ci"`` entry."""
    value = block.get(key)
    ci = block.get(f"{key}_ci") or {}
    if value is None:
        return "-"
    text = f"{100 * value:.1f}"
    if ci.get("ci_low") is not None:
        text += f" [{100 * ci['ci_low']:.1f}, {100 * ci['ci_high']:.1f}]"
    return text


# -- task-set audits (``eb audit``) --------------------------------------------------------------------------


def p50(curve: Sequence[tuple[float, float]]) -> float | None:
    """Noise level where success first falls to 50 % (linear between grid points); None if it never does."""
    prev_p, prev_s = curve[0]
    if prev_s <= 0.5:
        return prev_p
    for p, s in curve[1:]:
        if s <= 0.5:
            return prev_p + (p - prev_p) * (prev_s - 0.5) / (prev_s - s)
        prev_p, prev_s = p, s
    return None


def rise_z(lo: tuple[int, int], hi: tuple[int, int]) -> float:
    """One-sided two-proportion z statistic for success rising from ``lo`` to ``hi`` ((successes, n) pairs)."""
    (s1, n1), (s2, n2) = lo, hi
    pooled = (s1 + s2) / (n1 + n2)
    var = pooled * (1 - pooled) * (1 / n1 + 1 / n2)
    if var == 0:
        return 0.0
    return (s2 / n2 - s1 / n1) / math.sqrt(var)


def permutation_p_value(a: Sequence[float], b: Sequence[float], *, permutations: int = 20000,
                        seed: int = 0) -> float:
    """Two-sided permutation test on the difference of means of two samples of task scores.

    Tasks are the sampling units: under the null hypothesis both forms draw tasks from one population, so
    shuffling the form labels gives the difference that task sampling alone explains.
    """
    x = np.asarray(list(a) + list(b), dtype=float)
    n = len(a)
    if n == 0 or len(b) == 0:
        return 1.0
    observed = abs(x[:n].mean() - x[n:].mean())
    rng = np.random.default_rng(seed)
    hits = 0
    done = 0
    while done < permutations:
        k = min(2000, permutations - done)
        idx = np.argsort(rng.random((k, len(x))), axis=1)
        perm = x[idx]
        diff = np.abs(perm[:, :n].mean(axis=1) - perm[:, n:].mean(axis=1))
        hits += int((diff >= observed - 1e-12).sum())
        done += k
    return (hits + 1) / (permutations + 1)



def detectable_difference(a: Sequence[float], b: Sequence[float], alpha: float = 0.01,
                          power: float = 0.8) -> float:
    """The difference of means the two-sided test at ``alpha`` finds with probability ``power``, for samples the
    size and spread of ``a`` and ``b`` (normal approximation: (z_{1-alpha/2} + z_power) * standard error)."""
    from statistics import NormalDist

    z = NormalDist().inv_cdf(1 - alpha / 2) + NormalDist().inv_cdf(power)
    var = sum(float(np.var(x, ddof=1)) / len(x) if len(x) > 1 else 0.25 / max(len(x), 1) for x in (a, b))
    return z * math.sqrt(var)

