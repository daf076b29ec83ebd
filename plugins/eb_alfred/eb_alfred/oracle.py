"""The expert: a shortest-plan search from the CURRENT symbolic state, whatever actions led there.

The plan is a function of the state only (what is held, where everything is, open/closed, on/off, sliced,
clean/hot/cold, where the agent stands and what it faces), never of the task template. The search tries every
*binding* (which apple, which cabinet, knife, microwave, fridge, sink basin, lamp, movable receptacle) and a few
orderings of the sub-goals; each candidate is expanded by state-driven skill macros on a copy of the world:

* ``pick(x)``: nothing if ``x`` is in hand; else free the hand, walk to ``x`` unless it is already the nearest
  one of its kind, open what hides it (switching a running microwave off first) and pick it up.
* ``put_into(r)``: face ``r`` (unless ``put down`` already targets it), uncover and open it, put down.
* ``heat / cool / clean``: nothing if ``x`` already has the property; if ``x`` already sits in the appliance,
  only the missing switch steps (close, turn on / close / turn on the faucet); else bring it there first.
* ``slice(x)``: nothing if sliced; else a knife in hand (the held one if any), walk to ``x``, slice.

Every action a macro takes is executed by the world's own rules, so a returned plan is known to succeed; the
shortest over all candidates wins (branch and bound: a candidate is cut once it is as long as the best so far).
Because the macros skip whatever the state already satisfies, the tail of an expert plan is again an expert
plan: following its first action and asking again (closed loop) reaches the goal. :func:`why_unreachable` says
why no plan exists (e.g. the only apple was sliced and the task needs it whole).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, cast

from eb_alfred.catalog import KNIVES, TYPES, fits
from eb_alfred.goals import PROPERTY_OF_KIND, candidates, evaluate, look_alikes, properties, usable
from eb_alfred.world import VERBS, World

__all__ = ["expert_plan", "why_unreachable", "DEFAULT_LIMIT"]

DEFAULT_LIMIT = 40
"""The longest plan the expert looks for (the episode budget is 30 steps)."""

_PUT = VERBS["put"]
_DROP = VERBS["drop"]


class _Fail(Exception):
    pass


class _Sim:
    """A world copy that records the actions it takes; a failed action or the length limit aborts it."""

    def __init__(self, world: World, limit: int) -> None:
        self.w = world.copy()
        self.w.history = []
        self.plan: list[str] = []
        self.limit = limit

    def fork(self) -> _Sim:
        twin = _Sim.__new__(_Sim)
        twin.w = self.w.copy()
        twin.plan = list(self.plan)
        twin.limit = self.limit
        return twin

    def _room(self) -> None:
        if len(self.plan) >= self.limit:
            raise _Fail("too long")

    def do(self, action: str) -> None:
        self._room()
        ok, _ = self.w.step(action)
        if not ok:
            raise _Fail(action)
        self.plan.append(action)

    def try_do(self, action: str) -> bool:
        self._room()
        ok, _ = self.w.step(action)  # a failed action changes nothing
        if ok:
            self.plan.append(action)
        return ok

    def act(self, verb: str, x: str) -> None:
        """Apply ``verb`` to instance ``x`` through the action names that exist (type names act on the nearest)."""
        w = self.w
        name = x if verb in ("open", "close") else w.objects[x].type
        if w.resolve(verb, name) != x:
            self.do(VERBS["find"].format(x))
            if w.resolve(verb, name) != x:
                raise _Fail(f"cannot single out {x}")
        self.do(VERBS[verb].format(name))

    # ---------------------------------------------------------------- macros
    def free_hand(self) -> None:
        if self.w.held is None:
            return
        if self.w.target_recep is None or not self.try_do(_PUT):
            self.do(_DROP)

    def uncover(self, x: str) -> None:
        """Open every closed receptacle around ``x`` (the agent stands at ``x``'s place)."""
        while (c := self.w.closed_container(x)) is not None:
            self.open(c)

    def open(self, c: str) -> None:
        if self.w.objects[c].is_on:
            self.act("toggle_off", c)
        self.act("open", c)

    def pick(self, x: str) -> None:
        w = self.w
        if w.held == x:
            return
        self.free_hand()
        if not w.near(x):
            self.do(VERBS["find"].format(x))
        self.uncover(x)
        self.act("pickup", x)  # finds x first if another one of its kind is nearer
        if w.held != x:
            raise _Fail(f"picked the wrong {w.objects[x].type}")

    def pick_knife(self, knife: str) -> None:
        """Take ``knife`` or any knife of its kind within reach (all of them slice)."""
        w = self.w
        self.free_hand()
        if not w.near(knife):
            self.do(VERBS["find"].format(knife))
        self.uncover(knife)
        kind = w.objects[knife].type
        got = w.resolve("pickup", kind)
        if w.objects[got].type != kind or w.closed_container(got) is not None or w.is_held(got):
            self.do(VERBS["find"].format(knife))
        self.do(VERBS["pickup"].format(kind))

    def put_into(self, r: str) -> None:
        w = self.w
        held = w.held
        if held is None:
            raise _Fail("nothing to put")
        if w.target_recep != r or not w.near(r):
            self.do(VERBS["find"].format(r))
            if w.target_recep != r:
                raise _Fail(f"put down would not target {r}")
        self.uncover(r)
        o = w.objects[r]
        if TYPES[o.type].openable and not o.is_open:
            self.open(r)
        self.do(_PUT)
        if w.objects[held].parent != r:
            raise _Fail("put elsewhere")

    def place(self, x: str, r: str) -> None:
        if self.w.objects[x].parent == r and not self.w.is_held(x):
            return
        self.pick(x)
        self.put_into(r)

    def _in_settled(self, x: str, container: str) -> bool:
        return container in self.w.ancestors(x) and not self.w.is_held(x)

    def heat(self, x: str, mw: str) -> None:
        w = self.w
        if w.objects[x].is_hot:
            return
        if self._in_settled(x, mw):
            if not w.near(mw):
                self.do(VERBS["find"].format(mw))
            if w.objects[mw].is_on:
                self.act("toggle_off", mw)
            if w.objects[mw].is_open:
                self.act("close", mw)
        else:
            self.pick(x)
            self.put_into(mw)
            self.act("close", mw)
        self.act("toggle_on", mw)
        if not w.objects[x].is_hot:
            raise _Fail("not heated")

    def cool(self, x: str, fridge: str) -> None:
        w = self.w
        if w.objects[x].is_cold:
            return
        if self._in_settled(x, fridge):
            if not w.near(fridge):
                self.do(VERBS["find"].format(fridge))
            if not w.objects[fridge].is_open:
                self.act("open", fridge)
        else:
            self.pick(x)
            self.put_into(fridge)
        self.act("close", fridge)
        if not w.objects[x].is_cold:
            raise _Fail("not cooled")

    def clean(self, x: str, basin: str) -> None:
        w = self.w
        if not w.objects[x].is_dirty:
            return
        faucet = w.faucet_of(basin)
        if faucet is None:
            raise _Fail("no faucet")
        if self._in_settled(x, basin):
            if not w.near(basin):
                self.do(VERBS["find"].format(basin))
        else:
            self.pick(x)
            self.put_into(basin)
        if w.objects[x].is_dirty:
            if w.objects[faucet].is_on:
                self.act("toggle_off", faucet)
            self.act("toggle_on", faucet)
        if w.objects[x].is_dirty:
            raise _Fail("not washed")

    def slice(self, x: str, knife: str | None) -> None:
        w = self.w
        if w.objects[x].is_sliced:
            return
        if w.held is None or w.objects[w.held].type not in KNIVES:
            if knife is None:
                raise _Fail("no knife")
            if w.place_of(knife) == w.place_of(x) and not w.near(x) and not w.is_held(x):
                self.do(VERBS["find"].format(x))  # knife and food at one place: face the food, take the knife
            self.pick_knife(knife)
        if not w.near(x):
            self.do(VERBS["find"].format(x))
        self.uncover(x)
        self.act("slice", x)

    def light(self, x: str, lamp: str) -> None:
        w = self.w
        self.pick(x)
        if not w.near(lamp):
            self.do(VERBS["find"].format(lamp))
        if not w.objects[lamp].is_on:
            self.act("toggle_on", lamp)


def _fitting(world: World, obj: str, receps: Iterable[str]) -> list[str]:
    t = world.objects[obj].type
    return [r for r in receps if r != obj and fits(t, world.objects[r].type)]


def _situation(world: World, name: str, anchors: set[str] | None, watch: AbstractSet[str]) -> tuple[Any, ...]:
    """What makes two instances interchangeable for planning: their states, what hides them, which watched
    objects (goal objects) they hold, and their place -- but only when that place matters (``anchors``: where
    the agent or another bound object is); any other place costs the same one ``find``."""
    o = world.objects[name]
    place = world.place_of(name)
    if anchors is not None and place not in anchors:
        place = None
    t = TYPES[o.type]
    kind = "knife" if o.type in KNIVES else o.type
    return (kind, place, world.closed_container(name), world.is_held(name), t.openable and o.is_open, o.is_on,
            o.is_sliced, o.is_dirty, o.is_hot, o.is_cold, name == world.facing,
            tuple(c for c in world.children(name) if c in watch))


def _distinct(world: World, names: Iterable[str], anchors: set[str] | None = None,
              watch: AbstractSet[str] = frozenset()) -> list[str]:
    """One instance per situation (the first): the others would give plans of the same length."""
    seen: set[tuple[Any, ...]] = set()
    out = []
    for n in names:
        key = _situation(world, n, anchors, watch)
        if key not in seen:
            seen.add(key)
            out.append(n)
    return out


def _knives(world: World, anchors: set[str] | None = None) -> list[str]:
    """The held knife if there is one (slicing uses it whatever the binding), else one knife per situation."""
    ks = [k for t in sorted(KNIVES) for k in world.of_type(t)]
    held = [k for k in ks if world.held == k]
    return held or _distinct(world, ks, anchors)


def _helpers(world: World, prop: str | None, watch: set[str]) -> list[str | None]:
    if prop == "hot":
        return list(_distinct(world, world.of_type("Microwave"), watch=watch))
    if prop == "cold":
        return list(_distinct(world, world.of_type("Fridge"), watch=watch))
    if prop == "clean":
        basins = [b for b in world.of_type("SinkBasin") if world.faucet_of(b) is not None]
        return list(_distinct(world, basins, watch=watch))
    return [None]


def _objects(world: World, goal: dict[str, Any]) -> list[str]:
    """Instances that are, or can still become, the goal's object (whole ones for a sliced goal get sliced)."""
    if goal.get("sliced"):
        return [x for x in candidates(world, goal["object"]) if TYPES[world.objects[x].type].sliceable
                or world.objects[x].is_sliced]
    return usable(world, goal)


Step = tuple[str | None, ...]
"""One macro call, e.g. ``("place", "Apple_2", "Fridge")``: a :class:`_Sim` method's name, then its arguments (a
helper may be None); a candidate plan is a sequence of them."""


@dataclass
class _Bindings:
    """What a goal's candidates are built from: the instances each role can be bound to."""

    world: World
    sliced: bool
    props: list[str]
    """The object's preparations: the type's own property first, then the goal's extra ones."""
    xs: list[str]
    helper_sets: list[tuple[str | None, ...]]
    """Every way to bind a helper to each property (one microwave / fridge / basin each)."""
    lamps: list[str]
    ms: list[str]
    knives: list[str | None]
    rs: list[str]

    def cut(self, x: str, knife: str | None) -> tuple[Step, ...]:
        return (("slice", x, knife),) if self.sliced and knife is not None else ()

    def fixes(self, x: str, hs: tuple[str | None, ...]) -> list[tuple[Step, ...]]:
        """The preparation macros of ``x`` in every order (chilling after heating would undo it, and the
        world's rules reject such a candidate at the end)."""
        steps = [(_TREAT[p], x, h) for p, h in zip(self.props, hs)]
        return [tuple(order) for order in itertools.permutations(steps)] if steps else [()]


_TREAT = {"hot": "heat", "cold": "cool", "clean": "clean"}


def _bindings(world: World, goal: dict[str, Any]) -> _Bindings | None:
    """The instances each role of ``goal`` can be bound to, one per situation (None: no knife to slice with)."""
    kind = goal["kind"]
    sliced = bool(goal.get("sliced"))
    props = properties(goal)
    xs = _objects(world, goal)
    watch = set(xs)
    anchors = {world.place} | {world.place_of(x) for x in xs}
    if kind != "pick_two_and_place":  # pick two needs two of them, interchangeable or not
        xs = _distinct(world, xs)
    helper_sets = list(itertools.product(*(_helpers(world, p, watch) for p in props)))
    helpers = [h for hs in helper_sets for h in hs]
    lamps = _distinct(world, candidates(world, goal["lamp"])) if "lamp" in goal else []
    ms = _distinct(world, candidates(world, goal["movable"]), watch=watch) if "movable" in goal else []
    anchors |= {world.place_of(y) for y in [*helpers, *lamps, *ms] if y is not None}
    knives: list[str | None] = list(_knives(world, anchors)) if sliced else [None]
    if sliced and not knives:
        return None
    anchors |= {world.place_of(k) for k in knives if k is not None}
    rs = _distinct(world, candidates(world, goal["receptacle"]), anchors, watch) if "receptacle" in goal else []
    return _Bindings(world, sliced, props, xs, helper_sets, lamps, ms, knives, rs)


def _sequences(world: World, goal: dict[str, Any]) -> Iterable[tuple[Step, ...]]:
    """Every candidate (bindings x sub-goal orderings) as a sequence of macro calls."""
    b = _bindings(world, goal)
    if b is None:
        return
    kind = goal["kind"]
    if kind == "examine_in_light":
        yield from _examine_sequences(b)
    elif kind == "stack_and_place":
        yield from _stack_sequences(b)
    elif kind == "pick_two_and_place":
        yield from _pick_two_sequences(b)
    else:
        yield from _place_sequences(b)


def _examine_sequences(b: _Bindings) -> Iterable[tuple[Step, ...]]:
    for x, lamp, knife, hs in itertools.product(b.xs, b.lamps, b.knives, b.helper_sets):
        for fix in b.fixes(x, hs):
            yield (*b.cut(x, knife), *fix, ("light", x, lamp))
            if b.sliced and fix:
                yield (*fix, *b.cut(x, knife), ("light", x, lamp))


def _stack_sequences(b: _Bindings) -> Iterable[tuple[Step, ...]]:
    world = b.world
    for x, m, knife, hs in itertools.product(b.xs, b.ms, b.knives, b.helper_sets):
        if not fits(world.objects[x].type, world.objects[m].type):
            continue
        for r in _fitting(world, m, b.rs):
            for fix in b.fixes(x, hs):
                yield (*b.cut(x, knife), *fix, ("place", x, m), ("place", m, r))
                yield (*b.cut(x, knife), *fix, ("place", m, r), ("place", x, m))
                if b.sliced and fix:
                    yield (*fix, *b.cut(x, knife), ("place", x, m), ("place", m, r))


def _pick_two_sequences(b: _Bindings) -> Iterable[tuple[Step, ...]]:
    world, cut = b.world, b.cut
    for r in b.rs:
        fit = [x for x in b.xs if fits(world.objects[x].type, world.objects[r].type)]
        for (x1, x2), knife, hs in itertools.product(itertools.permutations(fit, 2), b.knives, b.helper_sets):
            for f1, f2 in zip(b.fixes(x1, hs), b.fixes(x2, hs)):
                yield (*cut(x1, knife), *f1, ("place", x1, r), *cut(x2, knife), *f2, ("place", x2, r))
                if f1:  # prepare both, then place both
                    yield (*cut(x1, knife), *f1, *cut(x2, knife), *f2, ("place", x1, r), ("place", x2, r))
                    yield (*cut(x1, knife), *cut(x2, knife), *f1, *f2, ("place", x1, r), ("place", x2, r))
                if b.sliced and not f1:  # cut both, then place both (either order: the last one cut is at hand)
                    yield (*cut(x1, knife), *cut(x2, knife), ("place", x1, r), ("place", x2, r))
                    yield (*cut(x1, knife), *cut(x2, knife), ("place", x2, r), ("place", x1, r))
                    yield (("place", x1, r), ("place", x2, r), *cut(x1, knife), *cut(x2, knife))


def _place_sequences(b: _Bindings) -> Iterable[tuple[Step, ...]]:
    for x, hs, knife in itertools.product(b.xs, b.helper_sets, b.knives):
        for r in _fitting(b.world, x, b.rs):
            for fix in b.fixes(x, hs):
                yield (*b.cut(x, knife), *fix, ("place", x, r))
                if b.sliced and fix:
                    yield (*fix, *b.cut(x, knife), ("place", x, r))
                if b.sliced:
                    yield (*fix, ("place", x, r), *b.cut(x, knife))


def _done(goal: dict[str, Any], world: World) -> bool:
    return evaluate(goal, world)[0]


_END = ("end",)


def expert_plan(world: World, goal: dict[str, Any], limit: int = DEFAULT_LIMIT) -> list[str] | None:
    """The shortest plan (action names) found from the current state; [] if solved, None if none is found.

    Candidates share their first macro calls, so they are walked as a tree: each macro runs once per distinct
    prefix, and a branch is cut as soon as it is as long as the best complete plan.
    """
    if _done(goal, world):
        return []
    if goal.get("untouched") and world.touched & set(look_alikes(world, goal)):
        return None  # a look-alike the goal protects has been handled: no plan can undo that
    tree: dict[Step, Any] = {}
    for seq in _sequences(world, goal):
        node = tree
        for step in seq:
            node = node.setdefault(step, {})
        node[_END] = {}
    best: list[str] | None = None

    def walk(sim: _Sim, node: dict[Step, Any]) -> None:
        nonlocal best
        items = list(node.items())
        for i, (step, child) in enumerate(items):
            if step == _END:
                if _done(goal, sim.w) and (best is None or len(sim.plan) < len(best)):
                    best = list(sim.plan)
                continue
            branch = sim if i == len(items) - 1 else sim.fork()
            branch.limit = limit if best is None else len(best) - 1
            try:
                getattr(branch, cast(str, step[0]))(*step[1:])  # a step is (a _Sim method's name, its arguments)
            except _Fail:
                continue
            walk(branch, child)

    walk(_Sim(world, limit), tree)
    return best


def why_unreachable(world: World, goal: dict[str, Any], limit: int = DEFAULT_LIMIT) -> str:
    """A one-line reason why :func:`expert_plan` found nothing from this state."""
    ref = goal["object"]
    name = ref.get("instance") or ref["type"]
    all_x = candidates(world, ref)
    xs = _objects(world, goal)
    need = 2 if goal["kind"] == "pick_two_and_place" else 1
    if not all_x:
        return f"there is no {name} in this room"
    spoiled = sorted(world.touched & set(look_alikes(world, goal)))
    if spoiled:
        return f"the task says to leave the look-alikes alone, and {', '.join(spoiled)} has been handled"
    if len(xs) < need:
        if not goal.get("sliced") and any(world.objects[x].is_sliced for x in all_x):
            left = len(xs)
            return (f"the task needs {'two whole ' if need == 2 else 'a whole '}{name}, but "
                    + (f"only {left} is left unsliced" if left else f"every {name} here has been sliced"))
        return f"the task needs {need} {name} and only {len(xs)} is here"
    for key in ("receptacle", "movable", "lamp"):
        if key in goal and not candidates(world, goal[key]):
            other = goal[key].get("instance") or goal[key]["type"]
            return f"there is no {other} in this room"
    for prop in properties(goal):
        if not _helpers(world, prop, set()):
            return f"nothing in this room can make the {name} {prop}"
    if goal.get("sliced") and not _knives(world):
        return "the task needs a slice, and there is no knife in this room"
    return f"no plan of at most {limit} actions reaches the goal from this state"
