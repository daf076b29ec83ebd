"""The scripted oracle solves every shipped task; random actions almost never do."""

from __future__ import annotations

import numpy as np
import pytest

from eb_manipulation.env import ManipulationEnv

MAX_STEPS = 15


def _run_oracle(env: ManipulationEnv, task) -> tuple[bool, int]:
    env.reset(task, 0)
    steps = 0
    while steps < MAX_STEPS:
        plan = env.expert_plan()
        assert plan, f"no plan for {task.id}"
        for action in plan:  # manipulation runs the whole plan unless done
            result = env.step(action)
            steps += 1
            if result.done or steps >= MAX_STEPS:
                return result.task_success, steps
        # plan ran out without success: ask again (as the oracle model would)
    return False, steps


def test_oracle_solves_all_228_shipped_tasks() -> None:
    env = ManipulationEnv(render=False)
    try:
        tasks = env.load_tasks()
        assert len(tasks) == 228
        failed = []
        for task in tasks:
            ok, _ = _run_oracle(env, task)
            if not ok:
                failed.append(task.id)
    finally:
        env.close()
    assert failed == []


def test_random_actions_stay_low() -> None:
    env = ManipulationEnv(render=False)
    rng = np.random.default_rng(0)
    space = env.action_space()
    tasks = env.load_tasks()[::29]  # 8 tasks spread over the subsets and families
    solved = 0
    try:
        for task in tasks:
            env.reset(task, 0)
            for _ in range(MAX_STEPS):
                action = tuple(int(rng.integers(lo, hi + 1)) for lo, hi in zip(space.low, space.high))
                if env.step(action).done:
                    solved += 1
                    break
    finally:
        env.close()
    assert solved <= 1


@pytest.mark.parametrize("task_id", ["base_pick_02", "spatial_stack_01", "common_sense_wipe_03"])
def test_oracle_recovers_after_a_wrong_grasp(task_id: str) -> None:
    """Close the gripper on nothing first, then follow the oracle from that state."""
    env = ManipulationEnv(render=False)
    try:
        task = next(t for t in env.load_tasks() if t.id == task_id)
        env.reset(task, 0)
        r = env.step((40, 50, 40, 120, 60, 60, 0))
        assert r.action_success and "not holding anything" in r.feedback
        ok = False
        for action in env.expert_plan() or []:
            res = env.step(action)
            if res.done:
                ok = res.task_success
                break
    finally:
        env.close()
    assert ok
