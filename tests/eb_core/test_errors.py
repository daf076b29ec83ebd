"""Automatic error analysis: every category from a constructed record set or a scripted run, and the
perception check's precision/recall on hand-built scenes."""

import json

import pytest

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.errors import CATEGORIES, DRIFT_WINDOW, FAILURE_LABELS, label_episode, label_run, perception_check
from eb_core.runner import run

PROMPT = ("Pick things up.\naction id 0: navigate to the kitchen counter\naction id 1: pick up the apple\n"
          "action id 2: put it in the fridge\naction id 3: open the fridge\n")


def step(n, actions=(), plan=None, error=None, plan_error=None, description=None, visible=None, prompt=PROMPT):
    parsed = None
    if error is None:
        names = [a["action_name"] for a in actions] if plan is None else plan
        parsed = {"visual_state_description": description, "reasoning_and_reflection": "r", "language_plan": "p",
                  "executable_plan": [{"action_id": i, "action_name": x} for i, x in enumerate(names)]}
    s = {"planner_step": n, "prompt": prompt, "parsed": parsed, "error": error, "plan_error": plan_error,
         "actions": list(actions)}
    if visible is not None:
        s["visible_objects"] = visible
    return s


def act(k, name, ok=True, progress=0.0, **extra):
    return {"env_step": k, "action": k, "action_name": name, "success": ok, "feedback": "fb", "progress": progress,
            **extra}


def cats(labels, n=None):
    steps = labels["steps"] if n is None else [labels["steps"][n]]
    return [lab["category"] for s in steps for lab in s["labels"]]


def test_format_errors_and_empty_plans():
    lab = label_episode([step(1, error="the answer contains no JSON object"), step(2, plan=[]), step(3, plan=[])],
                        {"end_reason": "max_steps", "success": False})
    assert cats(lab, 0) == ["format_error"] and cats(lab, 1) == ["format_error"] and cats(lab, 2) == ["format_error"]
    assert lab["counts"] == {"format_error": 3}


def test_an_empty_plan_that_ends_the_episode_is_a_premature_stop():
    lab = label_episode([step(1, [act(1, "navigate to the kitchen counter", progress=0.5)]), step(2, plan=[])],
                        {"end_reason": "empty_plan", "success": False})
    assert cats(lab, 1) == ["premature_stop"]
    done = label_episode([step(1, [act(1, "open the fridge")])], {"end_reason": "done", "success": False})
    assert cats(done) == ["premature_stop"]
    solved = label_episode([step(1, [act(1, "open the fridge", progress=1.0)])], {"end_reason": "success",
                                                                                  "success": True})
    assert cats(solved) == []


def test_invalid_plan_items_and_hallucinated_objects_in_the_plan():
    invalid = label_episode([step(1, plan=["navigate to the apple"], plan_error="plan item 1 is not an action")])
    assert cats(invalid) == ["invalid_action"]
    halluc = label_episode([step(1, plan=["pick up the banana"], plan_error="plan item 1 is not an action")])
    assert cats(halluc) == ["hallucinated_object"] and "banana" in halluc["steps"][0]["labels"][0]["detail"]
    # no action list to compare with (vector actions): an invalid item stays an invalid action
    vec = label_episode([step(1, plan=["[1, 2, 3]"], plan_error="out of range", prompt="move the arm")])
    assert cats(vec) == ["invalid_action"]


def test_world_failure_reasons_and_the_unclassified_fallback():
    for i, (value, label) in enumerate(FAILURE_LABELS.items()):
        lab = label_episode([step(1, [act(1, f"pick up the apple", ok=False, failure=value)])])
        assert cats(lab) == [label], value
    lab = label_episode([step(1, [act(1, "pick up the apple", ok=False)])])
    assert cats(lab) == ["failed_action"]
    lab = label_episode([step(1, [act(1, "pick up the apple", ok=False, failure="something new")])])
    assert cats(lab) == ["failed_action"]


def test_a_successful_action_on_the_wrong_thing_is_a_wrong_target():
    lab = label_episode([step(1, [act(1, "pick up the apple", wrong_target=True), act(2, "open the fridge")])])
    assert cats(lab) == ["wrong_target"] and lab["steps"][0]["labels"][0]["env_step"] == 1


def test_the_episode_records_the_world_keys_the_labeller_reads(tmp_path):
    """distance_to_goal and wrong_target travel from StepResult.info into steps.jsonl, and drift is labelled."""
    from eb_core.episode import run_episode
    from eb_core.planner import VLMPlanner

    class Walker(fixture_plugin.CorridorEnv):
        def step(self, action):
            result = super().step(action)
            result.info.update(distance_to_goal=float(abs(self.goal - self.pos)), wrong_target=self.pos == 1)
            return result

    cfg = make_config()
    answer = json.dumps({"visual_state_description": "", "reasoning_and_reflection": "", "language_plan": "",
                         "executable_plan": [{"action_id": 0}] * 2 + [{"action_id": 1}] * 4})
    task = fixture_plugin.CorridorEnv.load_tasks()[2]  # near-2: start 2, goal 4
    rec = run_episode(env=Walker(), task=task, seed=1, planner=VLMPlanner(cfg.planner, cfg.env),
                      backend=fixture_plugin.ScriptedBackend(answers=[answer]), env_config=cfg.env,
                      step_dir=tmp_path)
    assert rec.success
    steps = [json.loads(x) for x in (tmp_path / "steps.jsonl").read_text().splitlines()]
    acts = steps[0]["actions"]
    assert [a["distance_to_goal"] for a in acts] == [3.0, 4.0, 3.0, 2.0, 1.0, 0.0]
    assert [a["wrong_target"] for a in acts] == [True, False, True, False, False, False]
    assert "wrong_target" in cats(label_episode(steps)) and "navigation_drift" not in cats(label_episode(steps))


def test_repetition_of_a_failing_action_and_a_two_action_cycle():
    lab = label_episode([step(1, [act(1, "open the fridge", ok=False)]), step(2, [act(2, "open the fridge", ok=False)])])
    assert cats(lab, 0) == ["failed_action"] and cats(lab, 1) == ["failed_action", "repetition"]
    cycle = label_episode([step(1, [act(1, "turn left"), act(2, "turn right"), act(3, "turn left"),
                                    act(4, "turn right")], prompt="")])
    assert cats(cycle) == ["repetition"]
    progressing = label_episode([step(1, [act(1, "turn left", progress=0.1), act(2, "turn right", progress=0.2),
                                          act(3, "turn left", progress=0.3), act(4, "turn right", progress=0.4)])])
    assert cats(progressing) == []


def test_missing_step_wrong_order_and_extra_step_against_the_expert():
    missing = label_episode([step(1, [act(1, "put it in the fridge", ok=False, expert_action=3,
                                          expert_action_name="pick up the apple")])])
    assert set(cats(missing)) == {"failed_action", "missing_step"}
    order = label_episode([step(1, [act(1, "put it in the fridge", ok=False, expert_action=3,
                                        expert_action_name="open the fridge")],
                                plan=["put it in the fridge", "open the fridge"])])
    assert set(cats(order)) == {"failed_action", "wrong_order"}
    extra = label_episode([step(1, [act(1, "navigate to the kitchen counter", expert_action=1,
                                        expert_action_name="pick up the apple")])])
    assert cats(extra) == ["extra_step"]
    # another route that makes progress is not an error; the expert's own action never is
    other = label_episode([step(1, [act(1, "open the fridge", progress=0.5, expert_action=1,
                                        expert_action_name="pick up the apple"),
                                    act(2, "pick up the apple", progress=0.7, expert_action=1,
                                        expert_action_name="pick up the apple")])])
    assert cats(other) == []


def test_navigation_drift_from_the_distance_to_the_goal():
    far = [act(i + 1, "move forward", distance_to_goal=d, position=[0.0, -d]) for i, d in enumerate([2.0, 2.5, 3.0, 3.5])]
    lab = label_episode([step(1, far, prompt="")])
    assert cats(lab) == ["navigation_drift"] and lab["steps"][0]["labels"][0]["env_step"] == DRIFT_WINDOW + 1
    # the same rising distance where the world records no agent position (an arm lifting a shape before it moves
    # it to its hole): no navigation, no drift
    arm = [{k: v for k, v in a.items() if k != "position"} for a in far]
    assert cats(label_episode([step(1, arm, prompt="")])) == []
    near = [act(i + 1, "move forward", distance_to_goal=d, position=[0.0, -d])
            for i, d in enumerate([2.0, 2.5, 2.2, 3.0])]
    assert cats(label_episode([step(1, near, prompt="")])) == []


def test_a_zig_zag_that_closes_in_or_that_the_expert_agrees_with_is_neither_a_loop_nor_drift():
    names = ["move forward", "turn left"] * 2
    closing = [act(i + 1, n, distance_to_goal=d) for i, (n, d) in enumerate(zip(names, [3.0, 2.8, 2.6, 2.4]))]
    assert cats(label_episode([step(1, closing, prompt="")])) == []
    stuck = [act(i + 1, n, distance_to_goal=3.0) for i, n in enumerate(names)]
    assert cats(label_episode([step(1, stuck, prompt="")])) == ["repetition"]
    detour = [act(i + 1, "move forward", distance_to_goal=d, expert_action_name="move forward")
              for i, d in enumerate([2.0, 2.5, 3.0, 3.5])]  # around a wall: the expert walks the same way
    assert cats(label_episode([step(1, detour, prompt="")])) == []


def test_perception_precision_and_recall_on_hand_built_scenes():
    visible = [{"name": "Apple_1", "type": "Apple"}, {"name": "CounterTop_2", "type": "CounterTop"},
               {"name": "Mug_3", "type": "Mug"}]
    p = perception_check("I see an apple on the counter top, and a banana.", visible, vocabulary=["Banana"])
    assert p["mentioned"] == ["apple", "banana", "counter top"] and p["correct"] == ["apple", "counter top"]
    assert p["hallucinated"] == ["banana"]
    assert p["precision"] == pytest.approx(2 / 3) and p["recall"] == pytest.approx(2 / 3)
    # a negated mention is not a claim; plurals count
    p = perception_check("There is no banana. Two mugs stand there.", visible, vocabulary=["Banana"])
    assert p["mentioned"] == ["mug"] and p["precision"] == 1.0 and p["recall"] == pytest.approx(1 / 3)
    # colour words must match what is in view
    cubes = [{"name": "object 1", "type": "red cube"}, {"name": "object 2", "type": "blue star"}]
    p = perception_check("A green cube and a blue star.", cubes)
    assert p["correct"] == ["star"] and p["misperceived"] == ["cube"] and p["hallucinated"] == []
    assert p["wrong"] == ["cube"] and p["precision"] == 0.5
    assert perception_check("", visible) is None and perception_check("nothing", []) is None
    blind = perception_check("I will just walk on.", visible)  # names nothing while three objects are in view
    assert blind["precision"] is None and blind["recall"] == 0.0 and blind["f1"] == 0.0
    # a baseline's placeholder is no description: no score at all, not 0
    assert perception_check("(the image is ignored)", visible) is None


def test_a_description_naming_an_object_absent_from_the_scene_is_a_hallucination_and_scores_the_episode():
    steps = [step(1, [act(1, "open the fridge")], description="An apple and a banana.",
                  visible=[{"name": "Apple_1", "type": "Apple"}]),
             step(2, [act(2, "open the fridge")], description="A mug.", visible=[{"name": "Mug_1", "type": "Mug"}])]
    lab = label_episode(steps, vocabulary=["Banana"])  # the world has bananas; this scene has none
    assert cats(lab, 0) == ["hallucinated_object"] and cats(lab, 1) == []
    ev = lab["steps"][0]["labels"][0]["evidence"]
    assert ev["words"] == ["banana"] and ev["why"] == ["nowhere in the scene"] and ev["in_view"] == ["Apple_1"]
    # step 1: 1 of 2 judged mentions right; step 2: 1 of 1
    assert lab["perception_score"] == pytest.approx((1 / 2 + 1) / 2)
    # the mug of step 2 named at step 1, where it is out of view: remembered, not judged, no label
    remembered = label_episode([dict(steps[0], parsed=dict(steps[0]["parsed"], visual_state_description="An apple and a mug.")),
                                steps[1]])
    assert cats(remembered) == [] and remembered["steps"][0]["perception"]["unjudged"] == ["mug"]


def test_a_part_that_furniture_in_view_draws_is_no_hallucination():
    """"A red alarm clock near the pillows" with a bed in view: the bed draws its pillows, so naming them is no
    hallucination, even where the world has Pillow objects elsewhere (a calibration player's ALFRED play); the same
    word with no bed, sofa or armchair in view still is."""
    bed = [{"name": "Bed", "type": "Bed"}, {"name": "AlarmClock_5", "type": "AlarmClock"}]
    said = "A small red alarm clock near the pillows on the bed."
    p = perception_check(said, bed, vocabulary=["Pillow"])
    assert p["hallucinated"] == [] and "pillow" not in p["wrong"]
    desk = [{"name": "Desk", "type": "Desk"}, {"name": "AlarmClock_5", "type": "AlarmClock"}]
    p = perception_check("A small red alarm clock near the pillows on the desk.", desk, vocabulary=["Pillow"])
    assert p["hallucinated"] == ["pillow"]


def test_every_category_is_documented():
    from pathlib import Path

    doc = (Path(__file__).parents[2] / "docs" / "error_analysis.md").read_text()
    for key, cat in CATEGORIES.items():
        assert f"`{key}`" in doc, key
    for value in FAILURE_LABELS:
        assert f'`"{value}"`' in doc, value


def test_a_scripted_run_records_error_counts_and_the_summary_breakdown(tmp_path):
    left = json.dumps({"visual_state_description": "a corridor and the goal", "reasoning_and_reflection": "x",
                       "language_plan": "left", "executable_plan": [{"action_id": 0}]})
    cfg = make_config(model={"name": "lefty", "backend": "scripted", "answers": [left, "no json here"]},
                      limit=2, subset="near", runner__expert_labels=True)
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    recs = [json.loads(x) for x in (tmp_path / "episodes.jsonl").read_text().splitlines()]
    first = recs[0]  # near-0 starts at cell 0: stepping left bumps into the wall
    assert first["error_counts"]["format_error"] >= 1 and first["error_counts"]["failed_action"] >= 2
    assert first["error_counts"]["repetition"] >= 1 and first["error_counts"]["missing_step"] >= 1
    assert first["perception_score"] == 1.0  # named the goal, which has a box in the image
    ea = summary["overall"]["error_analysis"]
    assert ea["episodes"] == 2 and ea["categories"]["format_error"]["episode_rate"] == 1.0
    assert set(ea["categories"]) == set(CATEGORIES) and summary["subsets"]["near"]["error_analysis"]
    # relabelling the directory from its files gives the same counts
    again = label_run(tmp_path)
    assert again[("near-0", 0)]["counts"] == first["error_counts"]
