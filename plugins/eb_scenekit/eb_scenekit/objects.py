"""The household object catalogue: 93 object types built from MuJoCo primitives and generated meshes.

Every type is an :class:`ObjectType` with an AI2-THOR style CamelCase name, a category, named colour variants, a
footprint and height, support surfaces (for receptacles), and a builder that writes one MJCF ``<body>`` subtree.
Conventions every builder follows (so worlds can reason about objects without looking at geometry):

* the body origin is the centre of the object's footprint at floor/support level (z = 0 is its bottom);
* the object's *front* (doors, drawers, screens, seat) faces local +x; width runs along local y;
* every geom, body, joint and light of an instance is named ``"<instance>/<part>"`` so that segmentation and
  state changes can be attributed to the instance; instance names therefore must not contain ``/``;
* openable parts (doors, drawers, lids) are child bodies with one hinge or slide joint named
  ``"<instance>/<part>"``; joint value 0 is closed, the upper end of the joint range is fully open
  (see :func:`set_open`);
* movable (pickable) objects get a free joint ``"<instance>/free"`` so a world can move them with
  :func:`set_object_pose` without recompiling the model.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from types import ModuleType
from typing import TYPE_CHECKING, Literal, TypedDict

import numpy as np

from eb_scenekit._meshes import cached as _mesh
from eb_scenekit._mjcf import El, fmt

if TYPE_CHECKING:
    from mujoco import MjData, MjModel  # MuJoCo ships no type information: to the checker these are Any
    from typing_extensions import Unpack  # typing.Unpack from Python 3.11

__all__ = [
    "CATALOGUE",
    "COLORS",
    "Builder",
    "ObjectType",
    "Parts",
    "Surface",
    "get_type",
    "object_types",
    "material_assets",
    "set_open",
    "get_open",
    "articulated_joints",
    "set_object_pose",
    "set_powered",
    "shade",
    "surface_position",
    "yaw_quat",
]

RGB = tuple[float, float, float]
RGBA = tuple[float, float, float, float]
Category = Literal["furniture", "appliance", "food", "container", "small"]
Mount = Literal["floor", "surface", "wall"]

COLORS: dict[str, RGB] = {
    "red": (0.78, 0.1, 0.1),
    "dark_red": (0.45, 0.06, 0.08),
    "blue": (0.12, 0.3, 0.75),
    "navy": (0.1, 0.14, 0.35),
    "light_blue": (0.55, 0.75, 0.92),
    "white": (0.93, 0.93, 0.91),
    "cream": (0.93, 0.88, 0.74),
    "beige": (0.82, 0.74, 0.6),
    "yellow": (0.95, 0.8, 0.12),
    "green": (0.15, 0.55, 0.2),
    "dark_green": (0.08, 0.3, 0.12),
    "lime": (0.55, 0.8, 0.2),
    "orange": (0.95, 0.5, 0.08),
    "pink": (0.93, 0.55, 0.65),
    "purple": (0.45, 0.2, 0.6),
    "brown": (0.45, 0.28, 0.14),
    "tan": (0.78, 0.62, 0.4),
    "gray": (0.5, 0.5, 0.52),
    "light_gray": (0.75, 0.75, 0.76),
    "dark_gray": (0.22, 0.22, 0.24),
    "black": (0.06, 0.06, 0.07),
    "silver": (0.75, 0.77, 0.8),
    "steel": (0.62, 0.64, 0.67),
    "gold": (0.83, 0.66, 0.25),
    "wood": (0.62, 0.43, 0.26),
    "oak": (0.78, 0.62, 0.42),
    "walnut": (0.38, 0.24, 0.14),
    "terracotta": (0.72, 0.36, 0.22),
    "clear": (0.75, 0.85, 0.9),
}
"""Named colours (linear RGB in 0..1) used by the variants; worlds may use the names in instructions."""

# fixed part colours
_WHITE = (0.93, 0.93, 0.91)
_BLACK = (0.05, 0.05, 0.06)
_DARK = (0.16, 0.16, 0.18)
_GRAY = (0.5, 0.5, 0.52)
_CHROME = (0.85, 0.86, 0.9)
_STEEL = (0.64, 0.66, 0.69)
_GLASS = (0.6, 0.75, 0.82, 0.35)
_DARK_GLASS = (0.04, 0.06, 0.08, 1.0)
_SCREEN = (0.1, 0.25, 0.5)
_CREAM = (0.95, 0.91, 0.8)
_WOOD = (0.62, 0.43, 0.26)
_WALNUT = (0.38, 0.24, 0.14)
_LEAF = (0.2, 0.5, 0.15)
_BROWN = (0.42, 0.26, 0.12)
_STONE = (0.8, 0.79, 0.76)
_WARM_LIGHT = (1.0, 0.85, 0.55)


def shade(c: tuple[float, ...], f: float) -> RGB:
    """Darken (``f < 1``: scale towards black) or lighten (``f > 1``: move towards white) an RGB colour."""
    if f <= 1:
        return (c[0] * f, c[1] * f, c[2] * f)
    g = f - 1
    return (c[0] + (1 - c[0]) * g, c[1] + (1 - c[1]) * g, c[2] + (1 - c[2]) * g)


_shade = shade


def _rgba(c: tuple[float, ...]) -> RGBA:
    return (c[0], c[1], c[2], c[3] if len(c) > 3 else 1.0)


# ---------------------------------------------------------------------------------------------------------------
# rotations


def _quat_mul(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def _axis_quat(axis: tuple[float, float, float], deg: float) -> tuple[float, float, float, float]:
    n = math.sqrt(sum(a * a for a in axis))
    h = math.radians(deg) / 2
    s = math.sin(h) / n
    return (math.cos(h), axis[0] * s, axis[1] * s, axis[2] * s)


def _rpy_quat(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """Rz(yaw)·Ry(pitch)·Rx(roll), degrees."""
    q = _axis_quat((0, 0, 1), yaw)
    q = _quat_mul(q, _axis_quat((0, 1, 0), pitch))
    return _quat_mul(q, _axis_quat((1, 0, 0), roll))


def yaw_quat(yaw_deg: float) -> tuple[float, float, float, float]:
    """The (w, x, y, z) quaternion of a rotation by ``yaw_deg`` degrees about the world z axis."""
    return _axis_quat((0, 0, 1), yaw_deg)


def _is_identity(q: tuple[float, ...]) -> bool:
    return abs(q[0] - 1) < 1e-9 and all(abs(v) < 1e-9 for v in q[1:])


# ---------------------------------------------------------------------------------------------------------------
# materials shared by every object


def material_assets() -> list[El]:
    """The textures and materials object builders refer to (``eb_wood``, ``eb_metal`` ...), as MJCF elements."""
    els: list[El] = []

    def tex(name: str, **kw: object) -> None:
        els.append(El("texture", {"name": name, "type": "2d", **kw}))

    def mat(name: str, **kw: object) -> None:
        els.append(El("material", {"name": name, **kw}))

    tex("eb_tex_wood", builtin="checker", width=256, height=256, rgb1=(0.78, 0.78, 0.78), rgb2=(0.66, 0.66, 0.66),
        mark="random", random=0.04, markrgb=(0.55, 0.55, 0.55))
    tex("eb_tex_fabric", builtin="flat", width=128, height=128, rgb1=(0.92, 0.92, 0.92), mark="random",
        random=0.25, markrgb=(0.8, 0.8, 0.8))
    tex("eb_tex_stone", builtin="flat", width=256, height=256, rgb1=(0.95, 0.95, 0.95), mark="random",
        random=0.12, markrgb=(0.7, 0.7, 0.72))
    tex("eb_tex_wicker", builtin="checker", width=64, height=64, rgb1=(0.95, 0.95, 0.95), rgb2=(0.7, 0.7, 0.7))
    tex("eb_tex_peel", builtin="flat", width=64, height=64, rgb1=(1, 1, 1), mark="random", random=0.15,
        markrgb=(0.85, 0.85, 0.85))
    mat("eb_matte", specular=0.05, shininess=0.05)
    mat("eb_plastic", specular=0.35, shininess=0.45)
    mat("eb_glossy", specular=0.6, shininess=0.8)
    mat("eb_metal", specular=0.9, shininess=0.9, reflectance=0.0)
    mat("eb_glass", specular=1.0, shininess=1.0)
    mat("eb_rubber", specular=0.1, shininess=0.1)
    # half a checker period across and many along: wood-like stripes instead of a checkerboard
    mat("eb_wood", texture="eb_tex_wood", texrepeat=(0.5, 7), specular=0.2, shininess=0.3)
    mat("eb_fabric", texture="eb_tex_fabric", texrepeat=(6, 6), specular=0.02, shininess=0.02)
    mat("eb_stone", texture="eb_tex_stone", texrepeat=(3, 3), specular=0.4, shininess=0.6)
    mat("eb_wicker", texture="eb_tex_wicker", texrepeat=(16, 8), specular=0.1, shininess=0.1)
    mat("eb_peel", texture="eb_tex_peel", texrepeat=(4, 4), specular=0.45, shininess=0.5)
    mat("eb_screen", specular=0.8, shininess=0.9, emission=0.6)
    mat("eb_glow", specular=0.0, shininess=0.0, emission=1.0)
    return els


# ---------------------------------------------------------------------------------------------------------------
# building blocks


@lru_cache(maxsize=None)
def _mesh_text(key: str) -> tuple[str, str]:
    """The MJCF ``vertex`` and ``face`` text of a generated mesh, written once per process (a scene with a dozen
    meshes spent ~30 ms of every build formatting the same numbers again)."""
    v, f = _mesh(key)
    return " ".join(fmt(x) for x in v.ravel()), " ".join(str(int(i)) for i in f.ravel())


@dataclass
class _Ctx:
    inst: str
    scale: float
    assets: dict[str, El]
    names: set[str] = field(default_factory=set)
    open_fracs: Mapping[str, float] = field(default_factory=dict)
    shape: str | None = None
    stretch: tuple[float, float, float] = (1.0, 1.0, 1.0)
    """Per-axis factor of the instance's shape variant (on top of the uniform ``scale``)."""

    def unique(self, part: str) -> str:
        base = f"{self.inst}/{part}"
        name, k = base, 1
        while name in self.names:
            k += 1
            name = f"{base}_{k}"
        self.names.add(name)
        return name


class GeomOptions(TypedDict, total=False):
    """Options of :meth:`Parts.geom` that its shortcuts (``box``, ``cyl`` ...) pass through."""

    rot: tuple[float, float, float] | None
    xyaxes: tuple[float, ...] | None
    collide: bool


class Parts:
    """Writes the geoms and child bodies of one object instance: the first argument of every builder.

    A builder (``def build(p: Parts, c: RGB) -> None``) draws its object at scale 1 with the base centre at the
    origin and the front towards +x; :meth:`ObjectType.build` creates the ``Parts`` and applies the instance's
    scale and name prefix. Each method takes a part name (unique names are made for repeats: ``leg``, ``leg_2``
    ...), lengths in metres at scale 1, an ``rgba`` (or RGB) colour and a material from
    :func:`material_assets` (``eb_plastic``, ``eb_wood``, ``eb_metal``, ``eb_glass``, ``eb_fabric`` ...);
    ``collide=False`` makes a decoration that never takes part in contacts. :meth:`hinge` and :meth:`slide`
    return the writer of a moving child body (a door, a drawer) whose joint is ``"<instance>/<part>"``.
    """

    def __init__(self, ctx: _Ctx, el: El) -> None:
        self.ctx = ctx
        self.el = el

    @property
    def shape(self) -> str | None:
        """The shape variant being built (see :attr:`ObjectType.shapes`), or None for the default look."""
        return self.ctx.shape

    def _s(self, v: tuple[float, ...]) -> tuple[float, ...]:
        s = self.ctx.scale
        return tuple(x * s for x in v)

    def _p(self, v: tuple[float, ...]) -> tuple[float, ...]:
        """A position (or a list of points) scaled and stretched per axis."""
        st = self.ctx.stretch
        s = self.ctx.scale
        return tuple(x * s * st[i % 3] for i, x in enumerate(v))

    def _size(self, gtype: str, size: tuple[float, ...]) -> tuple[str, tuple[float, ...]]:
        """Geom type and size after the shape stretch (a stretched sphere becomes an ellipsoid)."""
        sx, sy, sz = self.ctx.stretch
        s = self.ctx.scale
        if (sx, sy, sz) == (1.0, 1.0, 1.0):
            return gtype, self._s(size)
        sxy = math.sqrt(sx * sy)
        if gtype == "sphere":
            r = size[0] * s
            return "ellipsoid", (r * sx, r * sy, r * sz)
        if gtype in ("box", "ellipsoid") and len(size) == 3:
            return gtype, (size[0] * s * sx, size[1] * s * sy, size[2] * s * sz)
        if gtype in ("cylinder", "capsule") and len(size) == 2:
            return gtype, (size[0] * s * sxy, size[1] * s * sz)
        return gtype, tuple(x * s * sxy for x in size)

    def geom(self, part: str, gtype: str, *, size: tuple[float, ...] | None = None,
             pos: tuple[float, float, float] = (0, 0, 0), rgba: tuple[float, ...] = _WHITE, mat: str = "eb_plastic",
             rot: tuple[float, float, float] | None = None, xyaxes: tuple[float, ...] | None = None,
             fromto: tuple[float, ...] | None = None, mesh: str | None = None, collide: bool = True) -> El:
        """Add one geom; ``rot`` = (roll, pitch, yaw) in degrees applied as Rz·Ry·Rx."""
        attrs: dict[str, object] = {"name": self.ctx.unique(part), "type": gtype}
        if mesh is not None:
            attrs["mesh"] = mesh
        if fromto is not None:
            attrs["fromto"] = self._p(fromto)
            sxy = math.sqrt(self.ctx.stretch[0] * self.ctx.stretch[1])
            attrs["size"] = tuple(x * sxy for x in self._s(size or (0.01,)))
        else:
            if size is not None:
                attrs["type"], attrs["size"] = self._size(gtype, size)
            if any(abs(p) > 1e-12 for p in pos):
                attrs["pos"] = self._p(pos)
        if rot is not None:
            q = _rpy_quat(*rot)
            if not _is_identity(q):
                attrs["quat"] = q
        if xyaxes is not None:
            attrs["xyaxes"] = xyaxes
        attrs["material"] = mat
        attrs["rgba"] = _rgba(rgba)
        if not collide:
            attrs["contype"] = 0
            attrs["conaffinity"] = 0
        el = El("geom", attrs)
        self.el.append(el)
        return el

    def box(self, part: str, half: tuple[float, float, float], pos: tuple[float, float, float],
            rgba: tuple[float, ...], mat: str = "eb_plastic", **kw: Unpack[GeomOptions]) -> El:
        return self.geom(part, "box", size=half, pos=pos, rgba=rgba, mat=mat, **kw)

    def cyl(self, part: str, r: float, hh: float, pos: tuple[float, float, float], rgba: tuple[float, ...],
            mat: str = "eb_plastic", **kw: Unpack[GeomOptions]) -> El:
        return self.geom(part, "cylinder", size=(r, hh), pos=pos, rgba=rgba, mat=mat, **kw)

    def sph(self, part: str, r: float, pos: tuple[float, float, float], rgba: tuple[float, ...],
            mat: str = "eb_plastic", **kw: Unpack[GeomOptions]) -> El:
        return self.geom(part, "sphere", size=(r,), pos=pos, rgba=rgba, mat=mat, **kw)

    def ell(self, part: str, radii: tuple[float, float, float], pos: tuple[float, float, float],
            rgba: tuple[float, ...], mat: str = "eb_plastic", **kw: Unpack[GeomOptions]) -> El:
        return self.geom(part, "ellipsoid", size=radii, pos=pos, rgba=rgba, mat=mat, **kw)

    def cap_ft(self, part: str, p0: tuple[float, float, float], p1: tuple[float, float, float], r: float,
               rgba: tuple[float, ...], mat: str = "eb_plastic", **kw: Unpack[GeomOptions]) -> El:
        return self.geom(part, "capsule", fromto=(*p0, *p1), size=(r,), rgba=rgba, mat=mat, **kw)

    def cyl_ft(self, part: str, p0: tuple[float, float, float], p1: tuple[float, float, float], r: float,
               rgba: tuple[float, ...], mat: str = "eb_plastic", **kw: Unpack[GeomOptions]) -> El:
        return self.geom(part, "cylinder", fromto=(*p0, *p1), size=(r,), rgba=rgba, mat=mat, **kw)

    def mesh(self, part: str, key: str, pos: tuple[float, float, float], rgba: tuple[float, ...],
             mat: str = "eb_plastic", stretch: tuple[float, float, float] = (1.0, 1.0, 1.0),
             **kw: Unpack[GeomOptions]) -> El:
        """Add a generated mesh (see ``_meshes.MESHES``); ``stretch`` scales it per axis."""
        s = self.ctx.scale
        st = self.ctx.stretch
        sc = (stretch[0] * s * st[0], stretch[1] * s * st[1], stretch[2] * s * st[2])
        name = f"eb_{key}" if sc == (1.0, 1.0, 1.0) else f"eb_{key}__{'_'.join(fmt(v) for v in sc)}"
        if name not in self.ctx.assets:
            vertex, face = _mesh_text(key)
            attrs: dict[str, object] = {"name": name, "vertex": vertex, "face": face, "inertia": "shell"}
            if sc != (1.0, 1.0, 1.0):
                attrs["scale"] = sc
            self.ctx.assets[name] = El("mesh", attrs)
        return self.geom(part, "mesh", mesh=name, pos=pos, rgba=rgba, mat=mat, **kw)

    def body(self, part: str, pos: tuple[float, float, float], rot: tuple[float, float, float] | None = None) -> Parts:
        """A static child body (for grouping); returns its writer."""
        attrs: dict[str, object] = {"name": self.ctx.unique(part), "pos": self._p(pos)}
        if rot is not None:
            attrs["quat"] = _rpy_quat(*rot)
        return Parts(self.ctx, self.el.add("body", **attrs))

    def hinge(self, part: str, pos: tuple[float, float, float], axis: tuple[float, float, float],
              max_deg: float) -> Parts:
        """An openable child body turning about ``axis`` through ``pos``; build its geoms in the closed pose."""
        frac = float(self.ctx.open_fracs.get(part, 0.0))
        ref = frac * max_deg
        attrs: dict[str, object] = {"name": self.ctx.unique(part), "pos": self._p(pos)}
        q = _axis_quat(axis, ref)
        if not _is_identity(q):
            attrs["quat"] = q
        body = self.el.add("body", **attrs)
        body.add("joint", name=f"{self.ctx.inst}/{part}", type="hinge", axis=axis, range=(0, max_deg), ref=ref,
                 damping=1.0, frictionloss=0.5, armature=0.01)
        return Parts(self.ctx, body)

    def slide(self, part: str, pos: tuple[float, float, float], axis: tuple[float, float, float],
              travel: float) -> Parts:
        """An openable child body sliding ``travel`` metres along ``axis``; build its geoms closed."""
        frac = float(self.ctx.open_fracs.get(part, 0.0))
        t = travel * self.ctx.scale
        ref = frac * t
        p = self._p(pos)
        n = math.sqrt(sum(a * a for a in axis))
        p = tuple(p[i] + axis[i] / n * ref for i in range(3))
        body = self.el.add("body", name=self.ctx.unique(part), pos=p)
        body.add("joint", name=f"{self.ctx.inst}/{part}", type="slide", axis=axis, range=(0, t), ref=ref,
                 damping=5.0, frictionloss=0.5, armature=0.01)
        return Parts(self.ctx, body)

    def light(self, part: str, pos: tuple[float, float, float], direction: tuple[float, float, float] = (0, 0, -1),
              diffuse: tuple[float, float, float] = (0.5, 0.45, 0.35), cutoff: float = 70.0,
              active: bool = True) -> None:
        """A (shadowless) spotlight, e.g. a lamp bulb; toggled with :func:`set_powered`."""
        self.el.add("light", name=self.ctx.unique(part), pos=self._p(pos), dir=direction, diffuse=diffuse,
                    specular=(0.1, 0.1, 0.1), cutoff=cutoff, exponent=2, attenuation=(1, 0.3, 0.1),
                    castshadow=False, active=active)


# ---------------------------------------------------------------------------------------------------------------
# the catalogue types


@dataclass(frozen=True)
class Surface:
    """A place other objects can be put on (``inside=False``) or in (``inside=True``), in the object's frame."""

    name: str
    """Name used to select it, e.g. ``"top"``, ``"interior"``, ``"shelf_1"``."""
    z: float
    """Height of the support plane above the object's base, at scale 1 (metres)."""
    half_extents: tuple[float, float]
    """Usable half size along local x and y, at scale 1."""
    center: tuple[float, float] = (0.0, 0.0)
    """Centre of the usable area in local x, y."""
    inside: bool = False
    """True for interiors (fridge, drawer, bowl): objects there are 'in' the receptacle."""
    clearance: float | None = None
    """Maximum height of an object that fits (None: unlimited)."""
    part: str | None = None
    """The drawer (a slide articulation) that carries this surface, or None for a fixed one. The surface is given
    in the closed pose and moves with the drawer: :func:`surface_position` gives where it is now."""


Builder = Callable[[Parts, RGB], None]
"""Draws one object: ``builder(parts, rgb)`` with the instance's colour (see :class:`Parts`)."""


class BuildOptions(TypedDict, total=False):
    """Options of :meth:`ObjectType.build` that :meth:`ObjectType.mjcf` passes through."""

    movable: bool | None
    open: Mapping[str, float] | float | None
    assets: dict[str, El] | None
    shape: str | None


@dataclass(frozen=True)
class ObjectType:
    """One kind of household object and how to build it."""

    name: str
    """Canonical AI2-THOR style name, e.g. ``"Fridge"``, ``"Apple"``, ``"Mug"``."""
    category: Category
    colors: Mapping[str, RGB]
    """Named colour variants; the first is the default."""
    half_extents: tuple[float, float]
    """Approximate footprint half size along local x (depth, front = +x) and y (width) at scale 1 (metres)."""
    height: float
    """Approximate height at scale 1 (metres)."""
    builder: Builder = field(repr=False, compare=False)
    mount: Mount = "surface"
    """Where the object normally stands: on the floor, on another object's surface, or on a wall."""
    surfaces: tuple[Surface, ...] = ()
    movable: bool = False
    """Small pickable object: gets a free joint so worlds can move it without recompiling."""
    articulations: tuple[str, ...] = ()
    """Part names of openable doors/drawers/lids; each is a joint ``"<instance>/<part>"``."""
    default_open: Mapping[str, float] = field(default_factory=dict)
    """Initial open fraction per articulation when the caller gives none (e.g. a laptop starts open)."""
    toggleable: bool = False
    """Has an on/off state shown by :func:`set_powered` (lamps, TV, stove, microwave ...)."""
    shapes: Mapping[str, tuple[float, float, float]] = field(default_factory=dict)
    """Named shape variants (``"tall"``, ``"thin"``, ``"square"`` ...) -> per-axis stretch (x, y, z) of the whole
    object; a builder may also draw a variant differently (it reads :attr:`Parts.shape`)."""

    def shape_stretch(self, shape: str | None) -> tuple[float, float, float]:
        """The per-axis stretch of a shape variant (None: the default look)."""
        if shape is None:
            return (1.0, 1.0, 1.0)
        if shape not in self.shapes:
            allowed = ", ".join(self.shapes) or "none"
            raise ValueError(f"{self.name} has no shape {shape!r}; available: {allowed}")
        x, y, z = self.shapes[shape]
        return (float(x), float(y), float(z))

    @property
    def default_color(self) -> str:
        return next(iter(self.colors))

    @property
    def receptacle(self) -> bool:
        """True if other objects can be placed on or in it."""
        return bool(self.surfaces)

    @property
    def openable(self) -> bool:
        return bool(self.articulations)

    def surface(self, name: str | None = None) -> Surface:
        """The named support surface (default: the first one)."""
        if not self.surfaces:
            raise ValueError(f"{self.name} is not a receptacle (it has no support surface)")
        if name is None:
            return self.surfaces[0]
        for s in self.surfaces:
            if s.name == name:
                return s
        raise ValueError(f"{self.name} has no surface {name!r}; available: {[s.name for s in self.surfaces]}")

    def color_rgb(self, color: str | tuple[float, ...] | None) -> tuple[str, RGB]:
        """Resolve a variant name (or an explicit RGB triple) to (name, rgb)."""
        if color is None:
            color = self.default_color
        if isinstance(color, str):
            if color in self.colors:
                return color, self.colors[color]
            raise ValueError(f"{self.name} has no colour {color!r}; available: {sorted(self.colors)}")
        rgb = tuple(float(c) for c in color)
        if len(rgb) != 3:
            raise ValueError(f"an explicit colour must be an (r, g, b) triple, got {color!r}")
        return "custom", (rgb[0], rgb[1], rgb[2])

    def build(self, instance: str, pos: tuple[float, float, float] = (0.0, 0.0, 0.0), yaw: float = 0.0,
              color: str | tuple[float, ...] | None = None, scale: float = 1.0, movable: bool | None = None,
              open: Mapping[str, float] | float | None = None,
              assets: dict[str, El] | None = None, shape: str | None = None) -> tuple[El, dict[str, El]]:
        """Write the MJCF ``<body name=instance>`` subtree of one instance.

        Args:
            instance: unique instance name (no ``/``), used as prefix of every part name.
            pos: world position of the base centre.
            yaw: rotation about z in degrees (front = local +x).
            color: a variant name from :attr:`colors` or an (r, g, b) triple; None = default.
            scale: uniform size factor.
            movable: add a free joint (default: :attr:`movable`).
            open: initial open fraction for all articulations (float) or per part (mapping).
            assets: asset dict to add meshes to (shared across a scene); a new one if None.
            shape: a shape variant from :attr:`shapes` (None = the default look).

        Returns:
            The body element and the asset dict (mesh assets this body needs, plus whatever was passed in).
        """
        if "/" in instance or not instance:
            raise ValueError(f"instance names must be non-empty and contain no '/': {instance!r}")
        _, rgb = self.color_rgb(color)
        fracs: dict[str, float] = dict(self.default_open)
        if isinstance(open, (int, float)):
            fracs = {a: float(open) for a in self.articulations}
        elif open is not None:
            unknown = set(open) - set(self.articulations)
            if unknown:
                raise ValueError(f"{self.name} has no openable part {sorted(unknown)}; has {self.articulations}")
            fracs.update({k: float(v) for k, v in open.items()})
        fracs = {k: min(max(v, 0.0), 1.0) for k, v in fracs.items()}
        assets = {} if assets is None else assets
        stretch = self.shape_stretch(shape)
        ctx = _Ctx(instance, float(scale), assets, open_fracs=fracs, shape=shape, stretch=stretch)
        attrs: dict[str, object] = {"name": instance, "pos": tuple(pos)}
        q = yaw_quat(yaw)
        if not _is_identity(q):
            attrs["quat"] = q
        body = El("body", attrs)
        if self.movable if movable is None else movable:
            body.add("freejoint", name=f"{instance}/free")
        self.builder(Parts(ctx, body), rgb)
        return body, assets

    def mjcf(self, instance: str, pos: tuple[float, float, float] = (0.0, 0.0, 0.0), yaw: float = 0.0,
             color: str | tuple[float, ...] | None = None, scale: float = 1.0,
             **kw: Unpack[BuildOptions]) -> tuple[str, str]:
        """Like :meth:`build`, as text: ``(body_xml, assets_xml)``; the assets (meshes) go in ``<asset>``, and the
        shared materials from :func:`material_assets` must be there too."""
        body, assets = self.build(instance, pos, yaw, color, scale, **kw)
        return body.to_string(), "\n".join(a.to_string() for a in assets.values())


CATALOGUE: dict[str, ObjectType] = {}
"""Every object type by canonical name, in catalogue order."""


class _TypeOptions(TypedDict, total=False):
    """The optional fields of :class:`ObjectType`, as the catalogue's ``@_register`` lines give them."""

    mount: Mount
    surfaces: tuple[Surface, ...]
    movable: bool
    articulations: tuple[str, ...]
    default_open: Mapping[str, float]
    toggleable: bool
    shapes: Mapping[str, tuple[float, float, float]]


def _register(name: str, category: Category, colors: tuple[str, ...], half: tuple[float, float], height: float,
              **kw: Unpack[_TypeOptions]) -> Callable[[Builder], Builder]:
    def deco(fn: Builder) -> Builder:
        if name in CATALOGUE:
            raise ValueError(f"duplicate object type {name}")
        CATALOGUE[name] = ObjectType(name=name, category=category, colors={c: COLORS[c] for c in colors},
                                     half_extents=half, height=height, builder=fn, **kw)
        return fn

    return deco


def object_types(category: Category | None = None) -> list[ObjectType]:
    """All object types (optionally of one category), in catalogue order."""
    return [t for t in CATALOGUE.values() if category is None or t.category == category]


def get_type(name: str) -> ObjectType:
    """Look up an object type by its canonical name; an unknown name lists the available ones."""
    try:
        return CATALOGUE[name]
    except KeyError:
        raise KeyError(f"unknown object type {name!r}; available: {', '.join(CATALOGUE)}") from None


# ---------------------------------------------------------------------------------------------------------------
# changing a compiled scene without recompiling


def _mj() -> ModuleType:
    from eb_scenekit._mujoco import mujoco

    return mujoco


def articulated_joints(model: MjModel, instance: str) -> list[str]:
    """Names of the hinge/slide joints (doors, drawers, lids) of one instance, e.g. ``["Fridge_1/door"]``."""
    mujoco = _mj()
    out = []
    for j in range(model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or ""
        if name.startswith(instance + "/") and model.jnt_type[j] in (mujoco.mjtJoint.mjJNT_HINGE,
                                                                     mujoco.mjtJoint.mjJNT_SLIDE):
            out.append(name)
    return out


def _joints_for(model: MjModel, instance: str, part: str | None) -> list[int]:
    mujoco = _mj()
    names = articulated_joints(model, instance)
    if part is not None:
        names = [n for n in names if n == f"{instance}/{part}"]
    if not names:
        raise KeyError(f"{instance!r} has no openable part{'' if part is None else ' ' + repr(part)}; "
                       f"joints: {articulated_joints(model, instance)}")
    return [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names]


def set_open(model: MjModel, data: MjData, instance_name: str, fraction: float, part: str | None = None) -> list[str]:
    """Open (1.0), close (0.0) or half-open the doors/drawers/lids of an instance, then ``mj_forward``.

    Args:
        part: only this articulation (e.g. ``"door"``, ``"drawer_1"``); default: all of them.

    Returns:
        The joint names that were set.
    """
    mujoco = _mj()
    f = min(max(float(fraction), 0.0), 1.0)
    names = []
    for j in _joints_for(model, instance_name, part):
        lo, hi = model.jnt_range[j]
        data.qpos[model.jnt_qposadr[j]] = lo + f * (hi - lo)
        data.qvel[model.jnt_dofadr[j]] = 0.0
        names.append(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j))
    mujoco.mj_forward(model, data)
    return names


def get_open(model: MjModel, data: MjData, instance_name: str, part: str | None = None) -> float:
    """Open fraction (0..1) of an articulation, or the largest one over all parts of the instance."""
    fr = []
    for j in _joints_for(model, instance_name, part):
        lo, hi = model.jnt_range[j]
        fr.append(float((data.qpos[model.jnt_qposadr[j]] - lo) / (hi - lo)))
    return max(fr)


def surface_position(model: MjModel, data: MjData, instance_name: str, surface: Surface, scale: float = 1.0,
                     offset: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """World (x, y, z) of a point of a support surface in the current state of the model.

    The point is the surface centre moved by ``offset`` (local x, y of the object, metres at scale 1), at the
    surface height; ``scale`` is the instance's scale. A surface carried by a drawer (:attr:`Surface.part`)
    follows the drawer's joint, so things put "in the drawer" come out with it when it opens.
    """
    mujoco = _mj()
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, instance_name)
    if b < 0:
        raise KeyError(f"no instance {instance_name!r} in the model")
    local = np.array([surface.center[0] + offset[0], surface.center[1] + offset[1], surface.z]) * scale
    pos = data.xpos[b] + data.xmat[b].reshape(3, 3) @ local
    if surface.part is not None:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{instance_name}/{surface.part}")
        if j < 0 or model.jnt_type[j] != mujoco.mjtJoint.mjJNT_SLIDE:
            raise KeyError(f"{instance_name!r} has no drawer {surface.part!r} carrying surface {surface.name!r}")
        pos = pos + data.qpos[model.jnt_qposadr[j]] * data.xaxis[j]
    return pos


def set_object_pose(model: MjModel, data: MjData, instance_name: str, pos: tuple[float, float, float],
                    yaw: float = 0.0) -> None:
    """Teleport a movable instance (one with a free joint) to a world position and yaw (degrees)."""
    mujoco = _mj()
    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{instance_name}/free")
    if j < 0:
        raise KeyError(f"{instance_name!r} is not movable (no free joint {instance_name}/free)")
    adr = model.jnt_qposadr[j]
    data.qpos[adr:adr + 3] = pos
    data.qpos[adr + 3:adr + 7] = yaw_quat(yaw)
    dof = model.jnt_dofadr[j]
    data.qvel[dof:dof + 6] = 0.0
    mujoco.mj_forward(model, data)


_POWER_CACHE: dict[int, dict[int, tuple[np.ndarray, int]]] = {}
_HEAT_ON = (1.0, 0.3, 0.05, 1.0)
_STREAM_ON = (0.6, 0.8, 1.0, 0.6)
_OFF = (0.07, 0.07, 0.08)


def set_powered(model: MjModel, instance_name: str, on: bool) -> None:
    """Switch an appliance's visible power state without recompiling (the next render shows it).

    * screens, displays and lamp bulbs are lit when on and dark when off; lamp lights are (de)activated;
    * heating parts (stove burners, toaster slots) glow orange when on;
    * a sink's faucet shows a water stream when on.

    Objects are built with screens and lamps on, heaters off and faucets off.
    """
    mujoco = _mj()
    glow_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, n) for n in ("eb_glow", "eb_screen")]
    glow = set(glow_ids)
    glossy = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, "eb_glossy")
    cache = _POWER_CACHE.setdefault(id(model), {})
    found = False
    prefix = instance_name + "/"
    for g in range(model.ngeom):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
        if not name.startswith(prefix):
            continue
        part = name[len(prefix):]
        heat = part.startswith(("burner", "slot"))
        stream = part.startswith("stream")
        if g not in cache and (model.geom_matid[g] in glow or heat or stream):
            cache[g] = (model.geom_rgba[g].copy(), int(model.geom_matid[g]))
        if g not in cache:
            continue
        found = True
        rgba, mat = cache[g]
        if heat:
            model.geom_rgba[g] = _HEAT_ON if on else rgba
            model.geom_matid[g] = glow_ids[0] if on else mat
        elif stream:
            model.geom_rgba[g] = _STREAM_ON if on else rgba
        else:
            model.geom_rgba[g] = rgba if on else (*_OFF, rgba[3])
            model.geom_matid[g] = mat if on else glossy
    for li in range(model.nlight):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_LIGHT, li) or ""
        if name.startswith(prefix):
            model.light_active[li] = 1 if on else 0
            found = True
    if not found:
        raise KeyError(f"{instance_name!r} has nothing to switch on or off")

