"""Scene builders of the harder task sets (``difficulty=medium`` and ``difficulty=hard``).

Same four families, same success checks and protocol as the classic set; what changes is the scene and the
instruction:

* more objects (hard: 7 shapes for pick and the sorter, 6 cubes for stacking, 7 marked areas for wiping; medium:
  5 / 5 / 4), so a guess has many candidates;
* look-alikes: the target's shape again in a near shade (red / maroon, blue / navy, green / lime ...), the target's
  colour again on another shape, containers and areas in near shades, all pairs a person tells apart in the image
  (the visual subset's curated pairs);
* "only" conditions stated in the instruction (``GoalSpec.keep_still``): every object the task does not need must
  stay where it is, a container other than the named one must stay empty, the sponge must not touch another area.
  A wrong guess ruins the episode, so a plan cannot queue guesses until one succeeds;
* multi-hop spatial references on a jittered grid ("the star just behind the cube that is just left of the red
  moon"), whose anchors are named by colour and shape, so coordinates alone never resolve them;
* smaller marked areas (14 x 9 cm) packed closer together;
* towers are built from scratch (a tower already begun shows in the list's heights).

Heights in the object list still tell a shape from a container, but not which shape: all shapes stand 4-4.5 cm
tall (z 17), and every role has several candidates.
"""

from __future__ import annotations

import numpy as np

from eb_manipulation.families import (
    _AREA_SIDE,
    _SIDE,
    _cubes,
    _Draft,
    _neighbour,
    _Placer,
    _Retry,
    _spatial_refs,
)
from eb_manipulation.shapes import COLOURS, SHAPES, SYMMETRY, colours_confusable
from eb_manipulation.spec import DIRECTIONS, VARIANTS, GoalSpec, ObjectSpec
from eb_manipulation.templates import (
    _CONTEXT_BRIDGE,
    _CONTEXT_OPEN,
    COLOUR_COMMON,
    COLOUR_VISUAL,
    DIRECTION_COMMON,
    DIRECTION_TEXT,
    SHAPE_COMMON,
    SHAPE_VISUAL,
    SPILLS,
    VISUAL_CONTRAST,
    pick,
)

__all__ = ["build"]


#: Where object centres may go in the harder sets (a little wider than the classic region; all reachable and in
#: view of the front camera).
REGION_X = (-0.04, 0.31)
REGION_Y = (-0.32, 0.32)
AREA_SIZE = (0.14, 0.09)  # long side along the wiping direction, short side across (m)

_KEEP = (
    "Leave everything else exactly where it is.",
    "Do not touch any other object.",
    "Move nothing else.",
    "Everything else must stay where it is.",
)
_KEEP_WIPE = (
    "Do not wipe any other area, and leave everything else where it is.",
    "Keep the sponge off every other area.",
    "No other area may be touched by the sponge.",
)
_FLUSH = (
    "Stack them flush: turn each cube so that its sides line up with the sides of the cube below it.",
    "The tower must be flush, every cube turned so its faces line up with the faces of the one beneath.",
)
_KEEP_ARROW = (
    "Touch it only with strokes the way its arrow points, and keep the sponge off every other area.",
    "The sponge may not move over it against or across its arrow, nor touch any other area.",
)
_KEEP_SORTER_MEDIUM = (
    "Drop it straight through its own hole: nothing may be left on the sorter's lid, and everything else stays "
    "where it is.",
    "Use its own hole at the first try, leave nothing on the lid, and move nothing else.",
)
_KEEP_SORTER = (
    "Turn each one to match its hole's outline and drop it straight through at the first try: nothing may be left on "
    "the sorter's lid, and everything else stays where it is.",
    "Line each one up with the outline of its own hole, leave nothing on the lid, and move nothing else.",
)
_CLOSE = (
    "Thanks, that will make the rest of my day easier.",
    "Once that is done, the table is ready for the next session.",
    "No need to rush, but please be careful.",
)


#: Shapes a person can still tell apart but that look alike from the front camera (a look-alike in the target's
#: colour takes one of these).
NEAR_SHAPES = {"cube": ("cylinder",), "cylinder": ("cube", "moon"), "moon": ("cylinder",), "star": ("triangle",),
               "triangle": ("star", "cube")}


def _near_pair(rng: np.random.Generator) -> tuple[str, str]:
    """Two near shades a person still tells apart (the visual subset's curated pairs), in random order."""
    a, b = pick(rng, VISUAL_CONTRAST)
    return (a, b) if rng.random() < 0.5 else (b, a)


def _others(rng: np.random.Generator, n: int, avoid: list[str]) -> list[str]:
    """``n`` colours, none confusable with ``avoid`` nor with each other."""
    names = [str(c) for c in rng.permutation(list(COLOURS))]
    out: list[str] = []
    for c in names:
        if len(out) == n:
            break
        if all(not colours_confusable(c, o) for o in [*avoid, *out]):
            out.append(c)
    if len(out) < n:
        raise _Retry("not enough distinct colours")
    return out


def _grid(rng: np.random.Generator, placer: _Placer, n: int, region_x=REGION_X, region_y=REGION_Y,
          ) -> list[tuple[float, float, float]]:
    """``n`` shape poses on a jittered grid of 2-3 rows: every object has neighbours to refer by."""
    for _ in range(60):
        rows = 2 if n <= 6 else 3
        cols = -(-n // rows)
        dx, dy = float(rng.uniform(0.115, 0.13)), float(rng.uniform(0.12, 0.14))
        x0 = float(rng.uniform(region_x[0], region_x[1] - dx * (rows - 1)))
        y0 = float(rng.uniform(region_y[0], region_y[1] - dy * (cols - 1)))
        cells = [(r, c) for r in range(rows) for c in range(cols)]
        chosen = [cells[int(i)] for i in rng.permutation(len(cells))[:n]]
        saved = list(placer.rects)
        out = []
        for r, c in chosen:
            x = x0 + r * dx + float(rng.uniform(-0.012, 0.012))
            y = y0 + c * dy + float(rng.uniform(-0.012, 0.012))
            a = float(rng.uniform(-180, 180))
            if not placer.put("shape", x, y, a):
                break
            out.append((round(x, 4), round(y, 4), round(a, 1)))
        if len(out) == n:
            return out
        placer.rects = saved
    raise _Retry("no room for a grid")


def _place_shapes(rng, placer, shapes, colours, grid: bool, prefix: str = "obj") -> list[ObjectSpec]:
    poses = _grid(rng, placer, len(shapes)) if grid else [
        placer.add("shape", region_x=REGION_X, region_y=REGION_Y) for _ in shapes]
    return [ObjectSpec(id=f"{prefix}{k}", kind="shape", shape=s, colour=c, x=p[0], y=p[1], yaw=p[2])
            for k, (s, c, p) in enumerate(zip(shapes, colours, poses))]


def _lookalike_shapes(rng: np.random.Generator, target_shape: str, n: int, shape_pool: list[str] | None = None,
                      ) -> tuple[list[str], list[str]]:
    """Shapes and colours of ``n`` loose objects, the target first: the target's shape in a near shade, the
    target's colour on another shape, and others (shapes may repeat)."""
    a, b = _near_pair(rng)
    pool = shape_pool or list(SHAPES)
    near = [s for s in NEAR_SHAPES[target_shape] if s in pool]  # hard to tell apart from above at 20 px
    other_shape = str(pick(rng, near or [s for s in pool if s != target_shape]))
    shapes = [target_shape, target_shape, other_shape]
    colours = [a, b, a]
    rest = _others(rng, n - 3, [a, b])
    for c in rest:
        shapes.append(str(pick(rng, pool)))
        colours.append(c)
    # no two loose objects with the same colour and shape
    seen = set()
    for s, c in zip(shapes, colours):
        if (s, c) in seen:
            raise _Retry("duplicate object")
        seen.add((s, c))
    return shapes, colours


def _two_hop(objs: list[ObjectSpec], target: ObjectSpec, rng: np.random.Generator,
             gone: ObjectSpec | None = None) -> str | None:
    """"the <shape> just <side> of the <shape A> that is just <side> of the <colour shape B>": the anchor A is named
    by its shape only, so both hops need the image; None when the layout has no such chain. With ``gone`` (an
    object the task moves away first), the chain must also hold without it, so a stateless player asked again
    after that move still finds the target in the image it then gets."""
    options = _chains(objs, target)
    if gone is not None:
        later = set(_chains([o for o in objs if o is not gone], target))
        options = [o for o in options if o in later]
    return pick(rng, options) if options else None


def _chains(objs: list[ObjectSpec], target: ObjectSpec) -> list[str]:
    named = {(o.colour, o.shape) for o in objs}
    options = []
    for a in objs:
        if a is target:
            continue
        for s1 in _SIDE:
            if _neighbour(objs, a, s1) is not target:
                continue
            for b in objs:
                if b is a or b is target or len([o for o in objs if (o.colour, o.shape) == (b.colour, b.shape)]) > 1:
                    continue
                for s2 in _SIDE:
                    if _neighbour(objs, b, s2) is a and (b.colour, b.shape) in named:
                        options.append(f"the {target.shape} just {_REL[s1]} the {a.shape} that is just {_REL[s2]} "
                                       f"the {b.colour} {b.shape}")
    return options


_REL = {"left": "to the left of", "right": "to the right of", "front": "in front of", "back": "behind"}


def _wrap(rng: np.random.Generator, core: str) -> str:
    opening = list(_CONTEXT_OPEN)
    first = pick(rng, opening)
    opening.remove(first)
    second = pick(rng, opening)
    return f"{first} {second} {pick(rng, _CONTEXT_BRIDGE)} {core[0].lower()}{core[1:]} {pick(rng, _CLOSE)}"


def _tpick(rng: np.random.Generator, options, rec: list[int]):
    """``pick`` (the same draw) that also records the sentence's index for the task's template id."""
    i = int(rng.integers(len(options)))
    rec.append(i)
    return options[i]


def _tid(family: str, subset: str, rec: list[int], extra: str = "") -> str:
    return f"{family}/{subset}/hard{extra}/" + ".".join(str(i) for i in rec)


def _finish(rng: np.random.Generator, subset: str, core: str, keep: tuple[str, ...] = _KEEP,
            rec: list[int] | None = None) -> str:
    core = f"{core} {_tpick(rng, keep, rec if rec is not None else [])}"
    return _wrap(rng, core) if subset == "complex" else core


def _obj_text(subset: str, o: ObjectSpec, rng: np.random.Generator) -> str:
    """How an instruction names a loose object by its looks (base/complex: colour and shape)."""
    if subset == "common_sense":
        return f"{pick(rng, SHAPE_COMMON[o.shape_name])} with the colour of {COLOUR_COMMON[o.colour_name]}"
    if subset == "visual":
        return f"the {COLOUR_VISUAL[o.colour_name]} object {SHAPE_VISUAL[o.shape_name]}"
    return f"the {o.colour} {o.shape}"


def _cont_text(subset: str, c: str) -> str:
    if subset == "common_sense":
        return f"the container the colour of {COLOUR_COMMON[c]}"
    if subset == "visual":
        return f"the {COLOUR_VISUAL[c]} container"
    return f"the {c} container"


# --------------------------------------------------------------------------------------------------------
def _pick(rng: np.random.Generator, subset: str, k: int, level: int) -> _Draft:
    placer = _Placer(rng)
    rec: list[int] = []  # indices of the sentences drawn (the template id)
    n = 7 if level >= 2 else 5
    n_cont = 3 if level >= 2 else 2
    ca, cb = _near_pair(rng)
    cont_cols = [ca, cb, *_others(rng, n_cont - 2, [ca, cb])]
    conts = []
    for j, c in enumerate(cont_cols):
        x, y, yaw = placer.add("container", region_x=REGION_X, region_y=REGION_Y, yaw=float(rng.uniform(-30, 30)),
                               tries=400)
        conts.append(ObjectSpec(id=f"box{j}", kind="container", colour=c, x=x, y=y, yaw=yaw))
    target_shape = str(pick(rng, list(SHAPES)))
    shapes, colours = _lookalike_shapes(rng, target_shape, n)
    objs = _place_shapes(rng, placer, shapes, colours, grid=False)
    target, box = objs[0], conts[0]
    if subset == "spatial":
        ref = _two_hop(objs, target, rng)
        if ref is None:
            raise _Retry("no two-hop reference")
        core = _tpick(rng, ("Put {o} into the {c} container.", "Move {o} into the {c} container.",
                          "Pick up {o} and drop it into the {c} container."), rec).format(o=ref, c=box.colour)
    else:
        o, c = _obj_text(subset, target, rng), _cont_text(subset, box.colour_name)
        core = _tpick(rng, ("Put only {o} into {c}.", "Move {o}, and nothing else, into {c}.",
                            "Pick up {o} and place it in {c}."), rec).format(o=o, c=c)
    instr = _finish(rng, subset, core[0].upper() + core[1:], rec=rec)
    keep = tuple(o.id for o in objs[1:]) + tuple(c.id for c in conts[1:])
    variant = "pick_cube_relative" if subset == "spatial" else VARIANTS["pick"]
    return _Draft(conts + objs, GoalSpec(family="pick", target=target.id, container=box.id, keep_still=keep), instr,
                  (target.id, box.id), variant, _tid("pick", subset, rec))


def _stack_colours(rng: np.random.Generator, n: int) -> list[str]:
    """Two near pairs (neither confusable with the other) and ``n - 4`` distinct others."""
    a, b = _near_pair(rng)
    c2, d2 = _near_pair(rng)
    if any(colours_confusable(x, y) and x != y for x in (a, b) for y in (c2, d2)) or {a, b} & {c2, d2}:
        raise _Retry("pairs overlap")
    return [a, b, c2, d2, *_others(rng, n - 4, [a, b, c2, d2])]


def _cube_refs(rng: np.random.Generator, subset: str, cubes: list[ObjectSpec], order: list[ObjectSpec]) -> list[str]:
    """How the instruction names each tower cube, per subset."""
    if subset == "spatial":
        return _spatial_refs(rng, cubes, order)
    if subset == "common_sense":
        return [f"the cube the colour of {COLOUR_COMMON[c.colour_name]}" for c in order]
    if subset == "visual":
        return [f"the {COLOUR_VISUAL[c.colour_name]} cube" for c in order]
    return [f"the {c.colour} cube" for c in order]


def _stack(rng: np.random.Generator, subset: str, k: int, level: int) -> _Draft:
    placer = _Placer(rng)
    rec: list[int] = []  # indices of the sentences drawn (the template id)
    n = 6 if level >= 2 else 5
    # towers start from scratch: a tower already begun would show itself in the list's heights (z 22 on top of a
    # cube), leaving a blind player one cube to guess
    mode = ("two", "three")[k % 2]
    height = 2 if mode == "two" else 3
    colours = _stack_colours(rng, n)
    # the tower takes one of each near pair at least, so a look-alike of a tower cube stays on the table
    order_idx = [0, 2] + ([int(pick(rng, [i for i in range(4, n)]))] if height == 3 else [])
    order_idx = [int(i) for i in rng.permutation(order_idx)]
    poses = _grid(rng, placer, n) if subset == "spatial" else [
        placer.add("shape", region_x=REGION_X, region_y=REGION_Y) for _ in range(n)]
    cubes = _cubes(rng, colours, {}, dict(zip(range(n), poses)))
    order = [cubes[i] for i in order_idx]
    if level >= 2 and any(abs((a.yaw - b.yaw + 45.0) % 90.0 - 45.0) < 30.0 for a, b in zip(order[1:], order)):
        raise _Retry("a tower cube already lies turned like the one it goes on")
    refs = _cube_refs(rng, subset, cubes, order)
    if height == 2:
        core = _tpick(rng, ("Stack {1} on top of {0}.", "Put {1} onto {0}."), rec).format(*refs)
    else:
        core = _tpick(rng, ("Build a tower with {0} at the bottom, {1} in the middle and {2} on top.",
                            "Stack these cubes from the bottom up: {0}, then {1}, then {2}."), rec).format(*refs)
    flush = level >= 2
    if flush:  # orientation that matters: each cube turned to line up with the one below
        core += " " + _tpick(rng, _FLUSH, rec)
    instr = _finish(rng, subset, core[0].upper() + core[1:],
                    keep=("Use only these cubes and leave the other cubes where they are.",
                          "Do not move any other cube."), rec=rec)
    keep = tuple(c.id for c in cubes if c not in order)
    variant = "stack_cubes_relative" if subset == "spatial" else VARIANTS["stack"]
    return _Draft(cubes, GoalSpec(family="stack", order=tuple(c.id for c in order), keep_still=keep, flush=flush),
                  instr,
                  tuple(c.id for c in order), variant, _tid("stack", subset, rec, f"/{mode}"))


def _hole_yaws(rng: np.random.Generator, holes: list[str], targets: list[ObjectSpec], sorter_yaw: float,
               ) -> tuple[float, ...]:
    """Turns of the hole outlines on the lid (degrees, relative to the sorter): each target's own hole is turned at
    least 40 degrees away from how the target lies (modulo its symmetry; it passes within 25), so it must be turned to
    fit; the others at random."""
    out = []
    for shape in holes:
        sym = SYMMETRY[shape]
        target = next((t for t in targets if t.shape == shape), None)
        if target is not None:
            off = float(rng.uniform(40.0, max(40.0, sym / 2))) * float(rng.choice([-1, 1]))
            turn = target.yaw + off - sorter_yaw
        else:
            turn = float(rng.uniform(-sym / 2, sym / 2))
        out.append(round((turn + sym / 2) % sym - sym / 2, 1))
    return tuple(out)


def _sorter(rng: np.random.Generator, subset: str, k: int, level: int) -> _Draft:
    placer = _Placer(rng)
    rec: list[int] = []  # indices of the sentences drawn (the template id)
    holes = [str(s) for s in rng.permutation(list(SHAPES))[:3]]
    yaw = float(rng.choice([0.0, 90.0])) + float(rng.uniform(-10, 10))
    if abs(yaw) < 45:
        sx, sy = float(rng.uniform(-0.03, 0.02)), float(rng.choice([-1, 1])) * float(rng.uniform(0.17, 0.22))
    else:
        sx, sy = float(rng.uniform(0.08, 0.14)), float(rng.choice([-1, 1])) * float(rng.uniform(0.22, 0.26))
    if not placer.put("sorter", sx, sy, yaw, holes=3):
        raise _Retry("sorter")
    n = 7 if level >= 2 else 5
    if level < 2:
        return _sorter_medium(rng, placer, subset, holes, (sx, sy, yaw), n, rec)
    # hard: two shapes, each turned to its hole, whose turn a person reads off the image (the moon and the triangle;
    # not the cylinder, which fits any way, the five-pointed star, which looks the same every 72 degrees, nor the
    # cube, whose 90-degree turns look alike from the front camera)
    turnable = [h for h in holes if h in ("moon", "triangle")]  # a cube's turn is hard to read at 500 px
    if len(turnable) < 2:
        raise _Retry("fewer than two holes whose turn the image shows")
    target_shape = str(pick(rng, turnable))
    second_shape = str(pick(rng, [h for h in turnable if h != target_shape]))
    shapes, colours = _lookalike_shapes(rng, target_shape, n, shape_pool=holes)
    shapes[3] = shapes[4] = second_shape  # the second shape and another of its shape in another colour
    objs = _place_shapes(rng, placer, shapes, colours, grid=subset == "spatial")
    first, second = objs[0], objs[3]
    sorter = ObjectSpec(id="sorter", kind="sorter", x=round(sx, 4), y=round(sy, 4), yaw=round(yaw, 1),
                        holes=tuple(holes), hole_yaws=_hole_yaws(rng, holes, [first, second], yaw))
    # the second shape's chain must not lean on the first, which is in the sorter by the time it is needed
    refs = [_two_hop(objs, o, rng, gone=first if o is second else None) if subset == "spatial"
            else _obj_text(subset, o, rng) for o in (first, second)]
    if None in refs:
        raise _Retry("no two-hop reference")
    core = _tpick(rng, ("Put two objects into the shape sorter: first {o}; then {p}.",
                        "Slot {o} into its hole in the shape sorter; after that, slot {p} into its own hole.",
                        "Drop {o} through its hole in the shape sorter; then drop {p} through its hole. Only those "
                        "two objects."), rec).format(o=refs[0], p=refs[1])
    instr = _finish(rng, subset, core[0].upper() + core[1:], keep=_KEEP_SORTER, rec=rec)
    keep = tuple(o.id for o in objs if o not in (first, second)) + (sorter.id,)
    variant = "place_into_shape_sorter_relative" if subset == "spatial" else VARIANTS["sorter"]
    return _Draft([sorter] + objs, GoalSpec(family="sorter", target=first.id, also=(second.id,), keep_still=keep),
                  instr, (first.id, second.id), variant, _tid("sorter", subset, rec))


def _sorter_medium(rng: np.random.Generator, placer: _Placer, subset: str, holes: list[str],
                   pose: tuple[float, float, float], n: int, rec: list[int]) -> _Draft:
    """medium: one shape, holes not turned."""
    sx, sy, yaw = pose
    target_shape = str(pick(rng, holes))
    shapes, colours = _lookalike_shapes(rng, target_shape, n, shape_pool=holes)
    objs = _place_shapes(rng, placer, shapes, colours, grid=subset == "spatial")
    target = objs[0]
    sorter = ObjectSpec(id="sorter", kind="sorter", x=round(sx, 4), y=round(sy, 4), yaw=round(yaw, 1),
                        holes=tuple(holes))
    ref = _two_hop(objs, target, rng) if subset == "spatial" else _obj_text(subset, target, rng)
    if ref is None:
        raise _Retry("no two-hop reference")
    core = _tpick(rng, ("Put {o} into the shape sorter.", "Slot {o} into its hole in the shape sorter.",
                        "Drop {o}, and only that object, through its hole in the shape sorter."), rec).format(o=ref)
    instr = _finish(rng, subset, core[0].upper() + core[1:], keep=_KEEP_SORTER_MEDIUM, rec=rec)
    keep = tuple(o.id for o in objs[1:]) + (sorter.id,)
    variant = "place_into_shape_sorter_relative" if subset == "spatial" else VARIANTS["sorter"]
    return _Draft([sorter] + objs, GoalSpec(family="sorter", target=target.id, keep_still=keep), instr,
                  (target.id,), variant, _tid("sorter", subset, rec))


def _area_size(direction: str) -> tuple[float, float]:
    long, short = AREA_SIZE
    return (short, long) if direction in ("left_to_right", "right_to_left") else (long, short)


def _wipe_colours(rng: np.random.Generator, subset: str, n: int) -> list[str]:
    """Colours of the ``n`` areas, the target's first: a near shade beside it (spatial: the target's colour twice)."""
    if subset == "common_sense":
        a = str(pick(rng, list(SPILLS)))
        near = [c for c in SPILLS if c != a and colours_confusable(a, c)] or [c for c in SPILLS if c != a]
        b = str(pick(rng, near))
        return [a, b, *[str(c) for c in rng.permutation(list(SPILLS)) if c not in (a, b)][: n - 2]]
    a, b = _near_pair(rng)
    if subset == "spatial":
        return [a, a, b, *_others(rng, n - 3, [a, b])]
    return [a, b, *_others(rng, n - 2, [a, b])]


def _wipe(rng: np.random.Generator, subset: str, k: int, level: int) -> _Draft:
    """Hard: 7 areas, each with an arrow printed on it (long side along it; the other areas' arrows point every way),
    and the instruction names no direction: "in the direction its arrow points". A blind player guesses the area and
    the direction; a stroke the wrong way over the area loses the task (stated in the instruction)."""
    placer = _Placer(rng)
    rec: list[int] = []  # indices of the sentences drawn (the template id)
    direction = DIRECTIONS[k % 4]
    colours = _wipe_colours(rng, subset, 7 if level >= 2 else 4)
    arrows = [direction, *(str(pick(rng, list(DIRECTIONS))) for _ in colours[1:])] if level >= 2 else \
        [direction] * len(colours)
    areas: list[ObjectSpec] = []
    for j, (c, d) in enumerate(zip(colours, arrows)):
        size = _area_size(d)
        x, y, _ = placer.add("area", region_x=(-0.05, 0.31), region_y=(-0.33, 0.33), yaw=0.0, size=size, tries=600)
        areas.append(ObjectSpec(id=f"area{j}", kind="area", colour=c, x=x, y=y, size=size,
                                arrow=d if level >= 2 else None))
    sx, sy, syaw = placer.add("sponge", region_x=REGION_X, region_y=REGION_Y, tries=400)
    # hard: as tall as a cube (its listed z is a shape's, 17) and 2-3 shapes beside it, so the list does not say which
    # entry is the sponge
    sponge = ObjectSpec(id="sponge", kind="sponge", x=sx, y=sy, yaw=syaw, height=0.045 if level >= 2 else None)
    n_shapes = int(rng.integers(2, 4)) if level >= 2 else int(rng.integers(1, 3))
    shapes = [str(s) for s in rng.choice(list(SHAPES), size=n_shapes)]
    others = _place_shapes(rng, placer, shapes, _others(rng, n_shapes, []), grid=False)
    core = _wipe_core(rng, subset, areas, direction, rec, arrows=level >= 2)
    instr = _finish(rng, subset, core, keep=_KEEP_ARROW if level >= 2 else _KEEP_WIPE, rec=rec)
    keep = tuple(a.id for a in areas[1:]) + tuple(o.id for o in others)
    variant = "wipe_table_relative" if subset == "spatial" else VARIANTS["wipe"]
    return _Draft(areas + [sponge] + others,
                  GoalSpec(family="wipe", target="sponge", area=areas[0].id, direction=direction, keep_still=keep),
                  instr, ("sponge", areas[0].id), variant, _tid("wipe", subset, rec))


_ARROW = "in the direction its arrow points"


def _wipe_core(rng: np.random.Generator, subset: str, areas: list[ObjectSpec], direction: str, rec: list[int],
               arrows: bool) -> str:
    """The instruction's request: which area, and the direction (hard: only "the way its arrow points")."""
    target = areas[0]
    if subset == "common_sense":
        if arrows:
            forms = ("Wipe up the patch of {s} with the sponge, {d}.",
                     "Some {s} was spilled; clean just that patch with the sponge, {d}.")
            return _tpick(rng, forms, rec).format(s=pick(rng, SPILLS[target.colour_name]), d=_ARROW)
        return _tpick(rng, ("Wipe up the patch of {s} with the sponge, moving {d}.",
                            "Some {s} was spilled; clean just that patch with the sponge, wiping {d}."), rec).format(
            s=pick(rng, SPILLS[target.colour_name]), d=DIRECTION_COMMON[direction])
    d = _ARROW if arrows else DIRECTION_TEXT[direction]
    if subset == "spatial":
        sides = [side for side in _SIDE if _extreme_pair(target, areas[1], side)]
        if not sides:
            raise _Retry("the two areas are not clearly apart")
        forms = ("Wipe {a} {d}, using the sponge.", "With the sponge, wipe {a} {d}.")
        core = _tpick(rng, forms, rec).format(a=_AREA_SIDE[pick(rng, sides)].format(c=target.colour), d=d)
        return core[0].upper() + core[1:]
    return _tpick(rng, ("Wipe the {c} area {d} with the sponge.", "Use the sponge to wipe only the {c} area {d}."),
                  rec).format(c=target.colour, d=d)


def _extreme_pair(a: ObjectSpec, b: ObjectSpec, side: str, margin: float = 0.06) -> bool:
    axis, sign = _SIDE[side]
    va, vb = (a.y, b.y) if axis else (a.x, b.x)
    return sign * (va - vb) >= margin


_BUILDERS = {"pick": _pick, "stack": _stack, "sorter": _sorter, "wipe": _wipe}


def build(family: str, rng: np.random.Generator, subset: str, k: int, level: int) -> _Draft:
    """A draft task of ``family`` at a difficulty ``level`` >= 1 (see :data:`LEVELS`)."""
    return _BUILDERS[family](rng, subset, k, level)
