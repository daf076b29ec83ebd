"""The expert solves every shipped task (symbolic world, no rendering); a random agent does not."""

from __future__ import annotations

import random

import pytest

from eb_habitat.env import HabitatEnv


@pytest.fixture(scope="module")
def env():
    env = HabitatEnv(render=False)
    yield env
    env.close()


@pytest.fixture(scope="module")
def tasks():
    return HabitatEnv.load_tasks()


def run_oracle(env: HabitatEnv, task, budget: int = 30):
    env.reset(task, 0)
    steps, result = 0, None
    while steps < budget:
        plan = env.expert_plan()
        assert plan, f"no expert plan for unsolved {task.id}"
        for action in plan:
            result = env.step(action)
            steps += 1
            assert result.action_success, f"{task.id}: expert action failed: {result.feedback}"
            if result.done or steps >= budget:
                break
        if result is not None and result.done:
            break
    return steps, result


def test_oracle_solves_all_300(env, tasks) -> None:
    assert len(tasks) == 300
    failed = []
    for task in tasks:
        steps, result = run_oracle(env, task)
        if not (result.task_success and result.progress == 1.0):
            failed.append(task.id)
        assert steps == task.metadata["oracle_steps"], task.id
    assert not failed, f"oracle failed {failed}"


def test_random_agent_stays_low(env, tasks) -> None:
    rng = random.Random(0)
    wins, progress = 0, 0.0
    for task in tasks:
        env.reset(task, 0)
        result = None
        for _ in range(30):
            result = env.step(rng.randrange(70))
            if result.done:
                break
        wins += result.task_success
        progress += result.progress
    assert wins / len(tasks) < 0.05
    assert progress / len(tasks) < 0.15


def test_expert_recovers_from_odd_states(env, tasks) -> None:
    """From the middle of a random walk (holding things, containers open), the expert still finishes."""
    rng = random.Random(1)
    for task in tasks[::10]:
        env.reset(task, 0)
        for _ in range(12):
            if env.step(rng.randrange(70)).done:
                break
        steps, result = run_oracle(env, task, budget=60)
        assert result is None or result.task_success, task.id


def test_closed_loop_follows_the_open_loop_plan(env, tasks) -> None:
    """Asking the expert again after every single step gives the same actions as its first plan: the plan is a
    function of the state, and each step moves along it (a closed-loop oracle cannot wander)."""
    for task in tasks:
        env.reset(task, 0)
        first = env.expert_plan()
        taken = []
        for _ in range(len(first) + 2):
            plan = env.expert_plan()
            if not plan:
                break
            taken.append(plan[0])
            if env.step(plan[0]).done:
                break
        assert taken == first, task.id
