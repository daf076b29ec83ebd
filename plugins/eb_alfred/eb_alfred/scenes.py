"""Procedural household scenes: furniture along the walls and objects in/on receptacles, from a seed.

A scene is plain data (stored inside each task): the room kind and a list of instances with their parent
receptacle, states and looks. Instance names follow ALFRED's multi-instance convention: the first cabinet
is ``Cabinet``, the next ``Cabinet_2`` and so on, numbered left to right along the walls.
"""

from __future__ import annotations

import random
from typing import Any

from eb_alfred.catalog import TYPES, fits

__all__ = ["make_scene", "ROOM_RECIPES"]

# Furniture per room: type -> (min, max) count. Appliances that stand on a counter are listed apart.
ROOM_RECIPES: dict[str, dict[str, Any]] = {
    "kitchen": {
        "furniture": {"Fridge": (1, 1), "CounterTop": (2, 4), "Cabinet": (3, 22), "Drawer": (2, 13),
                      "Sink": (1, 1), "StoveBurner": (2, 4), "DiningTable": (0, 1), "GarbageCan": (1, 1),
                      "Shelf": (0, 2), "SideTable": (0, 1)},
        "on_counter": ("Microwave", "CoffeeMachine", "Toaster"),
        "objects": {"Apple": 3, "Bread": 1, "Lettuce": 2, "Tomato": 3, "Potato": 3, "Egg": 2, "Mug": 3, "Cup": 2,
                    "Bowl": 3, "Plate": 3, "Pan": 1, "Pot": 2, "Kettle": 1, "Knife": 2, "ButterKnife": 2,
                    "Fork": 2, "Spoon": 2, "Spatula": 2, "Ladle": 1, "SaltShaker": 1, "PepperShaker": 1,
                    "DishSponge": 2, "SoapBottle": 1, "WineBottle": 1, "GlassBottle": 1, "Vase": 1,
                    "Statue": 1, "Book": 1, "CreditCard": 1, "CellPhone": 1},
        "n_objects": (16, 52),
    },
    "living_room": {
        "furniture": {"Sofa": (1, 1), "ArmChair": (0, 2), "CoffeeTable": (1, 1), "SideTable": (1, 3),
                      "TVStand": (1, 1), "Shelf": (1, 4), "Drawer": (0, 6), "Cabinet": (0, 6), "Dresser": (0, 1),
                      "FloorLamp": (1, 1), "Ottoman": (0, 1), "GarbageCan": (1, 1), "DiningTable": (0, 1),
                      "Safe": (0, 1)},
        "lamp_on": "SideTable",
        "objects": {"RemoteControl": 2, "Laptop": 1, "Book": 2, "Newspaper": 2, "KeyChain": 2, "CreditCard": 2,
                    "Pillow": 2, "Statue": 2, "Vase": 3, "Watch": 2, "WateringCan": 1, "Box": 2, "Bowl": 2,
                    "Plate": 1, "TissueBox": 1, "CellPhone": 2, "Candle": 1, "WineBottle": 1},
        "n_objects": (12, 30),
    },
    "bedroom": {
        "furniture": {"Bed": (1, 1), "Desk": (1, 1), "Dresser": (0, 1), "SideTable": (1, 2), "Drawer": (2, 10),
                      "Shelf": (0, 4), "FloorLamp": (0, 1), "Safe": (0, 1), "GarbageCan": (1, 1),
                      "LaundryHamper": (0, 1), "ArmChair": (0, 1), "Cabinet": (0, 4)},
        "lamp_on": "Desk",
        "objects": {"AlarmClock": 2, "Book": 3, "CD": 2, "CellPhone": 2, "Pen": 3, "Pencil": 3, "Laptop": 1,
                    "Pillow": 2, "Mug": 2, "Bowl": 1, "KeyChain": 2, "CreditCard": 2, "BaseballBat": 1,
                    "BasketBall": 1, "TennisRacket": 1, "Watch": 2, "Box": 1, "Cloth": 1, "Statue": 1, "Vase": 2},
        "n_objects": (12, 30),
    },
    "bathroom": {
        "furniture": {"Toilet": (1, 1), "ToiletPaperHanger": (1, 1), "Sink": (1, 2), "Bathtub": (0, 1),
                      "CounterTop": (1, 2), "Cabinet": (2, 6), "Drawer": (0, 4), "TowelHolder": (1, 2),
                      "HandTowelHolder": (1, 1), "GarbageCan": (1, 1), "Shelf": (0, 2), "LaundryHamper": (0, 1)},
        "objects": {"SoapBar": 3, "SoapBottle": 2, "Cloth": 3, "HandTowel": 1, "Towel": 2, "ToiletPaper": 2,
                    "SprayBottle": 2, "ScrubBrush": 1, "Plunger": 1, "Candle": 2, "TissueBox": 1, "DishSponge": 1},
        "n_objects": (10, 24),
    },
}

# How likely an object lands on/in a receptacle type (unlisted fitting types get 1).
_PLACE_WEIGHT = {"CounterTop": 4, "DiningTable": 3, "Desk": 3, "CoffeeTable": 3, "SideTable": 2, "Shelf": 2,
                 "Bed": 2, "Sofa": 2, "Dresser": 2, "Fridge": 2, "TowelHolder": 8, "HandTowelHolder": 8,
                 "ToiletPaperHanger": 6, "StoveBurner": 3, "GarbageCan": 0.3, "Microwave": 0.5, "Toaster": 0.5,
                 "CoffeeMachine": 2, "Bowl": 0.6, "Plate": 0.6, "Pot": 0.3, "Pan": 0.3, "Mug": 0.3, "Cup": 0.3,
                 "Box": 0.5, "Safe": 0.6}
_FOOD = {"Apple", "Bread", "Lettuce", "Tomato", "Potato", "Egg"}


def _count(rng: random.Random, lo_hi: tuple[int, int], scale: float) -> int:
    lo, hi = lo_hi
    return lo + round((hi - lo) * scale * rng.random() ** 0.7) if hi > lo else lo


def make_scene(seed: int, room: str | None = None, size: float | None = None) -> dict[str, Any]:
    """A scene dict ``{"room", "objects": [...]}``. ``size`` in [0, 1] scales the furniture and object counts."""
    rng = random.Random(seed)
    room = room or rng.choice(["kitchen", "kitchen", "living_room", "bedroom", "bathroom"])
    recipe = ROOM_RECIPES[room]
    scale = rng.random() if size is None else size

    pieces = _furniture(rng, recipe, scale)
    counters: dict[str, int] = {}
    objects: list[dict[str, Any]] = []

    def new_name(t: str) -> str:
        counters[t] = counters.get(t, 0) + 1
        return t if counters[t] == 1 else f"{t}_{counters[t]}"

    def looks(t: str) -> dict[str, Any]:
        info = TYPES[t]
        out: dict[str, Any] = {}
        if info.colors:
            out["color"] = info.colors[0] if rng.random() < 0.45 else rng.choice(info.colors)
        if info.shapes:
            out["shape"] = rng.choice(info.shapes)
        return out

    for slot, t in enumerate(pieces):
        name = new_name(t)
        objects.append({"name": name, "type": t, "slot": slot, **looks(t)})
        if t == "Sink":
            objects.append({"name": new_name("SinkBasin"), "type": "SinkBasin", "parent": name, **looks("SinkBasin")})
            objects.append({"name": new_name("Faucet"), "type": "Faucet", "parent": name})
        if t == "Bathtub":
            objects.append({"name": new_name("BathtubBasin"), "type": "BathtubBasin", "parent": name})
    counter_tops = [o["name"] for o in objects if o["type"] == "CounterTop"]
    for t in recipe.get("on_counter", ()):
        objects.append({"name": new_name(t), "type": t, "parent": rng.choice(counter_tops), **looks(t)})
    if "lamp_on" in recipe:
        hosts = [o["name"] for o in objects if o["type"] == recipe["lamp_on"]]
        objects.append({"name": new_name("DeskLamp"), "type": "DeskLamp", "parent": rng.choice(hosts), **looks("DeskLamp")})

    # Objects: pick types with their multiplicity limits, then put each in a fitting receptacle.
    pool = recipe["objects"]
    n_obj = _count(rng, recipe["n_objects"], scale)
    chosen: list[str] = []
    budget = dict(pool)
    while len(chosen) < n_obj and any(budget.values()):
        t = rng.choice([k for k, v in budget.items() if v > 0])
        budget[t] -= 1
        chosen.append(t)
    # Receptacles first so small things can go into dishes.
    chosen.sort(key=lambda t: (not TYPES[t].receptacle, t))
    placed_in: dict[str, int] = {}
    for t in chosen:
        receps = [o for o in objects if _can_hold(o, t, objects, placed_in)]
        if not receps:
            continue
        weights = [_PLACE_WEIGHT.get(o["type"], 1.0) for o in receps]
        host = rng.choices(receps, weights=weights)[0]
        placed_in[host["name"]] = placed_in.get(host["name"], 0) + 1
        obj = {"name": new_name(t), "type": t, "parent": host["name"], **looks(t)}
        if TYPES[t].dirtyable and rng.random() < 0.25:
            obj["is_dirty"] = True
        objects.append(obj)
    _renumber(objects)
    return {"room": room, "objects": objects}


def _furniture(rng: random.Random, recipe: dict[str, Any], scale: float) -> list[str]:
    """The furniture types along the walls, left to right: the fridge at one end, the stove burners together
    between two pieces (next to the counters)."""
    pieces: list[str] = []
    for t, lo_hi in recipe["furniture"].items():
        pieces += [t] * _count(rng, lo_hi, scale)
    rng.shuffle(pieces)
    if "Fridge" in pieces:  # the fridge stands at one end of the kitchen
        pieces.remove("Fridge")
        pieces.insert(0 if rng.random() < 0.5 else len(pieces), "Fridge")
    burners = [p for p in pieces if p == "StoveBurner"]
    if burners:
        pieces = [p for p in pieces if p != "StoveBurner"]
        at = rng.randrange(1, len(pieces))
        pieces[at:at] = burners
    return pieces


def _can_hold(o: dict[str, Any], t: str, objects: list[dict[str, Any]], placed_in: dict[str, int]) -> bool:
    """Whether a new ``t`` may be put on/in ``o``: a fitting receptacle with room left (``placed_in``: what was
    put in each so far); the fridge takes food and dishes, an appliance one thing, a dish on a dish nothing."""
    return bool(TYPES[o["type"]].receptacle and fits(t, o["type"])
                and o["type"] not in ("Sink", "Bathtub")
                and placed_in.get(o["name"], 0) < (1 if TYPES[o["type"]].capacity <= 2 else 4)
                and not (o["type"] == "Fridge" and t not in _FOOD | {"Mug", "Cup", "Bowl", "Plate", "Pot",
                                                                     "WineBottle", "GlassBottle"})
                and not (o["type"] in ("Microwave", "Toaster", "CoffeeMachine") and placed_in.get(o["name"], 0))
                and not (o.get("parent") and TYPES[o["type"]].pickupable and
                         _parent_of(objects, o["parent"]) is not None))


def _parent_of(objects: list[dict[str, Any]], name: str) -> str | None:
    for o in objects:
        if o["name"] == name:
            return o.get("parent")
    return None


def _renumber(objects: list[dict[str, Any]]) -> None:
    """Number instances of a type in a stable order: furniture left to right, objects by where they are."""
    slot_of: dict[str, float] = {}
    for o in objects:
        if "parent" not in o:
            slot_of[o["name"]] = float(o["slot"])

    def top_slot(o: dict[str, Any]) -> float:
        cur = o
        depth = 0
        while "parent" in cur:
            cur = next(p for p in objects if p["name"] == cur["parent"])
            depth += 1
        return slot_of[cur["name"]] + 0.01 * depth

    by_type: dict[str, list[dict[str, Any]]] = {}
    for i, o in enumerate(objects):
        by_type.setdefault(o["type"], []).append(o)
    rename: dict[str, str] = {}
    for t, group in by_type.items():
        ordered = sorted(group, key=lambda o: (top_slot(o), objects.index(o)))
        for i, o in enumerate(ordered, start=1):
            rename[o["name"]] = t if i == 1 else f"{t}_{i}"
    for o in objects:
        o["name"] = rename[o["name"]]
        if "parent" in o:
            o["parent"] = rename[o["parent"]]
