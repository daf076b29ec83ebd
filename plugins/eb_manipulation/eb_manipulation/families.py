"""The classic set's scene builders: placement, colours, spatial wording and one builder per task family.

Shared by :mod:`eb_manipulation.generate` (the shipped files), :mod:`eb_manipulation.splits` (train/val) and
:mod:`eb_manipulation.hard` (the harder levels reuse the placement and the spatial helpers).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from eb_manipulation.scene import CONTAINER, SORTER
from eb_manipulation.shapes import COLOURS, SHAPES, colours_confusable
from eb_manipulation.spec import DIRECTIONS, TASK_FORMAT, VARIANTS, GoalSpec, ObjectSpec, SceneSpec
from eb_manipulation.templates import (
    COLOUR_COMMON,
    COLOUR_VISUAL,
    DIRECTION_COMMON,
    DIRECTION_TEXT,
    SHAPE_COMMON,
    SHAPE_VISUAL,
    SPILLS,
    TEMPLATES,
    VISUAL_CONTRAST,
    complex_wrap,
    pick,
)

__all__ = ["FAMILY_FN", "FAMILY_ORDER", "SUBSETS", "SUBSET_FAMILIES", "PER_FAMILY"]

SUBSETS = ("base", "common_sense", "complex", "spatial", "visual")
FAMILY_ORDER = ("pick", "stack", "sorter", "wipe")
SUBSET_FAMILIES: dict[str, tuple[str, ...]] = {s: FAMILY_ORDER for s in SUBSETS}
SUBSET_FAMILIES["visual"] = ("pick", "stack", "sorter")  # wiping areas cannot be told apart by looks alone
PER_FAMILY = 12
MAX_ORACLE_STEPS = 15

#: Where object centres may go (reachable top-down by the arm, visible from the front camera).
REGION_X = (-0.02, 0.30)
REGION_Y = (-0.30, 0.30)


# --------------------------------------------------------------------------------------------------------
# placement
@dataclass
class _Rect:
    x: float
    y: float
    hx: float
    hy: float
    yaw: float  # degrees

    def corners(self) -> np.ndarray:
        c, s = math.cos(math.radians(self.yaw)), math.sin(math.radians(self.yaw))
        R = np.array([[c, -s], [s, c]])
        pts = np.array([[sx * self.hx, sy * self.hy] for sx in (-1, 1) for sy in (-1, 1)])
        return pts @ R.T + [self.x, self.y]


def _overlap(a: _Rect, b: _Rect) -> bool:
    """Separating-axis test for two oriented rectangles."""
    ca, cb = a.corners(), b.corners()
    for r in (a, b):
        c, s = math.cos(math.radians(r.yaw)), math.sin(math.radians(r.yaw))
        for axis in (np.array([c, s]), np.array([-s, c])):
            pa, pb = ca @ axis, cb @ axis
            if pa.max() < pb.min() or pb.max() < pa.min():
                return False
    return True


_FOOT = {  # half extents including clearance for the open fingers
    "shape": (0.05, 0.05),
    "sponge": (0.05, 0.05),
    "container": (CONTAINER.inner / 2 + CONTAINER.wall + 0.03, CONTAINER.inner / 2 + CONTAINER.wall + 0.03),
}


def _foot(kind: str, holes: int = 3, size: tuple[float, float] | None = None) -> tuple[float, float]:
    if kind == "sorter":
        return SORTER.depth / 2 + 0.035, SORTER.length(holes) / 2 + 0.035
    if kind == "area":
        assert size is not None
        return size[0] / 2 + 0.02, size[1] / 2 + 0.02
    return _FOOT[kind]


class _Placer:
    def __init__(self, rng: np.random.Generator):
        self.rng = rng
        self.rects: list[_Rect] = []

    def free(self, r: _Rect) -> bool:
        return not any(_overlap(r, o) for o in self.rects)

    def add(self, kind: str, region_x=REGION_X, region_y=REGION_Y, yaw: float | None = None, tries: int = 200,
            **kw) -> tuple[float, float, float]:
        hx, hy = _foot(kind, **kw)
        for _ in range(tries):
            x = float(self.rng.uniform(*region_x))
            y = float(self.rng.uniform(*region_y))
            a = float(self.rng.uniform(-180, 180)) if yaw is None else yaw
            r = _Rect(x, y, hx, hy, a if kind not in ("area",) else 0.0)
            if self.free(r):
                self.rects.append(r)
                return round(x, 4), round(y, 4), round(a, 1)
        raise _Retry(f"no room for a {kind}")

    def put(self, kind: str, x: float, y: float, yaw: float = 0.0, **kw) -> bool:
        hx, hy = _foot(kind, **kw)
        r = _Rect(x, y, hx, hy, yaw)
        if not self.free(r):
            return False
        self.rects.append(r)
        return True


class _Retry(Exception):
    """This draw does not work out; try the next attempt."""


# --------------------------------------------------------------------------------------------------------
# colours
def _distinct_colours(rng: np.random.Generator, n: int, avoid: tuple[str, ...] = ()) -> list[str]:
    if n <= 0:
        return []
    names = list(COLOURS)
    rng.shuffle(names)
    out: list[str] = []
    for c in names:
        if all(not colours_confusable(c, o) for o in [*out, *avoid]):
            out.append(c)
        if len(out) == n:
            return out
    raise _Retry("not enough distinct colours")


def _contrast_pair(rng: np.random.Generator) -> tuple[str, str]:
    a, b = pick(rng, VISUAL_CONTRAST)
    return (a, b) if rng.random() < 0.5 else (b, a)


# --------------------------------------------------------------------------------------------------------
# spatial language (as seen in the front image: left = -y, right = +y, front = +x toward the camera)
_SIDE = {"left": (1, -1), "right": (1, 1), "front": (0, 1), "back": (0, -1)}


def _extreme(objs: list[ObjectSpec], side: str, margin: float = 0.06) -> ObjectSpec | None:
    axis, sign = _SIDE[side]
    vals = sorted(objs, key=lambda o: -sign * (o.y if axis else o.x))
    if len(vals) < 2:
        return None
    a, b = vals[0], vals[1]
    va, vb = (a.y, b.y) if axis else (a.x, b.x)
    return a if abs(va - vb) >= margin else None


def _neighbour(objs: list[ObjectSpec], anchor: ObjectSpec, side: str) -> ObjectSpec | None:
    """The one object just to ``side`` of ``anchor`` (same row/column), if exactly clear."""
    axis, sign = _SIDE[side]
    cands = []
    for o in objs:
        if o.id == anchor.id:
            continue
        d_along = sign * ((o.y - anchor.y) if axis else (o.x - anchor.x))
        d_across = abs((o.x - anchor.x) if axis else (o.y - anchor.y))
        if d_along > 0.06 and d_across < 0.06:
            cands.append((d_along, o))
    if not cands:
        return None
    cands.sort(key=lambda t: t[0])
    if len(cands) > 1 and cands[1][0] - cands[0][0] < 0.06:
        return None
    return cands[0][1]


_EXTREME_TEXT = {
    "left": "the leftmost {noun}",
    "right": "the rightmost {noun}",
    "front": "the {noun} nearest the camera",
    "back": "the {noun} nearest the robot",
}
_NEIGHBOUR_TEXT = {
    "left": "the {noun} just to the left of the {anchor}",
    "right": "the {noun} just to the right of the {anchor}",
    "front": "the {noun} just in front of the {anchor}",
    "back": "the {noun} just behind the {anchor}",
}


def _describe(o: ObjectSpec) -> str:
    return f"{o.colour} {o.shape}" if o.kind == "shape" else f"{o.colour} {o.kind}"


def _spatial_ref(rng: np.random.Generator, objs: list[ObjectSpec], target: ObjectSpec,
                 noun: str = "object") -> str | None:
    """A location-based reference that picks out exactly ``target`` among ``objs`` and needs the image too.

    Either the target is the extreme one of its own shape on some side while another object lies further that
    way ("the leftmost star" with a cylinder further left), or it is the neighbour of an anchor named by colour
    and shape ("the cube just behind the black cube"). References that coordinates alone resolve ("the leftmost
    object") are not used: a language-only model could follow them without seeing anything.
    """
    options: list[str] = []
    if target.kind == "shape":
        same = [o for o in objs if o.kind == "shape" and o.shape == target.shape]
        for side in _SIDE:
            if len(same) >= 2 and _extreme(same, side) is target and _extreme(objs, side, margin=0.0) is not target:
                options.append(_EXTREME_TEXT[side].format(noun=target.shape))
    for anchor in objs:
        if anchor is target:
            continue
        for side in _SIDE:
            if _neighbour(objs, anchor, side) is target:
                options.append(_NEIGHBOUR_TEXT[side].format(noun=noun, anchor=_describe(anchor)))
    return pick(rng, options) if options else None


def _row(rng: np.random.Generator, placer: _Placer, n: int, kind: str = "shape") -> list[tuple[float, float, float]]:
    """``n`` positions in a loose row (along y or x) for spatial tasks."""
    along_y = rng.random() < 0.6
    for _ in range(100):
        spacing = float(rng.uniform(0.12, 0.15))
        span = spacing * (n - 1)
        if along_y:
            x0 = float(rng.uniform(REGION_X[0] + 0.02, REGION_X[1] - 0.02))
            y0 = float(rng.uniform(REGION_Y[0], REGION_Y[1] - span))
            pts = [(x0 + float(rng.uniform(-0.015, 0.015)), y0 + k * spacing) for k in range(n)]
        else:
            if span > REGION_X[1] - REGION_X[0]:
                along_y = True
                continue
            y0 = float(rng.uniform(REGION_Y[0] + 0.02, REGION_Y[1] - 0.02))
            x0 = float(rng.uniform(REGION_X[0], REGION_X[1] - span))
            pts = [(x0 + k * spacing, y0 + float(rng.uniform(-0.015, 0.015))) for k in range(n)]
        saved = list(placer.rects)
        out = []
        for x, y in pts:
            a = float(rng.uniform(-180, 180))
            if not placer.put(kind, x, y, a):
                break
            out.append((round(x, 4), round(y, 4), round(a, 1)))
        if len(out) == n:
            return out
        placer.rects = saved
    raise _Retry("no room for a row")


# --------------------------------------------------------------------------------------------------------
# families
@dataclass
class _Draft:
    objects: list[ObjectSpec]
    goal: GoalSpec
    instruction: str
    target_ids: tuple[str, ...]
    variant: str
    template: str
    """Template id, ``family/subset/index`` (the complex subset reuses the base sentences inside its context)."""


def _say(rng: np.random.Generator, family: str, subset: str, group: str = "") -> tuple[str, str]:
    """A sentence template of ``TEMPLATES[family][subset or base][group]`` and its id."""
    key = "base" if subset == "complex" else subset
    table = TEMPLATES[family][key]
    options = table[group] if isinstance(table, dict) else table
    i = int(rng.integers(len(options)))
    return options[i], f"{family}/{subset}/{group + '.' if group else ''}{i}"


def _finish(rng: np.random.Generator, subset: str, core: str) -> str:
    return complex_wrap(rng, core) if subset == "complex" else core


def _shapes_with(rng, placer, shapes, colours, spatial: bool, prefix: str = "obj") -> list[ObjectSpec]:
    if spatial:
        poses = _row(rng, placer, len(shapes))
    else:
        poses = [placer.add("shape") for _ in shapes]
    return [ObjectSpec(id=f"{prefix}{k}", kind="shape", shape=s, colour=c, x=p[0], y=p[1], yaw=p[2])
            for k, (s, c, p) in enumerate(zip(shapes, colours, poses))]


def _family_pick(rng: np.random.Generator, subset: str, k: int) -> _Draft:
    placer = _Placer(rng)
    spatial = subset == "spatial"
    n = int(rng.integers(4, 6)) if spatial else int(rng.integers(3, 6))  # the target and 2 to 4 other shapes
    shapes = [str(s) for s in rng.permutation(list(SHAPES))[:n]]
    if spatial and rng.random() < 0.6:
        shapes[1] = shapes[0]  # a second object of the target's shape
    if subset == "visual":
        a, b = _contrast_pair(rng)
        colours = [a, b] + _distinct_colours(rng, n - 2, avoid=(a, b))
        if rng.random() < 0.5:
            shapes[1] = shapes[0]  # a look-alike of the target's shape in a close shade
        ca, cb = _contrast_pair(rng)
        cont_cols = [ca, cb]
    else:
        colours = [str(c) for c in rng.choice(list(COLOURS), size=n)]
        cont_cols = _distinct_colours(rng, 2)
    conts = []
    if spatial:
        # two containers side by side or one behind the other
        if rng.random() < 0.5:
            ys = sorted([float(rng.uniform(-0.30, -0.14)), float(rng.uniform(0.14, 0.30))])
            x = float(rng.uniform(REGION_X[0] + 0.04, REGION_X[1]))
            poses = [(x + float(rng.uniform(-0.03, 0.03)), y, 0.0) for y in ys]
        else:
            y = float(rng.choice([-0.24, 0.24])) + float(rng.uniform(-0.04, 0.04))
            poses = [(REGION_X[0] + 0.04, y, 0.0), (REGION_X[1] - 0.02, y + float(rng.uniform(-0.03, 0.03)), 0.0)]
        for p in poses:
            yaw = float(rng.uniform(-20, 20))
            if not placer.put("container", p[0], p[1], yaw):
                raise _Retry("containers overlap")
            conts.append((round(p[0], 4), round(p[1], 4), round(yaw, 1)))
    else:
        conts = [placer.add("container", yaw=float(rng.uniform(-45, 45))) for _ in range(2)]
    cont_objs = [ObjectSpec(id=f"box{j}", kind="container", colour=c, x=p[0], y=p[1], yaw=p[2])
                 for j, (c, p) in enumerate(zip(cont_cols, conts))]
    objs = _shapes_with(rng, placer, shapes, colours, spatial)
    target = objs[0]
    if subset in ("base", "complex") and any(o.shape == target.shape for o in objs[1:]):
        raise _Retry("the named shape must be unique")
    box = cont_objs[int(rng.integers(2))]
    if subset in ("base", "complex"):
        t, tid = _say(rng, "pick", subset)
        instr = _finish(rng, subset, t.format(s=target.shape, c=box.colour))
    elif subset == "common_sense":
        if any(o.shape == target.shape for o in objs[1:]):
            raise _Retry("the described shape must be unique")
        t, tid = _say(rng, "pick", subset)
        instr = t.format(s=pick(rng, SHAPE_COMMON[target.shape]), c=COLOUR_COMMON[box.colour])
    elif subset == "spatial":
        ref = _spatial_ref(rng, objs, target)
        if ref is None:
            raise _Retry("no unique spatial reference")
        t, tid = _say(rng, "pick", subset)
        instr = t.format(o=ref, c=box.colour)
    else:  # visual
        t, tid = _say(rng, "pick", subset)
        instr = t.format(sh=COLOUR_VISUAL[target.colour], f=SHAPE_VISUAL[target.shape], cs=COLOUR_VISUAL[box.colour])
    variant = "pick_cube_relative" if spatial else VARIANTS["pick"]
    return _Draft(cont_objs + objs, GoalSpec(family="pick", target=target.id, container=box.id), instr,
                  (target.id, box.id), variant, tid)


#: Stacking set-ups: build from scratch, finish a tower whose lower two cubes already stand, or first clear
#: another cube off the cube that must carry the tower.
STACK_MODES = ("scratch2", "scratch3", "partial3", "blocked2")


def _cubes(rng: np.random.Generator, colours: list[str], stacked: dict[int, int],
           where: dict[int, tuple[float, float, float]]) -> list[ObjectSpec]:
    """Cube ``i`` of a stacking scene: on cube ``stacked[i]`` (turned a little) or loose at ``where[i]``."""
    cubes = []
    for i in range(len(colours)):
        if i in stacked:
            bx, by, byaw = where[stacked[i]]
            cubes.append(ObjectSpec(id=f"cube{i}", kind="shape", shape="cube", colour=colours[i], x=bx, y=by,
                                    yaw=round(byaw + float(rng.uniform(-8, 8)), 1), on=f"cube{stacked[i]}"))
        else:
            x, y, yaw = where[i]
            cubes.append(ObjectSpec(id=f"cube{i}", kind="shape", shape="cube", colour=colours[i], x=x, y=y, yaw=yaw))
    return cubes


def _stack_extra(rng: np.random.Generator, mode: str, spatial: bool, height: int) -> int:
    """Cubes that are not in the tower: enough that text alone cannot tell which cubes are meant."""
    if mode in ("partial3", "blocked2"):
        return int(rng.integers(2, 4))
    if spatial:
        return 4 - height
    return int(rng.integers(1, 3)) if height == 2 else int(rng.integers(0, 2))


def _stack_colours(rng: np.random.Generator, subset: str, n: int, height: int) -> tuple[list[str], list[int]]:
    """Colours of the ``n`` cubes and the indices of the tower's cubes, bottom first (visual: a near pair in it)."""
    if subset == "visual":
        a, b = _contrast_pair(rng)
        colours = [a, b] + _distinct_colours(rng, n - 2, avoid=(a, b))
        order_idx = [0, 1] + [int(i) for i in rng.permutation(range(2, n))[: height - 2]]
        return colours, [int(i) for i in rng.permutation(order_idx)]
    colours = _distinct_colours(rng, n)
    return colours, [int(i) for i in rng.permutation(n)[:height]]


def _stacked_at_start(mode: str, n: int, order_idx: list[int]) -> dict[int, int]:
    """Cubes resting on another one at the start (index -> the one below); they take no room of their own."""
    if mode == "partial3":
        return {order_idx[1]: order_idx[0]}
    if mode == "blocked2":
        return {next(i for i in range(n) if i not in order_idx): order_idx[0]}
    return {}


def _spatial_refs(rng: np.random.Generator, cubes: list[ObjectSpec], order: list[ObjectSpec]) -> list[str]:
    """A unique spatial reference for each tower cube, or :class:`_Retry`."""
    refs = []
    for c in order:
        r = _spatial_ref(rng, cubes, c, noun="cube")
        if r is None:
            raise _Retry("no unique spatial reference")
        refs.append(r)
    return refs


def _family_stack(rng: np.random.Generator, subset: str, k: int) -> _Draft:
    placer = _Placer(rng)
    spatial = subset == "spatial"
    mode = STACK_MODES[k % 2] if spatial else STACK_MODES[k % 4]
    height = 2 if mode.endswith("2") else 3
    extra = _stack_extra(rng, mode, spatial, height)
    n = height + extra + (1 if mode == "blocked2" else 0)
    colours, order_idx = _stack_colours(rng, subset, n, height)
    stacked = _stacked_at_start(mode, n, order_idx)
    loose = [i for i in range(n) if i not in stacked]
    poses = _row(rng, placer, len(loose)) if spatial else [placer.add("shape") for _ in loose]
    cubes = _cubes(rng, colours, stacked, dict(zip(loose, poses)))
    order = [cubes[i] for i in order_idx]
    cols = [c.colour_name for c in order]
    t, tid = _say(rng, "stack", subset, "two" if height == 2 else "three")
    if subset in ("base", "complex"):
        instr = _finish(rng, subset, t.format(*cols))
    elif subset == "common_sense":
        instr = t.format(*[COLOUR_COMMON[c] for c in cols])
    elif subset == "spatial":
        instr = t.format(*_spatial_refs(rng, cubes, order))
    else:
        instr = t.format(*[COLOUR_VISUAL[c] for c in cols])
    variant = "stack_cubes_relative" if spatial else VARIANTS["stack"]
    return _Draft(cubes, GoalSpec(family="stack", order=tuple(c.id for c in order)), instr,
                  tuple(c.id for c in order), variant, f"{tid}/{mode}")


def _family_sorter(rng: np.random.Generator, subset: str, k: int) -> _Draft:
    placer = _Placer(rng)
    holes = [str(s) for s in rng.permutation(list(SHAPES))[:3]]
    yaw = float(rng.choice([0.0, 90.0])) + float(rng.uniform(-12, 12))
    if abs(yaw) < 45:
        sx, sy = float(rng.uniform(-0.02, 0.10)), float(rng.choice([-1, 1])) * float(rng.uniform(0.17, 0.25))
    else:
        sx, sy = float(rng.uniform(0.05, 0.13)), float(rng.choice([-1, 1])) * float(rng.uniform(0.19, 0.27))
    if not placer.put("sorter", sx, sy, yaw, holes=3):
        raise _Retry("sorter")
    sorter = ObjectSpec(id="sorter", kind="sorter", x=round(sx, 4), y=round(sy, 4), yaw=round(yaw, 1),
                        holes=tuple(holes))
    spatial = subset == "spatial"
    n = int(rng.integers(3, 5)) if spatial else int(rng.integers(2, 5))  # the target and 1 to 3 others
    target_shape = holes[int(rng.integers(3))]
    others = [str(s) for s in rng.choice(list(SHAPES), size=n - 1)]
    shapes = [target_shape] + others
    if subset == "visual":
        a, b = _contrast_pair(rng)
        colours = [a, b] + _distinct_colours(rng, n - 2, avoid=(a, b))
        if rng.random() < 0.5:
            shapes[1] = target_shape  # a look-alike of another shade
    else:
        colours = _distinct_colours(rng, n)
    if spatial and n > 1 and rng.random() < 0.6:
        shapes[1] = target_shape  # a second object of the target's shape
    objs = _shapes_with(rng, placer, shapes, colours, spatial)
    target = objs[0]
    t, tid = _say(rng, "sorter", subset)
    if subset in ("base", "complex"):
        instr = _finish(rng, subset, t.format(c=target.colour))
    elif subset == "common_sense":
        instr = t.format(c=COLOUR_COMMON[target.colour])
    elif subset == "spatial":
        ref = _spatial_ref(rng, objs, target)
        if ref is None:
            raise _Retry("no unique spatial reference")
        instr = t.format(o=ref)
    else:
        instr = t.format(sh=COLOUR_VISUAL[target.colour], f=SHAPE_VISUAL[target.shape])
    variant = "place_into_shape_sorter_relative" if spatial else VARIANTS["sorter"]
    return _Draft([sorter] + objs, GoalSpec(family="sorter", target=target.id), instr, (target.id,), variant, tid)


_AREA_LONG, _AREA_SHORT = 0.22, 0.12


def _area_size(direction: str) -> tuple[float, float]:
    return (_AREA_SHORT, _AREA_LONG) if direction in ("left_to_right", "right_to_left") else (_AREA_LONG, _AREA_SHORT)


def _family_wipe(rng: np.random.Generator, subset: str, k: int) -> _Draft:
    placer = _Placer(rng)
    direction = DIRECTIONS[k % 4]
    size = _area_size(direction)
    # four areas: the one to wipe and three others (text alone leaves a one-in-four guess)
    if subset == "common_sense":
        colours = _distinct_colours_from(rng, list(SPILLS), 4)
    elif subset == "spatial":  # two areas of one colour, told apart by where they are, and others
        a, b, c = _distinct_colours(rng, 3)
        colours = [a, a, b, c]
    else:
        colours = _distinct_colours(rng, 4)
    ax = (-0.04, 0.30) if size[0] < size[1] else (0.02, 0.24)
    ay = (-0.26, 0.26) if size[0] < size[1] else (-0.30, 0.30)
    areas = []
    for j, c in enumerate(colours):
        x, y, _ = placer.add("area", region_x=ax, region_y=ay, yaw=0.0, size=size, tries=400)
        areas.append(ObjectSpec(id=f"area{j}", kind="area", colour=c, x=x, y=y, size=size))
    sx, sy, syaw = placer.add("sponge")
    sponge = ObjectSpec(id="sponge", kind="sponge", x=sx, y=sy, yaw=syaw)
    n_shapes = int(rng.integers(0, 3))  # other things on the table
    shapes = [str(s) for s in rng.choice(list(SHAPES), size=n_shapes)]
    others = _shapes_with(rng, placer, shapes, _distinct_colours(rng, n_shapes), False)
    target = areas[0]
    d = DIRECTION_TEXT[direction]
    t, tid = _say(rng, "wipe", subset)
    if subset in ("base", "complex"):
        instr = _finish(rng, subset, t.format(c=target.colour, d=d))
    elif subset == "common_sense":
        instr = t.format(s=pick(rng, SPILLS[target.colour_name]), d=DIRECTION_COMMON[direction])
    else:  # spatial: the one of the two same-coloured areas on some side of the other
        twin = areas[1]
        sides = [side for side in _SIDE if _extreme([target, twin], side) is target]
        if not sides:
            raise _Retry("the two areas are not clearly apart")
        instr = t.format(a=_AREA_SIDE[pick(rng, sides)].format(c=target.colour), d=d)
    variant = "wipe_table_relative" if subset == "spatial" else VARIANTS["wipe"]
    return _Draft(areas + [sponge] + others,
                  GoalSpec(family="wipe", target="sponge", area=target.id, direction=direction),
                  instr, ("sponge", target.id), variant, tid)


_AREA_SIDE = {"left": "the {c} area further to the left", "right": "the {c} area further to the right",
              "front": "the {c} area nearer the camera", "back": "the {c} area nearer the robot"}


def _distinct_colours_from(rng: np.random.Generator, names: list[str], n: int) -> list[str]:
    names = list(names)
    rng.shuffle(names)
    out: list[str] = []
    for c in names:
        if all(not colours_confusable(c, o) for o in out):
            out.append(c)
        if len(out) == n:
            return out
    raise _Retry("not enough distinct spill colours")


_FAMILY_FN: dict[str, Callable[[np.random.Generator, str, int], _Draft]] = {
    "pick": _family_pick,
    "stack": _family_stack,
    "sorter": _family_sorter,
    "wipe": _family_wipe,
}

FAMILY_FN = _FAMILY_FN
