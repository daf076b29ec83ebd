"""Prompt parts for EB-Habitat, in our own words, with the original's structure.

The system prompt follows the original's order: who the robot is; one rule per skill kind saying when it is
valid; (the core adds the numbered action list); the in-context examples; the guidelines (no empty plan,
find before acting, valid actions only, no repeated failures, several instances of a kind, learn from history
and feedback; the core adds the 20-action plan limit and the exact-name rule).

The ten examples live in ``examples.json``. As in the original, each is one instruction answered in a single turn
by a ``language_plan`` and an ``executable_plan``, shown in a fixed order (the planner takes the first
``n_shot``), with no description of what the robot perceives and no list of the room's contents. Each example
also stores a scene that is never shown: :func:`examples` replays every plan in the symbolic world and refuses
an example whose plan fails a step or misses its goal.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

from eb_core.env import PromptParts
from eb_habitat.skills import SKILL_NAMES
from eb_habitat.tasks import TaskSpec

__all__ = ["ACTION_RULES", "GUIDELINES", "ROLE", "examples", "prompt_parts", "render_example"]

EXAMPLES_FILE = Path(__file__).parent / "examples.json"

ROLE = (
    "You are a household robot in an apartment. A person gives you a task, and you carry it out with the "
    "high-level actions listed below."
)

ACTION_RULES = (
    "- Navigate (\"navigate to the <receptacle>\"): walk to a receptacle: a counter, a table, a chair, the sofa, "
    "the TV stand, the sink, the fridge, a drawer or the kitchen cabinet. It always works; you can never walk "
    "straight to an object.\n"
    "- Pick (\"pick up the <object>\"): take an object of that kind from the receptacle you stand at. It works only "
    "when your hand is empty, the object lies there, and the receptacle, if it opens, is open. With several of that "
    "kind there, you get the leftmost one.\n"
    "- Place (\"place it on/in the <receptacle>\"): put the object you hold on or into a receptacle. It works only "
    "when you hold something, stand at that receptacle, it is open if it opens, and it has room left.\n"
    "- Open (\"open the <receptacle>\"): open the fridge, a kitchen drawer or the kitchen cabinet. It works only "
    "when you stand at it and it is closed. What is inside a closed one can be neither seen nor taken.\n"
    "- Close (\"close the <receptacle>\"): close one of those. It works only when you stand at it and it is open.\n"
    "You hold at most one object at a time."
)

GUIDELINES = (
    "Always answer with a plan of at least one action: an empty plan ends the episode.",
    "If the object you need is not in view, navigate to the receptacles where it may be (and open closed ones) "
    "before you try to pick it up or use it.",
    "Choose only actions whose conditions hold at that point of the plan; check the rules above for each one.",
    "Do not repeat an action or a sequence of actions that has already failed: change the plan instead.",
    "There may be several objects of the same kind, told apart by colour or by where they lie. Make sure the one "
    "you take is the one the task means; look at other receptacles if it is not here.",
    "Use the history of your actions and the feedback of the environment: when an action failed, work out why "
    "(a rule not met, a step missing) and plan around it.",
)

OUTPUT_NOTES = (
    "Each plan item is an action id from the list together with its exact name. Actions run in order; after a "
    "failed action the rest of the plan is dropped and you are asked again with the feedback. The episode ends "
    "after 30 actions, or as soon as 10 actions have failed (an answer that cannot be read counts as a failed "
    "action), so search with care."
)


def _item(name: str) -> dict[str, Any]:
    return {"action_id": SKILL_NAMES.index(name), "action_name": name}


def render_example(ex: dict[str, Any], number: int) -> str:
    """One example as prompt text; raises ValueError if its plan does not replay as written in its scene."""
    unknown = [name for name in ex["plan"] if name not in SKILL_NAMES]
    if unknown:
        raise ValueError(f"example {number}: unknown action name {unknown[0]!r}; use a name from eb_habitat.skills")
    spec = TaskSpec.model_validate(ex["scene"])
    world = spec.world()
    tracker = spec.tracker()
    for name in ex["plan"]:
        out = world.step(SKILL_NAMES.index(name))
        if not out.success:
            raise ValueError(f"example {number}: action {name!r} fails when replayed: {out.feedback}")
        tracker.update(world)
    if not tracker.success(world):
        raise ValueError(f"example {number} ({ex['instruction']!r}): its plan does not reach the goal")
    answer = {"language_plan": ex["language_plan"], "executable_plan": [_item(n) for n in ex["plan"]]}
    return f"Instruction: {ex['instruction']}\nAnswer: {json.dumps(answer, ensure_ascii=False)}"


@lru_cache(maxsize=1)
def _all_examples() -> tuple[str, ...]:
    data = json.loads(EXAMPLES_FILE.read_text(encoding="utf-8"))
    return tuple(render_example(ex, i + 1) for i, ex in enumerate(data["examples"]))


def examples(subset: str | None = None) -> tuple[str, ...]:
    """The ten examples as text, always in the file's order (the original shows the first ``n_shot``
    whatever the subset; ``subset`` is accepted for symmetry with other worlds and ignored)."""
    del subset
    return _all_examples()


def prompt_parts(subset: str | None = None) -> PromptParts:
    return PromptParts(role=ROLE, action_rules=ACTION_RULES, guidelines=GUIDELINES,
                       examples=examples(subset), output_notes=OUTPUT_NOTES)
