"""Prompt parts for EB-Navigation: role, action semantics, strategy and worked examples (our wording).

The structure follows the paper's navigation planner (role, how the actions work, a short strategy,
three examples of instruction + JSON answer); every sentence is ours.
"""

from __future__ import annotations

import json

from eb_core import PromptParts
from eb_navigation.geometry import ACTION_NAMES

__all__ = ["prompt_parts", "EXAMPLES"]

ROLE = (
    "You are a robot standing somewhere in a furnished room of a home. Through a camera at a person's eye "
    "height you see a first-person view of what is in front of you. You will get an instruction naming an "
    "object in the room; your job is to move through the room until you are standing close to that object "
    "(within about one metre of it). You act by choosing from a fixed list of small movements, and you can "
    "plan several of them at once."
)

ACTION_RULES = """\
- Moving (ids 0-3) shifts you 0.25 metres forward, backward, sideways to the right or sideways to the left, relative to the direction you are facing. Moving sideways does not change where you look.
- Turning (ids 4-5) rotates you on the spot by 90 degrees to the right or to the left. It changes which part of the room you see; it does not move you.
- Tilting (ids 6-7) points the camera 30 degrees up or down, which helps to see things on the floor or high up. The camera can look at most 60 degrees down and 30 degrees up; tilting further fails.
- A move into a wall or a piece of furniture fails and you stay where you were. After each action the only feedback you get is whether it worked.
- The task is solved automatically as soon as you are within about 1 metre of the target object; you do not need a special action to finish."""

GUIDELINES = (
    "Look at the image first: if the target is visible, note whether it is to your left, right or straight "
    "ahead and roughly how far away it is (each move covers 0.25 m, so 1 m is 4 moves).",
    "Prefer moving over turning: when the target is ahead and a little to one side, combine forward moves with "
    "sideways moves instead of turning.",
    "Turn only when the target is not in view, and turn one step (90 degrees) at a time, then look again.",
    "If a move fails, something is in the way: step sideways around the obstacle before trying forward again.",
    "Do not stop early: keep planning until the task is solved, and after a few moves check the new image again "
    "to see whether the target is still where you expected.",
    "Never answer with an empty plan.",
)

OUTPUT_NOTES = (
    "Keep plans short when the target is not yet in view (a turn or a few moves, then look again); when it is "
    "clearly in view you may plan all the moves needed to reach it."
)


def _answer(visual: str, reasoning: str, plan_text: str, ids: list[int]) -> str:
    return json.dumps(
        {
            "visual_state_description": visual,
            "reasoning_and_reflection": reasoning,
            "language_plan": plan_text,
            "executable_plan": [{"action_id": a, "action_name": ACTION_NAMES[a]} for a in ids],
        },
        indent=None,
    )


#: Three worked examples (instruction + answer), most useful first.
EXAMPLES: tuple[str, ...] = (
    "Instruction: Walk over to the armchair and stop next to it.\n"
    "Output: "
    + _answer(
        "A wooden floor stretches ahead. A red armchair stands against the far wall, slightly to the right of the "
        "centre of the image, about 2.5 metres away. A bookshelf is on the left.",
        "The armchair is ahead and a bit to the right, so I do not need to turn. About 1.5 metres forward brings me "
        "within reach; one sideways step to the right lines me up with it.",
        "Step right once, then walk forward six times toward the armchair.",
        [2, 0, 0, 0, 0, 0, 0],
    ),
    "Instruction: Find the potted plant in this room and move close to it.\n"
    "History: action 0 (Move forward by 0.25 meters) failed: something was in the way.\n"
    "Output: "
    + _answer(
        "A low coffee table fills the bottom of the image right in front of me. Behind it and to the left, a "
        "potted plant with green leaves stands in the corner, roughly 2 metres away.",
        "My last forward move failed because the coffee table blocks the way. The plant is beyond the table on "
        "the left, so I should go around the table on its left side before moving forward again.",
        "Step left three times to clear the table, then move forward five times toward the plant.",
        [3, 3, 3, 0, 0, 0, 0, 0],
    ),
    "Instruction: Go to the fridge.\n"
    "Output: "
    + _answer(
        "I see a wall with a window and a chest of drawers. There is no fridge anywhere in this view.",
        "The fridge is not in front of me, so it must be to a side or behind me. I will turn once and look "
        "again before moving, rather than walking blindly.",
        "Turn left by 90 degrees and check the new view.",
        [5],
    ),
)


def prompt_parts(subset: str | None = None) -> PromptParts:
    """The same parts for every subset (the instruction carries the difference)."""
    return PromptParts(role=ROLE, action_rules=ACTION_RULES, guidelines=GUIDELINES, examples=EXAMPLES,
                       output_notes=OUTPUT_NOTES)
