"""One episode's page of the viewer (``episodes/<id>/index.html``): each planner step with what the model was
sent, its answer, the parsed plan, every executed action with the world's feedback and the step's error labels,
then how the episode ended. A world's ``EnvSpec.notes`` is shown at the top."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from eb_core._html_parts import _e, _invalid_text, _labels_html, _page, _status
from eb_core.records import StepRecord, read_steps

#: Inline style of a world's note (inline, so that pages of worlds without one keep their exact bytes).
_NOTE_STYLE = ("background:#eef4ff;border:1px solid #b9cdf5;border-radius:6px;padding:8px 12px;font-size:13px;"
               "max-width:900px")


def world_note(env_name: str, registry: Any = None) -> str:
    """The ``notes`` of the world ``env_name`` from its ``EnvSpec`` (``""`` when it has none, or when the plugin
    that provides it is not installed here: the viewer still opens old runs of an uninstalled world).

    ``registry`` is an :class:`eb_core.plugins.Registry`; by default the installed plugins'.
    """
    from eb_core.plugins import PluginError, Registry

    if registry is None:
        try:
            registry = Registry.create()
        except PluginError:  # a broken plugin elsewhere must not keep a run's pages from being written
            return ""
    spec = registry.envs.get(env_name)
    return spec.notes if spec is not None else ""


def note_html(note: str) -> str:
    """A world's note as a paragraph (escaped); nothing when there is none."""
    if not note:
        return ""
    return f"<p style='{_NOTE_STYLE}'><b>About this world:</b> {_e(note)}</p>"


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


def _step_images(s: StepRecord, conf: dict[str, Any]) -> str:
    """The left column of a step: its image(s) and a line saying what the model was sent, marked when the
    picture was not sent to the model."""
    sent, what = _what_was_sent(s, conf)
    seen = "what the model saw" if sent else "the scene (not sent to the model)"
    img = (f"<img src='{_e(s.image)}' alt='{seen} at step {s.planner_step}'>" if s.image else "")
    for extra in s.extra_images or []:
        img += f"<img src='{_e(extra)}' alt='extra view {_e(extra)}'>"
    if img and sent:
        return (f"<div style='display:flex;flex-direction:column;gap:6px;width:300px;flex:none'>"
                f"<p class=sent>{_e(what)}</p>{img}</div>")
    if img:
        return (f"<div class=notsent style='display:flex;flex-direction:column;gap:6px;width:300px;flex:none'>"
                f"<p class=tag>NOT SENT TO THE MODEL</p><p class=sent>{_e(what)} The picture is for you.</p>"
                f"{img}</div>")
    return f"<div style='width:300px;flex:none'><p class=sent>{_e(what)}</p></div>"


def _actions_table(s: StepRecord) -> str:
    """The actions a planner step executed, with their result and the world's feedback ("" when none)."""
    actions = "".join(
        f"<tr><td class=num>{a.env_step}</td><td>{_e(a.action_name)}</td>"
        f"<td>{'<span class=ok>ok</span>' if a.success else '<span class=fail>failed</span>'}</td>"
        f"<td>{_e(a.feedback)}</td></tr>" for a in s.actions)
    if not actions:
        return ""
    return f"<table><tr><th>step</th><th>action</th><th>result</th><th>feedback</th></tr>{actions}</table>"


def _step_errors(s: StepRecord) -> str:
    """The step's output error and plan error, if any."""
    notes = ""
    if s.error:
        notes += f"<p class=err>Output error: {_e(s.error)}</p>"
    if s.plan_error:
        notes += f"<p class=err>{_e(s.plan_error)}</p>"
    return notes


def _step_html(s: StepRecord, conf: dict[str, Any], step_labels: dict[str, Any] | None) -> str:
    """One planner step of an episode page."""
    parsed = s.parsed
    return (f"<div class=step>{_step_images(s, conf)}<div class=body><b>Planner step {s.planner_step}</b>"
            + _labels_html(step_labels)
            + _step_errors(s)
            + (f"<p><b>Reasoning:</b> {_e(parsed.reasoning_and_reflection)}</p>"
               f"<p><b>Plan:</b> {_e(parsed.language_plan)}</p>" if parsed else "")
            + _actions_table(s)
            + f"<details><summary>raw model answer</summary><pre>{_e(s.raw_output)}</pre></details>"
            + f"<details><summary>prompt</summary><pre>{_e(s.prompt)}</pre></details>"
            + "</div></div>")


def episode_page(run_title: str, rec: dict[str, Any], ep_dir: Path, conf: dict[str, Any] | None = None,
                 labels: dict[str, Any] | None = None, note: str = "") -> str:
    """The whole page of one episode; ``note`` is the world's ``EnvSpec.notes``."""
    conf = conf or {}
    by_step = {st["planner_step"]: st for st in (labels or {}).get("steps", [])}
    repeat = f" · repeat {rec['repeat']}" if rec.get("repeat") else ""
    parts = [f"<p><a href='../../index.html'>&larr; {_e(run_title)}</a></p>",
             f"<h1>{_e(rec['task_id'])} <span class=muted>({_e(rec['subset'])}{repeat})</span> {_status(rec)}</h1>",
             f"<p><b>Instruction:</b> {_e(rec['instruction'])}</p>",
             f"<p class=muted>end: {_e(rec['end_reason'])} · env steps {rec['env_steps']} · planner steps "
             f"{rec['planner_steps']} · {_invalid_text(rec, labels)} · output errors {rec['output_errors']}"
             f" · progress {100 * rec['progress']:.0f}% · tokens {rec['prompt_tokens']}+{rec['completion_tokens']}</p>"]
    if note:
        parts.append(note_html(note))
    if rec.get("error"):
        parts.append(f"<h2>Error</h2><pre>{_e(rec['error'])}</pre>")
    steps = read_steps(ep_dir)
    for s in steps:
        parts.append(_step_html(s, conf, by_step.get(s.planner_step)))
    parts += _ending_html(ep_dir, steps)
    return _page(f"{rec['task_id']} — {run_title}", "\n".join(parts))


def _walk_svg(steps: list[Any]) -> str:
    """A small map of the agent's walk (recorded ``position`` per action) and its distance to the target."""
    recorded = [(a.model_extra or {}).get("position") for s in steps for a in s.actions]
    dist = [a.distance_to_goal for s in steps for a in s.actions]
    pts: list[Any] = [p for p in recorded if isinstance(p, (list, tuple)) and len(p) == 2]
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
            "fill='#b42318'></circle></svg><figcaption class=muted>The walk seen from above (north up): green after "
            "the "
            f"first action, red at the end; {span:.1f} m across.</figcaption></figure>")
    known = [d for d in dist if d is not None]
    if known:
        top = max(max(known), 1.0)
        w = 260 / max(1, len(dist) - 1)
        line = " ".join(f"{i * w:.1f},{110 - 100 * d / top:.1f}" for i, d in enumerate(dist) if d is not None)
        out.append(
            "<figure style='margin:0'><svg width=270 height=120 style='background:#fff;border:1px solid #dde1e6'>"
            f"<polyline points='{line}' fill='none' stroke='#a15c00' stroke-width='2'></polyline></svg>"
            "<figcaption class=muted>"
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
