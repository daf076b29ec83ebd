"""Prompt parts for EB-Navigation: role, action semantics, strategy, worked episodes (our wording).

The structure follows the original navigation planner: a one-line role, the numbered action list, a five-point
strategy (say where the target is; move forward and sideways rather than turning; deal with a failed move only
when it blocks the way to the target; turn one quarter at a time and only when the target is out of view; do not
stop early), three worked episodes of several planning rounds with the world's feedback, and a per-call line that
asks for about 1-2 actions on the first call and 5-6 on later ones. Every sentence is ours. The prompt is the same
for every task and subset: only the instruction differs.
"""

from __future__ import annotations

import math

from eb_core import PromptParts

from eb_navigation.geometry import AGENT_RADIUS, EYE_HEIGHT, FIRST_PERSON_FOVY

__all__ = ["ACTION_RULES_LANGUAGE_ONLY", "EXAMPLES", "FIRST_STEP_GUIDANCE", "GUIDELINES", "GUIDELINES_LANGUAGE_ONLY",
           "LATER_STEP_GUIDANCE", "ROLE", "ROLE_LANGUAGE_ONLY", "VIEW_DESCRIPTIONS", "prompt_parts"]

ROLE = (
    "You are a robot moving around a furnished room of a home. A camera at a person's eye height shows you what "
    "is in front of you. You will be given an instruction that points to one object in the room; your job is to "
    "move until you stand as close to that object as you can. You act by choosing actions from a fixed list, "
    "several at a time if you like."
)

ACTION_RULES = """\
- Moving (ids 0-3) shifts you 0.25 metres forward, backward, sideways to the right or sideways to the left, relative to the way you face. A sideways move does not change where you look.
- Turning (ids 4-5) rotates you on the spot by 90 degrees to the right or to the left: the view changes, your position does not.
- Tilting (ids 6-7) points the camera 30 degrees up or down (at most 60 down and 30 up) to see things near the floor or high up.
- A move into a wall or a piece of furniture fails and you stay where you were. After each action you learn only whether it worked.
- When an action fails, the rest of your plan is dropped: nothing after it is carried out, and you are asked for a new plan from where you stand.
- The episode ends after 20 actions in all, failed ones included. Plan a way that gets there well within that: moves that bump into things and turns that only look around use up the same budget.
- Success is measured from the centre of your body to the centre of the target object, along the floor: the episode ends by itself, as a success, once that distance is 1 metre (4 moves) or less. Beside a large object, such as the long side of a table or a sofa, its centre can still be more than 1 metre away, so keep moving toward the middle of the object until the episode ends."""

#: Metres of floor in front of the agent that the level camera does not show (its lower edge is half the vertical
#: field of view below the horizon): a calibration player walked into a low table there (session 10).
HIDDEN_FLOOR = EYE_HEIGHT / math.tan(math.radians(FIRST_PERSON_FOVY / 2))
NEAR_FLOOR_RULE = (f" With the camera level, the floor within about {HIDDEN_FLOOR:.1f} metres in front of you is "
                   "out of the picture, and a low table, stool or box just ahead of you may not show at all: tilt "
                   "the camera down to see it.")
#: The size of the body and what the camera never shows: which gaps are passable and why a sideways move can fail
#: (a calibration player lost hard tasks to gaps that looked passable and to furniture beside it; issue 25).
BODY_RULE = (f"- Your body is about {2 * AGENT_RADIUS:g} metres across: you pass between two things only where the "
             "gap is wider than that. The camera shows only what lies ahead, so a sideways or backward move can "
             "bump into something beside or behind you that no image has shown." + NEAR_FLOOR_RULE)
ACTION_RULES = ACTION_RULES.replace(
    "A sideways move does not change where you look.\n",
    "A sideways move does not change where you look.\n" + BODY_RULE + "\n", 1)
assert BODY_RULE in ACTION_RULES

GUIDELINES = (
    "Find the target in the image first and say where it is relative to you (ahead, front left, far right...) "
    "and roughly how many moves away (4 moves make 1 metre).",
    "Get there mainly with forward moves and sideways moves: any spot in front of you can be reached by "
    "combining them, so there is rarely a reason to turn while the target is in view. Plan around the "
    "furniture you see between you and the target.",
    "A failed move only matters when it stands between you and the target: if moving forward or sideways "
    "still brings you closer, keep doing that instead of fixing the failed direction.",
    "Turn only when the target is not in the image. Then plan a single 90-degree turn and nothing else, look "
    "again, and repeat until the target shows up; once it is in view, go back to moving and stop turning.",
    "Do not settle for 'near enough': keep closing in until the episode ends.",
    "Never answer with an empty plan.",
)

#: Under ``ablation=language_only`` (no image, no scene text) the prompt speaks of no camera and no image.
ROLE_LANGUAGE_ONLY = (
    "You are a robot moving around a furnished room of a home. You are given no picture and no description of "
    "the room: you know only the instruction, which points to one object in the room, and whether each of your "
    "actions worked. Your job is to move until you stand as close to that object as you can. You act by choosing "
    "actions from a fixed list, several at a time if you like."
)
ACTION_RULES_LANGUAGE_ONLY = ACTION_RULES.replace(
    "- Tilting (ids 6-7) points the camera 30 degrees up or down (at most 60 down and 30 up) to see things near the "
    "floor or high up.",
    "- Tilting (ids 6-7) only changes the view you are not given: it neither moves nor turns you.").replace(
    " The camera shows only what lies ahead, so a sideways or backward move can bump into something beside or "
    "behind you that no image has shown." + NEAR_FLOOR_RULE, "")
GUIDELINES_LANGUAGE_ONLY = (
    "You cannot see where the target is: reason from the instruction and from which of your moves worked or "
    "failed, and explore the room in a way that covers new ground instead of going back and forth.",
    "A failed move tells you a wall or a piece of furniture is that way: try another direction.",
    "Do not settle for 'near enough': keep moving until the episode ends.",
    "Never answer with an empty plan.",
)

FIRST_STEP_GUIDANCE = (
    "This is your first plan: aim for about 1-2 actions. You will not see the result of any action until the "
    "whole plan has been carried out, so plan with that in mind."
)
LATER_STEP_GUIDANCE = (
    "Aim for about 5-6 actions in this plan to get closer to the target. You will not see the result of any "
    "action until the whole plan has been carried out, so plan with that in mind."
)

#: What each image is, said by the planner when it is sent (noun phrases: the planner writes "Image 2: ...").
VIEW_DESCRIPTIONS: dict[str, str] = {
    "first_person": "your own first-person view, from the camera at your eye height",
    "overhead": ("the whole room seen from above; you are the round blue marker, and the small orange block on "
                 "its edge points the way you are facing"),
}

#: Three worked episodes (instruction, then rounds of reasoning, plan and feedback), most useful first.
EXAMPLES: tuple[str, ...] = (
    """\
Instruction: Walk over to the armchair and stop next to it.
Reasoning: The red armchair is ahead of me on the left, about 3 metres away, and nothing stands between us. A low side table is just to my left, so I will go forward before stepping left.
Plan: [0] Move forward by 0.25 meters, [0] Move forward by 0.25 meters
Feedback: both actions succeeded.
Reasoning: The armchair is closer and still ahead on the left. Forward and left moves in turn will bring me to it.
Plan: [0] Move forward, [3] Move sideways to the left, [0] Move forward, [3] Move sideways to the left, [0] Move forward, [0] Move forward
Feedback: the first five actions succeeded; the last forward move failed because something was in the way.
Reasoning: A coffee table now blocks the way forward. The armchair is still ahead on the left, so I will step left past the table and then go forward again.
Plan: [3] Move sideways to the left, [3] Move sideways to the left, [0] Move forward, [0] Move forward
Feedback: all four succeeded, and the episode ended: I am within reach of the armchair.""",
    """\
Instruction: Find the potted plant in this room and move close to it.
Reasoning: The plant stands in the far right corner, beyond a dining table that is right in front of me. I will first step right to get clear of the table.
Plan: [2] Move sideways to the right, [2] Move sideways to the right
Feedback: the first action succeeded; the second failed because something was in the way.
Reasoning: A chair stops me on the right, but I am already partly clear of the table. Going forward still brings me closer to the plant, so I will not worry about the failed move yet.
Plan: [0] Move forward, [0] Move forward, [0] Move forward, [0] Move forward, [2] Move sideways to the right
Feedback: the four forward moves succeeded; the move to the right failed.
Reasoning: The table is behind me now and the plant is ahead on the right. The chair is still at my right side, so I will go forward once more and then to the right.
Plan: [0] Move forward, [2] Move sideways to the right, [2] Move sideways to the right, [0] Move forward, [0] Move forward
Feedback: all five succeeded, and the episode ended: I am next to the plant.""",
    """\
Instruction: Go to the fridge.
Reasoning: I see a window and a chest of drawers, but no fridge. It must be to a side or behind me, so I will turn once and look again before moving.
Plan: [5] Turn left by 90 degrees
Feedback: the action succeeded.
Reasoning: Now I see a bed and a lamp, still no fridge. I will turn once more.
Plan: [5] Turn left by 90 degrees
Feedback: the action succeeded.
Reasoning: The white fridge is straight ahead, about 3 metres away, with open floor in between. I stop turning and walk to it.
Plan: [0] Move forward, [0] Move forward, [0] Move forward, [0] Move forward, [0] Move forward, [0] Move forward, [0] Move forward, [0] Move forward
Feedback: all actions succeeded, and the episode ended: I am in front of the fridge.""",
)


def prompt_parts(subset: str | None = None) -> PromptParts:
    """The same parts for every task and subset (the instruction carries the difference)."""
    from eb_navigation.visual_icl import visual_examples

    return PromptParts(role=ROLE, action_rules=ACTION_RULES, guidelines=GUIDELINES, examples=EXAMPLES,
                       first_step_guidance=FIRST_STEP_GUIDANCE, later_step_guidance=LATER_STEP_GUIDANCE,
                       view_descriptions=dict(VIEW_DESCRIPTIONS), visual_examples=visual_examples(),
                       role_language_only=ROLE_LANGUAGE_ONLY, action_rules_language_only=ACTION_RULES_LANGUAGE_ONLY,
                       guidelines_language_only=GUIDELINES_LANGUAGE_ONLY)
