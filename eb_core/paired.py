"""``eb report A B --paired``: is B's difference to A real? Per subset and overall, on the tasks both runs played,
with one method per row so that its interval and its test always agree (:func:`eb_core.stats.paired_comparison`)."""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

from eb_core.report import _emit, _has_results, _pct, load_run, rich_text

__all__ = ["overlap_note", "paired_rows", "render_paired"]


def paired_rows(run_a: dict[str, Any], run_b: dict[str, Any]) -> list[dict[str, Any]]:
    """Per subset and overall: success and subgoal rates of A and B, the difference B - A with its 95 %
    interval and the paired test. Raises ``ValueError`` (one line) when the task sets differ."""
    from eb_core.metrics import INTERVAL_METRICS, outcomes
    from eb_core.stats import outcome_matrix, paired_comparison

    recs_a, recs_b = run_a["records"], run_b["records"]
    ids_b_set = {r.task_id for r in recs_b}
    ids_a = [t for t in dict.fromkeys(r.task_id for r in recs_a) if t in ids_b_set]  # the shared tasks
    if not ids_a:
        raise ValueError(f"cannot pair {run_a['dir']} with {run_b['dir']}: they share no task (A has "
                         f"{len({r.task_id for r in recs_a})}, B {len(ids_b_set)}); pair runs of the same env "
                         f"and overlapping selections (subset=, limit=, tasks=)")
    subset_of = {r.task_id: r.subset for r in recs_a}
    subsets = list(dict.fromkeys(subset_of[t] for t in ids_a))
    out = []
    for group in [*subsets, "all"]:
        ids = [t for t in ids_a if group == "all" or subset_of[t] == group]
        for metric in ("success_rate", "subgoal_success"):
            score, binary = INTERVAL_METRICS[metric]
            oa = outcomes([r for r in recs_a if r.task_id in set(ids)], score)
            ob = outcomes([r for r in recs_b if r.task_id in set(ids)], score)
            common = [t for t in ids if t in oa and t in ob]  # measured in both
            _, ma = outcome_matrix({t: oa[t] for t in common})
            _, mb = outcome_matrix({t: ob[t] for t in common})
            res = paired_comparison(ma, mb, binary=binary)
            out.append({"subset": group, "metric": metric, **res})
    return out


def overlap_note(run_a: dict[str, Any], run_b: dict[str, Any]) -> str:
    """One sentence when the two runs' task sets differ: how many tasks are compared and how many are left out."""
    ids_a = {r.task_id for r in run_a["records"]}
    ids_b = {r.task_id for r in run_b["records"]}
    if ids_a == ids_b:
        return ""
    return (f"Compared on the {len(ids_a & ids_b)} tasks both runs played ({len(ids_a - ids_b)} only in A, "
            f"{len(ids_b - ids_a)} only in B, left out).")


def render_paired(dirs: list[str], fmt: str = "rich", out: str | None = None) -> str:
    """``eb report A B --paired``: is the difference between two runs on the same tasks real?"""
    from eb_core.exceptions import CliError

    if len(dirs) != 2:
        raise CliError(f"--paired compares exactly two run directories (got {len(dirs)}): eb report A B --paired")
    for d in dirs:
        if not _has_results(Path(d)):
            raise CliError(f"{d} is not a run directory with results (no finished episode in episodes.jsonl)")
    run_a, run_b = load_run(dirs[0]), load_run(dirs[1])
    try:
        rows = paired_rows(run_a, run_b)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    shared = overlap_note(run_a, run_b)
    header = ["subset", "metric", "tasks", "A %", "B %", "B - A [95% CI]", "test", "p", "verdict"]
    table: list[list[str]] = []
    for r in rows:
        if r["diff"] is None:
            table.append([r["subset"], r["metric"], "0", "-", "-", "-", "-", "-", "no measured tasks"])
            continue
        diff = f"{100 * r['diff']:+.1f} [{100 * r['ci_low']:+.1f}, {100 * r['ci_high']:+.1f}]"
        verdict = "significant" if r["significant"] else "n.s. (not significant)"
        from eb_core.stats import BOOTSTRAP_SAMPLES

        p = r["p_value"]
        p_text = f"<{1 / BOOTSTRAP_SAMPLES:.4f}" if r["test"] == "paired-bootstrap" and p == 0 else f"{p:.3g}"
        table.append([r["subset"], r["metric"], str(r["tasks"]), _pct(r["a"]), _pct(r["b"]), diff, r["test"],
                      p_text, verdict])
    title = (f"Paired comparison on {run_a['env']}: A = {run_a['model']} / {run_a['ablation']} "
             f"({run_a['repeats']} repeat(s)), B = {run_b['model']} / {run_b['ablation']} ({run_b['repeats']} "
             f"repeat(s))")
    note = ((shared + " " if shared else "")
            + "p < 0.05 is marked significant. One method per row, so the interval holds 0 exactly when the row is "
            "not significant: mcnemar-exact (binary success, one repeat each) is McNemar's exact test with its "
            "exact interval; paired-bootstrap (subgoal rates, or repeats) is a paired bootstrap over tasks for both.")
    if fmt == "csv":
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["subset", "metric", "tasks", "a", "b", "diff", "ci_low", "ci_high", "test", "p_value",
                    "significant"])
        for r in rows:
            w.writerow([r["subset"], r["metric"], r["tasks"], r["a"], r["b"], r["diff"], r["ci_low"], r["ci_high"],
                        r["test"], r["p_value"], r["significant"]])
        text = buf.getvalue()
    elif fmt == "markdown":
        md = [f"**{title}**", "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        md += ["| " + " | ".join(row) + " |" for row in table]
        text = "\n".join(md) + "\n\n" + note + "\n"
    else:
        text = rich_text(title, header, table, ("subset", "metric", "test", "verdict"), width=200,
                         colour=out is None) + "\n" + note + "\n"
    _emit(text, out)
    return text
