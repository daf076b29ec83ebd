"""The expert re-plans from whatever state the agent is in, and says why when the target cannot be reached."""

from __future__ import annotations

import numpy as np
import pytest

from eb_navigation.env import NavigationEnv
from eb_navigation.geometry import GRID_RESOLUTION, FreeSpace


@pytest.fixture(scope="module")
def tasks():
    return NavigationEnv.load_tasks()


@pytest.fixture()
def env():
    e = NavigationEnv(render=False)
    yield e
    e.close()


def _walk_away(env: NavigationEnv) -> None:
    for a in (1, 1, 1, 3, 3):  # back off and step aside (failed moves are fine)
        env.step(a)


def _turn_around(env: NavigationEnv) -> None:
    env.step(4)
    env.step(4)
    env.step(0)


def _bump_a_wall(env: NavigationEnv) -> None:
    for _ in range(30):
        if not env.step(2).action_success:  # side-step right until something stops it
            return
    raise AssertionError("no wall within 30 side steps")


def _finish(env: NavigationEnv) -> bool:
    plan = env.expert_plan()
    assert plan is not None and env.expert_reason is None
    result = None
    for a in plan:
        result = env.step(a)
        assert result.action_success, "the expert's plan never bumps into anything"
    return bool(result and result.task_success)


@pytest.mark.parametrize("detour", [_walk_away, _turn_around, _bump_a_wall])
def test_expert_reaches_the_goal_after_a_detour(env: NavigationEnv, tasks, detour) -> None:
    for task in tasks[::7]:  # every subset, 43 rooms and starts
        env.reset(task, 0)
        detour(env)
        if env.expert_plan() == []:
            continue  # the detour happened to end within reach
        assert _finish(env), task.id


def test_expert_after_random_wandering(env: NavigationEnv, tasks) -> None:
    rng = np.random.default_rng(1)
    for task in tasks[3::10]:
        env.reset(task, 0)
        for _ in range(12):
            if env.step(int(rng.integers(8))).done:
                break
        else:
            assert _finish(env), task.id


def test_expert_gives_none_and_a_reason_when_the_target_is_cut_off(env: NavigationEnv, tasks) -> None:
    task = tasks[0]
    env.reset(task, 0)
    free = env._free  # noqa: SLF001 - white-box: wall the target in to make it unreachable
    tx, ty = task.metadata["target"]["position"][:2]
    xs = (np.arange(free.grid.shape[0]) + 0.5) * GRID_RESOLUTION - free.size[0] / 2
    ys = (np.arange(free.grid.shape[1]) + 0.5) * GRID_RESOLUTION - free.size[1] / 2
    r = np.hypot(xs[:, None] - tx, ys[None, :] - ty)
    grid = free.grid & ~((r > 1.1) & (r < 1.5))
    env._free = FreeSpace(grid, free.size, free.resolution)  # noqa: SLF001
    assert env._free.goal_cells((tx, ty)).any()  # noqa: SLF001 - free floor near it, behind the ring
    assert env.expert_plan() is None
    assert "cannot be reached" in env.expert_reason and "cut off" in env.expert_reason
    assert task.metadata["target"]["id"] in env.expert_reason


def test_expert_gives_none_and_a_reason_without_free_floor_near_the_target(env: NavigationEnv, tasks) -> None:
    env.reset(tasks[0], 0)
    env._target_xy = (50.0, 50.0)  # noqa: SLF001 - white-box: a target far outside the room
    assert env.expert_plan() is None and "no free floor within 1 m" in env.expert_reason


def test_expert_before_reset_says_so() -> None:
    e = NavigationEnv(render=False)
    assert e.expert_plan() is None and "reset()" in e.expert_reason
