"""Instruction templates and vocabularies for the five subsets (all our own wording).

* base / long_horizon: name the target plainly ("the fridge").
* common_sense: name it only by what it is for or a property a person knows about it.
* complex_instruction: bury the plain name in a longer, partly irrelevant request, with no signpost
  ("what I need is ...") pointing at it.
* visual_appearance: name it only by colour and shape (same-type objects of other colours are in the room).
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["COLOUR_WORDS", "COMMON_SENSE_TYPES", "DISPLAY", "SHAPES", "TEMPLATES", "article", "colour_word",
           "display_name", "instruction_for", "with_article"]

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

def article(phrase: str) -> str:
    """``"a"`` or ``"an"`` for a phrase spoken aloud (``an orange lamp``, ``a white fridge``, ``an armchair``)."""
    word = phrase.strip().split(" ", 1)[0].lower()
    if word.startswith(("uni", "use", "eu", "one")):
        return "a"
    if word.startswith(("hour", "honest")):
        return "an"
    return "an" if word[:1] in "aeiou" else "a"


def with_article(phrase: str) -> str:
    """``"orange lamp"`` -> ``"an orange lamp"``."""
    return f"{article(phrase)} {phrase}"


#: base and long_horizon: the plain name. Template ids are ``base.00`` ...
_BASE = (
    "Go to the {name}.",
    "Walk over to the {name} and stop next to it.",
    "Find the {name} in this room and move close to it.",
    "Head toward the {name}.",
    "Make your way to the {name}.",
    "Approach the {name} and stay near it.",
    "Get yourself within arm's reach of the {name}.",
    "Move until you are standing beside the {name}.",
    "Navigate to the {name}.",
    "Please go and stand by the {name}.",
    "Take me to the {name}.",
    "Your destination is the {name}; get as close to it as you can.",
)

#: What a thing is for, or a property everyone knows, without its name (the noun phrase after a frame).
_COMMON_SENSE: dict[str, tuple[str, ...]] = {
    "Fridge": ("the appliance that keeps milk and vegetables cold",
               "the place where you would put leftovers so they stay fresh overnight",
               "where a carton of juice is kept chilled"),
    "Microwave": ("the appliance that warms up a cup of cold coffee in under a minute",
                  "the small kitchen machine for reheating leftovers quickly",
                  "what you would use to make popcorn from a paper bag"),
    "Stove": ("the thing you would put a pot of pasta water on to boil",
              "the appliance with burners for frying an egg",
              "where a kettle heats up over a flame or a hot ring"),
    "Sink": ("the place where you would rinse a dirty plate under running water",
             "where you would fill a glass with water from the tap",
             "the basin where you would wash your hands"),
    "GarbageCan": ("the container where an empty crisp packet should go",
                   "the thing you would throw a banana peel into",
                   "where used paper tissues belong"),
    "DiningTable": ("the piece of furniture a family sits around to eat dinner",
                    "where you would set out plates and cutlery for a meal",
                    "the surface where a birthday cake is served to the guests"),
    "Television": ("the screen you would switch on to watch the evening news",
                   "the device for watching a football match from the couch",
                   "what the remote control is meant to operate"),
    "Sofa": ("the piece of furniture where three people could sit side by side to watch a film",
             "the long, cushioned seat where a guest could nap in the afternoon",
             "the seat a whole family could share in the evening"),
    "ArmChair": ("a cushioned seat made for exactly one person to relax in",
                 "the comfortable single seat with places to rest both elbows",
                 "the padded chair where one person could read with a cup of tea"),
    "FloorLamp": ("the tall standing light you would switch on to read after dark",
                  "the light fixture that stands on the floor on its own pole",
                  "what you would turn on when the room gets dark in the evening"),
    "HousePlant": ("the living thing in this room that needs water every few days",
                   "the thing here that grows leaves and turns toward the sunlight",
                   "what would wilt if nobody watered it for a month"),
    "Bookshelf": ("the place where you would look for a novel to read",
                  "the tall piece of furniture that holds rows of books",
                  "where an encyclopedia would most likely be stored"),
    "Desk": ("the place where someone would sit to do homework or write letters",
             "the work table where you would put a computer and a notebook",
             "where a student would spread out papers to study"),
    "Dresser": ("the furniture whose drawers hold folded socks and sweaters",
                "where you would put away clean, folded clothes",
                "the piece of bedroom furniture you open to find a clean T-shirt"),
    "Toilet": ("the bathroom fixture you flush",
               "the thing you sit on in the bathroom that has a water tank behind it",
               "the fixture with a seat and a lid that is flushed after use"),
    "Bathtub": ("the place where you could lie down in warm water for a long soak",
                "where you would give a small child a bubble bath",
                "the long basin you would fill for a relaxing soak"),
    "WashingMachine": ("the machine that cleans dirty clothes",
                       "the appliance you would load with muddy socks and detergent",
                       "what spins wet laundry round and round"),
}

COMMON_SENSE_TYPES = frozenset(_COMMON_SENSE)

_COMMON_SENSE_FRAMES = (
    "Go to {desc}.",
    "Find {desc} and move close to it.",
    "Please walk over to {desc}.",
    "Navigate to {desc}.",
    "Head for {desc}.",
    "Make your way to {desc} and stop there.",
    "Stand next to {desc}.",
    "Bring yourself close to {desc}.",
    "I would like you beside {desc}.",
    "Move toward {desc} until you are right by it.",
    "Can you get near {desc}?",
)

#: Longer requests with the plain name somewhere inside, and another object of the room mentioned in passing.
#: No signpost ("what I need is ...") points at the request.
_COMPLEX = (
    "My sister is visiting this weekend, so I have been moving things around all morning and the {other} "
    "ended up in a strange spot. I am going to rest for a bit. Go and wait by the {name} for me.",
    "The {name} is where I would like you to be when I come back from the shop; I left the {other} alone, "
    "so there is no reason to touch it, and the shopping should take about twenty minutes.",
    "We had friends over last night and the room still smells of pizza. Someone put a jacket on the {other}. "
    "Stand close to the {name} while I open the window and air the place out.",
    "After the plumber left, the floor was a mess and the {other} got pushed aside. I have swept already. "
    "Please go over to the {name}, and we will see about the rest later.",
    "It rained all afternoon, the dog tracked mud in, and I spent an hour scrubbing near the {other}. "
    "Be a dear and move next to the {name}; I will join you there once I have changed.",
    "Last week we talked about replacing the {other}, but the budget is tight this month. Walk to the {name} "
    "and stay there until I call you.",
    "I am expecting a parcel and may need to run downstairs. The {other} has nothing to do with it. If you "
    "could head over to the {name} in the meantime, that would help.",
    "Grandma phoned to say she is coming for tea, and she always complains about the {other}. Never mind "
    "her. Get yourself beside the {name} before she arrives.",
    "Since the lights flickered this morning I have been checking every corner, starting with the {other}. "
    "Go and stand by the {name} so I know where you are.",
    "Before the cleaners come on Thursday, I want to know how much space there is around the {name}, so "
    "please go there; the {other} they can deal with themselves.",
    "The kids left crayons everywhere, some of them next to the {other}. I will pick them up myself. Make "
    "your way over to the {name} and wait for me.",
    "There is a draft coming from somewhere, possibly behind the {other}, and it has bothered me all week. "
    "For now, move over to the {name} and keep out of my way while I look.",
)

_VISUAL = (
    "Go to the {colour} {shape}.",
    "Find the {shape} that is {colour} and move close to it.",
    "Walk over to the {colour} one: the {shape}.",
    "Head toward the {shape} coloured {colour}.",
    "Approach the {colour} {shape} and stop next to it.",
    "There are several of these in the room; go to the {colour} {shape}.",
    "Stand beside the {shape}, the {colour} one.",
    "Of the look-alike pieces here, get close to the {colour} {shape}.",
    "Make your way to the {colour} {shape}.",
    "Navigate to the {shape} in {colour}.",
    "Take me to the {colour} {shape}, not to the ones in other colours.",
)

TEMPLATES: dict[str, tuple[str, ...]] = {
    "base": _BASE,
    "common_sense": _COMMON_SENSE_FRAMES,
    "complex_instruction": _COMPLEX,
    "visual_appearance": _VISUAL,
    "long_horizon": _BASE,
}
"""Instruction templates per subset (long_horizon words its tasks like base); a task records ``<subset>.<index>``."""


def _fill(subset: str, k: int, target_type: str, colour: str, other_type: str | None, variant: int) -> str:
    tpl = TEMPLATES[subset][k]
    name = display_name(target_type)
    if subset in ("base", "long_horizon"):
        return tpl.format(name=name)
    if subset == "common_sense":
        descs = _COMMON_SENSE[target_type]
        return tpl.format(desc=descs[variant % len(descs)])
    if subset == "complex_instruction":
        other = display_name(other_type) if other_type else "laundry basket"
        return tpl.format(name=name, other=other)
    if subset == "visual_appearance":
        shape = SHAPES.get(target_type)
        if not shape:
            raise ValueError(f"object type {target_type!r} has no shape description")
        return tpl.format(colour=colour_word(colour), shape=shape)
    raise ValueError(f"unknown subset {subset!r}; available: {', '.join(TEMPLATES)}")


def instruction_for(subset: str, target_type: str, colour: str, rng: np.random.Generator,
                    other_type: str | None = None, used: dict[str, int] | None = None) -> tuple[str, str]:
    """One instruction and its template id (``"base.03"``) from our templates, deterministic given ``rng``.

    ``used`` counts the instructions and templates already handed out in this subset (updated here): the least
    used template that gives a new instruction wins, so a subset's wording stays varied and unique.
    """
    if subset not in TEMPLATES:
        raise ValueError(f"unknown subset {subset!r}; available: {', '.join(TEMPLATES)}")
    used = {} if used is None else used
    n = len(TEMPLATES[subset])
    order = [int(k) for k in rng.permutation(n)]
    variants = [int(v) for v in rng.permutation(3)]
    best: tuple[int, int, int] | None = None
    for k in order:
        for v in variants:
            text = _fill(subset, k, target_type, colour, other_type, v)
            key = (used.get(text, 0), used.get(f"#{k}", 0))
            if best is None or key < best[:2]:
                best = (key[0], key[1], k * 10 + v)
    assert best is not None
    k, v = divmod(best[2], 10)
    text = _fill(subset, k, target_type, colour, other_type, v)
    used[text] = used.get(text, 0) + 1
    used[f"#{k}"] = used.get(f"#{k}", 0) + 1
    tid = f"{subset}.{k:02d}"
    return text, tid
