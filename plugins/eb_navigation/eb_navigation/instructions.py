"""Instruction templates and vocabularies for the five subsets (all our own wording).

* base / long_horizon: name the target plainly ("the fridge").
* common_sense: name it only by what it is for or a property a person knows about it.
* complex_instruction: bury the plain name in longer, partly irrelevant text.
* visual_appearance: name it only by colour and shape (same-type objects of other colours are in the room).
"""

from __future__ import annotations

import numpy as np

__all__ = ["DISPLAY", "display_name", "instruction_for"]

#: How people call each object type.
DISPLAY: dict[str, str] = {
    "fridge": "fridge", "microwave": "microwave", "stove": "stove", "counter": "kitchen counter",
    "long_counter": "kitchen counter", "sink_counter": "kitchen sink", "dining_table": "dining table",
    "chair": "chair", "coffee_table": "coffee table", "sofa": "sofa", "armchair": "armchair",
    "tv_stand": "TV stand", "tv": "TV", "bookshelf": "bookshelf", "floor_lamp": "floor lamp",
    "plant": "potted plant", "ball": "ball", "teddy_bear": "teddy bear", "laptop": "laptop", "bed": "bed",
    "nightstand": "nightstand", "wardrobe": "wardrobe", "desk": "desk", "dresser": "chest of drawers",
    "toilet": "toilet", "bathtub": "bathtub", "vanity": "bathroom sink", "washing_machine": "washing machine",
    "trash_can": "trash can", "laundry_basket": "laundry basket", "boxes": "stack of cardboard boxes",
    "stool": "stool", "towel_rack": "towel rack", "rug": "rug", "small_rug": "rug",
}


def display_name(type_name: str) -> str:
    return DISPLAY.get(type_name, type_name.replace("_", " "))


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
    "fridge": ("the appliance that keeps milk and vegetables cold",
               "the place where you would put leftovers so they stay fresh overnight"),
    "microwave": ("the appliance that warms up a cup of cold coffee in under a minute",
                  "the small kitchen machine for reheating leftovers quickly"),
    "stove": ("the thing you would put a pot of pasta water on to boil",
              "the appliance with burners for frying an egg"),
    "sofa": ("the piece of furniture where three people could sit side by side to watch a film",
             "the long, cushioned seat where a guest could nap in the afternoon"),
    "armchair": ("a cushioned seat made for exactly one person to relax in",
                 "the comfortable single seat with places to rest both elbows"),
    "tv": ("the screen you would switch on to watch the evening news",
           "the device for watching a football match from the couch"),
    "floor_lamp": ("the tall standing light you would switch on to read after dark",
                   "the light fixture that stands on the floor on its own pole"),
    "plant": ("the living thing in this room that needs water every few days",
              "the thing here that grows leaves and turns toward the sunlight"),
    "ball": ("the toy you could bounce, kick or throw to a friend",
             "the round thing you would take outside for a game in the park"),
    "teddy_bear": ("the soft toy a small child might hug when going to sleep",
                   "the cuddly stuffed animal"),
    "laptop": ("the portable computer someone could use to write an email",
               "the device you would open to join a video call from home"),
    "bed": ("the place where you would sleep at night",
            "the furniture you lie down on with your head on a pillow"),
    "wardrobe": ("the tall cupboard where coats and shirts hang on hangers",
                 "the furniture for storing clothes"),
    "toilet": ("the bathroom fixture you flush",
               "the thing you sit on in the bathroom that has a water tank behind it"),
    "bathtub": ("the place where you could lie down in warm water for a long soak",
                "where you would give a small child a bubble bath"),
    "washing_machine": ("the machine that cleans dirty clothes",
                        "the appliance you would load with muddy socks and detergent"),
}

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
    from eb_navigation.catalogue import get_type

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
        shape = get_type(target_type).shape_words
        if not shape:
            raise ValueError(f"object type {target_type!r} has no shape description")
        return str(rng.choice(_VISUAL)).format(colour=colour, shape=shape)
    raise ValueError(f"unknown subset {subset!r}")
