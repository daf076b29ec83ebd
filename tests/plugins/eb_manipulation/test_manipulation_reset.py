"""Resetting a task again (compiled model from the process cache) gives the episode of a first reset."""

from __future__ import annotations

import numpy as np

from eb_manipulation.env import ManipulationEnv


def _episode(env: ManipulationEnv, task, steps: int = 1) -> list[tuple[bytes, str, bool]]:
    obs = env.reset(task, 0)
    out = [(obs.images["front"].tobytes(), obs.text, True)]
    for action in (env.expert_plan() or [])[:steps]:
        r = env.step(action)
        out.append((r.observation.images["front"].tobytes(), r.observation.text, r.action_success))
    return out


def test_a_task_reset_again_replays_its_first_episode_exactly() -> None:
    tasks = ManipulationEnv.load_tasks()
    a = tasks[0]
    b = next(t for t in tasks if t.metadata["family"] != a.metadata["family"])
    env = ManipulationEnv(resolution=64)
    try:
        first = _episode(env, a)
        model_first = env._world.model  # noqa: SLF001 - the test looks inside on purpose
        other = _episode(env, b, steps=0)
        again = _episode(env, a)
        model_again = env._world.model  # noqa: SLF001
    finally:
        env.close()
    assert other[0][0] != first[0][0]
    assert again == first  # images (after reset and after each expert action), object lists, outcomes
    assert model_again is not model_first  # a copy: the first episode's model is not shared with the second
    assert np.array_equal(model_again.geom_rgba, model_first.geom_rgba)
