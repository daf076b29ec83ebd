"""Tolerant parsing of the planner's JSON answer.

Models wrap JSON in code fences, put prose before it, leave trailing commas, use single quotes, put a
raw newline inside a string or write the plan as a string. We accept what a careful reader would; whatever
still fails is an output error (counted, fed back to the model, never an exception out of the episode loop).
"""

from __future__ import annotations

import ast
import json
import re
import warnings
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from eb_core.env import Action, ActionSpace, PlanItemError

__all__ = ["ParseResult", "PlannerOutput", "parse_planner_output", "extract_json_object", "think_answer"]

_FENCE = re.compile(r"```(?:json|JSON)?\s*(.*?)```", re.S)
_TRAILING_COMMA = re.compile(r",\s*([}\]])")


class PlannerOutput(BaseModel):
    """The four fields of a planner answer."""

    model_config = ConfigDict(extra="ignore")

    visual_state_description: str = ""
    reasoning_and_reflection: str = ""
    language_plan: str = ""
    executable_plan: list[Any] = Field(default_factory=list)


class ParseResult(BaseModel):
    """What the planner got out of one answer."""

    model_config = ConfigDict(arbitrary_types_allowed=True)

    output: PlannerOutput | None = None
    actions: list[Action] = Field(default_factory=list)
    """Valid actions in order, cut before the first invalid item."""
    error: str | None = None
    """Why the answer could not be used at all (an output error), else None."""
    plan_error: str | None = None
    """Why the plan was cut at ``truncated_at`` (an out-of-range id, a malformed item)."""
    truncated_at: int | None = None


def _balanced_objects(text: str, limit: int = 8) -> list[str]:
    """Top-level balanced ``{...}`` spans in order (braces inside strings ignored), at most ``limit``."""
    out: list[str] = []
    i = text.find("{")
    while i != -1 and len(out) < limit:
        depth, in_str, esc, end = 0, False, False, -1
        for j in range(i, len(text)):
            ch = text[j]
            if in_str:
                if esc:
                    esc = False
                elif ch == "\\":
                    esc = True
                elif ch == '"':
                    in_str = False
            elif ch == '"':
                in_str = True
            elif ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
                if depth == 0:
                    end = j
                    break
        if end == -1:
            break
        out.append(text[i : end + 1])
        i = text.find("{", end + 1)
    return out


def _candidates(text: str) -> list[str]:
    out = [m.group(1) for m in _FENCE.finditer(text)]
    start = text.find("{")
    if start != -1:
        out += _balanced_objects(text)
        end = text.rfind("}")
        if end > start:
            out.append(text[start : end + 1])
    out.append(text)
    return out


def _quote_fixup(chunk: str) -> str:
    """The original's repair for Claude / InternVL / Qwen answers: single quotes to double quotes (but not in
    English possessives such as "agent's "), code fences dropped."""
    fixed = chunk.replace("```json", "").replace("```", "").replace("'", '"')
    return fixed.replace('"s ', "'s ")


def _loads_lenient(chunk: str) -> Any:
    chunk = chunk.strip()
    try:
        return json.loads(chunk)
    except ValueError:
        pass
    fixed = _TRAILING_COMMA.sub(r"\1", chunk)
    try:
        # strict=False: a raw newline or tab inside a string (llama.cpp's JSON grammar lets one through; models
        # write them in long reasoning) is text to a careful reader, not a broken answer
        return json.loads(fixed, strict=False)
    except ValueError:
        pass
    if "'" in fixed and '"' not in fixed:
        try:
            return json.loads(fixed.replace("'", '"'))
        except ValueError:
            pass
    if "'" in fixed:
        try:
            return json.loads(_TRAILING_COMMA.sub(r"\1", _quote_fixup(fixed)))
        except ValueError:
            pass
        if len(fixed) < 20000 and fixed[:1] in "{[":
            try:  # a Python literal (single-quoted strings with apostrophes inside, True/None)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")  # invalid escapes in model prose
                    value = ast.literal_eval(fixed)
            except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
                pass
            else:
                if isinstance(value, (dict, list)):
                    return value
    raise ValueError("not JSON")


def extract_json_object(text: str) -> dict[str, Any] | None:
    """The JSON object in ``text`` (fenced, bare or embedded in prose), or None.

    When several objects appear (an example echoed before the answer, a schema, a draft), the first one that
    holds ``executable_plan`` wins; else the first object found.
    """
    if not isinstance(text, str):
        return None
    first: dict[str, Any] | None = None
    for chunk in _candidates(text):
        try:
            value = _loads_lenient(chunk)
        except (ValueError, RecursionError):
            continue
        if isinstance(value, dict):
            if "executable_plan" in value:
                return value
            if first is None:
                first = value
    return first


def _flatten_plan(plan: list[Any]) -> list[Any]:
    """Unwrap nested plan lists: an item that is a list of actions (lists or objects) becomes those actions.

    ``[[{"action_id": 1}, {"action_id": 2}]]`` and ``[[[3, "a"], [3, "b"]]]`` give two items each; a vector
    action ``[1, 2, 3]`` or an ``[id, name]`` pair stays one item.
    """
    out: list[Any] = []
    for item in plan:
        if isinstance(item, list) and item and all(isinstance(x, (list, dict)) for x in item):
            out += _flatten_plan(item)
        else:
            out.append(item)
    return out


_ANSWER_TAG = re.compile(r"<answer>(.*?)(?:</answer>|$)", re.DOTALL | re.IGNORECASE)


def think_answer(text: str) -> str | None:
    """The part of a ``<think>...</think><answer>...</answer>`` reply inside the answer tags (the last
    ``<answer>`` after the reasoning; a missing closing tag runs to the end), or None when there is none."""
    rest = text
    end = rest.lower().rfind("</think>")
    if end >= 0:
        rest = rest[end + len("</think>"):]
    found = _ANSWER_TAG.findall(rest)
    return found[-1] if found else None


def parse_planner_output(text: str, space: ActionSpace, max_plan_length: int = 20,
                         answer_format: str = "json") -> ParseResult:
    """Parse a model answer against the episode's action space.

    An answer with no JSON object, or without an ``executable_plan`` list, is an output error. A plan
    item that is not a valid action cuts the plan there (the paper's rule for out-of-range ids). Under
    ``answer_format="think"`` the JSON object is read only from the ``<answer>`` part.
    """
    if answer_format == "think":
        inner = think_answer(text)
        if inner is None:
            return ParseResult(error="the answer has no <answer>...</answer> part after the reasoning "
                                     "(planner.answer_format=think)")
        text = inner
    obj = extract_json_object(text)
    if obj is None:
        return ParseResult(error="the answer contains no JSON object")
    plan = obj.get("executable_plan")
    if isinstance(plan, str):
        inner = plan.strip()
        if inner == "":
            plan = []
        else:
            try:
                plan = _loads_lenient(inner)
            except ValueError:
                return ParseResult(error="executable_plan is a string that is not a JSON list")
    if plan is None:
        return ParseResult(error="the JSON object has no 'executable_plan' field")
    if isinstance(plan, dict):
        plan = [plan]
    if not isinstance(plan, list):
        return ParseResult(error=f"executable_plan must be a list, got {type(plan).__name__}")
    plan = _flatten_plan(plan)
    fields = {k: obj.get(k) for k in ("visual_state_description", "reasoning_and_reflection", "language_plan")}
    output = PlannerOutput(
        **{k: v if isinstance(v, str) else ("" if v is None else json.dumps(v)) for k, v in fields.items()},
        executable_plan=plan,
    )
    actions: list[Action] = []
    plan_error = None
    truncated_at = None
    for i, item in enumerate(plan):
        if i >= max_plan_length:
            plan_error = f"the plan has more than {max_plan_length} actions; the rest was dropped"
            truncated_at = i
            break
        try:
            actions.append(space.parse_plan_item(item))
        except PlanItemError as exc:
            plan_error = f"plan item {i + 1} is invalid ({exc}); the plan was cut there"
            truncated_at = i
            break
    return ParseResult(output=output, actions=actions, plan_error=plan_error, truncated_at=truncated_at)
