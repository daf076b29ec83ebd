"""Paper-style result tables (per-subset success, average) as rich, Markdown or CSV."""

from __future__ import annotations

import csv
import io
import json
import sys
from pathlib import Path
from typing import Any

__all__ = ["load_run", "print_summary", "render_report"]


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100.0 * x:.1f}"


def print_summary(summary: dict[str, Any], run_dir: str) -> None:
    """The end-of-run table: per-subset success and the average, then where the files are."""
    from rich.console import Console
    from rich.table import Table

    console = Console(stderr=False, width=max(100, Console().width))
    o = summary["overall"]
    t = Table(title=f"{summary['env']} / {summary['model']} / ablation {summary['ablation']}")
    for col in ("subset", "episodes", "success %", "subgoal %", "planner steps", "env steps"):
        if col == "subset":
            t.add_column(col, justify="left", no_wrap=True, min_width=max(6, *(len(n) for n in summary["subsets"])))
        else:
            t.add_column(col, justify="right")
    for name, s in summary["subsets"].items():
        t.add_row(name, f"{s['episodes']:.0f}", _pct(s.get("success_rate")), _pct(s.get("subgoal_success")),
                  f"{s.get('avg_planner_steps', 0):.1f}", f"{s.get('avg_env_steps', 0):.1f}")
    t.add_row("[bold]all[/bold]", f"{o['episodes']:.0f}", f"[bold]{_pct(o.get('success_rate'))}[/bold]",
              _pct(o.get("subgoal_success")), f"{o.get('avg_planner_steps', 0):.1f}",
              f"{o.get('avg_env_steps', 0):.1f}")
    console.print(t)
    extra = (f"errors: {o.get('error_episodes', 0):.0f} episodes | output-error rate "
             f"{_pct(o.get('output_error_rate'))}% | tokens {o.get('prompt_tokens', 0):.0f}+"
             f"{o.get('completion_tokens', 0):.0f} | cost ${o.get('cost_usd', 0):.4f}")
    console.print(extra)
    if summary.get("stopped_early"):
        console.print(f"[yellow]stopped early: {summary['stopped_early']}; re-run the same command to resume[/yellow]")
    # A plain line that scripts (and CI logs) can grep.
    print(f"success rate: {_pct(o.get('success_rate'))}% ({summary['n_finished']}/{summary['n_selected']} episodes) "
          f"-> {run_dir}/summary.json", flush=True)


def load_run(run_dir: str | Path) -> dict[str, Any]:
    """Summary of a run directory, recomputed from ``episodes.jsonl`` with the built-in metrics."""
    from eb_core.metrics import compute_summary, errors, steps, subgoal_success, success_rate, usage
    from eb_core.records import RunFiles

    root = Path(run_dir)
    if not (root / "episodes.jsonl").exists():
        raise FileNotFoundError(f"{root} is not a run directory (no episodes.jsonl)")
    records = RunFiles(root).load_episodes()
    meta: dict[str, Any] = {}
    if (root / "summary.json").exists():
        meta = json.loads((root / "summary.json").read_text())
    fns = {"success_rate": success_rate, "subgoal_success": subgoal_success, "steps": steps, "errors": errors,
           "usage": usage}
    subsets = list(meta.get("subsets", {})) or None
    summary = compute_summary(records, fns, subsets)
    return {"dir": str(root), "env": meta.get("env", root.parts[-4] if len(root.parts) >= 4 else "?"),
            "model": meta.get("model", "?"), "ablation": meta.get("ablation", "?"), **summary}


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
        subsets: list[str] = []
        for r in env_runs:
            subsets += [s for s in r["subsets"] if s not in subsets]
        header = ["env", "model", "ablation", "avg", *subsets, "episodes"]
        rows = []
        for r in env_runs:
            rows.append([env, r["model"], r["ablation"], _pct(r["overall"]["avg_subset_success_rate"]),
                         *[_pct(r["subsets"][s]["success_rate"]) if s in r["subsets"] else "-" for s in subsets],
                         f"{r['overall']['episodes']:.0f}"])
        if fmt == "csv":
            if not rows_out:
                rows_out.append(header)
            elif rows_out[0] != header:
                rows_out.append(header)
            rows_out.extend(rows)
        elif fmt == "markdown":
            md = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
            md += ["| " + " | ".join(row) + " |" for row in rows]
            text_parts.append("\n".join(md))
        else:
            from rich.console import Console
            from rich.table import Table

            t = Table(title=f"Success rate (%) — {env}")
            for col in header:
                t.add_column(col, justify="left" if col in ("env", "model", "ablation") else "right")
            for row in rows:
                t.add_row(*row)
            buf = io.StringIO()
            Console(file=buf, width=160, force_terminal=out is None and sys.stdout.isatty()).print(t)
            text_parts.append(buf.getvalue().rstrip("\n"))
    if fmt == "csv":
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(rows_out)
        text = buf.getvalue()
    else:
        text = "\n\n".join(text_parts) + "\n"
    if out:
        Path(out).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return text
