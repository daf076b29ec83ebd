"""``eb show --bundle OUT RUN...``: a self-contained static results site.

The folder opens from disk or from any static host (relative links only, no script loads anything):

* ``index.html`` — a leaderboard per world: one row per run (model, ablation, task set), one column per subset
  with the success rate and its 95 % interval, the episode count, a mark on partial runs (fewer episodes than the
  task set has, or a stopped run) and whether the run verified (``eb verify``);
* ``capabilities.html`` — each capability subset (base, common sense, complex instruction, spatial, visual,
  long horizon) across the worlds;
* ``runs/<k>/index.html`` — each run's viewer (``eb show RUN``), episode pages included, on a copy of the run;
* ``compare/<world>/index.html`` — the runs of a world side by side on the tasks they share.
"""

from __future__ import annotations

import html
import json
import re
import shutil
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

__all__ = ["CAPABILITIES", "write_bundle"]

#: Capability -> the subset name each world uses for it.
CAPABILITIES: dict[str, tuple[str, ...]] = {
    "base": ("base",),
    "common sense": ("common_sense",),
    "complex instruction": ("complex_instruction", "complex"),
    "spatial": ("spatial_awareness", "spatial_relationship", "spatial"),
    "visual appearance": ("visual_appearance", "visual"),
    "long horizon": ("long_horizon",),
}

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:24px;color:#1d232a;background:#fafbfc}
h1{font-size:22px;margin:0 0 6px} h2{font-size:17px;margin:24px 0 8px} .muted{color:#68707a;font-size:13px}
table{border-collapse:collapse;background:#fff;font-size:13px;margin:6px 0} th,td{border:1px solid #dde1e6;padding:5px 9px}
th{background:#eef1f4;text-align:left} td.num{text-align:right;white-space:nowrap} a{color:#0b57d0;text-decoration:none}
a:hover{text-decoration:underline} .ci{color:#68707a;font-size:11px} .partial{color:#a15c00;font-weight:600}
.ok{color:#0a7a2f;font-weight:600} .bad{color:#b42318;font-weight:600} nav a{margin-right:14px}
"""

_SKIP_COPY = {"index.html", "compare", ".lock", "eb.log"}


def _e(x: Any) -> str:
    return html.escape(str(x), quote=True)


def _page(title: str, body: str) -> str:
    nav = "<nav><a href='index.html'>Leaderboards</a><a href='capabilities.html'>Capabilities</a></nav>"
    return (f"<!doctype html><html lang=en><head><meta charset=utf-8><title>{_e(title)}</title>"
            f"<style>{_CSS}</style></head><body>{nav}{body}</body></html>")


def _slug(text: str, taken: set[str]) -> str:
    base = re.sub(r"[^A-Za-z0-9._-]+", "-", text).strip("-") or "run"
    slug, k = base, 2
    while slug in taken:
        slug, k = f"{base}-{k}", k + 1
    taken.add(slug)
    return slug


def _copy_run(src: Path, dst: Path) -> None:
    dst.mkdir(parents=True, exist_ok=True)
    for item in src.iterdir():
        if item.name in _SKIP_COPY or item.name.startswith("."):
            continue
        if item.is_dir():
            shutil.copytree(item, dst / item.name, ignore=shutil.ignore_patterns("index.html"), dirs_exist_ok=True)
        else:
            shutil.copy2(item, dst / item.name)


def _cell(block: dict[str, Any] | None) -> str:
    if not block or not block.get("episodes"):
        return "<td class=num>–</td>"
    ci = block.get("success_rate_ci") or {}
    rate = 100 * block.get("success_rate", 0.0)
    span = (f"<br><span class=ci>[{100 * ci['ci_low']:.1f}, {100 * ci['ci_high']:.1f}] · "
            f"{int(block['episodes'])} ep.</span>") if ci.get("ci_low") is not None else ""
    return f"<td class=num>{rate:.1f}{span}</td>"


def _expected_episodes(world: str, run: dict[str, Any]) -> int | None:
    from eb_core.plugins import Registry

    try:
        spec = Registry.create().envs.get(world)
    except Exception:  # noqa: BLE001 - a bundle is still written without the plugin installed
        return None
    if spec is None:
        return None
    return sum(spec.subsets.values()) * int(run.get("repeats") or 1)


def _collect(run_dirs: Sequence[str | Path], out: Path,
             verify: Callable[[Path], tuple[bool | None, str]]) -> list[dict[str, Any]]:
    """Copy each run into the site, write its viewer, verify it and note whether it is partial."""
    from eb_core.html import write_html
    from eb_core.report import load_run

    taken: set[str] = set()
    entries: list[dict[str, Any]] = []
    for rd in map(Path, run_dirs):
        if not (rd / "episodes.jsonl").is_file():
            raise ValueError(f"{rd} is not a run directory (no episodes.jsonl)")
        run = load_run(rd)
        taskset = (run.get("config") or {}).get("taskset", "classic")
        slug = _slug(f"{run['env']}-{taskset}-{run['model']}-{run['ablation']}", taken)
        copy = out / "runs" / slug
        _copy_run(rd, copy)
        write_html(copy)
        ok, why = verify(rd)
        expected = _expected_episodes(run["env"], run) if taskset == "classic" else None
        n = int(run["overall"].get("episodes", 0))
        partial = (not run["complete"]) or (expected is not None and n < expected)
        entries.append({"run": run, "slug": slug, "taskset": taskset, "verified": ok, "why": why, "partial": partial,
                        "episodes": n, "expected": expected, "copy": copy})
    return entries


def _compares(entries: list[dict[str, Any]], out: Path) -> dict[str, str]:
    """A task-by-task comparison per world with several runs (worlds whose runs share no task get none)."""
    from eb_core.html import write_compare

    by_world: dict[str, list[dict[str, Any]]] = {}
    for e in entries:
        by_world.setdefault(e["run"]["env"], []).append(e)
    compares: dict[str, str] = {}
    for world, group in by_world.items():
        if len(group) > 1:
            try:
                write_compare([g["copy"] for g in group], out / "compare" / world)
                compares[world] = f"compare/{world}/index.html"
            except ValueError:
                pass  # the runs share no task
    return compares


def write_bundle(run_dirs: Sequence[str | Path], out: str | Path, *,
                 verify: Callable[[Path], tuple[bool | None, str]] | None = None) -> Path:
    """Write the site for ``run_dirs`` into ``out`` and return ``out/index.html``.

    ``verify(run_dir) -> (ok, one line)`` checks each run (``None``: not checked); by default ``eb verify``'s
    replay when it is installed."""
    out = Path(out)
    if out.exists() and any(out.iterdir()):
        raise FileExistsError(f"{out} exists and is not empty; choose a new folder for the bundle")
    verify = verify if verify is not None else _default_verify
    entries = _collect(run_dirs, out, verify)
    compares = _compares(entries, out)
    by_world: dict[str, list[dict[str, Any]]] = {}
    for e in entries:
        by_world.setdefault(e["run"]["env"], []).append(e)
    sections = []
    for world, group in sorted(by_world.items()):
        subsets = list(dict.fromkeys(s for g in group for s in g["run"]["subsets"]))
        head = ("<tr><th>model</th><th>ablation</th><th>task set</th>"
                + "".join(f"<th>{_e(s)}</th>" for s in subsets)
                + "<th>all</th><th>episodes</th><th>verified</th></tr>")
        rows = []
        for g in sorted(group, key=lambda g: -g["run"]["overall"].get("success_rate", 0.0)):
            r = g["run"]
            mark = " <span class=partial title='fewer episodes than the task set, or a stopped run'>partial</span>" \
                if g["partial"] else ""
            ver = ("<span class=ok>yes</span>" if g["verified"] else
                   f"<span class=bad title='{_e(g['why'])}'>NO</span>" if g["verified"] is False else
                   f"<span class=muted title='{_e(g['why'])}'>not checked</span>")
            count = f"{g['episodes']}" + (f" of {g['expected']}" if g["expected"] else "")
            rows.append(f"<tr><td><a href='runs/{_e(g['slug'])}/index.html'>{_e(r['model'])}</a>{mark}</td>"
                        f"<td>{_e(r['ablation'])}</td><td>{_e(g['taskset'])}</td>"
                        + "".join(_cell(r["subsets"].get(s)) for s in subsets) + _cell(r["overall"])
                        + f"<td class=num>{count}</td><td>{ver}</td></tr>")
        link = f" · <a href='{compares[world]}'>compare these runs task by task</a>" if world in compares else ""
        sections.append(f"<h2 id='{_e(world)}'>{_e(world)}</h2><table>{head}{''.join(rows)}</table>"
                        f"<p class=muted>Success rate %, 95 % interval over tasks [low, high] and episodes per "
                        f"cell{link}.</p>")
    (out / "index.html").write_text(_page(
        "EmbodiedBench results",
        "<h1>EmbodiedBench results</h1><p class=muted>"
        f"{len(entries)} run(s). <b>partial</b>: fewer episodes than the task set, or a stopped run. "
        "<b>verified</b>: every episode was replayed from its task, seed and recorded actions and gave the "
        "recorded result (<code>eb verify</code>).</p>" + "".join(sections)), encoding="utf-8")
    (out / "capabilities.html").write_text(_capabilities(entries), encoding="utf-8")
    (out / "runs.json").write_text(json.dumps([
        {"slug": e["slug"], "source": str(e["run"]["dir"]), "world": e["run"]["env"], "model": e["run"]["model"],
         "ablation": e["run"]["ablation"], "taskset": e["taskset"], "episodes": e["episodes"],
         "partial": e["partial"], "verified": e["verified"], "verify": e["why"]} for e in entries], indent=1) + "\n",
        encoding="utf-8")
    return out / "index.html"


def _capabilities(entries: list[dict[str, Any]]) -> str:
    worlds = sorted({e["run"]["env"] for e in entries})
    parts = ["<h1>Capabilities across the worlds</h1><p class=muted>Each capability subset, for every run that has it "
             "(success %, 95 % interval, episodes).</p>"]
    for cap, names in CAPABILITIES.items():
        rows = []
        for e in entries:
            r = e["run"]
            block = next((r["subsets"][n] for n in names if n in r["subsets"]), None)
            if block is None:
                continue
            cells = "".join(_cell(block) if w == r["env"] else "<td class=num></td>" for w in worlds)
            rows.append(f"<tr><td><a href='runs/{_e(e['slug'])}/index.html'>{_e(r['model'])}</a></td>"
                        f"<td>{_e(r['ablation'])}</td><td>{_e(e['taskset'])}</td>{cells}</tr>")
        if rows:
            parts.append(f"<h2>{_e(cap)}</h2><table><tr><th>model</th><th>ablation</th><th>task set</th>"
                         + "".join(f"<th>{_e(w)}</th>" for w in worlds) + "</tr>" + "".join(rows) + "</table>")
    return _page("Capabilities", "".join(parts))


def _default_verify(run_dir: Path) -> tuple[bool | None, str]:
    try:
        from eb_core import verify as verify_mod
    except ImportError:
        return None, "eb verify is not available in this installation"
    fn = getattr(verify_mod, "verify_run", None)
    if fn is None:
        return None, "eb verify is not available in this installation"
    try:
        result = fn(run_dir)
    except Exception as exc:  # noqa: BLE001 - shown on the page, the bundle is still written
        return False, f"verify failed: {type(exc).__name__}: {exc}".splitlines()[0]
    ok = bool(getattr(result, "ok", result))
    lines = getattr(result, "mismatches", None) or []
    return ok, ("all episodes replayed to the recorded result" if ok else str(lines[0]) if lines else "mismatch")
