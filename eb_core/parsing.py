"""Tolerant parsing of the planner's JSON answer.

Models wrap JSON in code fences, put prose before it, leave trailing commas, use single quotes or
write the plan as a string. We accept what a careful reader would; whatever still fails is an output
error (counted, fed back to the model, never an exception out of the episode loop).
"""

from __future__ import annotations

import json
import re
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from eb_core.env import Action, ActionSpace, PlanItemError

__all__ = ["ParseResult", "PlannerOutput", "parse_planner_output", "extract_json_object"]

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


def _candidates(text: str) -> list[str]:
    out = [m.group(1) for m in _FENCE.finditer(text)]
    start = text.find("{")
    if start != -1:
        # The longest balanced object starting at the first brace, ignoring braces inside strings.
        depth, in_str, esc = 0, False, False
        for i in range(start, len(text)):
            ch = text[i]
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
                    out.append(text[start : i + 1])
                    break
        end = text.rfind("}")
        if end > start:
            out.append(text[start : end + 1])
    out.append(text)
    return out


def _loads_lenient(chunk: str) -> Any:
    chunk = chunk.strip()
    try:
        return json.loads(chunk)
    except ValueError:
        pass
    fixed = _TRAILING_COMMA.sub(r"\1", chunk)
    try:
        return json.loads(fixed)
    except ValueError:
        pass
    if "'" in fixed and '"' not in fixed:
        try:
            return json.loads(fixed.replace("'", '"'))
        except ValueError:
            pass
    raise ValueError("not JSON")


def extract_json_object(text: str) -> dict[str, Any] | None:
    """The first JSON object found in ``text`` (fenced, bare or embedded in prose), or None."""
    if not isinstance(text, str):
        return None
    for chunk in _candidates(text):
        try:
            value = _loads_lenient(chunk)
        except (ValueError, RecursionError):
            continue
        if isinstance(value, dict):
            return value
    return None


def parse_planner_output(text: str, space: ActionSpace, max_plan_length: int = 20) -> ParseResult:
    """Parse a model answer against the episode's action space.

    An answer with no JSON object, or without an ``executable_plan`` list, is an output error. A plan
    item that is not a valid action cuts the plan there (the paper's rule for out-of-range ids).
    """
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
