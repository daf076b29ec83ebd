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

__all__ = ["instruction", "instruction_with_template", "prep", "noun", "plural", "relation_for_object",
           "relation_for_receptacle", "object_relations", "receptacle_relations", "template_count"]

_IN = {"Fridge", "Cabinet", "Drawer", "Microwave", "Safe", "Box", "SinkBasin", "BathtubBasin", "GarbageCan",
       "LaundryHamper", "Bowl", "Cup", "Mug", "Pot", "Pan", "CoffeeMachine", "Toaster"}


def prep(recep_type: str) -> str:
    return "in" if recep_type in _IN else "on"


def noun(type_name: str) -> str:
    return TYPES[type_name].noun


#: Shape words that read as a shade when a colour follows ("the deep green bowl" is taken for a dark green one):
#: before a colour they are written unambiguously. A calibration player lost a hard task to "deep green".
_SHAPE_BEFORE_COLOUR = {"deep": "deep-sided"}


def shape_before_colour(shape: str) -> str:
    """The shape word as written before a colour word: ``deep`` -> ``deep-sided``, others unchanged."""
    return _SHAPE_BEFORE_COLOUR.get(shape, shape)


def plural(type_name: str) -> str:
    n = noun(type_name)
    special = {"loaf of bread": "loaves of bread", "head of lettuce": "heads of lettuce", "CD": "CDs",
               "shelf": "shelves", "toilet paper": "rolls of toilet paper"}
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


# ----------------------------------------------------------------------------------------------- templates
# Every template has an id ``<subset>.<kind>.<n>`` recorded in the task (``template``) so audits can count them.
# Placeholders: {x} the object (with its article or referring phrase), {xs} the plural object phrase ("two
# tomatoes" is written "two {xs}"), {p} in/on, {r} the destination with its determiner ("the counter",
# "the leftmost counter"), {m} the movable dish with its article, {mn} its bare noun, {l} the lamp with "the".
_BASE = {
    "pick_and_place": ["Put {x} {p} {r}.", "Place {x} {p} {r}.", "Move {x} to {r}.", "Set {x} down {p} {r}.",
                       "Take {x} and leave it {p} {r}."],
    "pick_two_and_place": ["Put two {xs} {p} {r}.", "Place a pair of {xs} {p} {r}.", "Move two {xs} to {r}.",
                           "Gather two {xs} and set them {p} {r}."],
    "stack_and_place": ["Put {x} in {m}, then put the {mn} {p} {r}.", "Place {m} holding {x} {p} {r}.",
                        "Set {x} inside {m} and carry the {mn} to {r}."],
    "clean_and_place": ["Wash {x} and put it {p} {r}.", "Rinse {x} under the tap, then place it {p} {r}.",
                        "Clean {x} in the sink and set it {p} {r}.",
                        "Take {x}, wash it under the tap and leave it {p} {r}."],
    "heat_and_place": ["Warm up {x} and put it {p} {r}.", "Heat {x}, then set it {p} {r}.",
                       "Take {x}, heat it up and leave it {p} {r}."],
    "cool_and_place": ["Chill {x} and put it {p} {r}.", "Cool down {x}, then place it {p} {r}.",
                       "Take {x}, chill it and set it {p} {r}."],
    "examine_in_light": ["Turn on {l} and look at {x} under it.", "By the light of {l}, examine {x}.",
                         "Switch on {l} and inspect {x} in its light."],
}
_SLICED = {
    "pick_and_place": ["Slice {x} and put a slice {p} {r}.", "Cut {x} into slices and place one {p} {r}."],
    "pick_two_and_place": ["Slice two {xs} and put both {p} {r}.", "Cut two {xs} into slices and place them {p} {r}.",
                           "Get two {xs} sliced and move them to {r}.",
                           "Slice up two {xs}, then leave both {p} {r}."],
    "stack_and_place": ["Slice {x}, put a slice in {m} and place the {mn} {p} {r}.",
                        "Cut {x} up, lay a slice in {m} and move the {mn} to {r}."],
    "clean_and_place": ["Cut {x} into slices, rinse a slice and put it {p} {r}.",
                        "Slice {x}, wash one of the slices and set it {p} {r}."],
    "heat_and_place": ["Slice {x}, warm a slice up and put it {p} {r}.",
                       "Cut {x} into slices, heat one and leave it {p} {r}.",
                       "Slice {x}, then heat a slice and set it {p} {r}."],
    "cool_and_place": ["Slice {x}, chill a slice and put it {p} {r}.",
                       "Cut {x} into slices, cool one down and place it {p} {r}.",
                       "Slice {x}, let a slice get cold and then set it {p} {r}."],
    "examine_in_light": ["Slice {x}, then turn on {l} and look at a slice."],
}
# Goals with extra preparation (``also``, long_horizon): {done} lists every property the object must end with
# ("washed and heated"); heat/cool/clean tasks with an extra property use the pick & place wording.
_ALSO = {
    "pick_and_place": ["Get {x} {done}, then put it {p} {r}.", "Make sure {x} is {done} before you put it {p} {r}.",
                       "Take {x}, have it {done} and leave it {p} {r}."],
    "pick_two_and_place": ["Get two {xs} {done} and put both {p} {r}.",
                           "Make sure two {xs} are {done}, then place them {p} {r}."],
    "stack_and_place": ["Get {x} {done}, put it in {m} and place the {mn} {p} {r}.",
                        "Make sure {x} is {done}, then set it in {m} and move the {mn} to {r}."],
    "examine_in_light": ["Get {x} {done}, then turn on {l} and look at it.",
                         "Make sure {x} is {done} and examine it under {l}."],
}
_ALSO_SLICED = {
    "pick_and_place": ["Slice {x}, get a slice {done} and put it {p} {r}.",
                       "Cut {x} into slices, make sure one is {done} and leave it {p} {r}."],
    "pick_two_and_place": ["Slice two {xs}, get a slice of each {done} and put both {p} {r}."],
    "stack_and_place": ["Slice {x}, get a slice {done}, put it in {m} and place the {mn} {p} {r}."],
    "examine_in_light": ["Slice {x}, get a slice {done}, then turn on {l} and look at it."],
}
for _table in (_ALSO, _ALSO_SLICED):
    for _kind in ("clean_and_place", "heat_and_place", "cool_and_place"):
        _table[_kind] = _table["pick_and_place"]
_DONE = {"clean": "washed", "hot": "heated", "cold": "chilled"}

_CS = {
    "pick_and_place": ["Find {x} and leave it {p} {r}.", "Take {x} over to {r}.",
                       "Bring {x} and put it {p} {r}."],
    "pick_two_and_place": ["Gather two things, each of them {x}, and put both {p} {r}.",
                           "I need two items, each of them {x}; put them {p} {r}."],
    "stack_and_place": ["Put {x} into {m}, then carry that to {r}.",
                        "Load {x} into {m} and bring it to {r}."],
    "clean_and_place": ["Get {x} washed and then leave it {p} {r}.",
                        "Rinse {x} under running water and put it {p} {r}."],
    "heat_and_place": ["Make {x} warm and then leave it {p} {r}.", "Heat up {x} and set it {p} {r}."],
    "cool_and_place": ["Make {x} cold and then leave it {p} {r}.", "Chill {x} and set it {p} {r}."],
    "examine_in_light": ["Study {x} in the glow of {l}.", "Switch on {l} and look closely at {x}."],
}
_CS_SLICED = {
    "heat_and_place": ["Cut up {x}, warm a piece and leave it {p} {r}."],
    "cool_and_place": ["Cut up {x}, chill a piece and put it {p} {r}."],
    "clean_and_place": ["Cut up {x}, wash a piece and put it {p} {r}."],
    "pick_and_place": ["Cut up {x} and leave a piece {p} {r}."],
    "pick_two_and_place": ["Cut up two things, each of them {x}, and put them {p} {r}."],
    "stack_and_place": ["Cut up {x}, put a piece into {m} and move that to {r}."],
    "examine_in_light": ["Cut up {x} and study a piece in the glow of {l}."],
}
# complex_instruction: the request is one statement among several sentences of context, at a random place and
# never introduced by a signpost; some context sentences mention other things in the room that must be left alone.
_NEED = {
    "pick_and_place": ["{X} really belongs {p} {r}.", "I would like {x} to end up {p} {r}.",
                       "It would help if {x} were sitting {p} {r} when I come back."],
    "pick_two_and_place": ["I would like two {xs} to end up {p} {r}.",
                           "It would help if a pair of {xs} were sitting {p} {r}."],
    "stack_and_place": ["I would like {x} to be in {m}, and the {mn} to stand {p} {r}.",
                        "It would help if {m} with {x} in it were waiting {p} {r}."],
    "clean_and_place": ["{X} has to be washed and then left {p} {r}.",
                        "I would like {x} rinsed clean and put {p} {r}."],
    "heat_and_place": ["I would like {x} warmed up and then left {p} {r}.",
                       "{X} should be heated and end up {p} {r}."],
    "cool_and_place": ["I would like {x} chilled and then left {p} {r}.",
                       "{X} should be cooled down and end up {p} {r}."],
    "examine_in_light": ["I want to look at {x} closely under {l}, so it should be lit.",
                         "{X} needs a careful look in the light of {l}."],
}
_CONTEXT = [
    "I have friends coming over tonight and the place is a bit of a mess.",
    "It has been a long day and I barely had time to tidy up.",
    "My sister said she would drop by later, so I want things in order.",
    "I was reading the news this morning and completely forgot about the chores.",
    "We are hosting a small get-together this weekend.",
    "The weather is lovely today, but there is still housework to finish.",
    "I just got back from the grocery store and my hands are full.",
    "My kids left things all over the house again.",
    "I am trying to keep this room organised this week.",
    "The neighbours were loud last night, so I slept badly.",
    "I spent the morning on the phone with the bank.",
    "The plumber is supposed to come on Thursday.",
    "Tomorrow is my day off, and I would rather not spend it cleaning.",
    "I finally finished the report I was working on.",
]
_ASIDE = [
    "The {d} can stay exactly where it is.",
    "Please do not move the {d}.",
    "I already dealt with the {d} earlier.",
    "Ignore the {d}; it is fine as it is.",
    "Someone asked about the {d}, but that can wait.",
]
_CLOSE = [
    "Thanks, that would help me a lot.",
    "I will deal with the rest myself later.",
    "After that, you can take a break.",
    "Everything else can stay as it is.",
    "",
]


def _fill(template: str, words: dict[str, str]) -> str:
    out = template.format(**words)
    return out[0].upper() + out[1:]


def _ref_words(goal: dict[str, Any], world: World | None, obj: str | None = None, objs: str | None = None,
               recep: str | None = None, mov: str | None = None, lamp: str | None = None) -> dict[str, str]:
    """The words for the placeholders; ``obj``/``objs``/``recep``/``mov``/``lamp`` override the plain ones."""
    xt = _type_of(world, goal["object"])
    x = obj or _a(noun(xt))
    w = {"x": x, "X": x[0].upper() + x[1:], "xn": noun(xt), "xs": objs or plural(xt)}
    if "receptacle" in goal:
        rt = _type_of(world, goal["receptacle"])
        w["r"] = recep or "the " + noun(rt)
        w["p"] = prep(rt)
    if "movable" in goal:
        mt = _type_of(world, goal["movable"])
        w["m"] = mov or _a(noun(mt))
        w["mn"] = noun(mt)
    if "lamp" in goal:
        w["l"] = lamp or "the " + noun(_type_of(world, goal["lamp"]))
    return w


def _pick(rng: random.Random, subset: str, kind: str, table: dict[str, list[str]], tag: str = "") -> tuple[str, str]:
    k = rng.randrange(len(table[kind]))
    return f"{subset}.{kind}{tag}.{k}", table[kind][k]


def base_instruction(rng: random.Random, goal: dict[str, Any], world: World | None = None,
                     subset: str = "base", **over: str) -> tuple[str, str]:
    """(template id, instruction) with plain or overridden referring phrases."""
    sliced = bool(goal.get("sliced"))
    words = _ref_words(goal, world, **over)
    if goal.get("also"):
        tid, template = _pick(rng, subset, goal["kind"], _ALSO_SLICED if sliced else _ALSO,
                              ".sliced.also" if sliced else ".also")
        own = {"clean_and_place": "clean", "heat_and_place": "hot", "cool_and_place": "cold"}.get(goal["kind"])
        props = ([own] if own else []) + [p for p in goal["also"] if p != own]
        words["done"] = " and ".join(_DONE[p] for p in props)
        return tid, _fill(template, words)
    tid, template = _pick(rng, subset, goal["kind"], _SLICED if sliced else _BASE, ".sliced" if sliced else "")
    return tid, _fill(template, words)


def _use(rng: random.Random, type_name: str) -> str:
    return rng.choice(TYPES[type_name].uses)


def _definite(phrase: str) -> str:
    """``a flat dish for a meal`` -> ``the flat dish for a meal`` (a destination is one particular thing)."""
    return "the " + phrase[2:] if phrase.startswith("a ") else phrase


def common_sense_instruction(rng: random.Random, goal: dict[str, Any], world: World | None = None) -> tuple[str, str]:
    xt = _type_of(world, goal["object"])
    over = {"obj": _use(rng, xt)}
    if "receptacle" in goal:
        over["recep"] = _definite(_use(rng, _type_of(world, goal["receptacle"])))
    if "movable" in goal:
        over["mov"] = _use(rng, _type_of(world, goal["movable"]))
    if "lamp" in goal:
        over["lamp"] = _definite(_use(rng, _type_of(world, goal["lamp"])))
    sliced = bool(goal.get("sliced"))
    tid, template = _pick(rng, "common_sense", goal["kind"], _CS_SLICED if sliced else _CS,
                          ".sliced" if sliced else "")
    return tid, _fill(template, _ref_words(goal, world, **over))


def complex_instruction(rng: random.Random, goal: dict[str, Any], world: World) -> tuple[str, str]:
    """A few sentences of everyday context with the request stated once, somewhere in the middle."""
    tid, need = _pick(rng, "complex_instruction", goal["kind"], _NEED)
    need = _fill(need, _ref_words(goal, world))
    involved = {_type_of(world, goal[k]) for k in ("object", "receptacle", "movable", "lamp") if k in goal}
    others = sorted({o.type for o in world.objects.values() if TYPES[o.type].pickupable} - involved)
    context = rng.sample(_CONTEXT, 2 + rng.randrange(2))
    if others:
        aside = rng.choice(_ASIDE).format(d=noun(rng.choice(others)))
        context.insert(rng.randrange(1, len(context) + 1), aside)
    at = rng.randrange(1, len(context) + 1)
    parts = context[:at] + [need] + context[at:] + [rng.choice(_CLOSE)]
    return tid, " ".join(p for p in parts if p)


# --------------------------------------------------------------------------------- referring expressions
def object_relations(world: World, x: str) -> list[tuple[str, list[str]]]:
    """Phrases singling out ``x`` among its type by where it is, each with the instances a viewer must see
    together to check it (``x`` and what the phrase relates it to)."""
    xt = world.objects[x].type
    others = [o for o in world.of_type(xt) if o != x]
    parent = world.objects[x].parent
    if not others or parent is None:
        return []
    out: list[tuple[str, list[str]]] = []
    ptype = world.objects[parent].type
    other_parent_types = {world.objects[world.objects[o].parent].type for o in others if world.objects[o].parent}
    if ptype not in other_parent_types:
        if len(world.of_type(ptype)) == 1:
            out.append((f"the {noun(xt)} that is {prep(ptype)} the {noun(ptype)}", [x, parent]))
        else:
            out.append((f"the {noun(xt)} that is {prep(ptype)} one of the {plural(ptype)}", [x, parent]))
    # next to a one-of-a-kind object on the same receptacle
    for z in world.children(parent):
        zt = world.objects[z].type
        if z == x or zt == xt or len(world.of_type(zt)) != 1 or not TYPES[zt].pickupable:
            continue
        if all(world.objects[o].parent != parent for o in others):
            out.append((f"the {noun(xt)} that sits next to the {noun(zt)}", [x, z]))
    return out


def receptacle_relations(world: World, r: str) -> list[tuple[str, list[str]]]:
    """Phrases singling out furniture ``r`` among its type by its place along the walls, each with the
    instances a viewer must see together to check it."""
    o = world.objects[r]
    if o.parent is not None:
        return []
    rt = o.type
    same = sorted((world.objects[n].slot, n) for n in world.of_type(rt) if world.objects[n].parent is None)
    if len(same) < 2:
        return []
    by_slot = {world.objects[n].slot: n for n in world.objects if world.objects[n].parent is None}
    out: list[tuple[str, list[str]]] = []
    for side, delta in (("left", +1), ("right", -1)):
        y = by_slot.get(o.slot + delta)
        if y is None:
            continue
        yt = world.objects[y].type
        if yt == rt or len(world.of_type(yt)) != 1:
            continue
        out.append((f"the {noun(rt)} just to the {side} of the {noun(yt)}", [r, y]))
    if same[0][1] == r:
        out.append((f"the leftmost {noun(rt)}", [n for _, n in same]))
    if same[-1][1] == r:
        out.append((f"the rightmost {noun(rt)}", [n for _, n in same]))
    for c in world.children(r):
        ct = world.objects[c].type
        if len(world.of_type(ct)) == 1 and TYPES[ct].pickupable:
            out.append((f"the {noun(rt)} that holds the {noun(ct)}", [r, c]))
    return out


def relation_for_object(world: World, x: str) -> str | None:
    """The first phrase of :func:`object_relations` (None if there is none)."""
    got = object_relations(world, x)
    return got[0][0] if got else None


def relation_for_receptacle(world: World, r: str) -> str | None:
    """The first phrase of :func:`receptacle_relations` (None if there is none)."""
    got = receptacle_relations(world, r)
    return got[0][0] if got else None


def instruction_with_template(subset: str, rng: random.Random, goal: dict[str, Any], world: World,
                              phrases: dict[str, str] | None = None) -> tuple[str, str]:
    """(template id, instruction) for ``goal`` in ``subset``; ``phrases`` carries referring expressions."""
    if subset == "common_sense":
        return common_sense_instruction(rng, goal, world)
    if subset == "complex_instruction":
        return complex_instruction(rng, goal, world)
    return base_instruction(rng, goal, world, subset=subset, **(phrases or {}))


def instruction(subset: str, rng: random.Random, goal: dict[str, Any], world: World,
                phrases: dict[str, str] | None = None) -> str:
    """The instruction for ``goal`` in ``subset`` (see :func:`instruction_with_template`)."""
    return instruction_with_template(subset, rng, goal, world, phrases)[1]


def template_count() -> dict[str, int]:
    """How many instruction templates each subset draws from."""
    n_base = sum(len(v) for v in _BASE.values())
    n_sliced = sum(len(v) for v in _SLICED.values())
    return {"base": n_base, "common_sense": sum(len(v) for v in _CS.values()) + sum(len(v) for v in _CS_SLICED.values()),
            "complex_instruction": sum(len(v) for v in _NEED.values()), "spatial_awareness": n_base,
            "visual_appearance": n_base,
            "long_horizon": n_base + n_sliced + sum(len(_ALSO[k]) + len(_ALSO_SLICED[k]) for k in
                                                    ("pick_and_place", "pick_two_and_place", "stack_and_place",
                                                     "examine_in_light"))}
