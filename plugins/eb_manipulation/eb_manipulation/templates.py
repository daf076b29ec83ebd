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
    "TEMPLATES",
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

#: Instruction sentences per family and subset (complex reuses base inside unrelated context). Stacking has
#: groups for two- and three-cube towers. A task records which one it uses in ``metadata["template"]``.
TEMPLATES: dict[str, dict[str, tuple[str, ...] | dict[str, tuple[str, ...]]]] = {
    "pick": {
        "base": ("Pick up the {s} and put it into the {c} container.", "Put the {s} in the {c} container.",
                 "Move the {s} into the {c} container.", "Place the {s} inside the {c} container."),
        "common_sense": ("Pick up {s} and drop it into the container with the colour of {c}.",
                         "Find {s} and place it in the container that is the colour of {c}.",
                         "The container as coloured as {c} should hold {s}; please put it there."),
        "spatial": ("Pick up {o} and put it into the {c} container.", "Put {o} into the {c} container.",
                    "Move {o} over to the {c} container and drop it in."),
        "visual": ("Put the {sh} object {f} into the {cs} container.",
                   "Pick up the {sh} object {f} and place it in the {cs} container.",
                   "Find the {sh} object {f} and drop it into the {cs} container.",
                   "The {cs} container is waiting for the {sh} object {f}; move it there."),
    },
    "stack": {
        "base": {"two": ("Stack the {1} cube on top of the {0} cube.", "Put the {1} cube onto the {0} cube.",
                         "Place the {1} cube on the {0} cube."),
                 "three": ("Build a tower with the {0} cube at the bottom, the {1} cube in the middle and the {2} "
                           "cube on top.", "Stack the cubes in this order from the bottom up: {0}, {1}, {2}.")},
        "common_sense": {"two": ("Put the cube the colour of {1} on top of the cube the colour of {0}.",
                                 "Take the cube as coloured as {1} and set it on the cube as coloured as {0}."),
                         "three": ("Make a tower of three cubes: the one the colour of {0} at the bottom, then the "
                                   "one the colour of {1}, and the one the colour of {2} on top.",)},
        "spatial": {"two": ("Stack {1} on top of {0}.", "Set {1} down on {0}."),
                    "three": ("Build a tower with {0} at the bottom, {1} in the middle and {2} on top.",)},
        "visual": {"two": ("Put the {1} cube on top of the {0} cube.", "Set the {1} cube down on the {0} cube."),
                   "three": ("Stack the {0} cube first, then the {1} cube on it, then the {2} cube on top.",)},
    },
    "sorter": {
        "base": ("Put the {c} object into the shape sorter.",
                 "Insert the {c} object into its hole in the shape sorter.",
                 "Drop the {c} object into the matching hole of the shape sorter."),
        "common_sense": ("Put the object that has the colour of {c} into the shape sorter.",
                         "Find the object as coloured as {c} and slot it into the shape sorter.",
                         "Slot the object with the colour of {c} into the hole it fits in the shape sorter."),
        "spatial": ("Put {o} into the shape sorter.", "Slot {o} into its hole in the shape sorter.",
                    "Find {o} and drop it through the matching hole of the shape sorter."),
        "visual": ("Put the {sh} object {f} into the shape sorter.",
                   "Insert the {sh} object {f} into the sorting box.",
                   "Drop the {sh} object {f} through its hole in the shape sorter."),
    },
    "wipe": {
        "base": ("Wipe the {c} area {d} with the sponge.", "Use the sponge to wipe the {c} patch {d}.",
                 "Pick up the sponge and wipe the {c} area {d}."),
        "common_sense": ("Some {s} got spilled on the table. Take the sponge and wipe it up, moving {d}.",
                         "Clean the patch of {s} with the sponge, wiping {d}.",
                         "There is a patch of {s} on the table; wipe it with the sponge {d}."),
        "spatial": ("Wipe {a} {d} using the sponge.", "With the sponge, wipe {a} {d}.",
                    "Clean {a} with the sponge, moving {d}."),
    },
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
