"""World failure labels for the core's error analysis: ``info["failure"]`` on every failed skill and
``info["wrong_target"]`` on a successful skill that acted on the wrong instance (docs/error_analysis.md)."""

from __future__ import annotations

import random

import pytest

from eb_core.env import Task
from eb_core.errors import FAILURE_LABELS
from eb_habitat.env import HabitatEnv
from eb_habitat.skills import SKILLS, skill_id
from eb_habitat.world import FAILURES


def _task() -> Task:
    """Two red-vs-blue mugs: the goal wants mug_2 (on the coffee table) on the dining table; the blue mug_1 is
    the leftmost thing on the sofa; a ball fills the one-seat left chair; an apple waits in the closed fridge."""
    objects = [
        {"name": "mug_1", "type": "mug", "color": "blue", "at": "sofa", "slot": 0},
        {"name": "mug_2", "type": "mug", "color": "red", "at": "coffee_table", "slot": 0},
        {"name": "ball_1", "type": "ball", "color": "green", "at": "left_chair", "slot": 0},
        {"name": "apple_1", "type": "apple", "color": "red", "at": "fridge", "slot": 0},
    ]
    return Task(id="failures-00", subset="base", instruction="Put the red mug on the dining table.",
                metadata={"apartment": 0, "template": "base.move.0", "objects": objects, "open": [],
                          "goal": ["(on mug_2 dining_table)"],
                          "subgoals": [["(holding mug_2)"], ["(on mug_2 dining_table)"]], "oracle_steps": 4})


@pytest.fixture()
def env():
    e = HabitatEnv(render=False)
    e.reset(_task(), 0)
    yield e
    e.close()


def _do(env: HabitatEnv, kind: str, arg: str):
    return env.step(skill_id(kind, arg))


def _failed(env: HabitatEnv, kind: str, arg: str, label: str) -> None:
    r = _do(env, kind, arg)
    assert not r.action_success, f"{kind} {arg} should fail"
    assert r.info["failure"] == label, (kind, arg, r.feedback)
    assert "wrong_target" not in r.info


def _succeeded(env: HabitatEnv, kind: str, arg: str, wrong: bool = False) -> None:
    r = _do(env, kind, arg)
    assert r.action_success, r.feedback
    assert r.info["failure"] is None
    assert r.info.get("wrong_target", False) is wrong, (kind, arg)


def test_every_label_is_one_the_core_knows() -> None:
    assert set(FAILURES) <= set(FAILURE_LABELS)
    assert "affordance" not in FAILURES  # no skill can address something that cannot take it


def test_precondition_failures(env: HabitatEnv) -> None:
    _failed(env, "pick", "apple", "precondition")           # not at any receptacle
    _failed(env, "place", "sofa", "precondition")           # hand empty
    _failed(env, "open", "fridge", "precondition")          # out of reach
    _succeeded(env, "navigate", "sofa")
    _failed(env, "pick", "apple", "precondition")           # the apple lies elsewhere (in the fridge)
    _failed(env, "close", "fridge", "precondition")         # out of reach
    _succeeded(env, "navigate", "fridge")
    _failed(env, "pick", "apple", "precondition")           # the fridge is closed
    _failed(env, "close", "fridge", "precondition")         # already closed
    _succeeded(env, "open", "fridge")
    _failed(env, "open", "fridge", "precondition")          # already open
    _succeeded(env, "pick", "apple")
    _failed(env, "pick", "apple", "precondition")           # hand full (another apple would not be here anyway)
    _failed(env, "place", "sofa", "precondition")           # not at the sofa
    _succeeded(env, "navigate", "left_chair")
    _failed(env, "place", "left_chair", "precondition")     # the one seat is taken
    _succeeded(env, "navigate", "fridge")
    _succeeded(env, "place", "fridge")
    _succeeded(env, "close", "fridge")
    _failed(env, "place", "fridge", "precondition")         # hand empty again


def test_pick_of_a_kind_the_apartment_lacks_is_a_wrong_target(env: HabitatEnv) -> None:
    _succeeded(env, "navigate", "sofa")
    _failed(env, "pick", "hammer", "absent")          # there is no hammer anywhere
    _failed(env, "pick", "ball", "precondition")            # there is one, on the left chair


def test_look_alike_and_wrong_place_are_flagged_on_successful_skills(env: HabitatEnv) -> None:
    _succeeded(env, "navigate", "sofa")
    _succeeded(env, "pick", "mug", wrong=True)              # the blue mug_1, not the goal's mug_2
    _succeeded(env, "place", "sofa")                        # putting the look-alike back is no wrong target
    _succeeded(env, "navigate", "coffee_table")
    _succeeded(env, "pick", "mug")                          # mug_2 itself
    _succeeded(env, "navigate", "desk")
    _succeeded(env, "place", "desk", wrong=True)            # the goal's mug on a receptacle the goal does not name
    _succeeded(env, "pick", "mug")
    _succeeded(env, "navigate", "dining_table")
    r = _do(env, "place", "dining_table")
    assert r.task_success and r.info["failure"] is None and "wrong_target" not in r.info


def test_making_room_on_a_full_goal_receptacle_is_not_a_wrong_target() -> None:
    task = _task()
    task.metadata["goal"] = ["(on mug_2 left_chair)"]
    task.metadata["subgoals"] = [["(holding mug_2)"], ["(on mug_2 left_chair)"]]
    task.metadata["objects"][2] = {"name": "mug_3", "type": "mug", "color": "green", "at": "left_chair", "slot": 0}
    env = HabitatEnv(render=False)
    env.reset(task, 0)
    _succeeded(env, "navigate", "left_chair")
    _succeeded(env, "pick", "mug")                          # mug_3 off the full chair: clearing, not confusion
    steps = 0
    while not env._tracker.success(env._world):  # noqa: SLF001 - the expert finishes the task
        r = env.step(env.expert_plan()[0])
        assert r.action_success and "wrong_target" not in r.info
        steps += 1
    assert steps > 0


@pytest.mark.parametrize("seed", range(4))
def test_random_walks_label_every_failure(seed: int) -> None:
    rng = random.Random(seed)
    env = HabitatEnv(render=False)
    tasks = HabitatEnv.load_tasks()
    seen: set[str] = set()
    for task in rng.sample(tasks, 10):
        env.reset(task, 0)
        for _ in range(30):
            a = rng.randrange(len(SKILLS))
            r = env.step(a)
            if r.action_success:
                assert r.info["failure"] is None
            else:
                assert r.info["failure"] in FAILURES, (task.id, SKILLS[a], r.feedback)
                seen.add(r.info["failure"])
            if r.done:
                break
    assert "precondition" in seen


def test_the_expert_never_triggers_a_label() -> None:
    env = HabitatEnv(render=False)
    for task in HabitatEnv.load_tasks()[::5]:
        env.reset(task, 0)
        for a in env.expert_plan():
            r = env.step(a)
            assert r.action_success and r.info["failure"] is None and "wrong_target" not in r.info, task.id
        assert r.task_success
