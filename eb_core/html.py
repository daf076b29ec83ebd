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

import html
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from eb_core.records import RunFiles, StepRecord, atomic_write_text, episode_dir_name, read_run, read_steps

__all__ = ["write_compare", "write_html"]

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
.ci{position:relative;display:inline-block;width:160px;height:10px;background:#eef1f4;border-radius:2px}
.ci .span{position:absolute;top:3px;height:4px;background:#93b4f5} .ci .pt{position:absolute;top:0;width:2px;height:10px;background:#1d4ed8}
.warn{background:#fff4e5;border:1px solid #f3c77b;border-radius:6px;padding:8px 12px}
.sent{font-size:12px;color:#3d4651;margin:0 0 4px} .notsent img{opacity:.45;border:2px dashed #b42318}
.notsent .tag{color:#b42318;font-size:12px;font-weight:600}
.lab{display:inline-block;font-size:11px;padding:1px 6px;margin:1px 3px 1px 0;border-radius:9px;background:#fde8e7;
color:#8a1c12;border:1px solid #f5b5ae} .lab.perception{background:#efe7fd;color:#4b1c8a;border-color:#cdb5f5}
.lab.reasoning{background:#fff1db;color:#7a4a00;border-color:#f3c77b} .labels{margin:4px 0}
.filters{margin:8px 0;font-size:13px} .filters select{margin-right:12px}
.cmp{display:grid;gap:12px} .cmp .col{background:#fff;border:1px solid #dde1e6;border-radius:6px;padding:8px;min-width:0}
.cmp img{width:100%;max-width:320px;height:auto;border:1px solid #ccd} img.broken{outline:3px solid #b42318}
"""

#: Marks every image that did not load (a red outline and ``data-broken``), so a missing file shows.
_IMG_CHECK = ("<script>window.addEventListener('load',function(){document.querySelectorAll('img').forEach("
              "function(i){if(i.complete&&i.naturalWidth>0){i.setAttribute('data-loaded','1')}else{"
              "i.classList.add('broken');i.setAttribute('data-broken','1')}})});</script>")

#: Client-side filters of a table: every ``select[data-filter=KEY]`` keeps the rows whose ``data-KEY`` matches
#: (error categories: the row's space-separated list contains it). ``index.html?subset=base&errors=repetition``
#: opens with those filters set.
_FILTER_JS = ("<script>function ebFilter(){var s=document.querySelectorAll('select[data-filter]');"
              "document.querySelectorAll('tr[data-row]').forEach(function(r){var ok=true;s.forEach(function(x){"
              "var v=x.value,k=x.getAttribute('data-filter'),have=r.getAttribute('data-'+k)||'';"
              "if(v&&(k==='errors'?(' '+have+' ').indexOf(' '+v+' ')<0:have!==v))ok=false});"
              "r.style.display=ok?'':'none'});var n=document.querySelectorAll('tr[data-row]:not([style*=none])')"
              ".length;var c=document.getElementById('shown');if(c)c.textContent=n}"
              "document.querySelectorAll('select[data-filter]').forEach(function(x){x.addEventListener('change',"
              "ebFilter)});var q=new URLSearchParams(location.search);document.querySelectorAll('select[data-filter]')"
              ".forEach(function(x){var v=q.get(x.getAttribute('data-filter'));if(v!==null)x.value=v});ebFilter();"
              "</script>")



def _e(x: Any) -> str:
    return html.escape("" if x is None else str(x), quote=True)


def _page(title: str, body: str) -> str:
    return (f"<!doctype html><html lang=en><head><meta charset=utf-8><title>{_e(title)}</title>"
            f"<meta name=viewport content='width=device-width,initial-scale=1'><style>{_CSS}</style></head>"
            f"<body>{body}{_IMG_CHECK}</body></html>\n")


def _labels_html(step_labels: dict[str, Any] | None) -> str:
    """The automatic error labels of one planner step as badges (with their detail on hover), and the
    perception check's precision/recall when there is one."""
    from eb_core.errors import CATEGORIES

    if not step_labels:
        return ""
    badges = []
    for lab in step_labels.get("labels", []):
        cat = CATEGORIES.get(lab["category"])
        group = cat.group if cat else "planning"
        where = f" (env step {lab['env_step']})" if lab.get("env_step") is not None else ""
        badges.append(f"<span class='lab {group}' title='{_e(lab.get('detail'))}{_e(where)}'>"
                      f"{_e(cat.title if cat else lab['category'])}</span>")
    per = step_labels.get("perception")
    if per:
        def num(x: Any) -> str:
            return "-" if x is None else f"{100 * x:.0f}%"

        badges.append(f"<span class=muted style='font-size:12px'>perception: named {_e(', '.join(per['mentioned']) or 'nothing')}"
                      f"; in view {_e(', '.join(per['visible']) or 'nothing')}; precision {num(per['precision'])}"
                      f", recall {num(per['recall'])}</span>")
    evidence = _evidence_html(step_labels)
    return f"<div class=labels>{''.join(badges)}{evidence}</div>" if badges or evidence else ""


def _evidence_html(step_labels: dict[str, Any]) -> str:
    """What made each label fire (words matched, objects in view, the failing state), and the perception
    check's verdict per mention, as a list under the badges."""
    from eb_core.errors import CATEGORIES

    items = []
    for lab in step_labels.get("labels", []):
        ev = lab.get("evidence") or {}
        if not ev:
            continue
        cat = CATEGORIES.get(lab["category"])
        facts = "; ".join(f"{_e(k.replace('_', ' '))}: {_e(', '.join(map(str, v)) if isinstance(v, list) else v)}"
                          for k, v in ev.items())
        items.append(f"<li><b>{_e(cat.title if cat else lab['category'])}</b>: {facts}</li>")
    per = step_labels.get("perception") or {}
    for e in per.get("evidence") or []:
        why = f" ({_e(e['why'])})" if e.get("why") else ""
        items.append(f"<li>said <q>{_e(e['words'])}</q>: {_e(e['verdict'])}{why}</li>")
    if per.get("unjudged"):
        items.append(f"<li>not judged (remembered, out of view or denied): {_e(', '.join(per['unjudged']))}</li>")
    if step_labels.get("in_view"):
        items.append(f"<li>in view: {_e(', '.join(step_labels['in_view']))}</li>")
    if not items:
        return ""
    return f"<details class=evidence><summary>evidence</summary><ul style='font-size:12px'>{''.join(items)}</ul></details>"


def _invalid_number(rec: dict[str, Any], labels: dict[str, Any] | None) -> int:
    """Invalid actions as the labels count them (eb_core.errors.INVALID_LABELS); the runner's counter without."""
    from eb_core.errors import invalid_count

    counts = (labels or {}).get("counts")
    return int(rec["invalid_actions"]) if counts is None else invalid_count(counts)


def _invalid_text(rec: dict[str, Any], labels: dict[str, Any] | None) -> str:
    """The episode header's invalid-action count: refused actions as the labels count them
    (eb_core.errors.INVALID_LABELS), collisions and unmet preconditions beside them; the runner's counter when
    the episode has no labels."""
    from eb_core.errors import invalid_count

    counts = (labels or {}).get("counts")
    if counts is None:
        return f"invalid actions {rec['invalid_actions']}"
    return (f"invalid actions {invalid_count(counts)} · collisions {counts.get('collision', 0)} · unmet "
            f"preconditions {counts.get('precondition_error', 0)}")


def _filters(subsets: list[str], categories: list[str], results: tuple[str, ...] = ("success", "fail", "error"),
             result_label: str = "result") -> str:
    """The filter bar (subset, result, error category) of an index page."""
    from eb_core.errors import CATEGORIES

    def sel(key: str, label: str, options: list[tuple[str, str]]) -> str:
        opts = "".join(f"<option value='{_e(v)}'>{_e(t)}</option>" for v, t in options)
        return f"<label>{_e(label)} <select data-filter='{key}'><option value=''>all</option>{opts}</select></label>"

    return ("<div class=filters>" + sel("subset", "subset", [(x, x) for x in subsets])
            + sel("result", result_label, [(x, x) for x in results])
            + sel("errors", "error category", [(c, CATEGORIES[c].title if c in CATEGORIES else c) for c in categories])
            + " <span class=muted>showing <span id=shown></span></span></div>")


def _status(rec: dict[str, Any]) -> str:
    if rec["status"] == "error":
        return "<span class=err>error</span>"
    return "<span class=ok>success</span>" if rec["success"] else "<span class=fail>fail</span>"


def _what_was_sent(step: StepRecord, conf: dict[str, Any]) -> tuple[bool, str]:
    """Whether the model received images at this step, and one line saying what it received.

    A step that lists ``sent_images`` (the names of the images in the request) is taken at its word;
    older step files are read with the run's config (``planner.language_only``/``text_state``, the
    number of frames, ``env.multi_view``).
    """
    planner = conf.get("planner") or {}
    env = conf.get("env") or {}
    if step.sent_images is not None:
        names = [str(n) for n in step.sent_images]
        if not names:
            return False, "The model was sent no image at this step (text only)."
        return True, f"The model was sent {len(names)} image(s): {_describe_images(names)}."
    if planner.get("language_only") or planner.get("text_state"):
        mode = "language_only" if planner.get("language_only") else "text_state"
        return False, f"planner.{mode}: the model was sent no image, only the prompt's text."
    parts = ["the image below"]
    frames = int(planner.get("multi_step_images") or 1)
    if frames > 1:
        parts = [f"the current frame and up to {frames - 1} earlier one(s) (the images of the previous steps)"]
    if env.get("multi_view"):
        parts.append("the extra view(s) shown under it")
    return True, "The model was sent " + " and ".join(parts) + "."


def _describe_images(names: list[str]) -> str:
    """The images of one request in words: the frames (``frame-i``, oldest first), the views by name and the
    visual in-context examples' images (``example-i``)."""
    frames = [n for n in names if n.startswith("frame-")]
    examples = [n for n in names if n.startswith("example-")]
    views = [n for n in names if n not in frames and n not in examples]
    out: list[str] = []
    if examples:
        out.append(f"{len(examples)} image(s) of the in-context examples")
    if len(frames) == 1:
        out.append("its current view (no earlier frame yet)")
    elif frames:
        out.append(f"the last {len(frames)} frames of its view, oldest first: the views after the "
                   f"{len(frames) - 1} previous environment step(s), then the current one (below)")
    if views:
        out.append(" and ".join(f"the {v.replace('_', ' ')} view" for v in views)
                   + (" (in this order, as below)" if len(views) > 1 else ""))
    return "; ".join(out)


def _episode_page(run_title: str, rec: dict[str, Any], ep_dir: Path, conf: dict[str, Any] | None = None,
                  labels: dict[str, Any] | None = None) -> str:
    conf = conf or {}
    by_step = {st["planner_step"]: st for st in (labels or {}).get("steps", [])}
    repeat = f" · repeat {rec['repeat']}" if rec.get("repeat") else ""
    parts = [f"<p><a href='../../index.html'>&larr; {_e(run_title)}</a></p>",
             f"<h1>{_e(rec['task_id'])} <span class=muted>({_e(rec['subset'])}{repeat})</span> {_status(rec)}</h1>",
             f"<p><b>Instruction:</b> {_e(rec['instruction'])}</p>",
             f"<p class=muted>end: {_e(rec['end_reason'])} · env steps {rec['env_steps']} · planner steps "
             f"{rec['planner_steps']} · {_invalid_text(rec, labels)} · output errors {rec['output_errors']}"
             f" · progress {100 * rec['progress']:.0f}% · tokens {rec['prompt_tokens']}+{rec['completion_tokens']}</p>"]
    if rec.get("error"):
        parts.append(f"<h2>Error</h2><pre>{_e(rec['error'])}</pre>")
    steps = read_steps(ep_dir)
    for s in steps:
        sent, what = _what_was_sent(s, conf)
        seen = "what the model saw" if sent else "the scene (not sent to the model)"
        img = (f"<img src='{_e(s.image)}' alt='{seen} at step {s.planner_step}'>" if s.image else "")
        for extra in s.extra_images or []:
            img += f"<img src='{_e(extra)}' alt='extra view {_e(extra)}'>"
        if img and sent:
            img = (f"<div style='display:flex;flex-direction:column;gap:6px;width:300px;flex:none'>"
                   f"<p class=sent>{_e(what)}</p>{img}</div>")
        elif img:
            img = (f"<div class=notsent style='display:flex;flex-direction:column;gap:6px;width:300px;flex:none'>"
                   f"<p class=tag>NOT SENT TO THE MODEL</p><p class=sent>{_e(what)} The picture is for you.</p>"
                   f"{img}</div>")
        else:
            img = f"<div style='width:300px;flex:none'><p class=sent>{_e(what)}</p></div>"
        actions = "".join(
            f"<tr><td class=num>{a.env_step}</td><td>{_e(a.action_name)}</td>"
            f"<td>{'<span class=ok>ok</span>' if a.success else '<span class=fail>failed</span>'}</td>"
            f"<td>{_e(a.feedback)}</td></tr>" for a in s.actions)
        parsed = s.parsed
        notes = []
        if s.error:
            notes.append(f"<p class=err>Output error: {_e(s.error)}</p>")
        if s.plan_error:
            notes.append(f"<p class=err>{_e(s.plan_error)}</p>")
        parts.append(
            f"<div class=step>{img}<div class=body><b>Planner step {s.planner_step}</b>"
            + _labels_html(by_step.get(s.planner_step))
            + "".join(notes)
            + (f"<p><b>Reasoning:</b> {_e(parsed.reasoning_and_reflection)}</p>"
               f"<p><b>Plan:</b> {_e(parsed.language_plan)}</p>" if parsed else "")
            + (f"<table><tr><th>step</th><th>action</th><th>result</th><th>feedback</th></tr>{actions}</table>"
               if actions else "")
            + f"<details><summary>raw model answer</summary><pre>{_e(s.raw_output)}</pre></details>"
            + f"<details><summary>prompt</summary><pre>{_e(s.prompt)}</pre></details>"
            + "</div></div>")
    parts += _ending_html(ep_dir, steps)
    return _page(f"{rec['task_id']} — {run_title}", "\n".join(parts))


def _walk_svg(steps: list[Any]) -> str:
    """A small map of the agent's walk (recorded ``position`` per action) and its distance to the target."""
    pts = [(a.model_extra or {}).get("position") for s in steps for a in s.actions]
    dist = [a.distance_to_goal for s in steps for a in s.actions]
    pts = [p for p in pts if isinstance(p, (list, tuple)) and len(p) == 2]
    out = []
    if len(pts) >= 2:
        xs, ys = [float(p[0]) for p in pts], [float(p[1]) for p in pts]
        span = max(max(xs) - min(xs), max(ys) - min(ys), 0.5)
        scale = 220 / span

        def xy(x: float, y: float) -> str:  # north up: y grows upwards
            return f"{20 + (x - min(xs)) * scale:.1f},{240 - (y - min(ys)) * scale:.1f}"

        line = " ".join(xy(x, y) for x, y in zip(xs, ys))
        out.append(
            "<figure style='margin:0'><svg width=260 height=260 style='background:#fff;border:1px solid #dde1e6'>"
            f"<polyline points='{line}' fill='none' stroke='#3b82f6' stroke-width='2'></polyline>"
            f"<circle cx='{xy(xs[0], ys[0]).split(',')[0]}' cy='{xy(xs[0], ys[0]).split(',')[1]}' r='5' "
            "fill='#0a7a2f'></circle>"
            f"<circle cx='{xy(xs[-1], ys[-1]).split(',')[0]}' cy='{xy(xs[-1], ys[-1]).split(',')[1]}' r='5' "
            "fill='#b42318'></circle></svg><figcaption class=muted>The walk seen from above (north up): green after the "
            f"first action, red at the end; {span:.1f} m across.</figcaption></figure>")
    known = [d for d in dist if d is not None]
    if known:
        top = max(max(known), 1.0)
        w = 260 / max(1, len(dist) - 1)
        line = " ".join(f"{i * w:.1f},{110 - 100 * d / top:.1f}" for i, d in enumerate(dist) if d is not None)
        out.append(
            "<figure style='margin:0'><svg width=270 height=120 style='background:#fff;border:1px solid #dde1e6'>"
            f"<polyline points='{line}' fill='none' stroke='#a15c00' stroke-width='2'></polyline></svg><figcaption class=muted>"
            f"Distance to the target after each action: {known[0]:.2f} m to {known[-1]:.2f} m (top of the chart "
            f"{top:.1f} m).</figcaption></figure>")
    return "".join(out)


def _ending_html(ep_dir: Path, steps: list[Any]) -> list[str]:
    """The end of an episode page: the final state, a map of the walk, and the episode's video if exported."""
    from eb_core.episode import FINAL_IMAGE_PREFIX
    from eb_core.video import VIDEO_NAMES

    parts = []
    finals = sorted(p.name for p in ep_dir.glob(f"{FINAL_IMAGE_PREFIX}*.png")) if ep_dir.is_dir() else []
    walk = _walk_svg(steps)
    if finals or walk:
        imgs = "".join(f"<img src='{_e(n)}' alt='the final state' style='width:300px;border:1px solid #ccd'>"
                       for n in finals[:1])
        parts.append("<h2>How it ended</h2><div style='display:flex;gap:16px;align-items:flex-start'>"
                     + (f"<figure style='margin:0'>{imgs}<figcaption class=muted>The state after the last action "
                        f"(not sent to the model).</figcaption></figure>" if imgs else "")
                     + walk + "</div>")
    for name in VIDEO_NAMES:
        if (ep_dir / name).is_file():
            tag = (f"<video controls width=520 src='{_e(name)}'></video>" if name.endswith(".mp4")
                   else f"<img src='{_e(name)}' alt='the episode replayed' width=520>")
            parts.append(f"<h2>Replay</h2>{tag}<p class=muted>Every action replayed in the world "
                         f"(<code>eb export RUN --format video</code>); the model's views are framed in blue.</p>")
            break
    return parts


def _ci_cell(block: dict[str, Any], key: str) -> str:
    """``45.0 [39.5, 50.6]`` and a small bar: the interval in light blue, the estimate as a tick."""
    value = block.get(key)
    ci = block.get(f"{key}_ci") or {}
    if value is None:
        return "<td class=num>-</td><td></td>"
    lo, hi = ci.get("ci_low"), ci.get("ci_high")
    if lo is None:
        return f"<td class=num>{100 * value:.1f}</td><td></td>"
    bar = (f"<span class=ci title='95% interval {100 * lo:.1f} to {100 * hi:.1f}'>"
           f"<span class=span style='left:{160 * lo:.0f}px;width:{max(1.0, 160 * (hi - lo)):.0f}px'></span>"
           f"<span class=pt style='left:{min(158.0, 160 * value):.0f}px'></span></span>")
    return f"<td class=num>{100 * value:.1f} <span class=muted>[{100 * lo:.1f}, {100 * hi:.1f}]</span></td><td>{bar}</td>"


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


def write_html(run_dir: str | Path) -> Path:
    """Write the viewer into ``run_dir`` and return the path of ``index.html``."""
    from eb_core.report import _run_config, load_run

    root = Path(run_dir)
    files = RunFiles(root)
    run = load_run(root)  # recomputed from episodes.jsonl: also right for a run stopped before its end
    conf = _run_config(root)
    meta = read_run(root).summary or {}
    from eb_core.errors import CATEGORIES, label_episode, run_vocabulary

    records = [r.model_dump() for r in run["records"]]
    repeats = int(run.get("repeats") or 1)
    title = f"{run['env']} / {run['model']} / {run['ablation']}"
    step_sets = {episode_dir_name(r["task_id"], r.get("repeat", 0)):
                 read_steps(files.episodes_dir / episode_dir_name(r["task_id"], r.get("repeat", 0))) for r in records}
    vocab = run_vocabulary(step_sets.values())
    rows = []
    used: set[str] = set()
    for rec in records:
        name = episode_dir_name(rec["task_id"], rec.get("repeat", 0))
        ep_dir = files.episodes_dir / name
        label = rec["task_id"] + (f" (repeat {rec['repeat']})" if rec.get("repeat") else "")
        labels = label_episode(step_sets[name], rec, vocab) if rec["status"] == "ok" else None
        counts = (labels or {}).get("counts", {})
        used |= set(counts)
        if ep_dir.is_dir():
            atomic_write_text(ep_dir / "index.html", _episode_page(title, rec, ep_dir, conf, labels))
            link = f"<a href='episodes/{_e(name)}/index.html'>{_e(label)}</a>"
        else:
            link = _e(label)
        result = "error" if rec["status"] == "error" else ("success" if rec["success"] else "fail")
        errs = ", ".join(f"{CATEGORIES[k].title} {v}" for k, v in counts.items())
        score = (labels or {}).get("perception_score")
        rows.append(
            f"<tr data-row data-subset='{_e(rec['subset'])}' data-result='{result}' data-errors='{_e(' '.join(counts))}'>"
            f"<td>{link}</td><td>{_e(rec['subset'])}</td><td>{_status(rec)}</td><td>{_e(rec['end_reason'])}</td>"
            f"<td class=num>{rec['env_steps']}</td><td class=num>{rec['planner_steps']}</td>"
            f"<td class=num>{_invalid_number(rec, labels)}</td><td class=num>{rec['output_errors']}</td>"
            f"<td class=num>{100 * rec['progress']:.0f}%</td><td style='font-size:12px'>{_e(errs)}</td>"
            f"<td class=num>{'-' if score is None else f'{score:.2f}'}</td><td>{_e(rec['instruction'])}</td></tr>")
    overall = run["overall"]
    subset_rows = []
    for name, s in [*run["subsets"].items(), ("all", overall)]:
        label = "<b>all</b>" if name == "all" else _e(name)
        subset_rows.append(f"<tr><td>{label}</td><td class=num>{s.get('episodes', 0):.0f}</td>"
                           f"{_ci_cell(s, 'success_rate')}{_ci_cell(s, 'subgoal_success')}"
                           f"<td class=num>{100 * s.get('subgoal_success_paper', 0):.1f}</td></tr>")
    measured = int(overall.get("episodes", 0))
    banner = ""
    if not meta:
        banner = (f"<p class=warn><b>Incomplete run:</b> there is no summary.json, so the run was stopped before "
                  f"its end. Everything below is computed from the {len(records)} episode(s) recorded in "
                  f"episodes.jsonl; re-run the same command to finish it.</p>")
    elif not meta.get("complete", True):
        total = meta.get("n_episodes", meta.get("n_selected", "?"))
        why = f" ({_e(meta['stopped_early'])})" if meta.get("stopped_early") else ""
        banner = (f"<p class=warn><b>Incomplete run:</b> {meta.get('n_finished', measured)} of {total} episodes "
                  f"finished{why}. The numbers cover the finished episodes only; re-run the same command to "
                  f"resume.</p>")
    rate = (f"success rate {100 * overall['success_rate']:.1f}%" if measured and "success_rate" in overall
            else "no measured episode yet")
    ci = overall.get("success_rate_ci") or {}
    if measured and ci.get("ci_low") is not None:
        rate += f" (95% CI {100 * ci['ci_low']:.1f}–{100 * ci['ci_high']:.1f})"
    method = ci.get("ci_method") or "-"
    reps = f" · {repeats} repeats per task" if repeats > 1 else ""
    errors = (f"output-error rate {100 * overall['output_error_rate']:.1f}%"
              if measured and overall.get("output_error_rate") is not None else "output-error rate -")
    body = (f"<h1>{_e(title)}</h1>{banner}<p class=muted>{_e(root)} · {len(records)} episode{'' if len(records) == 1 else 's'}{reps} · {rate} · "
            f"{errors} · cost "
            f"${meta.get('total_cost_usd', overall.get('cost_usd', 0)):.4f}</p>"
            "<h2>Subsets</h2><table><tr><th>subset</th><th>episodes</th><th>success % [95% CI]</th><th></th>"
            "<th>subgoal % [95% CI]</th><th></th><th>subgoal % (original's rule)</th></tr>"
            f"{''.join(subset_rows)}</table>"
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


# -- several runs side by side ---------------------------------------------------------------------------


def _compare_step(s: StepRecord | None, step_labels: dict[str, Any] | None, img_prefix: str) -> str:
    """One run's planner step in a comparison column (images copied beside the page under ``img_prefix``)."""
    if s is None:
        return "<div class=col><p class=muted>(no step: the episode had ended)</p></div>"
    parsed = s.parsed
    imgs = "".join(f"<img src='{_e(img_prefix + name)}' alt='step {s.planner_step} {_e(name)}'>"
                   for name in ([s.image] if s.image else []))
    actions = "".join(
        f"<tr><td class=num>{a.env_step}</td><td>{_e(a.action_name)}</td>"
        f"<td>{'<span class=ok>ok</span>' if a.success else '<span class=fail>failed</span>'}</td>"
        f"<td>{_e(a.feedback)}</td></tr>" for a in s.actions)
    notes = ""
    if s.error:
        notes += f"<p class=err>Output error: {_e(s.error)}</p>"
    if s.plan_error:
        notes += f"<p class=err>{_e(s.plan_error)}</p>"
    return ("<div class=col>" + imgs + _labels_html(step_labels) + notes
            + (f"<p><b>Saw:</b> {_e(parsed.visual_state_description)}</p>"
               f"<p><b>Reasoning:</b> {_e(parsed.reasoning_and_reflection)}</p>"
               f"<p><b>Plan:</b> {_e(parsed.language_plan)}</p>" if parsed else "")
            + (f"<table><tr><th>step</th><th>action</th><th>result</th><th>feedback</th></tr>{actions}</table>"
               if actions else "")
            + f"<details><summary>raw model answer</summary><pre>{_e(s.raw_output)}</pre></details></div>")


def write_compare(run_dirs: Sequence[str | Path], out: str | Path) -> Path:
    """Write a comparison of several runs into ``out`` (one static folder that opens from disk):
    ``index.html`` lists the tasks the runs share with each run's result and error labels (filters: subset,
    which runs succeeded, error category); ``tasks/<task>.html`` shows the runs side by side, planner step by
    planner step. The step images are copied into ``out/img/``. Returns the path of ``index.html``."""
    import shutil

    from eb_core.errors import CATEGORIES, label_episode, run_vocabulary
    from eb_core.report import load_run

    out = Path(out)
    runs = [load_run(d) for d in run_dirs]
    names = [f"{r['model']} / {r['ablation']}" for r in runs]
    if len(set(names)) < len(names):
        names = [f"{n} ({Path(r['dir']).name})" for n, r in zip(names, runs)]
    recs = [{(rec.task_id, rec.repeat): rec for rec in r["records"]} for r in runs]
    keys = [k for k in recs[0] if all(k in m for m in recs[1:])]
    if not keys:
        raise ValueError("the runs share no task: compare runs of the same env and tasks (same subset=, limit=)")
    steps: list[dict[Any, list[StepRecord]]] = []
    vocabs = []
    for r in runs:
        root = Path(r["dir"])
        st = {k: read_steps(root / "episodes" / episode_dir_name(*k)) for k in keys}
        steps.append(st)
        vocabs.append(run_vocabulary(st.values()))
    (out / "tasks").mkdir(parents=True, exist_ok=True)
    title = f"Comparison on {runs[0]['env']}: " + " vs ".join(names)
    rows, used = [], set()
    for key in keys:
        task_id, repeat = key
        page_name = episode_dir_name(task_id, repeat)
        labels = []
        for i, r in enumerate(runs):
            rec = recs[i][key]
            labels.append(label_episode(steps[i][key], rec.model_dump(), vocabs[i]) if rec.status == "ok" else None)
            src = Path(r["dir"]) / "episodes" / page_name
            for s in steps[i][key]:
                if s.image and (src / s.image).exists():
                    dst = out / "img" / str(i) / page_name / s.image
                    dst.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(src / s.image, dst)
        first = recs[0][key]
        wins = [recs[i][key].success for i in range(len(runs))]
        outcome = "all succeeded" if all(wins) else "none succeeded" if not any(wins) else "they differ"
        cats = sorted({c for lab in labels if lab for c in lab["counts"]})
        used |= set(cats)
        n_steps = max(len(steps[i][key]) for i in range(len(runs)))
        body = [f"<p><a href='../index.html'>&larr; {_e(title)}</a></p>",
                f"<h1>{_e(task_id)} <span class=muted>({_e(first.subset)}"
                + (f" · repeat {repeat}" if repeat else "") + ")</span></h1>",
                f"<p><b>Instruction:</b> {_e(first.instruction)}</p>",
                f"<div class=cmp style='grid-template-columns:repeat({len(runs)},1fr)'>"
                + "".join(f"<div class=col><b>{_e(names[i])}</b> {_status(recs[i][key].model_dump())} "
                          f"<span class=muted>end {_e(recs[i][key].end_reason)} · "
                          f"{recs[i][key].planner_steps} planner steps · progress "
                          f"{100 * recs[i][key].progress:.0f}%</span></div>" for i in range(len(runs)))
                + "</div>"]
        for n in range(n_steps):
            cols = []
            for i in range(len(runs)):
                step = steps[i][key][n] if n < len(steps[i][key]) else None
                lab = labels[i]["steps"][n] if labels[i] and step is not None and n < len(labels[i]["steps"]) else None
                cols.append(_compare_step(step, lab, f"../img/{i}/{page_name}/"))
            body.append(f"<h2>Planner step {n + 1}</h2><div class=cmp style='grid-template-columns:"
                        f"repeat({len(runs)},1fr)'>{''.join(cols)}</div>")
        atomic_write_text(out / "tasks" / f"{page_name}.html", _page(f"{task_id} — {title}", "\n".join(body)))
        cells = "".join(
            f"<td>{_status(recs[i][key].model_dump())} <span class=muted>{100 * recs[i][key].progress:.0f}%</span>"
            f"</td><td style='font-size:12px'>"
            + _e(", ".join(f"{CATEGORIES[c].title} {v}" for c, v in (labels[i] or {}).get("counts", {}).items()))
            + "</td>" for i in range(len(runs)))
        rows.append(f"<tr data-row data-subset='{_e(first.subset)}' data-result='{outcome}' "
                    f"data-errors='{_e(' '.join(cats))}'><td><a href='tasks/{_e(page_name)}.html'>"
                    f"{_e(task_id + (f' (repeat {repeat})' if repeat else ''))}</a></td><td>{_e(first.subset)}</td>"
                    f"{cells}<td>{_e(first.instruction)}</td></tr>")
    subsets = list(dict.fromkeys(recs[0][k].subset for k in keys))
    head = "".join(f"<th>{_e(n)}</th><th>error labels</th>" for n in names)
    summary = "".join(
        f"<tr><td>{_e(names[i])}</td><td>{_e(r['dir'])}</td><td class=num>"
        f"{100 * sum(recs[i][k].success for k in keys) / len(keys):.1f}%</td></tr>" for i, r in enumerate(runs))
    body = (f"<h1>{_e(title)}</h1><p class=muted>{len(keys)} shared episodes</p>"
            f"<table><tr><th>run</th><th>directory</th><th>success on the shared episodes</th></tr>{summary}</table>"
            "<h2>Tasks</h2>"
            + _filters(subsets, [k for k in CATEGORIES if k in used],
                       ("all succeeded", "none succeeded", "they differ"), "outcome")
            + f"<table><tr><th>task</th><th>subset</th>{head}<th>instruction</th></tr>{''.join(rows)}</table>"
            + _FILTER_JS)
    index = out / "index.html"
    atomic_write_text(index, _page(title, body))
    return index
