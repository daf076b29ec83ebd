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
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from eb_habitat.catalog import (
    FRIDGE_END,
    KITCHEN_SIDE_CHAIR,
    N_APARTMENTS,
    OBJECT_TYPES,
    RECEPTACLES,
    ObjectType,
    capacity,
    object_type,
    receptacle,
)
from eb_habitat.goals import default_subgoals, parse_predicate
from eb_habitat.oracle import OracleError, expert_plan
from eb_habitat.tasks import FORMAT, SUBSETS, TASK_DIR, VERSION, load_task_file

__all__ = ["GENERATOR_VERSION", "PLURAL", "audit_form", "fix_articles", "generate", "generate_subset"]

GENERATOR_VERSION = "2"

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
    wide: bool = False
    """Hard sets (version 7): the long surfaces have :data:`~eb_habitat.catalog.WIDE_CAPACITY` slots."""

    def cap(self, key: str) -> int:
        """Slots of receptacle ``key`` in this scene."""
        return capacity(key, self.wide)

    def used_slots(self, key: str) -> set[int]:
        return {o["slot"] for o in self.objects if o["at"] == key}

    def has_room(self, key: str) -> bool:
        return len(self.used_slots(key)) < self.cap(key)

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
        free = [s for s in range(self.cap(at)) if s not in self.used_slots(at)]
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


# -- wording helpers ---------------------------------------------------------------------------------------

#: Object types whose name is plural ("the scissors are"): articles, pronouns and verbs follow.
PLURAL = frozenset({"scissors"})

_VOWEL_EXCEPTIONS = ("one", "uni", "use", "usu", "uten", "util", "eu")


def fix_articles(text: str) -> str:
    """``a`` before a vowel sound becomes ``an`` and ``an`` before a consonant becomes ``a``."""
    def repl(m: re.Match[str]) -> str:
        art, word = m.group(1), m.group(2)
        vowel = word[0].lower() in "aeiou" and not word.lower().startswith(_VOWEL_EXCEPTIONS)
        new = ("an" if vowel else "a") if art.lower() in ("a", "an") else art
        if art[0].isupper():
            new = new.capitalize()
        return f"{new} {word}"
    return re.sub(r"\b([Aa]n?) ([A-Za-z']+)", repl, text)


def _words(t: ObjectType) -> dict[str, str]:
    """Format fields for object ``t``: name, indefinite phrase, pronoun and verb forms that agree with it."""
    plural = t.key in PLURAL
    return {"o": t.name, "a_o": f"a pair of {t.name}" if plural else f"a {t.name}", "it": "them" if plural else "it",
            "is": "are" if plural else "is", "has": "have" if plural else "has", "needs": "need" if plural else "needs",
            "lies": "lie" if plural else "lies"}


def _frame(rng: random.Random, frames: tuple[str, ...], prefix: str) -> tuple[str, str]:
    """A random frame and its template id (``prefix.<index>``)."""
    i = rng.randrange(len(frames))
    return frames[i], f"{prefix}.{i}"


def _cap(text: str) -> str:
    return text[0].upper() + text[1:]


# -- base ------------------------------------------------------------------------------------------

_BASE_PHRASES = (
    "Move the {o} to the {t}.",
    "Find {a_o} and bring {it} to the {t}.",
    "Could you take the {o} and put {it} {pt}?",
    "Please relocate the {o} to the {t}.",
    "The {o} should be {pt}; please put {it} there.",
    "Go get the {o} and leave {it} {pt}.",
    "Carry {a_o} over to the {t}.",
    "I would like the {o} {pt}.",
    "Search the apartment for the {o} and set {it} down {pt}.",
    "Take the {o} to the {t}, please.",
)
_BASE_CLOSE = ("Put the {o} {pt} and close the {t} afterwards.", "Store {a_o} {pt}, then shut the {t}.")


def _base(rng: random.Random) -> Draft:
    t = _types(rng, 1)[0]
    scene = _new_scene(rng)
    src = rng.choice(ALL)
    scene.add(rng, t.key, at=src)
    target = _other_than(rng, src)
    _fill(rng, scene, rng.randint(5, 8), {t.key})
    style = rng.random()
    w = dict(_words(t), t=receptacle(target).name, pt=_prep_the(target))
    if style < 0.15:
        return Draft(f"Move the {t.name} from {_the(src)} to {_the(target)}.", scene,
                     [_place_pred("?" + t.key, target)], "base.move_from")
    if style < 0.3 and receptacle(target).articulated:
        frame, template = _frame(rng, _BASE_CLOSE, "base.store_close")
        return Draft(frame.format(**w), scene, [_place_pred("?" + t.key, target), f"(closed {target})"], template)
    frame, template = _frame(rng, _BASE_PHRASES, "base.move")
    return Draft(frame.format(**w), scene, [_place_pred("?" + t.key, target)], template)


# -- common sense ------------------------------------------------------------------------------------

#: Receptacles described by what they are for (our words), always as a noun phrase.
_RECEPTACLE_USES: dict[str, tuple[str, ...]] = {
    "fridge": ("the appliance that keeps food cold", "the cold box where fresh food is kept"),
    "sink": ("the basin where dirty dishes get washed",),
    "sofa": ("the comfortable seat where people relax and watch television",),
    "tv_stand": ("the piece of furniture that holds the television",),
    "dining_table": ("the table where the family eats dinner",),
    "desk": ("the place where someone sits to study or work",),
    "cabinet": ("the cupboard where kitchen supplies are stored",),
    "coffee_table": ("the low table where guests put down their drinks",),
}

_CS_FRAMES = (
    "Bring {u} to the {t}.",
    "I need {u}. Please leave it {pt}.",
    "Put {u} {pt}.",
    "Find {u} and place it {pt}.",
    "Someone asked for {u}; deliver it to the {t}.",
)
_CS_PLACE_FRAMES = ("Put {u} {p} {w}.", "Take {u} to {w}.", "Bring {u} over to {w}.")
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
        template = f"common_sense.purpose_{category}"
    else:
        t = _types(rng, 1)[0]
        frame, template = _frame(rng, _CS_FRAMES, "common_sense.object")
        category, targets = None, tuple(ALL)
    use = rng.choice(t.uses)
    target = rng.choice(targets)
    scene.add(rng, t.key, avoid=(target,))
    _fill(rng, scene, rng.randint(5, 8), {t.key})
    if category is None and target in _RECEPTACLE_USES and rng.random() < 0.6:
        frame, template = _frame(rng, _CS_PLACE_FRAMES, "common_sense.object_and_place")
        text = frame.format(u=use, w=rng.choice(_RECEPTACLE_USES[target]), p=receptacle(target).preposition)
    else:
        text = frame.format(u=use, t=receptacle(target).name, pt=_prep_the(target))
    return Draft(_cap(text), scene, [_place_pred("?" + t.key, target)], template)


# -- complex instructions ------------------------------------------------------------------------------

_IF_OPEN = (
    "If the {c} is open, move the {a} to the {t}; otherwise, move the {b} to the {t}.",
    "Check the {c}. When it is open, bring the {a} to the {t}; if it is shut, bring the {b} there instead.",
    "Should you find the {c} open, carry the {a} to the {t}. If not, carry the {b} to the {t}.",
)
_IF_PRESENT = (
    "If there is {a_x} {pp}, move the {a} to the {t}; if there is not, move the {b} to the {t}.",
    "Look at {p} first. Should {a_x} be lying there, put the {a} {pt}; otherwise put the {b} {pt}.",
)
#: The request is part of a longer story, not announced by a signpost; the object and the place appear once.
_CONTEXT = (
    "We have friends coming over tonight and I have been rushing around all afternoon, so the one thing still "
    "missing is the {o} {pt} before the doorbell rings.",
    "The plumber comes at noon because the heating made a strange noise this morning, and by then the {o} "
    "{is} supposed to be {pt}, which I keep forgetting to do myself.",
    "It rained all day, the windows are foggy, the cat has slept in the sun for hours, and I just noticed that "
    "the {o} never made it to the {t}; please take care of that.",
    "While I finish painting the hallway, I would be grateful if someone carried the {o} over to the {t}, "
    "because that is where I will look for {it} tonight.",
    "Our neighbour lent us a ladder, which is leaning against the wall outside; quite apart from that, the {o} "
    "{has} to go {pt} today, as I promised my sister.",
    "I keep forgetting where I put my reading glasses, and I am no better with other things: I meant to leave "
    "the {o} {pt} this morning and never did, so could you do it for me?",
)
#: A second object is named that must stay where it is.
_AVOID = (
    "Leave the {d} exactly where it is; it is the {o} that {needs} to go {pt}.",
    "Do not touch the {d}. What should end up {pt} is the {o}.",
)


def _complex(rng: random.Random) -> Draft:
    style = rng.random()
    scene = _new_scene(rng)
    if style < 0.25:  # conditional on a container's state
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
        frame, template = _frame(rng, _IF_OPEN, "complex.if_open")
        text = frame.format(c=receptacle(cont).name, a=a.name, b=b.name, t=receptacle(target).name)
        return Draft(text, scene, [_place_pred("?" + chosen.key, target)], template)
    if style < 0.5:  # conditional on what lies on a receptacle
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
        frame, template = _frame(rng, _IF_PRESENT, "complex.if_present")
        text = frame.format(a_x=_words(x)["a_o"], pp=_prep_the(probe), p=_the(probe), a=a.name, b=b.name,
                            t=receptacle(target).name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred("?" + chosen.key, target)], template)
    t = _types(rng, 1)[0]
    src = rng.choice(ALL)
    scene.add(rng, t.key, at=src)
    target = _other_than(rng, src)
    w = dict(_words(t), t=receptacle(target).name, pt=_prep_the(target))
    if style < 0.7:  # another object is named and must stay put
        d = rng.choice([o for o in OBJECT_TYPES if o.key != t.key])
        scene.add(rng, d.key, avoid=(target,))
        _fill(rng, scene, rng.randint(5, 8), {t.key, d.key})
        frame, template = _frame(rng, _AVOID, "complex.avoid")
        return Draft(frame.format(d=d.name, **w), scene, [_place_pred("?" + t.key, target)], template)
    _fill(rng, scene, rng.randint(5, 8), {t.key})
    frame, template = _frame(rng, _CONTEXT, "complex.context")
    return Draft(frame.format(**w), scene, [_place_pred("?" + t.key, target)], template)


# -- spatial relationships ----------------------------------------------------------------------------------

_BESIDE = (
    "On the {s}, take the object just to the {side} of the {r} and move it to the {t}.",
    "Move the item lying immediately to the {side} of the {r} {sp} to the {t}.",
    "Look at the {s}: whatever stands directly to the {side} of the {r} goes {pt}.",
)
_BETWEEN = (
    "Take the object between the {x} and the {y} {sp} and put it {pt}.",
    "{Sp}, something sits between the {x} and the {y}; move it to the {t}.",
)
_END = ("Move the {e} object {sp} to the {t}.", "Of the things {sp}, bring the {e} one to the {t}.")
_ORDINAL = ("Counting from the {side}, take the second object {sp} and move it to the {t}.",
            "{Sp} there are three objects in a row; bring the middle one to the {t}.")
_WITH_LANDMARK = (
    "Put the {o} on the same piece of furniture as the {lm}.",
    "Wherever the {lm} {lies}, the {o} should lie there too; bring {it} over.",
    "Find the {lm}, then move the {o} to the spot where you found {lm_it}.",
)
_SOURCE_LANDMARK = (
    "Take the {o} that {lies} right beside the {lm} and bring {it} to the {t}.",
    "There is more than one {o} around; move the one next to the {lm} to the {t}.",
)
_LAYOUT = (
    "Put the {o} {p} the {noun} {rel} the fridge.",
    "Put the {o} on the dining chair that is {rel} the kitchen.",
)

#: Surfaces with at least three slots (rows of objects).
_ROWS = [k for k in SURFACES if receptacle(k).capacity >= 3]


def _in_row(rng: random.Random, scene: Scene, src: str, types: list[ObjectType], first: int) -> list[dict]:
    """Put instances of ``types`` into consecutive slots of ``src`` from ``first``; returns them left to right."""
    out = []
    for k, t in enumerate(types):
        obj = {"name": f"{t.key}_1", "type": t.key, "color": rng.choice(t.colors), "at": src, "slot": first + k}
        scene.objects.append(obj)
        out.append(obj)
    return out


def _spatial(rng: random.Random) -> Draft:
    scene = _new_scene(rng)
    style = rng.random()
    if style < 0.22:  # the neighbour of a named object on a receptacle
        src = rng.choice(_ROWS)
        a, b = _types(rng, 2)
        side = rng.choice(("left", "right"))
        s = rng.randrange(receptacle(src).capacity - 1)
        pick, _ref = _in_row(rng, scene, src, [a, b] if side == "left" else [b, a], s)[::1 if side == "left" else -1]
        if rng.random() < 0.5:  # a twin elsewhere: "the one beside ..." matters
            scene.add(rng, a.key, avoid=(src,))
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), {a.key, b.key})
        frame, template = _frame(rng, _BESIDE, "spatial.beside")
        text = frame.format(s=receptacle(src).name, side=side, r=b.name, sp=_prep_the(src),
                            t=receptacle(target).name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred(pick["name"], target)], template)
    if style < 0.32:  # between two named objects
        src = rng.choice(_ROWS)
        x, m, y = _types(rng, 3)
        row = _in_row(rng, scene, src, [x, m, y], rng.randrange(receptacle(src).capacity - 2))
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), {x.key, m.key, y.key})
        frame, template = _frame(rng, _BETWEEN, "spatial.between")
        if rng.random() < 0.5:
            x, y = y, x
        sp = _prep_the(src)
        text = frame.format(x=x.name, y=y.name, sp=sp, Sp=_cap(sp), t=receptacle(target).name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred(row[1]["name"], target)], template)
    if style < 0.44:  # leftmost / rightmost
        src = rng.choice(_ROWS)
        types = _types(rng, 3)
        for t, slot in zip(types, rng.sample(range(receptacle(src).capacity), 3)):
            scene.objects.append({"name": f"{t.key}_1", "type": t.key, "color": rng.choice(t.colors), "at": src,
                                  "slot": slot})
        here = sorted((o for o in scene.objects if o["at"] == src), key=lambda o: o["slot"])
        end = rng.choice(("leftmost", "rightmost"))
        chosen = here[0] if end == "leftmost" else here[-1]
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), set(), avoid=(src,))
        frame, template = _frame(rng, _END, "spatial.end")
        text = frame.format(e=end, sp=_prep_the(src), t=receptacle(target).name)
        return Draft(text, scene, [_place_pred(chosen["name"], target)], template)
    if style < 0.54:  # second from one end / the middle of three
        frame, template = _frame(rng, _ORDINAL, "spatial.ordinal")
        if template.endswith(".0"):
            src = rng.choice([k for k in _ROWS if receptacle(k).capacity == 4])
            types = _types(rng, rng.choice((3, 4)))
            slots = sorted(rng.sample(range(4), len(types)))
        else:
            src = rng.choice([k for k in _ROWS if receptacle(k).capacity == 3])
            types, slots = _types(rng, 3), [0, 1, 2]
        for t, slot in zip(types, slots):
            scene.objects.append({"name": f"{t.key}_1", "type": t.key, "color": rng.choice(t.colors), "at": src,
                                  "slot": slot})
        here = sorted((o for o in scene.objects if o["at"] == src), key=lambda o: o["slot"])
        side = rng.choice(("left", "right"))
        chosen = here[1] if side == "left" or len(here) == 3 and not template.endswith(".0") else here[-2]
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), set(), avoid=(src,))
        sp = _prep_the(src)
        text = frame.format(side=side, sp=sp, Sp=_cap(sp), t=receptacle(target).name)
        return Draft(text, scene, [_place_pred(chosen["name"], target)], template)
    if style < 0.72:  # the target is wherever a movable landmark lies
        o, lm = _types(rng, 2)
        at = rng.choice(SURFACES)
        scene.add(rng, lm.key, at=at)
        if not scene.has_room(at):
            raise _Reject("no room beside the landmark")
        scene.add(rng, o.key, avoid=(at,))
        _fill(rng, scene, rng.randint(6, 9), {o.key, lm.key})
        frame, template = _frame(rng, _WITH_LANDMARK, "spatial.with_landmark")
        text = frame.format(lm=lm.name, lm_it=_words(lm)["it"], lies=_words(lm)["lies"], o=o.name,
                            it=_words(o)["it"])
        return Draft(text, scene, [_place_pred("?" + o.key, at)], template)
    if style < 0.88:  # which of several same-kind objects: the one beside a landmark
        o, lm = _types(rng, 2, [t for t in OBJECT_TYPES if t.key not in PLURAL])
        src = rng.choice(_ROWS)
        s = rng.randrange(receptacle(src).capacity - 1)
        n_twins = rng.choice((1, 2))
        for _ in range(n_twins):  # twins first, so the instance's number says nothing
            scene.add(rng, o.key, avoid=(src,))
        pair = [o, lm] if rng.random() < 0.5 else [lm, o]
        row = _in_row(rng, scene, src, pair, s)
        obj = next(r for r in row if r["type"] == o.key)
        obj["name"] = f"{o.key}_{n_twins + 1}"
        target = _other_than(rng, src)
        _fill(rng, scene, rng.randint(6, 9), {o.key, lm.key})
        frame, template = _frame(rng, _SOURCE_LANDMARK, "spatial.source_landmark")
        text = frame.format(o=o.name, lm=lm.name, lies="lies", it="it", t=receptacle(target).name)
        return Draft(text, scene, [_place_pred(obj["name"], target)], template)
    # a receptacle given by the apartment's layout, which differs between apartments
    o = _types(rng, 1)[0]
    frame, template = _frame(rng, _LAYOUT, "spatial.layout")
    near = rng.random() < 0.5
    if template.endswith(".0"):
        noun = rng.choice(("counter", "drawer"))
        end = FRIDGE_END[scene.apartment]
        side = end if near else ("right" if end == "left" else "left")
        target = f"{side}_{noun}"
        text = frame.format(o=o.name, p=receptacle(target).preposition, noun=noun,
                            rel="nearer to" if near else "farther from")
    else:
        kitchen_chair = KITCHEN_SIDE_CHAIR[scene.apartment]
        target = kitchen_chair if near else ("right_chair" if kitchen_chair == "left_chair" else "left_chair")
        text = frame.format(o=o.name, rel="nearer to" if near else "farther from")
    if not scene.has_room(target):
        raise _Reject("target full")
    scene.add(rng, o.key, avoid=(target,))
    _fill(rng, scene, rng.randint(6, 9), {o.key}, avoid=(target,))
    return Draft(text, scene, [_place_pred("?" + o.key, target)], template)


# -- visual appearance -----------------------------------------------------------------------------------

_COLOR_VARIANT = (
    "Move the {c} {o} to the {t}.",
    "Find the {o} that is {c} and put it {pt}.",
    "Only the {c} {o} should go {pt}; bring it there.",
    "The {c} {o}, not the other one, goes to the {t}.",
    "Pick out the {c} {o} and leave it {pt}.",
)
_LOOKS = (
    "Deliver {l} to the {t}.",
    "Somewhere there is {l}. Put it {pt}.",
    "Bring {l} over to the {t}.",
    "Move {l} so that it is {pt}.",
    "Look for {l} and set it down {pt}.",
)


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
        frame, template = _frame(rng, _COLOR_VARIANT, "visual.color_variant")
        text = frame.format(c=c1, o=t.name, t=receptacle(target).name, pt=_prep_the(target))
        return Draft(text, scene, [_place_pred(obj["name"], target)], template)
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
    frame, template = _frame(rng, _LOOKS, "visual.looks")
    text = frame.format(l=t.looks.format(color=color), t=receptacle(target).name, pt=_prep_the(target))
    return Draft(_cap(text), scene, [_place_pred(goal_obj, target)], template)


# -- long horizon ------------------------------------------------------------------------------------------


def _join(parts: list[str]) -> str:
    return ", ".join(parts[:-1]) + (", and " if len(parts) > 2 else " and ") + parts[-1]


_MULTI = ("Put {p}.", "Rearrange the apartment: {p}.", "Please place {p}.", "Tidy up as follows: {p}.",
          "Here is what I want: {p}.")
_GATHER = ("Gather {n} {pt}.", "Bring {n} to the {t}, one after another.",
           "Collect {n}, put them all {pt}, and close the {t} when you are done.")
_SWAP = (
    "Swap the places of the {a} and the {b}, carrying each to the receptacle where the other one started.",
    "Exchange the {a} and the {b}, so each ends up where the other one started.",
    "Trade the spots of the {a} and the {b}.",
)


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
        frame, template = _frame(rng, _MULTI, "long.multi_object")
        return Draft(frame.format(p=_join(parts)), scene, goals, template)
    if style < 0.75:  # several objects gathered in one place
        k = rng.choice((2, 3))
        target = rng.choice([key for key in ALL if receptacle(key).capacity >= k])
        types = _types(rng, k)
        for t in types:
            scene.add(rng, t.key, avoid=(target,))
        _fill(rng, scene, rng.randint(8, 10), {t.key for t in types})
        goals = [_place_pred("?" + t.key, target) for t in types]
        closing = receptacle(target).articulated and rng.random() < 0.6
        frame, template = _frame(rng, _GATHER if closing else _GATHER[:2], "long.gather")
        if closing:
            frame, template = _GATHER[2], "long.gather.2"
            goals.append(f"(closed {target})")
        text = frame.format(n=_join([f"the {t.name}" for t in types]), pt=_prep_the(target),
                            t=receptacle(target).name)
        return Draft(text, scene, goals, template)
    # multiple rearrangements: swap two objects
    a, b = _types(rng, 2)
    ra, rb = rng.sample([k for k in SURFACES], 2)
    scene.add(rng, a.key, at=ra)
    scene.add(rng, b.key, at=rb)
    _fill(rng, scene, rng.randint(7, 9), {a.key, b.key})
    if not scene.has_room(ra) or not scene.has_room(rb):
        raise _Reject("swap needs a free slot on both sides")
    frame, template = _frame(rng, _SWAP, "long.swap")
    text = frame.format(a=a.name, b=b.name)
    return Draft(text, scene, [_place_pred(f"{a.key}_1", rb), _place_pred(f"{b.key}_1", ra)], template)


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
    world = World(objects, scene.open, wide=scene.wide)
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
    if scene.wide:
        meta["wide"] = True
    return {"id": f"{subset}-{index:02d}", "subset": subset, "instruction": fix_articles(draft.instruction),
            "metadata": meta}


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


def generate(out: str | None = None, seed: int = 0, per_subset: int = 50, subset: str | None = None,
             split: str = "test", n: int | None = None, start: int = 0) -> list[str]:
    """Write validated task files and return their paths.

    ``split=train|val n=N [start=K] out=DIR`` writes tasks ``K .. K+N-1`` of a generated training split instead
    (disjoint from the shipped test tasks; :mod:`eb_habitat.splits`), for ``eb run env=habitat
    env.params.task_dir=DIR``.

    Args:
        out: a directory (one ``<subset>.json`` per subset) or a ``.json`` path (one subset only);
            default: the package's shipped ``tasks/`` folder.
        seed: generation seed (the shipped files use 0).
        per_subset: tasks per subset (the benchmark has 50).
        subset: only this subset (comma-separated list allowed); default all six.
    """
    if split != "test":  # generated train/val splits live in eb_habitat.splits (eb_habitat.make dispatches)
        raise ValueError(f"split={split}: eb_habitat.generate writes the test-style files only; use "
                         f"`eb tasks generate env=habitat split={split} n=N out=DIR` (eb_habitat.make:generate)")
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


def audit_form(out: str, seed: int, per_subset: int) -> list[str]:
    """A fresh form of ``per_subset`` tasks per subset (a folder at ``out``) for ``eb audit``'s parallel-forms
    probe; the subsets are drawn independently, so this is the first ``per_subset`` of a full file's draw."""
    return generate(out=out, seed=seed, per_subset=per_subset)


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
