"""PDDL-style goals of the 7 ALFRED task types, their conditions, success and progress.

A goal names objects by a *reference*: ``{"type": "Apple"}`` (any apple) or ``{"instance": "Apple_2"}``
(that apple; used when the instruction singles one out by colour or position). Each task type expands
into a short list of :class:`Condition` s; the task succeeds when all hold at once, and its progress is
the fraction that holds (the paper's subgoal success).

Condition counts follow the original's ``goal_conditions_met`` (``env/tasks.py``): pick & place 1, pick two &
place 2, examine in light 2, heat / cool / clean & place 3, stack & place 3; a sliced variant adds one
(``isSliced``), or two for pick two (two slices). As in the original, a sliced goal is about slices: only sliced
instances count for the other conditions. An unsliced goal is about a whole object: an instance that has been
sliced no longer counts (so slicing the only apple makes "put a washed apple in the fridge" unreachable).

A goal may combine conditions (long_horizon): ``"also": ["clean", "hot"]`` asks for extra preparation of the
object -- washed, heated or chilled (not both hot and cold: chilling undoes heating) -- on top of what its type
asks. Each extra property adds one condition ``(isClean x)``, and the final condition of the type (the object in
its receptacle, held under the lamp, in the dish on the table) then holds only for an object that has all of them.

A hard-set goal may also ask to leave look-alikes alone: ``"untouched": ["object", "receptacle"]`` means no
other instance of the object's (or the receptacle's) type may be handled at any time -- picked up, opened,
closed, switched, sliced or filled (:attr:`World.touched`). The instruction says so ("only the red one"), so a
wrong guess cannot be undone: it is one more condition, met only together with all the others.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal, get_args

from eb_alfred.world import World

__all__ = ["Condition", "GOAL_KINDS", "GoalKind", "conditions", "matches", "candidates", "usable", "evaluate", "PROPERTY_OF_KIND",
           "look_alike", "look_alikes", "failure_label", "properties", "EXTRA_PROPERTIES"]

GoalKind = Literal[
    "pick_and_place",
    "stack_and_place",
    "pick_two_and_place",
    "clean_and_place",
    "heat_and_place",
    "cool_and_place",
    "examine_in_light",
]
GOAL_KINDS: tuple[GoalKind, ...] = get_args(GoalKind)

#: The unary property each "X & place" kind asks for.
PROPERTY_OF_KIND = {"clean_and_place": "clean", "heat_and_place": "hot", "cool_and_place": "cold"}


@dataclass(frozen=True)
class Condition:
    text: str
    """Readable PDDL-like form, e.g. ``(and (isHot ?x) (inReceptacle ?x DiningTable))``."""
    check: Callable[[World], bool]


def matches(world: World, ref: dict[str, str], name: str) -> bool:
    """Whether instance ``name`` is what ``ref`` means (an instance, or a type with optional colour/shape)."""
    if "instance" in ref:
        return ref["instance"] == name
    o = world.objects[name]
    return (o.type == ref["type"] and ref.get("color", o.color) == o.color
            and ref.get("shape", o.shape) == o.shape)


def candidates(world: World, ref: dict[str, str]) -> list[str]:
    if "instance" in ref:
        return [ref["instance"]] if ref["instance"] in world.objects else []
    return [n for n in world.of_type(ref["type"]) if matches(world, ref, n)]


def _ref_text(ref: dict[str, str]) -> str:
    if "instance" in ref:
        return ref["instance"]
    looks = "".join(f"[{k}={ref[k]}]" for k in ("color", "shape") if k in ref)
    return ref["type"] + looks


def _having(prop: str) -> Callable[[World, str], bool]:
    """The predicate "``name`` has ``prop``" of :func:`_has`, for one property."""
    return lambda world, name: _has(world, name, prop)


def _has(world: World, name: str, prop: str) -> bool:
    o = world.objects[name]
    return {"hot": o.is_hot, "cold": o.is_cold, "clean": not o.is_dirty, "sliced": o.is_sliced}[prop]


def _inside(world: World, name: str, recep_ref: dict[str, str]) -> bool:
    parent = world.objects[name].parent
    return parent is not None and not world.is_held(name) and matches(world, recep_ref, parent)


#: The extra preparations a goal's ``also`` may ask for.
EXTRA_PROPERTIES = ("clean", "hot", "cold")


def properties(goal: dict[str, Any]) -> list[str]:
    """Every property the goal's object must end with: the type's own (heat -> hot) then the ``also`` ones."""
    own = PROPERTY_OF_KIND.get(goal["kind"])
    out = [own] if own else []
    return out + [p for p in goal.get("also", ()) if p not in out]


def usable(world: World, goal: dict[str, Any]) -> list[str]:
    """The instances that can serve as the goal's object in the current state.

    A sliced goal needs slices (the original's ``AppleSliced``), so only sliced instances count for placing,
    heating, holding...; an unsliced goal needs a whole object, so a sliced instance no longer counts.
    """
    want_sliced = bool(goal.get("sliced"))
    return [x for x in candidates(world, goal["object"]) if world.objects[x].is_sliced == want_sliced]


_PRED = {"hot": "isHot", "cold": "isCool", "clean": "isClean", "sliced": "isSliced"}


def conditions(goal: dict[str, Any]) -> list[Condition]:
    """Expand a goal into its conditions, counted as the original's ``goal_conditions_met`` counts them; a goal
    with ``untouched`` (the hard set) adds the gate of :func:`_untouched` last."""
    conds = _conditions(goal)
    if goal.get("untouched"):
        conds.append(_untouched(goal, list(conds)))
    return conds


def _conditions(goal: dict[str, Any]) -> list[Condition]:
    kind = goal["kind"]
    obj = goal["object"]
    sliced = bool(goal.get("sliced"))
    prop = PROPERTY_OF_KIND.get(kind)
    extra = [p for p in properties(goal) if p != prop]
    o = _ref_text(obj)
    xo = f"{o}Sliced" if sliced else o
    conds: list[Condition] = []

    def ready(w: World, x: str) -> bool:
        return all(_has(w, x, p) for p in extra)

    def some(pred: Callable[[World, str], bool]) -> Callable[[World], bool]:
        return lambda w: any(pred(w, x) for x in usable(w, goal))

    def and_ready(text: str) -> str:
        return f"(and {' '.join(f'({_PRED[p]} {xo})' for p in extra)} {text})" if extra else text

    def n_sliced(w: World) -> int:
        return sum(1 for x in candidates(w, obj) if w.objects[x].is_sliced)

    if sliced:
        conds.append(Condition(f"(isSliced {o})", lambda w: n_sliced(w) >= 1))
        if kind == "pick_two_and_place":
            conds.append(Condition(f"(isSliced {o}_second)", lambda w: n_sliced(w) >= 2))
    for p in extra:
        conds.append(Condition(f"({_PRED[p]} {xo})", some(_having(p))))

    if kind == "examine_in_light":
        lamp = goal["lamp"]
        conds.append(Condition(and_ready(f"(holds {xo})"), some(lambda w, x: w.held == x and ready(w, x))))
        conds.append(Condition(f"(and (isToggled {_ref_text(lamp)}) (atLocation agent {_ref_text(lamp)}))",
                               lambda w: any(w.objects[lm].is_on and w.near(lm) for lm in candidates(w, lamp))))
        return conds

    recep = goal["receptacle"]
    r = _ref_text(recep)
    if kind == "pick_two_and_place":
        def best(w: World) -> int:
            """Most usable objects inside one receptacle (both must share it, as in the original)."""
            counts: dict[str, int] = {}
            for x in usable(w, goal):
                if _inside(w, x, recep) and ready(w, x):
                    parent = w.objects[x].parent
                    counts[parent] = counts.get(parent, 0) + 1
            return max(counts.values(), default=0)
        conds.append(Condition(and_ready(f"(inReceptacle {xo} {r})"), lambda w: best(w) >= 1))
        conds.append(Condition(and_ready(f"(inReceptacle {xo}_second {r})"), lambda w: best(w) >= 2))
        return conds

    if kind == "stack_and_place":
        mov = goal["movable"]
        m = _ref_text(mov)

        def x_in_m(w: World, x: str) -> str | None:
            parent = w.objects[x].parent
            return parent if parent is not None and matches(w, mov, parent) else None

        conds.append(Condition(f"(inReceptacle {xo} {m})", some(lambda w, x: x_in_m(w, x) is not None)))
        conds.append(Condition(f"(inReceptacle {m} {r})", lambda w: any(_inside(w, y, recep) for y in candidates(w, mov))))
        conds.append(Condition(and_ready(f"(and (inReceptacle {xo} {m}) (inReceptacle {m} {r}))"),
                               some(lambda w, x: (mm := x_in_m(w, x)) is not None and _inside(w, mm, recep)
                                    and ready(w, x))))
        return conds

    if prop is None:
        conds.append(Condition(and_ready(f"(inReceptacle {xo} {r})"),
                               some(lambda w, x: _inside(w, x, recep) and ready(w, x))))
        return conds
    conds.append(Condition(f"(inReceptacle {xo} {r})", some(lambda w, x: _inside(w, x, recep))))
    conds.append(Condition(f"({_PRED[prop]} {xo})", some(lambda w, x: _has(w, x, prop))))
    conds.append(Condition(and_ready(f"(and ({_PRED[prop]} {xo}) (inReceptacle {xo} {r}))"),
                           some(lambda w, x: _inside(w, x, recep) and _has(w, x, prop) and ready(w, x))))
    return conds


def look_alikes(world: World, goal: dict[str, Any]) -> list[str]:
    """The instances a goal with ``untouched`` asks to leave alone: for each listed role, every instance of
    the role's type that the role's reference does not mean (the other mugs when the goal wants the red one)."""
    out: list[str] = []
    for role in goal.get("untouched", ()):
        ref = goal.get(role)
        if not ref:
            continue
        kind = ref["type"] if "type" in ref else world.objects[ref["instance"]].type
        out += [n for n in world.of_type(kind) if not matches(world, ref, n) and n not in out]
    return out


def _untouched(goal: dict[str, Any], inner: list[Condition]) -> Condition:
    """The gate of a goal with ``untouched``: every other condition holds and no look-alike was ever handled.

    It is counted as one more condition, so progress starts at 0 and reaches 1 only on success."""
    roles = " ".join(_ref_text(goal[r]) for r in goal["untouched"] if goal.get(r))

    def check(w: World) -> bool:
        return all(c.check(w) for c in inner) and not (w.touched & set(look_alikes(w, goal)))

    return Condition(f"(and (allOtherConditions) (untouchedLookAlikes {roles}))", check)


def evaluate(goal: dict[str, Any], world: World) -> tuple[bool, float, list[bool]]:
    """``(success, progress, per-condition flags)`` for the current state."""
    conds = conditions(goal)
    flags = [c.check(world) for c in conds]
    met = sum(flags)
    return met == len(flags), met / len(flags), flags


_ROLES = ("object", "receptacle", "movable", "lamp")


def look_alike(world: World, goal: dict[str, Any], name: str) -> bool:
    """Whether ``name`` is a same-type stand-in for something the goal singles out by instance, colour or shape
    (``Mug_1`` when the goal wants ``Mug_2``, the red mug when it wants the black one)."""
    if name not in world.objects:
        return False
    kind = world.objects[name].type
    for key in _ROLES:
        ref = goal.get(key)
        if not ref:
            continue
        picky = "instance" in ref or "color" in ref or "shape" in ref
        ref_type = world.objects[ref["instance"]].type if "instance" in ref and ref["instance"] in world.objects \
            else ref.get("type")
        if picky and ref_type == kind:
            return not matches(world, ref, name)
    return False


def failure_label(world: World, goal: dict[str, Any]) -> str | None:
    """The label of the action that just failed in ``world`` (``World.failure``), with a state failure on a
    look-alike of the goal's thing reported as ``wrong_target``."""
    label = world.failure
    if label == "precondition" and world.last_target is not None and look_alike(world, goal, world.last_target):
        return "wrong_target"
    return label
