"""The expert planner: a plan of skill ids that solves a task from any state of the symbolic world.

It knows where every object is (privileged information a model does not have) and simulates each action on
a copy of the world, so the plan it returns is exactly what the env will execute.
"""

from __future__ import annotations

from eb_habitat.catalog import RECEPTACLES
from eb_habitat.goals import HISTORY, Predicate
from eb_habitat.skills import skill_id
from eb_habitat.world import HAND, Item, World

__all__ = ["OracleError", "expert_plan"]


class OracleError(RuntimeError):
    """The goal cannot be reached by the expert from this state (a generator rejects such tasks)."""


class _Planner:
    def __init__(self, world: World, goal: list[Predicate]) -> None:
        self.w = world.copy()
        self.goal = goal
        self.plan: list[int] = []
        self.protected = {p.args[0] for p in goal if p.name == "untouched"}
        """Instances the goal forbids to pick up (the hard set's look-alikes): never taken, never moved aside."""

    def do(self, kind: str, arg: str) -> None:
        if kind == "pick":
            cand = self.w.pick_candidate(arg)
            if cand is not None and cand.name in self.protected:
                raise OracleError(f"picking the {arg} here would take {cand.name}, which must stay untouched")
        action = skill_id(kind, arg)
        out = self.w.step(action)
        if not out.success:
            raise OracleError(f"expert step {kind}({arg}) failed: {out.feedback}")
        self.plan.append(action)

    def goto(self, key: str) -> None:
        if self.w.agent_at != key:
            self.do("navigate", key)

    def ensure_open(self, key: str) -> None:
        if not self.w.is_open(key):
            self.goto(key)
            self.do("open", key)

    def placement_goals(self) -> list[Predicate]:
        return [p for p in self.goal if p.name in ("on", "inside")]

    def locked(self) -> set[str]:
        """Instances that currently satisfy a placement goal (the expert leaves them alone)."""
        out: set[str] = set()
        for p in self.placement_goals():
            for it in self.w.items_at(p.args[1]):
                if p.matches(it.name, it.type):
                    out.add(it.name)
                    break
        return out

    def goal_targets(self) -> set[str]:
        return {p.target for p in self.goal if p.target is not None}

    def blocked_places(self) -> set[str]:
        """Where a put-down object must not go: goal receptacles, and where objects still to be moved lie (it
        would block ``pick up`` there). A pure function of the state, so closed-loop replanning agrees."""
        out = self.goal_targets()
        locked = self.locked()
        for p in self.placement_goals():
            if not p.holds(self.w):
                out |= {it.loc for it in self.w.items.values()
                        if p.matches(it.name, it.type) and it.name not in locked and it.loc != HAND}
        return out

    def stash(self, avoid: frozenset[str] = frozenset()) -> None:
        """Put the held object down where it harms no goal: here if possible, else the first free surface."""
        here = self.w.agent_at
        blocked = self.blocked_places() | avoid
        if here is not None and self.w.is_open(here) and self.w.free_slot(here) is not None and here not in blocked:
            self.do("place", here)
            return
        for r in RECEPTACLES:
            if r.kind == "surface" and r.key not in blocked and self.w.free_slot(r.key) is not None:
                self.goto(r.key)
                self.do("place", r.key)
                return
        raise OracleError("no free surface to put the held object on")

    def clear_room(self, target: str) -> None:
        """``target`` is full: with an empty hand, carry away one thing that no goal wants there."""
        locked = self.locked()
        here = self.w.items_at(target)
        # `pick up` takes the leftmost of a kind: only the leftmost of its kind can be taken away directly.
        blockers = [it for it in here if it.name not in locked and it.name not in self.protected
                    and next(o for o in here if o.type == it.type).name == it.name]
        if not blockers:
            raise OracleError(f"the {target} is full and everything on it is needed there")
        if self.w.held is not None:
            self.stash(avoid=frozenset({target}))
        self.ensure_open(target)
        self.goto(target)
        blocker = blockers[0]
        self.do("pick", blocker.type)
        elsewhere = [p for p in self.placement_goals() if not p.holds(self.w) and p.args[1] != target
                     and p.matches(blocker.name, blocker.type)]
        if elsewhere:  # it is wanted somewhere else anyway: take it there (what a replanning expert would do)
            self.deliver(blocker, elsewhere[0].args[1])
        else:
            self.stash(avoid=frozenset({target}))

    def deliver(self, item: Item, target: str) -> None:
        """Bring ``item`` (held or lying somewhere) to ``target`` and put it there."""
        if self.w.free_slot(target) is None:
            self.clear_room(target)  # first, so that the plan is the same whichever step it is asked from
        if self.w.held != item.name:
            if self.w.held is not None:
                self.stash()
            source = item.loc
            self.ensure_open(source)
            self.goto(source)
            # `pick up the <type>` takes the leftmost instance of that type: move blockers out of the way.
            for _ in range(8):
                cand = self.w.pick_candidate(item.type)
                if cand is None or cand.name == item.name:
                    break
                self.do("pick", item.type)
                self.stash(avoid=frozenset({source}))
                self.goto(source)
            self.do("pick", item.type)
            if self.w.held != item.name:
                raise OracleError(f"could not pick {item.name}")
        self.ensure_open(target)
        self.goto(target)
        self.do("place", target)

    def choose(self, p: Predicate) -> Item:
        """The instance to bring for an unmet placement goal."""
        locked = self.locked()
        cands = [it for it in self.w.items.values() if p.matches(it.name, it.type) and it.name not in locked
                 and it.name not in self.protected]
        if not cands:
            raise OracleError(f"no object left for {p}")
        held = self.w.held
        # Prefer what is already in hand, then what lies where we stand, then anything (stable order).
        cands.sort(key=lambda it: (it.name != held, it.loc != self.w.agent_at, it.name))
        return cands[0]

    def solve(self) -> list[int]:
        lost = [p for p in self.goal if p.name in HISTORY and not p.holds(self.w)]
        if lost:  # the hard set's rules about the past: nothing brings them back
            how = "at all" if lost[0].name == "untouched" else "more than once"
            raise OracleError(f"{lost[0]} no longer holds: {lost[0].args[0]} was picked up {how}, which the task "
                              f"forbids")
        for _ in range(3):  # a later goal may be undone by an earlier one only in odd states: retry a little
            # What is in hand first: deliver it if a goal wants it, else put it down harmlessly.
            held = self.w.held_item
            if held is not None:
                wanted = [p for p in self.placement_goals() if not p.holds(self.w) and p.matches(held.name, held.type)]
                holding_goal = any(p.name == "holding" and p.matches(held.name, held.type) for p in self.goal)
                if wanted:
                    self.deliver(held, wanted[0].args[1])
                elif not holding_goal:
                    self.stash()
            for p in self.placement_goals():
                if not p.holds(self.w):
                    self.deliver(self.choose(p), p.args[1])
            for p in self.goal:
                if p.name == "open" and not p.holds(self.w):
                    self.ensure_open(p.args[0])
                elif p.name == "closed" and not p.holds(self.w):
                    self.goto(p.args[0])
                    self.do("close", p.args[0])
            for p in self.goal:
                if p.name == "holding" and not p.holds(self.w):
                    if self.w.held is not None:
                        self.stash()
                    cands = sorted((it for it in self.w.items.values() if p.matches(it.name, it.type)
                                    and it.name not in self.locked()), key=lambda it: it.name)
                    if not cands:
                        raise OracleError(f"nothing to hold for {p}")
                    item = cands[0]
                    self.ensure_open(item.loc)
                    self.goto(item.loc)
                    self.do("pick", item.type)
            if all(p.holds(self.w) for p in self.goal):
                return self.plan
        raise OracleError("the expert could not satisfy every goal predicate")


def expert_plan(world: World, goal: list[Predicate]) -> list[int]:
    """Skill ids that take ``world`` (left unchanged) to a state where every goal predicate holds.

    Returns an empty list when the goal already holds. Raises :class:`OracleError` if it cannot.
    """
    return _Planner(world, goal).solve()

