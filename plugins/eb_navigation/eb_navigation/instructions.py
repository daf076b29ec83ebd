"""Instruction templates and vocabularies for the five subsets (all our own wording).

* base / long_horizon: name the target plainly ("the fridge").
* common_sense: name it only by what it is for or a property a person knows about it.
* complex_instruction: bury the plain name in longer, partly irrelevant text.
* visual_appearance: name it only by colour and shape (same-type objects of other colours are in the room).
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["COLOUR_WORDS", "COMMON_SENSE_TYPES", "DISPLAY", "SHAPES", "colour_word", "display_name", "instruction_for"]

#: How people call the scene kit's object types (the rest: the CamelCase name split into lower-case words).
DISPLAY: dict[str, str] = {
    "Fridge": "fridge", "Television": "TV", "TVStand": "TV stand", "GarbageCan": "trash can",
    "HousePlant": "potted plant", "BasketBall": "basketball", "ArmChair": "armchair", "CounterTop": "kitchen counter",
    "WashingMachine": "washing machine", "Dresser": "chest of drawers", "SideTable": "side table",
    "CoffeeMachine": "coffee machine", "DeskLamp": "desk lamp", "FloorLamp": "floor lamp", "DiningTable": "dining table",
    "CoffeeTable": "coffee table", "TeddyBear": "teddy bear", "CellPhone": "phone", "RemoteControl": "remote control",
    "AlarmClock": "alarm clock", "SoapBottle": "soap bottle", "WineBottle": "wine bottle", "KeyChain": "key chain",
}

#: How people call the scene kit's colour names.
COLOUR_WORDS: dict[str, str] = {
    "dark_red": "dark red", "light_blue": "light blue", "dark_green": "dark green", "light_gray": "light grey",
    "dark_gray": "dark grey", "gray": "grey", "wood": "wooden", "oak": "light wooden", "walnut": "dark wooden",
    "steel": "stainless steel", "clear": "see-through",
}


def display_name(type_name: str) -> str:
    """``"GarbageCan"`` -> ``"trash can"``."""
    if type_name in DISPLAY:
        return DISPLAY[type_name]
    return re.sub(r"(?<!^)(?=[A-Z])", " ", type_name).lower()


def colour_word(colour: str) -> str:
    """``"dark_gray"`` -> ``"dark grey"``."""
    return COLOUR_WORDS.get(colour, colour.replace("_", " "))


#: Shape words for the types a visual_appearance task may target (never the type's name).
SHAPES: dict[str, str] = {
    "Fridge": "tall upright box with two stacked doors and long handles",
    "Stove": "square box with a dark glass window in its front door and knobs along the top edge",
    "Sofa": "long padded seat with a low back and armrests for three people",
    "ArmChair": "deep padded single seat with thick armrests",
    "FloorLamp": "thin pole as tall as a person with a shade on top",
    "HousePlant": "pot full of leafy green stems",
    "GarbageCan": "knee-high round bin",
    "WashingMachine": "cube with a round glass porthole in its front",
    "Bookshelf": "tall open frame of shelves filled with books",
    "Dresser": "waist-high box with rows of drawers",
    "Desk": "wide flat table top on legs, with a drawer unit",
    "Cabinet": "waist-high cupboard with doors",
    "Sink": "waist-high unit with a basin and a tap on top",
}

_BASE = (
    "Go to the {name}.",
    "Walk over to the {name} and stop next to it.",
    "Find the {name} in this room and move close to it.",
    "Head toward the {name}.",
    "Make your way to the {name}.",
    "Approach the {name} and stay near it.",
    "Your goal is the {name}: get close to it.",
    "Move until you are standing beside the {name}.",
)

#: What a thing is for, or a property everyone knows, without its name.
_COMMON_SENSE: dict[str, tuple[str, ...]] = {
    "Fridge": ("the appliance that keeps milk and vegetables cold",
               "the place where you would put leftovers so they stay fresh overnight"),
    "Microwave": ("the appliance that warms up a cup of cold coffee in under a minute",
                  "the small kitchen machine for reheating leftovers quickly"),
    "Stove": ("the thing you would put a pot of pasta water on to boil",
              "the appliance with burners for frying an egg"),
    "Sink": ("the place where you would rinse a dirty plate under running water",
             "where you would fill a glass with water from the tap"),
    "GarbageCan": ("the container where an empty crisp packet should go",
                   "the thing you would throw a banana peel into"),
    "DiningTable": ("the piece of furniture a family sits around to eat dinner",
                    "where you would set out plates and cutlery for a meal"),
    "Television": ("the screen you would switch on to watch the evening news",
                   "the device for watching a football match from the couch"),
    "Sofa": ("the piece of furniture where three people could sit side by side to watch a film",
             "the long, cushioned seat where a guest could nap in the afternoon"),
    "ArmChair": ("a cushioned seat made for exactly one person to relax in",
                 "the comfortable single seat with places to rest both elbows"),
    "FloorLamp": ("the tall standing light you would switch on to read after dark",
                  "the light fixture that stands on the floor on its own pole"),
    "HousePlant": ("the living thing in this room that needs water every few days",
                   "the thing here that grows leaves and turns toward the sunlight"),
    "Bookshelf": ("the place where you would look for a novel to read",
                  "the tall piece of furniture that holds rows of books"),
    "Desk": ("the place where someone would sit to do homework or write letters",
             "the work table where you would put a computer and a notebook"),
    "Dresser": ("the furniture whose drawers hold folded socks and sweaters",
                "where you would put away clean, folded clothes"),
    "Toilet": ("the bathroom fixture you flush",
               "the thing you sit on in the bathroom that has a water tank behind it"),
    "Bathtub": ("the place where you could lie down in warm water for a long soak",
                "where you would give a small child a bubble bath"),
    "WashingMachine": ("the machine that cleans dirty clothes",
                       "the appliance you would load with muddy socks and detergent"),
}

COMMON_SENSE_TYPES = frozenset(_COMMON_SENSE)

_COMMON_SENSE_FRAMES = (
    "Go to {desc}.",
    "Find {desc} and move close to it.",
    "Please walk over to {desc}.",
    "Navigate to {desc}.",
)

_COMPLEX = (
    "I just got home from a long day and my bag is still on my shoulder. The {other} can wait for now; what I "
    "need is for you to go over to the {name} and stay there.",
    "While you are up, could you do me a favour? Do not bother with the {other} at all. Just make your way to "
    "the {name} and stop when you are close to it.",
    "We are expecting guests later, and someone mentioned the {other} earlier, but that is not your job. Your "
    "job is simple: walk to the {name}.",
    "Before anything else, and ignoring whatever is lying on the floor, head straight to the {name}. If you "
    "pass the {other} on the way, just keep going.",
    "It has been a busy morning in this house. Somebody left the window open and the {other} is in the way as "
    "usual. Anyway, please go and stand next to the {name}.",
    "I think I left my glasses somewhere, maybe near the {other}, but never mind that for now. The thing I "
    "really need you to do is to approach the {name}.",
    "Once you have had a look around the room, skip the {other} and go to the {name}; that is the only place "
    "I need you to be right now.",
    "Here is a small errand for you. There is no need to tidy up or to touch the {other}. Simply move over to "
    "the {name} and wait beside it.",
)

_VISUAL = (
    "Go to the {colour} {shape}.",
    "Find the {shape} that is {colour} and move close to it.",
    "Walk over to the {colour} one: the {shape}.",
    "Head toward the {shape} coloured {colour}.",
    "Approach the {colour} {shape} and stop next to it.",
)


def instruction_for(subset: str, target_type: str, colour: str, rng: np.random.Generator,
                    other_type: str | None = None) -> str:
    """Write the instruction for one task from our templates (deterministic given ``rng``)."""
    name = display_name(target_type)
    if subset in ("base", "long_horizon"):
        return str(rng.choice(_BASE)).format(name=name)
    if subset == "common_sense":
        desc = str(rng.choice(_COMMON_SENSE[target_type]))
        return str(rng.choice(_COMMON_SENSE_FRAMES)).format(desc=desc)
    if subset == "complex_instruction":
        other = display_name(other_type) if other_type else "laundry"
        return str(rng.choice(_COMPLEX)).format(name=name, other=other)
    if subset == "visual_appearance":
        shape = SHAPES.get(target_type)
        if not shape:
            raise ValueError(f"object type {target_type!r} has no shape description")
        return str(rng.choice(_VISUAL)).format(colour=colour_word(colour), shape=shape)
    raise ValueError(f"unknown subset {subset!r}")
