"""World failure labels (``StepResult.info["failure"]``), goals with extra preparation (``also``), and the
shipped tasks against the current expert (stored ``oracle_steps``, the long_horizon subset's make-up)."""

from __future__ import annotations

import json
from collections import Counter

import pytest

from eb_core import Task

from eb_alfred.env import AlfredEnv
from eb_alfred.goals import conditions, evaluate
from eb_alfred.oracle import expert_plan
from eb_alfred.tasks import SUBSETS, TASK_DIR, TaskFileError, load_task_file
from eb_alfred.world import FAILURES, World


def scene() -> dict:
    return {"room": "kitchen", "objects": [
        {"name": "Fridge", "type": "Fridge", "slot": 0},
        {"name": "CounterTop", "type": "CounterTop", "slot": 1},
        {"name": "Sink", "type": "Sink", "slot": 2},
        {"name": "SinkBasin", "type": "SinkBasin", "parent": "Sink"},
        {"name": "Faucet", "type": "Faucet", "parent": "Sink"},
        {"name": "Cabinet", "type": "Cabinet", "slot": 3},
        {"name": "DiningTable", "type": "DiningTable", "slot": 4},
        {"name": "Microwave", "type": "Microwave", "parent": "CounterTop"},
        {"name": "Apple", "type": "Apple", "parent": "Fridge", "color": "red"},
        {"name": "Knife", "type": "Knife", "parent": "Cabinet"},
        {"name": "Mug", "type": "Mug", "parent": "CounterTop", "color": "white"},
        {"name": "Mug_2", "type": "Mug", "parent": "DiningTable", "color": "black"},
        {"name": "Pot", "type": "Pot", "parent": "CounterTop"},
    ]}


# --------------------------------------------------------------------------------------------- world labels
@pytest.mark.parametrize("actions, label", [
    # affordance: the thing does not support the action, whatever the state
    (["find a Apple", "open the Fridge", "slice the Apple"], "affordance"),          # no knife in hand
    (["find a Fridge", "pick up the Fridge"], "affordance"),                          # furniture is not picked up
    (["find a DiningTable", "open the DiningTable"], "affordance"),                   # a table does not open
    (["find a CounterTop", "turn on the CounterTop"], "affordance"),
    (["find a Mug", "slice the Mug"], "affordance"),
    (["find a Pot", "pick up the Pot", "find a Mug", "put down the object in hand"], "affordance"),  # pot in mug
    # precondition: the right action in the wrong state
    (["find a Apple", "pick up the Apple"], "precondition"),                          # inside the closed fridge
    (["pick up the Mug_2"], "precondition"),                                          # not found yet / not near
    (["find a Mug", "pick up the Mug", "pick up the Pot"], "precondition"),           # hand full
    (["put down the object in hand"], "precondition"),                                # hand empty
    (["drop the object in hand"], "precondition"),
    (["find a Fridge", "close the Fridge"], "precondition"),                          # already closed
    (["find a Microwave", "turn on the Microwave", "open the Microwave"], "precondition"),  # running
    (["find a Microwave", "open the Microwave", "turn on the Microwave"], "precondition"),  # open
    (["find a Mug", "pick up the Mug", "find a Cabinet", "put down the object in hand"], "precondition"),  # closed
    # absent: the room has no such thing (not_in_scene for the error analysis)
    (["find a Laptop"], "absent"),
])
def test_world_labels_each_failure(actions: list[str], label: str) -> None:
    w = World.from_scene(scene())
    results = [w.step(a) for a in actions]
    assert all(ok for ok, _ in results[:-1]), results
    ok, feedback = results[-1]
    assert not ok and feedback.startswith("Failed")
    assert w.failure == label and label in FAILURES


def test_success_clears_the_label_and_a_failed_affordance_changes_nothing() -> None:
    w = World.from_scene(scene())
    w.step("find a Fridge")
    before = w.to_scene()
    ok, fb = w.step("pick up the Fridge")
    assert not ok and w.failure == "affordance" and "does not support 'pick up'" in fb
    assert w.to_scene() == before and w.held is None
    assert w.step("open the Fridge")[0] and w.failure is None


def _env(goal: dict) -> AlfredEnv:
    env = AlfredEnv(render=False)
    task = Task(id="t", subset="visual_appearance", instruction="Put the black mug in the sink.",
                metadata={"goal": goal, "scene": scene()})
    env.reset(task, seed=0)
    return env


def _do(env: AlfredEnv, *names: str):
    space = env.action_space().actions
    return [env.step(space.index(n)) for n in names]


def test_env_reports_labels_in_step_info() -> None:
    env = _env({"kind": "pick_and_place", "object": {"type": "Apple"}, "receptacle": {"type": "DiningTable"}})
    ok, aff, pre = _do(env, "find a Apple", "slice the Apple", "pick up the Apple")
    assert ok.action_success and ok.info["failure"] is None
    assert (aff.action_success, aff.info["failure"]) == (False, "affordance")
    assert (pre.action_success, pre.info["failure"]) == (False, "precondition")
    absent = _do(env, "find a Laptop")[0]
    assert absent.info["failure"] == "absent"


def test_env_calls_a_state_failure_on_a_look_alike_a_wrong_target() -> None:
    # the goal singles out the black mug (Mug_2); failing on the white one is the wrong thing, not the wrong state
    for ref in ({"instance": "Mug_2"}, {"type": "Mug", "color": "black"}):
        env = _env({"kind": "pick_and_place", "object": ref, "receptacle": {"type": "SinkBasin"}})
        r = _do(env, "find a Pot", "pick up the Pot", "find a Mug", "pick up the Mug")[-1]
        assert not r.action_success and r.info["failure"] == "wrong_target", r.feedback
        # the same failure on the goal's own mug stays a precondition failure
        r = _do(env, "find a Mug_2", "pick up the Mug")[-1]
        assert not r.action_success and r.info["failure"] == "precondition"
    # a goal that does not single one out: any mug will do, so it is the state
    env = _env({"kind": "pick_and_place", "object": {"type": "Mug"}, "receptacle": {"type": "SinkBasin"}})
    r = _do(env, "find a Pot", "pick up the Pot", "find a Mug", "pick up the Mug")[-1]
    assert r.info["failure"] == "precondition"


# --------------------------------------------------------------------------------------------- also
def test_also_adds_one_condition_each_and_the_final_one_needs_all() -> None:
    base = {"kind": "pick_and_place", "object": {"type": "Mug"}, "receptacle": {"type": "DiningTable"}}
    goal = dict(base, also=["clean", "hot"])
    assert len(conditions(base)) == 1 and len(conditions(goal)) == 3
    assert len(conditions(dict(base, kind="heat_and_place", also=["clean"]))) == 4
    w = World.from_scene(scene())
    w.objects["Mug"].is_dirty = w.objects["Mug_2"].is_dirty = True  # (isClean Mug) holds for any clean mug
    for a in ("find a Mug", "pick up the Mug", "find a DiningTable", "put down the object in hand"):
        assert w.step(a)[0]
    ok, progress, flags = evaluate(goal, w)
    assert not ok and flags == [False, False, False]  # on the table, but neither washed nor heated
    plan = expert_plan(w, goal)
    assert plan is not None
    for a in plan:
        assert w.step(a)[0], a
    assert evaluate(goal, w)[0] and not w.objects["Mug"].is_dirty and w.objects["Mug"].is_hot


def test_also_rejects_hot_with_cold(tmp_path) -> None:
    doc = json.loads((TASK_DIR / "long_horizon.json").read_text())
    doc["tasks"] = doc["tasks"][:1]
    doc["tasks"][0]["goal"] = {"kind": "heat_and_place", "object": {"type": "Apple"},
                               "receptacle": {"type": "CounterTop"}, "also": ["cold"]}
    path = tmp_path / "long_horizon.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(TaskFileError, match="hot.*cold"):
        load_task_file(path)


# --------------------------------------------------------------------------------------------- shipped tasks
def _shipped() -> list[dict]:
    return [t for s in SUBSETS for t in json.loads((TASK_DIR / f"{s}.json").read_text())["tasks"]]


#: Tasks whose expert got shorter when "pick up the X" began to prefer the X inside or on what the agent faces
#: (issue 25): the classic files stay byte-identical, so their stored count is one more than the expert's now.
#: visual_appearance_18: after opening the microwave the plate inside it is taken without finding it again.
_SHORTER_SINCE_FACED_RULE = {"visual_appearance_18": (14, 13)}


def test_stored_oracle_steps_equal_the_current_expert() -> None:
    wrong = []
    for t in _shipped():
        plan = expert_plan(World.from_scene(t["scene"]), t["goal"])
        got = (t["oracle_steps"], None if plan is None else len(plan))
        if got[0] != got[1] and _SHORTER_SINCE_FACED_RULE.get(t["id"]) != got:
            wrong.append((t["id"], *got))
    assert not wrong, wrong


def test_long_horizon_is_long_for_several_types_and_rooms() -> None:
    tasks = [t for t in _shipped() if t["subset"] == "long_horizon"]
    assert len(tasks) == 50
    assert all(t["oracle_steps"] > 15 for t in tasks)
    assert len({t["task_type"] for t in tasks}) >= 5
    assert len({t["scene"]["room"] for t in tasks}) >= 2
    lengths = Counter(t["oracle_steps"] for t in tasks)
    assert len(lengths) >= 6 and max(lengths.values()) <= 50 // 3 + 1
    # long for the right reasons: every task hides things, slices, or asks for extra preparation
    for t in tasks:
        g = t["goal"]
        hidden = any("parent" in o and o["parent"].split("_")[0] in ("Drawer", "Cabinet", "Fridge", "Safe", "Box")
                     for o in t["scene"]["objects"])
        assert hidden or g.get("sliced") or g.get("also"), t["id"]
