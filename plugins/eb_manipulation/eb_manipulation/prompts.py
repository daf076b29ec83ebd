"""Prompt parts for EB-Manipulation, in our own words (the paper's structure: role, action rules, guidelines,
four in-context examples per task family, answer notes).

The examples are stored in ``examples.json`` next to this file; ``python -m eb_manipulation.examples``
rebuilds them from held-out layouts with the scripted oracle (see :mod:`eb_manipulation.examples`).
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from eb_core.env import PromptParts

__all__ = ["ACTION_RULES", "GUIDELINES", "OUTPUT_NOTES", "ROLE", "prompt_parts"]

EXAMPLES_FILE = Path(__file__).parent / "examples.json"

ROLE = (
    "You control a Franka Panda robot arm with a two-finger gripper. The arm stands at the far edge of a wooden "
    "table with objects on it, and you make it carry out a person's instruction by choosing a sequence of gripper "
    "poses. You see the table through a front camera (and, if provided, a camera on the wrist). Every object in "
    "the front image has a numbered box, and its discrete coordinates are listed after the image."
)

ACTION_RULES = """Each action is a list of seven integers [x, y, z, roll, pitch, yaw, gripper].
- x, y, z (0 to 100) place the gripper's tool point, between the fingertips, in the same discrete grid as the \
object list: one step is 1 cm. Seen in the front image, x grows toward the camera, y grows to the right and z grows \
upward. The table top is at z = 15, and a listed coordinate is an object's centre (for a container or a sorter \
hole: the centre of its opening; for a marked area: its centre on the table). A red X/Y/Z frame at the robot's base \
shows the axes.
- roll, pitch, yaw (0 to 120) set the gripper's orientation in steps of 3 degrees: value v means v*3 - 180 \
degrees. roll 120 (or 0) with pitch 60 points the gripper straight down. yaw then turns it about the vertical: with \
yaw 60 the fingers close along the y axis, with yaw 90 (or 30) they close along the x axis.
- gripper is 1 to open and 0 to close. The arm first moves to the pose, then opens or closes the gripper.
- The arm plans its own path to the pose and avoids collisions. An action fails, and the arm stays where it was, \
when a value is out of range, the pose cannot be reached, the gripper would end up inside the table or an object, \
or every path would hit something.
- An object is held only when both fingers touch it as the gripper closes. A held object moves with the gripper; \
when the gripper opens, the object drops and comes to rest.
- Words like left, right, front and back in instructions mean the view of the front image: left/right = smaller/\
larger y, front = nearer the camera (larger x), back = nearer the robot (smaller x)."""

GUIDELINES = (
    "Always give at least one action: an empty plan ends the episode.",
    "An episode allows only 15 actions in total, so plan economically.",
    "Use the listed coordinates; they are more exact than what you can estimate from the image.",
    "Approach from above: go over an object with the gripper open, lower to its centre, close, and lift before "
    "moving sideways.",
    "To put something into a container or a sorter hole, hold it a few steps above the opening before you open the "
    "gripper; an object counts as sorted only when it drops through the hole of its own shape.",
    "To wipe, hold the sponge at the height where you picked it up so it touches the table, and sweep it across the "
    "whole marked area in the asked direction.",
    "Learn from the action history and the feedback: if an action failed, change the pose instead of repeating it.",
)

OUTPUT_NOTES = (
    'Each item of "executable_plan" is {"action": [x, y, z, roll, pitch, yaw, gripper]} with seven integers. The '
    "whole plan is executed in order unless the task is completed earlier."
)


@lru_cache(maxsize=1)
def _examples() -> dict[str, list[str]]:
    if not EXAMPLES_FILE.exists():
        return {}
    return json.loads(EXAMPLES_FILE.read_text())["examples"]


def prompt_parts(family: str) -> PromptParts:
    """Prompt parts for an episode of ``family`` (pick, stack, sorter or wipe)."""
    return PromptParts(role=ROLE, action_rules=ACTION_RULES, guidelines=GUIDELINES,
                       examples=tuple(_examples().get(family, ())), output_notes=OUTPUT_NOTES)
