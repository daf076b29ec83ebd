"""Prompt parts for EB-Manipulation, in our own words, on the original's protocol.

The original's structure, followed here: the text comes before the single image; the object list
("object k": [x, y, z], ordered by ascending y, re-read before every planner call) follows the instruction;
the prompt names the 19 colours objects can have; the in-context examples come from one of three sets chosen by
the run's condition (with the original's counts per family: pick 2, stack 4, sorter 4, wipe 8):

* ``baseline`` (boxes on every object, one view): wiping examples grouped, four left/right strokes first;
* ``ablation`` (any other image condition): the same examples, wiping ones alternating the stroke axis;
* ``language_only``: the baseline set without the visual description.

Visual in-context examples (``ablation=visual_icl``) are the first two of the ablation set with their front
images (rendered from this world, shipped as small PNGs in ``visual_examples/``, read on first use).
``python -m eb_manipulation.examples`` rebuilds ``examples.json`` and the PNGs.

Scenes of the harder sets where orientation or the "only" conditions matter (:func:`uses_hard_examples`) draw the
same three sets from ``examples_hard.json`` instead (``python -m eb_manipulation.examples --hard``): examples of
such scenes, whose answers turn a shape to its hole's outline, line a cube up with the one below, or stroke the way
an area's arrow points.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Literal

from eb_core.env import PromptParts, VisualExample
from eb_manipulation.shapes import COLOURS
from eb_manipulation.spec import SceneSpec

__all__ = ["ACTION_RULES", "EXAMPLE_COUNTS", "GUIDELINES", "OUTPUT_NOTES", "ROLE", "example_set", "prompt_parts",
           "uses_hard_examples"]

EXAMPLES_FILE = Path(__file__).parent / "examples.json"
HARD_EXAMPLES_FILE = Path(__file__).parent / "examples_hard.json"
VISUAL_DIR = Path(__file__).parent / "visual_examples"
#: In-context examples per family, as the original ships them.
EXAMPLE_COUNTS = {"pick": 2, "stack": 4, "sorter": 4, "wipe": 8}
#: Visual in-context examples per family (the original shows the first two, each with its image).
VISUAL_COUNT = 2

ROLE = (
    "You control a Franka Panda robot arm with a two-finger gripper. The arm stands at the far edge of a wooden "
    "table with objects on it, and you make it carry out a person's instruction by choosing a sequence of gripper "
    "poses. The image shows the table through a front camera; every object in it has a numbered box, and the "
    "object list after the instruction gives each numbered object's discrete coordinates."
)

_ACTION_RULES = f"""The object list: "object k": [x, y, z] for every object, numbered by ascending y (object 1 is \
the leftmost in the front image). It is measured again before each of your turns, so numbers and coordinates can \
change as things move.
Objects can have these colours: {", ".join(COLOURS)}.
Each action is a list of seven integers [x, y, z, roll, pitch, yaw, gripper].
- x, y, z (0 to 100) place the gripper's tool point, between the fingertips, in the same discrete grid as the \
object list: one step is 1 cm. Seen in the front image, x grows toward the camera, y grows to the right and z grows \
upward. The table top is at z = 15, and a listed coordinate is an object's centre (for a container or a sorter \
hole: the centre of its opening; for a marked area: its centre on the table). A red X/Y/Z frame at the robot's base \
shows the axes. Every box and number tag is drawn in the same white with a dark edge: it says nothing about the \
colour of the object it marks.
- roll, pitch, yaw (0 to 120) set the gripper's orientation in steps of 3 degrees: value v means v*3 - 180 \
degrees. roll 120 (or 0) with pitch 60 points the gripper straight down. yaw then turns it about the vertical: with \
yaw 60 the fingers close along the y axis, with yaw 90 (or 30) they close along the x axis. A larger yaw turns the \
gripper counter-clockwise as seen from above (and in the front image): from yaw 60, each +1 turns it by 3 degrees \
counter-clockwise, so at yaw 75 the fingers close along the diagonal from front-left to back-right.
- gripper is 1 to open and 0 to close. The arm first moves to the pose, then opens or closes the gripper.
- The arm plans its own path to the pose and avoids collisions. An action fails, and the arm stays where it was, \
when a value is out of range, the pose cannot be reached, the gripper would end up inside the table or an object, \
or every path would hit something.
- An object is held only when both fingers touch it as the gripper closes. A held object moves with the gripper; \
when the gripper opens, the object drops and comes to rest.
- The shape sorter lets a shape through only the hole of its own shape; any other hole is closed for it, and a shape \
dropped there stays on the lid.
- A wipe counts when, in one continuous stroke, the held sponge stays pressed on the table (its bottom at most 1.2 \
cm above the table top: hold it at the height where it lay) and its centre moves in the asked direction from within \
20 % of the area's length of its start edge to within 20 % of its end edge, never more than 2 cm off the area's \
sides: all of this is measured at the sponge's centre (its listed coordinate), not at its edges. A marked \
area's listed coordinates are its centre; {{area_size}}
- Feedback names objects by their numbers in the list from before that action, and adds the new number when the \
action changed it.
- Words like left, right, front and back in instructions mean the view of the front image: left/right = smaller/\
larger y, front = nearer the camera (larger x), back = nearer the robot (smaller x)."""

GUIDELINES = (
    "Always give at least one action: an empty plan ends the episode.",
    "An episode allows only 15 actions in total, so plan economically.",
    "Use the listed coordinates; they are more exact than what you can estimate from the image.",
    "Grasp from above: the open gripper goes to an object's centre, then closes; lift what you hold before "
    "carrying it past other objects.",
    "To put something into a container or a sorter hole, hold it a few steps above the opening before you open the "
    "gripper; an object counts as sorted only when it drops through the hole of its own shape.",
    "To wipe, hold the sponge at the height where you picked it up so it touches the table, and sweep it across the "
    "whole marked area in the asked direction.",
    "Learn from the action history and the feedback: if an action failed, change the pose instead of repeating it.",
    "When the instruction says to move only some objects and leave the others alone, the task fails for good as "
    "soon as another object is grasped or moved by more than 2 cm, something lands in another container, or the "
    "sponge touches another marked area.",
)

#: The size sentence of the wiping rule, per scene (marked areas of one scene all have the same size).
AREA_SIZE = ("each marked area is {long} cm long in the direction it is to be wiped and {short} cm across (the "
             "image shows its extent).")
CLASSIC_AREA = (22, 12)


#: Added to the sorter rule when the scene's hole outlines are turned (the hard set).
TURNED_HOLES = (" Here each hole's outline is drawn turned on the lid: a shape passes its own hole only when it is "
                "turned to match that outline, within {tol:g} degrees (a held object turns with the gripper); turned "
                "any other way it stays on the lid, and a shape left on the lid loses the task for good. To find the "
                "turn, compare in the image a feature of the shape (a triangle's corners, the way a moon's opening "
                "faces) with the same feature of its outline on the lid, and change the yaw by that angle while you "
                "hold it: up for counter-clockwise, down for clockwise.")
_SORTER_RULE_END = "dropped there stays on the lid."
_LIST_RENUMBERED = ("It is measured again before each of your turns, so numbers and coordinates can change as things "
                    "move.")
#: Instead of :data:`_LIST_RENUMBERED` in scenes whose objects keep their numbers for the episode.
LIST_FIXED = ("These numbers come from the first list of the episode and never change: an object keeps its number "
              "wherever it moves, in the image, the list and the feedback. Coordinates are measured again before "
              "each of your turns.")
_FEEDBACK_RENUMBERED = ("- Feedback names objects by their numbers in the list from before that action, and adds the "
                        "new number when the action changed it.")
FEEDBACK_FIXED = "- Feedback names objects by their numbers, which stay the same for the whole episode."


#: Added after the wiping rule in scenes with the hard set's sponge (as tall as a cube, listed at a shape's height).
SPONGE_LOOK = " The sponge is the yellow block with a green scouring layer on top."


def action_rules(area_cm: tuple[int, int] = CLASSIC_AREA, turned_holes: bool = False,
                 fixed_numbers: bool = False, sponge_look: bool = False) -> str:
    """The action rules, with the size of this scene's marked areas (long side along the wiping direction), for a
    sorter whose hole outlines are turned the rule that a shape must be turned to match, with ``fixed_numbers``
    that objects keep their numbers for the whole episode, and with ``sponge_look`` what the sponge looks like."""
    text = _ACTION_RULES.replace("{area_size}", AREA_SIZE.format(long=area_cm[0], short=area_cm[1])
                                 + (SPONGE_LOOK if sponge_look else ""))
    if fixed_numbers:
        text = text.replace(_LIST_RENUMBERED, LIST_FIXED).replace(_FEEDBACK_RENUMBERED, FEEDBACK_FIXED)
        text = text.replace("(object 1 is the leftmost in the front image)",
                            "(object 1 was the leftmost in the episode's first image)")
    if turned_holes:
        from eb_manipulation.spec import FIT_TOLERANCE

        text = text.replace(_SORTER_RULE_END, _SORTER_RULE_END + TURNED_HOLES.format(tol=FIT_TOLERANCE))
    return text


ACTION_RULES = action_rules()

OUTPUT_NOTES = (
    'Each item of "executable_plan" is {"action": [x, y, z, roll, pitch, yaw, gripper]} with seven integers. The '
    "whole plan is executed in order unless the task is completed earlier."
)

WRIST_VIEW = ("The second image comes from a camera on the robot's wrist, looking past the fingertips; it has no "
              "boxes or labels.")

ExampleSet = Literal["baseline", "ablation"]


@lru_cache(maxsize=2)
def _doc(hard: bool = False) -> dict:
    path = HARD_EXAMPLES_FILE if hard else EXAMPLES_FILE
    if not path.exists():
        return {"examples": {}, "visual": {}}
    return json.loads(path.read_text())


def uses_hard_examples(scene: SceneSpec) -> bool:
    """Whether a scene gets the hard example sets: a sorter with turned hole outlines, a flush tower, areas with
    arrows, or a pick with "only" conditions (the harder sets' pick scenes). Classic scenes never do."""
    g = scene.goal
    if g.family == "sorter":
        return any(o.hole_yaws for o in scene.objects)
    if g.family == "stack":
        return g.flush
    if g.family == "wipe":
        return any(o.arrow for o in scene.objects)
    return bool(g.keep_still)


def example_set(detection_boxes: str, multi_view: bool) -> ExampleSet:
    """The original uses its baseline set only with boxes on every object and a single view; any other image
    condition (target-only or no boxes, multi-view, multi-step, visual examples) gets the ablation set."""
    return "baseline" if detection_boxes == "all" and not multi_view else "ablation"


@lru_cache(maxsize=16)
def _visual(family: str, hard: bool = False) -> tuple[VisualExample, ...]:
    out = []
    for item in _doc(hard).get("visual", {}).get(family, [])[:VISUAL_COUNT]:
        out.append(VisualExample(text=item["text"], images=((VISUAL_DIR / item["image"]).read_bytes(),)))
    return tuple(out)


def prompt_parts(family: str, which: ExampleSet = "baseline", multi_view: bool = False,
                 visual: bool = True, area_cm: tuple[int, int] = CLASSIC_AREA,
                 turned_holes: bool = False, hard_examples: bool = False, fixed_numbers: bool = False,
                 sponge_look: bool = False) -> PromptParts:
    """Prompt parts for an episode of ``family`` (pick, stack, sorter or wipe) under an example set;
    ``area_cm``: (length, width) of the scene's marked areas in cm; ``turned_holes``: the sorter's hole outlines
    are turned (hard set), so a shape must be turned to match; ``hard_examples``: the examples come from the hard
    sets (:func:`uses_hard_examples`); ``fixed_numbers``: objects keep their numbers for the episode;
    ``sponge_look``: the rules say what the sponge looks like (the hard set's sponge, as tall as a cube)."""
    sets = _doc(hard_examples)["examples"].get(family, {})
    return PromptParts(
        role=ROLE, action_rules=action_rules(area_cm, turned_holes, fixed_numbers, sponge_look),
        guidelines=GUIDELINES,
        output_notes=OUTPUT_NOTES,
        examples=tuple(sets.get(which, ())), examples_language_only=tuple(sets.get("language_only", ())),
        visual_examples=_visual(family, hard_examples) if visual else (), text_before_images=True,
        view_descriptions={"wrist": WRIST_VIEW} if multi_view else {},
    )
