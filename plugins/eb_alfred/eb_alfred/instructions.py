"""Instruction templates (our own wording) and referring expressions for the six subsets.

``phrase`` functions turn a goal into words: plain nouns for base, uses and properties for common_sense,
a longer request with irrelevant context for complex_instruction, relations between things for
spatial_awareness and colours or shapes for visual_appearance.
"""

from __future__ import annotations

import random
from typing import Any

from eb_alfred.catalog import TYPES
from eb_alfred.world import World

__all__ = ["instruction", "prep", "noun", "plural", "relation_for_object", "relation_for_receptacle"]

_IN = {"Fridge", "Cabinet", "Drawer", "Microwave", "Safe", "Box", "SinkBasin", "BathtubBasin", "GarbageCan",
       "LaundryHamper", "Bowl", "Cup", "Mug", "Pot", "Pan", "CoffeeMachine", "Toaster"}


def prep(recep_type: str) -> str:
    return "in" if recep_type in _IN else "on"


def noun(type_name: str) -> str:
    return TYPES[type_name].noun


def plural(type_name: str) -> str:
    n = noun(type_name)
    special = {"loaf of bread": "loaves of bread", "head of lettuce": "heads of lettuce", "CD": "CDs"}
    if n in special:
        return special[n]
    if n.endswith("knife"):
        return n[:-2] + "ves"
    if n.endswith(("ch", "sh", "s", "x", "o")):
        return n + "es"
    if n.endswith("y") and n[-2] not in "aeiou":
        return n[:-1] + "ies"
    return n + "s"


def _a(word: str) -> str:
    return ("an " if word[0].lower() in "aeiou" else "a ") + word


def _type_of(world: World | None, ref: dict[str, str]) -> str:
    if "type" in ref:
        return ref["type"]
    assert world is not None
    return world.objects[ref["instance"]].type


# ----------------------------------------------------------------------------------------------- base
_BASE = {
    "pick_and_place": ["Put {x} {p} the {r}.", "Place {x} {p} the {r}.", "Move {x} to the {r}.",
                       "Set {x} down {p} the {r}."],
    "pick_two_and_place": ["Put two {xs} {p} the {r}.", "Place a pair of {xs} {p} the {r}.",
                           "Move two {xs} to the {r}."],
    "stack_and_place": ["Put {x} in {m}, then put the {mn} {p} the {r}.",
                        "Place {m} holding {x} {p} the {r}.",
                        "Set {x} inside {m} and carry the {mn} to the {r}."],
    "clean_and_place": ["Wash {x} and put it {p} the {r}.", "Rinse {x} clean, then place it {p} the {r}.",
                        "Clean {x} in the sink and set it {p} the {r}."],
    "heat_and_place": ["Warm up {x} and put it {p} the {r}.", "Heat {x}, then set it {p} the {r}.",
                       "Put a heated {xn} {p} the {r}."],
    "cool_and_place": ["Chill {x} and put it {p} the {r}.", "Cool down {x}, then place it {p} the {r}.",
                       "Put a cold {xn} {p} the {r}."],
    "examine_in_light": ["Turn on the {l} and look at {x} under it.", "By the light of the {l}, examine {x}.",
                         "Switch on the {l} and inspect {x} in its light."],
}
_SLICED = {
    "pick_and_place": ["Slice {x} and put a sliced {xn} {p} the {r}."],
    "pick_two_and_place": ["Slice two {xs} and put both {p} the {r}."],
    "stack_and_place": ["Slice {x}, put it in {m} and place the {mn} {p} the {r}."],
    "clean_and_place": ["Cut {x} into slices, rinse it and put it {p} the {r}."],
    "heat_and_place": ["Slice {x}, warm the sliced {xn} up and put it {p} the {r}.",
                       "Put a heated slice of {xn} {p} the {r}."],
    "cool_and_place": ["Slice {x}, chill it and put it {p} the {r}.",
                       "Put a chilled, sliced {xn} {p} the {r}."],
    "examine_in_light": ["Slice {x}, then turn on the {l} and look at it."],
}


def _fill(template: str, words: dict[str, str]) -> str:
    out = template.format(**words)
    return out[0].upper() + out[1:]


def _words(goal: dict[str, Any], world: World | None, obj: str | None = None, objs: str | None = None,
           recep: str | None = None,
           mov: str | None = None, lamp: str | None = None) -> dict[str, str]:
    """Default words: ``a tomato``, ``counter``... ``obj``/``recep``/``mov``/``lamp`` override the phrases."""
    xt = _type_of(world, goal["object"])
    w = {"x": obj or _a(noun(xt)), "xn": noun(xt), "xs": objs or plural(xt)}
    if "receptacle" in goal:
        rt = _type_of(world, goal["receptacle"])
        w["r"] = recep or noun(rt)
        w["p"] = prep(rt)
    if "movable" in goal:
        mt = _type_of(world, goal["movable"])
        w["m"] = mov or _a(noun(mt))
        w["mn"] = noun(mt)
    if "lamp" in goal:
        w["l"] = lamp or noun(_type_of(world, goal["lamp"]))
    return w


def base_instruction(rng: random.Random, goal: dict[str, Any], world: World | None = None, **over: str) -> str:
    table = _SLICED if goal.get("sliced") else _BASE
    words = _words(goal, world, **over)
    text = _fill(rng.choice(table[goal["kind"]]), words)
    return text.replace("the the ", "the ")


# ---------------------------------------------------------------------------------------- common sense
_CS = {
    "pick_and_place": ["Find {x} and leave it {p} {r}.", "Take {x} over to {r}.",
                       "Bring {x} and put it {p} {r}."],
    "pick_two_and_place": ["Gather two things, each {x}, and put both {p} {r}.",
                           "I need two items, each {x}; put them {p} {r}."],
    "stack_and_place": ["Put {x} into {m}, then carry that to {r}.",
                        "Load {x} into {m} and move it {p} {r}."],
    "clean_and_place": ["Get {x} washed and then leave it {p} {r}.",
                        "{x} is grimy; rinse it and put it {p} {r}."],
    "heat_and_place": ["Make {x} warm and then leave it {p} {r}.", "Heat up {x} and set it {p} {r}."],
    "cool_and_place": ["Make {x} cold and then leave it {p} {r}.", "Chill {x} and set it {p} {r}."],
    "examine_in_light": ["Study {x} in the glow of {l}.", "Switch on {l} and look closely at {x}."],
}
_CS_SLICED = {
    "heat_and_place": ["Cut up {x}, warm the pieces and leave them {p} {r}."],
    "cool_and_place": ["Cut up {x}, chill the pieces and put them {p} {r}."],
    "clean_and_place": ["Cut up {x}, wash the pieces and put them {p} {r}."],
    "pick_and_place": ["Cut up {x} and leave the pieces {p} {r}."],
    "pick_two_and_place": ["Cut up two things, each {x}, and put them {p} {r}."],
    "stack_and_place": ["Cut up {x}, put it into {m} and move that to {r}."],
    "examine_in_light": ["Cut up {x} and study it in the glow of {l}."],
}


def _use(rng: random.Random, type_name: str) -> str:
    return rng.choice(TYPES[type_name].uses)


def common_sense_instruction(rng: random.Random, goal: dict[str, Any], world: World | None = None) -> str:
    xt = _type_of(world, goal["object"])
    words = {"x": _use(rng, xt)}
    if "receptacle" in goal:
        rt = _type_of(world, goal["receptacle"])
        r = _use(rng, rt)
        words["r"] = r if r.startswith("the ") else "the " + r.split(" ", 1)[1] if r.startswith("a ") else r
        words["p"] = prep(rt)
    if "movable" in goal:
        words["m"] = _use(rng, _type_of(world, goal["movable"]))
    if "lamp" in goal:
        words["l"] = _use(rng, _type_of(world, goal["lamp"]))
    table = _CS_SLICED if goal.get("sliced") else _CS
    return _fill(rng.choice(table[goal["kind"]]), words)


# ----------------------------------------------------------------------------------- complex instruction
_OPENERS = [
    "I have friends coming over tonight and the place is a bit of a mess.",
    "It has been a long day and I barely had time to tidy up.",
    "My sister said she would drop by later, so I want things in order.",
    "I was reading the news this morning and completely forgot about the chores.",
    "We are hosting a small get-together this weekend.",
    "The weather is lovely today, but there is still housework to finish.",
    "I just got back from the grocery store and my hands are full.",
    "Before I head out to work, there is one thing I need.",
    "My kids left things all over the house again.",
    "I am trying to keep this room organised this week.",
]
_CLOSERS = [
    "Please leave everything else as it is.",
    "There is no need to touch the {d}.",
    "Don't bother with the {d}; it can stay where it is.",
    "The {d} is fine where it is, so ignore it.",
    "After that, you can take a break.",
    "I will deal with the rest myself later.",
    "Thanks, that would help me a lot.",
]
_REASONS = {
    "heat_and_place": "I would like it warm for my snack",
    "cool_and_place": "it tastes better cold",
    "clean_and_place": "it needs to be clean before anyone uses it",
    "pick_and_place": "that is where it belongs",
    "pick_two_and_place": "I need both of them there",
    "stack_and_place": "it is easier to carry things that way",
    "examine_in_light": "I want to check it for scratches",
}


def complex_instruction(rng: random.Random, goal: dict[str, Any], world: World) -> str:
    core = base_instruction(rng, goal, world)
    core = core[0].lower() + core[1:]
    xt = _type_of(world, goal["object"])
    distract = sorted({o.type for o in world.objects.values()
                       if TYPES[o.type].pickupable and o.type != xt})
    d = noun(rng.choice(distract)) if distract else "furniture"
    opener = rng.choice(_OPENERS)
    closer = rng.choice(_CLOSERS).format(d=d)
    middle = rng.choice([
        f"Could you please {core[:-1]}? {_REASONS[goal['kind']].capitalize()}.",
        f"What I need is simple: {core[:-1]}, because {_REASONS[goal['kind']]}.",
        f"Since {_REASONS[goal['kind']]}, please {core}",
    ])
    return f"{opener} {middle} {closer}"


# --------------------------------------------------------------------------------- referring expressions
def relation_for_object(world: World, x: str) -> str | None:
    """A phrase singling out ``x`` among its type by where it is, or None."""
    xt = world.objects[x].type
    others = [o for o in world.of_type(xt) if o != x]
    if not others:
        return None
    parent = world.objects[x].parent
    if parent is None:
        return None
    ptype = world.objects[parent].type
    if all(world.objects[o].parent is None or world.objects[world.objects[o].parent].type != ptype for o in others):
        if len(world.of_type(ptype)) == 1:
            return f"the {noun(xt)} that is {prep(ptype)} the {noun(ptype)}"
        rel = relation_for_receptacle(world, parent)
        if rel is not None:
            return f"the {noun(xt)} that is {prep(ptype)} {rel}"
        return f"the {noun(xt)} that is {prep(ptype)} one of the {plural(ptype)}"
    # Next to a unique object on the same receptacle.
    for z in world.children(parent):
        zt = world.objects[z].type
        if z == x or zt == xt or len(world.of_type(zt)) != 1:
            continue
        if all(world.objects[o].parent != world.objects[z].parent for o in others):
            return f"the {noun(xt)} that sits next to the {noun(zt)}"
    return None


def relation_for_receptacle(world: World, r: str) -> str | None:
    """A phrase singling out furniture ``r`` among its type by its position along the walls, or None."""
    o = world.objects[r]
    if o.parent is not None:
        return None
    rt = o.type
    same = sorted((world.objects[n].slot, n) for n in world.of_type(rt) if world.objects[n].parent is None)
    if len(same) < 2:
        return None
    by_slot = {world.objects[n].slot: n for n in world.objects if world.objects[n].parent is None}
    options = []
    for side, delta in (("left", +1), ("right", -1)):
        y = by_slot.get(o.slot + delta)
        if y is None:
            continue
        yt = world.objects[y].type
        if yt == rt or len(world.of_type(yt)) != 1:
            continue
        options.append(f"the {noun(rt)} just to the {side} of the {noun(yt)}")
    if same[0][1] == r:
        options.append(f"the leftmost {noun(rt)}")
    if same[-1][1] == r:
        options.append(f"the rightmost {noun(rt)}")
    inside = [c for c in world.children(r) if len(world.of_type(world.objects[c].type)) == 1]
    for c in inside:
        options.append(f"the {noun(rt)} that holds the {noun(world.objects[c].type)}")
    return options[0] if options else None


def instruction(subset: str, rng: random.Random, goal: dict[str, Any], world: World,
                phrases: dict[str, str] | None = None) -> str:
    """The instruction for ``goal`` in ``subset``; ``phrases`` carries referring expressions (spatial/visual)."""
    if subset == "common_sense":
        return common_sense_instruction(rng, goal, world)
    if subset == "complex_instruction":
        return complex_instruction(rng, goal, world)
    return base_instruction(rng, goal, world, **(phrases or {}))
