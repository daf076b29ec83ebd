"""The object catalogue: size, metadata, every type compiles alone, renders visibly, articulations work."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eb_scenekit import (
    CATALOGUE, ObjectType, Parts, SceneBuilder, SceneRenderer, Surface, articulated_joints, free_camera, get_open,
    get_type, object_types, set_object_pose, set_open, set_powered, shade, surface_position,
)
from eb_scenekit._mujoco import mujoco
from eb_scenekit.gallery import object_view

REQUIRED = {
    "Table", "DiningTable", "CoffeeTable", "Chair", "Sofa", "ArmChair", "Bed", "Desk", "Bookshelf", "Cabinet",
    "Dresser", "TVStand", "SideTable", "CounterTop", "Shelf", "Fridge", "Microwave", "Stove", "Toaster",
    "CoffeeMachine", "Television", "Laptop", "DeskLamp", "FloorLamp", "Sink", "Toilet", "Bathtub",
    "WashingMachine", "Apple", "Banana", "Orange", "Bread", "Tomato", "Potato", "Lettuce", "Egg", "WineBottle",
    "Mug", "Cup", "Bowl", "Plate", "Pot", "Pan", "Vase", "Box", "GarbageCan", "Basket", "Kettle", "Knife",
    "Spatula", "Book", "CellPhone", "RemoteControl", "KeyChain", "Pen", "Sponge", "SoapBottle", "Towel",
    "Pillow", "AlarmClock", "Candle", "HousePlant", "Painting", "TeddyBear", "BasketBall",
    # household extras first drawn for EB-ALFRED
    "Drawer", "Safe", "Ottoman", "LaundryHamper", "TowelHolder", "HandTowelHolder", "ToiletPaperHanger",
    "StoveBurner", "Slices", "SaltShaker", "PepperShaker", "Fork", "Spoon", "Ladle", "CD", "CreditCard", "Watch",
    "Statue", "ToiletPaper", "TennisRacket", "BaseballBat", "Plunger", "ScrubBrush", "SprayBottle", "Newspaper",
    "TissueBox", "SoapBar", "WateringCan",
}


def test_catalogue_has_the_required_types() -> None:
    assert len(CATALOGUE) >= 93
    assert REQUIRED <= set(CATALOGUE)


@pytest.mark.parametrize("otype", object_types(), ids=lambda t: t.name)
def test_type_metadata_is_complete(otype) -> None:  # type: ignore[no-untyped-def]
    assert otype.name[0].isupper() and otype.name.isalnum()
    assert otype.category in ("furniture", "appliance", "food", "container", "small")
    assert otype.colors and otype.default_color in otype.colors
    assert all(h > 0 for h in otype.half_extents) and otype.height > 0
    for s in otype.surfaces:
        assert 0 <= s.z <= otype.height + 1e-6
    assert otype.receptacle == bool(otype.surfaces)


def test_every_type_compiles_alone() -> None:
    for otype in object_types():
        b = SceneBuilder(name=otype.name)
        b.add_studio()
        b.add_object(otype.name, "thing")
        model, data = b.build()
        names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(model.ngeom)]
        own = [n for n in names if n and n.startswith("thing/")]
        assert own, otype.name
        # every geom is named and attributable to the instance or to the room
        assert all(n and (n.startswith("thing/") or n.startswith("room/")) for n in names), otype.name


@pytest.fixture(scope="module")
def catalogue_scene():  # type: ignore[no-untyped-def]
    """All types in one scene, 4 m apart (one renderer: GL context creation is the slow part)."""
    b = SceneBuilder(name="catalogue")
    b.add_studio(half_size=40.0)
    types = object_types()
    n = math.ceil(math.sqrt(len(types)))
    places = {}
    for i, t in enumerate(types):
        x, y = (i % n) * 4.0, (i // n) * 4.0
        b.add_object(t.name, f"{t.name}_1", (x, y))
        places[t.name] = (x, y)
    model, data = b.build()
    with SceneRenderer(model, data, 128, 128) as r:
        yield r, places


def test_every_type_is_visible_from_a_camera_pointed_at_it(catalogue_scene) -> None:  # type: ignore
    r, places = catalogue_scene
    missing = []
    for t in object_types():
        (lx, ly, lz), dist, az, el = object_view(t)
        x, y = places[t.name]
        seg = r.segmentation(free_camera((lx + x, ly + y, lz), dist, az, el))
        pixels = int((seg == r.instance_ids[f"{t.name}_1"]).sum())
        if pixels < 60:
            missing.append((t.name, pixels))
    assert not missing


def test_colour_variants_change_pixels() -> None:
    b = SceneBuilder()
    b.add_studio()
    b.add_object("Mug", "red_mug", (0, 0), color="red")
    b.add_object("Mug", "blue_mug", (0, 1), color="blue")
    model, data = b.build()
    with SceneRenderer(model, data, 96, 96) as r:
        lookat, dist, az, el = object_view(get_type("Mug"))
        reds = r.rgb(free_camera(lookat, dist, az, el))
        seg = r.segmentation(free_camera(lookat, dist, az, el))
        blues = r.rgb(free_camera((0, 1, lookat[2]), dist, az, el))
    mask = seg == r.instance_ids["red_mug"]
    red = reds[mask].mean(axis=0)
    assert red[0] > red[2] + 40
    assert blues[mask].mean(axis=0)[2] > blues[mask].mean(axis=0)[0]
    with pytest.raises(ValueError, match="available"):
        get_type("Mug").color_rgb("plaid")


def test_unknown_type_lists_the_catalogue() -> None:
    with pytest.raises(KeyError, match="Fridge"):
        get_type("Fridgee")


def test_open_close_and_poses_without_recompiling() -> None:
    b = SceneBuilder()
    b.add_studio()
    b.add_object("Fridge", "fridge", (0, 0))
    b.add_object("Dresser", "dresser", (2, 0))
    b.add_object("Laptop", "laptop", (4, 0))
    b.add_object("Apple", "apple", (6, 0))
    model, data = b.build()
    assert articulated_joints(model, "fridge") == ["fridge/door", "fridge/freezer_door"]
    assert get_open(model, data, "fridge") == pytest.approx(0.0)
    assert get_open(model, data, "laptop") == pytest.approx(0.9)  # laptops start open
    door = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "fridge/door")
    closed = data.xpos[door].copy()
    handle = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "fridge/handle")
    handle_closed = data.geom_xpos[handle].copy()
    set_open(model, data, "fridge", 1.0, part="door")
    assert get_open(model, data, "fridge", "door") == pytest.approx(1.0)
    assert get_open(model, data, "fridge", "freezer_door") == pytest.approx(0.0)
    assert np.allclose(data.xpos[door], closed)  # turns about its hinge ...
    assert data.geom_xpos[handle][0] > handle_closed[0] + 0.4  # ... and the handle swings out to the front
    set_open(model, data, "dresser", 1.0, part="drawer_1")
    drawer = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "dresser/drawer_1")
    assert data.xpos[drawer][0] == pytest.approx(2 + 0.195 + 0.3, abs=1e-6)
    with pytest.raises(KeyError, match="openable"):
        set_open(model, data, "apple", 1.0)
    set_object_pose(model, data, "apple", (1.0, 2.0, 0.5), yaw=90)
    apple = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "apple")
    assert np.allclose(data.xpos[apple], (1.0, 2.0, 0.5))
    with pytest.raises(KeyError, match="not movable"):
        set_object_pose(model, data, "fridge", (0, 0, 0))


def test_initial_open_state_and_power_switch() -> None:
    b = SceneBuilder()
    b.add_studio()
    b.add_object("Microwave", "mw", (0, 0), open=1.0)
    b.add_object("DeskLamp", "lamp", (1, 0))
    b.add_object("Stove", "stove", (3, 0))
    model, data = b.build()
    assert get_open(model, data, "mw") == pytest.approx(1.0)
    light = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_LIGHT, "lamp/light")
    bulb = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "lamp/bulb")
    lit = model.geom_rgba[bulb].copy()
    set_powered(model, "lamp", False)
    assert model.light_active[light] == 0 and not np.allclose(model.geom_rgba[bulb], lit)
    set_powered(model, "lamp", True)
    assert model.light_active[light] == 1 and np.allclose(model.geom_rgba[bulb], lit)
    burner = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "stove/burner")
    off = model.geom_rgba[burner].copy()
    set_powered(model, "stove", True)
    assert model.geom_rgba[burner][0] > off[0]
    with pytest.raises(KeyError):
        set_powered(model, "nothing_here", True)


def test_receptacle_placement_on_and_in() -> None:
    b = SceneBuilder()
    b.add_studio()
    table = b.add_object("DiningTable", None, (0, 0), yaw=90)
    fridge = b.add_object("Fridge", None, (3, 0))
    apple = b.add_object("Apple", None, (0.1, 0.0), parent=table.name)
    egg = b.add_object("Egg", None, parent=fridge.name, surface="shelf_1")
    assert table.name == "DiningTable_1" and apple.name == "Apple_1"
    assert apple.position[2] == pytest.approx(0.76)
    assert apple.position[0] == pytest.approx(0.0, abs=1e-6) and apple.position[1] == pytest.approx(0.1)
    assert apple.parent == "DiningTable_1" and not apple.inside
    assert egg.inside and egg.surface == "shelf_1" and egg.position[2] == pytest.approx(0.508)
    assert get_type("Fridge").surface("shelf_1").clearance is not None
    with pytest.raises(ValueError, match="not a receptacle"):
        b.add_object("Mug", None, parent=apple.name)
    with pytest.raises(ValueError, match="taken"):
        b.add_object("Mug", "Apple_1")
    model, data = b.build()
    assert model.nbody > 4


def test_every_toggleable_type_switches() -> None:
    b = SceneBuilder()
    b.add_studio()
    toggleable = [t for t in object_types() if t.toggleable]
    assert {"Microwave", "DeskLamp", "FloorLamp", "Sink", "Television", "Stove"} <= {t.name for t in toggleable}
    for i, t in enumerate(toggleable):
        b.add_object(t.name, t.name.lower(), (2.0 * i, 0.0))
    model, data = b.build()
    for t in toggleable:
        set_powered(model, t.name.lower(), True)
        set_powered(model, t.name.lower(), False)
    stream = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "sink/stream")
    assert model.geom_rgba[stream][3] == 0.0
    set_powered(model, "sink", True)
    assert model.geom_rgba[stream][3] > 0.0


def _geom_top(model, data, name: str) -> float:  # type: ignore[no-untyped-def]
    g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
    return float(data.geom_xpos[g][2] + model.geom_size[g][2])


def test_sink_basin_surface_is_the_basin_floor_and_holds_a_plate() -> None:
    sink = get_type("Sink")
    basin = sink.surface("basin")
    assert basin.inside and min(basin.half_extents) >= 0.125  # a dinner plate lies flat in it
    b = SceneBuilder()
    b.add_studio()
    b.add_object("Sink", "sink", (0, 0))
    model, data = b.build()
    assert _geom_top(model, data, "sink/basin") == pytest.approx(basin.z, abs=1e-6)
    # objects in the basin are below the worktop, i.e. really in the sink
    assert basin.z < _geom_top(model, data, "sink/counter_front") - 0.1


def test_counter_drawer_surface_moves_with_the_drawer() -> None:
    counter = get_type("CounterTop")
    tray = counter.surface("drawer")
    assert tray.inside and tray.part == "drawer"
    b = SceneBuilder()
    b.add_studio()
    b.add_object("CounterTop", "counter", (1.0, 2.0), yaw=90)
    model, data = b.build()
    assert _geom_top(model, data, "counter/tray") == pytest.approx(tray.z, abs=1e-6)
    closed = surface_position(model, data, "counter", tray)
    assert closed == pytest.approx((1.0 - tray.center[1], 2.0 + tray.center[0], tray.z), abs=1e-6)
    set_open(model, data, "counter", 1.0)
    opened = surface_position(model, data, "counter", tray, offset=(0.05, 0.0))
    assert opened == pytest.approx(closed + np.array([0.0, 0.35 + 0.05, 0.0]), abs=1e-6)  # front = +y here
    assert surface_position(model, data, "counter", counter.surface("top"))[2] == pytest.approx(0.92)


def test_a_world_registers_its_own_type_with_one_builder_only() -> None:
    def crate(p: Parts, c) -> None:  # type: ignore[no-untyped-def]
        p.box("box", (0.15, 0.2, 0.1), (0, 0, 0.1), c, "eb_wood")
        p.box("band", (0.152, 0.202, 0.01), (0, 0, 0.15), shade(c, 0.6), "eb_wood", collide=False)

    otype = ObjectType("Crate", "container", {"oak": (0.78, 0.62, 0.42)}, (0.15, 0.2), 0.2, crate, movable=True,
                       surfaces=(Surface("top", 0.2, (0.13, 0.18)),))
    b = SceneBuilder()
    b.add_studio()
    assert b.register_type(otype) is otype and b.register_type(otype) is otype  # idempotent
    c = b.add_object("Crate", None, (0.5, 0.0))
    apple = b.add_object("Apple", None, parent=c.name)
    assert c.name == "Crate_1" and c.movable and apple.position[2] == pytest.approx(0.2)
    model, data = b.build()
    with SceneRenderer(model, data, 64, 64) as r:
        assert "Crate_1" in r.instance_ids  # listed as an instance: segmented and boxed like catalogue objects
    assert "Crate" not in CATALOGUE
    with pytest.raises(KeyError, match="Crate"):
        SceneBuilder().add_object("Crate")
    with pytest.raises(ValueError, match="catalogue"):
        b.register_type(ObjectType("Mug", "small", {"red": (1, 0, 0)}, (0.1, 0.1), 0.1, crate))
    with pytest.raises(ValueError, match="already"):
        b.register_type(ObjectType("Crate", "small", {"red": (1, 0, 0)}, (0.1, 0.1), 0.1, crate))
    with pytest.raises(KeyError, match="registered here: Crate"):
        b.add_object("Crat")
