"""Prompt parts for EB-ALFRED (our wording, the paper's structure): role, skill rules, guidelines, examples.

The in-context examples have the original's form (instruction, then a language plan and an executable plan)
and are written from expert plans on scenes that are not among the 300 tasks (see :mod:`eb_alfred.examples`);
they are shipped in ``examples.json`` together with the scene each was written from. The general set (10) is
used for every subset except long_horizon, which has its own set (7), as in the original.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from eb_core import PromptParts

__all__ = ["ROLE", "ACTION_RULES", "GUIDELINES", "LEAVE_ALONE", "prompt_parts", "fit_example", "load_examples",
           "load_example_records", "EXAMPLES_PATH"]

EXAMPLES_PATH = Path(__file__).parent / "examples.json"

ROLE = (
    "You are a household robot in a simulated home. You are given a task in everyday language, a first-person "
    "picture of what is in front of you, and a numbered list of high-level skills. Work out a sequence of skills "
    "that completes the task and answer with it."
)

ACTION_RULES = """- "find a X": walk to X and face it. You can only act on things at the place you are standing, so find an object before you pick it up, open it, switch it or slice it. If X is inside a closed container you are taken to that container, but you cannot see or take X until you open it.
- "pick up the X": take X in your hand. You can hold one object at a time, and a closed container hides and blocks what is inside it.
- "put down the object in hand": place what you hold in or on the receptacle you last found (or the receptacle holding the object you last found). A sink takes it into its basin. A closed receptacle must be opened first, and a small receptacle only takes small things.
- "drop the object in hand": let go of what you hold; it falls on the floor where you stand.
- "open the X" / "close the X": for fridges, cabinets, drawers, microwaves, safes, boxes and laptops.
- "turn on the X" / "turn off the X": for microwaves, faucets, desk lamps and floor lamps. A microwave only runs when closed, and must be off before you open it.
- "slice the X": cut X into slices; you need a knife or butter knife in your hand.
Effects: an object is heated when the microwave it is in is switched on; cooled when the fridge it is in gets closed; washed when the faucet runs over the sink basin it is in. To examine an object in light, hold it while standing at a lamp that is on.
When a room has several things of one kind they carry number suffixes: "Cabinet" is the first cabinet, "Cabinet_2" the second, and so on. Extra instances only have their own "find" (and "open"/"close" for things that open). Every other action uses the plain name and acts on the nearest one of that kind: the one you are facing, else one you can see where you stand. So to pick up "Apple_2", use "find a Apple_2" and then "pick up the Apple"."""

GUIDELINES = (
    "Always give a non-empty plan; an empty plan ends the episode as if you were finished.",
    "Find an object before interacting with it, and open closed containers before taking things out or putting things in.",
    "You hold one object at a time: put down or drop what you hold before picking up something else.",
    "Pay attention to number suffixes (Cabinet_2, Apple_3): each one is a different instance. To act on a numbered one, find it first; the plain name then acts on it.",
    "Read the action history and the feedback on failed actions, work out what went wrong, and do not repeat a failing action unchanged.",
    "The task is checked in the end state only: for example, a heated object must still be where the task says once you are done.",
)


@lru_cache(maxsize=1)
def load_examples() -> dict[str, tuple[str, ...]]:
    data = json.loads(EXAMPLES_PATH.read_text(encoding="utf-8"))
    return {key: tuple(ex["text"] for ex in data[key]) for key in ("general", "long_horizon")}


def load_example_records() -> dict[str, list[dict]]:
    """The examples with the scene and goal each was written from (for replaying them)."""
    return json.loads(EXAMPLES_PATH.read_text(encoding="utf-8"))


LEAVE_ALONE = ("When the task says to leave other things alone, any action on one of them -- picking it up, "
               "opening, closing, switching or slicing it, or putting something in or on it -- breaks the task for "
               "good, even if you undo it later. Walking to one with 'find' and looking at it is fine: after "
               "'find a X_2' you face X_2, and it is what the centre of your view shows.")
"""The guideline added when the goal asks to leave look-alikes alone (the hard set)."""


def fit_example(text: str, ids: dict[str, int]) -> str:
    """An example with the action ids of the current room's list (``ids``: action name -> id).

    The examples were written in other rooms; an id there may name another action here (``find a Cloth_2`` in
    one room is ``find a Cabinet_3`` in another). Ids are replaced by this room's; an example with an action this
    room does not have (a numbered instance it lacks) shows action names only, without ids."""
    head, sep, answer = text.partition("\nAnswer: ")
    if not sep:
        return text
    doc = json.loads(answer)
    plan = doc.get("executable_plan", [])
    if all(step["action_name"] in ids for step in plan):
        for step in plan:
            step["action_id"] = ids[step["action_name"]]
    else:
        doc["executable_plan"] = [{"action_name": step["action_name"]} for step in plan]
    return f"{head}{sep}{json.dumps(doc)}"


def prompt_parts(subset: str, actions: list[str] | tuple[str, ...] | None = None,
                 leave_alone: bool = False) -> PromptParts:
    """The prompt parts for ``subset``; with the room's ``actions`` the examples carry this room's ids
    (:func:`fit_example`); ``leave_alone`` adds the :data:`LEAVE_ALONE` guideline."""
    examples = load_examples()
    chosen = examples["long_horizon"] if subset == "long_horizon" else examples["general"]
    if actions is not None:
        ids = {name: i for i, name in enumerate(actions)}
        chosen = tuple(fit_example(ex, ids) for ex in chosen)
    return PromptParts(
        role=ROLE,
        action_rules=ACTION_RULES,
        guidelines=GUIDELINES + ((LEAVE_ALONE,) if leave_alone else ()),
        examples=chosen,
        output_notes=("Take action ids from the current action list. The examples use this room's ids; an example "
                      "that needs a numbered thing this room lacks shows action names only. Actions run in order; "
                      "after a failed action the rest of the plan is dropped and you are asked again with the "
                      "feedback. The episode ends after 30 actions, or as soon as 10 actions have failed (an "
                      "answer that cannot be read counts as a failed action)."),
    )
