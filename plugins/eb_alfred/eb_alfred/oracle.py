"""The oracle planner: a search over the symbolic state for the shortest plan that reaches the goal.

The search is over *bindings* (which apple, which cabinet, which knife, which microwave...) and a few
orderings; for each it expands skill macros (fetch, put into, heat, cool, clean, slice, light) step by step
on a copy of the world, so every plan it returns has been executed symbolically and is known to succeed.
The shortest successful plan wins (ties: the first in a stable order). Plans start from the CURRENT state,
so the oracle can be asked again after any failure.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable
from typing import Any

from eb_alfred.catalog import KNIVES, TYPES, fits
from eb_alfred.goals import PROPERTY_OF_KIND, candidates, evaluate
from eb_alfred.world import World

__all__ = ["expert_plan"]


class _Fail(Exception):
    pass


class _Sim:
    """A world copy that records the actions it takes; any failed action aborts the candidate."""

    def __init__(self, world: World, limit: int) -> None:
        self.w = world.copy()
        self.plan: list[str] = []
        self.limit = limit

    def do(self, action: str) -> None:
        ok, _ = self.w.step(action)
        if not ok:
            raise _Fail(action)
        self.plan.append(action)
        if len(self.plan) > self.limit:
            raise _Fail("too long")

    def try_do(self, action: str) -> bool:
        probe = self.w.copy()
        ok, _ = probe.step(action)
        if ok:
            self.do(action)
        return ok

    # ---------------------------------------------------------------- macros
    def free_hand(self) -> None:
        if self.w.held is None:
            return
        if not self.try_do("put down the object in hand"):
            self.do("drop the object in hand")

    def reach(self, x: str) -> None:
        """Be at ``x``'s place with ``x`` visible."""
        if not self.w.near(x) or self.w.facing is None:
            self.do(f"find a {x}")
        while (c := self.w.closed_container(x)) is not None:
            self.do(f"open the {c}")

    def face(self, x: str) -> None:
        """Stand at ``x`` and face it (so ``put down`` targets it)."""
        if self.w.target_recep != x:
            self.do(f"find a {x}")
        while (c := self.w.closed_container(x)) is not None:
            self.do(f"open the {c}")

    def fetch(self, x: str) -> None:
        if self.w.held == x:
            return
        self.free_hand()
        self.reach(x)
        self.do(f"pick up the {x}")

    def put_into(self, r: str) -> None:
        self.face(r)
        if self.w.target_recep != r:
            raise _Fail(f"cannot face {r}")
        if TYPES[self.w.objects[r].type].openable and not self.w.objects[r].is_open:
            self.do(f"open the {r}")
        self.do("put down the object in hand")

    def slice(self, x: str, knife: str) -> None:
        if self.w.objects[x].is_sliced:
            return
        self.fetch(knife)
        self.reach(x)
        self.do(f"slice the {x}")

    def heat(self, x: str, mw: str) -> None:
        if self.w.objects[x].is_hot:
            return
        self.fetch(x)
        self.face(mw)
        if self.w.objects[mw].is_on:
            self.do(f"turn off the {mw}")
        self.put_into(mw)
        self.do(f"close the {mw}")
        self.do(f"turn on the {mw}")
        self.do(f"turn off the {mw}")
        self.do(f"open the {mw}")
        self.do(f"pick up the {x}")

    def cool(self, x: str, fridge: str) -> None:
        if self.w.objects[x].is_cold:
            return
        self.fetch(x)
        self.put_into(fridge)
        self.do(f"close the {fridge}")
        self.do(f"open the {fridge}")
        self.do(f"pick up the {x}")

    def clean(self, x: str, basin: str) -> None:
        if not self.w.objects[x].is_dirty:
            return
        self.fetch(x)
        self.put_into(basin)
        faucet = self.w.faucet_of(basin)
        if faucet is None:
            raise _Fail("no faucet")
        if self.w.objects[x].is_dirty:
            self.do(f"turn on the {faucet}")
            self.do(f"turn off the {faucet}")
        self.do(f"pick up the {x}")

    def place(self, x: str, r: str) -> None:
        if self.w.objects[x].parent == r and not self.w.is_held(x):
            return
        self.fetch(x)
        self.put_into(r)


def _goal_done(goal: dict[str, Any], w: World) -> bool:
    return evaluate(goal, w)[0]


def _run(world: World, goal: dict[str, Any], limit: int, body: Callable[[_Sim], None]) -> list[str] | None:
    sim = _Sim(world, limit)
    try:
        body(sim)
    except _Fail:
        return None
    return sim.plan if _goal_done(goal, sim.w) else None


def _fitting(world: World, obj: str, receps: Iterable[str]) -> list[str]:
    t = world.objects[obj].type
    return [r for r in receps if fits(t, world.objects[r].type) and r != obj]


def _candidate_bodies(world: World, goal: dict[str, Any]) -> Iterable[Callable[[_Sim], None]]:
    kind = goal["kind"]
    xs = candidates(world, goal["object"])
    knives = [k for t in KNIVES for k in world.of_type(t)] if goal.get("sliced") else [None]
    prop = PROPERTY_OF_KIND.get(kind)
    helpers = {
        "hot": world.of_type("Microwave"),
        "cold": world.of_type("Fridge"),
        "clean": [b for b in world.of_type("SinkBasin") if world.faucet_of(b) is not None],
        None: [None],
    }[prop]

    def prepare(sim: _Sim, x: str, knife: str | None) -> None:
        if knife is not None:
            sim.slice(x, knife)

    if kind == "examine_in_light":
        for x, lamp, knife in itertools.product(xs, candidates(world, goal["lamp"]), knives):
            def body(sim: _Sim, x=x, lamp=lamp, knife=knife) -> None:
                prepare(sim, x, knife)
                sim.fetch(x)
                if not sim.w.near(lamp):
                    sim.do(f"find a {lamp}")
                if not sim.w.objects[lamp].is_on:
                    sim.do(f"turn on the {lamp}")
            yield body
        return

    rs = candidates(world, goal["receptacle"])
    if kind == "stack_and_place":
        ms = candidates(world, goal["movable"])
        for x, m, knife in itertools.product(xs, ms, knives):
            if not fits(world.objects[x].type, world.objects[m].type):
                continue
            for r in _fitting(world, m, rs):
                def first_x(sim: _Sim, x=x, m=m, r=r, knife=knife) -> None:
                    prepare(sim, x, knife)
                    sim.place(x, m)
                    sim.place(m, r)

                def first_m(sim: _Sim, x=x, m=m, r=r, knife=knife) -> None:
                    prepare(sim, x, knife)
                    sim.place(m, r)
                    sim.place(x, m)
                yield first_x
                yield first_m
        return

    if kind == "pick_two_and_place":
        for (x1, x2), knife in itertools.product(itertools.combinations(xs, 2), knives):
            for r in rs:
                if not (fits(world.objects[x1].type, world.objects[r].type)
                        and fits(world.objects[x2].type, world.objects[r].type)):
                    continue

                def body(sim: _Sim, x1=x1, x2=x2, r=r, knife=knife) -> None:
                    for x in (x1, x2):
                        parent = sim.w.objects[x].parent
                        if parent is not None and parent in rs and not sim.w.is_held(x):
                            continue
                        prepare(sim, x, knife)
                        sim.place(x, r)
                yield body
        return

    for x, helper, knife in itertools.product(xs, helpers, knives):
        for r in _fitting(world, x, rs):
            def body(sim: _Sim, x=x, r=r, helper=helper, knife=knife) -> None:
                prepare(sim, x, knife)
                if prop == "hot":
                    sim.heat(x, helper)
                elif prop == "cold":
                    sim.cool(x, helper)
                elif prop == "clean":
                    sim.clean(x, helper)
                sim.place(x, r)
            yield body


def expert_plan(world: World, goal: dict[str, Any], limit: int = 40) -> list[str] | None:
    """The shortest plan (action names) found from the current state, [] if already solved, None if none."""
    if _goal_done(goal, world):
        return []
    best: list[str] | None = None
    for body in _candidate_bodies(world, goal):
        plan = _run(world, goal, limit if best is None else len(best) - 1, body)
        if plan is not None and (best is None or len(plan) < len(best)):
            best = plan
    return best
