"""Mesh generators: surfaces of revolution, swept tubes, tori and cushions as vertex + face lists.

Everything is generated in code (no files); the results are cached because the same mesh is written once per
scene however many instances use it.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

Mesh = tuple[np.ndarray, np.ndarray]  # (V x 3 float vertices, F x 3 int faces)


def _orient_outward(verts: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Flip all faces if the signed volume is negative, so normals point outwards."""
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)).sum()
    return faces[:, ::-1].copy() if vol < 0 else faces


def lathe(profile: tuple[tuple[float, float], ...], segments: int = 24, sx: float = 1.0, sy: float = 1.0,
          loop: bool = False) -> Mesh:
    """Revolve a closed (r, z) profile about the z axis. Points with r == 0 become single axis vertices.

    The profile should start and end on the axis (r == 0) so the solid is closed (e.g. bottom centre, outer wall,
    rim, inner wall, inner bottom centre), or ``loop=True`` for a ring-shaped cross-section (a lamp drum).
    ``sx``/``sy`` stretch the result into an ellipse.
    """
    verts: list[tuple[float, float, float]] = []
    rings: list[list[int]] = []
    for r, z in profile:
        if r <= 1e-9:
            verts.append((0.0, 0.0, z))
            rings.append([len(verts) - 1] * segments)
        else:
            ring = []
            for j in range(segments):
                t = 2 * math.pi * j / segments
                verts.append((r * math.cos(t) * sx, r * math.sin(t) * sy, z))
                ring.append(len(verts) - 1)
            rings.append(ring)
    faces: list[tuple[int, int, int]] = []
    pairs = [(i, i + 1) for i in range(len(rings) - 1)] + ([(len(rings) - 1, 0)] if loop else [])
    for i0, i1 in pairs:
        a, b = rings[i0], rings[i1]
        for j in range(segments):
            k = (j + 1) % segments
            if a[j] != a[k]:
                faces.append((a[j], a[k], b[k]))
            if b[j] != b[k]:
                faces.append((a[j], b[k], b[j]))
    # drop degenerate triangles (two identical indices)
    faces = [f for f in faces if len(set(f)) == 3]
    v = np.asarray(verts, dtype=float)
    f = np.asarray(faces, dtype=int)
    return v, _orient_outward(v, f)


def _frames(path: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """Parallel-transport normal/binormal frames along a polyline."""
    n = len(path)
    tangents = np.zeros_like(path)
    for i in range(n):
        if closed:
            d = path[(i + 1) % n] - path[i - 1]
        else:
            d = path[min(i + 1, n - 1)] - path[max(i - 1, 0)]
        tangents[i] = d / (np.linalg.norm(d) + 1e-12)
    ref = np.array([0.0, 0.0, 1.0]) if abs(tangents[0][2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    normal = np.cross(tangents[0], ref)
    normal /= np.linalg.norm(normal)
    normals = [normal]
    for i in range(1, n):
        t = tangents[i]
        nrm = normals[-1] - t * np.dot(normals[-1], t)
        nrm /= np.linalg.norm(nrm) + 1e-12
        normals.append(nrm)
    normals_a = np.asarray(normals)
    binormals = np.cross(tangents, normals_a)
    return normals_a, binormals


def tube(path: tuple[tuple[float, float, float], ...], radii: tuple[float, ...] | float, segments: int = 12,
         closed: bool = False) -> Mesh:
    """Sweep a circle (radius per path point) along a 3-D polyline; open tubes get flat end caps."""
    p = np.asarray(path, dtype=float)
    r = np.full(len(p), radii, dtype=float) if np.isscalar(radii) else np.asarray(radii, dtype=float)
    normals, binormals = _frames(p, closed)
    verts: list[np.ndarray] = []
    for i in range(len(p)):
        for j in range(segments):
            t = 2 * math.pi * j / segments
            verts.append(p[i] + r[i] * (math.cos(t) * normals[i] + math.sin(t) * binormals[i]))
    faces: list[tuple[int, int, int]] = []
    count = len(p) if closed else len(p) - 1
    for i in range(count):
        i2 = (i + 1) % len(p)
        for j in range(segments):
            k = (j + 1) % segments
            a, b, c, d = i * segments + j, i * segments + k, i2 * segments + k, i2 * segments + j
            faces += [(a, b, c), (a, c, d)]
    if not closed:
        for end, ring in ((0, 0), (len(p) - 1, (len(p) - 1) * segments)):
            verts.append(p[end])
            centre = len(verts) - 1
            for j in range(segments):
                k = (j + 1) % segments
                faces.append((centre, ring + k, ring + j) if end == 0 else (centre, ring + j, ring + k))
    v = np.asarray(verts)
    f = np.asarray(faces, dtype=int)
    return v, _orient_outward(v, f)


def arc(radius: float, start_deg: float, end_deg: float, n: int, plane: str = "xz",
        centre: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> tuple[tuple[float, float, float], ...]:
    """Points on a circular arc in the given plane ("xz", "yz" or "xy")."""
    pts = []
    for i in range(n):
        t = math.radians(start_deg + (end_deg - start_deg) * i / (n - 1))
        a, b = radius * math.cos(t), radius * math.sin(t)
        if plane == "xz":
            pts.append((centre[0] + a, centre[1], centre[2] + b))
        elif plane == "yz":
            pts.append((centre[0], centre[1] + a, centre[2] + b))
        else:
            pts.append((centre[0] + a, centre[1] + b, centre[2]))
    return tuple(pts)


def torus(major: float, minor: float, segments: int = 32, tube_segments: int = 10, plane: str = "xy") -> Mesh:
    """A closed ring; ``plane`` is the plane the ring lies in."""
    pts = arc(major, 0.0, 360.0 * (segments - 1) / segments, segments, plane)
    return tube(pts, minor, tube_segments, closed=True)


def cushion(hx: float, hy: float, hz: float, exponent: float = 0.35, nu: int = 24, nv: int = 12) -> Mesh:
    """A superellipsoid: a box with soft, rounded edges (pillows, cushions)."""

    def spow(x: float, e: float) -> float:
        return math.copysign(abs(x) ** e, x)

    verts: list[tuple[float, float, float]] = [(0.0, 0.0, -hz)]
    for i in range(1, nv):
        phi = -math.pi / 2 + math.pi * i / nv
        for j in range(nu):
            th = 2 * math.pi * j / nu
            c = spow(math.cos(phi), exponent)
            verts.append((hx * c * spow(math.cos(th), exponent), hy * c * spow(math.sin(th), exponent),
                          hz * spow(math.sin(phi), exponent)))
    verts.append((0.0, 0.0, hz))
    faces: list[tuple[int, int, int]] = []
    top = len(verts) - 1
    for j in range(nu):
        k = (j + 1) % nu
        faces.append((0, 1 + k, 1 + j))
        last = 1 + (nv - 2) * nu
        faces.append((top, last + j, last + k))
    for i in range(nv - 2):
        for j in range(nu):
            k = (j + 1) % nu
            a, b = 1 + i * nu + j, 1 + i * nu + k
            c, d = 1 + (i + 1) * nu + k, 1 + (i + 1) * nu + j
            faces += [(a, b, c), (a, c, d)]
    v = np.asarray(verts)
    f = np.asarray(faces, dtype=int)
    return v, _orient_outward(v, f)


def prism(outline: tuple[tuple[float, float], ...], thickness: float) -> Mesh:
    """Extrude a convex-or-star-shaped 2-D outline (in x, y, counter-clockwise) by ``thickness`` along z."""
    n = len(outline)
    cx = sum(p[0] for p in outline) / n
    cy = sum(p[1] for p in outline) / n
    h = thickness / 2
    verts = [(x, y, -h) for x, y in outline] + [(x, y, h) for x, y in outline] + [(cx, cy, -h), (cx, cy, h)]
    faces: list[tuple[int, int, int]] = []
    for i in range(n):
        k = (i + 1) % n
        faces += [(i, k, n + k), (i, n + k, n + i)]
        faces.append((2 * n, k, i))
        faces.append((2 * n + 1, n + i, n + k))
    v = np.asarray(verts, dtype=float)
    f = np.asarray(faces, dtype=int)
    return v, _orient_outward(v, f)


@lru_cache(maxsize=None)
def cached(key: str) -> Mesh:
    """Meshes by name, generated once per process (see ``MESHES``)."""
    return MESHES[key]()


def _shell(outer: tuple[tuple[float, float], ...], thickness: float, bottom: float) -> tuple[tuple[float, float], ...]:
    """Closed lathe profile of a vessel: outer wall bottom-up, rim, then the inner wall top-down."""
    inner = [(max(r - thickness, 0.0), z) for r, z in reversed(outer) if z > bottom]
    zs = [z for _, z in outer]
    rs = [r for r, _ in outer]
    r_bottom = float(np.interp(bottom, zs, rs))
    inner.append((max(r_bottom - thickness, 0.0), bottom))
    prof = [(0.0, outer[0][1])] + list(outer) + inner + [(0.0, bottom)]
    return tuple(prof)


def _egg() -> Mesh:
    prof = []
    for i in range(17):
        t = math.pi * i / 16  # 0 bottom .. pi top
        z = (1 - math.cos(t)) / 2 * 0.058
        r = 0.0215 * math.sin(t) * (1.0 - 0.18 * (z / 0.058))
        prof.append((r, z))
    return lathe(tuple(prof), 20)


def _banana() -> Mesh:
    pts, rad = [], []
    n = 14
    for i in range(n):
        t = i / (n - 1)
        ang = math.radians(-55 + 110 * t)
        pts.append((0.11 * math.sin(ang), 0.11 * (1 - math.cos(ang)) - 0.03, 0.018))
        rad.append(0.004 + 0.014 * math.sin(math.pi * (0.08 + 0.84 * t)) ** 0.6)
    return tube(tuple(pts), tuple(rad), 12)


def _mug_handle() -> Mesh:
    pts = arc(0.03, -80, 80, 12, "yz", (0.0, 0.035, 0.05))
    return tube(pts, 0.006, 10)


def _kettle_handle() -> Mesh:
    pts = arc(0.065, 15, 165, 14, "xz", (0.0, 0.0, 0.17))
    return tube(pts, 0.009, 10)


def _kettle_spout() -> Mesh:
    pts = ((0.07, 0.0, 0.04), (0.1, 0.0, 0.075), (0.125, 0.0, 0.11), (0.14, 0.0, 0.13))
    return tube(pts, (0.014, 0.011, 0.009, 0.008), 10)


def _faucet() -> Mesh:
    pts = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.16)) + arc(0.06, 180, 0, 9, "xz", (0.06, 0.0, 0.16))[1:] + (
        (0.12, 0.0, 0.12),)
    return tube(pts, 0.011, 10)


def _lamp_arm() -> Mesh:
    pts = ((0.0, 0.0, 0.02), (-0.04, 0.0, 0.2), (-0.02, 0.0, 0.34), (0.1, 0.0, 0.38), (0.16, 0.0, 0.36))
    return tube(pts, 0.009, 10)


def _knife_blade() -> Mesh:
    outline = ((0.0, -0.012), (0.1, -0.014), (0.14, -0.008), (0.155, 0.006), (0.0, 0.012))
    return prism(outline, 0.002)


def _mountain() -> Mesh:
    outline = ((-0.18, 0.0), (0.18, 0.0), (0.06, 0.22), (0.0, 0.18), (-0.06, 0.24))
    return prism(outline, 0.004)


MESHES = {
    "mug_body": lambda: lathe(_shell(((0.04, 0.0), (0.041, 0.05), (0.041, 0.1)), 0.005, 0.008)),
    "mug_handle": _mug_handle,
    "cup_body": lambda: lathe(_shell(((0.03, 0.0), (0.035, 0.05), (0.041, 0.11)), 0.003, 0.006)),
    "bowl": lambda: lathe(_shell(((0.04, 0.0), (0.045, 0.008), (0.07, 0.03), (0.085, 0.055), (0.088, 0.065)),
                                 0.005, 0.012), 28),
    "plate": lambda: lathe(((0.0, 0.0), (0.07, 0.0), (0.075, 0.006), (0.1, 0.01), (0.125, 0.022), (0.12, 0.024),
                            (0.095, 0.014), (0.07, 0.01), (0.0, 0.01)), 32),
    "pot_body": lambda: lathe(_shell(((0.105, 0.0), (0.11, 0.01), (0.11, 0.14), (0.116, 0.145)), 0.006, 0.01),
                              28),
    "pan_body": lambda: lathe(_shell(((0.1, 0.0), (0.11, 0.01), (0.13, 0.045), (0.132, 0.05)), 0.005, 0.008), 28),
    "vase": lambda: lathe(_shell(((0.045, 0.0), (0.07, 0.06), (0.075, 0.1), (0.06, 0.17), (0.035, 0.23),
                                  (0.032, 0.26), (0.045, 0.3)), 0.006, 0.02), 24),
    "wine_bottle": lambda: lathe(((0.0, 0.0), (0.036, 0.0), (0.038, 0.005), (0.038, 0.2), (0.034, 0.225),
                                  (0.022, 0.245), (0.014, 0.26), (0.013, 0.31), (0.015, 0.312), (0.015, 0.32),
                                  (0.0, 0.32)), 20),
    "soap_bottle": lambda: lathe(((0.0, 0.0), (0.034, 0.0), (0.037, 0.01), (0.037, 0.12), (0.03, 0.14),
                                  (0.014, 0.15), (0.0, 0.15)), 20, 1.0, 0.7),
    "garbage_can": lambda: lathe(_shell(((0.13, 0.0), (0.135, 0.01), (0.155, 0.38), (0.16, 0.4)), 0.008, 0.02),
                                 28),
    "basket": lambda: lathe(_shell(((0.12, 0.0), (0.14, 0.03), (0.16, 0.13), (0.165, 0.14)), 0.008, 0.012),
                            24, 1.0, 0.75),
    "kettle_body": lambda: lathe(((0.0, 0.0), (0.085, 0.0), (0.095, 0.02), (0.095, 0.09), (0.08, 0.14),
                                  (0.055, 0.165), (0.0, 0.165)), 24),
    "kettle_handle": _kettle_handle,
    "kettle_spout": _kettle_spout,
    "egg": _egg,
    "banana": _banana,
    "toilet_bowl": lambda: lathe(_shell(((0.1, 0.0), (0.1, 0.08), (0.13, 0.19), (0.175, 0.29), (0.198, 0.35),
                                         (0.2, 0.38)), 0.022, 0.22), 28, 1.0, 0.8),
    "apple": lambda: lathe(((0.0, 0.008), (0.014, 0.003), (0.028, 0.006), (0.038, 0.018), (0.043, 0.035),
                            (0.043, 0.05), (0.038, 0.064), (0.027, 0.073), (0.014, 0.074), (0.006, 0.069),
                            (0.0, 0.064)), 24),
    "loaf": lambda: cushion(0.064, 0.125, 0.035, 0.45),
    "toilet_seat": lambda: torus(0.16, 0.018, 28, 8),
    "sink_basin": lambda: lathe(_shell(((0.1, 0.0), (0.14, 0.04), (0.18, 0.11), (0.2, 0.14)), 0.01, 0.012),
                                24, 1.0, 0.75),
    "faucet": _faucet,
    "lamp_shade": lambda: lathe(_shell(((0.02, 0.0), (0.03, 0.01), (0.06, 0.06), (0.085, 0.11)), 0.003, 0.005),
                                20),
    "floor_shade": lambda: lathe(((0.21, 0.0), (0.14, 0.3), (0.134, 0.3), (0.204, 0.0)), 28, loop=True),
    "basket_handle": lambda: tube(arc(0.125, 5, 175, 16, "yz", (0.0, 0.0, 0.13)), 0.008, 10),
    "lamp_arm": _lamp_arm,
    "plant_pot": lambda: lathe(_shell(((0.09, 0.0), (0.12, 0.2), (0.13, 0.21), (0.13, 0.23)), 0.01, 0.02), 24),
    "carafe": lambda: lathe(_shell(((0.05, 0.0), (0.055, 0.06), (0.04, 0.12), (0.045, 0.13)), 0.003, 0.004), 20),
    "ball_seam": lambda: torus(0.1205, 0.0025, 40, 6),
    "ring_small": lambda: torus(0.014, 0.0016, 18, 6),
    "washer_ring": lambda: torus(0.17, 0.02, 32, 8, "yz"),
    "burner": lambda: torus(0.07, 0.008, 24, 6),
    "pillow": lambda: cushion(0.2, 0.3, 0.07),
    "cushion_seat": lambda: cushion(0.27, 0.3, 0.07, 0.25),
    "knife_blade": _knife_blade,
    "mountain": _mountain,
    "candle_holder": lambda: lathe(((0.0, 0.0), (0.05, 0.0), (0.055, 0.01), (0.05, 0.015), (0.0, 0.015)), 20),
    "bell": lambda: lathe(((0.0, 0.0), (0.03, 0.0), (0.028, 0.015), (0.018, 0.027), (0.0, 0.03)), 16),
}
