"""World failure labels and the distance to the goal for the core's error analysis (docs/error_analysis.md):
``info["failure"]`` on every failed action and ``info["distance_to_goal"]`` after every action."""

from __future__ import annotations

import math
import random

import pytest

from eb_core.errors import FAILURE_LABELS
from eb_navigation.env import FAILURES, NavigationEnv


@pytest.fixture(scope="module")
def tasks():
    return {t.id: t for t in NavigationEnv.load_tasks()}


@pytest.fixture()
def env():
    e = NavigationEnv(render=False)
    yield e
    e.close()


def _true_distance(env: NavigationEnv) -> float:
    s, (tx, ty) = env.state, env._target_xy  # noqa: SLF001 - the target's floor position
    return math.hypot(s.x - tx, s.y - ty)


def test_labels_are_ones_the_core_knows() -> None:
    assert set(FAILURES.values()) <= set(FAILURE_LABELS)


def test_walking_into_a_wall_is_a_collision(env: NavigationEnv, tasks) -> None:
    env.reset(tasks["base_000"], 0)
    for _ in range(200):  # forward until something is in the way
        before = env.state
        r = env.step(0)
        if not r.action_success:
            break
        assert r.info["failure"] is None
    else:
        pytest.fail("200 steps forward never hit anything")
    assert r.info["failure"] == "collision" and env.state == before
    assert r.info["distance_to_goal"] == pytest.approx(_true_distance(env), abs=1e-3)


def test_tilting_past_the_limit_is_a_precondition_failure(env: NavigationEnv, tasks) -> None:
    env.reset(tasks["base_001"], 0)
    r = env.step(6)
    assert r.action_success and r.info["failure"] is None
    r = env.step(6)
    assert not r.action_success and r.info["failure"] == "precondition"
    for _ in range(3):
        r = env.step(7)
    r = env.step(7)
    assert not r.action_success and r.info["failure"] == "precondition"


def test_distance_to_goal_after_every_action_and_at_reset(env: NavigationEnv, tasks) -> None:
    assert env.distance_to_goal is None
    env.reset(tasks["common_sense_000"], 0)
    start = env.distance_to_goal
    assert start == pytest.approx(_true_distance(env), abs=1e-3) and start > 1.0
    seen = [start]
    for a in env.expert_plan():
        r = env.step(a)
        assert r.info["distance_to_goal"] == pytest.approx(_true_distance(env), abs=1e-3)
        assert r.info["distance_to_goal"] == env.distance_to_goal
        seen.append(r.info["distance_to_goal"])
    assert r.task_success and seen[-1] <= 1.0 < seen[0]


@pytest.mark.parametrize("seed", range(3))
def test_random_walks_label_every_failure(seed: int, tasks) -> None:
    rng = random.Random(seed)
    env = NavigationEnv(render=False)
    seen = set()
    for task in rng.sample(sorted(tasks.values(), key=lambda t: t.id), 8):
        env.reset(task, 0)
        for _ in range(40):
            r = env.step(rng.randrange(8))
            assert isinstance(r.info["distance_to_goal"], float)
            if r.action_success:
                assert r.info["failure"] is None
            else:
                assert r.info["failure"] in ("collision", "precondition")
                seen.add(r.info["failure"])
            if r.done:
                break
    assert "collision" in seen
