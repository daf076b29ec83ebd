"""The paper's metrics. Each metric maps a list of episode records to named numbers.

Metrics are computed over measured episodes (status ``ok``); ``errors`` also counts the others.
:func:`compute_summary` adds a 95 % interval to every success and subgoal rate (``<metric>_ci``), computed
over tasks (and their repeats) by :mod:`eb_core.stats`, and the automatic error analysis
(``error_analysis``, :func:`error_analysis`) when the episodes carry error labels.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from eb_core import stats
from eb_core.records import EpisodeRecord

__all__ = ["INTERVAL_METRICS", "compute_summary", "error_analysis", "errors", "outcomes", "paper_progress", "steps",
           "subgoal_success", "success_rate", "usage"]

#: Per-episode scores that get an interval in every summary block: name -> (score of a record, binary?).
INTERVAL_METRICS: dict[str, tuple[Callable[[EpisodeRecord], float], bool]] = {}

Metric = Callable[[Sequence[EpisodeRecord]], dict[str, float]]


def _ok(eps: Sequence[EpisodeRecord]) -> list[EpisodeRecord]:
    return [e for e in eps if e.status == "ok"]


def _mean(values: list[float]) -> float:
    return sum(values) / len(values) if values else 0.0


def success_rate(eps: Sequence[EpisodeRecord]) -> dict[str, float]:
    ok = _ok(eps)
    return {"success_rate": _mean([1.0 if e.success else 0.0 for e in ok])}


def paper_progress(e: EpisodeRecord) -> float:
    """The subgoal score the original evaluators record: an episode that ends on an empty plan or at the
    invalid-action cap keeps a progress of 0 (their loop breaks before reading the env's progress)."""
    if e.success:
        return 1.0
    return 0.0 if e.end_reason in ("empty_plan", "invalid_cap") else e.progress


def subgoal_success(eps: Sequence[EpisodeRecord]) -> dict[str, float]:
    """Our subgoal rate (the progress an episode reached) and the paper-compatible one beside it."""
    ok = _ok(eps)
    return {"subgoal_success": _mean([e.progress for e in ok]),
            "subgoal_success_paper": _mean([paper_progress(e) for e in ok])}


INTERVAL_METRICS.update({
    "success_rate": (lambda e: 1.0 if e.success else 0.0, True),
    "subgoal_success": (lambda e: e.progress, False),
    "subgoal_success_paper": (paper_progress, False),
})


def outcomes(eps: Sequence[EpisodeRecord], score: Callable[[EpisodeRecord], float]) -> dict[str, dict[int, float]]:
    """``{task_id: {repeat: score}}`` of the measured episodes, tasks in first-seen order."""
    out: dict[str, dict[int, float]] = {}
    for e in _ok(eps):
        out.setdefault(e.task_id, {})[e.repeat] = score(e)
    return out


def steps(eps: Sequence[EpisodeRecord]) -> dict[str, float]:
    ok = _ok(eps)
    return {
        "avg_planner_steps": _mean([e.planner_steps for e in ok]),
        "avg_env_steps": _mean([e.env_steps for e in ok]),
    }


def errors(eps: Sequence[EpisodeRecord]) -> dict[str, float]:
    """Invalid actions per env step, output errors per planner step, empty plans and errored episodes.

    ``invalid_action_ratio`` counts what "invalid action" means everywhere (:data:`eb_core.errors.INVALID_LABELS`:
    actions the world refuses outright; not collisions, not unmet preconditions) when every measured episode
    carries error labels; on unlabelled records it falls back to the runner's counter, which is the original's
    invalid-action cap counter (every failed action and every unusable answer) and is kept as
    ``cap_counted_ratio``.
    """
    from eb_core.errors import invalid_count

    ok = _ok(eps)
    total_actions = sum(e.env_steps for e in ok)
    capped = sum(e.invalid_actions for e in ok)
    labelled = bool(ok) and all(e.error_counts is not None for e in ok)
    invalid = sum(invalid_count(e.error_counts) for e in ok) if labelled else capped
    return {
        "invalid_action_ratio": (invalid / total_actions) if total_actions else 0.0,
        "cap_counted_ratio": (capped / total_actions) if total_actions else 0.0,
        "output_error_rate": (sum(e.output_errors for e in ok) / max(1, sum(e.planner_steps for e in ok))),
        "empty_plan_rate": _mean([1.0 if e.empty_plan else 0.0 for e in ok]),
        "error_episodes": float(sum(1 for e in eps if e.status == "error")),
    }


def error_analysis(eps: Sequence[EpisodeRecord]) -> dict[str, object]:
    """Automatic error labels (:mod:`eb_core.errors`) of the measured, labelled episodes: per category the
    count, the rate per planner step and the share of episodes with at least one; per paper group (perception,
    reasoning, planning) its share of all labels; and the mean perception score. Empty when none is labelled."""
    from eb_core.errors import CATEGORIES

    labelled = [e for e in _ok(eps) if e.error_counts is not None]
    if not labelled:
        return {}
    planner_steps = max(1, sum(e.planner_steps for e in labelled))
    categories: dict[str, dict[str, float]] = {}
    for key in CATEGORIES:
        counts = [(e.error_counts or {}).get(key, 0) for e in labelled]
        categories[key] = {"count": float(sum(counts)), "per_step": sum(counts) / planner_steps,
                           "episode_rate": sum(1 for c in counts if c) / len(labelled)}
    total = sum(c["count"] for c in categories.values())
    groups: dict[str, float] = {}
    for key, cat in CATEGORIES.items():
        groups[cat.group] = groups.get(cat.group, 0.0) + categories[key]["count"]
    # runs that wrote no description (oracle, random, language_only) have no score: None, never 0
    scores = [e.perception_score for e in labelled if e.perception_score is not None]
    return {"episodes": float(len(labelled)), "labels": total, "categories": categories,
            "group_share": {g: (n / total if total else 0.0) for g, n in groups.items()},
            "perception_score": _mean(scores) if scores else None,
            "failed_episodes_with_label": _mean([1.0 if any((e.error_counts or {}).values()) else 0.0
                                                 for e in labelled if not e.success]) if any(
                not e.success for e in labelled) else None}


def usage(eps: Sequence[EpisodeRecord]) -> dict[str, float]:
    return {
        "prompt_tokens": float(sum(e.prompt_tokens for e in eps)),
        "completion_tokens": float(sum(e.completion_tokens for e in eps)),
        "model_calls": float(sum(e.model_calls for e in eps)),
        "cost_usd": round(sum(e.cost_usd for e in eps), 6),
        "model_latency_s": round(sum(e.model_latency_s for e in eps), 3),
        "wall_time_s": round(sum(e.wall_time_s for e in eps), 3),
    }


def compute_summary(eps: Sequence[EpisodeRecord], metrics: dict[str, Metric],
                    subsets: Sequence[str] | None = None) -> dict[str, object]:
    """``{"overall": {...}, "subsets": {name: {...}}}`` with ``episodes`` counts in each block."""

    def block(group: Sequence[EpisodeRecord]) -> dict[str, object]:
        out: dict[str, object] = {"episodes": float(len(_ok(group)))}
        for fn in metrics.values():
            out.update(fn(group))
        for name, (score, binary) in INTERVAL_METRICS.items():
            if name in out:
                _, m = stats.outcome_matrix(outcomes(group, score))
                out[f"{name}_ci"] = stats.rate_interval(m, binary)
        analysis = error_analysis(group)
        if analysis:
            out["error_analysis"] = analysis
        return out

    names = list(subsets) if subsets else sorted({e.subset for e in eps})
    per = {name: block([e for e in eps if e.subset == name]) for name in names}
    overall = block(eps)
    # The paper's "average" is the mean of per-subset success rates.
    measured = [float(rate) for v in per.values()
                if v["episodes"] and isinstance(rate := v.get("success_rate"), (int, float))]
    overall["avg_subset_success_rate"] = _mean(measured)
    return {"overall": overall, "subsets": per}
