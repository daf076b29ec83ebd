"""Navigation rooms on the scene kit: deterministic, furnished, walkable, extras shown or left out."""

from __future__ import annotations

import pytest

from eb_navigation.room import KINDS, ExtraSpec, NavRoom


@pytest.mark.parametrize("kind", KINDS)
def test_rooms_come_from_the_scene_kit_and_are_walkable(kind: str) -> None:
    a, b = NavRoom(kind, 5), NavRoom(kind, 5)
    assert a.objects == b.objects and a.layout.xml == b.layout.xml
    assert len(a.objects) >= 5 and len(a.index) == len(a.objects)
    free = a.free_space()
    assert len(free.free_cells()) > 20, "the agent needs room to walk"
    hx, hy = a.size[0] / 2, a.size[1] / 2
    for o in a.objects:
        assert -hx <= o.x <= hx and -hy <= o.y <= hy, o


def test_extras_are_in_the_room_only_for_tasks_that_use_them() -> None:
    plain = NavRoom("kitchen", 3)
    extra = ExtraSpec("Fridge_2", "Fridge", "black", -1.5, -1.9, 90.0)
    room = NavRoom("kitchen", 3, [extra])
    assert room.get("Fridge_2").type == "Fridge" and room.get("Fridge_2").colour == "black"
    assert room.counts()["Fridge"] == plain.counts()["Fridge"]
    assert room.counts({"Fridge_2"})["Fridge"] == plain.counts()["Fridge"] + 1
    assert room.free_space().free_cells() == plain.free_space().free_cells()
    with_it = set(room.free_space({"Fridge_2"}).free_cells())
    assert with_it < set(plain.free_space().free_cells()), "the extra fridge takes floor space"
    assert room.index["Fridge_2"] not in room.visible_objects()
    assert room.index["Fridge_2"] in room.visible_objects({"Fridge_2"})


def test_unknown_kind_is_named() -> None:
    with pytest.raises(ValueError, match="unknown room kind 'garage'"):
        NavRoom("garage", 0)
