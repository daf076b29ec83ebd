"""The pieces every viewer page shares (``eb_core.html``, ``eb_core.html_episode``, ``eb_core.html_compare``):
the style sheet and scripts, escaping, the page frame, the result badge, the filter bar and the error-label
badges with their evidence."""

from __future__ import annotations

import html
from typing import Any

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

