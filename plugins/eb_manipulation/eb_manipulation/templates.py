"""Our instruction templates for the five subsets (our own wording throughout).

* base: names the shape / colour directly.
* common_sense: refers to shapes, colours and spills through everyday knowledge.
* complex: wraps the base request in longer, partly irrelevant context.
* spatial: picks objects out by where they are (left/right/front/back as seen in the front image).
* visual: describes colour shades and shape features instead of naming the shape.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "COLOUR_COMMON",
    "COLOUR_VISUAL",
    "DIRECTION_TEXT",
    "SHAPE_COMMON",
    "SHAPE_VISUAL",
    "SPILLS",
    "complex_wrap",
    "pick",
]

SHAPE_COMMON: dict[str, tuple[str, ...]] = {
    "star": ("the object shaped like the things that twinkle in the night sky",
             "the object shaped like a sheriff's badge"),
    "moon": ("the object shaped like the night light that waxes and wanes each month",
             "the object shaped like a thin slice of the night sky's largest light"),
    "triangle": ("the object shaped like a slice of pizza", "the object shaped like a warning road sign"),
    "cube": ("the object shaped like a die from a board game", "the object shaped like a lump of sugar"),
    "cylinder": ("the object shaped like a can of soda", "the object shaped like a short round pillar"),
}

COLOUR_COMMON: dict[str, str] = {
    "red": "a ripe tomato",
    "maroon": "a glass of dark red wine",
    "lime": "a tennis ball",
    "green": "a pine tree",
    "blue": "a sapphire",
    "navy": "a sailor's dress uniform",
    "yellow": "a ripe banana",
    "cyan": "a shallow tropical lagoon",
    "magenta": "a fuchsia blossom",
    "silver": "a polished spoon",
    "gray": "an elephant's skin",
    "olive": "a green olive",
    "purple": "an aubergine",
    "teal": "a peacock's neck feathers",
    "azure": "a cloudless summer sky",
    "violet": "lavender flowers",
    "rose": "a flamingo",
    "black": "a lump of coal",
    "white": "fresh snow",
}

#: Shade descriptions for the visual subset (distinct within the pairs the generator lets co-occur).
COLOUR_VISUAL: dict[str, str] = {
    "red": "bright, pure red",
    "maroon": "dark brownish-red",
    "lime": "bright yellowish-green",
    "green": "deep, dark green",
    "blue": "strong, saturated blue",
    "navy": "very dark, almost black blue",
    "yellow": "sunny yellow",
    "cyan": "bright greenish-blue turquoise",
    "magenta": "vivid pinkish-purple",
    "silver": "pale metallic grey",
    "gray": "medium, flat grey",
    "olive": "dull khaki-green",
    "purple": "deep plum purple",
    "teal": "dark blue-green",
    "azure": "light sky-blue",
    "violet": "soft bluish-lilac",
    "rose": "soft pink",
    "black": "jet black",
    "white": "plain white",
}

#: Pairs of colours the visual subset may put side by side and describe apart.
VISUAL_CONTRAST: tuple[tuple[str, str], ...] = (
    ("red", "maroon"), ("red", "rose"), ("green", "lime"), ("blue", "navy"), ("azure", "navy"),
    ("gray", "white"), ("silver", "black"), ("purple", "rose"), ("teal", "lime"), ("yellow", "olive"),
)

SHAPE_VISUAL: dict[str, str] = {
    "star": "with five sharp points spread evenly around it",
    "moon": "curved like a bent banana with two pointed tips",
    "triangle": "with three straight sides and three corners",
    "cube": "with six equal square faces",
    "cylinder": "with a flat circular top and a smooth rounded side",
}

#: Spills for the common-sense wiping tasks: colour -> what was spilled.
SPILLS: dict[str, tuple[str, ...]] = {
    "maroon": ("red wine", "cold coffee"),
    "red": ("ketchup", "tomato sauce"),
    "white": ("milk", "yoghurt"),
    "purple": ("grape juice", "blackcurrant jam"),
    "yellow": ("mustard", "lemonade"),
    "olive": ("mud from a boot", "pea soup"),
    "green": ("spinach smoothie", "green paint"),
    "black": ("ink", "motor oil"),
}

DIRECTION_TEXT: dict[str, str] = {
    "left_to_right": "from left to right",
    "right_to_left": "from right to left",
    "front_to_back": "from front to back",
    "back_to_front": "from back to front",
}

DIRECTION_COMMON: dict[str, str] = {
    "left_to_right": "in the direction people read a line of English text",
    "right_to_left": "against the direction people read a line of English text",
    "front_to_back": "from the edge nearest the camera toward the robot",
    "back_to_front": "from the side nearest the robot toward the camera",
}

_CONTEXT_OPEN: tuple[str, ...] = (
    "We have visitors coming to the lab this afternoon and I want the bench to look tidy.",
    "The children were playing with the building toys all morning, so things are scattered around.",
    "I have been meaning to sort out this table since last week, but meetings kept getting in the way.",
    "The light in this corner is a little dim today and the radio is playing old jazz.",
    "Our group is recording a short video about the robot, so everything should look neat.",
    "It rained the whole night and the window by the table is still a bit foggy.",
    "My coffee went cold while I was answering emails, which happens more often than I'd like.",
    "The cleaning crew comes on Thursdays, but today is only Tuesday.",
)

_CONTEXT_CLOSE: tuple[str, ...] = (
    "After that, feel free to stay where you are.",
    "Thanks a lot, that will make the rest of my day easier.",
    "Don't worry about the other things on the table for now.",
    "We can deal with the rest of the mess later.",
    "Once that is done, the table will be ready for the next session.",
    "No need to rush, but please be careful.",
)

_CONTEXT_BRIDGE: tuple[str, ...] = (
    "Anyway, here is what I need:",
    "So here is one thing I need help with:",
    "Here is the one job for you right now:",
    "What I would like you to do is simple:",
)


def pick(rng: np.random.Generator, options) -> str:
    """A random element of ``options`` (a tuple or list)."""
    return options[int(rng.integers(len(options)))]


def complex_wrap(rng: np.random.Generator, core: str) -> str:
    """Surround a base request with unrelated context (the complex-instruction subset)."""
    opening = list(_CONTEXT_OPEN)
    first = pick(rng, opening)
    opening.remove(first)
    second = pick(rng, opening)
    return f"{first} {second} {pick(rng, _CONTEXT_BRIDGE)} {core[0].lower()}{core[1:]} {pick(rng, _CONTEXT_CLOSE)}"
