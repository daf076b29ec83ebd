"""The expert plans from the current state only: after scripted detours it still finishes within the budget;
when the goal cannot be reached it returns None and says why."""

from __future__ import annotations

import pytest

from eb_core.env import Task
from eb_habitat.env import HabitatEnv
from eb_habitat.skills import skill_id


@pytest.fixture()
def env():
    e = HabitatEnv(render=False)
    yield e
    e.close()


def _task(objects, goal, opened=(), tid="detour-00") -> Task:
    objs = [{"name": n, "type": n.rsplit("_", 1)[0], "color": c, "at": at, "slot": s} for n, c, at, s in objects]
    subgoals = [[g] for g in goal]
    meta = {"apartment": 0, "template": "test", "objects": objs, "open": list(opened), "goal": goal,
            "subgoals": subgoals, "oracle_steps": 1}
    return Task(id=tid, subset="base", instruction="test", metadata=meta)


SCENE = [("mug_1", "red", "dining_table", 0), ("apple_1", "red", "dining_table", 1),
         ("lemon_1", "yellow", "left_drawer", 0), ("ball_1", "red", "sofa", 2)]
GOAL = ["(inside ?lemon fridge)", "(closed fridge)"]


def _finish(env: HabitatEnv, budget: int = 30) -> bool:
    """Follow the expert from wherever the episode is, re-asking after each of its plans."""
    steps = 0
    while steps < budget:
        plan = env.expert_plan()
        assert plan is not None, env.expert_reason
        assert plan, "an empty plan for an unsolved task"
        for a in plan:
            r = env.step(a)
            steps += 1
            assert r.action_success, r.feedback
            if r.done:
                return True
    return False


def _do(env: HabitatEnv, *actions: tuple[str, str]) -> None:
    for kind, arg in actions:
        env.step(skill_id(kind, arg))


@pytest.mark.parametrize("detour", [
    # wrong pick: the robot takes the mug and is holding it
    (("navigate", "dining_table"), ("pick", "mug")),
    # opened the wrong drawer and walked off
    (("navigate", "right_drawer"), ("open", "right_drawer"), ("navigate", "desk")),
    # the right object put in the wrong place, the fridge left open
    (("navigate", "left_drawer"), ("open", "left_drawer"), ("pick", "lemon"), ("navigate", "fridge"),
     ("open", "fridge"), ("navigate", "sofa"), ("place", "sofa")),
    # holding the goal object next to a closed fridge
    (("navigate", "left_drawer"), ("open", "left_drawer"), ("pick", "lemon"), ("navigate", "fridge")),
])
def test_expert_finishes_after_a_detour(env, detour) -> None:
    env.reset(_task(SCENE, GOAL), 0)
    _do(env, *detour)
    assert _finish(env)


def test_plan_depends_on_the_state_not_the_history(env) -> None:
    task = _task(SCENE, GOAL)
    env.reset(task, 0)
    _do(env, ("navigate", "sofa"), ("navigate", "desk"), ("navigate", "left_drawer"), ("open", "left_drawer"),
        ("close", "left_drawer"))
    via_detour = env.expert_plan()
    env.reset(task, 0)
    _do(env, ("navigate", "left_drawer"))
    direct = env.expert_plan()
    assert via_detour == direct and env.expert_reason is None


def test_full_target_is_cleared_first(env) -> None:
    """The goal's receptacle is full of unrelated things (e.g. the agent filled it): the expert makes room."""
    scene = [("mug_1", "red", "left_chair", 0), ("apple_1", "red", "sofa", 0)]
    env.reset(_task(scene, ["(on ?apple left_chair)"]), 0)
    assert _finish(env)


def test_unreachable_goal_gives_none_and_a_reason(env) -> None:
    scene = [("mug_1", "red", "sofa", 0), ("apple_1", "red", "sofa", 1)]
    env.reset(_task(scene, ["(on ?apple left_chair)", "(on ?mug left_chair)"]), 0)  # the chair holds one thing
    assert env.expert_plan() is None
    assert env.expert_reason and "left_chair" in env.expert_reason
