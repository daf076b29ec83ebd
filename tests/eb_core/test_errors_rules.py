"""The exact conditions of docs/error_analysis.md, one at a time: a search is no repetition, a detour is no
drift, colour families and synonyms, "object k", remembered and denied objects, placeholders, evidence."""

import pytest

from eb_core.errors import (
    INVALID_LABELS,
    invalid_count,
    label_episode,
    perception_check,
)
from eb_core.metrics import error_analysis, errors
from eb_core.records import EpisodeRecord


def act(k, name, ok=True, **extra):
    return {"env_step": k, "action": k, "action_name": name, "success": ok, "feedback": "fb", "progress": 0.0,
            **extra}


def step(n, actions=(), description=None, visible=None, **extra):
    parsed = {"visual_state_description": description, "reasoning_and_reflection": "", "language_plan": "",
              "executable_plan": [{"action_id": 0, "action_name": a["action_name"]} for a in actions]}
    s = {"planner_step": n, "prompt": "", "parsed": parsed, "error": None, "plan_error": None,
         "actions": list(actions), **extra}
    if visible is not None:
        s["visible_objects"] = visible
    return s


def cats(lab):
    return [x["category"] for s in lab["steps"] for x in s["labels"]]


def test_a_search_across_receptacles_is_no_repetition_and_the_same_failure_from_the_same_state_is():
    search = [act(1, "pick up the plum", ok=False, failure="precondition"), act(2, "navigate to the table 2"),
              act(3, "pick up the plum", ok=False, failure="precondition"), act(4, "navigate to the sofa"),
              act(5, "pick up the plum", ok=False, failure="precondition")]
    assert "repetition" not in cats(label_episode([step(1, search)]))
    stuck = [act(1, "pick up the plum", ok=False, failure="precondition"),
             act(2, "pick up the plum", ok=False, failure="precondition"),
             act(3, "pick up the plum", ok=False, failure="precondition")]
    lab = label_episode([step(1, stuck)])
    reps = [x for s in lab["steps"] for x in s["labels"] if x["category"] == "repetition"]
    assert [x["env_step"] for x in reps] == [2, 3] and reps[0]["evidence"]["failed_before_at"] == 1
    # another action failing in between changes nothing in the world: still the same state
    mixed = [act(1, "open the fridge", ok=False), act(2, "pick up the plum", ok=False), act(3, "open the fridge", ok=False)]
    assert cats(label_episode([step(1, mixed)])).count("repetition") == 1


def test_drift_needs_a_rise_no_detour_explains():
    def walk(dists, paths=None, fail_first=False):
        acts = [act(1, "Move forward", ok=False, failure="collision")] if fail_first else []
        for i, d in enumerate(dists):
            extra = {"distance_to_goal": d, "position": [0.0, d]} | ({"path_distance": paths[i]} if paths else {})
            acts.append(act(len(acts) + 1, "Move left", **extra))
        return cats(label_episode([step(1, acts)]))

    rising = [2.0, 2.1, 2.3, 2.6]
    assert walk(rising).count("navigation_drift") == 1  # no obstacle met, no path length: drift
    assert "navigation_drift" not in walk(rising, paths=[3.0, 2.75, 2.5, 2.25])  # round a table: the path shrank
    assert walk(rising, paths=[2.0, 2.25, 2.5, 2.75]).count("navigation_drift") == 1  # walking away
    assert "navigation_drift" not in walk(rising, fail_first=True)  # blocked, then stepping round: a detour
    # a long walk away is one label, not one per step
    assert walk([1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6]).count("navigation_drift") == 1


def test_a_loop_of_states_is_a_repetition_and_a_zig_zag_that_moves_is_not():
    loop = [act(i + 1, n, distance_to_goal=d) for i, (n, d) in
            enumerate(zip(["turn left", "turn right"] * 2, [2.0, 2.0, 2.0, 2.0]))]
    assert cats(label_episode([step(1, loop)])) == ["repetition"]
    moving = [act(i + 1, n, distance_to_goal=d) for i, (n, d) in
              enumerate(zip(["move left", "move forward"] * 2, [2.0, 1.9, 2.0, 1.8]))]
    assert "repetition" not in cats(label_episode([step(1, moving)]))


def test_colour_families_synonyms_and_world_names():
    fridge = [{"name": "Fridge_1", "type": "Fridge", "colours": ["grey", "white"], "pixels": 900,
               "aliases": ["fridge"]},
              {"name": "Dresser_1", "type": "Dresser", "colours": ["brown"], "pixels": 900,
               "aliases": ["chest of drawers"]}]
    ok = perception_check("A silver (light grey) refrigerator and a dark wooden chest of drawers.", fridge)
    assert ok["hallucinated"] == [] and set(ok["correct"]) == {"fridge", "dresser"} and ok["score"] == 1.0
    bad = perception_check("A bright green refrigerator.", fridge)
    assert bad["misperceived"] == ["fridge"] and bad["hallucinated"] == [] and "said green" in bad["evidence"][0]["why"]
    rose = perception_check("object 2 is a soft pink (rose) star and object 1 is a navy cube.",
                            [{"name": "object 1", "type": "navy cube"}, {"name": "object 2", "type": "rose star"}],
                            vocabulary=["cube", "star"])
    assert rose["hallucinated"] == [] and rose["correct"] == ["object 1", "object 2"]
    shape = perception_check("object 1 is a navy star.", [{"name": "object 1", "type": "navy cube"},
                                                          {"name": "object 2", "type": "rose star"}])
    assert shape["misperceived"] == ["object 1"] and shape["wrong"] == ["object 1"] and "star" in shape["evidence"][0]["why"]
    # world names: the mustard bottle is "a yellow squeeze bottle"; "an orange bowl" names a bowl, not an orange
    mustard = [{"name": "mustard_bottle_1", "type": "mustard bottle", "colour": "yellow",
                "aliases": ["a yellow squeeze bottle"]}, {"name": "Bowl_1", "type": "Bowl", "colours": ["orange"],
                                                          "pixels": 500}]
    p = perception_check("A yellow squeeze bottle and an orange bowl.", mustard, vocabulary=["Orange"])
    assert p["correct"] == ["bowl", "mustard bottle"] and p["hallucinated"] == []
    p = perception_check("A red squeeze bottle.", mustard)
    assert p["misperceived"] == ["mustard bottle"] and p["hallucinated"] == []
    beside = perception_check("object 1 is next to the rose star.", [{"name": "object 1", "type": "navy cube"},
                                                                    {"name": "object 2", "type": "rose star"}])
    assert beside["hallucinated"] == []  # the star is what stands beside it, not what it is


def test_remembered_denied_and_hedged_objects_are_not_claims():
    view = [{"name": "Sofa_1", "type": "Sofa"}]
    world = ["Television", "Sofa", "Bed"]
    for text in ("No TV is visible.", "The bed is no longer in view.", "I remember a bed behind me.",
                 "Possibly a TV stand at the edge.", "I need to find the bed."):
        p = perception_check(text + " A sofa ahead.", view, vocabulary=world)
        assert p["hallucinated"] == [] and p["correct"] == ["sofa"], text
    # in the scene but out of view: remembered or at the edge, not judged
    p = perception_check("A sofa and a bed.", view, vocabulary=world, scene=["Bed"])
    assert p["hallucinated"] == [] and p["unjudged"] == ["bed"]
    # nowhere in the scene: a hallucination
    p = perception_check("A sofa and a bed.", view, vocabulary=world)
    assert p["hallucinated"] == ["bed"] and p["misperceived"] == [] and p["evidence"][-1]["why"] == "nowhere in the scene"


def test_runs_without_a_description_get_no_perception_score():
    view = [{"name": "Sofa_1", "type": "Sofa"}]
    for text in (None, "", "(oracle: the simulator state is known exactly)", "(random baseline: the image is ignored)"):
        lab = label_episode([step(1, [act(1, "go")], description=text, visible=view)])
        assert lab["perception_score"] is None and cats(lab) == []
    recs = [EpisodeRecord(task_id="t", subset="s", instruction="", status="ok", success=True, env_steps=4,
                          planner_steps=1, error_counts={}, perception_score=None)]
    assert error_analysis(recs)["perception_score"] is None


def test_invalid_actions_mean_the_same_in_the_labels_and_the_summary():
    lab = label_episode([step(1, [act(1, "move", ok=False, failure="collision"),
                                  act(2, "open the fridge", ok=False, failure="precondition"),
                                  act(3, "slice the fridge", ok=False, failure="affordance"),
                                  act(4, "jump", ok=False)])])
    assert cats(lab) == ["collision", "precondition_error", "affordance_error", "failed_action"]
    assert invalid_count(lab["counts"]) == 2 and set(INVALID_LABELS) >= {"affordance_error", "failed_action"}
    rec = EpisodeRecord(task_id="t", subset="s", instruction="", status="ok", env_steps=4, planner_steps=1,
                        invalid_actions=4, error_counts=lab["counts"])
    out = errors([rec])
    assert out["invalid_action_ratio"] == pytest.approx(2 / 4) and out["cap_counted_ratio"] == 1.0
    unlabelled = rec.model_copy(update={"error_counts": None})
    assert errors([unlabelled])["invalid_action_ratio"] == 1.0  # old records: the runner's counter


def test_every_label_carries_its_evidence():
    lab = label_episode([step(1, [act(1, "open the fridge", ok=False, failure="precondition",
                                      feedback="the fridge is locked")])])
    ev = lab["steps"][0]["labels"][0]["evidence"]
    assert ev == {"action": "open the fridge", "reason": "precondition", "state": "the fridge is locked"}
