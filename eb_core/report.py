"""Paper-style result tables (per-subset success with 95 % intervals, average) as rich, Markdown or CSV,
and the paired comparison of two runs on the same tasks (``eb report A B --paired``)."""

from __future__ import annotations

import csv
import io
import json
import sys
from pathlib import Path
from typing import Any

__all__ = ["load_run", "print_summary", "render_paired", "render_report"]


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100.0 * x:.1f}"


def _with_ci(block: dict[str, Any], key: str) -> str:
    """``"45.0 [39.5, 50.6]"``: the rate and its 95 % interval, in percent."""
    from eb_core.stats import describe_interval

    return describe_interval(block, key)


def _sd(block: dict[str, Any], key: str = "success_rate") -> str:
    sd = (block.get(f"{key}_ci") or {}).get("repeat_sd")
    return "-" if sd is None else f"{100 * sd:.1f}"


def print_summary(summary: dict[str, Any], run_dir: str) -> None:
    """The end-of-run table: per-subset success and subgoal rates with 95 % intervals, then where the files are."""
    from rich.console import Console
    from rich.table import Table

    console = Console(stderr=False, width=max(150, Console().width))
    o = summary["overall"]
    repeats = int(summary.get("repeats", 1))
    t = Table(title=f"{summary['env']} / {summary['model']} / ablation {summary['ablation']}"
                    + (f" / {repeats} repeats" if repeats > 1 else ""))
    cols = ["subset", "episodes", "success % [95% CI]", "subgoal % [95% CI]", "subgoal % (paper rule)"]
    if repeats > 1:
        cols.append("repeat sd")
    cols += ["planner steps", "env steps"]
    for col in cols:
        if col == "subset":
            t.add_column(col, justify="left", no_wrap=True, min_width=max(6, *(len(n) for n in summary["subsets"])))
        else:
            t.add_column(col, justify="right")

    def row(name: str, s: dict[str, Any], bold: bool = False) -> list[str]:
        cells = [name, f"{s['episodes']:.0f}", _with_ci(s, "success_rate"), _with_ci(s, "subgoal_success"),
                 _pct(s.get("subgoal_success_paper"))]
        if repeats > 1:
            cells.append(_sd(s))
        cells += [f"{s.get('avg_planner_steps', 0):.1f}", f"{s.get('avg_env_steps', 0):.1f}"]
        if bold:
            cells = [f"[bold]{c}[/bold]" if i in (0, 2) else c for i, c in enumerate(cells)]
        return cells

    for name, s in summary["subsets"].items():
        t.add_row(*row(name, s))
    t.add_row(*row("all", o, bold=True))
    console.print(t)
    pre = summary.get("preflight") or {}
    total_cost = summary.get("total_cost_usd", o.get("cost_usd", 0))
    extra = (f"errors: {o.get('error_episodes', 0):.0f} episodes | output-error rate "
             f"{_pct(o.get('output_error_rate'))}% | tokens {o.get('prompt_tokens', 0):.0f}+"
             f"{o.get('completion_tokens', 0):.0f} | cost ${total_cost:.4f}"
             + (f" (preflight ${pre.get('cost_usd', 0):.4f})" if pre.get("calls") else ""))
    console.print(extra)
    method = (o.get("success_rate_ci") or {}).get("ci_method")
    if method:
        console.print(f"[dim]95% intervals over tasks ({method}"
                      + (", each task's repeats kept together" if repeats > 1 else "")
                      + "); see docs/statistics.md[/dim]")
    if summary.get("stopped_early"):
        console.print(f"[yellow]stopped early: {summary['stopped_early']}; re-run the same command to resume[/yellow]")
    # A plain line that scripts (and CI logs) can grep.
    ci = o.get("success_rate_ci") or {}
    ci_text = (f", 95% CI [{_pct(ci['ci_low'])}, {_pct(ci['ci_high'])}]" if ci.get("ci_low") is not None else "")
    total = summary.get("n_episodes", summary["n_selected"])
    print(f"success rate: {_pct(o.get('success_rate'))}% ({summary['n_finished']}/{total} episodes){ci_text} "
          f"-> {run_dir}/summary.json", flush=True)


def _run_config(root: Path) -> dict[str, Any]:
    path = root / "config.yaml"
    if not path.exists():
        return {}
    import yaml

    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except yaml.YAMLError:
        return {}
    return data if isinstance(data, dict) else {}


def load_records(run_dir: str | Path) -> list[Any]:
    """Episode records of a run directory, subset names mapped through the env's ``subset_aliases``."""
    from eb_core.records import RunFiles

    root = Path(run_dir)
    if not (root / "episodes.jsonl").exists():
        raise FileNotFoundError(f"{root} is not a run directory (no episodes.jsonl)")
    records = RunFiles(root).load_episodes()
    aliases = ((_run_config(root).get("env") or {}).get("subset_aliases") or {})
    if aliases:
        records = [r.model_copy(update={"subset": aliases.get(r.subset, r.subset)}) for r in records]
    return records


def load_run(run_dir: str | Path) -> dict[str, Any]:
    """Summary of a run directory, recomputed from ``episodes.jsonl`` with the built-in metrics.

    Works on a run that was stopped before its end (no ``summary.json``): names come from ``config.yaml``
    and ``complete`` is False.
    """
    from eb_core.metrics import compute_summary, errors, steps, subgoal_success, success_rate, usage

    root = Path(run_dir)
    records = load_records(root)
    meta: dict[str, Any] = {}
    if (root / "summary.json").exists():
        meta = json.loads((root / "summary.json").read_text())
    conf = _run_config(root)
    aliases = ((conf.get("env") or {}).get("subset_aliases") or {})
    fns = {"success_rate": success_rate, "subgoal_success": subgoal_success, "steps": steps, "errors": errors,
           "usage": usage}
    subsets = list(dict.fromkeys(aliases.get(s, s) for s in meta.get("subsets", {})))
    subsets += [s for s in dict.fromkeys(r.subset for r in records) if s not in subsets]  # in the run's order
    summary = compute_summary(records, fns, subsets)

    def name(key: str) -> str:
        value = meta.get(key) or (conf.get(key) or {}).get("name")
        return str(value) if value else "(unknown)"

    repeats = int(meta.get("repeats") or (conf.get("runner") or {}).get("repeats") or 1)
    return {"dir": str(root), "env": name("env"), "model": name("model"), "ablation": name("ablation"),
            "repeats": repeats, "complete": bool(meta.get("complete", False)), "has_summary": bool(meta),
            "records": records, **summary}


def _subset_names(runs: list[dict[str, Any]]) -> list[str]:
    names: list[str] = []
    for r in runs:
        names += [s for s in r["subsets"] if s not in names]
    return names


def render_report(dirs: list[str], fmt: str = "rich", out: str | None = None) -> str:
    from eb_core.cli import CliError

    runs = []
    for d in dirs:
        try:
            runs.append(load_run(d))
        except FileNotFoundError as exc:
            raise CliError(str(exc)) from None
    by_env: dict[str, list[dict[str, Any]]] = {}
    for r in runs:
        by_env.setdefault(r["env"], []).append(r)
    rows_out: list[list[str]] = []
    text_parts: list[str] = []
    for env, env_runs in by_env.items():
        subsets = _subset_names(env_runs)
        tables: list[tuple[str, list[str], list[list[str]]]] = []
        for title, key in (("Success rate (%)", "success_rate"), ("Subgoal success (%)", "subgoal_success"),
                           ("Subgoal success, the original's rule (%)", "subgoal_success_paper")):
            header = ["env", "model", "ablation"]
            if key == "success_rate":
                header.append("avg")
            header += ["all [95% CI]", *subsets, "repeats", "sd between repeats", "episodes"]
            rows = []
            for r in env_runs:
                o = r["overall"]
                row = [env, r["model"], r["ablation"] + ("" if r["complete"] else " (incomplete)")]
                if key == "success_rate":
                    row.append(_pct(o["avg_subset_success_rate"]))
                row += [_with_ci(o, key), *[_with_ci(r["subsets"][s], key) if s in r["subsets"] else "-"
                                            for s in subsets],
                        str(r["repeats"]), _sd(o, key), f"{o['episodes']:.0f}"]
                rows.append(row)
            tables.append((f"{title} — {env}", header, rows))
        if fmt == "csv":
            header = ["env", "model", "ablation", "avg", "repeats", "episodes", "complete"]
            for key, short in (("success_rate", "success"), ("subgoal_success", "subgoal"),
                               ("subgoal_success_paper", "subgoal_paper")):
                for s in ["all", *subsets]:
                    header += [f"{short}:{s}", f"{short}:{s}:ci_low", f"{short}:{s}:ci_high"]
                header.append(f"{short}:repeat_sd")
            if not rows_out or rows_out[0] != header:
                rows_out.append(header)
            for r in env_runs:
                o = r["overall"]
                row = [env, r["model"], r["ablation"], _pct(o["avg_subset_success_rate"]), str(r["repeats"]),
                       f"{o['episodes']:.0f}", str(r["complete"]).lower()]
                for key in ("success_rate", "subgoal_success", "subgoal_success_paper"):
                    for s in ["all", *subsets]:
                        block = o if s == "all" else r["subsets"].get(s)
                        ci = (block or {}).get(f"{key}_ci") or {}
                        row += [_pct(block.get(key)) if block else "", _pct(ci.get("ci_low")),
                                _pct(ci.get("ci_high"))]
                    sd = (o.get(f"{key}_ci") or {}).get("repeat_sd")
                    row.append("" if sd is None else f"{100 * sd:.2f}")
                rows_out.append(row)
        elif fmt == "markdown":
            for title, header, rows in tables:
                md = [f"**{title}**", "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
                md += ["| " + " | ".join(row) + " |" for row in rows]
                text_parts.append("\n".join(md))
        else:
            from rich.console import Console
            from rich.table import Table

            for title, header, rows in tables:
                t = Table(title=title)
                for col in header:
                    t.add_column(col, justify="left" if col in ("env", "model", "ablation") else "right")
                for row in rows:
                    t.add_row(*row)
                buf = io.StringIO()
                Console(file=buf, width=200, force_terminal=out is None and sys.stdout.isatty()).print(t)
                text_parts.append(buf.getvalue().rstrip("\n"))
    if fmt == "csv":
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(rows_out)
        text = buf.getvalue()
    else:
        text_parts.append("Intervals: 95 %, over tasks (Wilson for a success rate with one repeat, else a cluster "
                          "bootstrap keeping each task's repeats together); see docs/statistics.md.")
        text = "\n\n".join(text_parts) + "\n"
    _emit(text, out)
    return text


def _emit(text: str, out: str | None) -> None:
    if out:
        Path(out).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)


# -- paired comparison -----------------------------------------------------------------------------


def paired_rows(run_a: dict[str, Any], run_b: dict[str, Any]) -> list[dict[str, Any]]:
    """Per subset and overall: success and subgoal rates of A and B, the difference B - A with its 95 %
    interval and the paired test. Raises ``ValueError`` (one line) when the task sets differ."""
    from eb_core.metrics import INTERVAL_METRICS, outcomes
    from eb_core.stats import outcome_matrix, paired_comparison

    recs_a, recs_b = run_a["records"], run_b["records"]
    ids_a = list(dict.fromkeys(r.task_id for r in recs_a))
    ids_b = list(dict.fromkeys(r.task_id for r in recs_b))
    only_a = [t for t in ids_a if t not in set(ids_b)]
    only_b = [t for t in ids_b if t not in set(ids_a)]
    if only_a or only_b:
        parts = []
        if only_a:
            parts.append(f"only in A ({len(only_a)}): {', '.join(only_a[:4])}" + (", ..." if len(only_a) > 4 else ""))
        if only_b:
            parts.append(f"only in B ({len(only_b)}): {', '.join(only_b[:4])}" + (", ..." if len(only_b) > 4 else ""))
        raise ValueError(f"cannot pair {run_a['dir']} with {run_b['dir']}: their task sets differ "
                         f"({'; '.join(parts)}); pair runs of the same tasks (same env, subset=, limit=, tasks=)")
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


def render_paired(dirs: list[str], fmt: str = "rich", out: str | None = None) -> str:
    """``eb report A B --paired``: is the difference between two runs on the same tasks real?"""
    from eb_core.cli import CliError

    if len(dirs) != 2:
        raise CliError(f"--paired compares exactly two run directories (got {len(dirs)}): eb report A B --paired")
    try:
        run_a, run_b = load_run(dirs[0]), load_run(dirs[1])
    except FileNotFoundError as exc:
        raise CliError(str(exc)) from None
    try:
        rows = paired_rows(run_a, run_b)
    except ValueError as exc:
        raise CliError(str(exc)) from None
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
    note = ("p < 0.05 is marked significant. Test: McNemar's exact test on per-task outcomes when both runs have "
            "one repeat, else a paired bootstrap over tasks; the interval is always a paired bootstrap over tasks.")
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
        from rich.console import Console
        from rich.table import Table

        t = Table(title=title)
        for col in header:
            t.add_column(col, justify="left" if col in ("subset", "metric", "test", "verdict") else "right")
        for row in table:
            t.add_row(*row)
        buf = io.StringIO()
        Console(file=buf, width=200, force_terminal=out is None and sys.stdout.isatty()).print(t)
        text = buf.getvalue().rstrip("\n") + "\n" + note + "\n"
    _emit(text, out)
    return text
