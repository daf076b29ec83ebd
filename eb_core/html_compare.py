"""Several runs side by side (``eb show RUN_A RUN_B ... --out DIR``): one static folder whose ``index.html``
lists the tasks the runs share, and whose ``tasks/<task>.html`` shows the runs planner step by planner step."""

from __future__ import annotations

import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from eb_core._html_parts import _FILTER_JS, _e, _filters, _labels_html, _page, _status
from eb_core.html_episode import note_html, world_note
from eb_core.records import EpisodeRecord, StepRecord, atomic_write_text, episode_dir_name, read_steps

__all__ = ["write_compare"]

_Key = tuple[str, int]


class _Compared:
    """The runs being compared: their names, their records and step records on the tasks they share."""

    def __init__(self, run_dirs: Sequence[str | Path]) -> None:
        from eb_core.errors import run_vocabulary
        from eb_core.report import load_run

        self.runs = [load_run(d) for d in run_dirs]
        names = [f"{r['model']} / {r['ablation']}" for r in self.runs]
        if len(set(names)) < len(names):
            names = [f"{n} ({Path(r['dir']).name})" for n, r in zip(names, self.runs)]
        self.names = names
        self.recs: list[dict[_Key, EpisodeRecord]] = [{(rec.task_id, rec.repeat): rec for rec in r["records"]}
                                                      for r in self.runs]
        self.keys = [k for k in self.recs[0] if all(k in m for m in self.recs[1:])]
        if not self.keys:
            raise ValueError("the runs share no task: compare runs of the same env and tasks (same subset=, limit=)")
        self.steps: list[dict[_Key, list[StepRecord]]] = []
        self.vocabs = []
        for r in self.runs:
            root = Path(r["dir"])
            st = {k: read_steps(root / "episodes" / episode_dir_name(*k)) for k in self.keys}
            self.steps.append(st)
            self.vocabs.append(run_vocabulary(st.values()))
        self.title = f"Comparison on {self.runs[0]['env']}: " + " vs ".join(names)

    def labels(self, key: _Key) -> list[dict[str, Any] | None]:
        """Each run's error labels of one episode (``None`` for an episode that ended in an error)."""
        from eb_core.errors import label_episode

        out = []
        for i in range(len(self.runs)):
            rec = self.recs[i][key]
            out.append(label_episode(self.steps[i][key], rec.model_dump(), self.vocabs[i]) if rec.status == "ok"
                       else None)
        return out

    def copy_images(self, key: _Key, out: Path) -> None:
        """Copy each run's step images of one episode to ``out/img/<run index>/<episode>/``."""
        page_name = episode_dir_name(*key)
        for i, r in enumerate(self.runs):
            src = Path(r["dir"]) / "episodes" / page_name
            for s in self.steps[i][key]:
                if s.image and (src / s.image).exists():
                    dst = out / "img" / str(i) / page_name / s.image
                    dst.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(src / s.image, dst)


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


def _task_page(c: _Compared, key: _Key, labels: list[dict[str, Any] | None], note: str) -> str:
    """The page of one shared task: each run's result, then the runs side by side per planner step."""
    task_id, repeat = key
    page_name = episode_dir_name(task_id, repeat)
    n_runs = len(c.runs)
    first = c.recs[0][key]
    n_steps = max(len(c.steps[i][key]) for i in range(n_runs))
    body = [f"<p><a href='../index.html'>&larr; {_e(c.title)}</a></p>",
            f"<h1>{_e(task_id)} <span class=muted>({_e(first.subset)}"
            + (f" · repeat {repeat}" if repeat else "") + ")</span></h1>",
            f"<p><b>Instruction:</b> {_e(first.instruction)}</p>"]
    if note:
        body.append(note_html(note))
    body.append(f"<div class=cmp style='grid-template-columns:repeat({n_runs},1fr)'>"
                + "".join(f"<div class=col><b>{_e(c.names[i])}</b> {_status(c.recs[i][key].model_dump())} "
                          f"<span class=muted>end {_e(c.recs[i][key].end_reason)} · "
                          f"{c.recs[i][key].planner_steps} planner steps · progress "
                          f"{100 * c.recs[i][key].progress:.0f}%</span></div>" for i in range(n_runs))
                + "</div>")
    for n in range(n_steps):
        cols = []
        for i in range(n_runs):
            s = c.steps[i][key][n] if n < len(c.steps[i][key]) else None
            lab = labels[i]
            step_lab = lab["steps"][n] if lab and s is not None and n < len(lab["steps"]) else None
            cols.append(_compare_step(s, step_lab, f"../img/{i}/{page_name}/"))
        body.append(f"<h2>Planner step {n + 1}</h2><div class=cmp style='grid-template-columns:"
                    f"repeat({n_runs},1fr)'>{''.join(cols)}</div>")
    return _page(f"{task_id} — {c.title}", "\n".join(body))


def _task_row(c: _Compared, key: _Key, labels: list[dict[str, Any] | None], cats: list[str]) -> str:
    """One shared task's row of the comparison's ``index.html``."""
    from eb_core.errors import CATEGORIES

    task_id, repeat = key
    page_name = episode_dir_name(task_id, repeat)
    first = c.recs[0][key]
    wins = [c.recs[i][key].success for i in range(len(c.runs))]
    outcome = "all succeeded" if all(wins) else "none succeeded" if not any(wins) else "they differ"
    cells = "".join(
        f"<td>{_status(c.recs[i][key].model_dump())} <span class=muted>{100 * c.recs[i][key].progress:.0f}%</span>"
        f"</td><td style='font-size:12px'>"
        + _e(", ".join(f"{CATEGORIES[k].title} {v}" for k, v in (labels[i] or {}).get("counts", {}).items()))
        + "</td>" for i in range(len(c.runs)))
    return (f"<tr data-row data-subset='{_e(first.subset)}' data-result='{outcome}' "
            f"data-errors='{_e(' '.join(cats))}'><td><a href='tasks/{_e(page_name)}.html'>"
            f"{_e(task_id + (f' (repeat {repeat})' if repeat else ''))}</a></td><td>{_e(first.subset)}</td>"
            f"{cells}<td>{_e(first.instruction)}</td></tr>")


def write_compare(run_dirs: Sequence[str | Path], out: str | Path, *, registry: Any = None) -> Path:
    """Write a comparison of several runs into ``out`` (one static folder that opens from disk):
    ``index.html`` lists the tasks the runs share with each run's result and error labels (filters: subset,
    which runs succeeded, error category); ``tasks/<task>.html`` shows the runs side by side, planner step by
    planner step, under the world's ``EnvSpec.notes`` (looked up in ``registry``, by default the installed
    plugins'). The step images are copied into ``out/img/``. Returns the path of ``index.html``."""
    from eb_core.errors import CATEGORIES

    out = Path(out)
    c = _Compared(run_dirs)
    (out / "tasks").mkdir(parents=True, exist_ok=True)
    note = world_note(str(c.runs[0]["env"]), registry)
    rows, used = [], set()
    for key in c.keys:
        labels = c.labels(key)
        c.copy_images(key, out)
        cats = sorted({k for lab in labels if lab for k in lab["counts"]})
        used |= set(cats)
        atomic_write_text(out / "tasks" / f"{episode_dir_name(*key)}.html", _task_page(c, key, labels, note))
        rows.append(_task_row(c, key, labels, cats))
    subsets = list(dict.fromkeys(c.recs[0][k].subset for k in c.keys))
    head = "".join(f"<th>{_e(n)}</th><th>error labels</th>" for n in c.names)
    summary = "".join(
        f"<tr><td>{_e(c.names[i])}</td><td>{_e(r['dir'])}</td><td class=num>"
        f"{100 * sum(c.recs[i][k].success for k in c.keys) / len(c.keys):.1f}%</td></tr>"
        for i, r in enumerate(c.runs))
    body = (f"<h1>{_e(c.title)}</h1><p class=muted>{len(c.keys)} shared episodes</p>"
            f"<table><tr><th>run</th><th>directory</th><th>success on the shared episodes</th></tr>{summary}</table>"
            "<h2>Tasks</h2>"
            + _filters(subsets, [k for k in CATEGORIES if k in used],
                       ("all succeeded", "none succeeded", "they differ"), "outcome")
            + f"<table><tr><th>task</th><th>subset</th>{head}<th>instruction</th></tr>{''.join(rows)}</table>"
            + _FILTER_JS)
    index = out / "index.html"
    atomic_write_text(index, _page(c.title, body))
    return index
