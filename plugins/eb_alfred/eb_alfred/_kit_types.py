"""Adapter to the scene kit's object catalogue: which kit type draws each ALFRED type, plus the few shapes
the kit does not have yet (drawer unit, safe, stove burner, cutlery, shakers, ...).

The extra shapes are kit ``ObjectType`` s named with an ``Alfred`` prefix (``AlfredDrawer``), so they can never clash
with a kit type; they are visible to the kit's ``SceneBuilder`` only while one of our scenes is being built
(:func:`registered`). When the kit grows a type of the same kind, switch the mapping below to it.
Imports MuJoCo-free parts of the kit only.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from eb_scenekit.objects import CATALOGUE, COLORS as KIT_COLORS, ObjectType, Parts, Surface, get_type

__all__ = ["EXTRA_TYPES", "KIT", "kit_get", "kit_type", "registered"]

RGB = tuple[float, float, float]
_CHROME = (0.85, 0.86, 0.9)
_DARK = (0.16, 0.16, 0.18)
_WHITE = (0.93, 0.93, 0.91)

#: ALFRED type -> (kit type, scale). Sink basins, faucets and bathtub basins are parts of their sink/bathtub.
KIT: dict[str, tuple[str, float]] = {
    "AlarmClock": ("AlarmClock", 1.0), "Apple": ("Apple", 1.0), "ArmChair": ("ArmChair", 1.0),
    "BaseballBat": ("AlfredBaseballBat", 1.0), "BasketBall": ("BasketBall", 1.0), "Bathtub": ("Bathtub", 1.0),
    "Bed": ("Bed", 1.0), "Book": ("Book", 1.0), "Bowl": ("Bowl", 1.0), "Box": ("Box", 1.0),
    "Bread": ("Bread", 1.0), "ButterKnife": ("Knife", 0.8), "CD": ("AlfredCD", 1.0), "Cabinet": ("Cabinet", 1.0),
    "Candle": ("Candle", 0.8), "CellPhone": ("CellPhone", 1.0), "Cloth": ("Towel", 0.7),
    "CoffeeMachine": ("CoffeeMachine", 1.0), "CoffeeTable": ("CoffeeTable", 1.0), "CounterTop": ("CounterTop", 1.0),
    "CreditCard": ("AlfredCreditCard", 1.0), "Cup": ("Cup", 1.0), "Desk": ("Desk", 1.0),
    "DeskLamp": ("DeskLamp", 1.0), "DiningTable": ("DiningTable", 1.0), "DishSponge": ("Sponge", 1.0),
    "Drawer": ("AlfredDrawer", 1.0), "Dresser": ("Dresser", 1.0), "Egg": ("Egg", 1.0),
    "FloorLamp": ("FloorLamp", 1.0), "Fork": ("AlfredFork", 1.0), "Fridge": ("Fridge", 1.0),
    "GarbageCan": ("GarbageCan", 1.0), "GlassBottle": ("WineBottle", 0.85), "HandTowel": ("Towel", 0.8),
    "HandTowelHolder": ("AlfredHandTowelHolder", 1.0), "Kettle": ("Kettle", 1.0), "KeyChain": ("KeyChain", 1.0),
    "Knife": ("Knife", 1.0), "Ladle": ("AlfredLadle", 1.0), "Laptop": ("Laptop", 1.0),
    "LaundryHamper": ("AlfredLaundryHamper", 1.0), "Lettuce": ("Lettuce", 1.0), "Microwave": ("Microwave", 1.0),
    "Mug": ("Mug", 1.0), "Newspaper": ("AlfredNewspaper", 1.0), "Ottoman": ("AlfredOttoman", 1.0),
    "Pan": ("Pan", 1.0), "Pen": ("Pen", 1.0), "Pencil": ("Pen", 1.2), "PepperShaker": ("AlfredShaker", 1.0),
    "Pillow": ("Pillow", 1.0), "Plate": ("Plate", 1.0), "Plunger": ("AlfredPlunger", 1.0), "Pot": ("Pot", 1.0),
    "Potato": ("Potato", 1.0), "RemoteControl": ("RemoteControl", 1.0), "Safe": ("AlfredSafe", 1.0),
    "SaltShaker": ("AlfredShaker", 1.0), "ScrubBrush": ("AlfredScrubBrush", 1.0), "Shelf": ("Shelf", 1.0),
    "SideTable": ("SideTable", 1.0), "Sink": ("Sink", 1.0), "SoapBar": ("AlfredSoapBar", 1.0),
    "SoapBottle": ("SoapBottle", 1.0), "Sofa": ("Sofa", 1.0), "Spatula": ("Spatula", 1.0),
    "Spoon": ("AlfredSpoon", 1.0), "SprayBottle": ("AlfredSprayBottle", 1.0), "Statue": ("AlfredStatue", 1.0),
    "StoveBurner": ("AlfredStoveBurner", 1.0), "TVStand": ("TVStand", 1.0), "TennisRacket": ("AlfredTennisRacket", 1.0),
    "TissueBox": ("AlfredTissueBox", 1.0), "Toaster": ("Toaster", 1.0), "Toilet": ("Toilet", 1.0),
    "ToiletPaper": ("AlfredToiletPaper", 1.0), "ToiletPaperHanger": ("AlfredToiletPaperHanger", 1.0),
    "Tomato": ("Tomato", 1.0), "Towel": ("Towel", 1.0), "TowelHolder": ("AlfredTowelHolder", 1.0),
    "Vase": ("Vase", 0.8), "Watch": ("AlfredWatch", 1.0), "WateringCan": ("AlfredWateringCan", 1.0),
    "WineBottle": ("WineBottle", 1.0),
}


def kit_type(alfred_type: str) -> tuple[str, float]:
    return KIT[alfred_type]


# ----------------------------------------------------------------------------------------------- builders
def _drawer(p: Parts, c: RGB) -> None:
    """A low chest with one pull-out drawer at the top (front = +x)."""
    p.box("plinth", (0.2, 0.22, 0.03), (-0.01, 0, 0.03), _DARK, "eb_matte")
    p.box("carcass", (0.22, 0.24, 0.25), (-0.02, 0, 0.31), c, "eb_wood")
    p.box("top", (0.235, 0.25, 0.012), (-0.01, 0, 0.572), c, "eb_wood")
    d = p.slide("drawer", (0, 0, 0), (1, 0, 0), 0.3)
    d.box("front", (0.012, 0.23, 0.1), (0.215, 0, 0.45), tuple(min(1.0, v * 1.1) for v in c), "eb_wood")
    d.box("floor", (0.2, 0.21, 0.006), (0.02, 0, 0.37), tuple(v * 0.8 for v in c), "eb_wood")
    for sy in (-1, 1):
        d.box("wall", (0.2, 0.006, 0.05), (0.02, sy * 0.21, 0.42), tuple(v * 0.8 for v in c), "eb_wood")
    d.box("back", (0.006, 0.21, 0.05), (-0.18, 0, 0.42), tuple(v * 0.8 for v in c), "eb_wood")
    d.cap_ft("handle", (0.245, -0.07, 0.45), (0.245, 0.07, 0.45), 0.009, _CHROME, "eb_metal")
    p.box("lower_front", (0.004, 0.23, 0.13), (0.205, 0, 0.19), tuple(v * 0.92 for v in c), "eb_wood",
          collide=False)


def _safe(p: Parts, c: RGB) -> None:
    p.box("body", (0.2, 0.22, 0.2), (0, 0, 0.2), c, "eb_metal")
    p.box("inside", (0.17, 0.19, 0.17), (0.03, 0, 0.2), _DARK, "eb_matte", collide=False)
    d = p.hinge("door", (0.2, -0.22, 0.0), (0, 0, -1), 100)
    d.box("panel", (0.012, 0.22, 0.2), (0.012, 0.22, 0.2), tuple(v * 0.85 for v in c), "eb_metal")
    d.cyl_ft("dial", (0.024, 0.22, 0.24), (0.04, 0.22, 0.24), 0.045, _CHROME, "eb_metal")
    d.cap_ft("handle", (0.045, 0.36, 0.14), (0.045, 0.36, 0.26), 0.01, _CHROME, "eb_metal")


def _burner(p: Parts, c: RGB) -> None:
    p.box("base", (0.3, 0.22, 0.44), (0, 0, 0.46), (0.85, 0.85, 0.86), "eb_metal")
    p.box("oven", (0.004, 0.18, 0.2), (0.302, 0, 0.42), _DARK, "eb_glass")
    p.box("top", (0.31, 0.23, 0.02), (0, 0, 0.92), (0.08, 0.08, 0.09), "eb_glossy")
    p.cyl("burner", 0.1, 0.008, (0, 0, 0.945), (0.2, 0.2, 0.22), "eb_metal")
    p.cyl("burner_ring", 0.06, 0.01, (0, 0, 0.948), (0.05, 0.05, 0.05), "eb_metal")
    p.cyl_ft("knob", (0.3, 0.0, 0.8), (0.33, 0.0, 0.8), 0.025, _CHROME, "eb_metal")


def _ottoman(p: Parts, c: RGB) -> None:
    p.box("cushion", (0.3, 0.3, 0.19), (0, 0, 0.23), c, "eb_fabric")
    for sx in (-1, 1):
        for sy in (-1, 1):
            p.cyl("foot", 0.025, 0.02, (sx * 0.25, sy * 0.25, 0.02), _DARK, "eb_wood")


def _towel_holder(p: Parts, c: RGB) -> None:
    for sy in (-1, 1):
        p.cyl_ft("post", (0, sy * 0.3, 0), (0, sy * 0.3, 1.1), 0.015, _CHROME, "eb_metal")
        p.cyl("foot", 0.08, 0.01, (0, sy * 0.3, 0.01), _CHROME, "eb_metal")
    p.cyl_ft("bar", (0, -0.3, 1.0), (0, 0.3, 1.0), 0.015, _CHROME, "eb_metal")


def _hand_towel_holder(p: Parts, c: RGB) -> None:
    p.cyl_ft("post", (0, 0, 0), (0, 0, 0.95), 0.015, _CHROME, "eb_metal")
    p.cyl("foot", 0.1, 0.01, (0, 0, 0.01), _CHROME, "eb_metal")
    p.geom("ring", "ellipsoid", size=(0.02, 0.1, 0.1), pos=(0.03, 0, 0.85), rgba=_CHROME, mat="eb_metal")


def _tp_hanger(p: Parts, c: RGB) -> None:
    p.cyl_ft("post", (0, 0, 0), (0, 0, 0.7), 0.012, _CHROME, "eb_metal")
    p.cyl("foot", 0.08, 0.01, (0, 0, 0.01), _CHROME, "eb_metal")
    p.cyl_ft("arm", (0, 0, 0.68), (0.0, 0.14, 0.68), 0.01, _CHROME, "eb_metal")


def _hamper(p: Parts, c: RGB) -> None:
    p.cyl("basket", 0.22, 0.3, (0, 0, 0.3), c, "eb_wicker")
    p.cyl("inside", 0.2, 0.29, (0, 0, 0.32), tuple(v * 0.6 for v in c), "eb_matte", collide=False)
    p.cyl("rim", 0.225, 0.015, (0, 0, 0.6), tuple(v * 0.8 for v in c), "eb_wicker")


def _fork(p: Parts, c: RGB) -> None:
    p.box("handle", (0.06, 0.008, 0.003), (-0.04, 0, 0.004), c, "eb_metal")
    p.box("neck", (0.02, 0.012, 0.003), (0.035, 0, 0.004), c, "eb_metal")
    for dy in (-0.009, -0.003, 0.003, 0.009):
        p.box("tine", (0.025, 0.0018, 0.002), (0.075, dy, 0.004), c, "eb_metal")


def _spoon(p: Parts, c: RGB) -> None:
    p.box("handle", (0.06, 0.007, 0.003), (-0.04, 0, 0.004), c, "eb_metal")
    p.ell("bowl", (0.028, 0.018, 0.006), (0.05, 0, 0.006), c, "eb_metal")


def _ladle(p: Parts, c: RGB) -> None:
    p.box("handle", (0.11, 0.008, 0.004), (-0.06, 0, 0.01), c, "eb_metal")
    p.ell("cup", (0.045, 0.045, 0.025), (0.09, 0, 0.025), c, "eb_metal")


def _cd(p: Parts, c: RGB) -> None:
    p.cyl("disc", 0.06, 0.001, (0, 0, 0.002), c, "eb_metal")
    p.cyl("label", 0.035, 0.0012, (0, 0, 0.0025), (0.3, 0.5, 0.9), "eb_plastic", collide=False)
    p.cyl("hole", 0.008, 0.0015, (0, 0, 0.003), _DARK, "eb_matte", collide=False)


def _card(p: Parts, c: RGB) -> None:
    p.box("card", (0.027, 0.043, 0.001), (0, 0, 0.002), c, "eb_glossy")
    p.box("chip", (0.006, 0.008, 0.0005), (0.008, -0.025, 0.0032), (0.85, 0.7, 0.3), "eb_metal", collide=False)
    p.box("stripe", (0.004, 0.04, 0.0005), (-0.015, 0, 0.0032), _WHITE, "eb_plastic", collide=False)


def _watch(p: Parts, c: RGB) -> None:
    p.box("band", (0.012, 0.06, 0.002), (0, 0, 0.003), (0.2, 0.15, 0.1), "eb_fabric")
    p.cyl("case", 0.02, 0.006, (0, 0, 0.01), c, "eb_metal")
    p.cyl("face", 0.016, 0.001, (0, 0, 0.0165), _WHITE, "eb_glossy", collide=False)


def _statue(p: Parts, c: RGB) -> None:
    p.box("plinth", (0.045, 0.045, 0.015), (0, 0, 0.015), _DARK, "eb_stone")
    p.cap_ft("body", (0, 0, 0.04), (0, 0, 0.16), 0.025, c, "eb_metal")
    p.sph("head", 0.022, (0, 0, 0.19), c, "eb_metal")
    p.cap_ft("arm", (0, -0.03, 0.14), (0, -0.045, 0.2), 0.009, c, "eb_metal")


def _toilet_paper(p: Parts, c: RGB) -> None:
    p.cyl("roll", 0.055, 0.05, (0, 0, 0.05), c, "eb_fabric")
    p.cyl("core", 0.02, 0.051, (0, 0, 0.05), (0.6, 0.45, 0.3), "eb_matte", collide=False)


def _shaker(p: Parts, c: RGB) -> None:
    p.cyl("body", 0.022, 0.04, (0, 0, 0.04), (0.85, 0.88, 0.9, 1), "eb_glass")
    p.cyl("fill", 0.02, 0.028, (0, 0, 0.03), c, "eb_matte", collide=False)
    p.ell("cap", (0.022, 0.022, 0.014), (0, 0, 0.08), _CHROME, "eb_metal")


def _racket(p: Parts, c: RGB) -> None:
    p.geom("frame", "ellipsoid", size=(0.13, 0.1, 0.01), pos=(0.12, 0, 0.012), rgba=c, mat="eb_glossy")
    p.geom("strings", "ellipsoid", size=(0.115, 0.087, 0.011), pos=(0.12, 0, 0.013), rgba=(0.95, 0.95, 0.85),
           mat="eb_matte", collide=False)
    p.cap_ft("handle", (-0.01, 0, 0.012), (-0.26, 0, 0.012), 0.014, (0.1, 0.1, 0.1), "eb_fabric")


def _bat(p: Parts, c: RGB) -> None:
    p.cap_ft("barrel", (0.05, 0, 0.035), (0.4, 0, 0.035), 0.033, c, "eb_wood")
    p.cap_ft("handle", (-0.4, 0, 0.035), (0.05, 0, 0.035), 0.015, c, "eb_wood")
    p.cyl_ft("knob", (-0.42, 0, 0.035), (-0.4, 0, 0.035), 0.024, c, "eb_wood")


def _plunger(p: Parts, c: RGB) -> None:
    p.ell("cup", (0.07, 0.07, 0.05), (0.0, 0, 0.05), c, "eb_glossy")
    p.cyl_ft("stick", (0, 0, 0.08), (0, 0, 0.5), 0.012, (0.55, 0.38, 0.2), "eb_wood")


def _scrub_brush(p: Parts, c: RGB) -> None:
    p.box("block", (0.08, 0.035, 0.015), (0, 0, 0.035), c, "eb_plastic")
    p.box("bristles", (0.075, 0.03, 0.012), (0, 0, 0.012), (0.95, 0.95, 0.9), "eb_fabric")
    p.cap_ft("handle", (0.04, 0, 0.05), (-0.08, 0, 0.09), 0.012, c, "eb_plastic")


def _spray(p: Parts, c: RGB) -> None:
    p.cyl("bottle", 0.035, 0.08, (0, 0, 0.08), c, "eb_glossy")
    p.cyl("neck", 0.015, 0.02, (0, 0, 0.18), _WHITE, "eb_plastic")
    p.box("head", (0.035, 0.015, 0.02), (0.015, 0, 0.215), _WHITE, "eb_plastic")
    p.box("trigger", (0.006, 0.01, 0.025), (0.03, 0, 0.18), _DARK, "eb_plastic")


def _newspaper(p: Parts, c: RGB) -> None:
    p.box("paper", (0.14, 0.1, 0.006), (0, 0, 0.006), c, "eb_matte")
    p.box("headline", (0.02, 0.08, 0.001), (0.1, 0, 0.0125), _DARK, "eb_matte", collide=False)
    for i, x in enumerate((0.04, 0.0, -0.04, -0.08)):
        p.box("column", (0.012, 0.08, 0.0008), (x, 0, 0.0125), (0.55, 0.55, 0.55), "eb_matte", collide=False)


def _tissue_box(p: Parts, c: RGB) -> None:
    p.box("box", (0.06, 0.11, 0.05), (0, 0, 0.05), c, "eb_plastic")
    p.ell("tissue", (0.03, 0.05, 0.03), (0, 0, 0.1), _WHITE, "eb_fabric")


def _soap_bar(p: Parts, c: RGB) -> None:
    p.ell("bar", (0.045, 0.03, 0.016), (0, 0, 0.016), c, "eb_glossy")


def _watering_can(p: Parts, c: RGB) -> None:
    p.cyl("tank", 0.09, 0.1, (0, 0, 0.1), c, "eb_glossy")
    p.cyl_ft("spout", (0.07, 0, 0.08), (0.22, 0, 0.2), 0.012, c, "eb_glossy")
    p.cyl("rose", 0.025, 0.012, (0.225, 0, 0.205), c, "eb_glossy")
    p.cap_ft("handle", (-0.08, 0, 0.22), (0.05, 0, 0.22), 0.012, c, "eb_glossy")


def _slices(p: Parts, c: RGB) -> None:
    """Three cut pieces of a fruit or vegetable (its colour outside, a pale face)."""
    flesh = tuple(min(1.0, 0.6 * v + 0.4 * w) for v, w in zip(c, (1.0, 0.95, 0.8)))
    for i, dx in enumerate((-0.03, 0.0, 0.03)):
        p.cyl_ft("skin", (dx - 0.009, 0, 0.04), (dx + 0.009, 0, 0.04), 0.04, c, "eb_peel")
        p.cyl_ft("face", (dx + 0.0092, 0, 0.04), (dx + 0.0095, 0, 0.04), 0.036, flesh, "eb_matte", collide=False)


S = Surface
_EXTRA: list[tuple[str, str, tuple[float, float], float, dict, object]] = [
    ("AlfredDrawer", "furniture", (0.24, 0.25), 0.58,
     dict(mount="floor", surfaces=(S("top", 0.58, (0.2, 0.22)), S("interior", 0.377, (0.16, 0.18), (0.02, 0.0),
                                                                   True, 0.08)),
          articulations=("drawer",)), _drawer),
    ("AlfredSafe", "furniture", (0.21, 0.23), 0.4,
     dict(mount="floor", surfaces=(S("interior", 0.035, (0.14, 0.16), (0.03, 0.0), True, 0.3),
                                   S("top", 0.4, (0.18, 0.2))), articulations=("door",)), _safe),
    ("AlfredStoveBurner", "appliance", (0.31, 0.23), 0.95,
     dict(mount="floor", surfaces=(S("top", 0.955, (0.1, 0.1)),)), _burner),
    ("AlfredOttoman", "furniture", (0.3, 0.3), 0.42, dict(mount="floor", surfaces=(S("top", 0.42, (0.25, 0.25)),)),
     _ottoman),
    ("AlfredTowelHolder", "furniture", (0.05, 0.32), 1.02,
     dict(mount="floor", surfaces=(S("bar", 0.92, (0.02, 0.2)),)), _towel_holder),
    ("AlfredHandTowelHolder", "furniture", (0.05, 0.1), 0.95,
     dict(mount="floor", surfaces=(S("ring", 0.72, (0.02, 0.05), (0.03, 0.0)),)), _hand_towel_holder),
    ("AlfredToiletPaperHanger", "furniture", (0.08, 0.16), 0.7,
     dict(mount="floor", surfaces=(S("arm", 0.62, (0.02, 0.04), (0.0, 0.09)),)), _tp_hanger),
    ("AlfredLaundryHamper", "furniture", (0.23, 0.23), 0.62,
     dict(mount="floor", surfaces=(S("interior", 0.4, (0.12, 0.12), (0.0, 0.0), True),)), _hamper),
    ("AlfredFork", "small", (0.1, 0.013), 0.008, dict(movable=True), _fork),
    ("AlfredSpoon", "small", (0.1, 0.018), 0.012, dict(movable=True), _spoon),
    ("AlfredLadle", "small", (0.17, 0.045), 0.05, dict(movable=True), _ladle),
    ("AlfredCD", "small", (0.06, 0.06), 0.004, dict(movable=True), _cd),
    ("AlfredCreditCard", "small", (0.027, 0.043), 0.004, dict(movable=True), _card),
    ("AlfredWatch", "small", (0.02, 0.06), 0.017, dict(movable=True), _watch),
    ("AlfredStatue", "small", (0.045, 0.05), 0.21, dict(movable=True), _statue),
    ("AlfredToiletPaper", "small", (0.055, 0.055), 0.1, dict(movable=True), _toilet_paper),
    ("AlfredShaker", "small", (0.022, 0.022), 0.095, dict(movable=True), _shaker),
    ("AlfredTennisRacket", "small", (0.27, 0.1), 0.025, dict(movable=True), _racket),
    ("AlfredBaseballBat", "small", (0.43, 0.035), 0.07, dict(movable=True), _bat),
    ("AlfredPlunger", "small", (0.07, 0.07), 0.5, dict(movable=True), _plunger),
    ("AlfredScrubBrush", "small", (0.09, 0.035), 0.1, dict(movable=True), _scrub_brush),
    ("AlfredSprayBottle", "small", (0.05, 0.035), 0.235, dict(movable=True), _spray),
    ("AlfredNewspaper", "small", (0.14, 0.1), 0.013, dict(movable=True), _newspaper),
    ("AlfredTissueBox", "small", (0.06, 0.11), 0.13, dict(movable=True), _tissue_box),
    ("AlfredSoapBar", "small", (0.045, 0.03), 0.032, dict(movable=True), _soap_bar),
    ("AlfredWateringCan", "small", (0.15, 0.09), 0.23, dict(movable=True), _watering_can),
    ("AlfredSlices", "food", (0.05, 0.04), 0.08, dict(movable=True), _slices),
]


def _build_extra() -> dict[str, ObjectType]:
    return {name: ObjectType(name=name, category=category, colors={"gray": KIT_COLORS["gray"]},  # type: ignore[arg-type]
                             half_extents=half, height=height, builder=builder, **kw)  # type: ignore[arg-type]
            for name, category, half, height, kw, builder in _EXTRA}


EXTRA_TYPES: dict[str, ObjectType] = _build_extra()
"""The shapes this package adds (not registered in the kit's catalogue outside :func:`registered`)."""


def kit_get(name: str) -> ObjectType:
    """A kit type or one of ours, by name."""
    return EXTRA_TYPES.get(name) or get_type(name)


@contextmanager
def registered() -> Iterator[None]:
    """Make our extra shapes known to the kit's ``SceneBuilder`` while a scene is being built, then remove them
    again, so the kit's catalogue (and other worlds or tests in the same process) never see them."""
    added = [name for name in EXTRA_TYPES if name not in CATALOGUE]
    for name in added:
        CATALOGUE[name] = EXTRA_TYPES[name]
    try:
        yield
    finally:
        for name in added:
            CATALOGUE.pop(name, None)
