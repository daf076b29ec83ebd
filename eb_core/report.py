"""Paper-style result tables (per-subset success with 95 % intervals, average, ablation deltas, the automatic
error breakdown) as rich, Markdown, CSV, LaTeX or HTML, plots (``--plot``, :mod:`eb_core.report_plot`) and the
paired comparison of two runs on the same tasks (``eb report A B --paired``)."""

from __future__ import annotations

import csv
import io
import json
import sys
from pathlib import Path
from typing import Any

__all__ = ["FORMATS", "load_run", "print_summary", "relabel", "render_report", "runs_with_results"]


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
    ea = o.get("error_analysis") or {}
    if ea.get("labels"):
        from eb_core.errors import CATEGORIES

        top = sorted(((v["episode_rate"], k) for k, v in ea["categories"].items() if v["count"]), reverse=True)[:5]
        console.print("error labels (% of episodes): " + ", ".join(f"{CATEGORIES[k].title} {100 * r:.0f}"
                                                                  for r, k in top)
                      + " [dim](docs/error_analysis.md)[/dim]")
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
    print(f"success rate: {_pct(o.get('success_rate'))}% ({_count_text(summary)}){ci_text} "
          f"-> {run_dir}/summary.json", flush=True)


def _count_text(summary: dict[str, Any]) -> str:
    """``7 of 10 episodes succeeded`` (+ how many did not finish, + a partial mark) for the summary line."""
    o = summary["overall"]
    total = int(summary.get("n_episodes", summary["n_selected"]))
    finished = int(summary["n_finished"])
    succeeded = round(float(o.get("success_rate") or 0.0) * finished)
    text = f"{succeeded} of {finished} episodes succeeded"
    if finished < total:
        text += f"; {total - finished} of {total} not finished"
    if summary.get("partial"):
        text += f"; partial: {summary['n_selected']} of {summary.get('n_tasks_total', '?')} tasks"
    return text


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


def relabel(records: list[Any], root: Path, force: bool = False) -> list[Any]:
    """Episode records with automatic error labels: those written by the runner are kept, the others (old runs)
    are labelled from the step files; ``force`` relabels every episode (``eb report --errors``)."""
    from eb_core.errors import label_episode, load_steps, run_vocabulary
    from eb_core.records import episode_dir_name

    todo = [r for r in records if r.status == "ok" and (force or r.error_counts is None)]
    if not todo:
        return records
    steps = {r.key: load_steps(root / "episodes" / episode_dir_name(*r.key)) for r in records if r.status == "ok"}
    if force:  # `eb report --errors`: what was in view is recomputed by replaying the actions in the world
        from eb_core.errors.replay import replay_run

        steps = replay_run(root, records, steps)
    vocab = run_vocabulary(steps.values())
    out = []
    for r in records:
        if r in todo and steps.get(r.key):
            lab = label_episode(steps[r.key], r.model_dump(), vocab)
            r = r.model_copy(update={"error_counts": lab["counts"], "perception_score": lab["perception_score"]})
        out.append(r)
    return out


def load_run(run_dir: str | Path, relabel_errors: bool = False) -> dict[str, Any]:
    """Summary of a run directory, recomputed from ``episodes.jsonl`` with the built-in metrics.

    Works on a run that was stopped before its end (no ``summary.json``): names come from ``config.yaml``
    and ``complete`` is False. Episodes without error labels (runs older than the labeller) are labelled from
    their step files; ``relabel_errors`` relabels all of them.
    """
    from eb_core.metrics import Metric, compute_summary, errors, steps, subgoal_success, success_rate, usage

    root = Path(run_dir)
    records = relabel(load_records(root), root, force=relabel_errors)
    meta: dict[str, Any] = {}
    if (root / "summary.json").exists():
        meta = json.loads((root / "summary.json").read_text())
    conf = _run_config(root)
    aliases = ((conf.get("env") or {}).get("subset_aliases") or {})
    fns: dict[str, Metric] = {"success_rate": success_rate, "subgoal_success": subgoal_success, "steps": steps,
                              "errors": errors, "usage": usage}
    subsets = list(dict.fromkeys(aliases.get(s, s) for s in meta.get("subsets", {})))
    subsets += [s for s in dict.fromkeys(r.subset for r in records) if s not in subsets]  # in the run's order
    summary = compute_summary(records, fns, subsets)

    def name(key: str) -> str:
        value = meta.get(key) or (conf.get(key) or {}).get("name")
        return str(value) if value else "(unknown)"

    repeats = int(meta.get("repeats") or (conf.get("runner") or {}).get("repeats") or 1)
    return {"dir": str(root), "env": name("env"), "model": name("model"), "ablation": name("ablation"),
            "repeats": repeats, "complete": bool(meta.get("complete", False)), "has_summary": bool(meta),
            "records": records, "config": conf, "meta": meta, **summary}


def _has_results(root: Path) -> bool:
    path = root / "episodes.jsonl"
    return path.exists() and path.stat().st_size > 0


def runs_with_results(dirs: list[str]) -> list[str]:
    """The run directories of ``dirs`` that hold finished episodes. Folders with none (a run that failed or was
    stopped before its first episode) are skipped with one note on stderr, so a glob such as
    ``runs/*/*/*/default`` keeps working; a path that does not exist, or no run with results at all, is an error."""
    from eb_core.exceptions import CliError

    kept: list[str] = []
    skipped: list[str] = []
    for d in dirs:
        root = Path(d)
        if not root.is_dir():
            raise CliError(f"{d} is not a run directory (no episodes.jsonl)")
        (kept if _has_results(root) else skipped).append(d)
    if not kept:
        raise CliError(f"{dirs[0]} is not a run directory (no episodes.jsonl)" if len(dirs) == 1 else
                       f"none of the {len(dirs)} folders holds a finished episode (no episodes.jsonl); run "
                       f"`eb run ...` first")
    if skipped:
        more = f" and {len(skipped) - 3} more" if len(skipped) > 3 else ""
        print(f"eb report: note: skipped {len(skipped)} folder(s) with no finished episodes: "
              f"{', '.join(skipped[:3])}{more}", file=sys.stderr)
    return kept


def _partial_mark(r: dict[str, Any]) -> str:
    """`` (partial: 20 of 300 tasks)`` for a run whose selection (subset=, limit=, tasks=) is not the whole set."""
    meta = r.get("meta") or {}
    if not meta.get("partial"):
        return ""
    return f" (partial: {meta.get('n_selected', '?')} of {meta.get('n_tasks_total', '?')} tasks)"


def _subset_names(runs: list[dict[str, Any]]) -> list[str]:
    names: list[str] = []
    for r in runs:
        names += [s for s in r["subsets"] if s not in names]
    return names


FORMATS = ("rich", "markdown", "csv", "latex", "html")

Table = tuple[str, list[str], list[list[str]]]


def _error_tables(env: str, env_runs: list[dict[str, Any]], detailed: bool) -> list[Table]:
    """The error breakdown: per run, each category's share of episodes with it (and its count), the paper's
    three groups and the perception score; ``detailed`` adds one table per subset."""
    from eb_core.errors import CATEGORIES

    analysed = [r for r in env_runs if r["overall"].get("error_analysis")]
    if not analysed:
        return []
    used = [k for k in CATEGORIES if any(r["overall"]["error_analysis"]["categories"][k]["count"] for r in analysed)]
    used = used or list(CATEGORIES)[:3]
    tables: list[Table] = []
    groups = ["perception", "reasoning", "planning"]
    blocks: list[tuple[str, str | None]] = [("all subsets", None)]
    if detailed:
        blocks += [(f"subset {s}", s) for s in _subset_names(analysed)]
    for label, subset in blocks:
        header = ["env", "model", "ablation", "episodes", "labels", *[CATEGORIES[k].title for k in used],
                  *[f"{g} share" for g in groups], "perception score"]
        rows = []
        for r in analysed:
            block = r["overall"] if subset is None else r["subsets"].get(subset) or {}
            ea = block.get("error_analysis")
            if not ea:
                continue
            cats = ea["categories"]
            ps = ea.get("perception_score")
            rows.append([env, r["model"], r["ablation"], f"{ea['episodes']:.0f}", f"{ea['labels']:.0f}",
                         *[f"{_pct(cats[k]['episode_rate'])} ({cats[k]['count']:.0f})" for k in used],
                         *[_pct(ea["group_share"].get(g, 0.0)) for g in groups],
                         "-" if ps is None else f"{ps:.2f}"])
        tables.append((f"Automatic error analysis, {label} — {env}: % of episodes with the error (count); "
                       f"group share = % of all labels", header, rows))
    return tables


def _ablation_tables(env: str, env_runs: list[dict[str, Any]]) -> list[Table]:
    """Ablation deltas (the paper's figures): per model, each ablation's success minus the baseline's (the
    run with ablation ``none``, else the first run of that model), per subset, in points."""
    by_model: dict[str, list[dict[str, Any]]] = {}
    for r in env_runs:
        by_model.setdefault(r["model"], []).append(r)
    tables: list[Table] = []
    for model, runs in by_model.items():
        if len({r["ablation"] for r in runs}) < 2:
            continue
        base = next((r for r in runs if r["ablation"] == "none"), runs[0])
        subsets = _subset_names(runs)
        header = ["env", "model", "ablation", "vs", "all", *subsets]
        rows = []
        for r in runs:
            if r is base:
                continue

            def delta(block_a: dict[str, Any] | None, block_b: dict[str, Any] | None) -> str:
                if not block_a or not block_b or not block_a.get("episodes") or not block_b.get("episodes"):
                    return "-"
                return f"{100 * (block_a['success_rate'] - block_b['success_rate']):+.1f}"

            rows.append([env, model, r["ablation"], base["ablation"], delta(r["overall"], base["overall"]),
                         *[delta(r["subsets"].get(s), base["subsets"].get(s)) for s in subsets]])
        tables.append((f"Ablation deltas — {env} / {model}: success rate minus the {base['ablation']!r} run "
                       f"(points)", header, rows))
    return tables


def _latex_escape(text: str) -> str:
    repl = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
            "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
            "\u2014": "---", "\u2013": "--", "\u2212": "-"}
    return "".join(repl.get(ch, ch) for ch in str(text))


def _render_tables(tables: list[Table], fmt: str, out: str | None, note: str) -> str:
    import html as _html

    parts: list[str] = []
    for title, header, rows in tables:
        if fmt == "markdown":
            md = [f"**{title}**", "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
            md += ["| " + " | ".join(row) + " |" for row in rows]
            parts.append("\n".join(md))
        elif fmt == "latex":
            cols = "l" * 3 + "r" * (len(header) - 3)
            tex = [f"% {_latex_escape(title)}", "\\begin{table}[t]", "\\centering", "\\small",
                   f"\\caption{{{_latex_escape(title)}}}", f"\\begin{{tabular}}{{{cols}}}", "\\toprule",
                   " & ".join(_latex_escape(h) for h in header) + " \\\\", "\\midrule"]
            tex += [" & ".join(_latex_escape(c) for c in row) + " \\\\" for row in rows]
            tex += ["\\bottomrule", "\\end{tabular}", "\\end{table}"]
            parts.append("\n".join(tex))
        elif fmt == "html":
            e = _html.escape
            head = "".join(f"<th>{e(h)}</th>" for h in header)
            body = "".join("<tr>" + "".join(f"<td>{e(c)}</td>" for c in row) + "</tr>" for row in rows)
            parts.append(f"<h2>{e(title)}</h2><table><tr>{head}</tr>{body}</table>")
        else:
            parts.append(rich_text(title, header, rows, ("env", "model", "ablation", "vs"), width=220,
                                   colour=out is None))
    if fmt == "latex":
        return ("% needs \\usepackage{booktabs}\n" + "\n\n".join(parts) + f"\n% {_latex_escape(note)}\n")
    if fmt == "html":
        css = ("body{font-family:system-ui,sans-serif;margin:24px}table{border-collapse:collapse;font-size:13px;"
               "margin-bottom:12px}th,td{border:1px solid #dde1e6;padding:4px 8px;text-align:right}"
               "th{background:#eef1f4}td:nth-child(-n+3){text-align:left}")
        return (f"<!doctype html><html lang=en><head><meta charset=utf-8><title>eb report</title><style>{css}"
                f"</style></head><body>{''.join(parts)}<p>{_html.escape(note)}</p></body></html>\n")
    return "\n\n".join([*parts, note]) + "\n"


def render_report(dirs: list[str], fmt: str = "rich", out: str | None = None, plot: str | None = None,
                  errors: bool = False) -> str:
    """``eb report``: runs side by side (models x subsets, like the paper's tables), ablation deltas and the
    automatic error breakdown, in ``fmt``; ``plot`` also draws them to an image; ``errors`` relabels every
    episode from its step files and adds the per-subset error tables."""

    runs = [load_run(d, relabel_errors=errors) for d in runs_with_results(dirs)]
    by_env: dict[str, list[dict[str, Any]]] = {}
    for r in runs:
        by_env.setdefault(r["env"], []).append(r)
    rows_out: list[list[str]] = []
    tables: list[Table] = []
    for env, env_runs in by_env.items():
        subsets = _subset_names(env_runs)
        tables += _rate_tables(env, env_runs, subsets)
        tables += _ablation_tables(env, env_runs)
        tables += _error_tables(env, env_runs, detailed=errors)
        if fmt == "csv":
            header = _csv_header(subsets)
            if not rows_out or rows_out[0] != header:
                rows_out.append(header)
            rows_out += [_csv_row(env, r, subsets) for r in env_runs]
    if fmt == "csv":
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(rows_out)
        text = buf.getvalue()
    else:
        partial = [r for r in runs if r["meta"].get("partial")]
        note = (("Partial runs (marked in the episodes column) cover less than their world's task set (subset=, "
                 "limit=, tasks=): their averages are not the benchmark's. " if partial else "")
                + "Intervals: 95 %, over tasks (Wilson for a success rate with one repeat, else a cluster "
                "bootstrap keeping each task's repeats together); see docs/statistics.md. Error labels are "
                "computed from the run's records; see docs/error_analysis.md.")
        text = _render_tables(tables, fmt, out, note)
    _emit(text, out)
    if plot:
        from eb_core.plot import plot_runs

        plot_runs(runs, plot)
    return text


_RATES = (("Success rate (%)", "success_rate", "success"), ("Subgoal success (%)", "subgoal_success", "subgoal"),
          ("Subgoal success, the original's rule (%)", "subgoal_success_paper", "subgoal_paper"))


def _rate_tables(env: str, env_runs: list[dict[str, Any]], subsets: list[str]) -> list[Table]:
    """The paper's tables: one per rate, a row per run, a column per subset, each with its interval."""
    tables: list[Table] = []
    for title, key, _short in _RATES:
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
                    str(r["repeats"]), _sd(o, key), f"{o['episodes']:.0f}" + _partial_mark(r)]
            rows.append(row)
        tables.append((f"{title} — {env}", header, rows))
    return tables


def _csv_header(subsets: list[str]) -> list[str]:
    from eb_core.errors import CATEGORIES

    header = ["env", "model", "ablation", "avg", "repeats", "episodes", "complete"]
    for _title, _key, short in _RATES:
        for s in ["all", *subsets]:
            header += [f"{short}:{s}", f"{short}:{s}:ci_low", f"{short}:{s}:ci_high"]
        header.append(f"{short}:repeat_sd")
    header += [f"errors:{k}" for k in CATEGORIES] + [f"errors:{k}:episode_rate" for k in CATEGORIES]
    return [*header, "perception_score", "partial", "tasks_total"]


def _csv_row(env: str, r: dict[str, Any], subsets: list[str]) -> list[str]:
    from eb_core.errors import CATEGORIES

    o = r["overall"]
    row = [env, r["model"], r["ablation"], _pct(o["avg_subset_success_rate"]), str(r["repeats"]),
           f"{o['episodes']:.0f}", str(r["complete"]).lower()]
    for _title, key, _short in _RATES:
        for s in ["all", *subsets]:
            block = o if s == "all" else r["subsets"].get(s)
            ci = (block or {}).get(f"{key}_ci") or {}
            row += [_pct(block.get(key)) if block else "", _pct(ci.get("ci_low")), _pct(ci.get("ci_high"))]
        sd = (o.get(f"{key}_ci") or {}).get("repeat_sd")
        row.append("" if sd is None else f"{100 * sd:.2f}")
    ea = o.get("error_analysis") or {}
    cats = ea.get("categories") or {}
    row += [f"{cats[k]['count']:.0f}" if k in cats else "" for k in CATEGORIES]
    row += [f"{100 * cats[k]['episode_rate']:.1f}" if k in cats else "" for k in CATEGORIES]
    ps = ea.get("perception_score")
    row.append("" if ps is None else f"{ps:.3f}")
    return [*row, str(bool(r["meta"].get("partial"))).lower(), str(r["meta"].get("n_tasks_total", ""))]


def rich_text(title: str, header: list[str], rows: list[list[str]], left: tuple[str, ...], width: int,
              colour: bool) -> str:
    """One table drawn by rich as text: the columns named in ``left`` flush left, the numbers right; terminal
    colours only when ``colour`` and standard output is a terminal."""
    from rich.console import Console
    from rich.table import Table as RichTable

    t = RichTable(title=title)
    for col in header:
        t.add_column(col, justify="left" if col in left else "right")
    for row in rows:
        t.add_row(*row)
    buf = io.StringIO()
    Console(file=buf, width=width, force_terminal=colour and sys.stdout.isatty()).print(t)
    return buf.getvalue().rstrip("\n")


def _emit(text: str, out: str | None) -> None:
    if out:
        Path(out).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
