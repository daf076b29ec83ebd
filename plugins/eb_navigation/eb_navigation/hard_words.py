"""Instruction wording of the harder task levels (``difficulty=medium|hard``), all our own.

Every hard target is a small thing standing on the floor with look-alikes of its own type in the room, so every
instruction names the target's colour (the only thing that tells it apart); complex_instruction also mentions a
look-alike by its colour, to be left alone. Kit types and colours are turned into words by
:mod:`eb_navigation.instructions`.
"""

from __future__ import annotations

import numpy as np

from eb_navigation.instructions import colour_word, display_name

__all__ = ["HARD_ALT_NAMES", "HARD_ALT_SHAPES", "HARD_COLOUR_WORDS", "HARD_COMMON_SENSE", "HARD_SHAPES",
           "HARD_TEMPLATES", "hard_colour_word", "hard_instruction"]

#: Where a kit colour renders as another word on one type (checked against the rendered pixels in the tests):
#: the "white" wicker of the laundry hamper renders light grey (median about RGB 160 at 500 px).
HARD_COLOUR_WORDS: dict[tuple[str, str], str] = {("LaundryHamper", "white"): "light grey"}


def hard_colour_word(type_name: str, colour: str) -> str:
    """The word a hard instruction uses for a ``type_name`` of kit colour ``colour``."""
    return HARD_COLOUR_WORDS.get((type_name, colour), colour_word(colour))

#: What each hard target type is for, as a noun phrase with ``{colour}`` in it (never the type's name).
HARD_COMMON_SENSE: dict[str, tuple[str, ...]] = {
    "Vase": ("the {colour} thing you would put a bunch of cut flowers in",
             "the {colour} container that holds flowers in water"),
    "WateringCan": ("the {colour} thing you would fill to water the plants",
                    "the {colour} can with a spout for giving plants a drink"),
    "TeddyBear": ("the {colour} soft toy a small child would hug at bedtime",
                  "the {colour} cuddly toy animal"),
    "GarbageCan": ("the {colour} container where an empty crisp packet should go",
                   "the {colour} bin you would throw a banana peel into"),
    "HousePlant": ("the living thing in the {colour} pot that needs water every few days",
                   "the green leaves growing out of the {colour} pot"),
    "Ottoman": ("the {colour} padded footrest you would put your feet up on",
                "the {colour} low cushioned seat without a back"),
    "LaundryHamper": ("the {colour} container where dirty clothes wait for the wash",
                      "the {colour} tall basket for worn socks and shirts"),
}

#: Shape words for visual_appearance (no type names).
HARD_SHAPES: dict[str, str] = {
    "Vase": "slender jar about knee high with a narrow neck",
    "WateringCan": "small can with a long spout and a handle on top",
    "TeddyBear": "small stuffed animal with round ears sitting on the floor",
    "GarbageCan": "knee-high round bin",
    "HousePlant": "pot of leafy green stems",
    "Ottoman": "low padded cube you could rest your feet on",
    "LaundryHamper": "thigh-high round wicker basket with clothes in it",
}

#: A second everyday name per target type: base and long_horizon (one template list of ten) offer it as every
#: template's second wording, so a type and colour drawn more than ten times in a subset still gets a new
#: instruction (the session 11 regeneration drew eleven white trash cans among its 60 base targets).
HARD_ALT_NAMES: dict[str, str] = {
    "Vase": "flower vase",
    "WateringCan": "plant watering can",
    "TeddyBear": "toy bear",
    "GarbageCan": "bin",
    "HousePlant": "house plant",
    "Ottoman": "footstool",
    "LaundryHamper": "hamper",
}

#: A second shape description per type, for visual_appearance's text when all ten of its templates have already
#: given this type and colour's words in the subset (the session 11 set repeated "Go to the white knee-high round
#: bin." once): only such a repeat changes, the template and every other text stay as drawn.
HARD_ALT_SHAPES: dict[str, str] = {
    "Vase": "tall jar with a narrow neck standing on the floor",
    "WateringCan": "can with a handle over the top and a long thin spout",
    "TeddyBear": "soft toy with round ears sitting on the floor",
    "GarbageCan": "round open-topped container about knee high",
    "HousePlant": "pot with green leaves growing out of it",
    "Ottoman": "low cushioned block about shin high",
    "LaundryHamper": "round woven basket about thigh high holding clothes",
}

_BASE = (
    "Go to the {colour} {name}.",
    "Walk over to the {colour} {name} and stop next to it.",
    "Find the {colour} {name} and move close to it; the others do not count.",
    "Head toward the {name} that is {colour}.",
    "Make your way to the {colour} {name}.",
    "Get yourself within arm's reach of the {colour} {name}.",
    "Navigate to the {colour} {name}, not to one of another colour.",
    "Please go and stand by the {colour} {name}.",
    "Only the {colour} {name} counts: go to it.",
    "Your destination is the {colour} {name}.",
)

_COMMON_SENSE_FRAMES = (
    "Go to {desc}.",
    "I would like you beside {desc}.",
    "Bring yourself close to {desc}.",
    "Find {desc} and move close to it.",
    "Please walk over to {desc}.",
    "Navigate to {desc}.",
    "Head for {desc}.",
    "Make your way to {desc} and stop there.",
    "Stand next to {desc}.",
    "Can you get near {desc}?",
)

#: The plain name with its colour, inside a longer request that also names a look-alike of another colour.
_COMPLEX = (
    "I bought a {other_colour} {name} last week and I already regret it, so never mind that one. "
    "Please go and wait by the {colour} {name} while I make some tea.",
    "The {other_colour} {name} belongs to my neighbour and she is picking it up later. The {colour} {name} is "
    "ours: stand next to it until I call you.",
    "We have more than one {name} in here. Not the {other_colour} one; I mean the {colour} {name}. Go over to it "
    "and stay there.",
    "My brother keeps moving the {other_colour} {name} around, which drives me mad, but leave it. What I want is "
    "for you to get close to the {colour} {name}.",
    "Before the guests arrive I want to check the {colour} {name}. Go there first; the {other_colour} {name} is "
    "for tomorrow.",
    "Whatever you do, keep away from the {other_colour} {name}. Walk over to the {colour} {name} and wait there.",
    "I keep mixing them up, but today I need the {colour} {name}, not the {other_colour} one. Please go to it.",
    "The cat knocked over the {other_colour} {name} last night, but that is sorted now. Make your way to the "
    "{colour} {name} and wait for me.",
    "Someone said the {other_colour} {name} was the one I meant. It is not: walk to the {colour} {name}.",
    "Of the {name}s here, not the {other_colour} one: the {colour} one is where I need you; go there.",
)

_VISUAL = (
    "Go to the {colour} {shape}.",
    "Find the {shape} that is {colour} and move close to it.",
    "There are several of these here; go to the {colour} {shape}.",
    "Approach the {colour} {shape} and stop next to it.",
    "Stand beside the {shape}, the {colour} one.",
    "Make your way to the {colour} {shape}, not to the ones in other colours.",
    "Of the look-alike pieces here, get close to the {colour} {shape}.",
    "Navigate to the {shape} in {colour}.",
    "Walk over to the {colour} one: the {shape}.",
    "Head toward the {shape} coloured {colour}.",
)

HARD_TEMPLATES: dict[str, tuple[str, ...]] = {
    "base": _BASE,
    "common_sense": _COMMON_SENSE_FRAMES,
    "complex_instruction": _COMPLEX,
    "visual_appearance": _VISUAL,
    "long_horizon": _BASE,
}


def _fill(subset: str, k: int, type_name: str, colour: str, other_colour: str, variant: int) -> str:
    tpl = HARD_TEMPLATES[subset][k]
    name = display_name(type_name)
    c, oc = hard_colour_word(type_name, colour), hard_colour_word(type_name, other_colour)
    if subset in ("base", "long_horizon"):
        return tpl.format(name=HARD_ALT_NAMES.get(type_name, name) if variant else name, colour=c)
    if subset == "common_sense":
        descs = HARD_COMMON_SENSE[type_name]
        return tpl.format(desc=descs[variant % len(descs)].format(colour=c))
    if subset == "complex_instruction":
        return tpl.format(name=name, colour=c, other_colour=oc)
    if subset == "visual_appearance":
        return tpl.format(colour=c, shape=(HARD_ALT_SHAPES if variant >= 2 else HARD_SHAPES)[type_name])
    raise ValueError(f"unknown subset {subset!r}; available: {', '.join(HARD_TEMPLATES)}")


def hard_instruction(subset: str, type_name: str, colour: str, other_colour: str, rng: np.random.Generator,
                     used: dict[str, int]) -> tuple[str, str]:
    """One instruction and its template id (``"base.03"``): the least used template giving a new text wins."""
    n = len(HARD_TEMPLATES[subset])
    best: tuple[int, int, int, int] | None = None
    for k in [int(v) for v in rng.permutation(n)]:
        for v in (0, 1):
            text = _fill(subset, k, type_name, colour, other_colour, v)
            key = (used.get(text, 0), used.get(f"#{k}", 0))
            if best is None or key < best[:2]:
                best = (key[0], key[1], k, v)
    assert best is not None
    _, _, k, v = best
    text = _fill(subset, k, type_name, colour, other_colour, v)
    if used.get(text, 0) and subset == "visual_appearance":  # every template's words taken: the other shape words
        text = _fill(subset, k, type_name, colour, other_colour, 2)
    used[text] = used.get(text, 0) + 1
    used[f"#{k}"] = used.get(f"#{k}", 0) + 1
    return text, f"{subset}.{k:02d}"
