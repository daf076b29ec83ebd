"""The harder task levels of EB-Navigation: ``eb tasks generate env=navigation difficulty=hard seed=N``.

Same protocol as the classic set (8 actions, 20 steps, success within 1 m of the target's centre); other scenes
and instructions. Per scene slot one room (seeds from :data:`SEED_BASE`, apart from every other task source) with:

* more small things on the furniture (the kit's ``clutter``) and a few extra things standing on the floor (the
  low ones along the walls);
* a small target standing on the floor (a vase, a watering can, a teddy bear, a bin, a potted plant, a footstool,
  a laundry hamper) and look-alikes of the same type in clearly different colours at least
  :data:`MIN_LOOKALIKE_GAP` metres away: walking up to a look-alike never succeeds, and only the colour named in
  the instruction tells the target apart (the names in the feedback never do: navigation's feedback names nothing);
* base / common_sense / complex_instruction: one start with the target AND a look-alike in view, the target at
  least ``min_target_pixels`` of a 128 x 128 segmentation (it may be partly hidden behind furniture);
* visual_appearance: its own start, the same rule, the target named by colour and shape only;
* long_horizon: a start with the target out of view in a random direction (to the left, to the right or behind,
  in turn over the slots), so the direction must be found by looking, not assumed.

No start sits in a pocket: from every start at least 1 m (4 moves) is clear straight ahead or to one side. No
start has a floor object lower than :data:`LOW_TOP` on its straight way to the target (:func:`clear_corridor`):
such a thing leaves the untilted view as the agent comes near, and an agent that keeps no memory of earlier images
walks into it; the low extra floor things stand along the walls (:data:`WALL_BAND`) so that enough starts keep a
clear way. At an in-view start every floor object on the way ahead shows in the first image (:func:`way_seen`).
With a level's ``open_way`` knob on (on for the shipped hard set: :data:`eb_navigation.hard_set.OPEN_WAY_SETS`), a
start also needs an open way for its first moves: nothing lower than :data:`WAY_TOP` within reach of any
forward-and-sideways route near the start (:func:`open_way`), everything within reach of the routes in view
(:func:`blockers_seen`), room for a wider body (:func:`wide_enough`), a long_horizon target that shows once the
player turns toward it (:func:`found_by_turning`); and, since such open starts are what the bump
agents solve, the target stands in the open (:data:`TARGET_WALL_GAP` from the walls), the extra floor things lower than
:data:`WAY_TOP` stand along the walls with more tall seats among them (:data:`OPEN_FLOOR_CLUTTER`), and no start that
more than :data:`OPEN_MAX_SOLVERS` feedback-only agents solve is taken (:data:`OPEN_SOLVER_COST` ranks the rest).
Every candidate start is checked on the geometry (:mod:`eb_navigation.baselines`) against all 10,948 blind
constant-action policies and the feedback-only rule agents; one that would lift any of them above ``cap`` tasks of
its subset (5 % of the scenes) is never taken. Of the rest the shortest expert plan wins (:func:`_pick`): a
baseline that solves the start costs it two actions of rank, and a start that shows a look-alike nearer the middle
of the view than the target wins a tie. A whole set is made by
:mod:`eb_navigation.hard_set` (``generate_level``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from eb_scenekit.objects import get_type

from eb_navigation.baselines import (
    CHECK_AGENTS,
    HARD_RULE_AGENTS,
    blind_successes,
    plan_lengths,
    rule_agent_successes,
)
from eb_navigation.geometry import (
    AGENT_RADIUS,
    GRID_RESOLUTION,
    HEADING_VECTORS,
    STEP,
    SUCCESS_DISTANCE,
    AgentState,
    FreeSpace,
    _move_delta,
    bearing_to,
)
from eb_navigation.hard_words import HARD_COMMON_SENSE, HARD_SHAPES, hard_instruction
from eb_navigation.room import ExtraSpec, NavObject, NavRoom, colour_distance, probe
from eb_navigation.tasks import SUBSETS

__all__ = ["CHECK_AGENTS", "DIFFICULTIES", "HARD_TYPES", "LEVELS", "LOW_TOP", "Level", "MIN_LOOKALIKE_GAP",
           "MIN_WAY_PIXELS", "NEAR_START", "OPEN_FLOOR_CLUTTER", "OPEN_MAX_SOLVERS", "OPEN_SOLVER_COST",
           "SEED_BASE", "Scene", "TARGET_WALL_GAP", "Tally", "WALL_BAND", "WAY_MARGIN", "WAY_TOP",
           "WIDE_SLACK",
           "blockers_seen", "clear_corridor", "draw_scene", "facing_target", "found_by_turning", "free_run",
           "lookalike_first", "not_in_pocket", "open_way", "scene_tasks", "way_blockers", "way_box", "way_objects", "way_seen",
           "wide_enough", "wide_space"]

DIFFICULTIES = ("classic", "medium", "hard")
"""The generator's difficulty knob: ``classic`` is the shipped classic generator (:mod:`eb_navigation.generate`)."""
SEED_BASE = 200_000
"""Room seeds of the harder levels start here (classic tests 0..99,999, visual examples 100,000+, splits 10^7+)."""
MIN_LOOKALIKE_GAP = 2.1
"""Metres between the centres of the target and of every look-alike: within 1 m of one is never within 1 m of
the other."""
MIN_COLOUR_DISTANCE = 0.62
"""RGB distance between the target's colour and every look-alike's (black vs white, red vs blue, brown vs pink)."""
MIN_LOOKALIKE_PIXELS = 12
"""Pixels (of 128 x 128) a look-alike shows at a start that promises the target and a look-alike in view."""
MIN_FREE_RUN = 4
"""Moves (1 m) that are clear straight ahead or to one side of every start: no start in a pocket."""
HARD_TYPES: tuple[str, ...] = ("Vase", "WateringCan", "TeddyBear", "GarbageCan", "HousePlant", "Ottoman",
                               "LaundryHamper")
FLOOR_CLUTTER: tuple[str, ...] = ("Box", "Basket", "BasketBall", "Chair", "SideTable", "LaundryHamper",
                                  "WateringCan", "Vase", "TeddyBear", "GarbageCan", "HousePlant", "Ottoman")
OPEN_FLOOR_CLUTTER: tuple[str, ...] = (*FLOOR_CLUTTER, "Chair", "ArmChair", "ArmChair")
"""With the open way on: more tall seats (seen in the first image) among the extra floor things, which break the
blind walks in the open middle of the room while the low things stand along the walls."""
_VIS_TRIES = 14
"""Rendered checks per start at most (the best-ranked candidates first)."""
_EVALUATE = 80
"""Candidates per start checked against the blind baselines at most (the cheapest-ranked first)."""
LOW_TOP = 0.5
"""Metres: a floor object lower than this drops below the untilted view when the agent comes near it (the camera
at 1.5 m looks 50 degrees down at most: a 0.45 m vase leaves the image within about 0.9 m)."""
CORRIDOR_HALF_WIDTH = 0.3
"""Metres either side of the straight way from a start toward the target (the agent's radius and 10 cm)."""
WALL_BAND = 0.35
"""Metres: the extra floor things lower than :data:`LOW_TOP` (not the target, not its look-alikes) stand at most
this far from a wall, so that short starts with no low thing on the way survive; the taller ones (chairs, side
tables, hampers, plants), which the first image shows, still stand anywhere and block the blind walks."""
MIN_WAY_PIXELS = 20
"""Pixels (of 128 x 128) that every floor object on the straight way shows in the first image of an in-view start
(:func:`way_seen`): what the agent may bump into first is in the picture it gets."""
SOLVED_COST = 2
WAY_MARGIN = 0.05
"""Metres to spare on either side of the 0.4 m body: :func:`way_blockers` looks this far beyond the body, and the
way must fit a body this much wider on each side (:func:`wide_enough`)."""
WAY_TOP = 0.75
"""Metres: nothing lower stands within reach of the routes to the target (:func:`open_way`). A thing this tall
stays in the level view until the agent's centre is about 0.6 m from it, a step before the body touches it."""
WIDE_SLACK = 2
TARGET_WALL_GAP = 1.0
"""Metres from the target's centre to every wall with the open way on: the bump agents slide along the walls
(the open way leaves the first moves free, so their forward walks end at a wall), and a target in the open is
reached only by turning or side-stepping toward it."""
OPEN_SOLVER_COST = 3
"""Actions of rank per feedback-only agent that solves a start, with the open way on: each one uses up a share of
that agent's cap (1 of the audit's 20 slots), so the start solved by fewest agents wins."""
OPEN_MAX_SOLVERS = 2
"""With the open way on, a start that more feedback-only agents than this solve is never a candidate, even while
their caps have room: open starts are solved by 10-16 of the 39 agents each, and taking them early would leave
no budget for the later slots (the session-9 trial: up to 678 rooms a slot)."""
NEAR_START = 1.0
"""Metres: the part of the routes next to the start (:func:`open_way`), where a low thing is under the level view
(a 0.45 m thing within about 0.9 m) or at the agent's side, and no image has shown it."""
"""Actions more than the expert's plan that the wider body (:func:`wide_enough`) may need."""
"""Actions a start's rank pays when some blind policy or feedback-only agent solves it (within the cap)."""


@dataclass(frozen=True)
class Level:
    """One difficulty level of the generator."""

    name: str
    clutter: int
    """Small things on the furniture (the classic rooms have 8)."""
    floor_clutter: tuple[int, int]
    """Other things added on the floor (min, max)."""
    lookalikes: tuple[int, int]
    """Same-type objects in other colours (min, max), counting those the room already has."""
    min_target_pixels: int
    """Target pixels of a 128 x 128 segmentation at a start that promises the target in view."""
    distance: tuple[float, float]
    """Start-to-target distance (metres) of the in-view starts; long_horizon up to 1 m more."""
    max_plan: int
    lh_max_plan: int
    lh_min_bearing: float
    """A long_horizon start has the target at least this many degrees off straight ahead (and out of view)."""
    open_way: bool = False
    """Refuse starts without an open way for the first moves (:func:`open_way`, :func:`wide_enough`,
    :func:`blockers_seen`), and draw the room and rank the starts so that few feedback-only agents solve them
    (:data:`TARGET_WALL_GAP`, :data:`OPEN_FLOOR_CLUTTER`, :data:`OPEN_MAX_SOLVERS`). Off in :data:`LEVELS`, so the
    train and val splits draw without it; ``generate_level`` turns it on for the levels in
    :data:`eb_navigation.hard_set.OPEN_WAY_SETS` (the shipped hard set; docs/hard_tasks/navigation.md)."""


LEVELS: dict[str, Level] = {
    "medium": Level("medium", 12, (1, 2), (1, 1), 50, (2.5, 3.5), 15, 17, 100.0),
    "hard": Level("hard", 20, (3, 5), (2, 3), 15, (2.0, 4.5), 14, 16, 60.0),
}
"""``hard`` keeps the expert's plan at 14 actions or fewer (long_horizon 16) of the 20-step budget, and the
generator takes the shortest start that passes every rule (about 11 and 14 on average)."""


# -- the room -----------------------------------------------------------------------------------------------------

def _door_probe(room: NavRoom) -> Any:
    shell = room.layout.room
    d = shell.door
    c, along, normal = shell.wall_frame(d.wall)
    p = c + along * d.offset + normal * 0.5
    return replace(probe("Box", float(p[0]), float(p[1]), 0.0), half_extents=(0.75, d.width / 2 + 0.4))


def _floor_spot(room: NavRoom, type_name: str, rng: np.random.Generator, taken: list, door: Any,
                far_from: list[tuple[float, float]], gap: float, wall: float | None = None,
                inner: float | None = None) -> tuple[float, float, float] | None:
    """A floor pose for ``type_name`` clear of everything on the floor (with room to walk past) and the door;
    with ``wall``, at most that many metres from a wall (pushed into the band along the wall of one side); with
    ``inner``, its centre at least that many metres from every wall."""
    t = get_type(type_name)
    hx, hy = room.size[0] / 2, room.size[1] / 2
    r = max(t.half_extents) + 0.05
    for _ in range(250):
        x = round(float(rng.uniform(-hx + r, hx - r)), 3)
        y = round(float(rng.uniform(-hy + r, hy - r)), 3)
        yaw = float(int(rng.integers(4)) * 90 + round(float(rng.uniform(-20, 20))))
        if wall is not None:
            depth = float(rng.uniform(0.0, wall))
            if rng.random() < 0.5:
                x = round(math.copysign(hx - r - depth, x), 3)
            else:
                y = round(math.copysign(hy - r - depth, y), 3)
        if any(math.hypot(x - a, y - b) < gap for a, b in far_from):
            continue
        if inner is not None and min(hx - abs(x), hy - abs(y)) < inner:
            continue
        cand = probe(type_name, x, y, yaw)
        if cand.overlaps(door) or any(cand.overlaps(o, 0.12) for o in taken):
            continue
        return x, y, yaw
    return None


def _target_colour(type_name: str, existing: list[str], n_look: int, rng: np.random.Generator
                   ) -> tuple[str, list[str]] | None:
    """The target's colour and the look-alikes' colours (all clearly different from the target's)."""
    colours = list(get_type(type_name).colors)
    for c in [colours[int(k)] for k in rng.permutation(len(colours))]:
        if any(colour_distance(c, e) < MIN_COLOUR_DISTANCE for e in existing):
            continue
        others = [o for o in colours if colour_distance(o, c) >= MIN_COLOUR_DISTANCE]
        if not others:
            continue
        need = max(0, n_look - len(existing))
        if not existing:
            need = max(1, need)
        return c, [others[int(rng.integers(len(others)))] for _ in range(need)]
    return None


def _furnish(kind: str, seed: int, level: Level, type_name: str, rng: np.random.Generator
             ) -> tuple[NavRoom, str, list[str]] | None:
    """The room with the target, its look-alikes and the floor clutter added; (room, target id, look-alike ids)."""
    plain = NavRoom(kind, seed, (), level.clutter)
    existing = [o for o in plain.objects if o.type == type_name]
    n_look = int(rng.integers(level.lookalikes[0], level.lookalikes[1] + 1))
    picked = _target_colour(type_name, [o.colour for o in existing], n_look, rng)
    if picked is None:
        return None
    colour, look_colours = picked
    door = _door_probe(plain)
    taken = [o for o in plain.layout.objects if o.parent is None and o.mount != "wall"]
    spots: list[tuple[float, float]] = [(o.x, o.y) for o in existing]
    extras: list[ExtraSpec] = []
    ids = [f"{type_name}_{k}" for k in rng.permutation(np.arange(11, 11 + 1 + len(look_colours)))]
    for k, c in enumerate([colour, *look_colours]):
        # with the open way the target stands in the open, away from the walls the bump agents follow
        inner = TARGET_WALL_GAP if level.open_way and k == 0 else None
        pose = _floor_spot(plain, type_name, rng, taken, door, spots, MIN_LOOKALIKE_GAP, inner=inner)
        if pose is None:
            if k == 0:
                return None
            continue
        extras.append(ExtraSpec(str(ids[k]), type_name, c, *pose))
        taken.append(probe(type_name, *pose))
        spots.append(pose[:2])
    if len(extras) - 1 + len(existing) < level.lookalikes[0]:
        return None
    pool = [t for t in (OPEN_FLOOR_CLUTTER if level.open_way else FLOOR_CLUTTER) if t != type_name]
    for n in range(int(rng.integers(level.floor_clutter[0], level.floor_clutter[1] + 1))):
        typ = pool[int(rng.integers(len(pool)))]
        # a low thing along a wall, a taller (seen) one anywhere; with the open way, "low" is under WAY_TOP
        low = get_type(typ).height < (WAY_TOP if level.open_way else LOW_TOP)
        pose = _floor_spot(plain, typ, rng, taken, door, [], 0.0, wall=WALL_BAND if low else None)
        if pose is None:
            continue
        cols = get_type(typ).colors
        extras.append(ExtraSpec(f"{typ}_{31 + n}", typ, list(cols)[int(rng.integers(len(cols)))], *pose))
        taken.append(probe(typ, *pose))
    room = NavRoom(kind, seed, extras, level.clutter)
    look_ids = [e.id for e in extras[1:] if e.type == type_name] + [o.id for o in existing]
    return room, str(ids[0]), look_ids


# -- starts -------------------------------------------------------------------------------------------------------

def free_run(free: FreeSpace, s: AgentState, action: int, limit: int = MIN_FREE_RUN) -> int:
    """How many moves of ``action`` (0 forward, 2 right, 3 left) in a row are clear from ``s`` (up to ``limit``)."""
    di, dj = _move_delta(s.heading, action)
    n, i, j = 0, s.i, s.j
    while n < limit and free.can_move(i, j, di, dj):
        i, j, n = i + di, j + dj, n + 1
    return n


def not_in_pocket(free: FreeSpace, s: AgentState) -> bool:
    """At least :data:`MIN_FREE_RUN` moves clear straight ahead or to one side."""
    return any(free_run(free, s, a) >= MIN_FREE_RUN for a in (0, 2, 3))


@dataclass
class _Start:
    state: AgentState
    plan: int
    blind: np.ndarray
    rules: np.ndarray


class Tally:
    """How many tasks of one subset each blind policy and rule agent solves so far (None caps: no check)."""

    def __init__(self, cap: int | None) -> None:
        self.cap = cap
        self.blind: np.ndarray | None = None
        self.rules: np.ndarray | None = None

    def admits(self, st: _Start) -> bool:
        if self.cap is None:
            return True
        blind = self.blind if self.blind is not None else np.zeros(st.blind.shape, dtype=np.int32)
        rules = self.rules if self.rules is not None else np.zeros(st.rules.shape, dtype=np.int32)
        worst = max(int(blind[st.blind].max()) if st.blind.any() else -1,
                    int(rules[st.rules].max()) if st.rules.any() else -1)
        return worst + 1 <= self.cap

    def add(self, st: _Start) -> None:
        if self.blind is None or self.rules is None:
            self.blind = np.zeros(st.blind.shape, dtype=np.int32)
            self.rules = np.zeros(st.rules.shape, dtype=np.int32)
        self.blind += st.blind
        self.rules += st.rules


def _sector_ok(b: float, sector: str, min_bearing: float) -> bool:
    if sector == "ahead":  # an in-view start: the target within 45 degrees of straight ahead
        return abs(b) <= 45.0
    if sector == "left":
        return min_bearing <= b <= 135.0
    if sector == "right":
        return -135.0 <= b <= -min_bearing
    if sector == "behind":
        return abs(b) > 135.0
    return abs(b) >= min_bearing  # "any"


def way_objects(room: NavRoom, s: AgentState, target: NavObject, ahead: bool = False) -> list[NavObject]:
    """The floor objects (not the target) whose footprint comes within :data:`CORRIDOR_HALF_WIDTH` of the straight
    way from ``s`` toward the target, up to 1 m short of it (where the episode ends); with ``ahead``, only those
    whose nearest point of the way lies ahead of the start (not the furniture beside or behind it)."""
    dx, dy = target.x - s.x, target.y - s.y
    length = math.hypot(dx, dy)
    if length <= 1.0:
        return []
    ux, uy = dx / length, dy / length
    out = []
    for o in room.objects:
        if not o.on_floor or o.id == target.id:
            continue
        t = min(max((o.x - s.x) * ux + (o.y - s.y) * uy, 0.0), length - 1.0)
        if ahead and t <= 0.0:
            continue
        if math.hypot(o.x - (s.x + t * ux), o.y - (s.y + t * uy)) - max(get_type(o.type).half_extents) \
                < CORRIDOR_HALF_WIDTH:
            out.append(o)
    return out


def clear_corridor(room: NavRoom, s: AgentState, target: NavObject) -> bool:
    """No floor object lower than :data:`LOW_TOP` (teddy bears, balls, boxes, ottomans, look-alikes) stands on the
    straight way from ``s`` toward the target (:func:`way_objects`). Such a thing drops below the untilted view as
    the agent comes near, even when the first image shows it, and a stateless agent, which keeps no memory of
    earlier images, then walks into it; a bump names nothing. The generator refuses such a start."""
    return not any(2 * o.centre[2] < LOW_TOP for o in way_objects(room, s, target))


def way_seen(room: NavRoom, s: AgentState, target: NavObject, vis: Any | None) -> bool:
    """Every floor object on the straight way ahead of the start shows at least :data:`MIN_WAY_PIXELS` in the
    first image: nothing the agent would walk into is out of the picture (the rendered check of in-view starts)."""
    return vis is None or all(vis.pixels(room, s, o.id) >= MIN_WAY_PIXELS
                              for o in way_objects(room, s, target, ahead=True))


def wide_space(room: NavRoom) -> FreeSpace:
    """Where a body :data:`WAY_MARGIN` wider on each side than the agent's fits (all extras present)."""
    return FreeSpace(room.layout.free_space(GRID_RESOLUTION, AGENT_RADIUS + WAY_MARGIN), room.size,
                     GRID_RESOLUTION)


def way_box(s: AgentState, target: NavObject) -> tuple[int, int, int, int] | None:
    """The lattice box ``(i0, i1, j0, j1)`` spanned by the start and the lattice point within 1 m of the target
    nearest to the point 1 m short of it on the straight way (None when the start is already that close)."""
    dx, dy = target.x - s.x, target.y - s.y
    length = math.hypot(dx, dy)
    if length <= SUCCESS_DISTANCE:
        return None
    px, py = target.x - dx / length * SUCCESS_DISTANCE, target.y - dy / length * SUCCESS_DISTANCE
    best: tuple[float, int, int] | None = None
    for gi in range(math.floor(px / STEP) - 1, math.ceil(px / STEP) + 2):
        for gj in range(math.floor(py / STEP) - 1, math.ceil(py / STEP) + 2):
            if math.hypot(gi * STEP - target.x, gj * STEP - target.y) <= SUCCESS_DISTANCE + 1e-9:
                d = math.hypot(gi * STEP - px, gj * STEP - py)
                if best is None or d < best[0]:
                    best = (d, gi, gj)
    if best is None:
        return None
    (i0, i1), (j0, j1) = sorted((s.i, best[1])), sorted((s.j, best[2]))
    return i0, i1, j0, j1


def open_way(room: NavRoom, s: AgentState, target: NavObject) -> bool:
    """Nothing lower than :data:`WAY_TOP` stands within reach of the routes of forward and sideways moves (after
    the turns toward the target) from ``s`` to the point 1 m short of the target where they run within
    :data:`NEAR_START` of the start (:func:`way_blockers` with ``near``): no coffee table, side table, ottoman,
    plant, hamper or floor clutter where the first forward or sideways moves go, which the player has never
    seen (under the level view, or at its side). Farther along the routes a low thing must show in the first
    view (:func:`blockers_seen`): the player meets it head-on, in view, before it drops under the level view.
    The generator refuses a start without it."""
    return all(room.layout.objects[room.index[n]].height >= WAY_TOP for n in way_blockers(room, s, target, True))


def wide_enough(wide_plans: dict[tuple[int, int, int], int], s: AgentState, plan: int) -> bool:
    """A body :data:`WAY_MARGIN` wider on each side than the agent reaches the target from ``s`` within
    :data:`WIDE_SLACK` actions of the expert's ``plan`` (``wide_plans``: :func:`plan_lengths` on
    :func:`wide_space`): the way does not hang on a gap narrower than the body and 10 cm."""
    return wide_plans.get((s.i, s.j, s.heading % 4), 10 ** 6) <= plan + WIDE_SLACK


def facing_target(s: AgentState, target: NavObject) -> AgentState:
    """``s`` turned to the lattice heading nearest the bearing of the target (what the player sees once it has
    turned toward it)."""
    b = bearing_to(s, (target.x, target.y))
    return replace(s, heading=(s.heading + round(b / 90.0)) % 4, tilt=0)


def blockers_seen(room: NavRoom, s: AgentState, target: NavObject, vis: Any | None) -> bool:
    """Every thing within reach of the routes (:func:`way_blockers`; near the start only :data:`WAY_TOP` or taller
    ones) shows at least :data:`MIN_WAY_PIXELS` in the view from ``s`` facing the target (:func:`facing_target`):
    the player has it in the picture before it gets there."""
    if vis is None:
        return True
    view = facing_target(s, target)
    return all(vis.pixels(room, view, n) >= MIN_WAY_PIXELS for n in way_blockers(room, s, target))


def way_blockers(room: NavRoom, s: AgentState, target: NavObject, near: bool = False) -> list[str]:
    """The floor things (furniture included, not the target) whose footprint comes within the body's radius and
    :data:`WAY_MARGIN` of a lattice point of :func:`way_box` (with ``near``: of one within :data:`NEAR_START` of
    the start), by name: what a player walking forward and sideways to the target may bump into."""
    box = way_box(s, target)
    if box is None:
        return []
    i0, i1, j0, j1 = box
    pts = np.array([(i * STEP, j * STEP) for i in range(i0, i1 + 1) for j in range(j0, j1 + 1)
                    if not near or math.hypot(i - s.i, j - s.j) * STEP <= NEAR_START + 1e-9])
    out = []
    for o in room.layout.objects:
        if o.parent is not None or o.mount == "wall" or o.name == target.id:
            continue
        c, si = math.cos(math.radians(o.yaw)), math.sin(math.radians(o.yaw))
        d = pts - np.array(o.position[:2])
        lx, ly = np.abs(c * d[:, 0] + si * d[:, 1]), np.abs(-si * d[:, 0] + c * d[:, 1])
        gap = np.hypot(np.maximum(lx - o.half_extents[0], 0.0), np.maximum(ly - o.half_extents[1], 0.0))
        if gap.min() < AGENT_RADIUS + WAY_MARGIN:
            out.append(o.name)
    return out


def lookalike_first(s: AgentState, target: NavObject, looks: list[NavObject]) -> bool:
    """A look-alike stands nearer the middle of the view than the target (both within 45 degrees of straight
    ahead): walking at the thing ahead goes to the wrong one, so the colour has to be read first."""
    b = abs(bearing_to(s, (target.x, target.y)))
    return any(abs(bearing_to(s, (o.x, o.y))) < min(b, 45.0) for o in looks)


def _pick(room: NavRoom, target: NavObject, looks: list[NavObject], lo: float, hi: float, min_plan: int,
          max_plan: int, sector: str, level: Level, tally: Tally, rng: np.random.Generator, accept: Any,
          avoid: AgentState | None = None, agents: dict[str, Any] | None = None,
          wide: dict[tuple[int, int, int], int] | None = None) -> _Start | None:
    """The best admissible start that ``accept`` (the rendered check) takes. A start with a low object on its
    straight way to the target (:func:`clear_corridor`), without an open way to it (:func:`open_way`) or whose
    way hangs on a narrow gap (:func:`wide_enough`; ``wide``: the wider body's plan lengths) is never a
    candidate. Candidates are ranked by the
    expert's plan length, plus :data:`SOLVED_COST` when any blind policy or rule agent (``agents``, default
    :data:`HARD_RULE_AGENTS`) solves the start; ties go to a start that shows a look-alike nearer the middle of the
    view, then to fewer solving baselines. A start that would lift a baseline above ``tally``'s cap is never
    taken. With the level's ``open_way``, a start that more than :data:`OPEN_MAX_SOLVERS` rule agents solve is
    never taken either, and each solving rule agent costs :data:`OPEN_SOLVER_COST` of rank."""
    free = room.free_space(room.extra_ids)
    xy = (target.x, target.y)
    if level.open_way and wide is None:
        wide = plan_lengths(wide_space(room), xy)
    wide = wide or {}
    ranked = []
    for (i, j, h), n in sorted(plan_lengths(free, xy).items()):
        if not min_plan <= n <= max_plan:
            continue
        if not lo - 1e-9 <= math.hypot(i * STEP - xy[0], j * STEP - xy[1]) <= hi + 1e-9:
            continue
        s = AgentState(i, j, h)
        if s != avoid and _sector_ok(bearing_to(s, xy), sector, level.lh_min_bearing) and not_in_pocket(free, s) \
                and clear_corridor(room, s, target) \
                and (not level.open_way or (wide_enough(wide, s, n) and open_way(room, s, target))):
            ranked.append((n, not lookalike_first(s, target, looks), float(rng.random()), s, n))
    ranked.sort(key=lambda c: c[:3])
    need = _VIS_TRIES if tally.cap is not None else 1
    scored: list[tuple[tuple[float, ...], _Start]] = []
    for cheap, far, tie, s, n in ranked[:_EVALUATE]:
        if sum(key[0] <= cheap for key, _ in scored) >= need:
            break  # enough starts that no later candidate can beat
        st = _Start(s, n, blind_successes(free, s, xy),
                    np.array(list(rule_agent_successes(free, s, xy, agents=agents or HARD_RULE_AGENTS).values()),
                             dtype=bool))
        if not tally.admits(st):
            continue
        solvers = int(st.blind.sum() + st.rules.sum())
        cost = cheap + (SOLVED_COST if solvers else 0)
        if level.open_way:  # each solving agent uses up a scarce share of its cap: few, or none
            agents_solving = int(st.rules.sum())
            if agents_solving > OPEN_MAX_SOLVERS:
                continue
            cost += OPEN_SOLVER_COST * agents_solving
        scored.append(((cost, far, solvers, tie), st))
    scored.sort(key=lambda c: c[0])
    for _key, st in scored[:_VIS_TRIES]:
        if accept(st):
            return st
    return None


def _visible(room: NavRoom, st: _Start, target_id: str, looks: list[str], level: Level, vis: Any | None) -> bool:
    if vis is None:
        return True
    if vis.pixels(room, st.state, target_id) < level.min_target_pixels:
        return False
    if not any(vis.pixels(room, st.state, d) >= MIN_LOOKALIKE_PIXELS for d in looks):
        return False
    target = room.get(target_id)
    return way_seen(room, st.state, target, vis) and (not level.open_way
                                                       or blockers_seen(room, st.state, target, vis))


def found_by_turning(room: NavRoom, s: AgentState, target: NavObject, level: Level, vis: Any | None) -> bool:
    """The target shows at least the level's ``min_target_pixels`` (what an in-view start promises) in the view
    from ``s`` turned toward it (:func:`facing_target`): a long_horizon player that looks around from the start
    finds it by looking. A calibration player lost long_horizon_041 of the first open-way set, whose white teddy
    bear showed only as a sliver behind a red chair from every heading of the start (session 11)."""
    return vis is None or vis.pixels(room, facing_target(s, target), target.id) >= level.min_target_pixels


def _hidden(room: NavRoom, st: _Start, target_id: str, level: Level, vis: Any | None) -> bool:
    if vis is None:
        return True
    target = room.get(target_id)
    return vis.pixels(room, st.state, target_id) == 0 and (
        not level.open_way or (blockers_seen(room, st.state, target, vis)
                               and found_by_turning(room, st.state, target, level, vis)))


# -- one scene ----------------------------------------------------------------------------------------------------

@dataclass
class Scene:
    """One room's five tasks (before wording)."""

    room: NavRoom
    target: NavObject
    lookalikes: list[NavObject]
    starts: dict[str, _Start]
    """``plain`` (base, common_sense, complex_instruction), ``visual_appearance``, ``long_horizon``."""


def draw_scene(kind: str, seed: int, type_name: str, level: Level, rng: np.random.Generator,
               tallies: dict[str, Tally], vis: Any | None, sector: str,
               parts: tuple[str, ...] = ("plain", "visual_appearance", "long_horizon"),
               agents: dict[str, Any] | None = None) -> Scene | None:
    """The tasks of one room, or None when this room cannot give them (the caller draws another). Each start is
    the best-ranked admissible one (:func:`_pick`) checked against all blind policies and ``agents``."""
    made = _furnish(kind, seed, level, type_name, rng)
    if made is None:
        return None
    room, target_id, look_ids = made
    target = room.get(target_id)
    looks = [room.get(i) for i in look_ids]
    lo, hi = level.distance
    wide = plan_lengths(wide_space(room), (target.x, target.y)) if level.open_way else None
    starts: dict[str, _Start] = {}
    for part in parts:
        if part == "long_horizon":
            min_plan = starts["plain"].plan + 2 if "plain" in starts else 8
            pick = _pick(room, target, looks, lo, hi + 1.0, min_plan, level.lh_max_plan, sector, level,
                         tallies[part], rng, lambda c: _hidden(room, c, target_id, level, vis), agents=agents,
                         wide=wide)
        else:
            avoid = starts["plain"].state if part == "visual_appearance" and "plain" in starts else None
            pick = _pick(room, target, looks, lo, hi, 6, level.max_plan, "ahead", level, tallies[part], rng,
                         lambda c: _visible(room, c, target_id, look_ids, level, vis), avoid=avoid, agents=agents,
                         wide=wide)
        if pick is None:
            return None
        starts[part] = pick
    return Scene(room, target, looks, starts)


def _extra_dict(e: ExtraSpec) -> dict[str, Any]:
    return {"id": e.id, "type": e.type, "colour": e.colour, "x": e.x, "y": e.y, "yaw": e.yaw}


def scene_tasks(sc: Scene, slot: int, rng: np.random.Generator, wording: dict[str, dict[str, int]],
                subsets: tuple[str, ...] = SUBSETS, id_prefix: str = "") -> list[dict[str, Any]]:
    """The task entries (file form) of a scene, one per subset in ``subsets``."""
    t = sc.target
    other = sc.lookalikes[int(rng.integers(len(sc.lookalikes)))].colour
    scene = {"kind": sc.room.kind, "seed": sc.room.seed, "clutter": sc.room.clutter}
    out = []
    for subset in subsets:
        st = sc.starts["plain" if subset in ("base", "common_sense", "complex_instruction") else subset]
        text, template = hard_instruction(subset, t.type, t.colour, other, rng, wording.setdefault(subset, {}))
        out.append({"id": f"{id_prefix}{subset}_{slot:03d}", "subset": subset, "instruction": text,
                    "template": template, "scene": scene,
                    "start": {"x": st.state.x, "y": st.state.y, "yaw": st.state.yaw_deg, "tilt": 0},
                    "target": {"id": t.id, "type": t.type, "colour": t.colour,
                               "position": [round(v, 4) for v in t.centre]},
                    "extra_objects": [_extra_dict(e) for e in sc.room.extras], "oracle_steps": st.plan})
    return out


assert set(HARD_COMMON_SENSE) == set(HARD_SHAPES) == set(HARD_TYPES)
assert HEADING_VECTORS  # the lattice headings the starts use
