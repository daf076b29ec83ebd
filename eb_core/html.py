"""A static HTML viewer for a run directory (``eb show RUN_DIR``): error analysis without reading JSON by hand.

``index.html`` lists every episode (success, end reason, steps, errors) with per-subset numbers;
``episodes/<id>/index.html`` shows each planner step: the image the model saw, the prompt, the raw answer,
the parsed plan and every executed action with the world's feedback. All model and env text is escaped.
"""

from __future__ import annotations

import html
import json
from pathlib import Path
from typing import Any

from eb_core.records import RunFiles, atomic_write_text

__all__ = ["write_html"]

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:24px;color:#1d232a;background:#fafbfc}
h1{font-size:22px;margin:0 0 4px} h2{font-size:17px;margin:22px 0 8px} .muted{color:#68707a}
table{border-collapse:collapse;background:#fff;font-size:13px} th,td{border:1px solid #dde1e6;padding:4px 8px;text-align:left}
th{background:#eef1f4} td.num{text-align:right} .ok{color:#0a7a2f;font-weight:600} .fail{color:#b42318;font-weight:600}
.err{color:#a15c00;font-weight:600} a{color:#0b57d0;text-decoration:none} a:hover{text-decoration:underline}
.step{background:#fff;border:1px solid #dde1e6;border-radius:6px;padding:12px;margin:14px 0;display:flex;gap:16px}
.step img{width:300px;height:auto;border:1px solid #ccd;flex:none} .step .body{flex:1;min-width:0}
pre{white-space:pre-wrap;word-break:break-word;background:#f3f5f7;padding:8px;border-radius:4px;font-size:12px;max-height:360px;overflow:auto}
details summary{cursor:pointer;color:#0b57d0;font-size:13px} .bar{display:inline-block;height:10px;background:#3b82f6;border-radius:2px}
"""


def _e(x: Any) -> str:
    return html.escape("" if x is None else str(x), quote=True)


def _page(title: str, body: str) -> str:
    return (f"<!doctype html><html lang=en><head><meta charset=utf-8><title>{_e(title)}</title>"
            f"<meta name=viewport content='width=device-width,initial-scale=1'><style>{_CSS}</style></head>"
            f"<body>{body}</body></html>\n")


def _status(rec: dict[str, Any]) -> str:
    if rec["status"] == "error":
        return "<span class=err>error</span>"
    return "<span class=ok>success</span>" if rec["success"] else "<span class=fail>fail</span>"


def _episode_page(run_title: str, rec: dict[str, Any], ep_dir: Path) -> str:
    parts = [f"<p><a href='../../index.html'>&larr; {_e(run_title)}</a></p>",
             f"<h1>{_e(rec['task_id'])} <span class=muted>({_e(rec['subset'])})</span> {_status(rec)}</h1>",
             f"<p><b>Instruction:</b> {_e(rec['instruction'])}</p>",
             f"<p class=muted>end: {_e(rec['end_reason'])} · env steps {rec['env_steps']} · planner steps "
             f"{rec['planner_steps']} · invalid actions {rec['invalid_actions']} · output errors {rec['output_errors']}"
             f" · progress {100 * rec['progress']:.0f}% · tokens {rec['prompt_tokens']}+{rec['completion_tokens']}</p>"]
    if rec.get("error"):
        parts.append(f"<h2>Error</h2><pre>{_e(rec['error'])}</pre>")
    steps_path = ep_dir / "steps.jsonl"
    steps = []
    if steps_path.exists():
        for line in steps_path.read_text(encoding="utf-8").splitlines():
            try:
                steps.append(json.loads(line))
            except ValueError:
                continue
    for s in steps:
        img = f"<img src='{_e(s['image'])}' alt='what the model saw at step {s['planner_step']}'>" if s.get("image") else ""
        for extra in s.get("extra_images", []):
            img += f"<img src='{_e(extra)}' alt='extra view {_e(extra)}'>"
        if img:
            img = f"<div style='display:flex;flex-direction:column;gap:6px'>{img}</div>"
        actions = "".join(
            f"<tr><td class=num>{a['env_step']}</td><td>{_e(a['action_name'])}</td>"
            f"<td>{'<span class=ok>ok</span>' if a['success'] else '<span class=fail>failed</span>'}</td>"
            f"<td>{_e(a['feedback'])}</td></tr>" for a in s.get("actions", []))
        parsed = s.get("parsed") or {}
        notes = []
        if s.get("error"):
            notes.append(f"<p class=err>Output error: {_e(s['error'])}</p>")
        if s.get("plan_error"):
            notes.append(f"<p class=err>{_e(s['plan_error'])}</p>")
        parts.append(
            f"<div class=step>{img}<div class=body><b>Planner step {s['planner_step']}</b>"
            + "".join(notes)
            + (f"<p><b>Reasoning:</b> {_e(parsed.get('reasoning_and_reflection'))}</p>"
               f"<p><b>Plan:</b> {_e(parsed.get('language_plan'))}</p>" if parsed else "")
            + (f"<table><tr><th>step</th><th>action</th><th>result</th><th>feedback</th></tr>{actions}</table>"
               if actions else "")
            + f"<details><summary>raw model answer</summary><pre>{_e(s.get('raw_output'))}</pre></details>"
            + f"<details><summary>prompt</summary><pre>{_e(s.get('prompt'))}</pre></details>"
            + "</div></div>")
    return _page(f"{rec['task_id']} — {run_title}", "\n".join(parts))


def write_html(run_dir: str | Path) -> Path:
    """Write the viewer into ``run_dir`` and return the path of ``index.html``."""
    root = Path(run_dir)
    files = RunFiles(root)
    records = [r.model_dump() for r in files.load_episodes()]
    summary = json.loads((root / "summary.json").read_text()) if (root / "summary.json").exists() else {}
    title = f"{summary.get('env', '?')} / {summary.get('model', '?')} / {summary.get('ablation', '?')}"
    rows = []
    for rec in records:
        ep_dir = files.episodes_dir / rec["task_id"]
        if ep_dir.is_dir():
            atomic_write_text(ep_dir / "index.html", _episode_page(title, rec, ep_dir))
            link = f"<a href='episodes/{_e(rec['task_id'])}/index.html'>{_e(rec['task_id'])}</a>"
        else:
            link = _e(rec["task_id"])
        rows.append(
            f"<tr><td>{link}</td><td>{_e(rec['subset'])}</td><td>{_status(rec)}</td><td>{_e(rec['end_reason'])}</td>"
            f"<td class=num>{rec['env_steps']}</td><td class=num>{rec['planner_steps']}</td>"
            f"<td class=num>{rec['invalid_actions']}</td><td class=num>{rec['output_errors']}</td>"
            f"<td class=num>{100 * rec['progress']:.0f}%</td><td>{_e(rec['instruction'])}</td></tr>")
    subset_rows = []
    for name, s in summary.get("subsets", {}).items():
        rate = s.get("success_rate", 0.0)
        subset_rows.append(
            f"<tr><td>{_e(name)}</td><td class=num>{s.get('episodes', 0):.0f}</td><td class=num>{100 * rate:.1f}</td>"
            f"<td><span class=bar style='width:{int(160 * rate)}px'></span></td>"
            f"<td class=num>{100 * s.get('subgoal_success', 0):.1f}</td></tr>")
    overall = summary.get("overall", {})
    body = (f"<h1>{_e(title)}</h1><p class=muted>{_e(root)} · {len(records)} episodes · success rate "
            f"{100 * overall.get('success_rate', 0):.1f}% · output-error rate "
            f"{100 * overall.get('output_error_rate', 0):.1f}% · cost ${overall.get('cost_usd', 0):.4f}</p>"
            "<h2>Subsets</h2><table><tr><th>subset</th><th>episodes</th><th>success %</th><th></th>"
            f"<th>subgoal %</th></tr>{''.join(subset_rows)}</table>"
            "<h2>Episodes</h2><table><tr><th>task</th><th>subset</th><th>result</th><th>end</th><th>env steps</th>"
            "<th>planner steps</th><th>invalid</th><th>output errors</th><th>progress</th><th>instruction</th></tr>"
            f"{''.join(rows)}</table>")
    index = root / "index.html"
    atomic_write_text(index, _page(title, body))
    return index
