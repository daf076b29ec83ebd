"""Automatic error analysis: every planner step and executed action labelled from the run's records.

The labels come from what the run directory already holds (``steps.jsonl``: the parsed answer, the plan
error, each action's success, the world's ``failure`` reason, the expert's next action, the objects with a box
in the image the model saw) and the episode record; never from a language model. The taxonomy and the paper
category each label maps to are documented in docs/error_analysis.md.

:func:`label_episode` labels one episode's steps; :func:`label_run` labels a whole run directory (old runs
too); :func:`perception_check` compares a visual-state description with the objects in view.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["CATEGORIES", "FAILURE_LABELS", "Category", "DRIFT_WINDOW", "label_episode", "label_run",
           "load_steps", "perception_check"]


@dataclass(frozen=True)
class Category:
    """One error label: its key, a short title, the paper's group (perception, reasoning, planning) and sub-type."""

    key: str
    title: str
    group: str
    paper: str


#: The taxonomy, in report order.
CATEGORIES: dict[str, Category] = {c.key: c for c in (
    Category("format_error", "format error", "planning", "invalid action (unusable output)"),
    Category("invalid_action", "invalid action", "planning", "invalid action"),
    Category("hallucinated_object", "hallucinated object", "perception", "hallucination"),
    Category("affordance_error", "affordance error", "planning", "inaccurate action"),
    Category("precondition_error", "precondition error", "reasoning", "inaccurate understanding of the state"),
    Category("wrong_target", "wrong target", "perception", "wrong recognition"),
    Category("collision", "collision", "planning", "collision"),
    Category("grasp_failure", "grasp failure", "planning", "inaccurate action"),
    Category("failed_action", "failed action (unclassified)", "planning", "inaccurate action"),
    Category("repetition", "repetition / loop", "reasoning", "reflection error"),
    Category("premature_stop", "premature stop / give-up", "reasoning", "wrong termination"),
    Category("missing_step", "missing step", "planning", "missing steps"),
    Category("wrong_order", "wrong order", "planning", "missing steps (order)"),
    Category("extra_step", "extra step", "planning", "inaccurate action (unneeded)"),
    Category("navigation_drift", "navigation drift", "reasoning", "spatial reasoning"),
)}

#: Allowed values of a world's ``StepResult.info["failure"]`` and the label each gives.
FAILURE_LABELS: dict[str, str] = {
    "affordance": "affordance_error",
    "precondition": "precondition_error",
    "wrong_target": "wrong_target",
    "absent": "hallucinated_object",
    "collision": "collision",
    "grasp": "grasp_failure",
}

#: Navigation drift: the distance to the goal grew over this many consecutive actions.
DRIFT_WINDOW = 3

#: Info keys read for the distance to the goal (the contract's name first; navigation's own name accepted).
DISTANCE_KEYS = ("distance_to_goal", "distance_to_target")

# Words that never name an object: verbs of the action lists, articles, places and directions.
_STOP = set("""a an the it its this that these those to of in on at into onto from with and or for by up down
off out over under near next left right middle center centre top bottom front back behind first second third
fourth last other another pick place put open close navigate go find move turn rotate step forward backward
backwards slice toggle drop hold holding held see visible there is are was be been can cannot not no none i
you my your we our robot agent image view scene camera room now currently also only some any all each one two
three four five six seven eight nine ten new same very more most less than then so as if else when where which
what who while above below beside between inside outside around degrees degree look looking appear appears
visible seen shown empty full""".split())

_COLOURS = set("""red green blue yellow orange purple pink brown black white gray grey silver gold cyan
magenta violet teal""".split())

_NEGATION = re.compile(r"\b(no|not|without|never|cannot|can't|don't|doesn't|isn't|aren't|nor)\b")


def _words(text: str) -> list[str]:
    """Lower-case words of ``text``, CamelCase split, digits and underscores dropped."""
    text = re.sub(r"([a-z])([A-Z])", r"\1 \2", str(text))
    return re.findall(r"[a-z]+", text.lower())


def _norm(text: str) -> str:
    return " ".join(_words(text))


def _singular(word: str) -> str:
    for suffix, repl in (("ies", "y"), ("ves", "f"), ("ches", "ch"), ("shes", "sh"), ("xes", "x"), ("s", "")):
        if word.endswith(suffix) and len(word) > len(suffix) + 2 and not word.endswith("ss"):
            return word[: -len(suffix)] + repl
    return word


def _term(obj: dict[str, Any]) -> str:
    """The object term of a visible object: its type, else its name, normalised, colours dropped."""
    words = [_singular(w) for w in _words(obj.get("type") or obj.get("name") or "")]
    return " ".join(w for w in words if w not in _COLOURS)


def _colours(obj: dict[str, Any]) -> set[str]:
    return {w for w in _words(f"{obj.get('type') or ''} {obj.get('name') or ''}") if w in _COLOURS}


def _action_list(prompt: str | None) -> list[str]:
    """Action names listed in a prompt (the core's ``action id i: name`` lines)."""
    return re.findall(r"^\s*action id \d+: (.+?)\s*$", prompt or "", flags=re.M)


def _content_words(text: str) -> set[str]:
    return {_singular(w) for w in _words(text) if len(w) > 2 and w not in _STOP and w not in _COLOURS}


def _mentions(text: str, terms: Iterable[str]) -> dict[str, list[str]]:
    """Object terms ``text`` names (not negated in their clause), each with the colour words just before it."""
    terms = set(terms)
    found: dict[str, list[str]] = {}
    for clause in re.split(r"[.;:!?,\n]+", text):
        for term, cols in _clause_mentions(clause, terms).items():
            found.setdefault(term, []).extend(cols)
    return found


def _clause_mentions(text: str, terms: set[str]) -> dict[str, list[str]]:
    words = [_singular(w) for w in _words(text)]
    raw = _words(text)
    found: dict[str, list[str]] = {}
    for term in sorted(set(terms), key=lambda t: -len(t.split())):
        tw = term.split()
        if not tw:
            continue
        for i in range(len(words) - len(tw) + 1):
            if words[i:i + len(tw)] != tw:
                continue
            before = " ".join(raw[max(0, i - 4):i])
            if _NEGATION.search(before):
                continue
            # a longer term already covers these words ("counter top" before "top")
            if any(term != t and term in t.split() and t in found for t in found):
                continue
            cols = [w for w in raw[max(0, i - 2):i] if w in _COLOURS]
            found.setdefault(term, []).extend(cols)
    return found


def perception_check(description: str | None, visible: Sequence[dict[str, Any]],
                     vocabulary: Iterable[str] = ()) -> dict[str, Any] | None:
    """Objects the description names against the objects with a box in the image.

    ``vocabulary``: further object terms of the scene (objects out of view), so that naming one of them counts
    as a mention too. A mention with a colour word counts only when a visible object of that type has that
    colour. Returns ``None`` when there is nothing to compare (no description, or nothing visible and nothing
    named); else ``mentioned``, ``visible``, ``correct`` (lists of terms), ``precision`` and ``recall`` (``None``
    when undefined), ``f1`` (0 when one of them is undefined: a complete miss) and ``hallucinated`` (named but
    not in view).
    """
    if not description or not str(description).strip():
        return None
    seen_terms: dict[str, set[str]] = {}
    for obj in visible:
        t = _term(obj)
        if t:
            seen_terms.setdefault(t, set()).update(_colours(obj))
    terms = set(seen_terms) | {_term({"type": v}) for v in vocabulary} - {""}
    named = _mentions(str(description), terms)
    if not named and not seen_terms:
        return None
    correct, wrong = [], []
    for term, cols in named.items():
        if term in seen_terms and (not cols or not seen_terms[term] or set(cols) <= seen_terms[term]):
            correct.append(term)
        else:
            wrong.append(term)
    precision = len(correct) / len(named) if named else None
    recall = len(correct) / len(seen_terms) if seen_terms else None
    if precision is not None and recall is not None:
        f1 = 0.0 if precision + recall == 0 else 2 * precision * recall / (precision + recall)
    else:  # nothing named while objects are in view, or objects named while none is: a complete miss
        f1 = 0.0
    return {"mentioned": sorted(named), "visible": sorted(seen_terms), "correct": sorted(correct),
            "hallucinated": sorted(wrong), "precision": precision, "recall": recall, "f1": f1}


def _label(category: str, detail: str, env_step: int | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {"category": category, "detail": detail}
    if env_step is not None:
        out["env_step"] = env_step
    return out


def _distance(action: dict[str, Any]) -> float | None:
    for key in DISTANCE_KEYS:
        value = action.get(key)
        if value is None and isinstance(action.get("info"), dict):
            value = action["info"].get(key)
        if isinstance(value, (int, float)):
            return float(value)
    return None


def _expert_name(action: dict[str, Any]) -> str | None:
    if "expert_action_name" in action and action["expert_action_name"] is not None:
        return str(action["expert_action_name"])
    if action.get("expert_action") is not None:
        return json.dumps(action["expert_action"])
    return None


def _agent_name(action: dict[str, Any]) -> str:
    return str(action.get("action_name") if action.get("action_name") is not None
               else json.dumps(action.get("action")))


def label_episode(steps: Sequence[dict[str, Any]], record: dict[str, Any] | None = None,
                  vocabulary: Iterable[str] = ()) -> dict[str, Any]:
    """Label one episode: ``{"steps": [{"planner_step", "labels": [...], "perception"}], "counts",
    "perception_score"}``.

    ``steps``: the lines of its ``steps.jsonl``; ``record``: its ``episodes.jsonl`` line (for how it ended);
    ``vocabulary``: object terms of the whole run, so a description naming an object out of view is caught.
    """
    record = record or {}
    steps = [_plain(s) for s in steps]
    vocab = set(vocabulary)
    for s in steps:
        for obj in s.get("visible_objects") or []:
            vocab.add(_term(obj))
    vocab.discard("")
    out_steps: list[dict[str, Any]] = []
    history: list[tuple[str, bool, str | None]] = []  # (action, success, failure) of every executed action
    failing: dict[str, int] = {}
    distances: list[float] = []
    f1s: list[float] = []
    last_progress = 0.0  # progress after the last executed action
    for idx, s in enumerate(steps):
        labels: list[dict[str, Any]] = []
        parsed = s.get("parsed") or {}
        actions = s.get("actions") or []
        plan = parsed.get("executable_plan") or []
        listed = _action_list(s.get("prompt"))
        is_last = idx == len(steps) - 1
        if s.get("error"):
            labels.append(_label("format_error", str(s["error"])))
        elif not plan and not actions and not s.get("plan_error"):
            if is_last and record.get("end_reason") == "empty_plan" and not record.get("success"):
                labels.append(_label("premature_stop", "the model answered an empty plan before the task was done"))
            else:
                labels.append(_label("format_error", "empty plan while the task is not done"))
        if s.get("plan_error"):
            # an invalid plan item naming an object absent from the action list and the image is a hallucination
            scene_words = set().union(*(_content_words(n) for n in listed)) if listed else set()
            for obj in s.get("visible_objects") or []:
                scene_words |= _content_words(f"{obj.get('type') or ''} {obj.get('name') or ''}")
            bad_items = [str(p.get("action_name") or "") for p in plan if isinstance(p, dict)
                         and listed and str(p.get("action_name") or "") not in listed]
            unknown = sorted({w for item in bad_items for w in _content_words(item)} - scene_words) if listed else []
            if unknown:
                labels.append(_label("hallucinated_object",
                                     f"the plan names {', '.join(unknown)}, which is not in the scene's action list"))
            else:
                labels.append(_label("invalid_action", str(s["plan_error"])))
        visible = s.get("visible_objects")
        perception = None
        if visible is not None:
            perception = perception_check(parsed.get("visual_state_description"), visible, vocab)
            if perception is not None:
                f1s.append(perception["f1"])
                if perception["hallucinated"]:
                    labels.append(_label("hallucinated_object", "the visual state description names "
                                         + ", ".join(perception["hallucinated"]) + ", not in view"))
        planned = [str(p.get("action_name")) for p in plan if isinstance(p, dict)]
        for j, a in enumerate(actions):
            name = _agent_name(a)
            ok = bool(a.get("success"))
            failure = a.get("failure")
            env_step = a.get("env_step")
            progress = float(a.get("progress") or 0.0)
            before = last_progress
            if not ok:
                if failure in FAILURE_LABELS:
                    labels.append(_label(FAILURE_LABELS[failure], str(a.get("feedback") or failure), env_step))
                else:
                    labels.append(_label("failed_action", str(a.get("feedback") or "the action failed"), env_step))
                failing[name] = failing.get(name, 0) + 1
                if failing[name] >= 2:
                    labels.append(_label("repetition", f"{name!r} failed {failing[name]} times", env_step))
            if ok and failure == "grasp":
                # executed as asked, but the grasp it was for did not happen (manipulation's empty close)
                labels.append(_label("grasp_failure", str(a.get("feedback") or "the gripper holds nothing"), env_step))
            if ok and a.get("wrong_target"):
                # the world says a successful action acted on the wrong instance (a look-alike, a wrong place)
                labels.append(_label("wrong_target", f"{name!r} succeeded on an object or place the goal does "
                                     f"not name", env_step))
            expert = _expert_name(a)
            agrees = expert is not None and expert == name  # the expert would do the same: not a loop, not drift
            dist = _distance(a)
            if ok and len(history) >= 3 and not agrees:
                # a two-action cycle (A B A B) that made no progress (and, where the world reports it, did not get
                # closer to the goal: a zig-zag towards the target is not a loop)
                a1, a2, a3 = history[-3][0], history[-2][0], history[-1][0]
                closer = dist is not None and len(distances) >= 3 and dist < distances[-3] - 1e-6
                if a1 == a3 and a2 == name and a1 != a2 and progress <= before and not closer:
                    labels.append(_label("repetition", f"cycle between {a1!r} and {a2!r}", env_step))
            if expert is not None and expert != name:
                if not ok:
                    rest = planned[planned.index(name) + 1:] if name in planned else planned[j + 1:]
                    if expert in rest:
                        labels.append(_label("wrong_order", f"{name!r} came before {expert!r}, which the expert "
                                             f"does first", env_step))
                    else:
                        labels.append(_label("missing_step", f"the expert would {expert!r} first; the plan "
                                             f"skips it", env_step))
                elif progress <= before:
                    labels.append(_label("extra_step", f"{name!r} is not needed (the expert would {expert!r}) "
                                         f"and made no progress", env_step))
            if dist is not None:
                distances.append(dist)
                last = distances[-(DRIFT_WINDOW + 1):]
                if len(last) == DRIFT_WINDOW + 1 and all(y > x for x, y in zip(last, last[1:])) and not agrees:
                    labels.append(_label("navigation_drift", f"the distance to the goal grew for {DRIFT_WINDOW} "
                                         f"actions ({last[0]:.2f} -> {last[-1]:.2f})", env_step))
            history.append((name, ok, failure))
            last_progress = progress
        if is_last and record.get("end_reason") == "done" and not record.get("success"):
            labels.append(_label("premature_stop", "the episode was ended before the task was done"))
        out_steps.append({"planner_step": s.get("planner_step", idx + 1), "labels": labels, "perception": perception})
    counts: dict[str, int] = {}
    for st in out_steps:
        for lab in st["labels"]:
            counts[lab["category"]] = counts.get(lab["category"], 0) + 1
    return {"steps": out_steps, "counts": {k: counts[k] for k in CATEGORIES if k in counts},
            "perception_score": (sum(f1s) / len(f1s)) if f1s else None}


def load_steps(ep_dir: str | Path) -> list[dict[str, Any]]:
    """The lines of ``ep_dir/steps.jsonl`` via the run reader (a torn line is skipped); [] when there is none."""
    from eb_core.records import read_steps

    return [s.as_dict() for s in read_steps(ep_dir)]


def _plain(step: Any) -> dict[str, Any]:
    """A step as its JSON line's dict, whether given as an :class:`eb_core.records.StepRecord` or a dict."""
    return step if isinstance(step, dict) else step.as_dict()


def run_vocabulary(step_sets: Iterable[Sequence[dict[str, Any]]]) -> set[str]:
    """Object terms seen in view anywhere in a run."""
    vocab: set[str] = set()
    for steps in step_sets:
        for s in map(_plain, steps):
            for obj in s.get("visible_objects") or []:
                vocab.add(_term(obj))
    vocab.discard("")
    return vocab


def label_run(run_dir: str | Path) -> dict[tuple[str, int], dict[str, Any]]:
    """Relabel every episode of a run directory from its files: ``{(task_id, repeat): labels}``."""
    from eb_core.records import RunFiles, episode_dir_name

    files = RunFiles(run_dir)
    records = files.load_episodes()
    steps = {r.key: load_steps(files.episodes_dir / episode_dir_name(*r.key)) for r in records}
    vocab = run_vocabulary(steps.values())
    return {r.key: label_episode(steps[r.key], r.model_dump(), vocab) for r in records}
