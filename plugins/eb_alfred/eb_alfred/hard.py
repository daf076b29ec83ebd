"""The hard set's draw (``taskset=hard``, ``eb tasks generate env=alfred difficulty=hard``).

Same world, actions, feedback, limits and success checks as classic; what changes is the scene and the words:

* crowds of look-alikes: the object is one of ``n_obj`` instances of its type (two of them for pick-two), told
  apart only by colour or shape (shape where the type has shapes, in visual_appearance), by colour and shape
  together where the type has both ("the round white plate" among white square and blue round plates) or, in
  spatial_awareness, only by which piece of furniture it stands on or in ("the mug that is in the cabinet just
  to the left of the fridge");
* the destination is one of ``n_rec``..``n_rec_max`` same-type pieces of furniture (cabinets, drawers,
  shelves, counters...), singled out by colour, by colour and a neighbour when a second piece has its colour
  ("the white drawer just to the left of the sink"), or by its place along the walls;
* instance numbers are shuffled, so ``Mug_3`` or ``Cabinet`` says nothing about where a thing stands;
* the instruction asks to leave the look-alikes alone, and the goal checks it (``goal.untouched``: no other mug,
  no other cabinet may be picked up, opened, closed, switched or filled at any time). A wrong guess cannot be
  taken back, so a player who cannot see has one guess among ``n_obj x n_rec`` (about 1 in 30);
* bigger, fuller rooms; even an exhaustive search fits the 30-step budget (:func:`search_bound`: find, open and
  close per shut-away candidate, a find per destination and per spare knife or dish, then the whole plan).

Relations that the text feedback would give away are not used: "the cabinet that holds the book" (``find a
Book`` says which cabinet), and the object's own place when look-alikes share it. Feedback rules are classic:
``find``/``open`` still name where things are and what is inside, which is no help when every candidate is a
mug at some cabinet.
"""

from __future__ import annotations

import random
import statistics
from typing import Any

from eb_alfred.actions import scene_actions
from eb_alfred.audit import (
    _targets,
    candidate_phrases,
    held_problems,
    phrase_problems,
    relation_problems,
    use_phrase,
)
from eb_alfred.catalog import KNIVES, TYPES, fits
from eb_alfred.draw import (
    _PLACE_TARGETS,
    KIND_ROOMS,
    LONG_ROOMS,
    MAX_ACTIONS,
    MIN_ACTIONS,
    _add_preparation,
    _prepare,
    _shut_away,
    image_problems,
    make_one,
    propose_goal,
)
from eb_alfred.goals import PROPERTY_OF_KIND, evaluate
from eb_alfred.instructions import (
    _ASIDE,
    _CLOSE,
    _CONTEXT,
    _NEED,
    _fill,
    _pick,
    _ref_words,
    base_instruction,
    noun,
    plural,
    prep,
    receptacle_relations,
    shape_before_colour,
)
from eb_alfred.oracle import expert_plan
from eb_alfred.scenes import _renumber, make_scene
from eb_alfred.world import World

__all__ = ["APPLIANCES", "LEVELS", "KINDS", "MAX_STEPS", "MIN_SHOWN", "STEP_RANGE", "half_hidden", "make_hard",
           "maker", "misread_places", "PART_LIKE", "search_bound", "shadowed_white"]

MAX_STEPS = 30
"""The benchmark's step budget (``conf/env/alfred.yaml``)."""

LEVELS: dict[str, dict[str, Any]] = {
    "medium": {"n_obj": 3, "n_rec": 2, "n_rec_max": 3, "n_host": 3, "untouched": ("object",), "two_looks": False},
    "hard": {"n_obj": 6, "n_rec": 4, "n_rec_max": 6, "n_host": 5, "untouched": ("object", "receptacle"),
             "two_looks": True, "short": {"n_obj": 7, "n_rec": 5}, "check_hidden": "target",
             "check_shown": "target"},
}
"""Per level: instances of the object's type, of the destination's type (at least ``n_rec``, at most
``n_rec_max``), of the furniture type holding the spatial look-alikes (one each), the roles whose look-alikes the
goal protects, whether a target of a type with colours and shapes is singled out by both ("the round white
plate" among white square plates and blue round ones), and what changes for the subsets of short plans (all
but spatial_awareness and long_horizon), which have steps to spare for more candidates. ``check_hidden``
refuses a candidate whose view after ``find`` shows much less of it than of the others
(:func:`hidden_candidates`): ``"target"`` when it is one the goal accepts (the shipped hard set), ``"all"`` when
it is any instance of the object's type (every look-alike too; much slower to draw), ``False`` never.
``check_shown`` refuses one whose own view hides part of it (:func:`half_hidden`, below :data:`MIN_SHOWN` of its
silhouette), with the same values: every target (both of a pick-two task) in the shipped set; ``"all"`` would
refuse most draws (about 60 % of the third regeneration's tasks have a look-alike partly hidden by its
neighbours) and makes the draw about twice as slow."""

#: Task types of the hard set: every type with a destination (examine-in-light has one lamp per room, so only
#: the object could be ambiguous, and one guess in six is too easy).
KINDS = ("pick_and_place", "stack_and_place", "pick_two_and_place", "clean_and_place", "heat_and_place",
         "cool_and_place")
#: Oracle-step range per subset (inclusive); the budget is 30.
STEP_RANGE = {"base": (4, 18), "common_sense": (4, 18), "complex_instruction": (4, 18),
              "spatial_awareness": (4, 20), "visual_appearance": (4, 20), "long_horizon": (16, 22)}
#: Where no look-alike is put: deep receptacles whose contents the view after ``find`` barely shows (a white
#: cloth at the bottom of a bathtub, hard long_horizon_23 of the first regeneration), bins, and appliances and
#: boxes, whose contents need extra steps or are unexpected. Every look-alike stands where a person sees it.
DEEP = ("Sink", "SinkBasin", "Bathtub", "BathtubBasin", "LaundryHamper", "GarbageCan", "Microwave", "Fridge",
        "Toaster", "CoffeeMachine", "Safe", "Box")
#: Colours never used to name a destination of the type: white drawers, side tables, shelves and dressers render
#: light grey with darker stripes at the model's size (no pixel of a "white" family; measured by
#: ``test_every_colour_named_destination_renders_its_colour``), so "the white drawer" is not named (the pieces
#: of the other colour may be white). A white cabinet renders plain off-white and is named.
_NOT_NAMED = {"Drawer": ("white",), "SideTable": ("white",), "Shelf": ("white",), "Dresser": ("white",)}
#: Shapes kept out of a furniture type: a tall vase in a cabinet pokes its flowers through the shelf above, so it
#: reads shorter than it is (hard spatial_awareness_08 of the third regeneration).
_NOT_INSIDE = {("Vase", "tall"): ("Cabinet",)}
#: Appliances that stand at the back of a counter or desk: a flat thing on the strip in front of one reads as a
#: part of it (a blue square plate under the coffee machine is its drip tray, hard long_horizon_36 of the third
#: regeneration), so no look-alike of the types in :data:`PART_LIKE` is put on furniture that carries one.
APPLIANCES = ("Microwave", "Toaster", "CoffeeMachine")
#: Flat things that read as an appliance's part when they stand in front of it (a tray, a turntable).
PART_LIKE = ("Plate",)
MIN_SHOWN = 0.75
"""Smallest share of its own silhouette a target or look-alike must show in its own view (after ``find``, and
``open``): a bowl behind a box that shows only its rim shows 0.4 of itself (hard spatial_awareness_35 of the third
regeneration), a tall vase in a cabinet 0.65 (:meth:`eb_alfred.audit.Views.shown`)."""
#: Types left out of hard rooms: a tennis racket lying flat reads as a white plate with a red rim at the
#: model's size (a model that called it a plate was labelled as hallucinating).
_LEFT_OUT = ("TennisRacket",)
#: Subsets whose candidates with an object type of one look only (colour or shape) are refused with this
#: probability (levels with ``two_looks``), so that most targets need two words judged at each candidate ("the
#: round white plate"; of mug, plate, bowl, vase, statue and book). Spatial_awareness tells its look-alikes apart
#: by place, and long_horizon's types follow its recipes (a sliced apple, a heated egg).
_BOTH_FIRST = {"base": 0.7, "common_sense": 0.7, "complex_instruction": 0.7, "visual_appearance": 0.7}
#: Subsets whose destination is always named by colour and a neighbour ("the brown drawer just to the left of
#: the sink"; levels with ``two_looks``); a candidate whose destination has no neighbour to name is refused.
_NEIGHBOUR_ALWAYS = ("base", "complex_instruction", "visual_appearance")
#: Furniture that can be a destination or hold the object in spatial tasks.
_HOSTS = ("Cabinet", "Drawer", "Shelf", "SideTable", "CounterTop", "Dresser", "TowelHolder")
_LEAVE = ("Leave the other {xs} and {rs} alone.", "Do not touch any of the other {xs} or {rs}.",
          "The other {xs} and {rs} must stay exactly as they are.",
          "Keep your hands off the other {xs} and {rs}.")
_LEAVE_OBJ = ("Leave the other {xs} alone.", "Do not touch any of the other {xs}.",
              "The other {xs} must stay exactly as they are.")


def maker(difficulty: str) -> Any:
    """The draw function for a generator level: ``make_one`` for classic, :func:`make_hard` otherwise."""
    if difficulty == "classic":
        return make_one
    if difficulty not in LEVELS:
        raise ValueError(f"alfred: unknown difficulty {difficulty!r}; allowed: classic, {', '.join(LEVELS)}")

    def draw(subset: str, kind: str, seed: int, rng: random.Random, views_for: Any = None) -> dict[str, Any] | None:
        return make_hard(subset, kind, seed, rng, views_for, level=difficulty)
    return draw


def _shuffle_names(objects: list[dict[str, Any]], rng: random.Random) -> None:
    """Give the instances of each type their numbers in random order (``Cabinet`` is no longer the leftmost)."""
    by_type: dict[str, list[dict[str, Any]]] = {}
    for o in objects:
        by_type.setdefault(o["type"], []).append(o)
    rename: dict[str, str] = {}
    for group in by_type.values():
        names = [o["name"] for o in group]
        shuffled = list(names)
        rng.shuffle(shuffled)
        rename.update(zip(names, shuffled))
    for o in objects:
        o["name"] = rename[o["name"]]
        if "parent" in o:
            o["parent"] = rename[o["parent"]]


def _standing(scene: dict[str, Any], t: str) -> list[dict[str, Any]]:
    return [o for o in scene["objects"] if o["type"] == t and "parent" not in o]


def _choose_destination(rng: random.Random, scene: dict[str, Any], goal: dict[str, Any], n_rec: int,
                        by_colour: bool, n_rec_max: int = 99) -> str | None:
    carried = goal["movable"]["type"] if "movable" in goal else goal["object"]["type"]
    kind = goal["kind"]
    options = [t for t in _HOSTS if t in _PLACE_TARGETS and fits(carried, t)
               and n_rec <= len(_standing(scene, t)) <= n_rec_max
               and not (by_colour and len(TYPES[t].colors) < 2)
               and not (kind == "cool_and_place" and t == "Fridge")]
    return rng.choice(options) if options else None


def _add_look_alikes(rng: random.Random, scene: dict[str, Any], xt: str, n_obj: int, avoid: set[str],
                     hosts: list[str] | None, open_first: bool = False) -> list[dict[str, Any]] | None:
    """Make ``n_obj`` instances of ``xt`` (clones of one of them), each on/in a fitting receptacle outside
    ``avoid`` (the destination's type) and outside :data:`DEEP`; with ``hosts``, one per host instance (spatial);
    with ``open_first``, on furniture in plain view (one ``find`` to inspect each) before any inside a drawer or
    cabinet (``find``, ``open``, ``close``; :func:`search_bound` decides whether the task can afford them).
    Returns the instances."""
    objs = scene["objects"]
    mine = [o for o in objs if o["type"] == xt]
    if not mine:
        return None
    model = {k: v for k, v in mine[0].items() if k not in ("name", "parent", "slot", "is_dirty")}
    carries = {o["parent"] for o in objs if o["type"] in APPLIANCES and "parent" in o} if xt in PART_LIKE else set()
    for o in mine:  # existing ones leave the destination's type and closed spots the plan cannot reach cheaply
        parent = next((p for p in objs if p["name"] == o.get("parent")), None)
        if (parent is None or parent["type"] in avoid or (hosts is not None and parent["name"] not in hosts)
                or parent["name"] in carries):
            o["parent"] = "?"
    if hosts is not None:
        free = [h for h in hosts if h not in carries]
        rng.shuffle(free)
        placed = [o for o in mine if o["parent"] != "?"]
        used = {o["parent"] for o in placed}
        free = [h for h in free if h not in used]
        for o in mine:
            if o["parent"] == "?":
                if not free:
                    return None
                o["parent"] = free.pop()
        while len(mine) < n_obj and free:
            twin = dict(model, name=f"{xt}_{90 + len(mine)}", parent=free.pop())
            objs.append(twin)
            mine.append(twin)
        if len(mine) < n_obj or len({o["parent"] for o in mine}) < len(mine):
            return None
        return mine
    # one instance per place (piece of furniture): after "find a Mug_3" the view shows that mug alone, so which
    # name goes with which look is never in doubt
    def top(o: dict[str, Any]) -> str:
        while "parent" in o and o["parent"] != "?":
            o = next(p for p in objs if p["name"] == o["parent"])
        return o["name"]

    receps = [o for o in objs if TYPES[o["type"]].receptacle and fits(xt, o["type"]) and o["type"] not in avoid
              and o["type"] not in DEEP and not TYPES[o["type"]].pickupable and o["name"] not in carries
              and top(o) not in avoid_places(objs, avoid)]
    by_place: dict[str, list[dict[str, Any]]] = {}
    for r in receps:
        by_place.setdefault(top(r), []).append(r)
    places = sorted(by_place)
    rng.shuffle(places)
    if open_first:  # places in plain view first; closed drawers and cabinets only to make up the number
        for p in places:
            by_place[p] = [r for r in by_place[p] if not TYPES[r["type"]].openable] or by_place[p]
        places.sort(key=lambda p: TYPES[by_place[p][0]["type"]].openable)
    if len(places) < n_obj:
        return None
    while len(mine) < n_obj:
        twin = dict(model, name=f"{xt}_{90 + len(mine)}", parent="?")
        objs.append(twin)
        mine.append(twin)
    for o, place in zip(mine, places):
        o["parent"] = rng.choice(by_place[place])["name"]
    for o in mine[n_obj:]:
        if any(c.get("parent") == o["name"] for c in objs):
            return None
        objs.remove(o)
    mine = mine[:n_obj]
    for o in mine:
        o.pop("is_dirty", None)
        o.pop("slot", None)
    return mine


def avoid_places(objs: list[dict[str, Any]], avoid: set[str]) -> set[str]:
    """Names of the standing furniture of the types in ``avoid`` (the destination's look-alikes)."""
    return {o["name"] for o in objs if "parent" not in o and o["type"] in avoid}


def _has_both_looks(xt: str) -> bool:
    """Whether the type has two colours and two shapes or more (a target can be named by both)."""
    return len(TYPES[xt].colors) >= 2 and len(TYPES[xt].shapes) >= 2


def _single_out_by_both_looks(rng: random.Random, mine: list[dict[str, Any]], xt: str, n_targets: int = 1
                              ) -> tuple[str, str, list[dict[str, Any]]] | None:
    """Give ``n_targets`` of ``mine`` a colour and a shape that together no other has, while each alone is
    shared: every other look-alike is a near miss that has exactly one of the two (the target's colour and
    another shape, or its shape and another colour; as many of each as the number allows, at least two), so no
    candidate can be ruled out by one word. Returns ("color+shape", "<shape> <colour>", targets)."""
    info = TYPES[xt]
    if len(info.colors) < 2 or len(info.shapes) < 2 or len(mine) < n_targets + 4:
        return None
    color, shape = rng.choice(info.colors), rng.choice(info.shapes)
    other_c = [c for c in info.colors if c != color]
    other_s = [v for v in info.shapes if v != shape]
    order = list(mine)
    rng.shuffle(order)
    targets, rest = order[:n_targets], order[n_targets:]
    for t in targets:
        t.update(color=color, shape=shape)
    first = rng.randrange(2)
    for i, o in enumerate(rest):
        if (i + first) % 2 == 0:
            o.update(color=color, shape=rng.choice(other_s))
        else:
            o.update(color=rng.choice(other_c), shape=shape)
    return "color+shape", f"{shape_before_colour(shape)} {color}", targets


def _single_out_by_looks(rng: random.Random, mine: list[dict[str, Any]], xt: str, n_targets: int,
                         prefer_shape: bool) -> tuple[str, str, list[dict[str, Any]]] | None:
    """Give ``n_targets`` of ``mine`` one look (colour or shape) none of the others has; the others differ
    only in that. Returns (attribute, value, targets)."""
    info = TYPES[xt]
    attrs = [a for a, vals in (("shape", info.shapes), ("color", info.colors)) if len(vals) >= 2]
    if not attrs:
        return None
    attr = "shape" if prefer_shape and "shape" in attrs else ("color" if "color" in attrs else attrs[0])
    values = list(info.shapes if attr == "shape" else info.colors)
    value = rng.choice(values)
    others = [v for v in values if v != value]
    base_color = rng.choice(info.colors) if info.colors else None
    base_shape = rng.choice(info.shapes) if info.shapes else None
    order = list(mine)
    rng.shuffle(order)
    targets = order[:n_targets]
    for o in order:
        if base_color:
            o["color"] = base_color
        if base_shape:
            o["shape"] = base_shape
        o[attr] = value if o in targets else rng.choice(others)
    return attr, value, targets


def make_hard(subset: str, kind: str, seed: int, rng: random.Random, views_for: Any = None,
              level: str = "hard") -> dict[str, Any] | None:
    """One hard candidate task (or None); ``views_for(world)`` renders it for the image checks (all subsets)."""
    cfg = dict(LEVELS[level])
    if subset not in ("spatial_awareness", "long_horizon"):
        cfg.update(cfg.get("short", {}))
    if kind not in KINDS:
        return None
    long = subset == "long_horizon"
    pick_two = kind == "pick_two_and_place"
    drawn = _hard_goal(subset, kind, seed, rng, cfg)
    if drawn is None:
        return None
    scene, goal, xt, rt = drawn
    if cfg["two_looks"] and subset in _BOTH_FIRST and not _has_both_looks(xt) and rng.random() < _BOTH_FIRST[subset]:
        return None  # most targets of these subsets are of a type named by colour and shape together
    picked = _hard_targets(rng, subset, scene, goal, cfg, xt, rt, pick_two)
    if picked is None:
        return None
    targets, attr, value, host_type = picked
    world, target_names, dest_name, dest_rel = _name_and_build(
        rng, scene, rt, targets, subset == "spatial_awareness",
        two_looks=cfg["two_looks"] and subset != "common_sense")
    if not MIN_ACTIONS <= len(scene_actions(world)) <= MAX_ACTIONS:
        return None
    if cfg["two_looks"] and subset in _NEIGHBOUR_ALWAYS and dest_rel is None:
        return None  # the destination needs its colour and its neighbour judged
    if pick_two:
        look = {"color": targets[0]["color"], "shape": targets[0]["shape"]} if attr == "color+shape" else {
            attr: value}
        goal["object"] = {"type": xt, **look}
    else:
        goal["object"] = {"instance": target_names[0]}
    goal["receptacle"] = {"instance": dest_name}
    goal["untouched"] = list(cfg["untouched"])
    _prepare(world, goal)
    if long and rng.random() < 0.85 and not _shut_all_away(rng, world, goal, xt, rt):
        return None
    if evaluate(goal, world)[1] > 0 or shadowed_white(world, xt) or misread_places(world, xt):
        return None
    lo, hi = STEP_RANGE[subset]
    if search_bound(world, goal, lo) > MAX_STEPS:  # cheap early check with the shortest plan allowed
        return None
    plan = expert_plan(world, goal, limit=hi)
    if plan is None or not lo <= len(plan) <= hi:
        return None
    if search_bound(world, goal, len(plan)) > MAX_STEPS:
        return None
    words = _words(rng, subset, goal, world, xt, rt, attr, value, host_type, dest_rel)
    if words is None:
        return None
    template, text = _instruction(rng, subset, goal, world, words, xt, rt, level)
    from eb_core.audit.instructions import grammar_issues  # the audit's own check (imported on first draw)

    if phrase_problems(text, goal, world) or grammar_issues(text):
        return None  # grammar: "the decorative jar you put flowers in in the white drawer" (audit's probe)
    rec = {"instruction": text, "task_type": kind, "goal": goal, "scene": world.to_scene(), "scene_seed": seed,
           "oracle_steps": len(plan), "notes": words["notes"], "template": template}
    if views_for is not None:
        # common_sense names the look by itself ("the red handled cup..."): check it as "the red mug"
        seen = dict(rec, instruction=f"{text} ({value} {noun(xt)})") if subset == "common_sense" and value else rec
        views = views_for(world)
        if (image_problems(seen, views) or relation_problems(text, goal, views, own_view=True)
                or _hidden_refused(cfg.get("check_hidden"), world, goal, xt, views)
                or _shown_refused(cfg.get("check_shown"), world, goal, xt, views)
                or held_problems(text, goal, views)):
            return None
    return rec


def _hidden_refused(check: str | bool | None, world: World, goal: dict[str, Any], xt: str, views: Any) -> bool:
    """Whether ``check_hidden`` (see :data:`LEVELS`) refuses the candidate: a target (``"target"``) or any
    instance of the object's type (``"all"``) that its own view barely shows (:func:`hidden_candidates`)."""
    if not check:
        return False
    if check not in ("target", "all"):
        raise ValueError(f"alfred: check_hidden must be 'target', 'all' or False, not {check!r}")
    hidden = hidden_candidates(world, xt, views)
    return bool(hidden) if check == "all" else any(n in hidden for n in _targets(goal, world))


def _shown_refused(check: str | bool | None, world: World, goal: dict[str, Any], xt: str, views: Any) -> bool:
    """Whether ``check_shown`` (see :data:`LEVELS`) refuses the candidate: a target (``"target"``: every target
    of a pick-two task) or any instance of the object's type (``"all"``) that its own view shows less than
    :data:`MIN_SHOWN` of (:func:`half_hidden`). Targets are checked first (they are rendered already)."""
    if not check:
        return False
    if check not in ("target", "all"):
        raise ValueError(f"alfred: check_shown must be 'target', 'all' or False, not {check!r}")
    targets = _targets(goal, world)
    names = targets + ([n for n in world.of_type(xt) if n not in targets] if check == "all" else [])
    return any(views.shown(n) < MIN_SHOWN for n in names)


def half_hidden(world: World, xt: str, views: Any) -> list[str]:
    """Instances of the object's type whose own view (after ``find``, and ``open``) shows less than
    :data:`MIN_SHOWN` of their silhouette: something in front of them (a box, a pillow, the shelf above a tall
    vase) hides the look that tells them apart. Every candidate must be judged from its own view, so the hard
    draw refuses a task with one."""
    return [n for n in world.of_type(xt) if views.shown(n) < MIN_SHOWN]


def misread_places(world: World, xt: str) -> list[str]:
    """Instances of the object's type placed where the render misleads: a flat thing (:data:`PART_LIKE`) on
    furniture that carries an appliance (:data:`APPLIANCES`: a plate in front of the coffee machine reads as its
    drip tray) or a shape inside furniture
    that cuts it (:data:`_NOT_INSIDE`: a tall vase in a cabinet reads short). The hard draw refuses a task with
    one."""
    out = []
    for n in world.of_type(xt):
        o = world.objects[n]
        parent = world.objects[o.parent] if o.parent else None
        if parent is None:
            continue
        if o.type in PART_LIKE and any(world.objects[c].type in APPLIANCES for c in world.children(parent.name)):
            out.append(n)
        elif parent.type in _NOT_INSIDE.get((o.type, o.shape or ""), ()):
            out.append(n)
    return out


def shadowed_white(world: World, xt: str) -> list[str]:
    """Instances of the object's type that are white and inside closed furniture: in the shade of a cabinet or
    drawer a white thing renders grey (it would be told apart by a colour it does not show), so the hard draw
    refuses a task with one."""
    return [n for n in world.of_type(xt) if world.objects[n].color == "white"
            and world.closed_container(n) is not None]


def hidden_candidates(world: World, xt: str, views: Any) -> list[str]:
    """Instances of the object's type that the view after their ``find`` (and ``open``) shows much less of than
    the others: under half the median share of the image (a vase behind a pillow shows only its flowers). Every
    candidate must be seen to be told apart, so a task with one is refused."""
    areas = {n: views.area(n) for n in world.of_type(xt)}
    floor = 0.5 * statistics.median(areas.values())
    return [n for n, a in areas.items() if a < floor]


def _hard_goal(subset: str, kind: str, seed: int, rng: random.Random,
               cfg: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any], str, str] | None:
    """A hard candidate's room and goal: ``(scene, goal, object type, destination type)``, or None. The
    destination is one of ``n_rec`` same-type pieces of furniture; long-horizon goals may get a preparation."""
    long = subset == "long_horizon"
    rooms = LONG_ROOMS.get(kind) if long else KIND_ROOMS[kind]
    if not rooms:
        return None
    room = rng.choice(rooms)
    scene = make_scene(seed, room, size=(0.5 + 0.5 * rng.random()) if long else (0.6 + 0.4 * rng.random()))
    scene["objects"] = [o for o in scene["objects"] if o["type"] not in _LEFT_OUT]
    world = World.from_scene(scene)
    sliced = long and room == "kitchen" and rng.random() < 0.5
    goal = propose_goal(rng, kind, world, sliced=sliced)
    if goal is None:
        return None
    xt = goal["object"]["type"]
    rt = _choose_destination(rng, scene, goal, cfg["n_rec"], by_colour=subset != "spatial_awareness",
                             n_rec_max=cfg["n_rec_max"])
    if rt is None:
        return None
    goal["receptacle"] = {"type": rt}
    if long and (kind not in PROPERTY_OF_KIND or rng.random() < 0.5):
        goal = _add_preparation(rng, world, goal)
        if goal is None:
            return None
    return scene, goal, xt, rt


def _hard_targets(rng: random.Random, subset: str, scene: dict[str, Any], goal: dict[str, Any],
                  cfg: dict[str, Any], xt: str, rt: str,
                  pick_two: bool) -> tuple[list[dict[str, Any]], str | None, str | None, str | None] | None:
    """The object's look-alikes and which of them the task is about: ``(targets, the attribute that tells them
    apart and its value (None in spatial tasks: the host tells), the host type (spatial tasks))``, or None."""
    spatial = subset == "spatial_awareness"
    hosts = None
    host_type = None
    if spatial and not pick_two:
        host_types = [t for t in _HOSTS if t != rt and fits(xt, t) and len(_standing(scene, t)) >= cfg["n_host"]]
        if not host_types:
            return None
        host_type = rng.choice(host_types)
        hosts = [o["name"] for o in _standing(scene, host_type)]
    n_obj = cfg["n_obj"] if hosts is None else min(cfg["n_obj"], len(hosts))
    mine = _add_look_alikes(rng, scene, xt, n_obj, {rt, *( [goal["movable"]["type"]] if "movable" in goal else [])},
                            hosts, open_first=subset == "long_horizon")
    if mine is None:
        return None
    if spatial and not pick_two:
        info = TYPES[xt]
        look = {"color": rng.choice(info.colors)} if info.colors else {}
        if info.shapes:
            look["shape"] = rng.choice(info.shapes)
        for o in mine:
            o.update(look)
        return [rng.choice(mine)], None, None, host_type
    got = None
    if cfg["two_looks"]:  # both looks wherever the type has both, pick-two and common_sense too
        got = _single_out_by_both_looks(rng, mine, xt, 2 if pick_two else 1)
    if got is None:
        got = _single_out_by_looks(rng, mine, xt, 2 if pick_two else 1, prefer_shape=subset == "visual_appearance")
    if got is None:
        return None
    attr, value, targets = got
    return targets, attr, value, host_type


def _name_and_build(rng: random.Random, scene: dict[str, Any], rt: str, targets: list[dict[str, Any]],
                    spatial: bool, two_looks: bool = False) -> tuple[World, list[str], str, str | None]:
    """Pick the destination among its look-alikes (one colour for it, the other for the rest; not in spatial
    tasks), number and shuffle the instance names: ``(world, the targets' names, the destination's name, its
    relation or None)``. With ``two_looks`` a second piece shares the destination's colour and a relation to a
    neighbour tells them apart ("the white drawer just to the left of the sink"): the relation ("drawer just to
    the left of the sink") is returned."""
    def clean() -> dict[str, Any]:
        return {"room": scene["room"], "objects": [{k: v for k, v in o.items() if not k.startswith("_")}
                                                   for o in scene["objects"]]}

    dests = _standing(scene, rt)
    dest = rng.choice(dests)
    dest_rel = None
    if not spatial:
        cols = list(TYPES[rt].colors)
        rng.shuffle(cols)
        if cols[0] in _NOT_NAMED.get(rt, ()):
            cols.reverse()
        same = [dest]
        if two_looks:
            rels = [p for p, _ in receptacle_relations(World.from_scene(clean()), dest["name"])
                    if p.startswith(f"the {noun(rt)} just ")]
            if rels:
                dest_rel = rng.choice(rels)[len("the "):]
                rest = [d for d in dests if d is not dest]
                same += rng.sample(rest, _same_colour(len(dests)) - 1)
        for d in dests:
            d["color"] = cols[0] if any(d is x for x in same) else cols[1]
    for t in targets:
        t["_target"] = True
    dest["_dest"] = True
    _renumber(scene["objects"])
    _shuffle_names(scene["objects"], rng)
    world = World.from_scene(clean())
    target_names = [o["name"] for o in scene["objects"] if o.get("_target")]
    dest_name = next(o["name"] for o in scene["objects"] if o.get("_dest"))
    return world, target_names, dest_name, dest_rel


def _same_colour(n_dests: int) -> int:
    """How many of ``n_dests`` pieces of furniture share the colour of a destination named by colour and a
    neighbour: most of them (3 of 4 or 5, 4 of 6), so the colour rules out one or two and the neighbour must be
    checked at nearly every candidate; at least one piece has the other colour."""
    return max(2, n_dests // 2 + 1)


def _shut_all_away(rng: random.Random, world: World, goal: dict[str, Any], xt: str, rt: str) -> bool:
    """Long-horizon: shut the dish and the knives away (:func:`_shut_away`; the object's look-alikes stay where
    :func:`_add_look_alikes` put them, in plain view where the room has places enough), still one per place;
    False when that fails."""
    shut_goal = dict(goal, object={"type": xt}, receptacle={"type": rt})
    if not _shut_away(rng, world, shut_goal, skip_object=True):
        return False
    places = [world.place_of(n) for n in world.of_type(xt)]
    return len(set(places)) == len(places)


def search_bound(world: World, goal: dict[str, Any], plan_length: int) -> int:
    """Actions a sighted player needs at worst: inspect every candidate -- for each instance of the object's
    type a ``find``, plus ``open`` and ``close`` when it is inside something closed; for each piece of furniture
    of the destination's type a ``find`` (plus ``open`` and ``close`` if it is closed inside something) -- then
    one ``find`` for every other instance of a tool or dish the plan uses (a knife, the movable receptacle)
    that may turn out to be out of reach, then the expert's whole plan. Kept within the step budget, so even an
    exhaustive search fits."""
    def t_of(ref: dict[str, str]) -> str:
        return world.objects[ref["instance"]].type if "instance" in ref else ref["type"]

    xt = t_of(goal["object"])
    rt = t_of(goal["receptacle"])

    def look(n: str) -> int:
        return 1 + (2 if world.closed_container(n) is not None else 0)

    cost = sum(look(n) for n in world.of_type(xt))
    cost += sum(look(n) for n in world.of_type(rt) if world.objects[n].parent is None)
    groups = [[t_of(goal["movable"])]] if "movable" in goal else []
    if goal.get("sliced"):
        groups.append(list(KNIVES))  # any knife slices
    for types in groups:
        cost += max(0, sum(len(world.of_type(t)) for t in types if t not in (xt, rt)) - 1)
    return cost + plan_length


def _words(rng: random.Random, subset: str, goal: dict[str, Any], world: World, xt: str, rt: str,
           attr: str | None, value: str | None, host_type: str | None,
           dest_rel: str | None = None) -> dict[str, str] | None:
    """Referring phrases for the object (``obj`` or ``objs``) and the destination (``recep``), and notes."""
    dest = goal["receptacle"]["instance"]
    out: dict[str, str] = {}
    if subset == "spatial_awareness":
        x = goal["object"].get("instance")
        if x is not None:
            parent = world.objects[x].parent
            rels = [p for p, _ in receptacle_relations(world, parent) if "holds" not in p]
            if not rels:
                return None
            out["obj"] = f"the {noun(xt)} that is {'in' if prep(host_type or '') == 'in' else 'on'} {rng.choice(rels)}"
        else:
            out["objs"] = f"{value} {plural(xt)}"
        rels = [p for p, _ in receptacle_relations(world, dest) if "holds" not in p]
        if not rels:
            return None
        out["recep"] = rng.choice(rels)
    elif subset == "common_sense":
        uses = list(TYPES[xt].uses)
        if attr == "color+shape":  # no use that says a shape itself ("the shallow white deep round dish")
            uses = [u for u in uses if not set(u.split()) & set(TYPES[xt].shapes)]
            if not uses:
                return None
        use = rng.choice(uses)
        if "instance" in goal["object"]:
            out["obj"] = use_phrase(use, value or "")
        else:
            out["objs"] = f"{value} {plural(xt)}"
        out["recep"] = use_phrase(rng.choice(TYPES[rt].uses), world.objects[dest].color or "")
    else:
        out["obj" if "instance" in goal["object"] else "objs"] = (
            f"the {value} {noun(xt)}" if "instance" in goal["object"] else f"{value} {plural(xt)}")
        out["recep"] = f"the {world.objects[dest].color} {dest_rel or noun(rt)}"
    if "instance" in goal["object"] and subset not in ("spatial_awareness", "common_sense"):
        if not any(p.lower() == out["obj"].lower() for p, _ in candidate_phrases(world, goal, "object")):
            return None
    out["notes"] = f"object {goal['object']}: {out.get('obj') or out.get('objs')}; receptacle {dest}: {out['recep']}"
    return out


def _instruction(rng: random.Random, subset: str, goal: dict[str, Any], world: World, words: dict[str, str],
                 xt: str, rt: str, level: str) -> tuple[str, str]:
    over = {k: v for k, v in words.items() if k in ("obj", "objs", "recep")}
    if subset == "complex_instruction":
        tid, need = _pick(rng, "complex_instruction", goal["kind"], _NEED)
        need = _fill(need, _ref_words(goal, world, **over))
        involved = {xt, rt} | ({goal["movable"]["type"]} if "movable" in goal else set())
        others = sorted({o.type for o in world.objects.values() if TYPES[o.type].pickupable} - involved)
        context = rng.sample(_CONTEXT, 2 + rng.randrange(2))
        if others:
            context.insert(rng.randrange(1, len(context) + 1), rng.choice(_ASIDE).format(d=noun(rng.choice(others))))
        at = rng.randrange(1, len(context) + 1)
        parts = context[:at] + [need] + context[at:]
        text = " ".join(parts)
        tid = "hard." + tid
    else:
        tid, text = base_instruction(rng, goal, world, subset=subset, **over)
        tid = "hard." + tid
    if LEVELS[level]["untouched"] == ("object",):
        k = rng.randrange(len(_LEAVE_OBJ))
        leave = _LEAVE_OBJ[k].format(xs=plural(xt))
    else:
        k = rng.randrange(len(_LEAVE))
        leave = _LEAVE[k].format(xs=plural(xt), rs=plural(rt))
    tail = rng.choice(_CLOSE) if subset == "complex_instruction" else ""
    return f"{tid}.leave{k}", " ".join(p for p in (text, leave, tail) if p)
