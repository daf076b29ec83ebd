"""The task generator: scene seeds -> the six versioned task files (``eb tasks generate env=alfred``).

For every subset it walks through scene seeds, proposes a goal of the next task type for a scene of a fitting
room, adapts the scene where the subset needs it (dirty objects to wash, look-alike distractors for the
visual subset), words the instruction, and keeps the task only if the oracle solves it within the subset's
step range. The output is deterministic for a given ``seed``.
"""

from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

from eb_alfred.actions import scene_actions
from eb_alfred.catalog import LAMPS, TYPES, fits, is_movable_receptacle
from eb_alfred.goals import GOAL_KINDS, evaluate
from eb_alfred.instructions import instruction, noun, plural, relation_for_object, relation_for_receptacle
from eb_alfred.oracle import expert_plan
from eb_alfred.scenes import _renumber, make_scene
from eb_alfred.tasks import FORMAT, SUBSETS, TASK_DIR, VERSION
from eb_alfred.world import World

__all__ = ["generate", "make_tasks", "propose_goal"]

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
# Destinations that make sense as "put it there" (no garbage can, no appliances for non-matching things).
_PLACE_TARGETS = {"CounterTop", "DiningTable", "Desk", "CoffeeTable", "SideTable", "Shelf", "Dresser", "Bed", "Sofa",
                  "ArmChair", "Ottoman", "TVStand", "Cabinet", "Drawer", "Fridge", "Safe", "SinkBasin",
                  "BathtubBasin", "Toilet", "TowelHolder", "HandTowelHolder", "ToiletPaperHanger", "CoffeeMachine",
                  "StoveBurner", "Microwave", "GarbageCan", "LaundryHamper", "Box", "Bowl", "Plate", "Pot", "Pan"}
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
    pick = lambda o: TYPES[o].pickupable  # noqa: E731
    if sliced and not (present & {"Knife", "ButterKnife"}):
        return None
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
    receps = [r for r in sorted(present) if r in _PLACE_TARGETS and fits(x_for_r, r) and r != x_for_r
              and not (kind == "cool_and_place" and r == "Fridge")
              and not (kind == "heat_and_place" and r == "Microwave")
              and not (kind == "clean_and_place" and r in ("SinkBasin", "BathtubBasin"))
              and r != "GarbageCan"]
    if not receps:
        return None
    goal["receptacle"] = {"type": rng.choice(receps)}
    return goal


def _prepare(world: World, goal: dict[str, Any]) -> None:
    """Scene adjustments a task type needs: things to wash start dirty, lamps start off."""
    if goal["kind"] == "clean_and_place":
        t = goal["object"].get("type") or world.objects[goal["object"]["instance"]].type
        for n in world.of_type(t):
            world.objects[n].is_dirty = True
    for t in LAMPS:
        for n in world.of_type(t):
            world.objects[n].is_on = False


def _visual_variant(rng: random.Random, scene: dict[str, Any], goal: dict[str, Any]) -> tuple[dict, dict, str] | None:
    """Give the goal object look-alike distractors of the same type that differ in colour or shape."""
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
        o[attr] = value if any(o is c for c in chosen) else rng.choice(others)
    if need == 2:
        goal = dict(goal, object={"type": xt, attr: value})
        _renumber(objs)
        return scene, goal, f"{value} {plural(xt)}"
    target["_mark"] = True
    _renumber(objs)
    name = next(o["name"] for o in objs if o.pop("_mark", False))
    goal = dict(goal, object={"instance": name})
    return scene, goal, f"the {value} {noun(xt)}"


def _spatial_variant(rng: random.Random, world: World, goal: dict[str, Any]) -> tuple[dict, dict[str, str], str] | None:
    """Refer to the object and/or the destination by where they are."""
    phrases: dict[str, str] = {}
    notes = []
    goal = json.loads(json.dumps(goal))
    xt = goal["object"]["type"]
    if goal["kind"] != "pick_two_and_place" and len(world.of_type(xt)) >= 2:
        options = [(x, relation_for_object(world, x)) for x in world.of_type(xt)]
        options = [(x, p) for x, p in options if p]
        if options:
            x, phrase = rng.choice(options)
            goal["object"] = {"instance": x}
            phrases["obj"] = phrase
            notes.append(f"object {x}: {phrase}")
    if "receptacle" in goal and "type" in goal["receptacle"]:
        rt = goal["receptacle"]["type"]
        if len(world.of_type(rt)) >= 2:
            options = [(r, relation_for_receptacle(world, r)) for r in world.of_type(rt)]
            options = [(r, p) for r, p in options if p]
            if options:
                r, phrase = rng.choice(options)
                goal["receptacle"] = {"instance": r}
                phrases["recep"] = phrase
                notes.append(f"receptacle {r}: {phrase}")
    if not phrases:
        return None
    return goal, phrases, "; ".join(notes)


def _make_one(subset: str, kind: str, seed: int, rng: random.Random) -> dict[str, Any] | None:
    room = rng.choice(KIND_ROOMS[kind])
    size = rng.random()
    if subset == "long_horizon":
        size = 0.4 + 0.6 * size
    scene = make_scene(seed, room, size=size)
    world = World.from_scene(scene)
    if not MIN_ACTIONS <= len(scene_actions(world)) <= MAX_ACTIONS:
        return None
    sliced = subset == "long_horizon" and rng.random() < 0.6
    goal = propose_goal(rng, kind, world, sliced=sliced)
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
    if subset == "spatial_awareness":
        got2 = _spatial_variant(rng, world, goal)
        if got2 is None:
            return None
        goal, phrases, notes = got2
    if evaluate(goal, world)[1] > 0:  # start with nothing of the goal done
        return None
    lo, hi = STEP_RANGE[subset]
    plan = expert_plan(world, goal, limit=hi)
    if plan is None or not lo <= len(plan) <= hi:
        return None
    text = instruction(subset, rng, goal, world, phrases)
    return {"instruction": text, "task_type": kind, "goal": goal, "scene": world.to_scene(), "scene_seed": seed,
            "oracle_steps": len(plan), "notes": notes}


def make_tasks(subset: str, seed: int = 0, n: int = 50) -> list[dict[str, Any]]:
    """``n`` tasks of ``subset``, task types in turn, deterministic for ``seed``."""
    rng = random.Random(f"eb-alfred/{seed}/{subset}")
    base_seed = 1000 * (SUBSETS.index(subset) + 1) + 100_000 * seed
    tasks: list[dict[str, Any]] = []
    scene_seed = base_seed
    count = {k: 0 for k in GOAL_KINDS}
    misses = {k: 0 for k in GOAL_KINDS}
    while len(tasks) < n:
        # The task type with the fewest tasks so far (types that keep failing are given up on).
        open_kinds = [k for k in GOAL_KINDS if misses[k] < 400]
        if not open_kinds:
            raise RuntimeError(f"could not generate {n} {subset} tasks (got {len(tasks)})")
        kind = min(open_kinds, key=lambda k: (count[k], GOAL_KINDS.index(k)))
        scene_seed += 1
        rec = _make_one(subset, kind, scene_seed, rng)
        if rec is None:
            misses[kind] += 1
            continue
        misses[kind] = 0
        count[kind] += 1
        tasks.append({"id": f"{subset}_{len(tasks):02d}", "subset": subset, **rec})
    return tasks


def generate(out: str | None = None, seed: int = 0, n: int = 50, subset: str | None = None) -> list[str]:
    """Write task files. ``out``: a directory (one ``<subset>.json`` each) or a ``.json`` path with ``subset``.

    Defaults to the package's own ``tasks/`` folder (the shipped, versioned files).
    """
    subsets = [subset] if subset else list(SUBSETS)
    for s in subsets:
        if s not in SUBSETS:
            raise ValueError(f"unknown subset {s!r}; choose from {', '.join(SUBSETS)}")
    target = Path(out) if out else TASK_DIR
    if target.suffix == ".json" and len(subsets) != 1:
        raise ValueError("writing a single .json file needs subset=<name>")
    written = []
    for s in subsets:
        path = target if target.suffix == ".json" else target / f"{s}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        doc = {"format": FORMAT, "version": VERSION, "subset": s,
               "generator": {"function": "eb_alfred.generate:generate", "seed": seed, "n": n},
               "tasks": make_tasks(s, seed=seed, n=n)}
        path.write_text(json.dumps(doc, indent=1, sort_keys=False) + "\n", encoding="utf-8")
        written.append(str(path))
    return written


if __name__ == "__main__":  # python -m eb_alfred.generate
    for p in generate():
        print("wrote", p)
