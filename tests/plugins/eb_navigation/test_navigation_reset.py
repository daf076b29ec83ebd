"""Resets across rooms keep their images; remembered split tasks are handed out as copies."""

from __future__ import annotations

import numpy as np

from eb_navigation.env import NavigationEnv
from eb_navigation.splits import split_tasks


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
