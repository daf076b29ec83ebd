"""The world's error labels (``info["failure"]``, ``info["wrong_target"]``) and ``info["distance_to_goal"]``."""

from __future__ import annotations

import numpy as np
import pytest

from eb_core.errors import FAILURE_LABELS
from eb_manipulation.actions import pos_to_bin
from eb_manipulation.env import ManipulationEnv
from eb_manipulation.oracle import expert_plan, state_of_world
from eb_manipulation.world import FAILURES


def test_every_failure_value_is_one_the_core_knows() -> None:
    assert set(FAILURES.values()) <= set(FAILURE_LABELS)


@pytest.mark.parametrize(("action", "label", "words"), [
    ((10, 10, 10, 200, 60, 60, 1), "affordance", "roll=200"),  # a value out of range
    ((99, 50, 20, 120, 60, 60, 1), "precondition", "cannot reach"),  # 1 m in front of the robot: no IK solution
    ((40, 50, 5, 120, 60, 60, 1), "collision", "table"),  # 10 cm below the table top
])
def test_a_scripted_failure_carries_its_label(env: ManipulationEnv, tasks, action, label: str, words: str) -> None:
    env.reset(tasks["base_stack_00"], 0)
    r = env.step(action)
    assert not r.action_success and r.info["failure"] == label and words in r.feedback
    assert r.info["distance_to_goal"] > 0


def test_closing_on_nothing_is_executed_but_labelled_a_grasp_failure(env: ManipulationEnv, tasks) -> None:
    """As in the original the action is executed (a success); the world still reports the missed grasp."""
    env.reset(tasks["base_stack_00"], 0)
    r = env.step((40, 50, 40, 120, 60, 60, 0))  # closing in mid-air
    assert r.action_success and r.info["failure"] == "grasp" and "not holding anything" in r.feedback


def test_a_path_through_an_object_is_a_collision(env: ManipulationEnv, tasks) -> None:
    """A goal pose that puts the hand into an object is refused with ``collision``."""
    env.reset(tasks["base_pick_00"], 0)
    world = env._world
    hits = 0
    for key in world.free_objects:
        p = world.body_pos(key)
        env.reset(tasks["base_pick_00"], 0)
        # the tool centre point at the object's own centre, fingers closing across it: the hand would be inside
        r = env.step((pos_to_bin(p[0], "x"), pos_to_bin(p[1], "y"), pos_to_bin(p[2] - 0.03, "z"), 120, 60, 60, 1))
        if not r.action_success:
            assert r.info["failure"] in ("collision", "precondition")
            hits += r.info["failure"] == "collision"
    assert hits >= 1


def test_grasping_the_wrong_object_is_flagged(env: ManipulationEnv, tasks) -> None:
    task = tasks["base_pick_00"]
    env.reset(task, 0)
    scene = env._scene
    other = next(o.id for o in scene.objects if o.kind == "shape" and o.id != scene.goal.target)
    # the expert's plan for a scene whose target is another shape: it grasps that shape
    wrong = scene.model_copy(update={"goal": scene.goal.model_copy(update={"target": other})})
    plan = expert_plan(wrong, state_of_world(env._world))
    for action in plan:
        r = env.step(tuple(action))
        assert r.action_success
        if action[6] == 0:
            break
    assert env._world.held == other and r.info["wrong_target"] is True and r.info["failure"] is None
    # the task's own target is not flagged
    env.reset(task, 0)
    flags = [env.step(a).info["wrong_target"] for a in env.expert_plan()]
    assert not any(flags)


def test_random_failures_all_carry_a_known_label(env: ManipulationEnv, tasks) -> None:
    rng = np.random.default_rng(1)
    space = env.action_space()
    seen: dict[str, int] = {}
    for task in list(tasks.values())[5::57]:  # 4 tasks, one per family
        env.reset(task, 0)
        for i in range(12):
            action = [int(rng.integers(lo, hi + 1)) for lo, hi in zip(space.low, space.high)]
            if i % 4 == 3:
                action[3] = 121 + int(rng.integers(0, 50))  # now and then a value out of range
            r = env.step(tuple(action))
            if r.action_success:
                assert r.info["failure"] in (None, "grasp")  # an empty close is executed but labelled
            else:
                assert r.info["failure"] in FAILURE_LABELS, r.feedback
                seen[r.info["failure"]] = seen.get(r.info["failure"], 0) + 1
            assert r.info["distance_to_goal"] >= 0
    assert "affordance" in seen and len(seen) >= 3


@pytest.mark.parametrize("family", ["pick", "stack", "sorter", "wipe"])
def test_distance_shrinks_along_the_expert_plan(env: ManipulationEnv, tasks, family: str) -> None:
    """Positive until the goal holds and 0 then; it grows by more than 1 cm only when the task made progress
    (a stacked cube hands the goal over to the next cube), and every pick/sorter/wipe plan ends far below its start."""
    for k in range(2):
        env.reset(tasks[f"spatial_{family}_{k:02d}"], 0)
        dist, progress = [env.distance_to_goal()], [0.0]
        for action in env.expert_plan():
            r = env.step(action)
            dist.append(r.info["distance_to_goal"])
            progress.append(r.progress)
        assert r.task_success and dist[-1] == 0.0 and all(d > 0 for d in dist[:-1])
        for i in range(1, len(dist)):
            if dist[i] > dist[i - 1] + 0.01:
                assert progress[i] > progress[i - 1], (dist, progress)
        if family != "stack":
            assert max(dist[1:]) < dist[0]
