"""A static HTML viewer for a run directory (``eb show RUN_DIR``): error analysis without reading JSON by hand.

``index.html`` lists every episode (success, end reason, steps, errors) with per-subset numbers and their
95 % intervals, recomputed from ``episodes.jsonl`` (so a run stopped before its end is shown too, marked
incomplete); ``episodes/<id>/index.html`` shows each planner step: what the model was sent (which image,
which views and frames, or no image at all), the prompt, the raw answer, the parsed plan and every
executed action with the world's feedback and the step's automatic error labels. ``index.html`` filters
episodes by subset, result and error category. :func:`write_compare` puts several runs side by side (same
task, step by step) in one folder. All model and env text is escaped.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from eb_core._html_parts import _FILTER_JS, _e, _filters, _invalid_number, _page, _status
from eb_core.html_compare import write_compare
from eb_core.html_episode import episode_page, world_note
from eb_core.records import RunFiles, atomic_write_text, episode_dir_name, read_run, read_steps

__all__ = ["write_compare", "write_html"]


def _ci_cell(block: dict[str, Any], key: str) -> str:
    """``45.0 [39.5, 50.6]`` and a small bar: the interval in light blue, the estimate as a tick."""
    value = block.get(key)
    ci = block.get(f"{key}_ci") or {}
    if value is None:
        return "<td class=num>-</td><td></td>"
    lo, hi = ci.get("ci_low"), ci.get("ci_high")
    if lo is None or hi is None:
        return f"<td class=num>{100 * value:.1f}</td><td></td>"
    bar = (f"<span class=ci title='95% interval {100 * lo:.1f} to {100 * hi:.1f}'>"
           f"<span class=span style='left:{160 * lo:.0f}px;width:{max(1.0, 160 * (hi - lo)):.0f}px'></span>"
           f"<span class=pt style='left:{min(158.0, 160 * value):.0f}px'></span></span>")
    return (f"<td class=num>{100 * value:.1f} <span class=muted>[{100 * lo:.1f}, {100 * hi:.1f}]</span></td>"
            f"<td>{bar}</td>")


def _error_summary_html(block: dict[str, Any]) -> str:
    """The run's automatic error analysis: per category the share of episodes with it and its count."""
    from eb_core.errors import CATEGORIES

    ea = block.get("error_analysis")
    if not ea:
        return ""
    rows = []
    for key, cat in ea["categories"].items():
        if not cat["count"]:
            continue
        c = CATEGORIES[key]
        rows.append(f"<tr><td><span class='lab {c.group}'>{_e(c.title)}</span></td><td>{_e(c.group)}: "
                    f"{_e(c.paper)}</td><td class=num>{100 * cat['episode_rate']:.1f}%</td>"
                    f"<td class=num>{cat['count']:.0f}</td><td class=num>{cat['per_step']:.2f}</td></tr>")
    ps = ea.get("perception_score")
    return ("<h2>Automatic error analysis</h2><table><tr><th>label</th><th>paper category</th>"
            "<th>episodes with it</th><th>count</th><th>per planner step</th></tr>" + "".join(rows) + "</table>"
            + f"<p class=muted>{ea['episodes']:.0f} labelled episodes; perception score "
            + ("-" if ps is None else f"{ps:.2f}") + " (F1 of the objects named against those in view); labels "
            "from the run's records, see docs/error_analysis.md.</p>")


def _index_row(rec: dict[str, Any], link: str, labels: dict[str, Any] | None) -> str:
    """One episode's row of ``index.html`` (its ``data-*`` attributes feed the filters)."""
    from eb_core.errors import CATEGORIES

    counts = (labels or {}).get("counts", {})
    result = "error" if rec["status"] == "error" else ("success" if rec["success"] else "fail")
    errs = ", ".join(f"{CATEGORIES[k].title} {v}" for k, v in counts.items())
    score = (labels or {}).get("perception_score")
    return (
        f"<tr data-row data-subset='{_e(rec['subset'])}' data-result='{result}' data-errors='{_e(' '.join(counts))}'>"
        f"<td>{link}</td><td>{_e(rec['subset'])}</td><td>{_status(rec)}</td><td>{_e(rec['end_reason'])}</td>"
        f"<td class=num>{rec['env_steps']}</td><td class=num>{rec['planner_steps']}</td>"
        f"<td class=num>{_invalid_number(rec, labels)}</td><td class=num>{rec['output_errors']}</td>"
        f"<td class=num>{100 * rec['progress']:.0f}%</td><td style='font-size:12px'>{_e(errs)}</td>"
        f"<td class=num>{'-' if score is None else f'{score:.2f}'}</td><td>{_e(rec['instruction'])}</td></tr>")


def _subset_rows(run: dict[str, Any]) -> str:
    """The rows of the per-subset table, the whole run last."""
    rows = []
    for name, s in [*run["subsets"].items(), ("all", run["overall"])]:
        label = "<b>all</b>" if name == "all" else _e(name)
        rows.append(f"<tr><td>{label}</td><td class=num>{s.get('episodes', 0):.0f}</td>"
                    f"{_ci_cell(s, 'success_rate')}{_ci_cell(s, 'subgoal_success')}"
                    f"<td class=num>{100 * s.get('subgoal_success_paper', 0):.1f}</td></tr>")
    return "".join(rows)


def _incomplete_banner(meta: dict[str, Any], n_records: int, measured: int) -> str:
    """The warning over a run stopped before its end ("" for a finished run)."""
    if not meta:
        return (f"<p class=warn><b>Incomplete run:</b> there is no summary.json, so the run was stopped before "
                f"its end. Everything below is computed from the {n_records} episode(s) recorded in "
                f"episodes.jsonl; re-run the same command to finish it.</p>")
    if not meta.get("complete", True):
        total = meta.get("n_episodes", meta.get("n_selected", "?"))
        why = f" ({_e(meta['stopped_early'])})" if meta.get("stopped_early") else ""
        return (f"<p class=warn><b>Incomplete run:</b> {meta.get('n_finished', measured)} of {total} episodes "
                f"finished{why}. The numbers cover the finished episodes only; re-run the same command to "
                f"resume.</p>")
    return ""


def _headline(overall: dict[str, Any], measured: int) -> tuple[str, str, str]:
    """The run's success rate (with its interval), the interval method, and the output-error rate."""
    rate = (f"success rate {100 * overall['success_rate']:.1f}%" if measured and "success_rate" in overall
            else "no measured episode yet")
    ci = overall.get("success_rate_ci") or {}
    if measured and ci.get("ci_low") is not None:
        rate += f" (95% CI {100 * ci['ci_low']:.1f}–{100 * ci['ci_high']:.1f})"
    method = ci.get("ci_method") or "-"
    errors = (f"output-error rate {100 * overall['output_error_rate']:.1f}%"
              if measured and overall.get("output_error_rate") is not None else "output-error rate -")
    return rate, method, errors


def _episode_pages(root: Path, run: dict[str, Any], title: str, registry: Any) -> tuple[list[str], set[str]]:
    """Write every episode's page (with its error labels) and return the index rows and the error
    categories that occur."""
    from eb_core.errors import label_episode, run_vocabulary
    from eb_core.report import _run_config

    files = RunFiles(root)
    conf = _run_config(root)
    records = [r.model_dump() for r in run["records"]]
    step_sets = {episode_dir_name(r["task_id"], r.get("repeat", 0)):
                 read_steps(files.episodes_dir / episode_dir_name(r["task_id"], r.get("repeat", 0))) for r in records}
    vocab = run_vocabulary(step_sets.values())
    note: str | None = None  # looked up once, when the first page is written
    rows = []
    used: set[str] = set()
    for rec in records:
        name = episode_dir_name(rec["task_id"], rec.get("repeat", 0))
        ep_dir = files.episodes_dir / name
        label = rec["task_id"] + (f" (repeat {rec['repeat']})" if rec.get("repeat") else "")
        labels = label_episode(step_sets[name], rec, vocab) if rec["status"] == "ok" else None
        used |= set((labels or {}).get("counts", {}))
        if ep_dir.is_dir():
            if note is None:
                note = world_note(str(run["env"]), registry)
            atomic_write_text(ep_dir / "index.html", episode_page(title, rec, ep_dir, conf, labels, note))
            link = f"<a href='episodes/{_e(name)}/index.html'>{_e(label)}</a>"
        else:
            link = _e(label)
        rows.append(_index_row(rec, link, labels))
    return rows, used


def write_html(run_dir: str | Path, *, registry: Any = None) -> Path:
    """Write the viewer into ``run_dir`` and return the path of ``index.html``.

    ``registry`` (an :class:`eb_core.plugins.Registry`, by default the installed plugins') is asked for the
    world's ``EnvSpec.notes``, shown on every episode page."""
    from eb_core.errors import CATEGORIES
    from eb_core.report import load_run

    root = Path(run_dir)
    run = load_run(root)  # recomputed from episodes.jsonl: also right for a run stopped before its end
    meta = read_run(root).summary or {}
    n_records = len(run["records"])
    repeats = int(run.get("repeats") or 1)
    title = f"{run['env']} / {run['model']} / {run['ablation']}"
    rows, used = _episode_pages(root, run, title, registry)
    overall = run["overall"]
    measured = int(overall.get("episodes", 0))
    banner = _incomplete_banner(meta, n_records, measured)
    rate, method, errors = _headline(overall, measured)
    reps = f" · {repeats} repeats per task" if repeats > 1 else ""
    body = (f"<h1>{_e(title)}</h1>{banner}<p class=muted>{_e(root)} · {n_records} "
            f"episode{'' if n_records == 1 else 's'}{reps} · {rate} · "
            f"{errors} · cost "
            f"${meta.get('total_cost_usd', overall.get('cost_usd', 0)):.4f}</p>"
            "<h2>Subsets</h2><table><tr><th>subset</th><th>episodes</th><th>success % [95% CI]</th><th></th>"
            "<th>subgoal % [95% CI]</th><th></th><th>subgoal % (original's rule)</th></tr>"
            f"{_subset_rows(run)}</table>"
            f"<p class=muted>Intervals: 95 % over tasks ({_e(method)}"
            + (", each task's repeats kept together" if repeats > 1 else "")
            + "); see docs/statistics.md.</p>"
            + _error_summary_html(overall)
            + "<h2>Episodes</h2>"
            + _filters(list(run["subsets"]), [k for k in CATEGORIES if k in used])
            + "<table><tr><th>task</th><th>subset</th><th>result</th><th>end</th><th>env steps</th>"
            "<th>planner steps</th><th>invalid</th><th>output errors</th><th>progress</th><th>error labels</th>"
            "<th>perception</th><th>instruction</th></tr>"
            f"{''.join(rows)}</table>{_FILTER_JS}")
    index = root / "index.html"
    atomic_write_text(index, _page(title, body))
    return index
