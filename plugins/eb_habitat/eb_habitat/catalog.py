"""What exists in an EB-Habitat apartment: receptacles, small object types and their colour variants.

This is data only (no simulator). The 70 skills in :mod:`eb_habitat.skills` are derived from it, so the
order of :data:`RECEPTACLES` and :data:`OBJECT_TYPES` is part of the benchmark and must never change.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = [
    "COLORS",
    "DECOR",
    "FRIDGE_END",
    "HARD_COLORS",
    "KITCHEN_ROWS",
    "KITCHEN_SIDE_CHAIR",
    "N_APARTMENTS",
    "OBJECT_TYPES",
    "RECEPTACLES",
    "ObjectType",
    "Receptacle",
    "WIDE_CAPACITY",
    "allowed_colors",
    "capacity",
    "object_type",
    "receptacle",
]


N_APARTMENTS = 3
"""Apartment layouts (furniture placement, colours); the receptacle set and the skills are the same in all."""

KITCHEN_ROWS: tuple[tuple[str, ...], ...] = (
    ("fridge", "cabinet", "left_counter", "sink", "right_counter"),
    ("left_counter", "sink", "right_counter", "cabinet", "fridge"),
    ("fridge", "left_counter", "sink", "right_counter", "cabinet"),
)
"""Per apartment, the kitchen row from left to right as seen facing it. The order differs in every apartment;
the counters always flank the sink (the left counter is left of it), so their names stay true.
:mod:`eb_habitat.render` builds the rows from this."""

FRIDGE_END: tuple[str, ...] = tuple("left" if row.index("fridge") < row.index("sink") else "right"
                                    for row in KITCHEN_ROWS)
"""Per apartment, the side of the sink the fridge is on: "the counter nearer to the fridge" is the left counter
where this is ``left``."""

KITCHEN_SIDE_CHAIR: tuple[str, ...] = ("left_chair", "right_chair", "left_chair")
"""Per apartment, the dining chair on the side of the table that faces the kitchen (the renderer checks it)."""


@dataclass(frozen=True)
class Receptacle:
    """A place the agent can walk to and put things on (``surface``) or into (``container``)."""

    key: str
    """Identifier used in goals and task files, e.g. ``left_counter``."""
    name: str
    """Display name used in action names and feedback, e.g. ``left counter``."""
    kind: str
    """``surface`` (things lie on it) or ``container`` (things go inside; these open and close)."""
    capacity: int
    """How many small objects fit (one per slot, slots ordered left to right as seen by the agent)."""
    room: str
    """``kitchen``, ``living``, ``dining`` or ``study``."""
    prep: str = ""
    """Preposition for things lying there, when not the kind's default (``in`` the sink)."""

    @property
    def articulated(self) -> bool:
        return self.kind == "container"

    @property
    def preposition(self) -> str:
        return self.prep or ("in" if self.kind == "container" else "on")


#: Decoration every apartment draws (scene-kit type names): no skill touches it, but it is in the images, so a
#: description that names it ("the ball in front of the TV") speaks of the scene, not of something imagined.
DECOR: tuple[str, ...] = ("Television", "DeskLamp", "FloorLamp", "HousePlant", "Painting")


#: The 15 receptacles, in skill order. Containers (fridge, drawers, cabinet) are articulated.
RECEPTACLES: tuple[Receptacle, ...] = (
    Receptacle("left_counter", "left counter", "surface", 4, "kitchen"),
    Receptacle("right_counter", "right counter", "surface", 4, "kitchen"),
    Receptacle("sink", "sink", "surface", 2, "kitchen", prep="in"),
    Receptacle("fridge", "fridge", "container", 4, "kitchen"),
    Receptacle("left_drawer", "left drawer", "container", 3, "kitchen"),
    Receptacle("right_drawer", "right drawer", "container", 3, "kitchen"),
    Receptacle("cabinet", "kitchen cabinet", "container", 4, "kitchen"),
    Receptacle("sofa", "sofa", "surface", 3, "living"),
    Receptacle("tv_stand", "TV stand", "surface", 3, "living"),
    Receptacle("coffee_table", "coffee table", "surface", 3, "living"),
    Receptacle("dining_table", "dining table", "surface", 4, "dining"),
    Receptacle("left_chair", "left chair", "surface", 1, "dining"),
    Receptacle("right_chair", "right chair", "surface", 1, "dining"),
    Receptacle("brown_table", "brown table", "surface", 3, "living"),
    Receptacle("desk", "desk", "surface", 3, "study"),
)

_RECEPTACLE_BY_KEY = {r.key: r for r in RECEPTACLES}

#: Hard sets (version 7): slots of the long surfaces in a "wide" task, objects standing closer and in two depths,
#: so one surface can show a group of five to eight to count. Classic tasks never use it.
WIDE_CAPACITY: dict[str, int] = {"left_counter": 9, "right_counter": 9, "dining_table": 9, "tv_stand": 7, "sofa": 7}


def capacity(key: str, wide: bool = False) -> int:
    """Slots of receptacle ``key``: :data:`WIDE_CAPACITY` in a wide (hard) task, else the catalogue's."""
    return WIDE_CAPACITY.get(key, receptacle(key).capacity) if wide else receptacle(key).capacity


def receptacle(key: str) -> Receptacle:
    """The receptacle with ``key``; a KeyError lists the known keys."""
    try:
        return _RECEPTACLE_BY_KEY[key]
    except KeyError:
        raise KeyError(f"unknown receptacle {key!r}; known: {', '.join(_RECEPTACLE_BY_KEY)}") from None


#: Colour name -> RGBA used by the renderer (also the words instructions may use).
COLORS: dict[str, tuple[float, float, float, float]] = {
    "red": (0.82, 0.12, 0.10, 1.0),
    "dark red": (0.55, 0.05, 0.06, 1.0),
    "green": (0.20, 0.62, 0.20, 1.0),
    "light green": (0.55, 0.80, 0.25, 1.0),
    "blue": (0.15, 0.35, 0.85, 1.0),
    "navy": (0.10, 0.14, 0.45, 1.0),
    "yellow": (0.98, 0.84, 0.10, 1.0),
    "orange": (0.98, 0.50, 0.06, 1.0),
    "purple": (0.45, 0.16, 0.55, 1.0),
    "pink": (0.98, 0.50, 0.68, 1.0),
    "white": (0.93, 0.93, 0.92, 1.0),
    "black": (0.08, 0.08, 0.09, 1.0),
    "gray": (0.50, 0.50, 0.52, 1.0),
    "silver": (0.75, 0.76, 0.78, 1.0),
    "brown": (0.45, 0.28, 0.14, 1.0),
    "gold": (0.85, 0.66, 0.20, 1.0),
}


@dataclass(frozen=True)
class ObjectType:
    """A kind of small YCB-style object. ``colors`` lists the variants; the first is the usual one."""

    key: str
    """Identifier used in goals (``?mug``) and instance names (``mug_2``)."""
    name: str
    """Display name in action names and feedback."""
    category: str
    """``fruit``, ``food``, ``kitchenware``, ``tool``, ``toy`` or ``household`` (coarse groups for templates)."""
    colors: tuple[str, ...]
    looks: str
    """How it looks, without naming it, in our words (``{color}`` is filled with the instance colour)."""
    uses: tuple[str, ...] = ()
    """What it is for, without naming it (for the common_sense subset)."""
    aliases: tuple[str, ...] = field(default=())

    @property
    def has_variants(self) -> bool:
        return len(self.colors) > 1


#: The 32 pickable object types, in skill order.
OBJECT_TYPES: tuple[ObjectType, ...] = (
    # fruit
    ObjectType("apple", "apple", "fruit", ("red", "green"), "a round {color} fruit with a short stem",
               ("a crunchy fruit that keeps the doctor away, as the saying goes",)),
    ObjectType("banana", "banana", "fruit", ("yellow",), "a long curved yellow fruit",
               ("a fruit you peel that monkeys are said to love",)),
    ObjectType("orange", "orange", "fruit", ("orange",), "a round fruit whose colour shares its name",
               ("a citrus fruit you could squeeze for breakfast juice",)),
    ObjectType("lemon", "lemon", "fruit", ("yellow",), "a small oval yellow fruit with pointed ends",
               ("a very sour fruit used to flavour tea or fish",)),
    ObjectType("pear", "pear", "fruit", ("light green",), "a light green fruit, narrow on top and wide at the bottom",
               ("a sweet fruit shaped like a bell",)),
    ObjectType("plum", "plum", "fruit", ("purple",), "a small round purple fruit",
               ("a small stone fruit that becomes a prune when dried",)),
    ObjectType("strawberry", "strawberry", "fruit", ("red",), "a small red fruit with a green leafy top",
               ("a small berry often dipped in chocolate",)),
    # food packaging
    ObjectType("soda_can", "soda can", "food", ("red", "blue", "green"), "a slim {color} metal can",
               ("a fizzy drink in a metal can",)),
    ObjectType("soup_can", "soup can", "food", ("red",), "a short can with a red and white label",
               ("a tin of something you heat up for a quick warm meal",)),
    ObjectType("tuna_can", "tuna can", "food", ("blue",), "a flat round tin with a blue label",
               ("a small tin of fish for sandwiches",)),
    ObjectType("cracker_box", "cracker box", "food", ("red",), "a tall red cardboard box",
               ("a box of crisp salty biscuits for snacking",)),
    ObjectType("sugar_box", "sugar box", "food", ("yellow",), "a yellow and white cardboard box",
               ("a box of what you stir into coffee to sweeten it",)),
    ObjectType("gelatin_box", "gelatin box", "food", ("pink",), "a small flat pink box",
               ("a small packet for making a wobbly dessert",)),
    ObjectType("mustard_bottle", "mustard bottle", "food", ("yellow",), "a yellow squeeze bottle with a pointed cap",
               ("a yellow sauce for hot dogs",)),
    # kitchenware
    ObjectType("bowl", "bowl", "kitchenware", ("red", "blue", "green", "white"), "a {color} round open dish",
               ("something to serve cereal or soup in",)),
    ObjectType("cup", "cup", "kitchenware", ("red", "blue", "yellow", "green"), "a small {color} drinking vessel without a handle",
               ("a small vessel to drink water from",)),
    ObjectType("mug", "mug", "kitchenware", ("red", "blue", "white", "yellow"), "a {color} drinking vessel with a handle",
               ("something you drink hot coffee from",)),
    ObjectType("plate", "plate", "kitchenware", ("white", "blue"), "a flat {color} disc",
               ("a flat dish to serve a meal on",)),
    ObjectType("pitcher", "pitcher", "kitchenware", ("blue",), "a big blue jug with a spout and a handle",
               ("a jug for pouring lemonade at the table",)),
    ObjectType("spatula", "spatula", "kitchenware", ("black",), "a black flat turner on a long handle",
               ("a utensil for flipping pancakes",)),
    ObjectType("skillet", "frying pan", "kitchenware", ("black",), "a round black pan with a long handle",
               ("a pan for frying eggs",), aliases=("skillet", "pan")),
    # tools
    ObjectType("hammer", "hammer", "tool", ("brown",), "a tool with a wooden handle and a heavy metal head",
               ("a tool for driving nails into wood",)),
    ObjectType("wrench", "wrench", "tool", ("silver",), "a silver metal tool with an open jaw at the end",
               ("a tool for turning nuts and bolts",)),
    ObjectType("screwdriver", "screwdriver", "tool", ("red", "blue"), "a tool with a {color} handle and a thin metal shaft",
               ("a tool for turning screws",)),
    ObjectType("scissors", "scissors", "tool", ("orange",), "a cutting tool with two orange finger loops",
               ("a tool for cutting paper",)),
    # toys and household items
    ObjectType("toy_airplane", "toy airplane", "toy", ("red", "blue", "yellow"), "a small {color} toy with wings and a tail",
               ("a toy that pretends to fly",)),
    ObjectType("ball", "ball", "toy", ("light green", "red", "blue"), "a {color} round toy that bounces",
               ("a toy you can throw to a dog",)),
    ObjectType("rubiks_cube", "Rubik's cube", "toy", ("white",), "a cube puzzle with many small coloured squares",
               ("a puzzle you solve by twisting its faces",), aliases=("rubik's cube", "rubiks cube")),
    ObjectType("padlock", "padlock", "household", ("gold",), "a small gold lock with a curved shackle",
               ("something that keeps a locker shut",)),
    ObjectType("sponge", "sponge", "household", ("yellow", "pink", "blue"), "a soft {color} rectangular block for scrubbing",
               ("something to scrub dirty dishes with",)),
    ObjectType("foam_brick", "foam brick", "toy", ("red",), "a soft red block shaped like a brick",
               ("a soft block a child can throw without breaking anything",)),
    ObjectType("bleach_bottle", "bleach bottle", "household", ("white",), "a white plastic bottle with a blue cap",
               ("a strong cleaning liquid for the bathroom",)),
)

_OBJECT_BY_KEY = {o.key: o for o in OBJECT_TYPES}


def object_type(key: str) -> ObjectType:
    """The object type with ``key``; a KeyError lists the known keys."""
    try:
        return _OBJECT_BY_KEY[key]
    except KeyError:
        raise KeyError(f"unknown object type {key!r}; known: {', '.join(_OBJECT_BY_KEY)}") from None


#: Colour variants the hard task set adds to the types that already come in several colours (the classic set
#: uses only :attr:`ObjectType.colors`). Every list holds colours a person tells apart on their own, one object
#: at a time, in the 500-pixel first-person view: no two shades of one hue (red / dark red, blue / navy). Not the
#: sponge (its green scouring layer covers the top, only a thin band shows its colour) and no white soda can (it
#: renders as bare metal).
HARD_COLORS: dict[str, tuple[str, ...]] = {
    "apple": ("red", "green", "yellow"),
    "soda_can": ("red", "blue", "green", "yellow", "black"),
    "bowl": ("red", "blue", "green", "white", "yellow", "black", "orange", "purple"),
    "cup": ("red", "blue", "yellow", "green", "white", "orange", "purple", "pink"),
    "mug": ("red", "blue", "white", "yellow", "green", "black", "orange", "purple"),
    "plate": ("white", "blue", "yellow", "green", "red", "black"),
    "screwdriver": ("red", "blue", "yellow", "green", "black"),
    "toy_airplane": ("red", "blue", "yellow", "green", "white", "orange"),
    "ball": ("light green", "red", "blue", "yellow", "orange", "purple"),
}


def allowed_colors(key: str) -> tuple[str, ...]:
    """Every colour a task file may give an instance of type ``key``: its classic variants, then the hard set's."""
    t = object_type(key)
    return t.colors + tuple(c for c in HARD_COLORS.get(key, ()) if c not in t.colors)


def _check() -> None:
    assert len({r.key for r in RECEPTACLES}) == len(RECEPTACLES)
    assert len({o.key for o in OBJECT_TYPES}) == len(OBJECT_TYPES)
    for o in OBJECT_TYPES:
        for c in o.colors:
            assert c in COLORS, (o.key, c)
    for key, colors in HARD_COLORS.items():
        assert object_type(key).has_variants and set(object_type(key).colors) <= set(colors), key
        assert all(c in COLORS for c in colors), key


_check()
