"""The scripted expert plans from whatever state the world is in; random actions almost never solve a task."""

from __future__ import annotations

import numpy as np
import pytest

from eb_manipulation.actions import pos_to_bin
from eb_manipulation.env import ManipulationEnv
from eb_manipulation.oracle import _free_spot, state_of_world
from eb_manipulation.scene import TABLE_TOP

MAX_STEPS = 15


def _follow(env: ManipulationEnv, closed_loop: bool, steps: int = 0) -> tuple[bool, int]:
    """Follow the expert from the current state: its whole plan, or only the first action of each plan."""
    while steps < MAX_STEPS:
        plan = env.expert_plan()
        assert plan, f"no plan: {env.expert_reason}"
        for action in plan[:1] if closed_loop else plan:  # manipulation runs the whole plan unless done
            result = env.step(action)
            steps += 1
            if result.done or steps >= MAX_STEPS:
                return result.task_success, steps
    return False, steps


def test_closed_loop_expert_solves_all_228_tasks(env: ManipulationEnv, tasks) -> None:
    """Ask again after every single action: the next plan starts where the arm is (not with the same action)."""
    assert len(tasks) == 228
    failed = []
    for task in tasks.values():
        env.reset(task, 0)
        if not _follow(env, closed_loop=True)[0]:
            failed.append(task.id)
    assert failed == []


def test_open_loop_expert_solves_a_sample(env: ManipulationEnv, tasks) -> None:
    failed = []
    for task in list(tasks.values())[::3]:
        env.reset(task, 0)
        ok, steps = _follow(env, closed_loop=False)
        if not ok or steps != task.metadata["oracle_steps"]:
            failed.append(task.id)
    assert failed == []


def test_random_actions_stay_low(env: ManipulationEnv, tasks) -> None:
    rng = np.random.default_rng(0)
    space = env.action_space()
    solved = 0
    sample = list(tasks.values())[::29]  # 8 tasks spread over the subsets and families
    for task in sample:
        env.reset(task, 0)
        for _ in range(MAX_STEPS):
            action = tuple(int(rng.integers(lo, hi + 1)) for lo, hi in zip(space.low, space.high))
            if env.step(action).done:
                solved += 1
                break
    assert solved <= 1


def _first(tasks, family: str, subset: str = "base"):
    return next(t for t in tasks.values() if t.subset == subset and t.metadata["family"] == family)


@pytest.mark.parametrize("family", ["pick", "stack", "sorter", "wipe"])
def test_expert_recovers_from_a_gripper_closed_early(env: ManipulationEnv, tasks, family: str) -> None:
    env.reset(_first(tasks, family), 0)
    r = env.step((40, 50, 40, 120, 60, 60, 0))
    assert r.action_success and r.info["failure"] == "grasp" and "not holding anything" in r.feedback
    assert env.expert_plan()[0][6] == 1  # it opens the gripper first
    assert _follow(env, closed_loop=True, steps=1)[0]


@pytest.mark.parametrize("family", ["pick", "sorter", "wipe"])
def test_expert_recovers_after_the_arm_was_moved_away(env: ManipulationEnv, tasks, family: str) -> None:
    env.reset(_first(tasks, family, "common_sense"), 0)
    plan = env.expert_plan()
    assert env.step(plan[0]).action_success
    assert env.step((30, 80, 45, 120, 60, 90, 1)).action_success  # a detour to the far right, turned
    again = env.expert_plan()
    assert again[0] != plan[1] or again[0] == plan[0]  # re-planned from the new pose
    assert _follow(env, closed_loop=True, steps=2)[0]


def _hold_target(env: ManipulationEnv) -> int:
    steps = 0
    while env._world.held is None:  # follow the expert until it holds the object
        env.step(env.expert_plan()[0])
        steps += 1
    return steps


def test_expert_recovers_after_the_object_was_dropped_elsewhere(env: ManipulationEnv, tasks) -> None:
    task = _first(tasks, "pick", "complex")
    env.reset(task, 0)
    steps = _hold_target(env)
    target = env._world.held
    spot = _free_spot(env._scene, state_of_world(env._world), target)  # a free place on the table
    drop = (pos_to_bin(spot[0], "x"), pos_to_bin(spot[1], "y"), 30, 120, 60, 60)
    assert env.step((*drop, 0)).action_success  # carry it there
    assert env.step((*drop, 1)).action_success  # and let it fall
    assert env._world.held is None and np.linalg.norm(env._world.body_pos(target)[:2] - spot) < 0.03
    assert _follow(env, closed_loop=True, steps=steps + 2)[0]


def test_no_plan_for_an_object_pressed_against_a_container(env: ManipulationEnv, tasks) -> None:
    """Dropped right beside a container wall, the object cannot be grasped: None and the reason, no endless loop."""
    env.reset(_first(tasks, "pick", "complex"), 0)
    _hold_target(env)
    env.step((45, 20, 30, 120, 60, 60, 0))
    env.step((45, 20, 30, 120, 60, 60, 1))
    assert env.expert_plan() is None
    assert "against a container" in env.expert_reason


def test_expert_moves_a_cube_out_of_the_way(env: ManipulationEnv, tasks) -> None:
    """A cube stands on the one the tower must start from: it is put aside first, from the start or in mid-air."""
    task = next(t for t in tasks.values() if t.metadata["template"].endswith("/blocked2"))
    env.reset(task, 0)
    assert len(env.expert_plan()) > 8
    assert _follow(env, closed_loop=True)[0]


def test_no_plan_when_an_object_fell_off_the_table(env: ManipulationEnv, tasks) -> None:
    task = _first(tasks, "sorter")
    env.reset(task, 0)
    world = env._world
    target = task.metadata["goal"]["target"]
    world._set_free_pose(target, np.array([0.2, 0.9, TABLE_TOP - 0.3]), np.eye(3))  # knocked off the far side
    world.settle()
    assert env.expert_plan() is None
    assert "fell off the table" in env.expert_reason and "object " in env.expert_reason
