"""Colours and shapes of the tabletop objects, with prism meshes generated in code.

The 19 colour names are the paper's list; the RGB values are our choice (web-like, adjusted so each one
reads clearly under the scene's lights). Star, moon and triangle are extruded polygons whose meshes we
build here; cube and cylinder are MuJoCo primitives. MuJoCo collides meshes through their convex hulls,
which is enough for grasping, stacking, dropping into containers and falling through sorter holes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "COLOURS",
    "CONFUSABLE",
    "SHAPES",
    "SYMMETRY",
    "ShapeInfo",
    "colours_confusable",
    "prism_mesh",
    "shape_outline",
]

#: Rotational symmetry (degrees) of each shape about the vertical: turned by this much it looks (and fits) the same.
SYMMETRY = {"cube": 90.0, "cylinder": 360.0, "star": 72.0, "triangle": 120.0, "moon": 360.0}

#: The paper's 19 colours, name -> RGB in [0, 1].
COLOURS: dict[str, tuple[float, float, float]] = {
    "red": (0.86, 0.08, 0.08),
    "maroon": (0.45, 0.02, 0.06),
    "lime": (0.55, 0.95, 0.10),
    "green": (0.05, 0.50, 0.12),
    "blue": (0.10, 0.25, 0.95),
    "navy": (0.04, 0.06, 0.42),
    "yellow": (0.98, 0.88, 0.05),
    "cyan": (0.05, 0.90, 0.92),
    "magenta": (0.92, 0.08, 0.85),
    "silver": (0.60, 0.62, 0.67),  # 0.78 rendered almost white under the scene's lights
    "gray": (0.45, 0.45, 0.47),
    "olive": (0.48, 0.50, 0.06),
    "purple": (0.45, 0.05, 0.55),
    "teal": (0.02, 0.48, 0.48),
    "azure": (0.20, 0.60, 1.00),
    "violet": (0.60, 0.35, 0.98),
    "rose": (0.95, 0.12, 0.45),  # the paper's rose is a deep pinkish red; 0.45 green rendered as plain pink
    "black": (0.04, 0.04, 0.04),
    "white": (0.97, 0.97, 0.97),
}

#: Groups of colours a person could mix up; a scene never uses two colours of one group for objects the
#: instruction has to tell apart (the visual subset relies on these shades being distinct, see templates).
CONFUSABLE: tuple[frozenset[str], ...] = (
    frozenset({"red", "maroon", "rose", "magenta"}),
    frozenset({"lime", "green", "olive", "teal"}),
    frozenset({"blue", "navy", "azure", "violet", "purple"}),
    frozenset({"cyan", "teal", "azure"}),
    frozenset({"silver", "gray", "white"}),
    frozenset({"gray", "black", "navy"}),
    frozenset({"yellow", "olive", "lime"}),
    frozenset({"purple", "magenta", "violet"}),
)


def colours_confusable(a: str, b: str) -> bool:
    """True if ``a`` and ``b`` are the same colour or belong to one confusable group."""
    return a == b or any(a in g and b in g for g in CONFUSABLE)


@dataclass(frozen=True)
class ShapeInfo:
    """A loose object shape: its name as instructions say it and its size."""

    name: str
    height: float
    """Height of the object standing on the table (m)."""
    footprint: float
    """Largest horizontal extent (m); every shape fits the 8 cm gripper opening in any orientation."""


SHAPES: dict[str, ShapeInfo] = {
    "cube": ShapeInfo("cube", 0.045, 0.045 * math.sqrt(2)),
    "cylinder": ShapeInfo("cylinder", 0.045, 0.046),
    "star": ShapeInfo("star", 0.040, 0.062),
    "moon": ShapeInfo("moon", 0.040, 0.060),
    "triangle": ShapeInfo("triangle", 0.040, 0.058),
}

CUBE_HALF = 0.0225
CYLINDER_RADIUS = 0.023
STAR_OUTER, STAR_INNER = 0.031, 0.014
TRIANGLE_R = 0.032  # circumradius
MOON_R, MOON_r, MOON_d = 0.030, 0.025, 0.016  # outer radius, cut-out radius, cut-out offset


def shape_outline(shape: str, scale: float = 1.0) -> list[tuple[float, float]]:
    """The 2-D outline (counter-clockwise) of a prism shape, centred on its grasp point.

    For ``cube`` and ``cylinder`` (primitives) this is the square / a 32-gon, used for sorter hole decals.
    """
    pts: list[tuple[float, float]]
    if shape == "star":
        pts = []
        for k in range(10):
            r = STAR_OUTER if k % 2 == 0 else STAR_INNER
            a = math.pi / 2 + k * math.pi / 5
            pts.append((r * math.cos(a), r * math.sin(a)))
    elif shape == "triangle":
        pts = [(TRIANGLE_R * math.cos(math.pi / 2 + k * 2 * math.pi / 3),
                TRIANGLE_R * math.sin(math.pi / 2 + k * 2 * math.pi / 3)) for k in range(3)]
        cy = sum(p[1] for p in pts) / 3
        pts = [(x, y - cy) for x, y in pts]
    elif shape == "moon":
        pts = _moon_outline()
    elif shape == "cube":
        h = CUBE_HALF
        pts = [(-h, -h), (h, -h), (h, h), (-h, h)]
    elif shape == "cylinder":
        pts = [(CYLINDER_RADIUS * math.cos(2 * math.pi * k / 32), CYLINDER_RADIUS * math.sin(2 * math.pi * k / 32))
               for k in range(32)]
    else:
        raise ValueError(f"unknown shape {shape!r}; known: {sorted(SHAPES)}")
    return [(x * scale, y * scale) for x, y in pts]


def _moon_arcs(n: int = 14) -> tuple[list[tuple[float, float]], list[tuple[float, float]]]:
    """Outer and inner arcs of a crescent, both from the upper horn to the lower horn, centred on the bulge."""
    R, r, d = MOON_R, MOON_r, MOON_d
    xi = (R * R - r * r + d * d) / (2 * d)
    yi = math.sqrt(max(R * R - xi * xi, 0.0))
    phi0 = math.atan2(yi, xi)
    psi0 = math.atan2(yi, xi - d)
    outer = [(R * math.cos(a), R * math.sin(a)) for a in np.linspace(phi0, 2 * math.pi - phi0, n)]
    inner = [(d + r * math.cos(a), r * math.sin(a)) for a in np.linspace(psi0, 2 * math.pi - psi0, n)]
    # centre on the thickest part (x between -R and d - r), so grasping at the origin grips material
    cx = (-R + d - r) / 2
    outer = [(x - cx, y) for x, y in outer]
    inner = [(x - cx, y) for x, y in inner]
    return outer, inner


def _moon_outline() -> list[tuple[float, float]]:
    outer, inner = _moon_arcs()
    return outer + inner[::-1][1:-1]


def prism_mesh(shape: str, height: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (N, 3) and triangle faces (M, 3) of an extruded ``shape``, centred at its mid-height.

    Side faces get their own vertices so MuJoCo keeps the edges sharp.
    """
    h = height / 2
    verts: list[tuple[float, float, float]] = []
    faces: list[tuple[int, int, int]] = []

    def add(v: tuple[float, float, float]) -> int:
        verts.append(v)
        return len(verts) - 1

    if shape == "moon":
        outer, inner = _moon_arcs()
        for z in (h, -h):
            o = [add((x, y, z)) for x, y in outer]
            i = [add((x, y, z)) for x, y in inner]
            for k in range(len(outer) - 1):
                a, b, c, d = o[k], o[k + 1], i[k + 1], i[k]
                # outer arc runs counter-clockwise around the bulge; inner arc in the same sense
                faces += [(a, b, c), (a, c, d)]  # caps are oriented by _orient_outward
        outline = _moon_outline()
    else:
        outline = shape_outline(shape)
        for z, up in ((h, True), (-h, False)):
            c = add((0.0, 0.0, z))
            ring = [add((x, y, z)) for x, y in outline]
            for k in range(len(ring)):
                a, b = ring[k], ring[(k + 1) % len(ring)]
                faces.append((c, a, b) if up else (c, b, a))
    n = len(outline)
    for k in range(n):
        (x0, y0), (x1, y1) = outline[k], outline[(k + 1) % n]
        a, b = add((x0, y0, -h)), add((x1, y1, -h))
        c, d = add((x1, y1, h)), add((x0, y0, h))
        faces += [(a, b, c), (a, c, d)]
    v = np.asarray(verts, dtype=float)
    f = np.asarray(faces, dtype=int)
    area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    return v, _orient_outward(v, f[area > 1e-10])


def _orient_outward(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Flip cap faces whose normal points the wrong way (cheap and robust for our prisms)."""
    out = f.copy()
    for k, (a, b, c) in enumerate(f):
        n = np.cross(v[b] - v[a], v[c] - v[a])
        centre = (v[a] + v[b] + v[c]) / 3
        if abs(n[2]) > 1e-12 and abs(abs(centre[2]) - abs(v[:, 2].max())) < 1e-9:
            # cap face: normal must point away from the mid-plane
            if np.sign(n[2]) != np.sign(centre[2]):
                out[k] = (a, c, b)
    return out
