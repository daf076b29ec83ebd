"""The oracle solves all 300 shipped tasks (15 steps at most, 17 in long_horizon); a seeded random agent almost
never does."""

from __future__ import annotations

import numpy as np

from eb_navigation.env import NavigationEnv


def _oracle_episode(env: NavigationEnv, max_steps: int = 20) -> tuple[bool, int]:
    steps, result = 0, None
    while steps < max_steps:
        plan = env.expert_plan()
        assert plan, "the oracle must always have a plan for an unsolved task"
        for a in plan:
            result = env.step(a)
            steps += 1
            if result.done or not result.action_success or steps >= max_steps:
                break
        if result is not None and result.done:
            break
    return bool(result and result.task_success), steps


def test_oracle_solves_all_300_shipped_tasks_geometry_only() -> None:
    env = NavigationEnv(render=False)
    tasks = NavigationEnv.load_tasks()
    failures, steps = [], []
    for task in tasks:
        env.reset(task, 0)
        ok, n = _oracle_episode(env)
        steps.append(n)
        if not ok:
            failures.append(task.id)
        assert n == task.metadata["oracle_steps"], task.id
    env.close()
    assert not failures, f"oracle failed: {failures}"
    assert max(steps) <= 17


def test_oracle_replans_from_the_current_state() -> None:
    env = NavigationEnv(render=False)
    task = NavigationEnv.load_tasks()[0]
    env.reset(task, 0)
    before = env.expert_plan()
    env.step(4)  # turn away
    env.step(4)
    after = env.expert_plan()
    assert after and after != before and len(after) >= len(before)
    ok, _ = _oracle_episode(env, 18)
    assert ok
    env.close()


def test_seeded_random_agent_rarely_succeeds() -> None:
    env = NavigationEnv(render=False)
    tasks = NavigationEnv.load_tasks()
    rng = np.random.default_rng(0)
    wins = 0
    for task in tasks:
        env.reset(task, 0)
        for _ in range(20):
            if env.step(int(rng.integers(8))).done:
                wins += 1
                break
    env.close()
    assert wins / len(tasks) <= 0.05, f"random agent solved {wins}/{len(tasks)}"
