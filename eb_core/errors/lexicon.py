"""Words for the perception check: how people name the worlds' objects, colour families, and words that never
name an object.

Object *terms* are normalised type names: CamelCase split, lower case, singular (``GarbageCan`` -> ``garbage
can``). :data:`SYNONYMS` maps a phrase a person may write to the terms it can mean; a world adds its own names per
object in view (``aliases`` of a ``visible_objects`` entry: navigation's display names, ALFRED's nouns).
"""

from __future__ import annotations

import re

__all__ = [
    "COLOURS",
    "COLOUR_FAMILIES",
    "GENERIC",
    "LOOKALIKES",
    "PARTS",
    "SHAPES",
    "SYNONYMS",
    "colour_families",
    "norm",
    "singular",
    "term_of",
    "words",
]

#: Phrase -> the object terms it can name (besides the term itself).
SYNONYMS: dict[str, tuple[str, ...]] = {
    "refrigerator": ("fridge",), "freezer": ("fridge",),
    "couch": ("sofa",), "settee": ("sofa",),
    "chest of drawer": ("dresser", "drawer"), "chest": ("dresser", "drawer"),
    "dresser": ("dresser", "drawer", "side table", "cabinet", "tv stand"),
    "tv": ("television",), "television set": ("television",), "screen": ("television", "laptop"),
    "monitor": ("television", "laptop"), "tv stand": ("tv stand",), "tv unit": ("tv stand",),
    "tv cabinet": ("tv stand",), "media console": ("tv stand",),
    "bin": ("garbage can",), "trash can": ("garbage can",), "trash bin": ("garbage can",),
    "waste bin": ("garbage can",), "dustbin": ("garbage can",), "wastebasket": ("garbage can",),
    "rubbish bin": ("garbage can",),
    "counter": ("counter top",), "countertop": ("counter top",), "worktop": ("counter top",),
    "kitchen counter": ("counter top",), "kitchen island": ("counter top",),
    "cooker": ("stove", "stove burner"), "hob": ("stove", "stove burner"), "stove top": ("stove", "stove burner"),
    "stovetop": ("stove", "stove burner"), "oven": ("stove",), "burner": ("stove burner", "stove"),
    "towel rack": ("towel holder",), "towel rail": ("towel holder",), "towel bar": ("towel holder",),
    "toilet paper stand": ("toilet paper hanger",), "toilet roll holder": ("toilet paper hanger",),
    "toilet roll": ("toilet paper",),
    "plant": ("house plant",), "potted plant": ("house plant",), "houseplant": ("house plant",),
    "teddy": ("teddy bear",), "stuffed bear": ("teddy bear",), "stuffed animal": ("teddy bear",),
    "remote": ("remote control",), "phone": ("cell phone",), "cellphone": ("cell phone",),
    "mobile phone": ("cell phone",), "smartphone": ("cell phone",),
    "bookcase": ("bookshelf", "shelf"), "bookshelf": ("bookshelf", "shelf", "shelving unit"),
    "shelving": ("shelf", "bookshelf", "shelving unit"), "shelf unit": ("shelf", "bookshelf", "shelving unit"),
    "armchair": ("arm chair",), "easy chair": ("arm chair",), "stool": ("stool", "chair", "ottoman"),
    "footstool": ("ottoman",), "pouf": ("ottoman",),
    "lamp": ("floor lamp", "desk lamp"), "standing lamp": ("floor lamp",), "table lamp": ("desk lamp",),
    "picture": ("painting",), "artwork": ("painting",), "framed picture": ("painting",),
    "coffee maker": ("coffee machine",), "espresso machine": ("coffee machine",),
    "washer": ("washing machine",), "faucet": ("faucet", "sink"), "tap": ("faucet", "sink"),
    "basin": ("sink", "sink basin", "bathtub"), "tub": ("bathtub",), "bath": ("bathtub",),
    "nightstand": ("side table", "drawer", "dresser"), "night stand": ("side table", "drawer", "dresser"),
    "bedside table": ("side table", "drawer", "dresser"),
    "end table": ("side table",), "console table": ("side table",),
    "mug": ("mug", "cup"), "cup": ("cup", "mug"), "glass": ("cup", "mug", "glass bottle"), "bottle": ("bottle",),
    "pan": ("pan",), "frying pan": ("pan",), "skillet": ("pan",), "saucepan": ("pot",),
    "sponge": ("sponge", "dish sponge"), "soap": ("soap bar", "soap bottle"),
    "cloth": ("cloth", "towel"), "rag": ("cloth",), "towel": ("towel", "cloth", "hand towel"),
    "keys": ("key chain",), "key": ("key chain",), "clock": ("alarm clock",),
    "laptop computer": ("laptop",), "computer": ("laptop",), "notebook": ("laptop", "book"),
    "loaf": ("bread",), "jar": ("vase",), "flower": ("vase", "house plant"), "vase of flower": ("vase",),
    "pepper": ("pepper shaker",), "salt": ("salt shaker",), "shaker": ("salt shaker", "pepper shaker"),
    "cube": ("cube",), "block": ("cube",), "desk": ("desk", "table"),
    "drawer": ("drawer", "dresser", "cabinet", "side table", "desk", "tv stand"),
    "cupboard": ("cabinet", "counter top", "sink", "stove"), "safe": ("safe",),
    "shelf": ("shelf", "cabinet", "fridge", "bookshelf", "desk", "tv stand", "side table", "dresser", "shelving unit",
              "counter top"),
    "cabinet": ("cabinet", "counter top", "sink", "stove", "dresser", "tv stand", "side table", "desk", "shelf",
                "bookshelf", "microwave", "fridge"),
    "drawer unit": ("dresser", "drawer", "cabinet", "desk", "side table", "tv stand", "counter top"),
}

#: Shape words an "object k" claim is judged on (manipulation's shapes and their common names).
SHAPES: dict[str, str] = {"cube": "cube", "block": "cube", "box": "cube", "star": "star", "moon": "moon",
                          "crescent": "moon", "triangle": "triangle", "triangular prism": "triangle",
                          "cylinder": "cylinder", "container": "container", "bowl": "container"}

#: Single words too generic to judge: naming them is never a hallucination (a "box" may be any boxy thing).
GENERIC = frozenset(["object", "objects", "item", "items", "thing", "things", "box", "unit", "piece", "stand", "furniture", "shape", "something", "stuff", "surface", "top", "side", "edge", "corner", "wall", "floor", "ceiling", "window", "door", "doorway", "room", "kitchen", "bathroom", "bedroom", "hallway", "area", "space", "light", "shadow", "frame", "handle", "leg", "legs", "rug", "carpet", "mat", "runner", "curtain", "curtains", "tile", "tiles", "panel", "base", "structure", "block", "body", "container", "decoration", "decor", "cover", "lid", "shelfs", "can", "control", "bar", "paper", "maker", "machine", "holder", "hanger"])

#: Things that furniture draws as a part of itself: naming one on a piece of furniture in view is no hallucination,
#: even where the world also has the thing as an object type (a bed's pillows; ALFRED has Pillow objects too).
PARTS: dict[str, frozenset[str]] = {
    "pillow": frozenset({"bed", "sofa", "armchair"}),
    "cushion": frozenset({"sofa", "armchair", "chair", "bed", "ottoman"}),
    "knob": frozenset({"drawer", "dresser", "cabinet", "stove", "stove burner", "side table", "desk", "tv stand"}),
    "burner": frozenset({"stove", "stove burner"}),
    "faucet": frozenset({"sink", "sink basin", "bathtub", "bathtub basin"}),
}

#: Object types a world draws so alike at the model's image size that a careful person may name one for the other:
#: naming one while the other is in view is not judged when the named one is nowhere in the scene, nor when the
#: colour said fits only the other. ALFRED draws its watering can as a red pot with a spout and a top handle: a
#: calibration player called it "a red kettle". Navigation's armchairs are wide upholstered seats: close up, a
#: red armchair filling the corner of the view was called "the red sofa" while a green sofa stood across the room.
LOOKALIKES: dict[str, frozenset[str]] = {
    "kettle": frozenset({"watering can"}),
    "watering can": frozenset({"kettle"}),
    "sofa": frozenset({"arm chair"}),
    "arm chair": frozenset({"sofa"}),
}

#: Colour words and the family each belongs to (a person calls silver "light grey" and rose "pink").
COLOUR_FAMILIES: dict[str, set[str]] = {
    "red": {"red", "maroon", "rose", "crimson", "scarlet", "dark red", "burgundy"},
    "pink": {"pink", "rose", "magenta", "salmon"},
    "orange": {"orange", "amber", "tan"},
    "yellow": {"yellow", "gold", "golden", "mustard", "olive", "beige", "cream"},
    "green": {"green", "lime", "olive", "teal", "dark green", "mint"},
    "blue": {"blue", "navy", "azure", "cyan", "teal", "dark blue", "light blue", "turquoise", "sky"},
    "purple": {"purple", "violet", "magenta", "lilac", "lavender", "indigo"},
    "brown": {"brown", "wood", "wooden", "walnut", "oak", "tan", "beige", "maroon", "bronze", "copper", "dark wooden",
              "light wooden", "chocolate"},
    "grey": {"grey", "gray", "silver", "steel", "stainless", "metal", "metallic", "light grey", "dark grey",
             "charcoal", "chrome", "aluminium"},
    "white": {"white", "cream", "ivory", "silver", "light grey", "beige", "off white"},
    "black": {"black", "dark grey", "charcoal", "ebony", "navy"},
}

#: Every colour word the check knows (single words; "light"/"dark" are modifiers, not colours).
COLOURS: set[str] = {w for fam in COLOUR_FAMILIES.values() for c in fam for w in c.split()} - {"light", "dark", "off"}


def words(text: str) -> list[str]:
    """Lower-case words of ``text``, CamelCase split, digits and underscores dropped."""
    text = re.sub(r"([a-z])([A-Z])", r"\1 \2", str(text))
    text = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1 \2", text)
    return re.findall(r"[a-z]+", text.lower())


def singular(word: str) -> str:
    if word in ("glass", "grass", "bus", "glasses", "dresses"):
        return word[:-2] if word.endswith("sses") else word
    for suffix, repl in (("ies", "y"), ("ves", "f"), ("ches", "ch"), ("shes", "sh"), ("xes", "x"), ("s", "")):
        if word.endswith(suffix) and len(word) > len(suffix) + 2 and not word.endswith("ss"):
            return word[: -len(suffix)] + repl
    return word


def norm(text: str) -> str:
    """Singular lower-case words of ``text`` joined by one space."""
    return " ".join(singular(w) for w in words(text))


#: Colour words that are also things (a mustard bottle, an orange): kept in a type unless a shape follows.
_THING_COLOURS = {"mustard", "orange", "lime", "olive", "salmon", "chocolate", "cream", "mint", "gold", "copper",
                  "bronze", "wood", "oak", "walnut", "steel", "metal", "glass", "sky"}


def term_of(type_or_name: str) -> str:
    """An object's term: its type (or name) normalised, colour words dropped (``Red_Cube`` -> ``cube``), except
    colour words that name a thing (``mustard bottle``, ``Orange``) unless a shape follows (``lime container``)."""
    ws = norm(type_or_name).split()
    shaped = bool(ws) and ws[-1] in SHAPES.values()
    kept = [w for w in ws if w not in COLOURS or (w in _THING_COLOURS and not shaped)]
    return " ".join(kept)


def colour_families(colour_text: str | None) -> set[str]:
    """The families a colour name belongs to (``"light_gray"`` -> grey and white; ``"navy"`` -> blue, black)."""
    if not colour_text:
        return set()
    text = " ".join(words(colour_text.replace("_", " ")))
    fams = {f for f, members in COLOUR_FAMILIES.items() if text in members}
    if not fams:  # "dark steel blue": any word that is a colour
        fams = {f for w in text.split() for f, members in COLOUR_FAMILIES.items() if w in members}
    return fams
