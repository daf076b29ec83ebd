"""Task generator behind ``eb tasks generate env=habitat``: our own instruction templates, six subsets.

Every candidate task is validated before it is written: the file schema and catalogue checks of
:mod:`eb_habitat.tasks`, the goal must not hold at the start, and the expert must solve it within a step
bound that leaves a searching agent room inside the 30-step budget. Generation is deterministic in ``seed``.

    eb tasks generate env=habitat out=/tmp/habitat_tasks seed=1
    python -m eb_habitat.generate --out plugins/eb_habitat/eb_habitat/tasks
"""

from __future__ import annotations

import json
import random
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from eb_habitat.catalog import N_APARTMENTS, OBJECT_TYPES, RECEPTACLES, ObjectType, object_type, receptacle
from eb_habitat.goals import default_subgoals, parse_predicate
from eb_habitat.oracle import OracleError, expert_plan
from eb_habitat.tasks import FORMAT, SUBSETS, TASK_DIR, VERSION, load_task_file

__all__ = ["GENERATOR_VERSION", "generate", "generate_subset"]

GENERATOR_VERSION = "1"

SURFACES = [r.key for r in RECEPTACLES if r.kind == "surface"]
CONTAINERS = [r.key for r in RECEPTACLES if r.kind == "container"]
ALL = [r.key for r in RECEPTACLES]
#: Oracle-step bound per subset: a model that must search needs the rest of the 30-step budget.
MAX_ORACLE_STEPS = {"long_horizon": 20}
DEFAULT_MAX_ORACLE_STEPS = 12


# -- scenes -------------------------------------------------------------------------------------


@dataclass
class Scene:
    apartment: int
    objects: list[dict[str, Any]] = field(default_factory=list)
    open: list[str] = field(default_factory=list)

    def used_slots(self, key: str) -> set[int]:
        return {o["slot"] for o in self.objects if o["at"] == key}

    def has_room(self, key: str) -> bool:
        return len(self.used_slots(key)) < receptacle(key).capacity

    def types_at(self, key: str) -> set[str]:
        return {o["type"] for o in self.objects if o["at"] == key}

    def add(self, rng: random.Random, type_key: str, at: str | None = None, color: str | None = None,
            avoid: tuple[str, ...] = ()) -> dict[str, Any]:
        """Put a new instance of ``type_key`` at ``at`` (or a random receptacle with room) in a random slot."""
        t = object_type(type_key)
        if at is None:
            choices = [k for k in ALL if k not in avoid and self.has_room(k) and type_key not in self.types_at(k)]
            at = rng.choice(choices)
        if not self.has_room(at) or type_key in self.types_at(at):
            raise _Reject(f"no room for {type_key} at {at}")
        free = [s for s in range(receptacle(at).capacity) if s not in self.used_slots(at)]
        n = 1 + sum(1 for o in self.objects if o["type"] == type_key)
        obj = {"name": f"{type_key}_{n}", "type": type_key, "color": color or rng.choice(t.colors), "at": at,
               "slot": rng.choice(free)}
        self.objects.append(obj)
        return obj

    def sorted_objects(self) -> list[dict[str, Any]]:
        return sorted(self.objects, key=lambda o: (ALL.index(o["at"]), o["slot"]))


class _Reject(Exception):
    """This random draw does not make a good task; draw again."""


def _new_scene(rng: random.Random, p_open: float = 0.2) -> Scene:
    return Scene(apartment=rng.randrange(N_APARTMENTS), open=[c for c in CONTAINERS if rng.random() < p_open])


def _fill(rng: random.Random, scene: Scene, n_total: int, exclude: set[str], avoid: tuple[str, ...] = ()) -> None:
    """Add distractor objects of types not in ``exclude`` (and not already present) up to ``n_total``,
    never on the receptacles in ``avoid``."""
    present = {o["type"] for o in scene.objects}
    pool = [t.key for t in OBJECT_TYPES if t.key not in exclude and t.key not in present]
    rng.shuffle(pool)
    while len(scene.objects) < n_total and pool:
        scene.add(rng, pool.pop(), avoid=avoid)


def _types(rng: random.Random, k: int, pool: list[ObjectType] | None = None) -> list[ObjectType]:
    return rng.sample(pool or list(OBJECT_TYPES), k)


def _place_pred(obj: str, target: str) -> str:
    return f"({'inside' if receptacle(target).kind == 'container' else 'on'} {obj} {target})"


def _the(key: str) -> str:
    return f"the {receptacle(key).name}"


def _prep_the(key: str) -> str:
    r = receptacle(key)
    return f"{r.preposition} the {r.name}"


def _other_than(rng: random.Random, *keys: str, pool: list[str] | None = None) -> str:
    return rng.choice([k for k in (pool or ALL) if k not in keys])


@dataclass
class Draft:
    instruction: str
    scene: Scene
    goal: list[str]
    template: str


# -- base ------------------------------------------------------------------------------------------

_BASE_PHRASES = (
    "Move the {o} to the {t}.",
    "Find a {o} and bring it to the {t}.",
    "Could you take the {o} and put it {pt}?",
    "Relocate one {o} so that it ends up {pt}.",
    "The {o} belongs {pt}; please put it there.",
    "Go get the {o} and leave it {pt}.",
    "Carry a {o} over to the {t}.",
    "I would like the {o} to be {pt}.",
    "Search the apartment for the {o} and set it down {pt}.",
    "Take the {o} to the {t}, please.",
)


def _base(rng: random.Random) -> Draft:
    t = _types(rng, 1)[0]
    scene = _new_scene(rng)
    src = rng.choice(ALL)
    scene.add(rng, t.key, at=src)
    target = _other_than(rng, src)
    _fill(rng, scene, rng.randint(5, 8), {t.key})
    style = rng.random()
    if style < 0.15:
        text = f"Move the {t.name} from {_the(src)} to {_the(target)}."
        template = "base.move_from"
    elif style < 0.3 and receptacle(target).articulated:
        text = rng.choice(("Put the {o} {pt} and close it afterwards.", "Store a {o} {pt}, then shut it."))
        text = text.format(o=t.name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred("?" + t.key, target), f"(closed {target})"], "base.store_close")
    else:
        text = rng.choice(_BASE_PHRASES).format(o=t.name, t=receptacle(target).name, pt=_prep_the(target))
        template = "base.move"
    return Draft(text, scene, [_place_pred("?" + t.key, target)], template)


# -- common sense ------------------------------------------------------------------------------------

#: Receptacles described by what they are for (our words).
_RECEPTACLE_USES: dict[str, tuple[str, ...]] = {
    "fridge": ("the appliance that keeps food cold", "where food goes to stay fresh and chilled"),
    "sink": ("the place where dirty dishes get washed",),
    "sofa": ("the comfortable seat where people relax and watch television",),
    "tv_stand": ("the furniture that holds the television",),
    "dining_table": ("the table where the family eats dinner",),
    "desk": ("the place where someone sits to study or work",),
    "cabinet": ("the cupboard where kitchen supplies are stored",),
    "coffee_table": ("the low table where guests put their drinks while sitting on the sofa",),
}

_CS_FRAMES = (
    "Bring {u} to the {t}.",
    "I need {u}. Please leave it {pt}.",
    "Put {u} {pt}.",
    "Find {u} and place it {pt}.",
    "Someone asked for {u}; deliver it to the {t}.",
)
_CS_PURPOSE = (
    ("Get ready for a game: deliver {u} to the {t}.", "toy", ("tv_stand", "coffee_table", "sofa")),
    ("I am about to cook. Put {u} {pt}.", "kitchenware", ("left_counter", "right_counter", "sink")),
    ("Time for a snack: bring {u} to the {t}.", "fruit", ("coffee_table", "dining_table", "sofa", "desk")),
    ("There is a repair job to do. Leave {u} {pt}.", "tool", ("desk", "brown_table", "dining_table")),
    ("Stock up the kitchen: put {u} {pt}.", "food", ("cabinet", "fridge", "left_counter", "right_counter")),
)


def _common_sense(rng: random.Random) -> Draft:
    scene = _new_scene(rng)
    if rng.random() < 0.4:
        frame, category, targets = rng.choice(_CS_PURPOSE)
        t = rng.choice([o for o in OBJECT_TYPES if o.category == category])
    else:
        frame, category, targets = rng.choice(_CS_FRAMES), None, tuple(ALL)
    if category is None:
        t = _types(rng, 1)[0]
    use = rng.choice(t.uses)
    target = rng.choice(targets)
    scene.add(rng, t.key, avoid=(target,))
    _fill(rng, scene, rng.randint(5, 8), {t.key})
    if category is None and target in _RECEPTACLE_USES and rng.random() < 0.6:
        where = rng.choice(_RECEPTACLE_USES[target])
        text = rng.choice(("Put {u} {p} {w}.", "Take {u} to {w}.", "Bring {u} over to {w}."))
        text = text.format(u=use, w=where, p=receptacle(target).preposition)
        template = "common_sense.object_and_place"
    else:
        text = frame.format(u=use, t=receptacle(target).name, pt=_prep_the(target))
        template = "common_sense.object" if category is None else f"common_sense.purpose_{category}"
    text = text[0].upper() + text[1:]
    return Draft(text, scene, [_place_pred("?" + t.key, target)], template)


# -- complex instructions ------------------------------------------------------------------------------

_NOISE_BEFORE = (
    "We have friends coming over tonight and I have been rushing around all afternoon.",
    "The heating made a strange noise this morning, but it seems fine now.",
    "My cousin left a pile of magazines by the door, just ignore those.",
    "It rained all day, so the windows are a bit foggy.",
    "I finally finished painting the hallway last weekend.",
    "The cat has been sleeping in the sun for hours.",
    "Our neighbour lent us a ladder that is leaning against the wall outside.",
    "I keep forgetting where I put my reading glasses.",
)
_NOISE_AFTER = (
    "Thanks, that will make the evening much easier.",
    "No need to tidy anything else.",
    "After that you can take a break.",
    "The rest of the room is fine as it is.",
    "I will water the plants myself later.",
)


def _complex(rng: random.Random) -> Draft:
    style = rng.random()
    scene = _new_scene(rng)
    if style < 0.3:  # conditional on a container's state
        a, b = _types(rng, 2)
        cont = rng.choice(CONTAINERS)
        is_open = rng.random() < 0.5
        scene.open = sorted(set(scene.open) - {cont} | ({cont} if is_open else set()))
        scene.add(rng, a.key)
        scene.add(rng, b.key)
        target = rng.choice([k for k in ALL if k != cont])
        chosen = a if is_open else b
        if any(o["type"] == chosen.key and o["at"] == target for o in scene.objects):
            raise _Reject("already there")
        _fill(rng, scene, rng.randint(5, 8), {a.key, b.key})
        frame = rng.choice((
            "If the {c} is open, move the {a} to the {t}; otherwise, move the {b} to the {t}.",
            "Check the {c}. When its door is open, bring the {a} to the {t}; if it is shut, bring the {b} there instead.",
            "Should you find the {c} open, carry the {a} to the {t}. If not, carry the {b} to the {t}.",
        ))
        text = frame.format(c=receptacle(cont).name, a=a.name, b=b.name, t=receptacle(target).name)
        return Draft(text, scene, [_place_pred("?" + chosen.key, target)], "complex.if_open")
    if style < 0.55:  # conditional on what lies on a receptacle
        a, b, x = _types(rng, 3)
        probe = rng.choice(SURFACES)
        present = rng.random() < 0.5
        if present:
            scene.add(rng, x.key, at=probe)
        scene.add(rng, a.key, avoid=(probe,))
        scene.add(rng, b.key, avoid=(probe,))
        target = _other_than(rng, probe)
        chosen = a if present else b
        if any(o["type"] == chosen.key and o["at"] == target for o in scene.objects):
            raise _Reject("already there")
        _fill(rng, scene, rng.randint(5, 8), {a.key, b.key, x.key})
        if not present and x.key in {o["type"] for o in scene.objects}:
            raise _Reject("probe type present elsewhere")
        frame = rng.choice((
            "If there is a {x} {pp}, move the {a} to the {t}; if there is not, move the {b} to the {t}.",
            "Look at {p} first. Should a {x} be lying there, put the {a} {pt}; otherwise put the {b} {pt}.",
        ))
        text = frame.format(x=x.name, pp=_prep_the(probe), p=_the(probe), a=a.name, b=b.name,
                            t=receptacle(target).name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred("?" + chosen.key, target)], "complex.if_present")
    # irrelevant context around a plain request
    t = _types(rng, 1)[0]
    src = rng.choice(ALL)
    scene.add(rng, t.key, at=src)
    target = _other_than(rng, src)
    _fill(rng, scene, rng.randint(5, 8), {t.key})
    core = rng.choice((
        "what I actually need is the {o} {pt}.",
        "could you move the {o} to the {t}?",
        "please find the {o} and put it {pt}.",
        "the {o} should end up {pt}.",
    )).format(o=t.name, t=receptacle(target).name, pt=_prep_the(target))
    before = rng.sample(_NOISE_BEFORE, rng.randint(1, 2))
    text = " ".join(before) + " Anyway, " + core + " " + rng.choice(_NOISE_AFTER)
    return Draft(text, scene, [_place_pred("?" + t.key, target)], "complex.irrelevant_context")


# -- spatial relationships ----------------------------------------------------------------------------------


def _spatial(rng: random.Random) -> Draft:
    scene = _new_scene(rng)
    style = rng.random()
    if style < 0.35:  # target receptacle given by where it is
        t = _types(rng, 1)[0]
        target = rng.choice([r.key for r in RECEPTACLES if r.spatial])
        scene.add(rng, t.key, avoid=(target,))
        _fill(rng, scene, rng.randint(5, 8), {t.key})
        where = rng.choice(receptacle(target).spatial)
        prep = receptacle(target).preposition
        text = rng.choice(("Move the {o} to {w}.", "Put a {o} {p} {w}.", "Find the {o} and leave it {p} {w}."))
        text = text.format(o=t.name, p=prep, w=where)
        return Draft(text, scene, [_place_pred("?" + t.key, target)], "spatial.target")
    if style < 0.7:  # object next to another object on a receptacle
        src = rng.choice([k for k in SURFACES if receptacle(k).capacity >= 3])
        a, b = _types(rng, 2)
        s = rng.randrange(receptacle(src).capacity - 1)
        side = rng.choice(("left", "right"))
        pick_t, ref_t = (a, b)
        pick_slot, ref_slot = (s, s + 1) if side == "left" else (s + 1, s)
        scene.objects.append({"name": f"{pick_t.key}_1", "type": pick_t.key, "color": rng.choice(pick_t.colors),
                              "at": src, "slot": pick_slot})
        scene.objects.append({"name": f"{ref_t.key}_1", "type": ref_t.key, "color": rng.choice(ref_t.colors),
                              "at": src, "slot": ref_slot})
        if rng.random() < 0.5:  # a twin elsewhere makes "the one next to..." matter
            scene.add(rng, pick_t.key, avoid=(src,))
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), {a.key, b.key})
        frame = rng.choice((
            "On {s}, take the object just to the {side} of the {r} and move it to the {t}.",
            "Move the item lying immediately {side} of the {r} {sp} to the {t}.",
        ))
        text = frame.format(s=_the(src), side=side, r=ref_t.name, sp=_prep_the(src), t=receptacle(target).name)
        return Draft(text, scene, [_place_pred(f"{pick_t.key}_1", target)], "spatial.next_to_object")
    if style < 0.85:  # leftmost / rightmost
        src = rng.choice([k for k in SURFACES if receptacle(k).capacity >= 3])
        types = _types(rng, 3)
        for t, slot in zip(types, rng.sample(range(receptacle(src).capacity), 3)):
            scene.objects.append({"name": f"{t.key}_1", "type": t.key, "color": rng.choice(t.colors), "at": src,
                                  "slot": slot})
        here = sorted((o for o in scene.objects if o["at"] == src), key=lambda o: o["slot"])
        end = rng.choice(("leftmost", "rightmost"))
        chosen = here[0] if end == "leftmost" else here[-1]
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), set(), avoid=(src,))
        text = rng.choice(("Move the {e} object {sp} to the {t}.", "Of the things {sp}, bring the {e} one to the {t}."))
        text = text.format(e=end, sp=_prep_the(src), t=receptacle(target).name)
        return Draft(text, scene, [_place_pred(chosen["name"], target)], "spatial.end_of_row")
    # source receptacle given by where it is, with a twin elsewhere
    t = _types(rng, 1)[0]
    src = rng.choice([r.key for r in RECEPTACLES if r.spatial])
    obj = scene.add(rng, t.key, at=src)
    scene.add(rng, t.key, avoid=(src,))
    target = _other_than(rng, src)
    _fill(rng, scene, rng.randint(6, 9), {t.key})
    where = rng.choice(receptacle(src).spatial)
    text = rng.choice(("Take the {o} that is {p} {w} and move it to the {t}.",
                       "Bring the {o} from {w} over to the {t}."))
    text = text.format(o=t.name, p=receptacle(src).preposition, w=where, t=receptacle(target).name)
    return Draft(text, scene, [_place_pred(obj["name"], target)], "spatial.source")


# -- visual appearance -----------------------------------------------------------------------------------


def _visual(rng: random.Random) -> Draft:
    scene = _new_scene(rng)
    style = rng.random()
    variants = [o for o in OBJECT_TYPES if o.has_variants]
    if style < 0.45:  # colour variants of one type in different places
        t = rng.choice(variants)
        c1, c2 = rng.sample(t.colors, 2)
        obj = scene.add(rng, t.key, color=c1)
        scene.add(rng, t.key, color=c2, avoid=(obj["at"],))
        target = _other_than(rng, obj["at"])
        _fill(rng, scene, rng.randint(6, 9), {t.key})
        text = rng.choice(("Move the {c} {o} to the {t}.", "Find the {o} that is {c} and put it {pt}.",
                           "Only the {c} {o} should go {pt}; bring it there."))
        text = text.format(c=c1, o=t.name, t=receptacle(target).name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred(obj["name"], target)], "visual.color_variant")
    # described by looks only
    t = rng.choice(OBJECT_TYPES)
    color = rng.choice(t.colors)
    obj = scene.add(rng, t.key, color=color)
    goal_obj = "?" + t.key
    if t.has_variants:  # the look names the colour: a differently coloured twin makes it matter
        scene.add(rng, t.key, color=rng.choice([c for c in t.colors if c != color]), avoid=(obj["at"],))
        goal_obj = obj["name"]
    target = _other_than(rng, obj["at"])
    _fill(rng, scene, rng.randint(6, 9), {t.key})
    looks = t.looks.format(color=color)
    text = rng.choice(("Deliver {l} to the {t}.", "Somewhere there is {l}. Put it {pt}.",
                       "Bring {l} over to the {t}.", "Move {l} so that it is {pt}."))
    text = text.format(l=looks, t=receptacle(target).name, pt=_prep_the(target))
    return Draft(text[0].upper() + text[1:], scene, [_place_pred(goal_obj, target)], "visual.looks")


# -- long horizon ------------------------------------------------------------------------------------------


def _join(parts: list[str]) -> str:
    return ", ".join(parts[:-1]) + (", and " if len(parts) > 2 else " and ") + parts[-1]


def _long(rng: random.Random) -> Draft:
    scene = _new_scene(rng, p_open=0.15)
    style = rng.random()
    if style < 0.45:  # several objects, each to its own place
        k = rng.choice((2, 3, 3))
        types = _types(rng, k)
        goals, parts = [], []
        for t in types:
            obj = scene.add(rng, t.key)
            target = _other_than(rng, obj["at"])
            goals.append(_place_pred("?" + t.key, target))
            parts.append(f"the {t.name} {_prep_the(target)}")
        _fill(rng, scene, rng.randint(8, 10), {t.key for t in types})
        text = rng.choice(("Put {p}.", "Rearrange the apartment: {p}.", "Please place {p}."))
        return Draft(text.format(p=_join(parts)), scene, goals, "long.multi_object")
    if style < 0.75:  # several objects gathered in one place
        k = rng.choice((2, 3))
        target = rng.choice([key for key in ALL if receptacle(key).capacity >= k])
        types = _types(rng, k)
        for t in types:
            scene.add(rng, t.key, avoid=(target,))
        _fill(rng, scene, rng.randint(8, 10), {t.key for t in types})
        names = _join([f"the {t.name}" for t in types])
        goals = [_place_pred("?" + t.key, target) for t in types]
        if receptacle(target).articulated and rng.random() < 0.6:
            goals.append(f"(closed {target})")
            text = f"Collect {names}, put them all {_prep_the(target)}, and close it when you are done."
        else:
            text = rng.choice(("Gather {n} {pt}.", "Bring {n} to the {t}, one after another."))
            text = text.format(n=names, pt=_prep_the(target), t=receptacle(target).name)
        return Draft(text, scene, goals, "long.gather")
    # multiple rearrangements: swap two objects, or a chain of moves
    a, b = _types(rng, 2)
    ra, rb = rng.sample([k for k in SURFACES], 2)
    scene.add(rng, a.key, at=ra)
    scene.add(rng, b.key, at=rb)
    _fill(rng, scene, rng.randint(7, 9), {a.key, b.key})
    if not scene.has_room(ra) or not scene.has_room(rb):
        raise _Reject("swap needs a free slot on both sides")
    text = rng.choice((
        "Swap the places of the {a} and the {b}: the {a} goes where the {b} is now, and the {b} goes where the {a} is now.",
        "Exchange the {a} and the {b}, so each ends up where the other one started.",
    )).format(a=a.name, b=b.name)
    return Draft(text, scene, [_place_pred(f"{a.key}_1", rb), _place_pred(f"{b.key}_1", ra)], "long.swap")


BUILDERS: dict[str, Callable[[random.Random], Draft]] = {
    "base": _base,
    "common_sense": _common_sense,
    "complex_instruction": _complex,
    "spatial_relationship": _spatial,
    "visual_appearance": _visual,
    "long_horizon": _long,
}


# -- validation and files ---------------------------------------------------------------------------------


def _finish(draft: Draft, subset: str, index: int) -> dict[str, Any] | None:
    """Turn a draft into a task entry, or None if it fails validation."""
    from eb_habitat.world import World

    scene = draft.scene
    objects = scene.sorted_objects()
    inst = {o["name"]: o["type"] for o in objects}
    goal = [parse_predicate(g, inst) for g in draft.goal]
    world = World(objects, scene.open)
    if all(p.holds(world) for p in goal):
        return None
    try:
        plan = expert_plan(world, goal)
    except OracleError:
        return None
    if len(plan) > MAX_ORACLE_STEPS.get(subset, DEFAULT_MAX_ORACLE_STEPS):
        return None
    meta = {
        "apartment": scene.apartment,
        "template": draft.template,
        "objects": objects,
        "open": sorted(scene.open),
        "goal": [str(p) for p in goal],
        "subgoals": [[str(p) for p in group] for group in default_subgoals(goal)],
        "oracle_steps": len(plan),
    }
    return {"id": f"{subset}-{index:02d}", "subset": subset, "instruction": draft.instruction, "metadata": meta}


def generate_subset(subset: str, n: int = 50, seed: int = 0) -> list[dict[str, Any]]:
    """``n`` validated task entries of ``subset`` (deterministic in ``seed``), distinct instructions."""
    if subset not in BUILDERS:
        raise ValueError(f"unknown subset {subset!r}; known: {', '.join(SUBSETS)}")
    rng = random.Random(f"eb-habitat/{GENERATOR_VERSION}/{seed}/{subset}")
    out: list[dict[str, Any]] = []
    seen: set[str] = set()
    tries = 0
    while len(out) < n:
        tries += 1
        if tries > 200 * n:
            raise RuntimeError(f"could not draw {n} valid {subset} tasks")
        try:
            draft = BUILDERS[subset](rng)
        except _Reject:
            continue
        if draft.instruction in seen:
            continue
        entry = _finish(draft, subset, len(out))
        if entry is None:
            continue
        seen.add(draft.instruction)
        out.append(entry)
    return out


def generate(out: str | None = None, seed: int = 0, per_subset: int = 50, subset: str | None = None) -> list[str]:
    """Write validated task files and return their paths.

    Args:
        out: a directory (one ``<subset>.json`` per subset) or a ``.json`` path (one subset only);
            default: the package's shipped ``tasks/`` folder.
        seed: generation seed (the shipped files use 0).
        per_subset: tasks per subset (the benchmark has 50).
        subset: only this subset (comma-separated list allowed); default all six.
    """
    subsets = list(SUBSETS) if subset is None else [s.strip() for s in str(subset).split(",") if s.strip()]
    target = Path(out) if out is not None else TASK_DIR
    if target.suffix == ".json" and len(subsets) != 1:
        raise ValueError("out=<file>.json writes one subset: also pass subset=<name>, or give a directory")
    written: list[str] = []
    for name in subsets:
        tasks = generate_subset(name, int(per_subset), int(seed))
        doc = {
            "format": FORMAT,
            "version": VERSION,
            "subset": name,
            "generator": {"name": "eb_habitat.generate", "version": GENERATOR_VERSION, "seed": int(seed)},
            "tasks": tasks,
        }
        path = target if target.suffix == ".json" else target / f"{name}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
        load_task_file(path)  # what we write must load
        written.append(str(path))
    return written


def main(argv: list[str] | None = None) -> None:
    import argparse

    ap = argparse.ArgumentParser(description="Generate EB-Habitat task files.")
    ap.add_argument("--out", default=None, help="directory or .json file (default: the shipped tasks/ folder)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--per-subset", type=int, default=50)
    ap.add_argument("--subset", default=None)
    args = ap.parse_args(argv)
    for p in generate(args.out, args.seed, args.per_subset, args.subset):
        print(p)


if __name__ == "__main__":
    main()
