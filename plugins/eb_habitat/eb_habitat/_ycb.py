"""YCB-style small objects the scene kit's catalogue does not have, built from MuJoCo primitives.

Each is an :class:`eb_scenekit.ObjectType` drawn through the kit's :class:`eb_scenekit.Parts` (same conventions
as the catalogue: origin at the bottom centre, front along local +x, parts named ``<instance>/<part>``, a free
joint when movable). They are not in the kit's catalogue: :mod:`eb_habitat.render` registers the ones a task
uses with that apartment's ``SceneBuilder`` (``register_type``). Types the kit already has (apple, banana,
orange, mug, cup, bowl, plate, frying pan, spatula, sponge) come from the kit.
"""

from __future__ import annotations

import math

from eb_scenekit.objects import ObjectType, Parts, get_type, shade

__all__ = ["KIT_TYPES", "YCB_TYPES", "kit_or_ycb"]

RGB = tuple[float, float, float]

_SILVER = (0.78, 0.79, 0.82)
_STEEL = (0.6, 0.62, 0.66)
_BLACK = (0.06, 0.06, 0.07)
_WHITE = (0.95, 0.95, 0.94)
_GREEN_LEAF = (0.15, 0.5, 0.12)
_BROWN_STEM = (0.35, 0.22, 0.1)
_WOOD = (0.68, 0.47, 0.26)


# -- fruit -----------------------------------------------------------------------------------------------


def _lemon(p: Parts, c: RGB) -> None:
    p.ell("fruit", (0.042, 0.03, 0.03), (0, 0, 0.03), c, "eb_peel")
    for sx in (-1, 1):
        p.ell("tip", (0.012, 0.009, 0.009), (sx * 0.045, 0, 0.03), shade(c, 0.92), "eb_peel", collide=False)


def _pear(p: Parts, c: RGB) -> None:
    p.sph("bottom", 0.04, (0, 0, 0.04), c, "eb_peel")
    p.ell("neck", (0.026, 0.026, 0.036), (0, 0, 0.082), c, "eb_peel", collide=False)
    p.cap_ft("stem", (0, 0, 0.11), (0.006, 0.004, 0.132), 0.003, _BROWN_STEM, "eb_matte", collide=False)


def _plum(p: Parts, c: RGB) -> None:
    p.ell("fruit", (0.032, 0.03, 0.03), (0, 0, 0.03), c, "eb_glossy")
    p.ell("crease", (0.033, 0.004, 0.026), (0, 0.0, 0.032), shade(c, 0.75), "eb_glossy", collide=False)
    p.cap_ft("stem", (0, 0, 0.058), (0.003, 0.0, 0.07), 0.002, _BROWN_STEM, "eb_matte", collide=False)


def _strawberry(p: Parts, c: RGB) -> None:
    p.ell("berry", (0.03, 0.03, 0.034), (0, 0, 0.036), c, "eb_glossy")
    p.ell("point", (0.017, 0.017, 0.02), (0, 0, 0.014), c, "eb_glossy", collide=False)
    for i in range(6):
        a = i * math.pi / 3
        p.ell("leaf", (0.02, 0.008, 0.002), (0.014 * math.cos(a), 0.014 * math.sin(a), 0.068), _GREEN_LEAF,
              "eb_plastic", rot=(0, -15, math.degrees(a)), collide=False)
    p.cap_ft("stem", (0, 0, 0.068), (0, 0, 0.08), 0.003, _GREEN_LEAF, "eb_matte", collide=False)
    for k in range(10):  # seeds
        a = k * 2.4
        z = 0.022 + 0.003 * (k % 5) * 2
        r = 0.029 if z > 0.03 else 0.024
        p.sph("seed", 0.0025, (r * math.cos(a), r * math.sin(a), z), (0.95, 0.85, 0.35), "eb_matte", collide=False)


# -- packaged food -----------------------------------------------------------------------------------------


def _soda_can(p: Parts, c: RGB) -> None:
    p.cyl("body", 0.033, 0.058, (0, 0, 0.062), c, "eb_glossy")
    p.cyl("stripe", 0.0333, 0.012, (0, 0, 0.07), _WHITE, "eb_glossy", collide=False)
    p.cyl("top", 0.029, 0.003, (0, 0, 0.122), _SILVER, "eb_metal", collide=False)
    p.cyl("bottom", 0.029, 0.003, (0, 0, 0.003), _SILVER, "eb_metal", collide=False)
    p.box("tab", (0.008, 0.005, 0.001), (0.01, 0, 0.1255), _STEEL, "eb_metal", collide=False)


def _soup_can(p: Parts, c: RGB) -> None:
    p.cyl("label_top", 0.034, 0.025, (0, 0, 0.075), c, "eb_glossy")
    p.cyl("label_bottom", 0.034, 0.025, (0, 0, 0.027), _WHITE, "eb_glossy")
    p.cyl("medal", 0.0342, 0.004, (0, 0, 0.052), (0.85, 0.68, 0.2), "eb_metal", collide=False)
    for z in (0.002, 0.1):
        p.cyl("rim", 0.0335, 0.002, (0, 0, z), _SILVER, "eb_metal", collide=False)


def _tuna_can(p: Parts, c: RGB) -> None:
    p.cyl("label", 0.043, 0.015, (0, 0, 0.017), c, "eb_glossy")
    p.cyl("band", 0.0432, 0.004, (0, 0, 0.018), (0.95, 0.8, 0.2), "eb_glossy", collide=False)
    p.cyl("lid", 0.041, 0.002, (0, 0, 0.034), _SILVER, "eb_metal", collide=False)
    p.cyl("ring", 0.008, 0.0015, (0.02, 0, 0.0365), _STEEL, "eb_metal", collide=False)


def _cracker_box(p: Parts, c: RGB) -> None:
    p.box("box", (0.03, 0.08, 0.106), (0, 0, 0.106), c, "eb_plastic")
    p.box("panel", (0.001, 0.06, 0.05), (0.031, 0, 0.11), (0.98, 0.85, 0.25), "eb_plastic", collide=False)
    for k in range(3):
        p.box("cracker", (0.0015, 0.014, 0.014), (0.0325, -0.035 + 0.035 * k, 0.08), (0.85, 0.6, 0.3), "eb_matte",
              rot=(45, 0, 0), collide=False)
    p.box("logo", (0.001, 0.05, 0.012), (0.031, 0, 0.18), _WHITE, "eb_plastic", collide=False)


def _sugar_box(p: Parts, c: RGB) -> None:
    p.box("box", (0.022, 0.047, 0.088), (0, 0, 0.088), _WHITE, "eb_plastic")
    p.box("band", (0.0225, 0.0475, 0.035), (0, 0, 0.12), c, "eb_plastic", collide=False)
    p.box("logo", (0.001, 0.03, 0.012), (0.0232, 0, 0.125), (0.1, 0.3, 0.7), "eb_plastic", collide=False)
    p.box("cubes", (0.001, 0.02, 0.012), (0.0232, 0, 0.05), (0.85, 0.85, 0.85), "eb_plastic", collide=False)


def _gelatin_box(p: Parts, c: RGB) -> None:
    p.box("box", (0.018, 0.045, 0.036), (0, 0, 0.036), c, "eb_plastic")
    p.box("window", (0.001, 0.028, 0.016), (0.019, 0, 0.04), (0.85, 0.15, 0.2), "eb_glossy", collide=False)
    p.box("brand", (0.001, 0.035, 0.006), (0.019, 0, 0.062), _WHITE, "eb_plastic", collide=False)


def _mustard_bottle(p: Parts, c: RGB) -> None:
    p.ell("body", (0.03, 0.045, 0.07), (0, 0, 0.07), c, "eb_glossy")
    p.cyl("shoulder", 0.018, 0.01, (0, 0, 0.142), c, "eb_glossy", collide=False)
    p.cyl("cap", 0.014, 0.012, (0, 0, 0.162), c, "eb_glossy", collide=False)
    p.cap_ft("nozzle", (0, 0, 0.172), (0, 0, 0.19), 0.005, c, "eb_glossy", collide=False)
    p.box("label", (0.001, 0.028, 0.03), (0.0295, 0, 0.07), (0.85, 0.15, 0.1), "eb_plastic", collide=False)


# -- kitchenware ---------------------------------------------------------------------------------------------


def _pitcher(p: Parts, c: RGB) -> None:
    p.cyl("body", 0.065, 0.1, (0, 0, 0.1), c, "eb_glossy")
    p.cyl("rim", 0.068, 0.006, (0, 0, 0.2), shade(c, 0.8), "eb_glossy", collide=False)
    p.cyl("inside", 0.058, 0.001, (0, 0, 0.205), shade(c, 0.55), "eb_glossy", collide=False)
    p.ell("spout", (0.03, 0.022, 0.012), (0.065, 0, 0.198), c, "eb_glossy", collide=False)
    p.cap_ft("handle_top", (-0.06, 0, 0.175), (-0.11, 0, 0.17), 0.011, c, "eb_glossy")
    p.cap_ft("handle_side", (-0.11, 0, 0.17), (-0.11, 0, 0.06), 0.011, c, "eb_glossy")
    p.cap_ft("handle_bottom", (-0.11, 0, 0.06), (-0.06, 0, 0.05), 0.011, c, "eb_glossy")


# -- tools ----------------------------------------------------------------------------------------------------


def _hammer(p: Parts, c: RGB) -> None:
    p.cap_ft("handle", (0, -0.14, 0.014), (0, 0.1, 0.014), 0.013, c, "eb_wood")
    p.box("head", (0.06, 0.016, 0.016), (0.0, 0.12, 0.016), _STEEL, "eb_metal")
    p.cyl("face", 0.017, 0.008, (0.066, 0.12, 0.016), _SILVER, "eb_metal", rot=(0, 90, 0), collide=False)
    p.box("claw", (0.03, 0.012, 0.012), (-0.085, 0.12, 0.02), _STEEL, "eb_metal", rot=(0, -15, 0), collide=False)
    p.cap_ft("grip", (0, -0.15, 0.014), (0, -0.07, 0.014), 0.0145, (0.15, 0.15, 0.15), "eb_rubber", collide=False)


def _wrench(p: Parts, c: RGB) -> None:
    p.box("shaft", (0.011, 0.085, 0.004), (0, 0, 0.005), c, "eb_metal")
    # open jaw at +y: a C made of three boxes
    p.box("jaw_back", (0.026, 0.007, 0.005), (0, 0.094, 0.005), c, "eb_metal")
    for sx in (-1, 1):
        p.box("jaw", (0.007, 0.018, 0.005), (sx * 0.02, 0.116, 0.005), c, "eb_metal")
    # ring at -y
    p.cyl("ring", 0.024, 0.005, (0, -0.1, 0.005), c, "eb_metal")
    p.cyl("ring_hole", 0.012, 0.0052, (0, -0.1, 0.005), shade(c, 0.35), "eb_matte", collide=False)
    p.box("groove", (0.004, 0.05, 0.0002), (0, 0, 0.0092), shade(c, 0.7), "eb_metal", collide=False)


def _screwdriver(p: Parts, c: RGB) -> None:
    p.cap_ft("handle", (0, -0.1, 0.017), (0, -0.01, 0.017), 0.016, c, "eb_glossy")
    for k in range(4):
        a = k * math.pi / 2
        p.cap_ft("rib", (0.016 * math.cos(a), -0.09, 0.017 + 0.016 * math.sin(a)),
                 (0.016 * math.cos(a), -0.03, 0.017 + 0.016 * math.sin(a)), 0.004, shade(c, 0.7), "eb_glossy",
                 collide=False)
    p.cyl_ft("shaft", (0, -0.01, 0.017), (0, 0.1, 0.017), 0.0035, _SILVER, "eb_metal")
    p.box("tip", (0.006, 0.008, 0.0012), (0, 0.104, 0.017), _SILVER, "eb_metal", collide=False)


def _scissors(p: Parts, c: RGB) -> None:
    for sx in (-1, 1):
        p.cyl("loop", 0.022, 0.005, (sx * 0.024, -0.055, 0.005), c, "eb_glossy")
        p.cyl("loop_hole", 0.013, 0.0052, (sx * 0.024, -0.055, 0.005), _WHITE, "eb_matte", collide=False)
        p.box("blade", (0.007, 0.065, 0.0025), (sx * 0.007, 0.045, 0.004), _SILVER, "eb_metal",
              rot=(0, 0, sx * 6))
    p.cyl("pivot", 0.006, 0.004, (0, -0.015, 0.008), _STEEL, "eb_metal", collide=False)


# -- toys and household -----------------------------------------------------------------------------------


def _toy_airplane(p: Parts, c: RGB) -> None:
    p.cap_ft("fuselage", (-0.1, 0, 0.04), (0.1, 0, 0.04), 0.024, c, "eb_glossy")
    p.box("wing", (0.03, 0.13, 0.005), (0.02, 0, 0.038), shade(c, 0.85), "eb_glossy")
    p.box("tailplane", (0.016, 0.05, 0.004), (-0.1, 0, 0.05), shade(c, 0.85), "eb_glossy", collide=False)
    p.box("fin", (0.022, 0.004, 0.03), (-0.1, 0, 0.075), shade(c, 0.85), "eb_glossy", collide=False)
    p.ell("cockpit", (0.03, 0.016, 0.014), (0.04, 0, 0.062), (0.35, 0.75, 0.95), "eb_glass", collide=False)
    p.box("propeller", (0.003, 0.05, 0.006), (0.128, 0, 0.04), _BLACK, "eb_matte", collide=False)
    p.cyl("spinner", 0.008, 0.006, (0.124, 0, 0.04), _WHITE, "eb_glossy", rot=(0, 90, 0), collide=False)
    for sy in (-1, 1):
        p.cyl("wheel", 0.01, 0.004, (0.03, sy * 0.03, 0.01), _BLACK, "eb_rubber", rot=(90, 0, 0), collide=False)
        p.cyl_ft("strut", (0.03, sy * 0.02, 0.02), (0.03, sy * 0.03, 0.012), 0.003, _BLACK, "eb_matte",
                 collide=False)


def _ball(p: Parts, c: RGB) -> None:
    p.sph("ball", 0.036, (0, 0, 0.036), c, "eb_rubber" if c[1] > 0.7 else "eb_glossy")
    # two seam bands make it read as a ball rather than a fruit
    p.ell("seam_a", (0.0365, 0.003, 0.0365), (0, 0, 0.036), _WHITE, "eb_matte", rot=(0, 0, 35), collide=False)
    p.ell("seam_b", (0.003, 0.0365, 0.0365), (0, 0, 0.036), _WHITE, "eb_matte", rot=(0, 0, 35), collide=False)


_CUBE_FACES = ((1.0, 1.0, 1.0), (0.85, 0.1, 0.1), (0.1, 0.35, 0.85), (0.15, 0.65, 0.2), (0.98, 0.5, 0.05),
               (0.98, 0.85, 0.1))


def _rubiks_cube(p: Parts, c: RGB) -> None:
    h = 0.028
    p.box("core", (h, h, h), (0, 0, h), _BLACK, "eb_glossy")
    step = 2 * h / 3
    s = step / 2 - 0.0025
    faces = (  # (normal axis, sign, colour index)
        (2, 1, 0), (0, 1, 1), (1, 1, 2), (1, -1, 3), (0, -1, 4),
    )
    for axis, sign, ci in faces:
        col = _CUBE_FACES[ci]
        for i in (-1, 0, 1):
            for j in (-1, 0, 1):
                pos = [0.0, 0.0, h]
                half = [s, s, s]
                pos[axis] += sign * (h + 0.0006)
                half[axis] = 0.0008
                others = [a for a in range(3) if a != axis]
                pos[others[0]] += i * step
                pos[others[1]] += j * step
                p.box("sticker", tuple(half), tuple(pos), col, "eb_glossy", collide=False)


def _padlock(p: Parts, c: RGB) -> None:
    p.box("body", (0.013, 0.03, 0.028), (0, 0, 0.028), c, "eb_metal")
    p.box("face", (0.0135, 0.026, 0.024), (0, 0, 0.028), shade(c, 0.85), "eb_metal", collide=False)
    p.cyl("keyhole", 0.004, 0.001, (0.0142, 0, 0.024), _BLACK, "eb_matte", rot=(0, 90, 0), collide=False)
    r = 0.019
    pts = [(0.0, -r * math.cos(a), 0.056 + 0.008 + r * math.sin(a)) for a in
           [k * math.pi / 6 for k in range(7)]]
    p.cyl_ft("shackle_l", (0, -r, 0.05), (0, -r, 0.064), 0.0045, _SILVER, "eb_metal")
    p.cyl_ft("shackle_r", (0, r, 0.05), (0, r, 0.064), 0.0045, _SILVER, "eb_metal")
    for a, b in zip(pts, pts[1:]):
        p.cap_ft("shackle", a, b, 0.0045, _SILVER, "eb_metal", collide=False)


def _foam_brick(p: Parts, c: RGB) -> None:
    p.box("brick", (0.025, 0.038, 0.025), (0, 0, 0.025), c, "eb_fabric")
    for sy in (-1, 1):
        p.cyl("hole", 0.007, 0.0252, (0, sy * 0.017, 0.025), shade(c, 0.55), "eb_matte", collide=False)


def _bleach_bottle(p: Parts, c: RGB) -> None:
    p.box("body", (0.035, 0.055, 0.085), (0, 0, 0.085), c, "eb_glossy")
    for sy in (-1, 1):
        p.cyl("edge", 0.035, 0.085, (0, sy * 0.055, 0.085), c, "eb_glossy", collide=False)
    p.cyl("neck", 0.018, 0.015, (0, -0.03, 0.185), c, "eb_glossy", collide=False)
    p.cyl("cap", 0.02, 0.014, (0, -0.03, 0.212), (0.1, 0.35, 0.85), "eb_glossy", collide=False)
    p.cap_ft("handle", (0, 0.02, 0.17), (0, 0.07, 0.12), 0.012, c, "eb_glossy", collide=False)
    p.box("label", (0.001, 0.04, 0.04), (0.0355, -0.005, 0.08), (0.1, 0.35, 0.85), "eb_plastic", collide=False)


def _t(key: str, builder, half: tuple[float, float], height: float) -> ObjectType:
    return ObjectType(name=f"ycb_{key}", category="small", colors={"default": (0.5, 0.5, 0.5)}, half_extents=half,
                      height=height, builder=builder, movable=True)


#: Our builders, by eb_habitat object type key.
YCB_TYPES: dict[str, ObjectType] = {
    "lemon": _t("lemon", _lemon, (0.055, 0.03), 0.06),
    "pear": _t("pear", _pear, (0.04, 0.04), 0.13),
    "plum": _t("plum", _plum, (0.032, 0.03), 0.07),
    "strawberry": _t("strawberry", _strawberry, (0.03, 0.03), 0.08),
    "soda_can": _t("soda_can", _soda_can, (0.033, 0.033), 0.125),
    "soup_can": _t("soup_can", _soup_can, (0.034, 0.034), 0.1),
    "tuna_can": _t("tuna_can", _tuna_can, (0.043, 0.043), 0.036),
    "cracker_box": _t("cracker_box", _cracker_box, (0.03, 0.08), 0.21),
    "sugar_box": _t("sugar_box", _sugar_box, (0.022, 0.047), 0.176),
    "gelatin_box": _t("gelatin_box", _gelatin_box, (0.018, 0.045), 0.072),
    "mustard_bottle": _t("mustard_bottle", _mustard_bottle, (0.03, 0.045), 0.19),
    "pitcher": _t("pitcher", _pitcher, (0.1, 0.07), 0.21),
    "hammer": _t("hammer", _hammer, (0.07, 0.15), 0.03),
    "wrench": _t("wrench", _wrench, (0.026, 0.13), 0.01),
    "screwdriver": _t("screwdriver", _screwdriver, (0.016, 0.11), 0.034),
    "scissors": _t("scissors", _scissors, (0.046, 0.11), 0.01),
    "toy_airplane": _t("toy_airplane", _toy_airplane, (0.13, 0.13), 0.1),
    "ball": _t("ball", _ball, (0.036, 0.036), 0.072),
    "rubiks_cube": _t("rubiks_cube", _rubiks_cube, (0.028, 0.028), 0.056),
    "padlock": _t("padlock", _padlock, (0.013, 0.03), 0.09),
    "foam_brick": _t("foam_brick", _foam_brick, (0.025, 0.038), 0.05),
    "bleach_bottle": _t("bleach_bottle", _bleach_bottle, (0.035, 0.09), 0.23),
}

#: eb_habitat type key -> scene-kit catalogue type name, for types the kit already draws well.
KIT_TYPES: dict[str, str] = {
    "apple": "Apple",
    "banana": "Banana",
    "orange": "Orange",
    "mug": "Mug",
    "cup": "Cup",
    "bowl": "Bowl",
    "plate": "Plate",
    "skillet": "Pan",
    "spatula": "Spatula",
    "sponge": "Sponge",
}


def kit_or_ycb(type_key: str) -> ObjectType:
    """The ObjectType that draws ``type_key`` (from the kit's catalogue when it has one)."""
    if type_key in KIT_TYPES:
        return get_type(KIT_TYPES[type_key])
    return YCB_TYPES[type_key]
