"""The planner's JSON answer, written by the offline backends (oracle, random, human)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

from eb_core.env import Action, ActionSpace

__all__ = ["planner_answer"]

MAX_PLAN = 20


def planner_answer(space: ActionSpace, plan: Sequence[Action], *, seen: str, reasoning: str) -> str:
    """JSON text with the four fields the planner parses; the plan is cut to 20 actions."""
    items: list[dict[str, Any]] = [space.plan_item(a) for a in list(plan)[:MAX_PLAN]]
    names = [space.name_of(a) for a in list(plan)[:MAX_PLAN]]
    return json.dumps({
        "visual_state_description": seen,
        "reasoning_and_reflection": reasoning,
        "language_plan": "; ".join(names) if names else "No action.",
        "executable_plan": items,
    })
