"""Labelling one episode, or a whole run directory, from its records.

The labels come from what the run directory holds (``steps.jsonl``: the parsed answer, the plan error, each
action's success, the world's ``failure`` reason, the expert's next action, the objects in the image the model
saw) and the episode record; never from a language model. docs/error_analysis.md states each rule.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from eb_core.errors.actions import ActionRules
from eb_core.errors.lexicon import norm, term_of
from eb_core.errors.perception import ABSENT, has_description, perception_check
from eb_core.errors.taxonomy import CATEGORIES, make_label

__all__ = ["label_episode", "label_run", "load_steps", "run_vocabulary", "scene_terms"]

_STOP = frozenset(["a", "an", "the", "it", "its", "this", "that", "to", "of", "in", "on", "at", "into", "onto", "from", "with", "and", "or", "for", "by", "up", "down", "off", "out", "over", "under", "near", "next", "left", "right", "top", "bottom", "front", "back", "behind", "pick", "place", "put", "open", "close", "navigate", "go", "find", "move", "turn", "rotate", "slice", "toggle", "drop", "hold", "see", "there", "is", "are", "be", "can", "not", "no", "you", "your", "robot", "camera", "now", "also", "some", "any", "all", "one", "two", "new", "meter", "meters", "metre", "metres", "degree", "degrees", "forward", "backward", "backwards"])


def _action_list(prompt: str | None) -> list[str]:
    """Action names listed in a prompt (the core's ``action id i: name`` lines)."""
    return re.findall(r"^\s*action id \d+: (.+?)\s*$", prompt or "", flags=re.MULTILINE)


def _content_words(text: str) -> set[str]:
    return {w for w in norm(text).split() if len(w) > 2 and w not in _STOP}


def _listed_types(steps: Sequence[dict[str, Any]]) -> tuple[set[str], set[str]]:
    """Object types an action list names (``find a SoapBar``), and those it names with an instance number
    (``find a SoapBar_2``: the scene holds at least two). ALFRED's list names every type of the world, as the
    original's does, so only the numbered ones say what this scene holds."""
    ends = (steps[0], steps[-1]) if steps else ()
    names = {n for s in ends for n in _action_list(s.get("prompt"))}
    types, numbered = set(), set()
    for n in names:
        for tok, num in re.findall(r"(?<=\s)([A-Z][A-Za-z]+)(_\d+)?\b", n):
            types.add(term_of(tok))
            if num:
                numbered.add(term_of(tok))
    return types - {""}, numbered - {""}


def scene_terms(steps: Sequence[dict[str, Any]], known: Iterable[str] = ()) -> set[str]:
    """Terms of the episode's scene: every object in view at a planner step, the types its action list numbers
    (``SoapBar_2``) and the types the world says the scene holds (``scene_objects`` of the first step)."""
    out = {term_of(o.get("type") or o.get("name") or "") for s in steps for o in s.get("visible_objects") or []}
    out |= _listed_types(steps)[1]
    out |= {term_of(t) for s in steps for t in s.get("scene_objects") or []}  # what the world says it holds
    out.discard("")
    return out


def _plain(step: Any) -> dict[str, Any]:
    """A step as its JSON line's dict, whether given as an :class:`eb_core.records.StepRecord` or a dict."""
    return step if isinstance(step, dict) else step.as_dict()


def run_vocabulary(step_sets: Iterable[Sequence[Any]]) -> set[str]:
    """Object terms in view anywhere in a run: the world's objects as far as the run shows them."""
    vocab: set[str] = set()
    for steps in step_sets:
        for s in map(_plain, steps):
            for obj in s.get("visible_objects") or []:
                vocab.add(term_of(obj.get("type") or obj.get("name") or ""))
    vocab.discard("")
    return vocab


def _plan_item_labels(s: dict[str, Any], plan: list[Any], listed: list[str]) -> list[dict[str, Any]]:
    """A plan item that is no action of the list: a hallucination when it names a word found in no action and no
    object in view ("pick up the banana" where there is none), else an invalid action."""
    scene_words = set().union(*(_content_words(n) for n in listed)) if listed else set()
    for obj in s.get("visible_objects") or []:
        scene_words |= _content_words(f"{obj.get('type') or ''} {obj.get('name') or ''}")
    bad = [str(p.get("action_name") or "") for p in plan if isinstance(p, dict)
           and listed and str(p.get("action_name") or "") not in listed]
    unknown = sorted({w for item in bad for w in _content_words(item)} - scene_words) if listed else []
    if unknown:
        return [make_label("hallucinated_object", f"the plan names {', '.join(unknown)}, which is not in the scene's "
                           "action list", words=unknown, plan_items=bad)]
    return [make_label("invalid_action", str(s["plan_error"]), plan_items=bad or None)]


def _answer_labels(s: dict[str, Any], plan: list[Any], listed: list[str], is_last: bool,
                   record: dict[str, Any]) -> list[dict[str, Any]]:
    """Labels of the answer itself: unusable, empty, or a plan item that is no action."""
    labels = []
    if s.get("error"):
        labels.append(make_label("format_error", str(s["error"]), answer=str(s.get("raw_output") or "")[:300]))
    elif not plan and not s.get("actions") and not s.get("plan_error"):
        if is_last and record.get("end_reason") == "empty_plan" and not record.get("success"):
            labels.append(make_label("premature_stop", "the model answered an empty plan before the task was done",
                                     progress=record.get("progress")))
        else:
            labels.append(make_label("format_error", "empty plan while the task is not done"))
    if s.get("plan_error"):
        labels += _plan_item_labels(s, plan, listed)
    return labels


def _perception(s: dict[str, Any], parsed: dict[str, Any], vocab: set[str], scene: set[str]
                ) -> tuple[dict[str, Any] | None, list[dict[str, Any]]]:
    visible = s.get("visible_objects")
    if visible is None or not has_description(parsed.get("visual_state_description")):
        return None, []
    p = perception_check(parsed.get("visual_state_description"), visible, vocab, scene)
    if p is None or not p["wrong"]:
        return p, []
    wrong = [e for e in p["evidence"] if e["verdict"] == "wrong"]
    # an object that is nowhere in the scene is a hallucination; a wrong colour or shape for an object that is in
    # view is a misperception of a real object (the paper's "wrong recognition"), not a hallucination
    labels = []
    for category, group in (("hallucinated_object", [e for e in wrong if e.get("why") == ABSENT]),
                            ("misperceived_object", [e for e in wrong if e.get("why") != ABSENT])):
        if group:
            detail = "; ".join(f"{e['words']!r}: {e.get('why')}" for e in group)
            labels.append(make_label(category, f"the visual state description says {detail}",
                                     words=[e["words"] for e in group], why=[e.get("why") for e in group],
                                     in_view=sorted({str(o.get("name")) for o in visible})))
    return p, labels


def label_episode(steps: Sequence[Any], record: dict[str, Any] | None = None,
                  vocabulary: Iterable[str] = ()) -> dict[str, Any]:
    """Label one episode: ``{"steps": [{"planner_step", "labels", "perception", "in_view"}], "counts",
    "perception_score"}``.

    ``steps``: its step records (:class:`~eb_core.records.StepRecord` or their dicts; ``visible_objects`` recomputed by :mod:`eb_core.errors.replay`
    for old runs); ``record``: its ``episodes.jsonl`` line (for how it ended); ``vocabulary``: object terms the
    world may have, so that a description naming one absent from this scene is recognised.
    """
    record = record or {}
    steps = [_plain(s) for s in steps]  # StepRecord or dict
    scene = scene_terms(steps)
    vocab = set(vocabulary) | run_vocabulary([steps]) | scene | _listed_types(steps)[0]
    rules = ActionRules()
    out_steps: list[dict[str, Any]] = []
    scores: list[float] = []
    for idx, s in enumerate(steps):
        parsed = s.get("parsed") or {}
        plan = parsed.get("executable_plan") or []
        is_last = idx == len(steps) - 1
        labels = _answer_labels(s, plan, _action_list(s.get("prompt")), is_last, record)
        perception, seen_labels = _perception(s, parsed, vocab, scene)
        labels += seen_labels
        if perception is not None and perception["score"] is not None:
            scores.append(perception["score"])
        planned = [str(p.get("action_name")) for p in plan if isinstance(p, dict)]
        for j, a in enumerate(s.get("actions") or []):
            labels += rules.label(a, planned, j)
        if is_last and record.get("end_reason") == "done" and not record.get("success"):
            labels.append(make_label("premature_stop", "the episode was ended before the task was done",
                                     progress=record.get("progress")))
        out_steps.append({"planner_step": s.get("planner_step", idx + 1), "labels": labels, "perception": perception,
                          "in_view": [str(o.get("name")) for o in s.get("visible_objects") or []]})
    counts: dict[str, int] = {}
    for st in out_steps:
        for lab in st["labels"]:
            counts[lab["category"]] = counts.get(lab["category"], 0) + 1
    return {"steps": out_steps, "counts": {k: counts[k] for k in CATEGORIES if k in counts},
            "perception_score": (sum(scores) / len(scores)) if scores else None}


def load_steps(ep_dir: str | Path) -> list[dict[str, Any]]:
    """The lines of ``ep_dir/steps.jsonl`` via the run reader (a torn line is skipped); [] when there is none."""
    from eb_core.records import read_steps

    return [s.as_dict() for s in read_steps(ep_dir)]


def label_run(run_dir: str | Path, replay: bool = False) -> dict[tuple[str, int], dict[str, Any]]:
    """Relabel every episode of a run directory from its files: ``{(task_id, repeat): labels}``.

    ``replay``: recompute what was in view (and the free-path distances) by replaying each episode's recorded
    actions in its world (:func:`eb_core.errors.replay.replay_run`), for runs recorded before the world filled
    ``visible_objects`` from its segmentation pixels.
    """
    from eb_core.records import RunFiles, episode_dir_name

    files = RunFiles(run_dir)
    records = files.load_episodes()
    steps = {r.key: load_steps(files.episodes_dir / episode_dir_name(*r.key)) for r in records}
    if replay:
        from eb_core.errors.replay import replay_run

        steps = replay_run(run_dir, records, steps)
    vocab = run_vocabulary(steps.values())
    return {r.key: label_episode(steps[r.key], r.model_dump(), vocab) for r in records}



