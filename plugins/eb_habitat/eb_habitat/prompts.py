"""Prompt parts for EB-Habitat, in our own words, with the paper's structure.

The ten in-context examples live in ``examples.json`` as scripted episodes (scene, instruction, and per turn
the agent's reasoning and plan). Their feedback lines are not stored: :func:`examples` replays every plan in
the symbolic world, so the examples always show exactly the feedback the env gives.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

from eb_core.env import PromptParts
from eb_habitat.skills import SKILL_NAMES
from eb_habitat.tasks import TaskSpec
from eb_habitat.world import World

__all__ = ["ACTION_RULES", "GUIDELINES", "ROLE", "examples", "prompt_parts"]

EXAMPLES_FILE = Path(__file__).parent / "examples.json"

ROLE = (
    "You control a household robot in an apartment. You receive a request from a person and must rearrange "
    "small objects to fulfil it, using only the high-level skills listed below. After every step you see a "
    "first-person picture of the receptacle in front of you and what lies on it, plus text feedback on whether "
    "your last action worked."
)

ACTION_RULES = (
    "There are five kinds of skills.\n"
    "- navigate to <receptacle>: walk to a receptacle (a counter, table, chair, the sofa, the sink, the fridge, a "
    "drawer, the cabinet...). You can only walk to receptacles, never straight to an object, so to find an object "
    "you have to visit the places where it might be and look.\n"
    "- pick up <object>: take an object of that kind from the receptacle you are standing at. Your hand must be "
    "empty, the object must lie on or in that receptacle, and a fridge, drawer or cabinet must be open first.\n"
    "- place it on/in <receptacle>: put down what you hold. You must be standing at that receptacle, and a fridge, "
    "drawer or cabinet must be open. A receptacle that is full takes nothing more.\n"
    "- open <receptacle> / close <receptacle>: only the fridge, the two kitchen drawers and the kitchen cabinet "
    "open and close, and only when you stand at them. Things inside a closed one cannot be seen or reached.\n"
    "You hold at most one object at a time."
)

GUIDELINES = (
    "Never answer with an empty plan: the episode ends at once.",
    "Plan only as far as you can see: a short plan you can check is better than a long guess.",
    "Find an object before trying to pick it up: if it is not visible where you are, navigate to other "
    "receptacles, and open closed ones to look inside.",
    "Objects of the same kind can differ in colour; read the request carefully and pick the right one.",
    "When a step fails, read the feedback, which says why, and change the plan instead of repeating it.",
    "Use the history of your actions and their feedback to avoid visiting the same empty place twice.",
    "The task is finished when every requested object is where it should be (and containers are open or closed "
    "as asked); you do not need to do anything else.",
)

OUTPUT_NOTES = (
    "Each plan item is an action id from the list together with its exact name. Actions run in order; after a "
    "failed action the rest of the plan is dropped and you are asked again with the feedback."
)


def _action(i: int) -> str:
    return json.dumps({"action_id": i, "action_name": SKILL_NAMES[i]})


def render_example(ex: dict[str, Any], number: int) -> str:
    """One scripted episode as prompt text; raises ValueError if its script does not replay as written."""
    spec = TaskSpec.model_validate(ex["scene"])
    world = World([o.model_dump() for o in spec.objects], spec.open)
    tracker = spec.tracker()
    lines = [f"Instruction: {ex['instruction']}"]
    for t, turn in enumerate(ex["turns"], 1):
        ids = [SKILL_NAMES.index(name) for name in turn["plan"]]
        answer = {
            "reasoning_and_reflection": turn["reasoning"],
            "language_plan": turn["language_plan"],
            "executable_plan": [json.loads(_action(i)) for i in ids],
        }
        lines.append(f"Planning step {t}. The robot perceives: {world.describe()}")
        lines.append("Answer: " + json.dumps(answer, ensure_ascii=False))
        lines.append("Execution:")
        for k, i in enumerate(ids):
            out = world.step(i)
            tracker.update(world)
            lines.append(f"  action id {i}, {SKILL_NAMES[i]}: {out.feedback}")
            if not out.success:
                if k != len(ids) - 1:
                    raise ValueError(f"example {number}: action {SKILL_NAMES[i]!r} fails before the end of its plan")
                break
    if not tracker.success(world):
        raise ValueError(f"example {number} ({ex['instruction']!r}) does not reach its goal")
    lines.append("The task is complete.")
    return "\n".join(lines)


@lru_cache(maxsize=1)
def _all_examples() -> tuple[tuple[str, str], ...]:
    data = json.loads(EXAMPLES_FILE.read_text(encoding="utf-8"))
    return tuple((ex["subset"], render_example(ex, i + 1)) for i, ex in enumerate(data["examples"]))


def examples(subset: str | None = None) -> tuple[str, ...]:
    """The ten examples as text (the planner numbers them), those written for ``subset`` first."""
    items = list(_all_examples())
    if subset is not None:
        items.sort(key=lambda item: item[0] != subset)  # stable: keeps the file order otherwise
    return tuple(text for _, text in items)


def prompt_parts(subset: str | None = None) -> PromptParts:
    return PromptParts(role=ROLE, action_rules=ACTION_RULES, guidelines=GUIDELINES,
                       examples=examples(subset), output_notes=OUTPUT_NOTES)
