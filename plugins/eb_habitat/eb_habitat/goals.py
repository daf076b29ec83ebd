"""PDDL-style goal predicates, their evaluation on a :class:`~eb_habitat.world.World`, and sticky progress.

A predicate is written as a string, e.g. ``(on ?apple sofa)``, ``(inside mug_2 fridge)``, ``(open fridge)``,
``(closed left_drawer)``, ``(holding ?banana)``, ``(untouched mug_1)``, ``(once mug_2)``. An object argument is an
instance name (``mug_2``) or ``?type`` meaning "any instance of that type". Two conditions of the hard set read the
episode's history: ``untouched`` holds while that instance has never been picked up (a look-alike taken by mistake
stays a mistake even if it is put back), ``once`` while it has been picked up at most once (the object to move
goes straight to its place: trying receptacle after receptacle is no way to find it).

A task succeeds when every goal predicate holds. Its progress is the fraction of its subgoal predicate sets
that have held at some point of the episode (sticky: once reached, a set stays counted), as in the paper.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from eb_habitat.catalog import object_type, receptacle

if TYPE_CHECKING:
    from eb_habitat.world import World

__all__ = ["HISTORY", "GoalTracker", "Predicate", "PredicateError", "default_subgoals", "parse_predicate"]

_ARITY = {"on": 2, "inside": 2, "open": 1, "closed": 1, "holding": 1, "untouched": 1, "once": 1}
#: Predicates about the episode's history of one instance (hold at the start, can only get lost).
HISTORY = ("untouched", "once")
_FORM = re.compile(r"^\(\s*([a-z]+)((?:\s+[?A-Za-z0-9_]+)+)\s*\)$")


class PredicateError(ValueError):
    """A predicate string is malformed or names something unknown."""


@dataclass(frozen=True)
class Predicate:
    name: str
    args: tuple[str, ...]

    def __str__(self) -> str:
        return "(" + " ".join((self.name, *self.args)) + ")"

    @property
    def obj(self) -> str | None:
        """The object argument (instance name or ``?type``) of on/inside/holding, else None."""
        return self.args[0] if self.name in ("on", "inside", "holding") else None

    @property
    def target(self) -> str | None:
        """The receptacle argument of on/inside/open/closed, else None."""
        if self.name in ("on", "inside"):
            return self.args[1]
        if self.name in ("open", "closed"):
            return self.args[0]
        return None

    def matches(self, instance: str, type_key: str) -> bool:
        """Whether an object instance fits this predicate's object argument."""
        arg = self.obj
        return arg is not None and (arg == instance or arg == "?" + type_key)

    def holds(self, world: World) -> bool:
        if self.name in ("on", "inside"):
            return any(self.matches(it.name, it.type) for it in world.items_at(self.args[1]))
        if self.name == "open":
            return self.args[0] in world.opened
        if self.name == "closed":
            return self.args[0] not in world.opened
        if self.name == "holding":
            held = world.held_item
            return held is not None and self.matches(held.name, held.type)
        if self.name == "untouched":
            return world.picks.get(self.args[0], 0) == 0
        if self.name == "once":
            return world.picks.get(self.args[0], 0) <= 1
        raise AssertionError(self.name)  # pragma: no cover


def parse_predicate(text: str, instances: dict[str, str] | None = None) -> Predicate:
    """Parse ``text`` and check it against the catalogue.

    ``instances`` (instance name -> type key), when given, is used to check instance names.
    Raises :class:`PredicateError` with a one-line reason.
    """
    m = _FORM.match(text.strip()) if isinstance(text, str) else None
    if m is None:
        raise PredicateError(f"{text!r} is not a predicate like '(on ?apple sofa)'")
    name, args = m.group(1), tuple(m.group(2).split())
    if name not in _ARITY:
        raise PredicateError(f"unknown predicate {name!r} in {text!r}; known: {', '.join(_ARITY)}")
    if len(args) != _ARITY[name]:
        raise PredicateError(f"{name} takes {_ARITY[name]} argument(s), got {len(args)} in {text!r}")
    pred = Predicate(name, args)
    if name in HISTORY:
        if args[0].startswith("?"):
            raise PredicateError(f"{text!r}: {name} takes one instance name (e.g. mug_2), not a type")
        if instances is not None and args[0] not in instances:
            raise PredicateError(f"{text!r} names object {args[0]!r}, which is not in the scene")
    if pred.obj is not None:
        arg = pred.obj
        try:
            if arg.startswith("?"):
                object_type(arg[1:])
            elif instances is not None and arg not in instances:
                raise PredicateError(f"{text!r} names object {arg!r}, which is not in the scene")
        except KeyError as exc:
            raise PredicateError(f"{text!r}: {exc.args[0]}") from None
    if pred.target is not None:
        try:
            r = receptacle(pred.target)
        except KeyError as exc:
            raise PredicateError(f"{text!r}: {exc.args[0]}") from None
        if name == "on" and r.kind != "surface":
            raise PredicateError(f"{text!r}: the {r.name} is a container; use (inside ...)")
        if name == "inside" and r.kind != "container":
            raise PredicateError(f"{text!r}: the {r.name} is a surface; use (on ...)")
        if name in ("open", "closed") and not r.articulated:
            raise PredicateError(f"{text!r}: the {r.name} cannot be opened or closed")
    return pred


def default_subgoals(goal: list[Predicate]) -> list[list[Predicate]]:
    """The subgoal sets of a goal: for each object to move, holding it then having it in place;
    one set for each open/closed condition; holding goals are their own set. ``untouched`` and ``once`` hold from
    the start and only ever get lost, so they are no step of progress."""
    sets: list[list[Predicate]] = []
    for p in goal:
        if p.name in HISTORY:
            continue
        if p.name in ("on", "inside"):
            sets.append([Predicate("holding", (p.args[0],))])
            sets.append([p])
        else:
            sets.append([p])
    return sets


class GoalTracker:
    """Evaluates a task's goal and keeps the sticky subgoal progress of one episode."""

    def __init__(self, goal: list[Predicate], subgoals: list[list[Predicate]]) -> None:
        self.goal = goal
        self.subgoals = subgoals
        self.reached = [False] * len(subgoals)

    def update(self, world: World) -> None:
        for i, preds in enumerate(self.subgoals):
            if not self.reached[i] and all(p.holds(world) for p in preds):
                self.reached[i] = True

    def success(self, world: World) -> bool:
        return all(p.holds(world) for p in self.goal)

    def progress(self, world: World) -> float:
        if self.success(world):
            return 1.0
        if not self.subgoals:
            return 0.0
        return sum(self.reached) / len(self.subgoals)

    def unmet(self, world: World) -> list[Predicate]:
        return [p for p in self.goal if not p.holds(world)]
