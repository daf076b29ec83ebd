"""The furniture and objects the rooms are made of, built from MuJoCo primitives.

Every object type is a function ``(colour, rng) -> list[Part]`` in the object's local frame: the
footprint is centred on the origin, the floor is ``z = 0`` and the object's front faces local ``+y``.
:mod:`eb_navigation.layout` places objects (position + a yaw in quarter turns) and
:mod:`eb_navigation.mjcf` turns the parts into geoms. This module is pure Python (no MuJoCo).

Target types carry several colour variants so the visual-appearance subset can name an object by
colour and shape alone while same-type objects of other colours stand in the room.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["COLOURS", "CATALOGUE", "ObjectType", "Part", "TARGET_TYPES", "colour_rgba", "get_type"]

RGBA = tuple[float, float, float, float]

#: Named colours (the names are used in instructions, so they must be what a person would say).
COLOURS: dict[str, tuple[float, float, float]] = {
    "red": (0.78, 0.12, 0.12),
    "orange": (0.93, 0.45, 0.10),
    "yellow": (0.95, 0.80, 0.15),
    "green": (0.20, 0.58, 0.25),
    "teal": (0.10, 0.55, 0.55),
    "blue": (0.15, 0.32, 0.78),
    "navy": (0.10, 0.14, 0.38),
    "purple": (0.50, 0.22, 0.62),
    "pink": (0.95, 0.55, 0.70),
    "white": (0.93, 0.93, 0.92),
    "cream": (0.93, 0.88, 0.74),
    "beige": (0.82, 0.74, 0.58),
    "grey": (0.50, 0.50, 0.52),
    "silver": (0.74, 0.76, 0.78),
    "black": (0.09, 0.09, 0.10),
    "brown": (0.45, 0.28, 0.14),
}


def colour_rgba(name: str, alpha: float = 1.0) -> RGBA:
    r, g, b = COLOURS[name]
    return (r, g, b, alpha)


def _rgb(r: float, g: float, b: float) -> RGBA:
    return (r, g, b, 1.0)


def _shade(rgba: RGBA, k: float) -> RGBA:
    """Darken (k < 1) or lighten (k > 1) a colour."""
    if k <= 1.0:
        return (rgba[0] * k, rgba[1] * k, rgba[2] * k, rgba[3])
    t = k - 1.0
    return (rgba[0] + (1 - rgba[0]) * t, rgba[1] + (1 - rgba[1]) * t, rgba[2] + (1 - rgba[2]) * t, rgba[3])


WOOD = _rgb(0.55, 0.36, 0.20)
DARK_WOOD = _rgb(0.33, 0.20, 0.11)
LIGHT_WOOD = _rgb(0.76, 0.60, 0.40)
METAL = _rgb(0.70, 0.72, 0.75)
DARK = _rgb(0.12, 0.12, 0.13)
WHITE = _rgb(0.94, 0.94, 0.93)
GLASS = _rgb(0.10, 0.12, 0.14)
LEAF = _rgb(0.16, 0.50, 0.18)
LEAF2 = _rgb(0.26, 0.62, 0.22)
SOIL = _rgb(0.25, 0.16, 0.09)


@dataclass(frozen=True)
class Part:
    """One MuJoCo primitive in the object's local frame (sizes are MuJoCo's half sizes / radii)."""

    shape: str
    pos: tuple[float, float, float]
    size: tuple[float, ...]
    rgba: RGBA
    euler: tuple[float, float, float] | None = None
    """Rotation in degrees (MuJoCo ``xyz`` euler), if any."""
    material: str = "matte"
    """One of the materials :mod:`eb_navigation.mjcf` defines: matte, glossy, metal, screen, glow."""


def _box(x, y, z, hx, hy, hz, rgba, material="matte", euler=None) -> Part:
    return Part("box", (x, y, z), (hx, hy, hz), rgba, euler, material)


def _cyl(x, y, z, r, hz, rgba, material="matte", euler=None) -> Part:
    return Part("cylinder", (x, y, z), (r, hz), rgba, euler, material)


def _sph(x, y, z, r, rgba, material="matte") -> Part:
    return Part("sphere", (x, y, z), (r,), rgba, None, material)


def _ell(x, y, z, a, b, c, rgba, material="matte", euler=None) -> Part:
    return Part("ellipsoid", (x, y, z), (a, b, c), rgba, euler, material)


def _frustum(x, y, z, r_bottom, r_top, h, rgba, material="matte") -> Part:
    """A truncated cone from ``z`` to ``z + h`` (mjcf.py makes one convex mesh per distinct size)."""
    return Part("frustum", (x, y, z), (r_bottom, r_top, h), rgba, None, material)


@dataclass(frozen=True)
class ObjectType:
    """A kind of object: its footprint, how it stands in a room and how to build it."""

    name: str
    size: tuple[float, float, float]
    """Footprint width (local x), depth (local y) and height, metres."""
    build: Callable[[str, np.random.Generator], list[Part]]
    colours: tuple[str, ...]
    """Colour variants (the first is the default)."""
    obstacle: bool = True
    """Blocks the agent (floor furniture); False for rugs and things standing on other furniture."""
    surface: float | None = None
    """Height of the top a small object can stand on (tables, counters), if any."""
    shape_words: str = ""
    """How the object looks without naming it (used by the visual-appearance instructions)."""


# ----------------------------------------------------------------------------------------------------
# Builders. Front = +y. Keep geoms few: every geom costs render time at every step.


def _fridge(colour: str, rng: np.random.Generator) -> list[Part]:
    w, d, h = 0.76, 0.70, 1.82
    c = colour_rgba(colour)
    fy = d / 2
    handle = DARK if colour in ("white", "cream", "silver", "red") else METAL
    return [
        _box(0, 0, h / 2 + 0.03, w / 2, d / 2 - 0.02, h / 2 - 0.03, c, "glossy"),
        _box(0, fy - 0.02, 1.22, w / 2 + 0.002, 0.008, 0.008, _shade(c, 0.45)),  # freezer door gap
        _box(0, fy - 0.02, 0.045, w / 2 - 0.02, 0.01, 0.04, DARK),  # kick plate
        _cyl(w / 2 - 0.09, fy + 0.025, 1.45, 0.016, 0.16, handle, "metal"),
        _cyl(w / 2 - 0.09, fy + 0.025, 0.88, 0.016, 0.24, handle, "metal"),
    ]


def _microwave(colour: str, rng: np.random.Generator) -> list[Part]:
    w, d, h = 0.52, 0.38, 0.30
    c = colour_rgba(colour)
    fy = d / 2
    return [
        _box(0, 0, h / 2, w / 2, d / 2, h / 2, c, "glossy"),
        _box(-0.06, fy + 0.003, h / 2, 0.165, 0.004, 0.10, GLASS, "glossy"),
        _box(0.185, fy + 0.003, h / 2, 0.055, 0.004, 0.115, _shade(c, 0.6)),
        _box(0.185, fy + 0.008, h / 2 + 0.05, 0.035, 0.003, 0.018, _rgb(0.2, 0.7, 0.3), "glow"),
        _cyl(0.115, fy + 0.02, h / 2, 0.012, 0.09, METAL, "metal"),
    ]


def _stove(colour: str, rng: np.random.Generator) -> list[Part]:
    w, d, h = 0.62, 0.62, 0.90
    c = colour_rgba(colour)
    fy = d / 2
    parts = [
        _box(0, 0, h / 2, w / 2, d / 2, h / 2, c, "glossy"),
        _box(0, 0, h + 0.01, w / 2, d / 2, 0.01, DARK, "glossy"),
        _box(0, fy + 0.003, 0.42, 0.24, 0.004, 0.18, GLASS, "glossy"),
        _cyl(0, fy + 0.04, 0.66, 0.014, 0.22, METAL, "metal", euler=(0, 90, 0)),
        _box(0, -d / 2 + 0.04, h + 0.09, w / 2, 0.03, 0.08, _shade(c, 0.8)),
    ]
    for bx, by, r in ((-0.14, 0.12, 0.085), (0.14, 0.12, 0.065), (-0.14, -0.14, 0.065), (0.14, -0.14, 0.085)):
        parts.append(_cyl(bx, by, h + 0.025, r, 0.006, _rgb(0.25, 0.25, 0.26), "metal"))
    for kx in (-0.18, -0.06, 0.06, 0.18):
        parts.append(_cyl(kx, -d / 2 + 0.075, h + 0.12, 0.022, 0.01, METAL, "metal", euler=(90, 0, 0)))
    return parts


def _counter(width: float) -> Callable[[str, np.random.Generator], list[Part]]:
    def build(colour: str, rng: np.random.Generator) -> list[Part]:
        d, h = 0.62, 0.90
        c = colour_rgba(colour)
        top = _rgb(0.30, 0.30, 0.32) if colour in ("white", "cream") else _rgb(0.85, 0.84, 0.80)
        parts = [
            _box(0, -0.02, h / 2 - 0.02, width / 2, d / 2 - 0.02, h / 2 - 0.02, c),
            _box(0, 0, h - 0.02, width / 2 + 0.01, d / 2, 0.02, top, "glossy"),
        ]
        n = max(1, int(round(width / 0.5)))
        for k in range(n):
            x = -width / 2 + (k + 0.5) * width / n
            parts.append(_box(x + width / (2 * n) - 0.004, d / 2 - 0.035, h / 2 - 0.03, 0.004, 0.004, h / 2 - 0.08,
                              _shade(c, 0.55)))
            parts.append(_box(x, d / 2 - 0.02, h - 0.14, 0.06, 0.012, 0.008, METAL, "metal"))
        # wall cupboards above the counter
        parts.append(_box(0, -d / 2 + 0.18, 1.85, width / 2, 0.17, 0.33, c))
        for k in range(n):
            x = -width / 2 + (k + 0.5) * width / n
            parts.append(_box(x + width / (2 * n) - 0.004, -d / 2 + 0.355, 1.85, 0.004, 0.004, 0.31, _shade(c, 0.55)))
        return parts

    return build


def _sink_counter(colour: str, rng: np.random.Generator) -> list[Part]:
    parts = _counter(1.2)(colour, rng)
    parts += [
        _box(0.2, 0.02, 0.885, 0.24, 0.18, 0.01, _rgb(0.55, 0.57, 0.60), "metal"),
        _cyl(0.2, -0.2, 1.0, 0.015, 0.11, METAL, "metal"),
        _cyl(0.2, -0.13, 1.1, 0.013, 0.07, METAL, "metal", euler=(90, 0, 0)),
    ]
    return parts


def _table(w: float, d: float, h: float, top_rgba: RGBA | None = None, leg_r: float = 0.025) -> list[Part]:
    c = top_rgba or WOOD
    parts = [_box(0, 0, h - 0.02, w / 2, d / 2, 0.02, c, "glossy")]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(_cyl(sx * (w / 2 - 0.06), sy * (d / 2 - 0.06), (h - 0.04) / 2, leg_r, (h - 0.04) / 2,
                              _shade(c, 0.7)))
    return parts


def _dining_table(colour: str, rng: np.random.Generator) -> list[Part]:
    parts = _table(1.4, 0.85, 0.76, colour_rgba(colour) if colour != "brown" else WOOD)
    # a fruit bowl and two plates
    parts += [
        _cyl(0, 0, 0.79, 0.13, 0.035, WHITE, "glossy"),
        _sph(-0.04, 0.02, 0.85, 0.045, _rgb(0.85, 0.15, 0.10)),
        _sph(0.05, -0.03, 0.85, 0.045, _rgb(0.95, 0.75, 0.10)),
        _sph(0.02, 0.06, 0.85, 0.04, _rgb(0.4, 0.7, 0.15)),
        _cyl(-0.45, 0.22, 0.765, 0.11, 0.006, WHITE, "glossy"),
        _cyl(0.45, -0.22, 0.765, 0.11, 0.006, WHITE, "glossy"),
    ]
    return parts


def _chair(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour) if colour != "brown" else WOOD
    parts = [
        _box(0, 0, 0.45, 0.22, 0.21, 0.025, c),
        _box(0, -0.2, 0.72, 0.22, 0.02, 0.2, c),
    ]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(_cyl(sx * 0.19, sy * 0.18, 0.215, 0.018, 0.215, _shade(c, 0.7)))
    return parts


def _coffee_table(colour: str, rng: np.random.Generator) -> list[Part]:
    parts = _table(1.0, 0.55, 0.42, colour_rgba(colour) if colour != "brown" else DARK_WOOD)
    parts += [
        _box(0.25, 0.05, 0.435, 0.12, 0.09, 0.015, _rgb(0.7, 0.2, 0.2)),
        _box(0.25, 0.05, 0.46, 0.11, 0.08, 0.012, _rgb(0.2, 0.35, 0.6)),
        _cyl(-0.3, -0.1, 0.465, 0.04, 0.045, WHITE, "glossy"),
    ]
    return parts


def _sofa_like(width: float, colour: str, cushions: int) -> list[Part]:
    d, seat_h, back_h, arm_h = 0.90, 0.44, 0.86, 0.62
    c = colour_rgba(colour)
    base = _shade(c, 0.8)
    arm_w = 0.16
    inner = width - 2 * arm_w
    parts = [
        _box(0, 0.02, 0.06, width / 2 - 0.03, d / 2 - 0.05, 0.06, DARK),  # plinth
        _box(0, 0.05, 0.27, inner / 2, d / 2 - 0.05, 0.15, base),
        _box(0, -d / 2 + 0.12, (back_h + 0.12) / 2, width / 2, 0.12, (back_h - 0.12) / 2, c),
    ]
    for sx in (-1, 1):
        parts.append(_box(sx * (width / 2 - arm_w / 2), 0.0, (arm_h + 0.12) / 2, arm_w / 2, d / 2, (arm_h - 0.12) / 2, c))
    seat_d = d - 0.26
    for k in range(cushions):
        x = -inner / 2 + (k + 0.5) * inner / cushions
        parts.append(_box(x, 0.11, seat_h + 0.01, inner / (2 * cushions) - 0.012, seat_d / 2, 0.07, _shade(c, 1.08)))
    return parts


def _sofa(colour: str, rng: np.random.Generator) -> list[Part]:
    parts = _sofa_like(2.0, colour, 3)
    pillow = colour_rgba("cream") if colour not in ("cream", "white", "beige") else colour_rgba("teal")
    parts += [
        _box(-0.55, -0.22, 0.66, 0.18, 0.05, 0.16, pillow, euler=(-15, 0, 0)),
        _box(0.55, -0.22, 0.66, 0.18, 0.05, 0.16, pillow, euler=(-15, 0, 0)),
    ]
    return parts


def _armchair(colour: str, rng: np.random.Generator) -> list[Part]:
    return _sofa_like(0.92, colour, 1)


def _tv_stand(colour: str, rng: np.random.Generator) -> list[Part]:
    c = DARK_WOOD if colour == "brown" else colour_rgba(colour)
    w, d, h = 1.5, 0.45, 0.5
    return [
        _box(0, 0, h / 2 + 0.04, w / 2, d / 2, h / 2 - 0.04, c),
        _box(-w / 4, d / 2 + 0.002, h / 2 + 0.04, w / 4 - 0.02, 0.003, h / 2 - 0.08, _shade(c, 0.75)),
        _box(w / 4, d / 2 + 0.002, h / 2 + 0.04, w / 4 - 0.02, 0.003, h / 2 - 0.08, _shade(c, 0.75)),
        _box(0, 0, 0.02, w / 2 - 0.05, d / 2 - 0.05, 0.02, DARK),
    ]


def _tv(colour: str, rng: np.random.Generator) -> list[Part]:
    """A flat TV on a foot (stands on a TV stand); the screen shows a bright landscape picture."""
    frame = colour_rgba(colour)
    w, h, z0 = 1.24, 0.72, 0.12
    zc = z0 + h / 2
    return [
        _box(0, -0.02, 0.01, 0.25, 0.11, 0.01, DARK, "metal"),
        _box(0, -0.04, z0 / 2 + 0.01, 0.04, 0.02, z0 / 2, DARK, "metal"),
        _box(0, -0.04, zc, w / 2, 0.03, h / 2, frame, "glossy"),
        # the picture: sky, hills, a sun
        _box(0, -0.008, zc + 0.1, w / 2 - 0.035, 0.004, h / 2 - 0.135, _rgb(0.35, 0.62, 0.95), "screen"),
        _box(0, -0.008, zc - h / 2 + 0.12, w / 2 - 0.035, 0.004, 0.085, _rgb(0.25, 0.65, 0.25), "screen"),
        _cyl(0.3, -0.006, zc + 0.15, 0.06, 0.002, _rgb(1.0, 0.88, 0.3), "screen", euler=(90, 0, 0)),
    ]


def _bookshelf(colour: str, rng: np.random.Generator) -> list[Part]:
    c = WOOD if colour == "brown" else colour_rgba(colour)
    w, d, h = 0.9, 0.34, 1.85
    parts = [
        _box(0, -d / 2 + 0.01, h / 2, w / 2, 0.01, h / 2, _shade(c, 0.8)),
        _box(-w / 2 + 0.015, 0, h / 2, 0.015, d / 2, h / 2, c),
        _box(w / 2 - 0.015, 0, h / 2, 0.015, d / 2, h / 2, c),
    ]
    shelves = [0.04, 0.47, 0.9, 1.33, 1.83]
    for z in shelves:
        parts.append(_box(0, 0, z, w / 2 - 0.03, d / 2, 0.015, c))
    book_cols = [_rgb(0.7, 0.15, 0.15), _rgb(0.15, 0.3, 0.65), _rgb(0.2, 0.5, 0.25), _rgb(0.85, 0.7, 0.2),
                 _rgb(0.9, 0.9, 0.85), _rgb(0.4, 0.2, 0.45)]
    for z in shelves[:-1]:
        x = -w / 2 + 0.05
        while True:
            bw = float(rng.uniform(0.12, 0.26))
            if x + bw > w / 2 - 0.05:
                break
            bh = float(rng.uniform(0.22, 0.34))
            parts.append(_box(x + bw / 2, 0.01, z + 0.015 + bh / 2, bw / 2 - 0.004, d / 2 - 0.05, bh / 2,
                              book_cols[int(rng.integers(len(book_cols)))]))
            x += bw + float(rng.uniform(0.0, 0.08))
    return parts


def _floor_lamp(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    return [
        _cyl(0, 0, 0.015, 0.16, 0.015, DARK, "metal"),
        _cyl(0, 0, 0.76, 0.016, 0.74, DARK, "metal"),
        _frustum(0, 0, 1.38, 0.24, 0.13, 0.32, c, "glow"),
        _sph(0, 0, 1.45, 0.05, _rgb(1.0, 0.95, 0.75), "glow"),
    ]


def _table_lamp(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    return [
        _cyl(0, 0, 0.1, 0.06, 0.1, _shade(c, 0.7), "glossy"),
        _frustum(0, 0, 0.2, 0.13, 0.08, 0.17, c, "glow"),
    ]


def _plant(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    parts = [
        _frustum(0, 0, 0.0, 0.14, 0.2, 0.34, c, "glossy"),
        _cyl(0, 0, 0.33, 0.185, 0.012, SOIL),
        _cyl(0, 0, 0.55, 0.018, 0.22, _rgb(0.35, 0.25, 0.12)),
    ]
    n = 9
    for k in range(n):
        ang = 2 * math.pi * k / n + float(rng.uniform(-0.2, 0.2))
        r = float(rng.uniform(0.1, 0.2))
        z = float(rng.uniform(0.68, 1.02))
        tilt = float(rng.uniform(25, 55))
        col = LEAF if k % 2 else LEAF2
        parts.append(_ell(r * math.cos(ang), r * math.sin(ang), z, 0.16, 0.06, 0.018, col,
                          euler=(0, -tilt, math.degrees(ang))))
    parts.append(_ell(0, 0, 1.1, 0.12, 0.12, 0.16, LEAF2))
    return parts


def _ball(colour: str, rng: np.random.Generator) -> list[Part]:
    r = 0.18
    c = colour_rgba(colour)
    seam = DARK if colour not in ("black", "navy") else WHITE
    return [
        _sph(0, 0, r, r, c),
        _cyl(0, 0, r, r + 0.002, 0.003, seam, euler=(0, 0, 0)),
        _cyl(0, 0, r, r + 0.002, 0.003, seam, euler=(90, 0, 0)),
        _cyl(0, 0, r, r + 0.002, 0.003, seam, euler=(0, 90, 0)),
    ]


def _teddy(colour: str, rng: np.random.Generator) -> list[Part]:
    """A big seated teddy bear (about 0.65 m tall) facing +y."""
    c = colour_rgba(colour)
    light = _shade(c, 1.45)
    s = 1.35
    parts = [
        _ell(0, 0, 0.22 * s, 0.15 * s, 0.13 * s, 0.18 * s, c),  # body
        _ell(0, 0.07 * s, 0.2 * s, 0.1 * s, 0.07 * s, 0.12 * s, light),  # belly
        _sph(0, 0.01 * s, 0.45 * s, 0.115 * s, c),  # head
        _sph(0.085 * s, 0.0, 0.54 * s, 0.045 * s, c),
        _sph(-0.085 * s, 0.0, 0.54 * s, 0.045 * s, c),
        _sph(0, 0.1 * s, 0.425 * s, 0.05 * s, light),  # muzzle
        _sph(0, 0.145 * s, 0.44 * s, 0.018 * s, DARK, "glossy"),  # nose
        _sph(0.045 * s, 0.1 * s, 0.49 * s, 0.016 * s, DARK, "glossy"),
        _sph(-0.045 * s, 0.1 * s, 0.49 * s, 0.016 * s, DARK, "glossy"),
        _ell(0.15 * s, 0.04 * s, 0.27 * s, 0.05 * s, 0.05 * s, 0.11 * s, c, euler=(-25, -20, 0)),
        _ell(-0.15 * s, 0.04 * s, 0.27 * s, 0.05 * s, 0.05 * s, 0.11 * s, c, euler=(-25, 20, 0)),
        _ell(0.08 * s, 0.13 * s, 0.07 * s, 0.06 * s, 0.12 * s, 0.06 * s, c),
        _ell(-0.08 * s, 0.13 * s, 0.07 * s, 0.06 * s, 0.12 * s, 0.06 * s, c),
        _ell(0.08 * s, 0.245 * s, 0.07 * s, 0.045 * s, 0.01 * s, 0.045 * s, light),
        _ell(-0.08 * s, 0.245 * s, 0.07 * s, 0.045 * s, 0.01 * s, 0.045 * s, light),
    ]
    return parts


def _laptop(colour: str, rng: np.random.Generator) -> list[Part]:
    """An open laptop (stands on a desk or table); the lid shows a bright screen."""
    c = colour_rgba(colour)
    w, d = 0.40, 0.28
    lid_h = 0.27
    ang = 18.0  # lid leans back by this much
    cz = 0.02 + lid_h / 2 * math.cos(math.radians(ang))
    cy = -d / 2 - lid_h / 2 * math.sin(math.radians(ang))
    return [
        _box(0, 0, 0.01, w / 2, d / 2, 0.01, c, "metal"),
        _box(0, 0.02, 0.021, w / 2 - 0.025, d / 2 - 0.06, 0.002, DARK),
        _box(0, cy, cz, w / 2, 0.008, lid_h / 2, c, "metal", euler=(-ang, 0, 0)),
        _box(0, cy + 0.0095 * math.cos(math.radians(ang)), cz + 0.0095 * math.sin(math.radians(ang)),
             w / 2 - 0.02, 0.002, lid_h / 2 - 0.02, _rgb(0.3, 0.55, 0.95), "screen", euler=(-ang, 0, 0)),
    ]


def _bed(colour: str, rng: np.random.Generator) -> list[Part]:
    w, d = 1.5, 2.1
    c = colour_rgba(colour)
    frame = WOOD
    return [
        _box(0, 0, 0.17, w / 2, d / 2, 0.17, frame),
        _box(0, 0.02, 0.42, w / 2 - 0.04, d / 2 - 0.04, 0.09, WHITE),
        _box(0, 0.22, 0.47, w / 2 - 0.01, d / 2 - 0.24, 0.06, c),  # blanket
        _box(0, 0.22 + d / 2 - 0.24, 0.3, w / 2 - 0.01, 0.01, 0.2, c),  # blanket over the foot end
        _box(0, -d / 2 + 0.05, 0.6, w / 2, 0.05, 0.6, DARK_WOOD),  # headboard
        _ell(-0.33, -d / 2 + 0.3, 0.56, 0.26, 0.14, 0.07, WHITE),
        _ell(0.33, -d / 2 + 0.3, 0.56, 0.26, 0.14, 0.07, WHITE),
    ]


def _nightstand(colour: str, rng: np.random.Generator) -> list[Part]:
    c = WOOD if colour == "brown" else colour_rgba(colour)
    return [
        _box(0, 0, 0.28, 0.22, 0.2, 0.28, c),
        _box(0, 0.202, 0.38, 0.19, 0.003, 0.1, _shade(c, 0.8)),
        _box(0, 0.21, 0.38, 0.05, 0.008, 0.01, METAL, "metal"),
    ] + [Part(p.shape, (p.pos[0] + 0.05, p.pos[1] - 0.03, p.pos[2] + 0.56), p.size, p.rgba, p.euler, p.material)
         for p in _table_lamp("cream", rng)]


def _wardrobe(colour: str, rng: np.random.Generator) -> list[Part]:
    c = WOOD if colour == "brown" else colour_rgba(colour)
    w, d, h = 1.1, 0.6, 2.05
    return [
        _box(0, 0, h / 2, w / 2, d / 2, h / 2, c),
        _box(0, d / 2 + 0.002, h / 2, 0.004, 0.003, h / 2 - 0.05, _shade(c, 0.5)),
        _cyl(-0.06, d / 2 + 0.025, 1.05, 0.012, 0.12, METAL, "metal"),
        _cyl(0.06, d / 2 + 0.025, 1.05, 0.012, 0.12, METAL, "metal"),
    ]


def _desk(colour: str, rng: np.random.Generator) -> list[Part]:
    c = LIGHT_WOOD if colour == "brown" else colour_rgba(colour)
    parts = _table(1.2, 0.62, 0.75, c, leg_r=0.022)
    parts += [
        _box(-0.4, -0.12, 0.78, 0.1, 0.14, 0.025, _rgb(0.2, 0.35, 0.6)),  # books
        _cyl(0.45, -0.15, 0.8, 0.035, 0.045, _rgb(0.85, 0.2, 0.2), "glossy"),  # mug
    ]
    return parts


def _dresser(colour: str, rng: np.random.Generator) -> list[Part]:
    c = WOOD if colour == "brown" else colour_rgba(colour)
    w, d, h = 1.0, 0.5, 0.9
    parts = [_box(0, 0, h / 2, w / 2, d / 2, h / 2, c)]
    for k in range(3):
        z = 0.15 + k * 0.28
        parts.append(_box(0, d / 2 + 0.002, z + 0.1, w / 2 - 0.03, 0.003, 0.005, _shade(c, 0.5)))
        parts.append(_box(0, d / 2 + 0.01, z, 0.08, 0.008, 0.012, METAL, "metal"))
    parts.append(_cyl(0.3, 0.0, h + 0.12, 0.05, 0.12, _rgb(0.2, 0.45, 0.7), "glossy"))  # vase
    return parts


def _toilet(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    seat = _shade(c, 1.15) if colour != "white" else _rgb(0.99, 0.99, 0.99)
    return [
        _box(0, -0.27, 0.6, 0.2, 0.085, 0.19, c, "glossy"),  # tank
        _box(0, -0.27, 0.8, 0.215, 0.1, 0.018, _shade(c, 0.9), "glossy"),
        _cyl(0.12, -0.27, 0.83, 0.02, 0.012, METAL, "metal"),  # flush button
        _ell(0, -0.02, 0.19, 0.13, 0.17, 0.2, c, "glossy"),  # pedestal
        _ell(0, 0.06, 0.34, 0.2, 0.26, 0.1, c, "glossy"),  # bowl
        _ell(0, 0.06, 0.42, 0.205, 0.265, 0.022, seat, "glossy"),  # seat
        _ell(0, 0.07, 0.425, 0.13, 0.175, 0.02, _rgb(0.55, 0.68, 0.78), "glossy"),  # water in the bowl
        _box(0, -0.165, 0.68, 0.19, 0.018, 0.24, seat, "glossy", euler=(-8, 0, 0)),  # lid, up
    ]


def _bathtub(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    w, d, h = 1.65, 0.78, 0.56
    return [
        _box(0, 0, h / 2, w / 2, d / 2, h / 2, c, "glossy"),
        _box(0, 0, h + 0.001, w / 2 - 0.07, d / 2 - 0.07, 0.002, _rgb(0.55, 0.75, 0.9), "glossy"),  # water
        _cyl(-w / 2 + 0.12, -d / 2 + 0.08, h + 0.12, 0.02, 0.12, METAL, "metal"),
        _cyl(-w / 2 + 0.12, -d / 2 + 0.16, h + 0.23, 0.018, 0.08, METAL, "metal", euler=(90, 0, 0)),
    ]


def _vanity(colour: str, rng: np.random.Generator) -> list[Part]:
    c = WHITE if colour == "white" else colour_rgba(colour)
    w, d, h = 0.9, 0.5, 0.85
    return [
        _box(0, 0, h / 2, w / 2, d / 2, h / 2, c),
        _box(0, d / 2 + 0.002, h / 2, 0.004, 0.003, h / 2 - 0.05, _shade(c, 0.5)),
        _box(0, 0, h + 0.02, w / 2 + 0.02, d / 2 + 0.01, 0.02, _rgb(0.85, 0.85, 0.83), "glossy"),
        _ell(0, 0.03, h + 0.041, 0.22, 0.16, 0.004, _rgb(0.6, 0.62, 0.66), "glossy"),
        _cyl(0, -0.17, h + 0.12, 0.015, 0.09, METAL, "metal"),
        _cyl(0, -0.12, h + 0.2, 0.013, 0.05, METAL, "metal", euler=(90, 0, 0)),
        _box(0, -d / 2 + 0.015, 1.55, 0.32, 0.012, 0.36, _rgb(0.75, 0.85, 0.9), "glossy"),  # mirror
        _box(0, -d / 2 + 0.008, 1.55, 0.35, 0.006, 0.39, METAL, "metal"),
    ]


def _washer(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    w, d, h = 0.62, 0.62, 0.88
    fy = d / 2
    return [
        _box(0, 0, h / 2, w / 2, d / 2, h / 2, c, "glossy"),
        _cyl(0, fy + 0.005, 0.42, 0.22, 0.008, METAL, "metal", euler=(90, 0, 0)),
        _cyl(0, fy + 0.014, 0.42, 0.17, 0.006, GLASS, "glossy", euler=(90, 0, 0)),
        _box(0, fy + 0.003, h - 0.08, w / 2 - 0.02, 0.004, 0.05, _shade(c, 0.75)),
        _cyl(0.18, fy + 0.02, h - 0.08, 0.03, 0.012, METAL, "metal", euler=(90, 0, 0)),
    ]


def _trash_can(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    return [
        _cyl(0, 0, 0.3, 0.16, 0.3, c, "metal"),
        _cyl(0, 0, 0.61, 0.165, 0.015, _shade(c, 0.7), "metal"),
    ]


def _basket(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    return [_cyl(0, 0, 0.25, 0.2, 0.25, c), _cyl(0, 0, 0.5, 0.17, 0.02, _rgb(0.9, 0.9, 0.95))]


def _box_pile(colour: str, rng: np.random.Generator) -> list[Part]:
    card = _rgb(0.72, 0.55, 0.33)
    return [
        _box(0, 0, 0.18, 0.25, 0.2, 0.18, card),
        _box(0.03, -0.02, 0.47, 0.18, 0.15, 0.11, _shade(card, 0.9), euler=(0, 0, 12)),
    ]


def _stool(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    return [_cyl(0, 0, 0.62, 0.18, 0.03, c), _cyl(0, 0, 0.31, 0.03, 0.31, METAL, "metal"),
            _cyl(0, 0, 0.02, 0.17, 0.02, METAL, "metal")]


def _rug(width: float, depth: float) -> Callable[[str, np.random.Generator], list[Part]]:
    def build(colour: str, rng: np.random.Generator) -> list[Part]:
        c = colour_rgba(colour)
        return [
            _box(0, 0, 0.004, width / 2, depth / 2, 0.004, _shade(c, 0.8)),
            _box(0, 0, 0.006, width / 2 - 0.12, depth / 2 - 0.12, 0.004, c),
        ]

    return build


def _towel_rack(colour: str, rng: np.random.Generator) -> list[Part]:
    c = colour_rgba(colour)
    return [
        _cyl(-0.3, 0, 0.5, 0.015, 0.5, METAL, "metal"),
        _cyl(0.3, 0, 0.5, 0.015, 0.5, METAL, "metal"),
        _box(0, 0.0, 0.8, 0.26, 0.03, 0.22, c),
        _box(0, 0, 0.015, 0.34, 0.1, 0.015, METAL, "metal"),
    ]


_BIG = ("red", "blue", "green", "grey", "beige", "navy", "purple", "teal", "yellow", "brown")

CATALOGUE: dict[str, ObjectType] = {
    t.name: t
    for t in [
        ObjectType("fridge", (0.76, 0.70, 1.85), _fridge, ("white", "silver", "red", "teal", "cream", "blue"),
                   shape_words="tall box-shaped standing cabinet with long door handles"),
        ObjectType("microwave", (0.52, 0.38, 0.30), _microwave, ("white", "black", "silver", "red"), obstacle=False,
                   shape_words="small box with a dark glass window on its front"),
        ObjectType("stove", (0.62, 0.62, 1.1), _stove, ("white", "black", "silver", "red"),
                   shape_words="waist-high box with round black rings on its top and a glass door"),
        ObjectType("counter", (1.6, 0.62, 2.2), _counter(1.6), ("white", "cream", "grey", "teal", "navy"), surface=0.9),
        ObjectType("long_counter", (2.2, 0.62, 2.2), _counter(2.2), ("white", "cream", "grey", "teal", "navy"), surface=0.9),
        ObjectType("sink_counter", (1.2, 0.62, 2.2), _sink_counter, ("white", "cream", "grey", "teal", "navy")),
        ObjectType("dining_table", (1.4, 0.85, 0.85), _dining_table, ("brown", "white", "black"), surface=0.76),
        ObjectType("chair", (0.46, 0.44, 0.92), _chair, ("brown", "white", "black", "red", "blue")),
        ObjectType("coffee_table", (1.0, 0.55, 0.5), _coffee_table, ("brown", "white", "black"), surface=0.42),
        ObjectType("sofa", (2.0, 0.90, 0.86), _sofa, _BIG,
                   shape_words="long padded seat for several people with a back and two arm rests"),
        ObjectType("armchair", (0.92, 0.90, 0.86), _armchair, _BIG,
                   shape_words="padded seat for one person with a back and two arm rests"),
        ObjectType("tv_stand", (1.5, 0.45, 0.5), _tv_stand, ("brown", "black", "white"), surface=0.5),
        ObjectType("tv", (1.24, 0.25, 0.84), _tv, ("black", "silver", "white"), obstacle=False,
                   shape_words="wide flat rectangle with a bright picture on it"),
        ObjectType("bookshelf", (0.9, 0.34, 1.85), _bookshelf, ("brown", "white", "black")),
        ObjectType("floor_lamp", (0.34, 0.34, 1.7), _floor_lamp, ("white", "yellow", "red", "blue", "green", "orange"),
                   shape_words="thin pole with a glowing cone-shaped shade on top"),
        ObjectType("plant", (0.42, 0.42, 1.25), _plant, ("orange", "blue", "white", "red", "yellow", "black"),
                   shape_words="leafy green bush growing out of a round pot"),
        ObjectType("ball", (0.36, 0.36, 0.36), _ball, ("orange", "blue", "red", "yellow", "green", "purple"),
                   shape_words="round sphere with thin lines on it, lying on the floor"),
        ObjectType("teddy_bear", (0.45, 0.5, 0.75), _teddy, ("brown", "cream", "pink", "grey", "blue"),
                   shape_words="soft, round, sitting figure with two small round ears"),
        ObjectType("laptop", (0.40, 0.40, 0.28), _laptop, ("silver", "black", "pink", "blue"), obstacle=False,
                   shape_words="thin open lid with a lit screen, like a small folding screen"),
        ObjectType("bed", (1.5, 2.1, 1.2), _bed, ("blue", "red", "green", "yellow", "purple", "grey", "pink", "teal"),
                   shape_words="large, low, rectangular piece with pillows and a cover spread over it"),
        ObjectType("nightstand", (0.44, 0.40, 0.8), _nightstand, ("brown", "white")),
        ObjectType("wardrobe", (1.1, 0.6, 2.05), _wardrobe, ("brown", "white", "grey", "navy"),
                   shape_words="very tall cabinet with two long doors"),
        ObjectType("desk", (1.2, 0.62, 0.8), _desk, ("brown", "white", "black"), surface=0.75),
        ObjectType("dresser", (1.0, 0.5, 1.1), _dresser, ("brown", "white")),
        ObjectType("toilet", (0.44, 0.74, 0.82), _toilet, ("white", "black", "blue", "pink"),
                   shape_words="glossy seat with a round bowl and an upright tank behind it"),
        ObjectType("bathtub", (1.65, 0.78, 0.8), _bathtub, ("white", "blue", "pink", "yellow"),
                   shape_words="long open tub filled with water"),
        ObjectType("vanity", (0.9, 0.5, 1.95), _vanity, ("white", "brown", "grey", "navy")),
        ObjectType("washing_machine", (0.62, 0.62, 0.88), _washer, ("white", "silver", "black", "red"),
                   shape_words="cube with a round glass door on its front"),
        ObjectType("trash_can", (0.33, 0.33, 0.63), _trash_can, ("silver", "black", "white", "green", "red")),
        ObjectType("laundry_basket", (0.4, 0.4, 0.52), _basket, ("beige", "blue", "white", "grey")),
        ObjectType("boxes", (0.5, 0.4, 0.6), _box_pile, ("beige",)),
        ObjectType("stool", (0.36, 0.36, 0.65), _stool, ("red", "black", "white", "yellow")),
        ObjectType("towel_rack", (0.7, 0.2, 1.0), _towel_rack, ("white", "blue", "pink", "yellow")),
        ObjectType("rug", (2.2, 1.6, 0.01), _rug(2.2, 1.6), ("red", "blue", "beige", "grey", "green", "purple"),
                   obstacle=False),
        ObjectType("small_rug", (1.4, 0.9, 0.01), _rug(1.4, 0.9), ("red", "blue", "beige", "grey", "green", "purple"),
                   obstacle=False),
    ]
}

#: Object types that can be a navigation target (recognisable, reachable from the floor).
TARGET_TYPES: tuple[str, ...] = (
    "fridge", "microwave", "stove", "sofa", "armchair", "tv", "floor_lamp", "plant", "ball", "teddy_bear",
    "laptop", "bed", "wardrobe", "toilet", "bathtub", "washing_machine",
)


def get_type(name: str) -> ObjectType:
    try:
        return CATALOGUE[name]
    except KeyError:
        raise KeyError(f"unknown object type {name!r}; known: {', '.join(sorted(CATALOGUE))}") from None
