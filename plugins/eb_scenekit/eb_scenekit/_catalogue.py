"""Builders of every catalogue object type (registered into ``objects.CATALOGUE`` on import).

Each builder draws one object at scale 1 with its base centre at the origin and its front towards +x.
"""

from __future__ import annotations

import math

import numpy as np

from eb_scenekit.objects import (
    _BLACK, _CHROME, _CREAM, _DARK, _DARK_GLASS, _GLASS, _GRAY, _LEAF, _SCREEN, _STEEL, _STONE,
    _WALNUT, _WHITE, _WOOD, RGB, Parts, Surface, _register, _shade,
)

S = Surface

# ============================================================ furniture


def _legs(p: Parts, x: float, y: float, h: float, half: float, rgba: tuple[float, ...], mat: str = "eb_wood",
          round_: bool = False) -> None:
    for sx in (-1, 1):
        for sy in (-1, 1):
            if round_:
                p.cyl("leg", half, h / 2, (sx * x, sy * y, h / 2), rgba, mat)
            else:
                p.box("leg", (half, half, h / 2), (sx * x, sy * y, h / 2), rgba, mat)


@_register("Table", "furniture", ("white", "black", "oak", "red"), (0.4, 0.4), 0.76, mount="floor",
           surfaces=(S("top", 0.76, (0.36, 0.36)),))
def _table(p: Parts, c: RGB) -> None:
    p.box("top", (0.4, 0.4, 0.02), (0, 0, 0.74), c, "eb_plastic")
    p.box("apron", (0.36, 0.36, 0.04), (0, 0, 0.68), _shade(c, 0.8), "eb_plastic")
    _legs(p, 0.34, 0.34, 0.72, 0.018, _STEEL, "eb_metal", round_=True)


@_register("DiningTable", "furniture", ("walnut", "oak", "white"), (0.45, 0.85), 0.76, mount="floor",
           surfaces=(S("top", 0.76, (0.4, 0.78)),))
def _dining_table(p: Parts, c: RGB) -> None:
    p.box("top", (0.45, 0.85, 0.03), (0, 0, 0.73), c, "eb_wood")
    p.box("apron_x", (0.4, 0.02, 0.05), (0, 0.78, 0.65), _shade(c, 0.85), "eb_wood")
    p.box("apron_x", (0.4, 0.02, 0.05), (0, -0.78, 0.65), _shade(c, 0.85), "eb_wood")
    p.box("apron_y", (0.02, 0.78, 0.05), (0.4, 0, 0.65), _shade(c, 0.85), "eb_wood")
    p.box("apron_y", (0.02, 0.78, 0.05), (-0.4, 0, 0.65), _shade(c, 0.85), "eb_wood")
    for sx in (-1, 1):
        for sy in (-1, 1):
            x, y = sx * 0.39, sy * 0.77
            p.cyl("leg", 0.03, 0.35, (x, y, 0.35), _shade(c, 0.85), "eb_wood")
            p.sph("leg_knob", 0.037, (x, y, 0.42), _shade(c, 0.85), "eb_wood")
    p.box("runner", (0.16, 0.7, 0.002), (0, 0, 0.761), (0.9, 0.88, 0.8), "eb_fabric", collide=False)


@_register("CoffeeTable", "furniture", ("oak", "walnut", "white", "black"), (0.3, 0.55), 0.42, mount="floor",
           surfaces=(S("top", 0.42, (0.26, 0.5)),))
def _coffee_table(p: Parts, c: RGB) -> None:
    p.box("top", (0.3, 0.55, 0.025), (0, 0, 0.395), c, "eb_wood")
    p.box("shelf", (0.26, 0.5, 0.012), (0, 0, 0.1), _shade(c, 0.9), "eb_wood")
    _legs(p, 0.26, 0.5, 0.37, 0.025, _shade(c, 0.75))


@_register("SideTable", "furniture", ("oak", "walnut", "white"), (0.22, 0.22), 0.58, mount="floor",
           surfaces=(S("top", 0.58, (0.19, 0.19)),), articulations=("drawer",))
def _side_table(p: Parts, c: RGB) -> None:
    p.box("top", (0.23, 0.23, 0.015), (0, 0, 0.565), c, "eb_wood")
    p.box("body", (0.2, 0.2, 0.07), (-0.005, 0, 0.48), _shade(c, 0.9), "eb_wood")
    p.box("shelf", (0.19, 0.19, 0.01), (0, 0, 0.15), _shade(c, 0.9), "eb_wood")
    _legs(p, 0.19, 0.19, 0.55, 0.02, _shade(c, 0.8))
    d = p.slide("drawer", (0.195, 0, 0.48), (1, 0, 0), 0.22)
    d.box("front", (0.01, 0.18, 0.06), (0.01, 0, 0), _shade(c, 1.1), "eb_wood")
    d.sph("knob", 0.014, (0.03, 0, 0), _CHROME, "eb_metal")
    d.box("tray", (0.17, 0.16, 0.005), (-0.17, 0, -0.05), _shade(c, 0.8), "eb_wood", collide=False)


@_register("Chair", "furniture", ("wood", "black", "white", "red"), (0.23, 0.23), 0.92, mount="floor",
           surfaces=(S("seat", 0.47, (0.18, 0.18)),))
def _chair(p: Parts, c: RGB) -> None:
    mat = "eb_wood" if c == (0.62, 0.43, 0.26) else "eb_plastic"
    p.box("seat", (0.23, 0.22, 0.025), (0, 0, 0.45), c, mat)
    p.box("cushion", (0.2, 0.19, 0.012), (0.01, 0, 0.485), (0.75, 0.72, 0.66), "eb_fabric", collide=False)
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.cyl("leg", 0.017, 0.215, (sx * 0.19, sy * 0.19, 0.215), _shade(c, 0.85), mat)
    for sy in (-1, 1):
        p.box("post", (0.018, 0.018, 0.23), (-0.2, sy * 0.19, 0.7), _shade(c, 0.85), mat)
    p.box("back_rail", (0.016, 0.21, 0.07), (-0.2, 0, 0.86), c, mat)
    p.box("back_slat", (0.012, 0.19, 0.025), (-0.2, 0, 0.68), c, mat)


def _upholstered(p: Parts, c: RGB, half_y: float, seats: int) -> None:
    wood = _WALNUT
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.cyl("leg", 0.025, 0.05, (sx * 0.36, sy * (half_y - 0.06), 0.05), wood, "eb_wood")
    p.box("base", (0.42, half_y, 0.1), (0, 0, 0.2), c, "eb_fabric")
    inner = half_y - 0.16
    w = inner / seats
    for i in range(seats):
        y = -inner + w * (2 * i + 1)
        p.mesh("seat_cushion", "cushion_seat", (0.06, y, 0.36), _shade(c, 1.08), "eb_fabric",
               stretch=(1.0, (w - 0.01) / 0.3, 1.0))
        p.mesh("back_cushion", "cushion_seat", (-0.22, y, 0.6), _shade(c, 1.08), "eb_fabric",
               stretch=(0.5, (w - 0.01) / 0.3, 2.3), rot=(0, -78, 0))
    p.box("back", (0.1, half_y, 0.27), (-0.33, 0, 0.5), c, "eb_fabric")
    p.cyl_ft("back_roll", (-0.33, -half_y, 0.77), (-0.33, half_y, 0.77), 0.1, c, "eb_fabric")
    for sy in (-1, 1):
        p.box("arm", (0.42, 0.08, 0.16), (0, sy * (half_y - 0.08), 0.44), c, "eb_fabric")
        p.cyl_ft("arm_roll", (-0.42, sy * (half_y - 0.08), 0.6), (0.42, sy * (half_y - 0.08), 0.6), 0.085,
                 _shade(c, 1.04), "eb_fabric")


@_register("Sofa", "furniture", ("gray", "blue", "beige", "green", "red"), (0.45, 1.0), 0.87, mount="floor",
           surfaces=(S("seat", 0.44, (0.22, 0.75), (0.06, 0.0)),))
def _sofa(p: Parts, c: RGB) -> None:
    _upholstered(p, c, 1.0, 3)


@_register("ArmChair", "furniture", ("beige", "gray", "blue", "green", "red"), (0.45, 0.45), 0.87, mount="floor",
           surfaces=(S("seat", 0.44, (0.2, 0.22), (0.06, 0.0)),))
def _armchair(p: Parts, c: RGB) -> None:
    _upholstered(p, c, 0.45, 1)


@_register("Bed", "furniture", ("blue", "white", "gray", "green", "red", "beige"), (1.05, 0.82), 1.1,
           mount="floor", surfaces=(S("top", 0.57, (0.6, 0.65), (0.3, 0.0)),))
def _bed(p: Parts, c: RGB) -> None:
    p.box("frame", (1.02, 0.8, 0.1), (0.02, 0, 0.2), _WOOD, "eb_wood")
    _legs(p, 0.95, 0.74, 0.1, 0.04, _WALNUT)
    p.box("mattress", (1.0, 0.78, 0.12), (0.02, 0, 0.42), _WHITE, "eb_fabric")
    p.box("blanket", (0.7, 0.805, 0.025), (0.33, 0, 0.55), c, "eb_fabric")
    for sy in (-1, 1):
        p.box("blanket_side", (0.7, 0.008, 0.14), (0.33, sy * 0.81, 0.44), c, "eb_fabric", collide=False)
    p.box("blanket_foot", (0.008, 0.81, 0.14), (1.035, 0, 0.44), c, "eb_fabric", collide=False)
    p.box("sheet_fold", (0.07, 0.81, 0.03), (-0.4, 0, 0.555), _shade(c, 1.5), "eb_fabric")
    for sy in (-1, 1):
        p.mesh("pillow", "pillow", (-0.78, sy * 0.37, 0.6), (0.97, 0.97, 0.95), "eb_fabric",
               stretch=(0.9, 1.1, 1.0))
    p.box("headboard", (0.04, 0.84, 0.52), (-1.03, 0, 0.55), _WALNUT, "eb_wood")
    p.box("headboard_pad", (0.015, 0.74, 0.22), (-0.985, 0, 0.8), _shade(c, 0.7), "eb_fabric")


@_register("Desk", "furniture", ("oak", "white", "walnut", "black"), (0.32, 0.65), 0.76, mount="floor",
           surfaces=(S("top", 0.76, (0.28, 0.6)),), articulations=("drawer",))
def _desk(p: Parts, c: RGB) -> None:
    p.box("top", (0.32, 0.66, 0.02), (0, 0, 0.74), c, "eb_wood")
    p.box("pedestal", (0.29, 0.2, 0.36), (-0.01, 0.44, 0.36), _shade(c, 0.9), "eb_wood")
    for sx in (-1, 1):
        p.box("leg", (0.025, 0.025, 0.36), (sx * 0.27, -0.61, 0.36), _shade(c, 0.85), "eb_wood")
    p.box("modesty", (0.01, 0.42, 0.14), (-0.27, -0.2, 0.56), _shade(c, 0.85), "eb_wood")
    p.box("front2", (0.01, 0.18, 0.15), (0.285, 0.44, 0.18), _shade(c, 1.1), "eb_wood")
    p.cap_ft("handle2", (0.31, 0.39, 0.25), (0.31, 0.49, 0.25), 0.007, _CHROME, "eb_metal")
    d = p.slide("drawer", (0.28, 0.44, 0.55), (1, 0, 0), 0.3)
    d.box("front", (0.01, 0.18, 0.14), (0.01, 0, 0), _shade(c, 1.1), "eb_wood")
    d.cap_ft("handle", (0.035, -0.05, 0.06), (0.035, 0.05, 0.06), 0.007, _CHROME, "eb_metal")
    d.box("tray", (0.25, 0.16, 0.006), (-0.25, 0, -0.12), _shade(c, 0.8), "eb_wood", collide=False)


_BOOK_COLORS = ((0.7, 0.12, 0.1), (0.1, 0.25, 0.6), (0.15, 0.45, 0.2), (0.85, 0.7, 0.2), (0.35, 0.2, 0.45),
                (0.9, 0.9, 0.85), (0.1, 0.1, 0.12), (0.8, 0.4, 0.1), (0.2, 0.55, 0.6), (0.6, 0.15, 0.3))
_SHELF_Z = (0.06, 0.48, 0.9, 1.32)


@_register("Bookshelf", "furniture", ("walnut", "oak", "white", "black"), (0.16, 0.45), 1.8, mount="floor",
           surfaces=tuple(S(f"shelf_{i}", z + 0.012, (0.12, 0.16), (0.0, 0.24), clearance=0.38)
                          for i, z in enumerate(_SHELF_Z)) + (S("top", 1.8, (0.13, 0.4)),))
def _bookshelf(p: Parts, c: RGB) -> None:
    for sy in (-1, 1):
        p.box("side", (0.16, 0.015, 0.9), (0, sy * 0.435, 0.9), c, "eb_wood")
    p.box("back", (0.006, 0.42, 0.9), (-0.152, 0, 0.9), _shade(c, 0.75), "eb_wood")
    p.box("top", (0.16, 0.45, 0.015), (0, 0, 1.785), c, "eb_wood")
    p.box("plinth", (0.01, 0.42, 0.03), (0.15, 0, 0.03), _shade(c, 0.8), "eb_wood")
    rng = np.random.default_rng(7)
    for z in _SHELF_Z:
        p.box("shelf", (0.155, 0.42, 0.012), (0, 0, z), c, "eb_wood")
        y = -0.41
        while True:
            w = float(rng.uniform(0.012, 0.024))
            if y + 2 * w > 0.06:
                break
            h = float(rng.uniform(0.1, 0.15))
            d = float(rng.uniform(0.08, 0.11))
            col = _BOOK_COLORS[int(rng.integers(len(_BOOK_COLORS)))]
            p.box("book", (d, w, h), (0.14 - d, y + w, z + 0.012 + h), col, "eb_plastic", collide=False)
            y += 2 * w + 0.002
        if z < 1.0:
            p.box("book_flat", (0.09, 0.12, 0.02), (0.03, 0.3, z + 0.032), _BOOK_COLORS[int(rng.integers(10))],
                  "eb_plastic", collide=False)


@_register("Cabinet", "furniture", ("white", "wood", "gray", "navy", "green"), (0.23, 0.3), 0.9, mount="floor",
           surfaces=(S("top", 0.9, (0.2, 0.27)), S("interior", 0.098, (0.17, 0.25), (-0.01, 0.0), True, 0.37),
                     S("shelf", 0.489, (0.17, 0.25), (-0.01, 0.0), True, 0.38)), articulations=("door",))
def _cabinet(p: Parts, c: RGB) -> None:
    mat = "eb_wood" if c == (0.62, 0.43, 0.26) else "eb_plastic"
    inner = _shade(c, 1.15)
    p.box("plinth", (0.2, 0.28, 0.04), (-0.01, 0, 0.04), _DARK, "eb_matte")
    p.box("bottom", (0.215, 0.3, 0.009), (0, 0, 0.089), inner, mat)
    p.box("top", (0.225, 0.3, 0.01), (0, 0, 0.89), c, mat)
    for sy in (-1, 1):
        p.box("side", (0.215, 0.009, 0.4), (0, sy * 0.291, 0.48), c, mat)
    p.box("back", (0.009, 0.3, 0.4), (-0.206, 0, 0.48), inner, mat)
    p.box("shelf", (0.2, 0.28, 0.009), (-0.01, 0, 0.48), inner, mat)
    d = p.hinge("door", (0.215, -0.3, 0.0), (0, 0, -1), 110)
    d.box("panel", (0.01, 0.3, 0.4), (0.01, 0.3, 0.48), c, mat)
    d.box("inset", (0.002, 0.25, 0.34), (0.021, 0.3, 0.48), _shade(c, 0.92), mat, collide=False)
    d.cap_ft("handle", (0.045, 0.54, 0.55), (0.045, 0.54, 0.75), 0.008, _CHROME, "eb_metal")
    for z in (0.58, 0.72):
        d.cyl_ft("standoff", (0.02, 0.54, z), (0.045, 0.54, z), 0.005, _CHROME, "eb_metal")


@_register("Dresser", "furniture", ("white", "wood", "walnut", "gray"), (0.23, 0.45), 0.86, mount="floor",
           surfaces=(S("top", 0.86, (0.2, 0.42)),), articulations=("drawer_0", "drawer_1", "drawer_2"))
def _dresser(p: Parts, c: RGB) -> None:
    mat = "eb_plastic" if c in ((0.93, 0.93, 0.91), (0.5, 0.5, 0.52)) else "eb_wood"
    p.box("body", (0.21, 0.44, 0.39), (-0.015, 0, 0.44), c, mat)
    p.box("top", (0.235, 0.46, 0.015), (0, 0, 0.845), _shade(c, 0.85), mat)
    _legs(p, 0.19, 0.4, 0.05, 0.025, _shade(c, 0.7))
    for i, z in enumerate((0.19, 0.44, 0.69)):
        d = p.slide(f"drawer_{i}", (0.195, 0, z), (1, 0, 0), 0.3)
        d.box("front", (0.012, 0.42, 0.115), (0.012, 0, 0), _shade(c, 1.06), mat)
        for sy in (-1, 1):
            d.cyl("knob", 0.015, 0.012, (0.036, sy * 0.22, 0), _CHROME, "eb_metal", rot=(0, 90, 0))
        d.box("tray", (0.18, 0.4, 0.006), (-0.18, 0, -0.09), _shade(c, 0.8), mat, collide=False)


@_register("TVStand", "furniture", ("walnut", "white", "black", "oak"), (0.21, 0.75), 0.5, mount="floor",
           surfaces=(S("top", 0.5, (0.18, 0.7)),))
def _tv_stand(p: Parts, c: RGB) -> None:
    p.box("top", (0.21, 0.75, 0.02), (0, 0, 0.48), c, "eb_wood")
    p.box("bottom", (0.2, 0.74, 0.015), (0, 0, 0.1), c, "eb_wood")
    p.box("back", (0.008, 0.72, 0.18), (-0.19, 0, 0.28), _DARK, "eb_matte")
    for y in (-0.74, -0.25, 0.25, 0.74):
        p.box("divider", (0.2, 0.012, 0.18), (0, y, 0.28), c, "eb_wood")
    for sy in (-1, 1):
        p.box("door", (0.01, 0.235, 0.17), (0.195, sy * 0.495, 0.285), _shade(c, 1.08), "eb_wood")
        p.cap_ft("handle", (0.215, sy * 0.3, 0.33), (0.215, sy * 0.3, 0.24), 0.006, _CHROME, "eb_metal")
    _legs(p, 0.17, 0.7, 0.085, 0.015, _DARK, "eb_metal", round_=True)


@_register("CounterTop", "furniture", ("white", "wood", "gray", "navy", "green"), (0.31, 0.6), 0.92,
           mount="floor", surfaces=(S("top", 0.92, (0.26, 0.55)),
                                    S("drawer", 0.685, (0.2, 0.24), (0.0225, -0.3), True, 0.18, part="drawer")),
           articulations=("drawer",))
def _counter(p: Parts, c: RGB) -> None:
    """Base cabinets under a stone worktop: two doors, a dummy drawer front on the right and a real drawer on the
    left, whose box has a floor (the ``drawer`` surface) and slides out with its contents."""
    mat = "eb_wood" if c == (0.62, 0.43, 0.26) else "eb_plastic"
    body = _shade(c, 0.95)
    p.box("plinth", (0.26, 0.59, 0.045), (-0.03, 0, 0.045), _DARK, "eb_matte")
    # the carcass, hollow where the drawer slides: lower part, right block, and the drawer bay's walls
    p.box("body", (0.285, 0.6, 0.275), (-0.02, 0, 0.365), body, mat)
    p.box("body_right", (0.285, 0.3, 0.12), (-0.02, 0.3, 0.76), body, mat)
    p.box("bay_side", (0.285, 0.01, 0.12), (-0.02, -0.59, 0.76), body, mat)
    p.box("bay_back", (0.01, 0.29, 0.12), (-0.295, -0.3, 0.76), body, mat)
    p.box("slab", (0.31, 0.61, 0.02), (0, 0, 0.9), _STONE, "eb_stone")
    for sy in (-1, 1):
        p.box("door", (0.008, 0.29, 0.26), (0.27, sy * 0.3, 0.36), c, mat)
        p.cap_ft("door_handle", (0.29, sy * 0.06, 0.48), (0.29, sy * 0.06, 0.56), 0.007, _CHROME, "eb_metal")
    # drawer fronts close the bay from the carcass to the worktop (no slit shows what is inside)
    p.box("front_right", (0.008, 0.29, 0.12), (0.27, 0.3, 0.76), c, mat)
    p.cap_ft("handle_right", (0.29, 0.24, 0.78), (0.29, 0.36, 0.78), 0.007, _CHROME, "eb_metal")
    d = p.slide("drawer", (0.265, -0.3, 0.76), (1, 0, 0), 0.35)
    d.box("front", (0.008, 0.29, 0.12), (0.008, 0, 0), c, mat)
    d.cap_ft("handle", (0.028, -0.06, 0.02), (0.028, 0.06, 0.02), 0.007, _CHROME, "eb_metal")
    inner = _shade(c, 0.8)
    d.box("tray", (0.2375, 0.27, 0.005), (-0.2425, 0, -0.08), inner, mat)
    for sy in (-1, 1):
        d.box("tray_side", (0.2375, 0.005, 0.065), (-0.2425, sy * 0.265, -0.02), inner, mat, collide=False)
    d.box("tray_back", (0.005, 0.26, 0.065), (-0.475, 0, -0.02), inner, mat, collide=False)


@_register("Shelf", "furniture", ("oak", "white", "black"), (0.16, 0.5), 1.23, mount="floor",
           surfaces=tuple(S(f"board_{i}", z + 0.012, (0.13, 0.45), clearance=0.36)
                          for i, z in enumerate((0.06, 0.45, 0.84))) + (S("top", 1.222, (0.13, 0.45)),))
def _shelf(p: Parts, c: RGB) -> None:
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.cyl("post", 0.013, 0.61, (sx * 0.145, sy * 0.485, 0.61), _DARK, "eb_metal")
    for z in (0.06, 0.45, 0.84, 1.21):
        p.box("board", (0.16, 0.5, 0.012), (0, 0, z), c, "eb_wood")
    for sy in (-1, 1):
        p.cyl_ft("brace", (-0.15, sy * 0.47, 0.07), (-0.15, -sy * 0.47, 1.2), 0.005, _DARK, "eb_metal",
                 collide=False)


# ============================================================ appliances


@_register("Fridge", "appliance", ("white", "silver", "black"), (0.36, 0.38), 1.8, mount="floor",
           surfaces=(S("shelf_0", 0.1, (0.26, 0.3), (-0.02, 0.0), True, 0.38),
                     S("shelf_1", 0.508, (0.26, 0.3), (-0.02, 0.0), True, 0.38),
                     S("shelf_2", 0.908, (0.26, 0.3), (-0.02, 0.0), True, 0.36),
                     S("freezer", 1.32, (0.26, 0.3), (-0.02, 0.0), True, 0.42),
                     S("top", 1.8, (0.3, 0.33))),
           articulations=("door", "freezer_door"))
def _fridge(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_glossy"
    liner = (0.95, 0.96, 0.97)
    p.box("back", (0.02, 0.38, 0.85), (-0.33, 0, 0.95), c, mat)
    for sy in (-1, 1):
        p.box("side", (0.34, 0.02, 0.85), (0.0, sy * 0.36, 0.95), c, mat)
        p.box("liner_side", (0.32, 0.002, 0.8), (-0.01, sy * 0.338, 0.95), liner, "eb_plastic", collide=False)
    p.box("bottom", (0.34, 0.36, 0.025), (0, 0, 0.075), c, mat)
    p.box("top", (0.34, 0.38, 0.02), (0, 0, 1.78), c, mat)
    p.box("divider", (0.32, 0.34, 0.02), (0, 0, 1.3), liner, "eb_plastic")
    p.box("liner_back", (0.002, 0.34, 0.8), (-0.308, 0, 0.95), liner, "eb_plastic", collide=False)
    p.box("kick", (0.02, 0.36, 0.025), (0.32, 0, 0.025), _DARK, "eb_matte")
    for z in (0.5, 0.9):
        p.box("shelf", (0.3, 0.33, 0.006), (-0.02, 0, z), _GLASS, "eb_glass")
    p.box("crisper", (0.25, 0.3, 0.06), (-0.03, 0, 0.16), (0.85, 0.92, 0.95, 0.6), "eb_glass", collide=False)
    p.sph("lamp", 0.025, (-0.2, 0, 1.26), (1, 1, 0.9), "eb_glow", collide=False)
    d = p.hinge("door", (0.34, -0.38, 0.0), (0, 0, -1), 110)
    d.box("panel", (0.025, 0.38, 0.6), (0.025, 0.38, 0.68), c, mat)
    d.box("liner", (0.02, 0.33, 0.55), (-0.02, 0.38, 0.68), liner, "eb_plastic", collide=False)
    for z in (0.35, 0.75, 1.05):
        d.box("bin", (0.03, 0.3, 0.04), (-0.07, 0.38, z), (0.8, 0.9, 0.95, 0.7), "eb_glass", collide=False)
    d.cap_ft("handle", (0.085, 0.7, 0.75), (0.085, 0.7, 1.2), 0.012, _CHROME, "eb_metal")
    for z in (0.8, 1.15):
        d.cyl_ft("standoff", (0.05, 0.7, z), (0.085, 0.7, z), 0.008, _CHROME, "eb_metal")
    f = p.hinge("freezer_door", (0.34, -0.38, 0.0), (0, 0, -1), 110)
    f.box("panel", (0.025, 0.38, 0.22), (0.025, 0.38, 1.55), c, mat)
    f.cap_ft("handle", (0.085, 0.7, 1.38), (0.085, 0.7, 1.6), 0.012, _CHROME, "eb_metal")
    for z in (1.42, 1.56):
        f.cyl_ft("standoff", (0.05, 0.7, z), (0.085, 0.7, z), 0.008, _CHROME, "eb_metal")
    f.box("badge", (0.002, 0.05, 0.012), (0.051, 0.2, 1.7), _GRAY, "eb_metal", collide=False)


@_register("Microwave", "appliance", ("black", "silver", "white"), (0.19, 0.26), 0.31,
           surfaces=(S("interior", 0.035, (0.12, 0.14), (-0.01, -0.07), True, 0.22), S("top", 0.31, (0.15, 0.2))),
           articulations=("door",), toggleable=True)
def _microwave(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_plastic"
    cavity = (0.82, 0.82, 0.8)
    p.box("bottom", (0.18, 0.25, 0.01), (0, 0, 0.02), c, mat)
    p.box("top", (0.18, 0.25, 0.01), (0, 0, 0.3), c, mat)
    p.box("back", (0.01, 0.25, 0.14), (-0.17, 0, 0.16), c, mat)
    p.box("left", (0.18, 0.008, 0.14), (0, -0.242, 0.16), c, mat)
    p.box("panel_block", (0.18, 0.06, 0.14), (0, 0.19, 0.16), c, mat)
    for part, half, pos in (("cav_floor", (0.16, 0.125, 0.002), (-0.005, -0.06, 0.031)),
                            ("cav_back", (0.002, 0.125, 0.13), (-0.158, -0.06, 0.16)),
                            ("cav_top", (0.16, 0.125, 0.002), (-0.005, -0.06, 0.289))):
        p.box(part, half, pos, cavity, "eb_matte", collide=False)
    p.cyl("turntable", 0.1, 0.003, (-0.01, -0.06, 0.036), _GLASS, "eb_glass", collide=False)
    p.sph("oven_light", 0.012, (-0.15, 0.05, 0.27), (1, 0.95, 0.7), "eb_plastic", collide=False)
    p.box("control", (0.003, 0.05, 0.13), (0.181, 0.19, 0.16), _DARK, "eb_plastic", collide=False)
    p.box("display", (0.002, 0.035, 0.015), (0.185, 0.19, 0.255), (0.2, 0.9, 0.4), "eb_glow", collide=False)
    for i in range(3):
        for j in range(3):
            p.cyl("button", 0.008, 0.003, (0.185, 0.165 + 0.025 * j, 0.21 - 0.03 * i), _GRAY, "eb_plastic",
                  rot=(0, 90, 0), collide=False)
    p.cyl("start_button", 0.014, 0.004, (0.185, 0.19, 0.09), (0.2, 0.6, 0.25), "eb_plastic", rot=(0, 90, 0),
          collide=False)
    d = p.hinge("door", (0.18, -0.25, 0.0), (0, 0, -1), 110)
    d.box("frame", (0.01, 0.19, 0.14), (0.01, 0.19, 0.16), c, mat)
    d.box("window", (0.003, 0.13, 0.095), (0.021, 0.17, 0.16), _DARK_GLASS, "eb_glass", collide=False)
    d.cap_ft("handle", (0.03, 0.355, 0.08), (0.03, 0.355, 0.24), 0.007, _shade(c, 0.7), "eb_plastic")
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.cyl("foot", 0.012, 0.007, (sx * 0.15, sy * 0.21, 0.007), _BLACK, "eb_rubber")


@_register("Stove", "appliance", ("white", "steel", "black"), (0.32, 0.38), 1.05, mount="floor",
           surfaces=(S("top", 0.92, (0.25, 0.34), (0.03, 0.0)),), articulations=("oven_door",), toggleable=True)
def _stove(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.62, 0.64, 0.67) else "eb_glossy"
    p.box("body", (0.3, 0.38, 0.41), (-0.02, 0, 0.49), c, mat)
    p.box("plinth", (0.29, 0.37, 0.04), (-0.02, 0, 0.04), _DARK, "eb_matte")
    p.box("cavity", (0.002, 0.33, 0.24), (0.281, 0, 0.4), (0.06, 0.06, 0.06), "eb_matte", collide=False)
    p.box("cooktop", (0.32, 0.38, 0.01), (0, 0, 0.91), (0.03, 0.03, 0.035), "eb_glass")
    for bx in (-0.12, 0.15):
        for by in (-0.18, 0.18):
            r = 1.0 if bx > 0 else 0.8
            p.mesh("burner", "burner", (bx, by, 0.921), (0.25, 0.25, 0.27), "eb_metal", stretch=(r, r, 1.0),
                   collide=False)
            p.cyl("burner_cap", 0.03 * r, 0.004, (bx, by, 0.922), (0.12, 0.12, 0.13), "eb_metal", collide=False)
    p.box("backsplash", (0.03, 0.38, 0.07), (-0.29, 0, 0.99), c, mat)
    for i, y in enumerate((-0.27, -0.15, 0.15, 0.27)):
        p.cyl("knob", 0.022, 0.012, (-0.255, y, 0.99), _DARK, "eb_plastic", rot=(0, 90, 0))
    p.box("clock", (0.002, 0.06, 0.018), (-0.259, 0, 0.99), (0.15, 0.9, 0.4), "eb_glow", collide=False)
    d = p.hinge("oven_door", (0.28, 0, 0.11), (0, 1, 0), 85)
    d.box("panel", (0.012, 0.36, 0.28), (0.012, 0, 0.28), c, mat)
    d.box("window", (0.003, 0.26, 0.15), (0.025, 0, 0.27), _DARK_GLASS, "eb_glass", collide=False)
    d.cap_ft("handle", (0.06, -0.3, 0.51), (0.06, 0.3, 0.51), 0.012, _CHROME, "eb_metal")
    for sy in (-1, 1):
        d.cyl_ft("standoff", (0.02, sy * 0.27, 0.51), (0.06, sy * 0.27, 0.51), 0.008, _CHROME, "eb_metal")


@_register("Toaster", "appliance", ("silver", "red", "white", "black"), (0.09, 0.15), 0.22, toggleable=True)
def _toaster(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_glossy"
    p.box("body", (0.085, 0.14, 0.075), (0, 0, 0.085), c, mat)
    p.box("upper", (0.06, 0.14, 0.025), (0, 0, 0.175), c, mat)
    for sx in (-1, 1):
        p.cyl_ft("edge", (sx * 0.06, -0.14, 0.16), (sx * 0.06, 0.14, 0.16), 0.025, c, mat)
    for sx in (-1, 1):
        p.box("slot", (0.009, 0.1, 0.002), (sx * 0.028, 0, 0.2), _BLACK, "eb_matte", collide=False)
        p.box("toast", (0.006, 0.075, 0.04), (sx * 0.028, 0, 0.2), (0.82, 0.58, 0.3), "eb_matte")
        p.box("crust", (0.0065, 0.077, 0.004), (sx * 0.028, 0, 0.24), (0.55, 0.32, 0.12), "eb_matte",
              collide=False)
    p.box("base", (0.09, 0.145, 0.008), (0, 0, 0.008), _DARK, "eb_plastic")
    p.box("lever_slot", (0.03, 0.002, 0.05), (0.0, 0.141, 0.11), _DARK, "eb_matte", collide=False)
    p.box("lever", (0.018, 0.012, 0.008), (0.0, 0.153, 0.15), _BLACK, "eb_plastic")
    p.cyl("dial", 0.014, 0.005, (0.0, 0.145, 0.06), _BLACK, "eb_plastic", rot=(90, 0, 0))


@_register("CoffeeMachine", "appliance", ("black", "silver", "red"), (0.15, 0.12), 0.4, toggleable=True)
def _coffee_machine(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_glossy"
    p.box("base", (0.15, 0.12, 0.015), (0, 0, 0.015), c, mat)
    p.box("tray", (0.07, 0.08, 0.004), (0.06, 0, 0.033), _DARK, "eb_metal", collide=False)
    p.box("tower", (0.07, 0.12, 0.18), (-0.08, 0, 0.21), c, mat)
    p.box("head", (0.15, 0.12, 0.035), (0, 0, 0.36), c, mat)
    p.box("tank", (0.04, 0.1, 0.14), (-0.16, 0, 0.22), (0.7, 0.85, 0.95, 0.45), "eb_glass", collide=False)
    p.cyl("spout", 0.02, 0.015, (0.06, 0, 0.315), _DARK, "eb_metal")
    p.mesh("carafe", "carafe", (0.06, 0, 0.037), (0.75, 0.85, 0.9, 0.45), "eb_glass")
    p.cyl("coffee", 0.047, 0.03, (0.06, 0, 0.072), (0.18, 0.08, 0.03), "eb_glossy", collide=False)
    p.cap_ft("carafe_handle", (0.06, 0.075, 0.06), (0.06, 0.075, 0.15), 0.01, _BLACK, "eb_plastic")
    p.box("display", (0.002, 0.05, 0.012), (0.151, 0, 0.37), (0.3, 0.8, 1.0), "eb_glow", collide=False)
    for y in (-0.07, 0.07):
        p.cyl("button", 0.01, 0.003, (0.152, y, 0.36), (0.9, 0.9, 0.9), "eb_plastic", rot=(0, 90, 0),
              collide=False)


@_register("Television", "appliance", ("black", "silver"), (0.12, 0.58), 0.78, toggleable=True)
def _television(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_glossy"
    p.box("foot", (0.11, 0.22, 0.01), (0, 0, 0.01), c, mat)
    p.box("neck", (0.015, 0.04, 0.07), (-0.02, 0, 0.08), c, mat)
    p.box("panel", (0.025, 0.58, 0.33), (-0.01, 0, 0.45), c, mat)
    p.box("screen", (0.002, 0.56, 0.31), (0.016, 0, 0.455), _SCREEN, "eb_screen")
    p.box("screen_sky", (0.001, 0.54, 0.13), (0.0185, 0, 0.6), (0.35, 0.6, 0.9), "eb_screen", collide=False)
    p.ell("screen_hill", (0.001, 0.4, 0.12), (0.0185, -0.15, 0.27), (0.2, 0.6, 0.25), "eb_screen",
          collide=False)
    p.box("logo", (0.002, 0.03, 0.006), (0.016, 0, 0.135), _GRAY, "eb_metal", collide=False)


@_register("Laptop", "appliance", ("silver", "black", "white"), (0.13, 0.17), 0.25, movable=True,
           articulations=("lid",), default_open={"lid": 0.9}, toggleable=True)
def _laptop(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_plastic"
    p.box("base", (0.12, 0.17, 0.009), (0, 0, 0.009), c, mat)
    p.box("keyboard", (0.055, 0.145, 0.001), (-0.03, 0, 0.0185), _DARK, "eb_matte", collide=False)
    for i in range(5):
        p.box("key_row", (0.004, 0.14, 0.0005), (-0.075 + 0.022 * i, 0, 0.02), (0.35, 0.35, 0.37),
              "eb_plastic", collide=False)
    p.box("touchpad", (0.03, 0.045, 0.0008), (0.075, 0, 0.0185), _shade(c, 0.85), "eb_plastic", collide=False)
    lid = p.hinge("lid", (-0.118, 0, 0.019), (0, -1, 0), 115)
    lid.box("lid", (0.118, 0.17, 0.005), (0.118, 0, 0.005), c, mat)
    lid.box("bezel", (0.114, 0.165, 0.0005), (0.118, 0, -0.0005), _BLACK, "eb_plastic", collide=False)
    lid.box("screen", (0.1, 0.15, 0.0006), (0.12, 0, -0.0011), (0.25, 0.45, 0.8), "eb_screen", collide=False)
    lid.box("window", (0.05, 0.07, 0.0004), (0.15, -0.04, -0.0018), (0.92, 0.92, 0.95), "eb_screen",
            collide=False)


@_register("DeskLamp", "appliance", ("black", "white", "green", "red"), (0.1, 0.09), 0.42, toggleable=True)
def _desk_lamp(p: Parts, c: RGB) -> None:
    p.cyl("base", 0.085, 0.012, (0, 0, 0.012), c, "eb_glossy")
    p.mesh("arm", "lamp_arm", (0, 0, 0), c, "eb_glossy")
    p.sph("joint", 0.018, (-0.02, 0, 0.34), _CHROME, "eb_metal")
    p.mesh("shade", "lamp_shade", (0.16, 0, 0.375), c, "eb_glossy", rot=(0, 150, 0))
    p.sph("bulb", 0.02, (0.19, 0, 0.33), (1.0, 0.95, 0.75), "eb_glow", collide=False)
    p.light("light", (0.2, 0, 0.31), (0.5, 0, -0.87), (0.55, 0.5, 0.4), cutoff=60)


@_register("FloorLamp", "appliance", ("cream", "white", "black"), (0.22, 0.22), 1.75, mount="floor",
           toggleable=True)
def _floor_lamp(p: Parts, c: RGB) -> None:
    p.cyl("base", 0.16, 0.015, (0, 0, 0.015), _DARK, "eb_metal")
    p.cyl("pole", 0.013, 0.72, (0, 0, 0.74), (0.7, 0.6, 0.35), "eb_metal")
    p.mesh("shade", "floor_shade", (0, 0, 1.42), _rgba_a(c, 0.95), "eb_fabric")
    p.sph("bulb", 0.04, (0, 0, 1.5), (1.0, 0.95, 0.75), "eb_glow", collide=False)
    p.light("light", (0, 0, 1.6), (0, 0, -1), (0.5, 0.45, 0.35), cutoff=80)


def _rgba_a(c: tuple[float, ...], a: float) -> tuple[float, float, float, float]:
    return (c[0], c[1], c[2], a)


@_register("Sink", "appliance", ("white", "wood", "gray", "navy"), (0.28, 0.3), 1.1, mount="floor",
           surfaces=(S("basin", 0.78, (0.15, 0.2), (0.035, 0.0), True, 0.3),), toggleable=True)
def _sink(p: Parts, c: RGB) -> None:
    """A kitchen sink unit: a cabinet under a stone worktop with a deep rectangular steel basin (the ``basin``
    surface is its floor, 14 cm below the worktop) and a mixer tap whose stream shows when it is on."""
    mat = "eb_wood" if c == (0.62, 0.43, 0.26) else "eb_plastic"
    body = _shade(c, 0.95)
    p.box("plinth", (0.24, 0.28, 0.04), (-0.02, 0, 0.04), _DARK, "eb_matte")
    p.box("cabinet", (0.265, 0.3, 0.34), (-0.015, 0, 0.42), body, mat)  # stops below the basin
    for sy in (-1, 1):
        p.box("door", (0.008, 0.145, 0.36), (0.255, sy * 0.15, 0.47), c, mat)
        p.cap_ft("handle", (0.275, sy * 0.04, 0.62), (0.275, sy * 0.04, 0.74), 0.007, _CHROME, "eb_metal")
        p.box("side", (0.265, 0.01, 0.06), (-0.015, sy * 0.29, 0.82), body, mat)
    p.box("back", (0.01, 0.28, 0.06), (-0.27, 0, 0.82), body, mat)
    p.box("apron", (0.008, 0.3, 0.025), (0.25, 0, 0.855), c, mat)
    # worktop around the basin opening x in [x0, x1], y in [-y, y]
    x0, x1, y, top = -0.13, 0.2, 0.22, 0.92
    p.box("counter_front", ((0.285 - x1) / 2, 0.31, 0.02), ((0.285 + x1) / 2, 0, 0.9), _STONE, "eb_stone")
    p.box("counter_back", ((x0 + 0.285) / 2, 0.31, 0.02), ((x0 - 0.285) / 2, 0, 0.9), _STONE, "eb_stone")
    for sy in (-1, 1):
        p.box("counter_side", ((x1 - x0) / 2, (0.31 - y) / 2, 0.02), ((x0 + x1) / 2, sy * (0.31 + y) / 2, 0.9),
              _STONE, "eb_stone")
    floor = 0.78
    depth = (top - floor + 0.012) / 2
    zc = floor - 0.012 + depth
    p.box("basin", ((x1 - x0) / 2, y, 0.006), ((x0 + x1) / 2, 0, floor - 0.006), _CHROME, "eb_metal")
    for part, x in (("basin_front", x1 - 0.004), ("basin_back", x0 + 0.004)):
        p.box(part, (0.004, y, depth), (x, 0, zc), _STEEL, "eb_metal")
    for sy in (-1, 1):
        p.box("basin_side", ((x1 - x0) / 2, 0.004, depth), ((x0 + x1) / 2, sy * (y - 0.004), zc), _STEEL, "eb_metal")
    p.cyl("drain", 0.025, 0.001, ((x0 + x1) / 2, 0, floor + 0.001), _DARK, "eb_metal", collide=False)
    p.cyl("faucet_base", 0.022, 0.015, (-0.19, 0, 0.935), _CHROME, "eb_metal")
    p.mesh("faucet", "faucet", (-0.19, 0, 0.95), _CHROME, "eb_metal")
    p.cap_ft("faucet_lever", (-0.19, 0, 1.13), (-0.25, 0, 1.16), 0.007, _CHROME, "eb_metal")
    p.cyl("stream", 0.007, 0.145, (-0.07, 0, 0.925), (0.6, 0.8, 1.0, 0.0), "eb_glass", collide=False)


@_register("Toilet", "appliance", ("white", "cream"), (0.35, 0.21), 0.8, mount="floor",
           articulations=("lid",), default_open={"lid": 1.0})
def _toilet(p: Parts, c: RGB) -> None:
    p.mesh("bowl", "toilet_bowl", (0.1, 0, 0.0), c, "eb_glossy")
    p.cyl("water", 0.07, 0.001, (0.11, 0, 0.24), (0.62, 0.8, 0.9), "eb_glass", collide=False)
    p.mesh("seat", "toilet_seat", (0.1, 0, 0.39), c, "eb_glossy", stretch=(1.12, 0.9, 1.0))
    p.box("tank", (0.09, 0.2, 0.17), (-0.24, 0, 0.57), c, "eb_glossy")
    p.box("tank_lid", (0.1, 0.21, 0.015), (-0.24, 0, 0.755), c, "eb_glossy")
    p.cyl("flush", 0.015, 0.004, (-0.24, 0, 0.772), _CHROME, "eb_metal")
    p.box("tank_neck", (0.07, 0.1, 0.12), (-0.13, 0, 0.3), c, "eb_glossy")
    lid = p.hinge("lid", (-0.1, 0, 0.41), (0, -1, 0), 100)
    lid.mesh("lid", "pillow", (0.2, 0, 0.008), c, "eb_glossy", stretch=(1.0, 0.55, 0.12))


@_register("Bathtub", "appliance", ("white", "cream"), (0.38, 0.85), 0.58, mount="floor",
           surfaces=(S("basin", 0.08, (0.24, 0.68), (0.0, 0.03), True),))
def _bathtub(p: Parts, c: RGB) -> None:
    inner = _shade(c, 0.97)
    p.box("floor", (0.36, 0.84, 0.04), (0, 0, 0.04), c, "eb_glossy")
    p.box("bottom", (0.3, 0.77, 0.003), (0, 0.03, 0.081), (0.9, 0.93, 0.96), "eb_glossy", collide=False)
    for sx in (-1, 1):
        p.box("wall_long", (0.04, 0.85, 0.25), (sx * 0.34, 0, 0.33), c, "eb_glossy")
        p.cap_ft("rim_long", (sx * 0.34, -0.82, 0.58), (sx * 0.34, 0.82, 0.58), 0.045, c, "eb_glossy")
    for sy in (-1, 1):
        p.box("wall_end", (0.31, 0.04, 0.25), (0, sy * 0.81, 0.33), inner, "eb_glossy")
        p.cap_ft("rim_end", (-0.34, sy * 0.81, 0.58), (0.34, sy * 0.81, 0.58), 0.045, c, "eb_glossy")
    p.box("apron", (0.01, 0.85, 0.27), (0.385, 0, 0.28), _shade(c, 0.98), "eb_glossy")
    p.cyl("drain", 0.025, 0.002, (0, -0.62, 0.085), _STEEL, "eb_metal", collide=False)
    p.cyl("spout_base", 0.02, 0.02, (0, -0.83, 0.64), _CHROME, "eb_metal")
    p.cap_ft("spout", (0, -0.83, 0.66), (0, -0.7, 0.66), 0.014, _CHROME, "eb_metal")
    for sx in (-1, 1):
        p.cyl("tap", 0.022, 0.02, (sx * 0.12, -0.83, 0.645), _CHROME, "eb_metal")


@_register("WashingMachine", "appliance", ("white", "silver", "black"), (0.31, 0.3), 0.86, mount="floor",
           surfaces=(S("top", 0.86, (0.26, 0.26)),), articulations=("door",), toggleable=True)
def _washing_machine(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_glossy"
    p.box("body", (0.29, 0.3, 0.42), (-0.01, 0, 0.43), c, mat)
    p.box("top", (0.3, 0.3, 0.008), (0, 0, 0.852), _shade(c, 0.97), mat)
    p.box("panel", (0.005, 0.29, 0.055), (0.282, 0, 0.77), (0.82, 0.82, 0.84), "eb_plastic", collide=False)
    p.box("drawer", (0.004, 0.08, 0.035), (0.288, -0.19, 0.77), (0.7, 0.7, 0.72), "eb_plastic", collide=False)
    p.cyl("knob", 0.03, 0.012, (0.29, 0.18, 0.77), _CHROME, "eb_metal", rot=(0, 90, 0))
    p.box("display", (0.003, 0.05, 0.02), (0.288, 0.04, 0.77), (0.1, 0.2, 0.25), "eb_screen", collide=False)
    p.cyl("drum", 0.16, 0.002, (0.281, 0, 0.42), (0.25, 0.25, 0.27), "eb_metal", rot=(0, 90, 0), collide=False)
    d = p.hinge("door", (0.28, -0.2, 0.42), (0, 0, -1), 100)
    d.mesh("ring", "washer_ring", (0.02, 0.2, 0), _CHROME, "eb_metal")
    d.cyl("glass", 0.155, 0.008, (0.02, 0.2, 0), (0.15, 0.2, 0.25, 0.8), "eb_glass", rot=(0, 90, 0))
    d.cap_ft("handle", (0.045, 0.345, -0.05), (0.045, 0.345, 0.05), 0.012, _DARK, "eb_plastic")


# ============================================================ food


@_register("Apple", "food", ("red", "green", "yellow"), (0.04, 0.04), 0.09, movable=True)
def _apple(p: Parts, c: RGB) -> None:
    p.mesh("fruit", "apple", (0, 0, 0), c, "eb_peel")
    p.cap_ft("stem", (0, 0, 0.064), (0.004, 0.002, 0.088), 0.0025, (0.35, 0.22, 0.1), "eb_matte", collide=False)
    p.ell("leaf", (0.017, 0.007, 0.0015), (0.015, 0.004, 0.083), _LEAF, "eb_plastic", rot=(0, -25, 20),
          collide=False)


@_register("Banana", "food", ("yellow", "green"), (0.06, 0.09), 0.04, movable=True)
def _banana(p: Parts, c: RGB) -> None:
    p.mesh("fruit", "banana", (0, 0, 0), c, "eb_plastic")
    for ang in (-55, 55):
        t = math.radians(ang)
        p.sph("tip", 0.005, (0.11 * math.sin(t), 0.11 * (1 - math.cos(t)) - 0.03, 0.018), (0.3, 0.22, 0.1),
              "eb_matte", collide=False)


@_register("Orange", "food", ("orange", "yellow", "lime"), (0.04, 0.04), 0.08, movable=True)
def _orange(p: Parts, c: RGB) -> None:
    p.sph("fruit", 0.039, (0, 0, 0.039), c, "eb_peel")
    p.cyl("stem", 0.005, 0.003, (0, 0, 0.078), (0.3, 0.45, 0.15), "eb_matte", collide=False)
    p.ell("leaf", (0.014, 0.006, 0.0015), (0.01, 0, 0.079), _LEAF, "eb_plastic", collide=False)


@_register("Bread", "food", ("tan", "brown", "cream"), (0.07, 0.13), 0.11, movable=True)
def _bread(p: Parts, c: RGB) -> None:
    p.mesh("loaf", "loaf", (0, 0, 0.036), c, "eb_matte")
    p.ell("crust", (0.058, 0.118, 0.045), (0, 0, 0.058), _shade(c, 0.78), "eb_matte")
    for y in (-0.07, 0.0, 0.07):
        z = 0.058 + 0.045 * math.sqrt(1 - (y / 0.118) ** 2) - 0.003
        p.ell("score", (0.035, 0.007, 0.0035), (0, y, z), _shade(c, 1.3), "eb_matte", rot=(0, 0, 30),
              collide=False)


@_register("Tomato", "food", ("red", "orange", "yellow"), (0.036, 0.036), 0.065, movable=True)
def _tomato(p: Parts, c: RGB) -> None:
    p.ell("fruit", (0.036, 0.036, 0.029), (0, 0, 0.029), c, "eb_glossy")
    for k in range(5):
        a = 72 * k
        p.ell("sepal", (0.014, 0.004, 0.002), (0.011 * math.cos(math.radians(a)), 0.011 * math.sin(math.radians(a)),
              0.0575), _LEAF, "eb_plastic", rot=(0, 0, a), collide=False)
    p.cyl("stem", 0.0025, 0.005, (0, 0, 0.062), (0.25, 0.45, 0.15), "eb_plastic", collide=False)


@_register("Potato", "food", ("brown", "tan", "dark_red"), (0.055, 0.04), 0.06, movable=True)
def _potato(p: Parts, c: RGB) -> None:
    p.ell("tuber", (0.05, 0.035, 0.029), (-0.01, 0, 0.029), c, "eb_peel")
    p.ell("lobe", (0.032, 0.03, 0.025), (0.03, 0.005, 0.027), c, "eb_peel")
    for pos in ((0.0, 0.03, 0.04), (0.04, -0.02, 0.035), (-0.04, -0.015, 0.045)):
        p.sph("eye", 0.003, pos, _shade(c, 0.55), "eb_matte", collide=False)


@_register("Lettuce", "food", ("green", "lime"), (0.09, 0.09), 0.15, movable=True)
def _lettuce(p: Parts, c: RGB) -> None:
    p.sph("heart", 0.068, (0, 0, 0.072), _shade(c, 1.35), "eb_plastic")
    for k in range(7):
        yaw = 360 * k / 7
        a = math.radians(yaw)
        p.ell("leaf", (0.055, 0.01, 0.07), (0.05 * math.cos(a), 0.05 * math.sin(a), 0.065), c, "eb_plastic",
              rot=(-22, 0, yaw + 90), collide=False)
    for k in range(5):
        yaw = 360 * k / 5 + 30
        a = math.radians(yaw)
        p.ell("inner_leaf", (0.04, 0.008, 0.05), (0.03 * math.cos(a), 0.03 * math.sin(a), 0.1), _shade(c, 1.2),
              "eb_plastic", rot=(-30, 0, yaw + 90), collide=False)


@_register("Egg", "food", ("white", "tan"), (0.022, 0.022), 0.058, movable=True)
def _egg(p: Parts, c: RGB) -> None:
    p.mesh("shell", "egg", (0, 0, 0), _shade(c, 1.02) if c[0] < 0.9 else (0.97, 0.95, 0.9), "eb_glossy")


@_register("WineBottle", "food", ("dark_green", "brown", "dark_red"), (0.038, 0.038), 0.32, movable=True)
def _wine_bottle(p: Parts, c: RGB) -> None:
    p.mesh("glass", "wine_bottle", (0, 0, 0), (c[0], c[1], c[2], 0.92), "eb_glass")
    p.cyl("label", 0.0392, 0.045, (0, 0, 0.11), _CREAM, "eb_matte", collide=False)
    p.cyl("label_band", 0.0394, 0.008, (0, 0, 0.13), (0.6, 0.1, 0.12), "eb_matte", collide=False)
    p.cyl("foil", 0.0158, 0.025, (0, 0, 0.297), (0.55, 0.08, 0.1), "eb_metal", collide=False)


# ============================================================ containers


@_register("Mug", "container", ("red", "blue", "white", "yellow", "green"), (0.045, 0.07), 0.1, movable=True,
           shapes={"tall": (0.95, 0.95, 1.45), "short": (1.1, 1.1, 0.65)},
           surfaces=(S("interior", 0.008, (0.02, 0.02), inside=True, clearance=0.09),))
def _mug(p: Parts, c: RGB) -> None:
    p.mesh("body", "mug_body", (0, 0, 0), c, "eb_glossy")
    p.mesh("handle", "mug_handle", (0, 0, 0), c, "eb_glossy")
    p.cyl("coffee", 0.035, 0.002, (0, 0, 0.08), (0.25, 0.12, 0.05), "eb_glossy", collide=False)


@_register("Cup", "container", ("blue", "white", "clear", "red"), (0.042, 0.042), 0.11, movable=True,
           surfaces=(S("interior", 0.006, (0.02, 0.02), inside=True, clearance=0.1),))
def _cup(p: Parts, c: RGB) -> None:
    if c == (0.75, 0.85, 0.9):
        p.mesh("body", "cup_body", (0, 0, 0), (0.75, 0.88, 0.95, 0.4), "eb_glass")
        p.cyl("water", 0.034, 0.03, (0, 0, 0.04), (0.55, 0.75, 0.95, 0.35), "eb_glass", collide=False)
    else:
        p.mesh("body", "cup_body", (0, 0, 0), c, "eb_glossy")
        p.cyl("band", 0.0395, 0.008, (0, 0, 0.07), _shade(c, 1.6), "eb_glossy", collide=False)


@_register("Bowl", "container", ("white", "blue", "red", "green"), (0.09, 0.09), 0.065, movable=True,
           shapes={"deep": (0.9, 0.9, 1.9), "shallow": (1.15, 1.15, 0.5)},
           surfaces=(S("interior", 0.012, (0.04, 0.04), inside=True),))
def _bowl(p: Parts, c: RGB) -> None:
    p.mesh("body", "bowl", (0, 0, 0), c, "eb_glossy")
    if c != (0.93, 0.93, 0.91):
        p.cyl("inside", 0.05, 0.001, (0, 0, 0.014), (0.95, 0.95, 0.93), "eb_glossy", collide=False)


@_register("Plate", "container", ("white", "blue", "cream", "green"), (0.125, 0.125), 0.025, movable=True,
           shapes={"round": (1.0, 1.0, 1.0), "square": (1.0, 1.0, 1.0)},
           surfaces=(S("top", 0.011, (0.06, 0.06)),))
def _plate(p: Parts, c: RGB) -> None:
    if p.shape == "square":  # a flat square dish with a raised rim
        p.box("body", (0.105, 0.105, 0.005), (0, 0, 0.005), c, "eb_glossy")
        for k in (-1, 1):
            p.box("rim_x", (0.008, 0.112, 0.008), (k * 0.104, 0, 0.012), c, "eb_glossy")
            p.box("rim_y", (0.098, 0.008, 0.008), (0, k * 0.104, 0.012), c, "eb_glossy")
        p.box("rim_band", (0.09, 0.09, 0.0008), (0, 0, 0.0105), _shade(c, 0.6), "eb_glossy", collide=False)
        return
    p.mesh("body", "plate", (0, 0, 0), c, "eb_glossy")
    p.mesh("rim_band", "burner", (0, 0, 0.02), _shade(c, 0.6), "eb_glossy", stretch=(1.55, 1.55, 0.4),
           collide=False)


@_register("Pot", "container", ("steel", "black", "red"), (0.13, 0.16), 0.15, movable=True,
           surfaces=(S("interior", 0.01, (0.07, 0.07), inside=True),))
def _pot(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.62, 0.64, 0.67) else "eb_glossy"
    p.mesh("body", "pot_body", (0, 0, 0), c, mat)
    p.cyl("inside", 0.1, 0.001, (0, 0, 0.011), _shade(c, 0.7), mat, collide=False)
    for sy in (-1, 1):
        p.cap_ft("handle", (0.03, sy * 0.125, 0.12), (-0.03, sy * 0.125, 0.12), 0.01, _BLACK, "eb_plastic")
        for sx in (-1, 1):
            p.cyl_ft("bracket", (sx * 0.03, sy * 0.105, 0.12), (sx * 0.03, sy * 0.125, 0.12), 0.006, _BLACK,
                     "eb_plastic")


@_register("Pan", "container", ("black", "steel", "red"), (0.14, 0.24), 0.06, movable=True,
           surfaces=(S("interior", 0.009, (0.07, 0.07), inside=True),))
def _pan(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.62, 0.64, 0.67) else "eb_glossy"
    p.mesh("body", "pan_body", (0, -0.09, 0), c, mat)
    p.cyl("coating", 0.103, 0.001, (0, -0.09, 0.0095), (0.08, 0.08, 0.09), "eb_glossy", collide=False)
    p.cap_ft("handle", (0, 0.05, 0.045), (0, 0.25, 0.06), 0.012, _BLACK, "eb_plastic")


@_register("Vase", "container", ("blue", "white", "green", "red"), (0.08, 0.08), 0.45, movable=True,
           shapes={"tall": (0.95, 0.95, 1.35), "short": (1.2, 1.2, 0.55)})
def _vase(p: Parts, c: RGB) -> None:
    p.mesh("body", "vase", (0, 0, 0), c, "eb_glossy")
    blossoms = ((0.9, 0.2, 0.25), (0.95, 0.85, 0.2), (0.95, 0.55, 0.7))
    for k, (dx, dy, top) in enumerate(((0.05, 0.0, 0.43), (-0.03, 0.045, 0.41), (-0.025, -0.045, 0.45))):
        p.cap_ft("stem", (0, 0, 0.25), (dx, dy, top), 0.003, _LEAF, "eb_plastic", collide=False)
        for j in range(5):
            a = math.radians(72 * j)
            p.sph("petal", 0.013, (dx + 0.014 * math.cos(a), dy + 0.014 * math.sin(a), top), blossoms[k],
                  "eb_plastic", collide=False)
        p.sph("centre", 0.01, (dx, dy, top + 0.004), (0.95, 0.8, 0.2), "eb_plastic", collide=False)


@_register("Box", "container", ("tan", "white", "brown"), (0.125, 0.18), 0.25, movable=True,
           surfaces=(S("interior", 0.006, (0.1, 0.15), inside=True, clearance=0.22),),
           articulations=("flap_front", "flap_back"))
def _box(p: Parts, c: RGB) -> None:
    t = 0.004
    p.box("bottom", (0.125, 0.175, t), (0, 0, t), _shade(c, 0.9), "eb_matte")
    for sx in (-1, 1):
        p.box("wall_x", (t, 0.175, 0.125), (sx * 0.121, 0, 0.125), c, "eb_matte")
    for sy in (-1, 1):
        p.box("wall_y", (0.117, t, 0.125), (0, sy * 0.171, 0.125), _shade(c, 0.95), "eb_matte")
    p.box("inside", (0.115, 0.165, 0.001), (0, 0, 0.009), _shade(c, 0.6), "eb_matte", collide=False)
    p.box("label", (0.001, 0.07, 0.04), (0.126, 0.06, 0.17), (0.97, 0.97, 0.95), "eb_matte", collide=False)
    p.box("arrow", (0.001, 0.01, 0.03), (0.126, -0.08, 0.16), _BLACK, "eb_matte", collide=False)
    front = p.hinge("flap_front", (0.125, 0, 0.25), (0, 1, 0), 200)
    front.box("flap", (0.0625, 0.175, 0.003), (-0.0625, 0, 0.003), c, "eb_matte")
    front.box("tape", (0.02, 0.17, 0.0006), (-0.02, 0, 0.0065), (0.85, 0.72, 0.5, 0.9), "eb_glossy",
              collide=False)
    back = p.hinge("flap_back", (-0.125, 0, 0.25), (0, -1, 0), 200)
    back.box("flap", (0.0625, 0.175, 0.003), (0.0625, 0, 0.003), c, "eb_matte")
    back.box("tape", (0.02, 0.17, 0.0006), (0.02, 0, 0.0065), (0.85, 0.72, 0.5, 0.9), "eb_glossy", collide=False)


@_register("GarbageCan", "container", ("gray", "white", "black", "blue", "green"), (0.16, 0.16), 0.4,
           mount="floor", surfaces=(S("interior", 0.03, (0.08, 0.08), inside=True),))
def _garbage_can(p: Parts, c: RGB) -> None:
    p.mesh("body", "garbage_can", (0, 0, 0), c, "eb_plastic")
    bag = (0.12, 0.12, 0.13) if c[0] > 0.15 else (0.3, 0.3, 0.32)
    p.mesh("bag_fold", "burner", (0, 0, 0.395), bag, "eb_glossy", stretch=(2.27, 2.27, 1.2), collide=False)
    p.cyl("bag", 0.15, 0.002, (0, 0, 0.25), bag, "eb_glossy", collide=False)
    p.box("pedal", (0.03, 0.05, 0.008), (0.15, 0, 0.02), _DARK, "eb_plastic")


@_register("Basket", "container", ("tan", "brown", "white"), (0.165, 0.125), 0.26, movable=True,
           surfaces=(S("interior", 0.012, (0.1, 0.07), inside=True),))
def _basket(p: Parts, c: RGB) -> None:
    p.mesh("body", "basket", (0, 0, 0), c, "eb_wicker")
    p.mesh("handle", "basket_handle", (0, 0, 0), _shade(c, 0.85), "eb_wicker")
    p.mesh("rim", "burner", (0, 0, 0.14), _shade(c, 0.8), "eb_wicker", stretch=(2.35, 1.78, 1.4), collide=False)


@_register("Kettle", "container", ("steel", "red", "white", "black"), (0.12, 0.1), 0.24, movable=True)
def _kettle(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.62, 0.64, 0.67) else "eb_glossy"
    p.mesh("body", "kettle_body", (0, 0, 0), c, mat)
    p.mesh("spout", "kettle_spout", (0, 0, 0), c, mat)
    p.mesh("handle", "kettle_handle", (0, 0, 0), _BLACK, "eb_plastic")
    p.cyl("lid", 0.05, 0.004, (0, 0, 0.168), _shade(c, 0.85), mat)
    p.sph("knob", 0.014, (0, 0, 0.18), _BLACK, "eb_plastic")


# ============================================================ tools and small things


@_register("Knife", "small", ("black", "wood", "red"), (0.14, 0.016), 0.018, movable=True)
def _knife(p: Parts, c: RGB) -> None:
    mat = "eb_wood" if c == (0.62, 0.43, 0.26) else "eb_plastic"
    p.box("handle", (0.05, 0.011, 0.008), (-0.07, 0, 0.008), c, mat)
    for x in (-0.1, -0.07, -0.04):
        p.cyl("rivet", 0.003, 0.0085, (x, 0, 0.008), _CHROME, "eb_metal", collide=False)
    p.box("bolster", (0.006, 0.012, 0.009), (-0.015, 0, 0.009), _CHROME, "eb_metal")
    p.mesh("blade", "knife_blade", (-0.01, 0, 0.006), (0.85, 0.87, 0.9), "eb_metal")


@_register("Spatula", "small", ("black", "red", "wood"), (0.15, 0.045), 0.02, movable=True)
def _spatula(p: Parts, c: RGB) -> None:
    mat = "eb_wood" if c == (0.62, 0.43, 0.26) else "eb_plastic"
    p.cap_ft("handle", (-0.15, 0, 0.01), (0.01, 0, 0.01), 0.01, c, mat)
    p.box("neck", (0.025, 0.008, 0.002), (0.035, 0, 0.006), _STEEL, "eb_metal")
    p.box("head", (0.045, 0.045, 0.002), (0.1, 0, 0.004), _shade(c, 1.1), mat)
    for y in (-0.02, 0, 0.02):
        p.box("slot", (0.03, 0.004, 0.0008), (0.1, y, 0.0062), _BLACK, "eb_matte", collide=False)


@_register("Book", "small", ("red", "blue", "green", "black", "yellow"), (0.082, 0.118), 0.034, movable=True,
           shapes={"thick": (1.0, 1.0, 2.2), "thin": (1.0, 1.0, 0.4)})
def _book(p: Parts, c: RGB) -> None:
    p.box("cover_bottom", (0.082, 0.118, 0.002), (0, 0, 0.002), c, "eb_plastic")
    p.box("cover_top", (0.082, 0.118, 0.002), (0, 0, 0.032), c, "eb_plastic")
    p.box("spine", (0.004, 0.118, 0.017), (-0.078, 0, 0.017), _shade(c, 0.85), "eb_plastic")
    p.box("pages", (0.077, 0.114, 0.013), (0.001, 0, 0.017), (0.96, 0.94, 0.86), "eb_matte")
    p.box("title", (0.04, 0.06, 0.0005), (0.01, 0, 0.0345), (0.95, 0.85, 0.4), "eb_plastic", collide=False)


@_register("CellPhone", "small", ("black", "white", "blue"), (0.038, 0.077), 0.009, movable=True)
def _cell_phone(p: Parts, c: RGB) -> None:
    p.box("body", (0.038, 0.077, 0.004), (0, 0, 0.004), c, "eb_glossy")
    p.box("screen", (0.034, 0.07, 0.0005), (0, 0, 0.0085), (0.15, 0.3, 0.55), "eb_screen", collide=False)
    icon = ((0.95, 0.35, 0.3), (0.3, 0.8, 0.4), (0.95, 0.8, 0.2), (0.4, 0.6, 0.95))
    for i in range(4):
        for j in range(3):
            p.box("icon", (0.006, 0.006, 0.0004), (-0.017 + 0.017 * j, 0.045 - 0.02 * i, 0.0092),
                  icon[(i + j) % 4], "eb_screen", collide=False)
    p.cyl("camera", 0.004, 0.001, (0.0, 0.073, 0.0085), _BLACK, "eb_glass", collide=False)


@_register("RemoteControl", "small", ("black", "gray", "white"), (0.026, 0.09), 0.022, movable=True)
def _remote(p: Parts, c: RGB) -> None:
    p.box("body", (0.024, 0.085, 0.009), (0, 0, 0.01), c, "eb_plastic")
    for sy in (-1, 1):
        p.cyl("end", 0.024, 0.009, (0, sy * 0.085, 0.01), c, "eb_plastic")
    p.cyl("power", 0.006, 0.002, (0.0, 0.085, 0.02), (0.85, 0.1, 0.1), "eb_plastic", collide=False)
    p.cyl("dpad", 0.013, 0.0015, (0, 0.045, 0.02), _GRAY if c[0] < 0.3 else _DARK, "eb_plastic", collide=False)
    for i in range(4):
        for j in range(3):
            p.box("button", (0.004, 0.0045, 0.0015), (-0.011 + 0.011 * j, 0.012 - 0.016 * i, 0.02),
                  (0.7, 0.7, 0.72) if c[0] < 0.3 else _DARK, "eb_plastic", collide=False)


@_register("KeyChain", "small", ("red", "blue", "black"), (0.05, 0.045), 0.012, movable=True)
def _keychain(p: Parts, c: RGB) -> None:
    p.mesh("ring", "ring_small", (0, 0, 0.002), _CHROME, "eb_metal")
    for k, (col, ang) in enumerate(((_CHROME, 20.0), ((0.85, 0.7, 0.3), -40.0))):
        a = math.radians(ang)
        ca, sa = math.cos(a), math.sin(a)
        bx, by = 0.024 * ca, 0.024 * sa
        p.cyl("key_bow", 0.011, 0.0015, (bx, by, 0.002), col, "eb_metal")
        p.box("key_blade", (0.022, 0.004, 0.0015), (bx + 0.03 * ca, by + 0.03 * sa, 0.002), col, "eb_metal",
              rot=(0, 0, ang))
        p.box("key_teeth", (0.012, 0.002, 0.0015), (bx + 0.035 * ca - 0.005 * sa, by + 0.035 * sa + 0.005 * ca,
              0.002), col, "eb_metal", rot=(0, 0, ang))
    p.ell("fob", (0.022, 0.013, 0.005), (-0.03, 0.0, 0.005), c, "eb_plastic", rot=(0, 0, 160))


@_register("Pen", "small", ("blue", "black", "red"), (0.072, 0.006), 0.012, movable=True)
def _pen(p: Parts, c: RGB) -> None:
    p.cap_ft("barrel", (-0.065, 0, 0.0055), (0.055, 0, 0.0055), 0.0055, (0.92, 0.92, 0.9), "eb_plastic")
    p.cyl_ft("cap", (-0.07, 0, 0.0058), (-0.02, 0, 0.0058), 0.0058, c, "eb_glossy")
    p.box("clip", (0.02, 0.0015, 0.001), (-0.045, 0, 0.0125), _CHROME, "eb_metal", collide=False)
    p.cyl_ft("tip", (0.058, 0, 0.0055), (0.07, 0, 0.0055), 0.002, c, "eb_plastic", collide=False)


@_register("Sponge", "small", ("yellow", "blue", "pink"), (0.05, 0.035), 0.032, movable=True)
def _sponge(p: Parts, c: RGB) -> None:
    p.box("foam", (0.05, 0.035, 0.012), (0, 0, 0.012), c, "eb_fabric")
    p.box("scrub", (0.05, 0.035, 0.004), (0, 0, 0.028), (0.1, 0.5, 0.2), "eb_fabric")


@_register("SoapBottle", "small", ("green", "blue", "pink", "white"), (0.04, 0.03), 0.21, movable=True)
def _soap_bottle(p: Parts, c: RGB) -> None:
    p.mesh("bottle", "soap_bottle", (0, 0, 0), (c[0], c[1], c[2], 0.9), "eb_glossy")
    p.box("label", (0.001, 0.02, 0.03), (0.0375, 0, 0.07), (0.97, 0.97, 0.95), "eb_matte", collide=False)
    p.cyl("collar", 0.015, 0.008, (0, 0, 0.156), _WHITE, "eb_plastic")
    p.cyl("stem", 0.004, 0.02, (0, 0, 0.18), _WHITE, "eb_plastic")
    p.cyl("head", 0.011, 0.007, (0, 0, 0.2), _WHITE, "eb_plastic")
    p.cap_ft("nozzle", (0.0, 0, 0.202), (0.032, 0, 0.198), 0.004, _WHITE, "eb_plastic")


@_register("Towel", "small", ("blue", "white", "pink", "green", "yellow"), (0.12, 0.16), 0.07, movable=True)
def _towel(p: Parts, c: RGB) -> None:
    for k in range(3):
        p.mesh("layer", "pillow", (0.004 * k, 0, 0.012 + 0.022 * k), _shade(c, 1.0 - 0.04 * (2 - k)), "eb_fabric",
               stretch=(0.6, 0.55, 0.17))
    p.box("stripe", (0.118, 0.012, 0.0015), (0.008, 0.1, 0.067), _shade(c, 0.7), "eb_fabric", collide=False)


@_register("Pillow", "small", ("blue", "white", "red", "yellow", "green"), (0.2, 0.3), 0.14, movable=True)
def _pillow(p: Parts, c: RGB) -> None:
    p.mesh("cushion", "pillow", (0, 0, 0.07), c, "eb_fabric")
    p.box("piping", (0.19, 0.29, 0.003), (0, 0, 0.07), _shade(c, 0.8), "eb_fabric", collide=False)


@_register("AlarmClock", "small", ("red", "black", "blue", "silver"), (0.04, 0.07), 0.16, movable=True)
def _alarm_clock(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.75, 0.77, 0.8) else "eb_glossy"
    p.cyl("case", 0.055, 0.025, (0, 0, 0.075), c, mat, rot=(0, 90, 0))
    p.cyl("face", 0.047, 0.001, (0.026, 0, 0.075), (0.97, 0.97, 0.93), "eb_plastic")
    for k in range(12):
        a = math.radians(30 * k)
        p.box("tick", (0.0005, 0.0015, 0.005 if k % 3 == 0 else 0.003),
              (0.0275, 0.039 * math.sin(a), 0.075 + 0.039 * math.cos(a)), _BLACK, "eb_matte", rot=(-30 * k, 0, 0),
              collide=False)
    p.box("hour_hand", (0.0006, 0.002, 0.018), (0.028, 0.009, 0.085), _BLACK, "eb_matte", rot=(-60, 0, 0),
          collide=False)
    p.box("minute_hand", (0.0006, 0.0015, 0.028), (0.028, -0.01, 0.095), _BLACK, "eb_matte", rot=(20, 0, 0),
          collide=False)
    p.cyl("pin", 0.004, 0.002, (0.029, 0, 0.075), (0.8, 0.1, 0.1), "eb_metal", rot=(0, 90, 0), collide=False)
    for sy in (-1, 1):
        p.mesh("bell", "bell", (0, sy * 0.033, 0.123), _CHROME, "eb_metal", rot=(sy * -30, 0, 0))
        p.cap_ft("leg", (0, sy * 0.03, 0.03), (0, sy * 0.045, 0.004), 0.005, _CHROME, "eb_metal")
    p.cap_ft("hammer", (0, 0, 0.13), (0, 0, 0.152), 0.003, _CHROME, "eb_metal", collide=False)


@_register("Candle", "small", ("white", "red", "yellow"), (0.055, 0.055), 0.15, movable=True)
def _candle(p: Parts, c: RGB) -> None:
    p.mesh("holder", "candle_holder", (0, 0, 0), (0.8, 0.65, 0.3), "eb_metal")
    p.cyl("wax", 0.026, 0.05, (0, 0, 0.065), c if c != (0.93, 0.93, 0.91) else (0.97, 0.95, 0.88), "eb_plastic")
    p.cyl("wick", 0.0012, 0.006, (0, 0, 0.121), _BLACK, "eb_matte", collide=False)
    p.ell("flame", (0.007, 0.007, 0.016), (0, 0, 0.138), (1.0, 0.75, 0.25), "eb_glow", collide=False)
    p.ell("flame_core", (0.004, 0.004, 0.008), (0, 0, 0.132), (1.0, 1.0, 0.85), "eb_glow", collide=False)


@_register("HousePlant", "small", ("terracotta", "white", "blue"), (0.15, 0.15), 0.65, mount="floor")
def _house_plant(p: Parts, c: RGB) -> None:
    p.mesh("pot", "plant_pot", (0, 0, 0), c, "eb_matte" if c == (0.72, 0.36, 0.22) else "eb_glossy")
    p.cyl("soil", 0.115, 0.004, (0, 0, 0.205), (0.22, 0.15, 0.09), "eb_matte", collide=False)
    rng = np.random.default_rng(3)
    for k in range(14):
        yaw = 360 * k / 14 + float(rng.uniform(-10, 10))
        height = 0.3 + 0.28 * float(rng.uniform(0, 1))
        lean = float(rng.uniform(10, 35))
        a = math.radians(yaw)
        r = 0.05 + 0.04 * float(rng.uniform(0, 1))
        tip = (r * math.cos(a), r * math.sin(a), height)
        p.cap_ft("stem", (0.01 * math.cos(a), 0.01 * math.sin(a), 0.2), tip, 0.003, (0.25, 0.45, 0.15),
                 "eb_plastic", collide=False)
        p.ell("leaf", (0.075, 0.03, 0.004), (tip[0] + 0.05 * math.cos(a), tip[1] + 0.05 * math.sin(a), tip[2]),
              _shade(_LEAF, 0.8 + 0.5 * float(rng.uniform(0, 1))), "eb_glossy", rot=(0, -lean, yaw), collide=False)


@_register("Painting", "small", ("gold", "black", "wood", "white"), (0.03, 0.45), 0.66, mount="wall")
def _painting(p: Parts, c: RGB) -> None:
    mat = "eb_metal" if c == (0.83, 0.66, 0.25) else "eb_wood"
    w, h, t = 0.45, 0.33, 0.03
    for sy in (-1, 1):
        p.box("frame_v", (t / 2 + 0.005, 0.03, h), (t / 2, sy * (w - 0.03), h), c, mat)
    for z in (0.03, 2 * h - 0.03):
        p.box("frame_h", (t / 2 + 0.005, w, 0.03), (t / 2, 0, z), c, mat)
    p.box("sky", (0.004, w - 0.055, h - 0.055), (0.012, 0, h), (0.55, 0.75, 0.95), "eb_matte")
    p.mesh("mountain", "mountain", (0.018, 0.06, h - 0.1), (0.45, 0.45, 0.55), "eb_matte",
           xyaxes=(0, 1, 0, 0, 0, 1), stretch=(1.1, 1.0, 1.0), collide=False)
    p.ell("hill", (0.004, 0.3, 0.1), (0.02, -0.1, 0.13), (0.3, 0.62, 0.25), "eb_matte", collide=False)
    p.ell("hill2", (0.004, 0.25, 0.08), (0.021, 0.18, 0.12), (0.22, 0.5, 0.2), "eb_matte", collide=False)
    p.box("meadow", (0.004, w - 0.055, 0.05), (0.021, 0, 0.1), (0.35, 0.65, 0.28), "eb_matte", collide=False)
    p.cyl("sun", 0.04, 0.002, (0.02, -0.25, 0.5), (1.0, 0.85, 0.3), "eb_matte", rot=(0, 90, 0), collide=False)


@_register("TeddyBear", "small", ("brown", "tan", "white", "pink"), (0.12, 0.13), 0.32, movable=True)
def _teddy(p: Parts, c: RGB) -> None:
    light = _shade(c, 1.35)
    p.ell("body", (0.075, 0.085, 0.1), (0, 0, 0.1), c, "eb_fabric")
    p.ell("belly", (0.02, 0.055, 0.065), (0.06, 0, 0.095), light, "eb_fabric", collide=False)
    p.sph("head", 0.068, (0.01, 0, 0.245), c, "eb_fabric")
    for sy in (-1, 1):
        p.sph("ear", 0.026, (0.0, sy * 0.055, 0.3), c, "eb_fabric")
        p.ell("inner_ear", (0.008, 0.016, 0.016), (0.02, sy * 0.056, 0.3), light, "eb_fabric", collide=False)
        p.sph("eye", 0.009, (0.062, sy * 0.026, 0.265), _BLACK, "eb_glossy", collide=False)
        p.ell("arm", (0.03, 0.03, 0.06), (0.03, sy * 0.085, 0.13), c, "eb_fabric", rot=(sy * 25, -20, 0))
        p.ell("leg", (0.065, 0.035, 0.035), (0.07, sy * 0.05, 0.035), c, "eb_fabric")
        p.cyl("foot_pad", 0.026, 0.003, (0.133, sy * 0.05, 0.037), light, "eb_fabric", rot=(0, 90, 0),
              collide=False)
    p.ell("snout", (0.03, 0.034, 0.024), (0.062, 0, 0.228), light, "eb_fabric")
    p.sph("nose", 0.011, (0.09, 0, 0.236), _BLACK, "eb_glossy", collide=False)


@_register("BasketBall", "small", ("orange",), (0.12, 0.12), 0.24, movable=True)
def _basketball(p: Parts, c: RGB) -> None:
    p.sph("ball", 0.12, (0, 0, 0.12), (0.85, 0.38, 0.1), "eb_peel")
    for rot in ((0, 0, 0), (90, 0, 0), (0, 90, 0)):
        p.mesh("seam", "ball_seam", (0, 0, 0.12), (0.08, 0.05, 0.04), "eb_matte", rot=rot, collide=False)


# ============================================================ household extras (first drawn for EB-ALFRED)


@_register("Drawer", "furniture", ("wood", "white", "walnut", "oak", "gray"), (0.24, 0.25), 0.58, mount="floor",
           surfaces=(S("top", 0.58, (0.2, 0.22)),
                     S("interior", 0.377, (0.16, 0.18), (0.02, 0.0), True, 0.08, part="drawer")),
           articulations=("drawer",))
def _drawer(p: Parts, c: RGB) -> None:
    """A low chest with one pull-out drawer at the top (a drawer you can walk up to)."""
    p.box("plinth", (0.2, 0.22, 0.03), (-0.01, 0, 0.03), _DARK, "eb_matte")
    p.box("carcass", (0.22, 0.24, 0.25), (-0.02, 0, 0.31), c, "eb_wood")
    p.box("top", (0.235, 0.25, 0.012), (-0.01, 0, 0.572), c, "eb_wood")
    d = p.slide("drawer", (0, 0, 0), (1, 0, 0), 0.3)
    d.box("front", (0.012, 0.23, 0.1), (0.215, 0, 0.45), tuple(min(1.0, v * 1.1) for v in c), "eb_wood")
    d.box("floor", (0.2, 0.21, 0.006), (0.02, 0, 0.37), _shade(c, 0.8), "eb_wood")
    for sy in (-1, 1):
        d.box("wall", (0.2, 0.006, 0.05), (0.02, sy * 0.21, 0.42), _shade(c, 0.8), "eb_wood")
    d.box("back", (0.006, 0.21, 0.05), (-0.18, 0, 0.42), _shade(c, 0.8), "eb_wood")
    d.cap_ft("handle", (0.245, -0.07, 0.45), (0.245, 0.07, 0.45), 0.009, _CHROME, "eb_metal")
    p.box("lower_front", (0.004, 0.23, 0.13), (0.205, 0, 0.19), _shade(c, 0.92), "eb_wood", collide=False)


@_register("Safe", "furniture", ("dark_gray", "gray", "black", "steel"), (0.21, 0.23), 0.4, mount="floor",
           surfaces=(S("interior", 0.035, (0.14, 0.16), (0.03, 0.0), True, 0.3), S("top", 0.4, (0.18, 0.2))),
           articulations=("door",))
def _safe(p: Parts, c: RGB) -> None:
    p.box("body", (0.2, 0.22, 0.2), (0, 0, 0.2), c, "eb_metal")
    p.box("inside", (0.17, 0.19, 0.17), (0.03, 0, 0.2), _DARK, "eb_matte", collide=False)
    d = p.hinge("door", (0.2, -0.22, 0.0), (0, 0, -1), 100)
    d.box("panel", (0.012, 0.22, 0.2), (0.012, 0.22, 0.2), _shade(c, 0.85), "eb_metal")
    d.cyl_ft("dial", (0.024, 0.22, 0.24), (0.04, 0.22, 0.24), 0.045, _CHROME, "eb_metal")
    d.cap_ft("handle", (0.045, 0.36, 0.14), (0.045, 0.36, 0.26), 0.01, _CHROME, "eb_metal")


@_register("Ottoman", "furniture", ("beige", "gray", "blue", "green", "red"), (0.3, 0.3), 0.42, mount="floor",
           surfaces=(S("top", 0.42, (0.25, 0.25)),))
def _ottoman(p: Parts, c: RGB) -> None:
    """An upholstered footstool: a padded box with a soft, buttoned top."""
    p.box("cushion", (0.29, 0.29, 0.175), (0, 0, 0.215), c, "eb_fabric")
    p.mesh("top", "pillow", (0, 0, 0.4), c, "eb_fabric", stretch=(1.5, 1.0, 0.3))
    p.box("piping", (0.295, 0.295, 0.006), (0, 0, 0.388), _shade(c, 0.8), "eb_fabric", collide=False)
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.sph("button", 0.012, (sx * 0.1, sy * 0.1, 0.418), _shade(c, 0.7), "eb_fabric", collide=False)
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.cyl("foot", 0.025, 0.02, (sx * 0.25, sy * 0.25, 0.02), _DARK, "eb_wood")


@_register("LaundryHamper", "furniture", ("tan", "white", "brown"), (0.23, 0.23), 0.62, mount="floor",
           surfaces=(S("interior", 0.4, (0.12, 0.12), (0.0, 0.0), True),))
def _hamper(p: Parts, c: RGB) -> None:
    """An open wicker laundry basket, half full of clothes."""
    p.mesh("basket", "garbage_can", (0, 0, 0), c, "eb_wicker", stretch=(1.38, 1.38, 1.5))
    laundry = (0.82, 0.8, 0.76)
    p.cyl("laundry", 0.17, 0.18, (0, 0, 0.21), laundry, "eb_fabric", collide=False)
    p.ell("laundry_top", (0.185, 0.185, 0.03), (0, 0, 0.375), laundry, "eb_fabric", collide=False)
    p.mesh("rim", "burner", (0, 0, 0.6), _shade(c, 0.8), "eb_wicker", stretch=(3.15, 3.15, 1.5), collide=False)


@_register("TowelHolder", "furniture", ("silver",), (0.05, 0.32), 1.02, mount="floor",
           surfaces=(S("bar", 0.92, (0.02, 0.2)),))
def _towel_holder(p: Parts, c: RGB) -> None:
    """A free-standing chrome rail for bath towels."""
    for sy in (-1, 1):
        p.cyl_ft("post", (0, sy * 0.3, 0), (0, sy * 0.3, 1.1), 0.015, _CHROME, "eb_metal")
        p.cyl("foot", 0.08, 0.01, (0, sy * 0.3, 0.01), _CHROME, "eb_metal")
    p.cyl_ft("bar", (0, -0.3, 1.0), (0, 0.3, 1.0), 0.015, _CHROME, "eb_metal")


@_register("HandTowelHolder", "furniture", ("silver",), (0.05, 0.1), 0.95, mount="floor",
           surfaces=(S("ring", 0.72, (0.02, 0.05), (0.03, 0.0)),))
def _hand_towel_holder(p: Parts, c: RGB) -> None:
    """A chrome stand with a ring for a hand towel."""
    p.cyl_ft("post", (0, 0, 0), (0, 0, 0.95), 0.015, _CHROME, "eb_metal")
    p.cyl("foot", 0.1, 0.01, (0, 0, 0.01), _CHROME, "eb_metal")
    p.geom("ring", "ellipsoid", size=(0.02, 0.1, 0.1), pos=(0.03, 0, 0.85), rgba=_CHROME, mat="eb_metal")


@_register("ToiletPaperHanger", "furniture", ("silver",), (0.08, 0.16), 0.7, mount="floor",
           surfaces=(S("arm", 0.62, (0.02, 0.04), (0.0, 0.09)),))
def _tp_hanger(p: Parts, c: RGB) -> None:
    p.cyl_ft("post", (0, 0, 0), (0, 0, 0.7), 0.012, _CHROME, "eb_metal")
    p.cyl("foot", 0.08, 0.01, (0, 0, 0.01), _CHROME, "eb_metal")
    p.cyl_ft("arm", (0, 0, 0.68), (0.0, 0.14, 0.68), 0.01, _CHROME, "eb_metal")


@_register("StoveBurner", "appliance", ("black",), (0.31, 0.23), 0.96, mount="floor",
           surfaces=(S("top", 0.955, (0.1, 0.1)),), toggleable=True)
def _stove_burner(p: Parts, c: RGB) -> None:
    """A narrow one-burner cooker with an oven door (one burner you can walk up to)."""
    p.box("base", (0.3, 0.22, 0.44), (0, 0, 0.46), (0.85, 0.85, 0.86), "eb_metal")
    p.box("oven", (0.004, 0.18, 0.2), (0.302, 0, 0.42), _DARK, "eb_glass")
    p.box("top", (0.31, 0.23, 0.02), (0, 0, 0.92), (0.08, 0.08, 0.09), "eb_glossy")
    p.cyl("burner", 0.1, 0.008, (0, 0, 0.945), (0.2, 0.2, 0.22), "eb_metal")
    p.cyl("burner_ring", 0.06, 0.01, (0, 0, 0.948), (0.05, 0.05, 0.05), "eb_metal")
    p.cyl_ft("knob", (0.3, 0.0, 0.8), (0.33, 0.0, 0.8), 0.025, _CHROME, "eb_metal")


@_register("Slices", "food", ("red", "green", "yellow", "tan", "brown"), (0.05, 0.04), 0.08, movable=True)
def _slices(p: Parts, c: RGB) -> None:
    """Three cut pieces of a fruit or vegetable: its colour outside, a pale cut face."""
    flesh = tuple(min(1.0, 0.6 * v + 0.4 * w) for v, w in zip(c, (1.0, 0.95, 0.8)))
    for dx in (-0.03, 0.0, 0.03):
        p.cyl_ft("skin", (dx - 0.009, 0, 0.04), (dx + 0.009, 0, 0.04), 0.04, c, "eb_peel")
        p.cyl_ft("face", (dx + 0.0092, 0, 0.04), (dx + 0.0095, 0, 0.04), 0.036, flesh, "eb_matte", collide=False)


def _shaker(p: Parts, c: RGB) -> None:
    """A glass shaker showing its filling, with a chrome cap."""
    p.cyl("body", 0.022, 0.04, (0, 0, 0.04), (0.85, 0.88, 0.9, 0.35), "eb_glass")
    p.cyl("fill", 0.02, 0.028, (0, 0, 0.03), c, "eb_matte", collide=False)
    p.ell("cap", (0.022, 0.022, 0.014), (0, 0, 0.08), _CHROME, "eb_metal")


_register("SaltShaker", "small", ("white", "cream"), (0.022, 0.022), 0.095, movable=True)(_shaker)
_register("PepperShaker", "small", ("dark_gray", "black", "brown"), (0.022, 0.022), 0.095, movable=True)(_shaker)


@_register("Fork", "small", ("silver", "steel", "gold"), (0.1, 0.013), 0.008, movable=True)
def _fork(p: Parts, c: RGB) -> None:
    p.box("handle", (0.06, 0.008, 0.003), (-0.04, 0, 0.004), c, "eb_metal")
    p.box("neck", (0.02, 0.012, 0.003), (0.035, 0, 0.004), c, "eb_metal")
    for dy in (-0.009, -0.003, 0.003, 0.009):
        p.box("tine", (0.025, 0.0018, 0.002), (0.075, dy, 0.004), c, "eb_metal")


@_register("Spoon", "small", ("silver", "steel", "gold"), (0.1, 0.018), 0.012, movable=True)
def _spoon(p: Parts, c: RGB) -> None:
    p.box("handle", (0.06, 0.007, 0.003), (-0.04, 0, 0.004), c, "eb_metal")
    p.ell("bowl", (0.028, 0.018, 0.006), (0.05, 0, 0.006), c, "eb_metal")


@_register("Ladle", "small", ("steel", "silver", "black"), (0.17, 0.045), 0.05, movable=True)
def _ladle(p: Parts, c: RGB) -> None:
    p.box("handle", (0.11, 0.008, 0.004), (-0.06, 0, 0.01), c, "eb_metal")
    p.ell("cup", (0.045, 0.045, 0.025), (0.09, 0, 0.025), c, "eb_metal")


@_register("CD", "small", ("silver", "gold"), (0.06, 0.06), 0.004, movable=True)
def _cd(p: Parts, c: RGB) -> None:
    p.cyl("disc", 0.06, 0.001, (0, 0, 0.002), c, "eb_metal")
    p.cyl("label", 0.035, 0.0012, (0, 0, 0.0025), (0.3, 0.5, 0.9), "eb_plastic", collide=False)
    p.cyl("hole", 0.008, 0.0015, (0, 0, 0.003), _DARK, "eb_matte", collide=False)


@_register("CreditCard", "small", ("blue", "gold", "black", "red"), (0.027, 0.043), 0.004, movable=True)
def _credit_card(p: Parts, c: RGB) -> None:
    p.box("card", (0.027, 0.043, 0.001), (0, 0, 0.002), c, "eb_glossy")
    p.box("chip", (0.006, 0.008, 0.0005), (0.008, -0.025, 0.0032), (0.85, 0.7, 0.3), "eb_metal", collide=False)
    p.box("stripe", (0.004, 0.04, 0.0005), (-0.015, 0, 0.0032), _WHITE, "eb_plastic", collide=False)


@_register("Watch", "small", ("silver", "gold", "black"), (0.02, 0.06), 0.017, movable=True)
def _watch(p: Parts, c: RGB) -> None:
    p.box("band", (0.012, 0.06, 0.002), (0, 0, 0.003), (0.2, 0.15, 0.1), "eb_fabric")
    p.cyl("case", 0.02, 0.006, (0, 0, 0.01), c, "eb_metal")
    p.cyl("face", 0.016, 0.001, (0, 0, 0.0165), _WHITE, "eb_glossy", collide=False)


@_register("Statue", "small", ("gold", "silver", "dark_gray"), (0.045, 0.05), 0.21, movable=True,
           shapes={"tall": (1.0, 1.0, 1.5), "short": (1.15, 1.15, 0.6)})
def _statue(p: Parts, c: RGB) -> None:
    """A small metal figure on a stone plinth."""
    p.box("plinth", (0.045, 0.045, 0.015), (0, 0, 0.015), _DARK, "eb_stone")
    p.cap_ft("body", (0, 0, 0.04), (0, 0, 0.16), 0.025, c, "eb_metal")
    p.sph("head", 0.022, (0, 0, 0.19), c, "eb_metal")
    p.cap_ft("arm", (0, -0.03, 0.14), (0, -0.045, 0.2), 0.009, c, "eb_metal")


@_register("ToiletPaper", "small", ("white", "cream"), (0.055, 0.055), 0.1, movable=True)
def _toilet_paper(p: Parts, c: RGB) -> None:
    p.cyl("roll", 0.055, 0.05, (0, 0, 0.05), c, "eb_fabric")
    p.cyl("core", 0.02, 0.051, (0, 0, 0.05), (0.6, 0.45, 0.3), "eb_matte", collide=False)


@_register("TennisRacket", "small", ("red", "blue", "green", "black"), (0.27, 0.1), 0.025, movable=True)
def _tennis_racket(p: Parts, c: RGB) -> None:
    p.geom("frame", "ellipsoid", size=(0.13, 0.1, 0.01), pos=(0.12, 0, 0.012), rgba=c, mat="eb_glossy")
    p.geom("strings", "ellipsoid", size=(0.115, 0.087, 0.011), pos=(0.12, 0, 0.013), rgba=(0.95, 0.95, 0.85),
           mat="eb_matte", collide=False)
    p.cap_ft("handle", (-0.01, 0, 0.012), (-0.26, 0, 0.012), 0.014, (0.1, 0.1, 0.1), "eb_fabric")


@_register("BaseballBat", "small", ("wood", "oak", "black"), (0.43, 0.035), 0.07, movable=True)
def _baseball_bat(p: Parts, c: RGB) -> None:
    p.cap_ft("barrel", (0.05, 0, 0.035), (0.4, 0, 0.035), 0.033, c, "eb_wood")
    p.cap_ft("handle", (-0.4, 0, 0.035), (0.05, 0, 0.035), 0.015, c, "eb_wood")
    p.cyl_ft("knob", (-0.42, 0, 0.035), (-0.4, 0, 0.035), 0.024, c, "eb_wood")


@_register("Plunger", "small", ("red", "black"), (0.07, 0.07), 0.5, movable=True)
def _plunger(p: Parts, c: RGB) -> None:
    p.ell("cup", (0.07, 0.07, 0.05), (0.0, 0, 0.05), c, "eb_glossy")
    p.cyl_ft("stick", (0, 0, 0.08), (0, 0, 0.5), 0.012, (0.55, 0.38, 0.2), "eb_wood")


@_register("ScrubBrush", "small", ("blue", "green", "red", "yellow"), (0.09, 0.035), 0.1, movable=True)
def _scrub_brush(p: Parts, c: RGB) -> None:
    p.box("block", (0.08, 0.035, 0.015), (0, 0, 0.035), c, "eb_plastic")
    p.box("bristles", (0.075, 0.03, 0.012), (0, 0, 0.012), (0.95, 0.95, 0.9), "eb_fabric")
    p.cap_ft("handle", (0.04, 0, 0.05), (-0.08, 0, 0.09), 0.012, c, "eb_plastic")


@_register("SprayBottle", "small", ("blue", "green", "white", "yellow"), (0.05, 0.035), 0.235, movable=True)
def _spray_bottle(p: Parts, c: RGB) -> None:
    p.cyl("bottle", 0.035, 0.08, (0, 0, 0.08), c, "eb_glossy")
    p.cyl("neck", 0.015, 0.02, (0, 0, 0.18), _WHITE, "eb_plastic")
    p.box("head", (0.035, 0.015, 0.02), (0.015, 0, 0.215), _WHITE, "eb_plastic")
    p.box("trigger", (0.006, 0.01, 0.025), (0.03, 0, 0.18), _DARK, "eb_plastic")


@_register("Newspaper", "small", ("light_gray", "cream", "white"), (0.14, 0.1), 0.013, movable=True)
def _newspaper(p: Parts, c: RGB) -> None:
    p.box("paper", (0.14, 0.1, 0.006), (0, 0, 0.006), c, "eb_matte")
    p.box("headline", (0.02, 0.08, 0.001), (0.1, 0, 0.0125), _DARK, "eb_matte", collide=False)
    for x in (0.04, 0.0, -0.04, -0.08):
        p.box("column", (0.012, 0.08, 0.0008), (x, 0, 0.0125), (0.55, 0.55, 0.55), "eb_matte", collide=False)


@_register("TissueBox", "small", ("blue", "white", "green", "pink"), (0.06, 0.11), 0.13, movable=True)
def _tissue_box(p: Parts, c: RGB) -> None:
    p.box("box", (0.06, 0.11, 0.05), (0, 0, 0.05), c, "eb_plastic")
    p.ell("tissue", (0.03, 0.05, 0.03), (0, 0, 0.1), _WHITE, "eb_fabric")


@_register("SoapBar", "small", ("pink", "white", "green", "yellow"), (0.045, 0.03), 0.032, movable=True)
def _soap_bar(p: Parts, c: RGB) -> None:
    p.ell("bar", (0.045, 0.03, 0.016), (0, 0, 0.016), c, "eb_glossy")


@_register("WateringCan", "small", ("green", "red", "blue", "yellow"), (0.15, 0.09), 0.23, movable=True)
def _watering_can(p: Parts, c: RGB) -> None:
    p.cyl("tank", 0.09, 0.1, (0, 0, 0.1), c, "eb_glossy")
    p.cyl_ft("spout", (0.07, 0, 0.08), (0.22, 0, 0.2), 0.012, c, "eb_glossy")
    p.cyl("rose", 0.025, 0.012, (0.225, 0, 0.205), c, "eb_glossy")
    p.cap_ft("handle", (-0.08, 0, 0.22), (0.05, 0, 0.22), 0.012, c, "eb_glossy")
