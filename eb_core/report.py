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

__all__ = ["FORMATS", "load_run", "print_summary", "relabel", "render_paired", "render_report"]


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
            from rich.console import Console
            from rich.table import Table as RichTable

            t = RichTable(title=title)
            for col in header:
                t.add_column(col, justify="left" if col in ("env", "model", "ablation", "vs") else "right")
            for row in rows:
                t.add_row(*row)
            buf = io.StringIO()
            Console(file=buf, width=220, force_terminal=out is None and sys.stdout.isatty()).print(t)
            parts.append(buf.getvalue().rstrip("\n"))
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
    from eb_core.errors import CATEGORIES

    for env, env_runs in by_env.items():
        subsets = _subset_names(env_runs)
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
                        str(r["repeats"]), _sd(o, key), f"{o['episodes']:.0f}" + _partial_mark(r)]
                rows.append(row)
            tables.append((f"{title} — {env}", header, rows))
        tables += _ablation_tables(env, env_runs)
        tables += _error_tables(env, env_runs, detailed=errors)
        if fmt == "csv":
            header = ["env", "model", "ablation", "avg", "repeats", "episodes", "complete"]
            for _key, short in (("success_rate", "success"), ("subgoal_success", "subgoal"),
                               ("subgoal_success_paper", "subgoal_paper")):
                for s in ["all", *subsets]:
                    header += [f"{short}:{s}", f"{short}:{s}:ci_low", f"{short}:{s}:ci_high"]
                header.append(f"{short}:repeat_sd")
            header += [f"errors:{k}" for k in CATEGORIES] + [f"errors:{k}:episode_rate" for k in CATEGORIES]
            header += ["perception_score", "partial", "tasks_total"]
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
                ea = o.get("error_analysis") or {}
                cats = ea.get("categories") or {}
                row += [f"{cats[k]['count']:.0f}" if k in cats else "" for k in CATEGORIES]
                row += [f"{100 * cats[k]['episode_rate']:.1f}" if k in cats else "" for k in CATEGORIES]
                ps = ea.get("perception_score")
                row.append("" if ps is None else f"{ps:.3f}")
                row += [str(bool(r["meta"].get("partial"))).lower(), str(r["meta"].get("n_tasks_total", ""))]
                rows_out.append(row)
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
        plot_runs(runs, plot)
    return text


def plot_runs(runs: list[dict[str, Any]], path: str | Path) -> Path:
    """Draw the runs to ``path`` (.png or .svg): success per subset as grouped bars with the 95 % intervals as
    error bars, and, when the runs are labelled, the share of episodes with each error category.
    matplotlib is imported here only (Agg backend, no display)."""
    from eb_core.exceptions import CliError

    path = Path(path)
    if path.suffix.lower() not in (".png", ".svg"):
        raise CliError(f"--plot {path}: the file must end in .png or .svg (e.g. --plot report.png)")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise CliError("--plot needs matplotlib: pip install 'embodiedbench[report]' "
                       "(or pip install -r requirements.txt)") from None
    from eb_core.errors import CATEGORIES

    subsets = [*_subset_names(runs), "all"]
    labelled = [r for r in runs if r["overall"].get("error_analysis")]
    used = [k for k in CATEGORIES if any(r["overall"]["error_analysis"]["categories"][k]["count"] for r in labelled)]
    ncols = 2 if used else 1
    fig, axes = plt.subplots(1, ncols, figsize=(6.5 * ncols + 0.5, 5.0), squeeze=False,
                             gridspec_kw={"width_ratios": [1.3, 1][:ncols]})
    cmap: Any = plt.get_cmap("tab10")  # a ListedColormap: its .colors are the ten tab10 colours
    colours = cmap.colors
    names = [f"{r['model']} / {r['ablation']}" + ("" if len({x['env'] for x in runs}) == 1 else f" ({r['env']})")
             for r in runs]
    ax = axes[0][0]
    width = 0.8 / max(1, len(runs))
    for i, (r, name) in enumerate(zip(runs, names)):
        xs, ys, lo, hi = [], [], [], []
        for j, s in enumerate(subsets):
            block = r["overall"] if s == "all" else r["subsets"].get(s)
            if not block or not block.get("episodes"):
                continue
            value = 100 * float(block["success_rate"])
            ci = block.get("success_rate_ci") or {}
            xs.append(j - 0.4 + width * (i + 0.5))
            ys.append(value)
            lo.append(value - 100 * ci["ci_low"] if ci.get("ci_low") is not None else 0.0)
            hi.append(100 * ci["ci_high"] - value if ci.get("ci_high") is not None else 0.0)
        ax.bar(xs, ys, width=width * 0.92, color=colours[i % len(colours)], label=name,
               yerr=[lo, hi], capsize=3, error_kw={"elinewidth": 1, "ecolor": "#333333"})
        for x, y in zip(xs, ys):
            ax.text(x, y + 1, f"{y:.0f}", ha="center", va="bottom", fontsize=7, color="#222222")
    ax.set_xticks(range(len(subsets)))
    ax.set_xticklabels(subsets, rotation=25 if len(subsets) > 4 else 0, ha="right" if len(subsets) > 4 else "center",
                       fontsize=9)
    ax.set_ylim(0, 110)
    ax.set_ylabel("success rate (%)")
    envs = ", ".join(dict.fromkeys(r["env"] for r in runs))
    ax.set_title(f"Success per subset — {envs} (bars: 95% CI over tasks)", fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    handles, legend_labels = ax.get_legend_handles_labels()
    fig.legend(handles, legend_labels, fontsize=9, loc="lower center", ncol=min(4, len(runs)), frameon=False)
    if used:
        ax2 = axes[0][1]
        h = 0.8 / max(1, len(labelled))
        for i, r in enumerate(labelled):
            cats = r["overall"]["error_analysis"]["categories"]
            ys = [k - 0.4 + h * (i + 0.5) for k in range(len(used))]
            ax2.barh(ys, [100 * cats[c]["episode_rate"] for c in used], height=h * 0.92,
                     color=colours[runs.index(r) % len(colours)], label=names[runs.index(r)])
        ax2.set_yticks(range(len(used)))
        ax2.set_yticklabels([f"{CATEGORIES[c].title}\n({CATEGORIES[c].group})" for c in used], fontsize=8)
        ax2.invert_yaxis()
        ax2.set_xlim(0, 100)
        ax2.set_xlabel("episodes with the error (%)")
        ax2.set_title("Automatic error analysis (all subsets)", fontsize=10)
        ax2.grid(axis="x", alpha=0.3)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


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
