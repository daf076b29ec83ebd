"""Drawing one candidate task: a scene from a seed, a goal of a task type, the subset's adaptations, the wording.

:func:`make_one` is the draw function shared by the shipped-set generator (:mod:`eb_alfred.generate`) and the
generated train/val splits (:mod:`eb_alfred.splits`); it lives here so that neither imports the other. For every
subset it proposes a goal of the given task type for a scene of a fitting room, adapts the scene where the subset
needs it (dirty objects to wash, look-alike distractors for the visual subset; for long_horizon: the things it
needs shut away in closed drawers, cabinets and the fridge, and extra preparation of the object, see
:data:`LONG_ROOMS`), words the instruction, and keeps the task only if the oracle solves it within the subset's
step range, the instruction names the instance the goal singles out, and -- for the spatial and visual subsets
-- a render of the start state shows what the words refer to (:func:`image_problems`). ``difficulty="hard"``
applies :mod:`eb_alfred.hard` on top (crowds of look-alikes, destinations singled out among look-alikes, the
instruction asking to leave the others alone).
"""

from __future__ import annotations

import json
import random
from typing import Any

from eb_alfred.actions import scene_actions
from eb_alfred.audit import attribute_problems, phrase_problems, relation_problems, visibility_problems
from eb_alfred.catalog import KNIVES, LAMPS, TYPES, fits, is_movable_receptacle
from eb_alfred.goals import PROPERTY_OF_KIND, evaluate, properties
from eb_alfred.instructions import instruction_with_template, noun, object_relations, plural, receptacle_relations
from eb_alfred.oracle import expert_plan
from eb_alfred.scenes import _renumber, make_scene
from eb_alfred.world import World

__all__ = ["DIFFICULTIES", "LONG_ROOMS", "STEP_RANGE", "image_problems", "make_one", "propose_goal"]

HEATABLE = ("Apple", "Bread", "Egg", "Potato", "Tomato", "Mug", "Cup", "Plate", "Bowl")
COOLABLE = ("Apple", "Bread", "Lettuce", "Tomato", "Potato", "Egg", "Mug", "Cup", "Bowl", "Plate", "WineBottle")
EXAMINABLE = ("AlarmClock", "Book", "CD", "CellPhone", "CreditCard", "KeyChain", "Newspaper", "Pen", "Pencil",
              "RemoteControl", "Statue", "Vase", "Watch", "Box", "Bowl", "Mug", "Plate", "Laptop", "Pillow",
              "TissueBox", "Candle", "BasketBall", "BaseballBat", "TennisRacket", "Cloth")
KIND_ROOMS = {
    "pick_and_place": ("kitchen", "living_room", "bedroom", "bathroom"),
    "stack_and_place": ("kitchen", "living_room", "bedroom"),
    "pick_two_and_place": ("kitchen", "living_room", "bedroom", "bathroom"),
    "clean_and_place": ("kitchen", "kitchen", "bathroom"),
    "heat_and_place": ("kitchen",),
    "cool_and_place": ("kitchen",),
    "examine_in_light": ("living_room", "bedroom"),
}
#: long_horizon: the rooms each task type is drawn in. Long plans come from the scene and the goal -- the things
#: shut away in closed drawers, cabinets and the fridge, slicing, and extra preparation (``also``: washed, heated,
#: chilled) -- so a type goes where the appliances for that are: kitchens, and bathrooms for washing. Examining in
#: light is not drawn: lamps stand in living rooms and bedrooms, which have no knife, sink or appliance.
LONG_ROOMS = {
    "pick_and_place": ("kitchen", "bathroom"),
    "stack_and_place": ("kitchen",),
    "pick_two_and_place": ("bathroom",),
    "clean_and_place": ("kitchen", "bathroom", "bathroom"),
    "heat_and_place": ("kitchen",),
    "cool_and_place": ("kitchen",),
}
#: Which appliance a preparation needs in the room.
_HELPER_TYPE = {"clean": "SinkBasin", "hot": "Microwave", "cold": "Fridge"}
#: Destinations that would undo or make no sense after a preparation (a heated slice left in the fridge).
_UNDOES = {"hot": {"Fridge"}, "cold": {"Microwave"}, "clean": {"SinkBasin", "BathtubBasin"}}
# Destinations that make sense as "put it there" (no garbage can, no appliances for non-matching things).
_PLACE_TARGETS = {"CounterTop", "DiningTable", "Desk", "CoffeeTable", "SideTable", "Shelf", "Dresser", "Bed", "Sofa",
                  "ArmChair", "Ottoman", "TVStand", "Cabinet", "Drawer", "Fridge", "Safe", "SinkBasin",
                  "BathtubBasin", "Toilet", "TowelHolder", "HandTowelHolder", "ToiletPaperHanger", "CoffeeMachine",
                  "StoveBurner", "Microwave", "GarbageCan", "LaundryHamper", "Box", "Bowl", "Plate", "Pot", "Pan"}
#: Generator levels (``eb tasks generate env=alfred difficulty=...``; the splits take the same knob).
DIFFICULTIES = ("classic", "medium", "hard")
#: Action-list sizes kept (the paper's range).
MIN_ACTIONS, MAX_ACTIONS = 171, 298
#: Oracle-step range per subset (inclusive).
STEP_RANGE = {"base": (1, 14), "common_sense": (1, 14), "complex_instruction": (1, 14),
              "spatial_awareness": (1, 24), "visual_appearance": (1, 24), "long_horizon": (16, 26)}


def _types_in(world: World, pred) -> list[str]:
    return sorted({o.type for o in world.objects.values() if pred(o.type)})


def propose_goal(rng: random.Random, kind: str, world: World, sliced: bool = False) -> dict[str, Any] | None:
    """A type-level goal of ``kind`` that makes sense in ``world`` (or None)."""
    present = {o.type for o in world.objects.values()}
    if sliced and not (present & {"Knife", "ButterKnife"}):
        return None
    pool = _object_types(kind, world, present, sliced)
    if not pool:
        return None
    x = rng.choice(pool)
    goal: dict[str, Any] = {"kind": kind, "object": {"type": x}}
    if sliced:
        goal["sliced"] = True
    if kind == "examine_in_light":
        lamps = [t for t in LAMPS if t in present]
        if not lamps:
            return None
        goal["lamp"] = {"type": rng.choice(lamps)}
        return goal
    if kind == "stack_and_place":
        movs = [m for m in sorted(present) if is_movable_receptacle(m) and fits(x, m) and m != x]
        m = rng.choice(movs)
        goal["movable"] = {"type": m}
        x_for_r = m
    else:
        x_for_r = x
    receps = _destination_types(kind, x_for_r, present)
    if not receps:
        return None
    goal["receptacle"] = {"type": rng.choice(receps)}
    return goal


def _object_types(kind: str, world: World, present: set[str], sliced: bool) -> list[str]:
    """The types a goal of ``kind`` can be about in ``world`` (``present``: its types), in a stable order."""
    pick = lambda o: TYPES[o].pickupable
    pool = {
        "heat_and_place": [t for t in HEATABLE if t in present],
        "cool_and_place": [t for t in COOLABLE if t in present],
        "clean_and_place": [t for t in _types_in(world, lambda t: TYPES[t].dirtyable)],
        "examine_in_light": [t for t in EXAMINABLE if t in present],
        "pick_two_and_place": [t for t in _types_in(world, pick) if len(world.of_type(t)) >= 2],
    }.get(kind, _types_in(world, pick))
    if sliced:
        pool = [t for t in pool if TYPES[t].sliceable]
    if kind == "stack_and_place":
        pool = [t for t in pool if any(is_movable_receptacle(m) and fits(t, m) and m != t for m in present)]
    return pool


def _destination_types(kind: str, carried: str, present: set[str]) -> list[str]:
    """Where a goal of ``kind`` may put ``carried`` (not where its own step happens: no fridge for a cool goal)."""
    return [r for r in sorted(present) if r in _PLACE_TARGETS and fits(carried, r) and r != carried
            and not (kind == "cool_and_place" and r == "Fridge")
            and not (kind == "heat_and_place" and r == "Microwave")
            and not (kind == "clean_and_place" and r in ("SinkBasin", "BathtubBasin"))
            and r != "GarbageCan"]


def _can_be(type_name: str, prop: str) -> bool:
    return {"clean": TYPES[type_name].dirtyable, "hot": type_name in HEATABLE, "cold": type_name in COOLABLE}[prop]


def _add_preparation(rng: random.Random, world: World, goal: dict[str, Any]) -> dict[str, Any] | None:
    """long_horizon: ask for one or two extra preparations of the object (``also``) that the room and the
    object allow; None when none fits. Heat and cool never go together (chilling undoes heating)."""
    xt = goal["object"]["type"] if "type" in goal["object"] else world.objects[goal["object"]["instance"]].type
    own = PROPERTY_OF_KIND.get(goal["kind"])
    rec = goal.get("receptacle", {})
    dest = rec["type"] if "type" in rec else world.objects[rec["instance"]].type if rec else None
    options = [p for p in ("clean", "hot", "cold") if p != own and _can_be(xt, p) and world.of_type(_HELPER_TYPE[p])
               and (own is None or _can_be(xt, own)) and {p, own} != {"hot", "cold"} and dest not in _UNDOES[p]]
    if not options or (own is not None and dest in _UNDOES[own]):
        return None
    rng.shuffle(options)
    extra = options[:1] if own or rng.random() < 0.5 else options[:2]
    if {"hot", "cold"} <= set(extra):
        extra = extra[:1]
    return dict(goal, also=sorted(extra))


def _prepare(world: World, goal: dict[str, Any]) -> None:
    """Scene adjustments a task type needs: things to wash start dirty, lamps start off."""
    if "clean" in properties(goal):
        t = goal["object"].get("type") or world.objects[goal["object"]["instance"]].type
        for n in world.of_type(t):
            world.objects[n].is_dirty = True
    for t in LAMPS:
        for n in world.of_type(t):
            world.objects[n].is_on = False


_SHUT = ("Drawer", "Cabinet", "Safe", "Fridge", "Box")


def _shut_away(rng: random.Random, world: World, goal: dict[str, Any], skip_object: bool = False) -> bool:
    """Long-horizon scenes: put every instance of the things the task needs (the object, the dish it goes in,
    the knife) into closed drawers, cabinets, boxes or the fridge, so the agent has to search and open first.
    ``skip_object`` leaves the object's instances where they are (the hard set, whose look-alikes must each be
    cheap to inspect). False if some cannot be shut away."""
    def t_of(ref: dict[str, str]) -> str:
        return ref["type"] if "type" in ref else world.objects[ref["instance"]].type

    need = ([] if skip_object else [t_of(goal["object"])]) + ([t_of(goal["movable"])] if "movable" in goal else [])
    if goal.get("sliced"):
        need += [k for k in KNIVES if world.of_type(k)]
    dest = goal.get("receptacle", {})
    dest_names = set(world.of_type(dest["type"])) if "type" in dest else {dest.get("instance")}
    boxes = [n for n, o in world.objects.items() if o.type in _SHUT and n not in dest_names
             and not any(world.objects[a].type in need for a in [n, *world.ancestors(n)])]
    for t in need:
        for n in world.of_type(t):
            if world.closed_container(n) is not None:
                continue
            fits_in = [b for b in boxes if fits(t, world.objects[b].type) and len(world.children(b)) < 4
                       and not (world.objects[b].type == "Fridge" and not TYPES[t].sliceable and t not in HEATABLE)]
            if not fits_in:
                return False
            b = rng.choice(fits_in)
            world.objects[n].parent = b
            world.objects[n].floor_at = None
    return True


def _visual_variant(rng: random.Random, scene: dict[str, Any], goal: dict[str, Any]) -> tuple[dict, dict, str] | None:
    """Give the goal object look-alike distractors of the same type that differ in colour or shape only.

    Look-alikes start clean (dirt would change how their colour reads); a shape contrast keeps one colour
    for all of them, so only the drawn shape tells them apart.
    """
    xt = goal["object"]["type"]
    info = TYPES[xt]
    attrs = []
    if len(info.colors) >= 2:
        attrs.append("color")
    if len(info.shapes) >= 2:
        attrs.append("shape")
    if not attrs:
        return None
    attr = rng.choice(attrs)
    values = list(info.colors if attr == "color" else info.shapes)
    objs = scene["objects"]
    mine = [o for o in objs if o["type"] == xt]
    need = 2 if goal["kind"] == "pick_two_and_place" else 1
    target = rng.choice(mine)
    twins = 0
    while len(mine) < need + 1:  # add look-alikes next to the target
        twin = {k: v for k, v in target.items() if k not in ("is_dirty", "_mark")}
        twin["name"] = f"{xt}_{90 + twins}"
        twins += 1
        objs.append(twin)
        mine.append(twin)
    value = rng.choice(values)
    others = [v for v in values if v != value]
    rng.shuffle(mine)
    chosen = [target] + [o for o in mine if o is not target][: need - 1]
    for o in mine:
        o.pop("is_dirty", None)
        o[attr] = value if any(o is c for c in chosen) else rng.choice(others)
        if attr == "shape":
            o["color"] = target.get("color", info.colors[0])
    if need == 2:
        goal = dict(goal, object={"type": xt, attr: value})
        _renumber(objs)
        return scene, goal, f"{value} {plural(xt)}"
    target["_mark"] = True
    _renumber(objs)
    name = next(o["name"] for o in objs if o.pop("_mark", False))
    goal = dict(goal, object={"instance": name})
    return scene, goal, f"the {value} {noun(xt)}"


def _spatial_variant(rng: random.Random, world: World, goal: dict[str, Any],
                     views: Any = None) -> tuple[dict, dict[str, str], str] | None:
    """Refer to the object and/or the destination by where they are.

    With ``views`` (rendered images of the scene), only relations whose related things appear together in an
    image the agent can get are used.
    """
    phrases: dict[str, str] = {}
    notes = []
    goal = json.loads(json.dumps(goal))
    xt = goal["object"]["type"]

    roles = {world.objects[goal[k]["instance"]].type if "instance" in goal[k] else goal[k]["type"]
             for k in ("object", "receptacle", "movable", "lamp") if k in goal}

    def usable(options: list[tuple[str, str, list[str]]]) -> list[tuple[str, str, list[str]]]:
        # a landmark must not be another thing the task acts on ("the statue next to the box" into a box)
        options = [o for o in options if all(world.objects[n].type not in roles or world.objects[n].type ==
                                              world.objects[o[0]].type for n in o[2])]
        rng.shuffle(options)
        if views is None:
            return options
        out = []
        for o in options:
            where = views().together(o[2])
            if where is not None:
                out.append((o[0], f"{o[1]} (seen {where})", o[2]))
        return out

    if goal["kind"] != "pick_two_and_place" and len(world.of_type(xt)) >= 2:
        options = usable([(x, p, refs) for x in world.of_type(xt) for p, refs in object_relations(world, x)])
        if options:
            x, phrase, refs = options[0]
            goal["object"] = {"instance": x}
            phrases["obj"] = phrase.split(" (seen")[0]
            notes.append(f"object {x}: {phrase}")
    if "receptacle" in goal and "type" in goal["receptacle"]:
        rt = goal["receptacle"]["type"]
        if len(world.of_type(rt)) >= 2:
            options = usable([(r, p, refs) for r in world.of_type(rt) for p, refs in receptacle_relations(world, r)])
            if options:
                r, phrase, refs = options[0]
                goal["receptacle"] = {"instance": r}
                phrases["recep"] = phrase.split(" (seen")[0]
                notes.append(f"receptacle {r}: {phrase}")
    if not phrases:
        return None
    return goal, phrases, "; ".join(notes)


def image_problems(rec: dict[str, Any], views: Any) -> list[str]:
    """What the rendered start state of a generated task fails (see :mod:`eb_alfred.audit`); empty = keep it."""
    return (visibility_problems(rec["goal"], views) + attribute_problems(rec["instruction"], rec["goal"], views)
            + relation_problems(rec["instruction"], rec["goal"], views))


def make_one(subset: str, kind: str, seed: int, rng: random.Random,
              views_for: Any = None) -> dict[str, Any] | None:
    """One candidate task, or None. ``views_for(world)`` (optional) gives rendered views of a scene: then the
    task is kept only if everything it refers to can be seen (:func:`image_problems`)."""
    long = subset == "long_horizon"
    room = rng.choice(LONG_ROOMS[kind] if long else KIND_ROOMS[kind])
    size = rng.random()
    if long:
        size = 0.4 + 0.6 * size
    scene = make_scene(seed, room, size=size)
    world = World.from_scene(scene)
    if not MIN_ACTIONS <= len(scene_actions(world)) <= MAX_ACTIONS:
        return None
    sliced = long and room == "kitchen" and rng.random() < 0.6
    goal = propose_goal(rng, kind, world, sliced=sliced)
    if goal is None:
        return None
    # extra preparation: always for the plain kinds, half the time for washing / heating / chilling
    if long and (kind not in PROPERTY_OF_KIND or rng.random() < 0.5):
        goal = _add_preparation(rng, world, goal)
        if goal is None:
            return None
    notes = ""
    phrases: dict[str, str] | None = None
    if subset == "visual_appearance":
        got = _visual_variant(rng, scene, goal)
        if got is None:
            return None
        scene, goal, phrase = got
        world = World.from_scene(scene)
        phrases = {"obj": phrase} if "instance" in goal["object"] else {"objs": phrase}
        notes = f"object {json.dumps(goal['object'])}: {phrase}"
    _prepare(world, goal)
    if subset == "long_horizon" and rng.random() < 0.85:
        if not _shut_away(rng, world, goal):
            return None
    views_cache: list[Any] = []

    def views() -> Any:
        if not views_cache:
            views_cache.append(views_for(world))
        return views_cache[0]

    if subset == "spatial_awareness":
        got2 = _spatial_variant(rng, world, goal, views if views_for is not None else None)
        if got2 is None:
            return None
        goal, phrases, notes = got2
    if evaluate(goal, world)[1] > 0:  # start with nothing of the goal done
        return None
    lo, hi = STEP_RANGE[subset]
    plan = expert_plan(world, goal, limit=hi)
    if plan is None or not lo <= len(plan) <= hi:
        return None
    template, text = instruction_with_template(subset, rng, goal, world, phrases)
    if phrase_problems(text, goal, world):
        return None
    rec = {"instruction": text, "task_type": kind, "goal": goal, "scene": world.to_scene(), "scene_seed": seed,
           "oracle_steps": len(plan), "notes": notes, "template": template}
    if views_for is not None and subset in ("spatial_awareness", "visual_appearance") and image_problems(rec, views()):
        return None
    return rec




_make_one = make_one  # the old private name
