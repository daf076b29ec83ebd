"""Blind baselines on the geometry alone: constant-action policies and feedback-only rule agents.

The task generator uses them to reject starts that an agent could solve without looking, and the world's audit
probes (:mod:`eb_navigation.audit`) measure them on a whole task file. Everything runs on the lattice of
:class:`~eb_navigation.geometry.FreeSpace` (no rendering), with the same collision checks as the env.

* **Blind policies** (the core's :class:`~eb_core.audit.contract.BlindPolicy` over action indices) ignore
  everything: a fixed prefix (none, one or two turns) followed by a fixed action cycle of length 1-4 repeated
  until the step budget runs out (always forward; turn left once then forward; forward, forward, left, ...).
  Tilting never moves the agent, so actions 6 and 7 are folded into one "wait" action.
  All policies are stepped together with numpy over a transition table of the room's ``(cell, heading)`` states.
* **Rule agents** see what a language-only model sees when it is told nothing about the scene: the instruction
  (useless without a view) and whether each action succeeded. They walk forward and react to bumps.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from functools import partial

import numpy as np

from eb_core.audit.contract import BlindPolicy
from eb_navigation.geometry import SUCCESS_DISTANCE, AgentState, FreeSpace, _move_delta

__all__ = ["BLIND_POLICIES", "CHECK_AGENTS", "HARD_RULE_AGENTS", "MAX_STEPS", "REACTIVE_ON_FAIL",
           "REACTIVE_RULE_AGENTS", "RULE_AGENTS", "SIDESTEP_RULE_AGENTS", "BlindPolicy", "blind_policy",
           "blind_successes", "plan_lengths", "policy_name", "rule_agent_successes"]

MAX_STEPS = 20
"""The env's step budget (``max_steps`` in ``conf/env/navigation.yaml``)."""

_WAIT = 6
"""Stand-in for the tilt actions (6, 7): neither moves nor turns the agent."""
_ACTIONS = (0, 1, 2, 3, 4, 5, _WAIT)
_PREFIXES: tuple[tuple[int, ...], ...] = ((), (4,), (5,), (4, 4))


_NAMES = {0: "fwd", 1: "back", 2: "right", 3: "left", 4: "turnR", 5: "turnL", _WAIT: "tilt"}


def policy_name(p: BlindPolicy) -> str:
    """``"turnL, then (fwd fwd left)*"``."""
    return p.name


def blind_policy(prefix: tuple[int, ...], cycle: tuple[int, ...]) -> BlindPolicy:
    """The core's :class:`~eb_core.audit.contract.BlindPolicy` over action indices (6 = a tilt, which neither
    moves nor turns), named like ``"turnL, then (fwd fwd left)*"``: ``prefix`` once, then ``cycle`` repeated."""
    cyc = "(" + " ".join(_NAMES[a] for a in cycle) + ")*"
    name = (" ".join(_NAMES[a] for a in prefix) + ", then " + cyc) if prefix else cyc
    return BlindPolicy(name, tuple(cycle), tuple(prefix))


def _canonical(cycle: tuple[int, ...]) -> bool:
    """Keep one of the cycles that repeat a shorter one ((0, 0) is (0,))."""
    n = len(cycle)
    return not any(n % k == 0 and cycle == cycle[:k] * (n // k) for k in range(1, n))


def _policies() -> tuple[BlindPolicy, ...]:
    cycles = [c for n in range(1, 5) for c in itertools.product(_ACTIONS, repeat=n) if _canonical(c)]
    return tuple(blind_policy(p, c) for p in _PREFIXES for c in cycles)


BLIND_POLICIES: tuple[BlindPolicy, ...] = _policies()
"""Every blind policy the generator and the tests try: 4 prefixes x 2,737 cycles of length <= 4 = 10,948."""



class _Lattice:
    """Transition table over the free ``(i, j, heading)`` states of one free space."""

    def __init__(self, free: FreeSpace) -> None:
        self.free = free
        cells = free.free_cells()
        self.cells = cells
        index = {c: k for k, c in enumerate(cells)}
        n = len(cells)
        self.next = np.zeros((len(_ACTIONS), 4 * n), dtype=np.int32)
        for k, (i, j) in enumerate(cells):
            for h in range(4):
                s = 4 * k + h
                for col, a in enumerate(_ACTIONS):
                    if a <= 3:
                        di, dj = _move_delta(h, a)
                        ok = free.can_move(i, j, di, dj) and (i + di, j + dj) in index
                        self.next[col, s] = 4 * index[(i + di, j + dj)] + h if ok else s
                    elif a == 4:
                        self.next[col, s] = 4 * k + (h - 1) % 4
                    elif a == 5:
                        self.next[col, s] = 4 * k + (h + 1) % 4
                    else:
                        self.next[col, s] = s
        self.index = index

    def goal(self, target_xy: tuple[float, float]) -> np.ndarray:
        g = self.free.goal_cells(target_xy, SUCCESS_DISTANCE)
        cell_goal = np.array([bool(g[i - self.free.i0, j - self.free.j0]) for i, j in self.cells])
        return np.repeat(cell_goal, 4)


    def plan_lengths(self, target_xy: tuple[float, float]) -> np.ndarray:
        """Oracle plan length from every state (-1: unreachable), by value iteration over the transition table:
        the same lengths as :meth:`FreeSpace.shortest_plan`, for all starts at once."""
        goal = self.goal(target_xy)
        big = np.iinfo(np.int32).max // 2
        # a plan ends with a move into the goal: dist 0 at goal states only counts as arrival
        dist = np.full(goal.shape, big, dtype=np.int64)
        moves = self.next[:4]
        turns = self.next[4:6]
        arrive = np.where(goal, 0, big)
        for _ in range(4 * len(goal)):
            via_move = (np.minimum(arrive[moves], dist[moves]) + 1)
            via_move = np.where(moves == np.arange(goal.size), big, via_move).min(axis=0)
            via_turn = (dist[turns] + 1).min(axis=0)
            new = np.minimum(via_move, via_turn)
            if np.array_equal(new, dist):
                break
            dist = new
        dist = np.where(goal, 0, dist)  # already there: the empty plan
        return np.where(dist >= big, -1, dist)


_COL = {a: k for k, a in enumerate(_ACTIONS)}
_LATTICES: dict[int, _Lattice] = {}


def _lattice(free: FreeSpace) -> _Lattice:
    lat = _LATTICES.get(id(free))
    if lat is None or lat.free is not free:
        if len(_LATTICES) > 16:
            _LATTICES.clear()
        lat = _LATTICES[id(free)] = _Lattice(free)
    return lat


def plan_lengths(free: FreeSpace, target_xy: tuple[float, float]) -> dict[tuple[int, int, int], int]:
    """Oracle plan length from every free ``(i, j, heading)`` (unreachable states left out)."""
    lat = _lattice(free)
    d = lat.plan_lengths(target_xy)
    return {(i, j, h): int(d[4 * k + h]) for k, (i, j) in enumerate(lat.cells) for h in range(4) if d[4 * k + h] >= 0}


def _policy_table(policies: Sequence[BlindPolicy], n: int) -> np.ndarray:
    return np.array([[_COL[a] for a in p.actions(n)] for p in policies], dtype=np.int32)


_TABLE_CACHE: dict[tuple[int, int], np.ndarray] = {}


def blind_successes(free: FreeSpace, start: AgentState, target_xy: tuple[float, float],
                    policies: Sequence[BlindPolicy] = BLIND_POLICIES, max_steps: int = MAX_STEPS) -> np.ndarray:
    """Boolean array over ``policies``: which ones come within the success distance within ``max_steps``."""
    lat = _lattice(free)
    key = (id(policies), max_steps)
    table = _TABLE_CACHE.get(key) if policies is BLIND_POLICIES else None
    if table is None:
        table = _policy_table(policies, max_steps)
        if policies is BLIND_POLICIES:
            _TABLE_CACHE[key] = table
    goal = lat.goal(target_xy)
    k = lat.index.get((start.i, start.j))
    if k is None:
        raise ValueError(f"start ({start.x}, {start.y}) is not a free lattice point")
    state = np.full(len(policies), 4 * k + start.heading % 4, dtype=np.int32)
    solved = np.zeros(len(policies), dtype=bool)
    for t in range(max_steps):
        state = lat.next[table[:, t], state]
        solved |= goal[state]
    return solved


# -- rule agents (instruction + feedback only) -----------------------------------------------------------------

#: A rule agent: given whether the last action worked (None before the first) and its own memory, the next action.
RuleAgent = Callable[[bool | None, dict], int]


def _forward_turn(side: int) -> RuleAgent:
    def act(ok: bool | None, mem: dict) -> int:
        if ok is False and mem.get("last") in (0,):
            return side
        return 0
    return act


def _forward_sidestep(side: int) -> RuleAgent:
    def act(ok: bool | None, mem: dict) -> int:
        if ok is False and mem.get("last") == 0:
            return side
        if mem.get("last") == side and ok:
            return 0
        if ok is False and mem.get("last") == side:
            return 4 if side == 2 else 5
        return 0
    return act


def _spiral(ok: bool | None, mem: dict) -> int:
    """Walk forward in growing legs, turning left after each leg or bump (a blind search pattern)."""
    leg = mem.setdefault("leg", 2)
    done = mem.setdefault("done", 0)
    if ok is False or done >= leg:
        mem["done"] = 0
        mem["leg"] = leg + 1
        return 5
    mem["done"] = done + 1
    return 0


RULE_AGENTS: dict[str, Callable[[], RuleAgent]] = {
    "forward, turn right on a bump": lambda: _forward_turn(4),
    "forward, turn left on a bump": lambda: _forward_turn(5),
    "forward, step right on a bump": lambda: _forward_sidestep(2),
    "forward, step left on a bump": lambda: _forward_sidestep(3),
    "spiral: forward legs of growing length, turn left": lambda: _spiral,
}
"""Feedback-only agents: what a model told only the instruction and the success of each action could do."""


def _turn_first(turns: tuple[int, ...], then: Callable[[], RuleAgent]) -> Callable[[], RuleAgent]:
    """Turn ``turns`` first (blind), then behave like ``then``."""
    def make() -> RuleAgent:
        inner = then()

        def act(ok: bool | None, mem: dict) -> int:
            k = mem.setdefault("k", 0)
            mem["k"] = k + 1
            if k < len(turns):
                return turns[k]
            if k == len(turns):
                mem["last"] = None
                return inner(None, mem)
            return inner(ok, mem)
        return act
    return make


def _forward_turn_around() -> RuleAgent:
    def act(ok: bool | None, mem: dict) -> int:
        pending = mem.setdefault("pending", [])
        if pending:
            return pending.pop()
        if ok is False and mem.get("last") == 0:
            pending.append(4)
            return 4
        return 0
    return act


def _forward_dodge(first: int = 2) -> Callable[[], RuleAgent]:
    """Forward; on a bump step to one side, and when that fails too, to the other side, then turn."""
    second = 3 if first == 2 else 2

    def make() -> RuleAgent:
        def act(ok: bool | None, mem: dict) -> int:
            last = mem.get("last")
            if ok is False and last == 0:
                return first
            if ok is False and last == first:
                return second
            if ok is False and last == second:
                return 4 if first == 2 else 5
            return 0
        return act
    return make


HARD_RULE_AGENTS: dict[str, Callable[[], RuleAgent]] = {
    **RULE_AGENTS,
    "forward, turn around on a bump": _forward_turn_around,
    "forward, on a bump step right, then left, then turn": _forward_dodge(2),
    "forward, on a bump step left, then right, then turn": _forward_dodge(3),
    "step right once, then forward, step right on a bump": _turn_first((2,), lambda: _forward_sidestep(2)),
    "step left once, then forward, step left on a bump": _turn_first((3,), lambda: _forward_sidestep(3)),
    "step right twice, then forward, step right on a bump": _turn_first((2, 2), lambda: _forward_sidestep(2)),
    "step left twice, then forward, step left on a bump": _turn_first((3, 3), lambda: _forward_sidestep(3)),
    "turn right once, then forward, step right on a bump": _turn_first((4,), lambda: _forward_sidestep(2)),
    "turn left once, then forward, step left on a bump": _turn_first((5,), lambda: _forward_sidestep(3)),
    "turn around, then forward, turn left on a bump": _turn_first((4, 4), lambda: _forward_turn(5)),
}
"""The rule agents the harder levels are checked against: the classic five plus agents that turn first (the
target's direction is unknown) and that react to a bump by turning round or dodging to both sides."""


def _reactive(on_fail: tuple[int, ...]) -> Callable[[], RuleAgent]:
    """Forward; after ``k`` failures in a row play ``on_fail[k - 1]`` (the last repeats): the core audit's
    feedback policies (:class:`eb_core.audit.blind.ReactivePolicy`)."""
    def make() -> RuleAgent:
        def act(ok: bool | None, mem: dict) -> int:
            mem["fails"] = mem.get("fails", 0) + 1 if ok is False else 0
            return on_fail[min(mem["fails"], len(on_fail)) - 1] if mem["fails"] else 0
        return act
    return make


_WORD = {2: "step right", 3: "step left", 4: "turn right", 5: "turn left"}
REACTIVE_ON_FAIL: dict[str, tuple[int, ...]] = {
    **{f"forward; after a failure {_WORD[r]}": (r,) for r in (4, 5, 2, 3)},
    **{f"forward; after a failure {_WORD[s]}, after two {_WORD[t]}": (s, t) for s in (2, 3) for t in (4, 5)},
}
"""The core audit's ``feedback_policies`` for navigation by name: the actions played after 1, 2, ... failures in a
row (:class:`eb_core.audit.blind.ReactivePolicy`'s ``on_fail``); the cycle is always forward."""
REACTIVE_RULE_AGENTS: dict[str, Callable[[], RuleAgent]] = {
    name: _reactive(on_fail) for name, on_fail in REACTIVE_ON_FAIL.items()}
"""The core audit's ``feedback_policies`` for navigation, on the geometry."""


SIDESTEP_RULE_AGENTS: dict[str, Callable[[], RuleAgent]] = {
    **{f"step {name} {k} times, then forward, step {name} on a bump":
       _turn_first((side,) * k, partial(_forward_sidestep, side))
       for k in (3, 4, 5, 6) for side, name in ((2, "right"), (3, "left"))},
    **{f"step {name} {k} times, then forward, turn {name} on a bump":
       _turn_first((side,) * k, partial(_forward_turn, turn))
       for k in (1, 2, 3, 4) for side, name, turn in ((2, "right", 4), (3, "left", 5))},
}
"""Side-step-first agents: a blind guess that the target is ahead and a little to one side. The hard generator
never takes a start that would lift one of them above its cap (:mod:`eb_navigation.hard_set`)."""


CHECK_AGENTS: dict[str, Callable[[], RuleAgent]] = {**HARD_RULE_AGENTS, **SIDESTEP_RULE_AGENTS, **REACTIVE_RULE_AGENTS}
"""Every feedback-only agent a hard set is held to: the hard generator (:mod:`eb_navigation.hard_set`) checks each
candidate start against all of them (generated splits use the cheaper :data:`HARD_RULE_AGENTS`)."""


def rule_agent_successes(free: FreeSpace, start: AgentState, target_xy: tuple[float, float],
                         max_steps: int = MAX_STEPS, agents: dict[str, Callable[[], RuleAgent]] | None = None
                         ) -> dict[str, bool]:
    """Whether each rule agent (default :data:`RULE_AGENTS`) reaches the target within ``max_steps``."""
    goal = free.goal_cells(target_xy, SUCCESS_DISTANCE)
    out = {}
    for name, make in (RULE_AGENTS if agents is None else agents).items():
        agent = make()
        mem: dict = {}
        s, ok, solved = start, None, False
        for _ in range(max_steps):
            a = agent(ok, mem)
            mem["last"] = a
            s, ok, _ = free.apply(s, a)
            if goal[s.i - free.i0, s.j - free.j0]:
                solved = True
                break
        out[name] = solved
    return out


def blind_table(task_file: str | None = None) -> str:
    """A Markdown table per subset: always forward, turn once then forward, the best of all blind policies, the
    best rule agent and a seeded random agent, measured on the geometry of ``task_file`` (None: the shipped)."""
    from collections import defaultdict

    from eb_navigation.geometry import distance_to
    from eb_navigation.room import NavRoom
    from eb_navigation.tasks import SUBSETS, load_task_file

    def build_room(t):  # the task's room (no import of the env: baselines stays below it)
        return NavRoom(t.scene.kind, t.scene.seed, [e.spec() for e in t.extra_objects], t.scene.clutter)

    tf = load_task_file(task_file)
    rooms: dict[tuple, NavRoom] = {}
    blind: dict[str, list[np.ndarray]] = defaultdict(list)
    rules: dict[str, list[np.ndarray]] = defaultdict(list)
    for t in tf.tasks:
        key = (t.scene.kind, t.scene.seed, t.scene.clutter, t.extra_objects)
        room = rooms.get(key) or rooms.setdefault(key, build_room(t))
        free = room.free_space(room.extra_ids)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
        blind[t.subset].append(blind_successes(free, s, t.target.position[:2]))
        rules[t.subset].append(np.array(list(rule_agent_successes(free, s, t.target.position[:2]).values())))
    rng = np.random.default_rng(0)
    random_wins: dict[str, int] = defaultdict(int)
    for t in tf.tasks:  # a seeded random agent, stepped on the same free space the env uses
        room = rooms[(t.scene.kind, t.scene.seed, t.scene.clutter, t.extra_objects)]
        free = room.free_space(room.extra_ids)
        s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw, t.start.tilt)
        for _ in range(MAX_STEPS):
            s, _, _ = free.apply(s, int(rng.integers(8)))
            if distance_to(s, t.target.position[:2]) <= SUCCESS_DISTANCE + 1e-9:
                random_wins[t.subset] += 1
                break
    fwd = BLIND_POLICIES.index(blind_policy((), (0,)))
    turn_fwd = [BLIND_POLICIES.index(blind_policy((t,), (0,))) for t in (4, 5)]
    rule_names = list(RULE_AGENTS)
    lines = ["| subset | always forward | turn once, then forward | best of 10,948 blind policies | "
             "best rule agent | random (seed 0) |", "|---|---|---|---|---|---|"]
    for subset in SUBSETS:
        b = np.mean(blind[subset], axis=0)
        r = np.mean(rules[subset], axis=0)
        best, rbest = int(np.argmax(b)), int(np.argmax(r))
        n = len(blind[subset])
        lines.append(f"| {subset} | {100 * b[fwd]:.1f} % | {100 * max(b[k] for k in turn_fwd):.1f} % | "
                     f"{100 * b[best]:.1f} % (`{policy_name(BLIND_POLICIES[best])}`) | {100 * r[rbest]:.1f} % "
                     f"({rule_names[rbest]}) | {100 * random_wins[subset] / n:.1f} % |")
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    import sys

    print(blind_table(sys.argv[1] if len(sys.argv) > 1 else None))
