"""Step bounds of seeing agents without privileged knowledge, for the hard generator and the difficulty figures.

* :func:`search_steps`: an agent **with memory** walks to the receptacles in catalogue order (opening closed ones)
  until it has seen everything it needs, then follows the expert's plan.
* :func:`stateless_search_steps`: an agent **without memory**, as the benchmark's planner is with its default
  ``chat_history=False``: every call sees the current image and the action history with the world's feedback,
  never its own earlier descriptions. It can act only on what one view (and the text) tells it.

Both walk the catalogue forward by default; ``reverse=True`` walks it backward (desk first). The hard generator
holds its bounds in both directions, so a task is not kept for lying early in one order (a blind player that knows
the order would gain).
"""

from __future__ import annotations

from typing import Any

from eb_habitat.catalog import RECEPTACLES, object_type, receptacle

__all__ = ["GATHERING", "IN_THE_WAY", "WITNESS_ELSEWHERE", "first_met", "gather_steps", "stateless_search_steps",
           "search_steps"]

GATHERING = (".gather.", ".gather_not.")
"""Template parts of quantified gatherings ("bring every red toy to the coffee table"): the instruction never says
how many objects qualify, so no agent can know it has found them all before it has seen every receptacle."""

WITNESS_ELSEWHERE = (".if_beside.",)
"""Template parts whose object is told by a witness on another receptacle (version 2's conditionals: "if the mug
beside the red bowl is yellow, bring the orange mug there"): the view that tells which object to move is not the
view where it can be picked up, so no agent without memory can act on it."""

IN_THE_WAY = ".in_the_way."
"""Template part of version 5's "in the way" clause ("if another mug stands to its left on the furniture it stands
on, first move that one to the sofa"): the view that shows the object shows the look-alike left of it, so one plan
moves the look-alike to the named receptacle and walks straight back for the object."""

_LIMIT = 60
"""A walk longer than this is not worth following: the caller's bound is far below."""


def _named(key: str, instruction: str) -> bool:
    return receptacle(key).name.lower() in instruction.lower()


def _order(reverse: bool) -> list[str]:
    keys = [r.key for r in RECEPTACLES]
    return keys[::-1] if reverse else keys


def _deciding_place(objects: list[dict[str, Any]], movers: set[str], instruction: str, template: str) -> str | None:
    """For a counting conditional (``.if_count.``): the receptacle of the landmark whose count decides the branch
    (the one object other than the movers named by colour and type); else None."""
    if ".if_count." not in template:
        return None
    text = instruction.lower()
    named = [o["at"] for o in objects if o["name"] not in movers
             and f"{o['color']} {object_type(o['type']).name.lower()}" in text]
    return named[0] if len(named) == 1 else None


def search_steps(objects: list[dict[str, Any]], opened: list[str], goal: list[str], instruction: str,
                 template: str = "", reverse: bool = False, wide: bool = False) -> int:
    """Steps of a seeing agent with memory: it walks to the receptacles in catalogue order (``reverse``: backward)
    opening the closed ones, until it has seen every object the goal moves and every destination the instruction
    does not name (a landmark's place) or whose count decides a conditional, then follows the expert's plan from
    there."""
    from eb_habitat.goals import parse_predicate
    from eb_habitat.oracle import expert_plan
    from eb_habitat.skills import skill_id
    from eb_habitat.world import World

    if any(part in template for part in GATHERING):
        return gather_steps(objects, opened, goal, reverse, memory=True, wide=wide) or _LIMIT + 1
    w = World(objects, opened, wide=wide)
    inst = {o["name"]: o["type"] for o in objects}
    preds = [parse_predicate(g, inst) for g in goal]
    places = [p for p in preds if p.name in ("on", "inside")]
    need = {next(o["at"] for o in objects if o["name"] == p.args[0]) for p in places if p.args[0] in inst}
    need |= {p.args[1] for p in places if not _named(p.args[1], instruction)}
    gate = _deciding_place(objects, set(inst) & {p.args[0] for p in places}, instruction, template)
    need |= {gate} if gate else set()
    steps = 0
    for key in _order(reverse):
        if not need:
            break
        w.step(skill_id("navigate", key))
        steps += 1
        if not w.is_open(key):
            w.step(skill_id("open", key))
            steps += 1
        need.discard(key)
    return steps + len(expert_plan(w, preds))


class _Walker:
    """The world of a step bound, with the steps taken so far: ``do`` one skill, ``go`` to a receptacle (and open
    it), ``finish`` with the expert's remaining non-placing goals (None when it has no plan for them)."""

    def __init__(self, objects: list[dict[str, Any]], opened: list[str], goal: list[str], wide: bool = False
                 ) -> None:
        from eb_habitat.goals import parse_predicate
        from eb_habitat.world import World

        self.w = World(objects, opened, wide=wide)
        inst = {o["name"]: o["type"] for o in objects}
        self.preds = [parse_predicate(g, inst) for g in goal]
        self.dest = {p.args[0]: p.args[1] for p in self.preds if p.name in ("on", "inside") and p.args[0] in inst}
        self.steps = 0

    def do(self, kind: str, arg: str) -> bool:
        from eb_habitat.skills import skill_id

        self.steps += 1
        return self.w.step(skill_id(kind, arg)).success

    def go(self, key: str) -> None:
        if self.w.agent_at != key:
            self.do("navigate", key)
        if not self.w.is_open(key):
            self.do("open", key)

    def finish(self) -> int | None:
        from eb_habitat.oracle import OracleError, expert_plan

        try:
            return self.steps + len(expert_plan(self.w, [p for p in self.preds if p.name not in ("on", "inside")]))
        except OracleError:
            return None


def stateless_search_steps(objects: list[dict[str, Any]], opened: list[str], goal: list[str], instruction: str,
                           template: str = "", reverse: bool = False, wide: bool = False) -> int | None:
    """Steps of a seeing agent **without memory**, or None when no such agent can solve the task.

    It walks to the receptacles in catalogue order (``reverse``: backward), opening closed ones, and in each view
    does everything that view allows, in one plan: with an empty hand it picks up an object the goal moves if the
    view tells that it is that object (its colour, its row, what lies beside it: all on the object's own
    receptacle); holding one, it places it when it stands at its destination and knows it is one -- a receptacle
    the instruction names is known from the text (it walks straight there), a landmark's receptacle only in the
    view that shows the landmark, and in a counting conditional the named receptacle only once it holds the object
    at the landmark whose count decides. It cannot know what it passed, so after every pick it starts its walk
    again from the first receptacle -- except after moving a look-alike out of the way (:data:`IN_THE_WAY`): the
    view that showed it showed the object right of it, so the same plan walks straight back there. None when an
    object is told only by a witness on another receptacle (:data:`WITNESS_ELSEWHERE`), when ``pick up`` would
    take another instance, or when a whole walk finds nothing to act on."""
    if any(part in template for part in WITNESS_ELSEWHERE):
        return None
    if any(part in template for part in GATHERING):
        return gather_steps(objects, opened, goal, reverse, wide=wide)
    walker = _Walker(objects, opened, goal, wide)
    w, preds, dest, do, go = walker.w, walker.preds, walker.dest, walker.do, walker.go
    if len(dest) != sum(p.name in ("on", "inside") for p in preds):
        return None  # a goal that accepts any instance of a type: not a hard-set goal
    pending = set(dest)
    gate = _deciding_place(objects, set(dest), instruction, template)

    order = _order(reverse)
    walk = 0  # the next receptacle of the current walk
    origin: dict[str, str] = {}  # where each picked object came from
    while pending and walker.steps <= _LIMIT:
        held = w.held
        if held is not None and _named(dest[held], instruction) and gate in (None, w.agent_at):
            go(dest[held])
            if not do("place", dest[held]):
                return None
            pending.discard(held)
            back = origin.get(held)
            if back is not None and IN_THE_WAY in template and any(w.items[n].loc == back for n in pending):
                walk = order.index(back)  # it moved a look-alike out of the way there: the object is right there
            continue
        if walk >= len(order):
            return None  # a whole walk without anything to act on
        here = order[walk]
        walk += 1
        go(here)
        while True:  # everything this view allows
            held = w.held
            if held is not None and dest[held] == here:
                if not do("place", here):
                    return None
                pending.discard(held)
                continue
            if held is None:
                todo = sorted(n for n in pending if w.items[n].loc == here)
                if todo:
                    takes = [w.pick_candidate(w.items[n].type) for n in todo]
                    cand = next((c for c in takes if c is not None and c.name in todo), None)
                    if cand is None:
                        return None  # the object is not the one ``pick up`` takes
                    do("pick", cand.type)
                    origin[cand.name] = here
                    walk = 0  # it cannot know what it passed: the walk starts again
                    if _named(dest[cand.name], instruction) and gate in (None, here):
                        break
                    continue
            break
    if pending or walker.steps > _LIMIT:
        return None
    return walker.finish()


def gather_steps(objects: list[dict[str, Any]], opened: list[str], goal: list[str], reverse: bool = False,
                 memory: bool = False, wide: bool = False) -> int | None:
    """Steps of a seeing agent in a quantified gathering (:data:`GATHERING`), or None when it cannot finish.

    Every view tells by itself which objects qualify (their colour and type) and the destination is named, so the
    agent needs no landmark; but it does not know how many objects qualify, so it walks every receptacle in
    catalogue order (``reverse``: backward), opening closed ones, until the last one is delivered (the episode
    ends on success). In each view it picks up a qualifying object if ``pick up`` takes one (else it moves on; None
    if ``pick up`` would take another instance first), carries it to the destination, places it and walks back to
    look again. Without memory (the benchmark's planner) it always walks back, since only the view can tell
    whether another one is left there; with ``memory`` only when one is. ``wide``: a wide (hard) task's slots."""
    walker = _Walker(objects, opened, goal, wide)
    w, dest, do, go = walker.w, walker.dest, walker.do, walker.go
    pending = set(dest)

    for here in _order(reverse):
        if not pending:
            break
        go(here)
        while pending:
            todo = [n for n in pending if w.items[n].loc == here]
            if not todo:
                break
            cand = w.pick_candidate(w.items[todo[0]].type)
            if cand is None or cand.name not in pending:
                return None  # ``pick up`` takes another instance first
            do("pick", cand.type)
            go(dest[cand.name])
            if not do("place", dest[cand.name]):
                return None
            pending.discard(cand.name)
            if pending and (not memory or any(w.items[n].loc == here for n in pending)):
                go(here)
    if pending:
        return None
    return walker.finish()


def first_met(objects: list[dict[str, Any]], goal: list[str], reverse: bool = False) -> bool:
    """Whether a blind walker takes every object the goal moves: walking the catalogue in order (``reverse``:
    backward), it picks up each object's type at the first receptacle that holds one."""
    from eb_habitat.world import World

    types = {o["name"]: o["type"] for o in objects}
    movers = [g.split()[1] for g in goal if g.startswith(("(on ", "(inside "))]
    for name in movers:
        for key in _order(reverse):
            cand = World(objects, agent_at=key).pick_candidate(types[name])
            if cand is not None:
                if cand.name != name:
                    return False
                break
    return True
