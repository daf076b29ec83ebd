"""Resets across rooms keep their images; remembered split tasks are handed out as copies."""

from __future__ import annotations

import numpy as np
import pytest

from eb_navigation.env import NavigationEnv
from eb_navigation import splits
from eb_navigation.splits import split_tasks, take_room


def test_switching_rooms_and_back_gives_the_same_first_images() -> None:
    tasks = NavigationEnv.load_tasks()
    a = tasks[0]
    b = next(t for t in tasks if t.metadata["scene"] != a.metadata["scene"])
    env = NavigationEnv(resolution=96)
    try:
        first_a = env.reset(a, 0).images["first_person"].copy()
        first_b = env.reset(b, 0).images["first_person"].copy()
        again_a = env.reset(a, 0).images["first_person"]
    finally:
        env.close()
    fresh = NavigationEnv(resolution=96)
    try:
        fresh_b = fresh.reset(b, 0).images["first_person"]
    finally:
        fresh.close()
    assert not np.array_equal(first_a, first_b)
    assert np.array_equal(again_a, first_a)
    assert np.array_equal(fresh_b, first_b)


def test_a_remembered_split_task_is_a_copy() -> None:
    task = split_tasks("train", 123_457, 1)[0]
    task.metadata["start"]["x"] = -99.0  # a caller scribbling on its task
    task.metadata["extra_objects"].append({"id": "scribble"})
    again = split_tasks("train", 123_457, 1)[0]
    assert again.metadata["start"]["x"] != -99.0 and {"id": "scribble"} not in again.metadata["extra_objects"]
    assert again.model_dump() == split_tasks("train", 123_457, 1)[0].model_dump()


@pytest.mark.parametrize("index", [234_561, 234_563])  # a room as generated, one with look-alikes added
def test_a_train_reset_takes_the_generators_room_once_and_draws_what_a_new_room_draws(index: int) -> None:
    splits._recent.cache_clear()  # draw it now, even if this process drew it before
    task = split_tasks("train", index, 1)[0]  # its room is kept for the reset
    scene = task.metadata["scene"]
    kept = [room for key, room in splits._ROOMS.items() if key[:2] == (scene["kind"], scene["seed"])]
    assert len(kept) == 1
    env = NavigationEnv(resolution=96)
    try:
        image = env.reset(task, 0).images["first_person"].copy()
        assert env._world.room is kept[0]  # noqa: SLF001 - the handed-over room, not a second layout
    finally:
        env.close()
    assert take_room(scene["kind"], scene["seed"], tuple(kept[0].extras)) is None  # handed out once
    fresh = NavigationEnv(resolution=96)
    try:
        rebuilt = fresh.reset(task, 0)  # nothing kept now: the room is laid out again from (kind, seed, extras)
        assert fresh._world.room is not kept[0]  # noqa: SLF001
        assert np.array_equal(rebuilt.images["first_person"], image)
    finally:
        fresh.close()
