"""The symbolic world's rules and feedback (no rendering)."""

from __future__ import annotations

import pytest

from eb_alfred.world import World, instance_index, parse_action


def kitchen() -> World:
    scene = {"room": "kitchen", "objects": [
        {"name": "Fridge", "type": "Fridge", "slot": 0},
        {"name": "CounterTop", "type": "CounterTop", "slot": 1},
        {"name": "Sink", "type": "Sink", "slot": 2},
        {"name": "SinkBasin", "type": "SinkBasin", "parent": "Sink"},
        {"name": "Faucet", "type": "Faucet", "parent": "Sink"},
        {"name": "Cabinet", "type": "Cabinet", "slot": 3},
        {"name": "Cabinet_2", "type": "Cabinet", "slot": 4},
        {"name": "DiningTable", "type": "DiningTable", "slot": 5},
        {"name": "Microwave", "type": "Microwave", "parent": "CounterTop"},
        {"name": "Apple", "type": "Apple", "parent": "Fridge", "color": "red"},
        {"name": "Apple_2", "type": "Apple", "parent": "DiningTable", "color": "green"},
        {"name": "Knife", "type": "Knife", "parent": "Cabinet_2"},
        {"name": "Mug", "type": "Mug", "parent": "CounterTop", "is_dirty": True},
        {"name": "Pencil", "type": "Pencil", "parent": "CounterTop"},
    ]}
    return World.from_scene(scene)


def run(w: World, *actions: str) -> list[tuple[bool, str]]:
    return [w.step(a) for a in actions]


def test_parse_action_and_suffix() -> None:
    assert parse_action("open the Cabinet_2") == ("open", "Cabinet_2")
    assert parse_action("put down the object in hand") == ("put", None)
    assert instance_index("Cabinet_2") == ("Cabinet", 2)
    assert instance_index("Cabinet") == ("Cabinet", 1)
    with pytest.raises(ValueError):
        parse_action("teleport to the moon")


def test_object_not_in_scene_is_named() -> None:
    ok, fb = kitchen().step("find a Laptop")
    assert not ok and "no Laptop" in fb


def test_must_find_before_acting() -> None:
    w = kitchen()
    ok, fb = w.step("pick up the Apple_2")
    assert not ok and "not found" in fb
    ok, fb = run(w, "find a Apple_2", "find a Mug")[-1]
    ok, fb = w.step("pick up the Apple_2")
    assert not ok and "not close" in fb


def test_closed_receptacle_hides_and_blocks() -> None:
    w = kitchen()
    ok, fb = w.step("find a Apple")
    assert ok and "closed" in fb and "Fridge" in fb
    ok, fb = w.step("pick up the Apple")
    assert not ok and "inside the Fridge, which is closed" in fb
    run(w, "open the Fridge", "pick up the Apple")
    assert w.held == "Apple"


def test_one_object_in_hand_and_put_down_feedback() -> None:
    w = kitchen()
    run(w, "find a Apple_2", "pick up the Apple_2", "find a Mug")
    ok, fb = w.step("pick up the Mug")
    assert not ok and "holding the Apple_2" in fb
    ok, fb = kitchen().step("put down the object in hand")
    assert not ok and "not holding anything" in fb


def test_put_down_goes_into_sink_basin_not_on_sink() -> None:
    w = kitchen()
    run(w, "find a Mug", "pick up the Mug", "find a Sink")
    ok, _ = w.step("put down the object in hand")
    assert ok and w.objects["Mug"].parent == "SinkBasin"


def test_already_open_and_closed() -> None:
    w = kitchen()
    run(w, "find a Cabinet", "open the Cabinet")
    ok, fb = w.step("open the Cabinet")
    assert not ok and "already open" in fb
    w.step("close the Cabinet")
    ok, fb = w.step("close the Cabinet")
    assert not ok and "already closed" in fb


def test_slicing_needs_a_knife() -> None:
    w = kitchen()
    w.step("find a Apple_2")
    ok, fb = w.step("slice the Apple_2")
    assert not ok and "knife" in fb
    run(w, "find a Cabinet_2", "open the Cabinet_2", "pick up the Knife", "find a Apple_2")
    ok, _ = w.step("slice the Apple_2")
    assert ok and w.objects["Apple_2"].is_sliced


def test_heat_cool_clean() -> None:
    w = kitchen()
    # Heat: inside a closed microwave that is switched on.
    run(w, "find a Apple_2", "pick up the Apple_2", "find a Microwave", "open the Microwave",
        "put down the object in hand", "close the Microwave")
    ok, fb = w.step("open the Microwave")
    assert ok
    ok, fb = w.step("turn on the Microwave")
    assert not ok and "close it" in fb
    run(w, "close the Microwave", "turn on the Microwave")
    assert w.objects["Apple_2"].is_hot
    ok, fb = w.step("open the Microwave")
    assert not ok and "Turn it off" in fb
    # Cool: fridge closed with it inside.
    run(w, "turn off the Microwave", "open the Microwave", "pick up the Apple_2", "find a Fridge", "open the Fridge",
        "put down the object in hand")
    assert not w.objects["Apple_2"].is_cold
    w.step("close the Fridge")
    assert w.objects["Apple_2"].is_cold and not w.objects["Apple_2"].is_hot
    # Clean: in the basin while the faucet runs.
    run(w, "find a Mug", "pick up the Mug", "find a SinkBasin", "put down the object in hand")
    assert w.objects["Mug"].is_dirty
    ok, fb = w.step("turn on the Faucet")
    assert ok and not w.objects["Mug"].is_dirty and "Mug" in fb


def test_stack_carries_contents() -> None:
    w = kitchen()
    run(w, "find a Pencil", "pick up the Pencil", "find a Mug", "put down the object in hand", "pick up the Mug",
        "find a DiningTable", "put down the object in hand")
    assert w.objects["Pencil"].parent == "Mug" and w.objects["Mug"].parent == "DiningTable"


def test_failed_action_changes_nothing() -> None:
    w = kitchen()
    before = w.to_scene()
    w.step("pick up the Apple")
    w.step("open the Fridge")
    assert w.to_scene() == before


def living_room() -> World:
    return World.from_scene({"room": "living_room", "objects": [
        {"name": "Sofa", "type": "Sofa", "slot": 0},
        {"name": "Desk", "type": "Desk", "slot": 1},
        {"name": "SideTable", "type": "SideTable", "slot": 2},
        {"name": "Drawer", "type": "Drawer", "slot": 3},
        {"name": "Drawer_2", "type": "Drawer", "slot": 4},
        {"name": "DeskLamp", "type": "DeskLamp", "parent": "Desk"},
        {"name": "DeskLamp_2", "type": "DeskLamp", "parent": "SideTable"},
        {"name": "RemoteControl", "type": "RemoteControl", "parent": "Sofa"},
        {"name": "RemoteControl_2", "type": "RemoteControl", "parent": "SideTable"},
        {"name": "RemoteControl_3", "type": "RemoteControl", "parent": "SideTable"},
        {"name": "KeyChain", "type": "KeyChain", "parent": "Drawer_2"},
    ]})


def test_plain_name_acts_on_the_instance_you_are_at() -> None:
    """Issue 11: 'find a RemoteControl_2' then 'pick up the RemoteControl' takes RemoteControl_2."""
    w = living_room()
    run(w, "find a RemoteControl_2")
    ok, fb = w.step("pick up the RemoteControl")
    assert ok and w.held == "RemoteControl_2", fb
    run(w, "find a SideTable", "put down the object in hand")
    # The lamp, the drawer: the plain name means the one here, not the first one in the room.
    ok, _ = w.step("turn on the DeskLamp")
    assert ok and w.objects["DeskLamp_2"].is_on and not w.objects["DeskLamp"].is_on
    run(w, "find a Drawer_2")
    ok, fb = w.step("open the Drawer")
    assert ok and w.objects["Drawer_2"].is_open and not w.objects["Drawer"].is_open and "KeyChain" in fb


def test_nearest_prefers_the_faced_then_the_lowest_visible_instance() -> None:
    w = living_room()
    run(w, "find a RemoteControl_3", "pick up the RemoteControl")
    assert w.held == "RemoteControl_3"  # faced, although RemoteControl_2 lies on the same table
    run(w, "put down the object in hand", "find a SideTable", "pick up the RemoteControl")
    assert w.held == "RemoteControl_2"  # facing the table: the lowest-numbered one in view


def test_plain_name_with_none_in_reach_says_so() -> None:
    w = living_room()
    run(w, "find a Desk")
    ok, fb = w.step("pick up the RemoteControl")
    assert not ok and "no RemoteControl is within reach" in fb and "you are at the Desk" in fb
    ok, fb = w.step("close the Drawer")
    assert not ok and "Drawer" in fb


def test_slice_with_plain_name_cuts_the_one_here() -> None:
    w = kitchen()
    run(w, "find a Cabinet_2", "open the Cabinet_2", "pick up the Knife", "find a Apple_2")
    ok, _ = w.step("slice the Apple")
    assert ok and w.objects["Apple_2"].is_sliced and not w.objects["Apple"].is_sliced


def test_extra_instances_only_get_find_open_close() -> None:
    from eb_alfred.actions import GLOBAL_ACTIONS, scene_actions

    acts = scene_actions(living_room())
    extra = acts[len(GLOBAL_ACTIONS):]
    assert acts[:len(GLOBAL_ACTIONS)] == GLOBAL_ACTIONS
    assert set(extra) == {"find a DeskLamp_2", "find a Drawer_2", "open the Drawer_2", "close the Drawer_2",
                          "find a RemoteControl_2", "find a RemoteControl_3"}
