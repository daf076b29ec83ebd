"""The exact conditions of docs/error_analysis.md, one at a time: a search is no repetition, a detour is no
drift, colour families and synonyms, "object k", remembered and denied objects, placeholders, evidence."""

import pytest

from eb_core.errors import (
    CATEGORIES,
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
    mixed = [act(1, "open the fridge", ok=False), act(2, "pick up the plum", ok=False),
             act(3, "open the fridge", ok=False)]
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
    assert shape["misperceived"] == ["object 1"] and shape["wrong"] == ["object 1"]
    assert "star" in shape["evidence"][0]["why"]
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
    assert p["hallucinated"] == ["bed"] and p["misperceived"] == []
    assert p["evidence"][-1]["why"] == "nowhere in the scene"


def test_runs_without_a_description_get_no_perception_score():
    view = [{"name": "Sofa_1", "type": "Sofa"}]
    for text in (None, "", "(oracle: the simulator state is known exactly)", "(random baseline: the image is ignored)"):
        lab = label_episode([step(1, [act(1, "go")], description=text, visible=view)])
        assert lab["perception_score"] is None and cats(lab) == []
    recs = [EpisodeRecord(task_id="t", subset="s", instruction="", status="ok", success=True, env_steps=4,
                          planner_steps=1, error_counts={}, perception_score=None)]
    assert error_analysis(recs)["perception_score"] is None


def test_acting_on_a_thing_the_scene_lacks_is_a_wrong_belief_and_a_hallucination_only_when_claimed_seen():
    """A calibration player's won ALFRED long_horizon_49: "find a Knife" first (the action list offers every
    type; this kitchen has only a butter knife), with a description that says knives are too small to judge. The
    world's ``absent`` failure is a wrong belief about the room (``not_in_scene``), not a hallucination; a
    description that claims a knife in view still is one, from the perception check."""
    view = [{"name": "CounterTop_3", "type": "CounterTop"}, {"name": "Apple_5", "type": "Apple", "colour": "red"}]
    find = act(1, "find a Knife", ok=False, failure="absent")
    honest = label_episode([step(1, [find], description="A grey counter with a red apple; details of the knives "
                                 "are too small to judge.", visible=view)], vocabulary=["Knife"])
    assert cats(honest) == ["not_in_scene"] and "hallucinated_object" not in honest["counts"]
    assert CATEGORIES["not_in_scene"].group == "reasoning" and "not_in_scene" not in INVALID_LABELS
    claimed = label_episode([step(1, [find], description="A knife lies on the grey counter beside a red apple.",
                                  visible=view)], vocabulary=["Knife"])
    assert sorted(cats(claimed)) == ["hallucinated_object", "not_in_scene"]


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


# The calibration players of session 8 played hard tasks well, yet these excerpts of their descriptions fired
# labels (docs/error_analysis.md, "Labels on good play"); each test below fails without its fix.

def test_a_thing_said_to_look_like_another_names_no_object():
    """ALFRED complex_instruction_22: "a green bowl that looks shallow and wide-rimmed, almost plate-like" says what
    the bowl looks like; no plate is claimed."""
    view = [{"name": "Bowl_6", "type": "Bowl", "colours": ["green"], "pixels": 900, "aliases": ["bowl"]},
            {"name": "Cup", "type": "Cup", "colours": ["grey"], "pixels": 300, "aliases": ["cup"]}]
    for said in ("behind a grey cup, is a green bowl that looks shallow and wide-rimmed, almost plate-like.",
                 "A green bowl shaped like a plate, behind a grey cup.",
                 "A green bowl resembling a plate, behind a grey cup."):
        p = perception_check(said, view, vocabulary=["Plate"])
        assert p["hallucinated"] == [] and p["correct"] == ["bowl", "cup"], said
    p = perception_check("A green bowl and a plate behind a grey cup.", view, vocabulary=["Plate"])
    assert p["hallucinated"] == ["plate"]  # a plate named outright is still judged


def test_a_colour_word_belongs_to_its_own_list_item():
    """ALFRED long_horizon_00: "a small round fruit, a blue item, bread and a green bottle": the item is blue, not
    the bread; a colour said of the bread itself is still judged."""
    view = [{"name": "Bread", "type": "Bread", "colours": ["brown"], "pixels": 62, "aliases": ["loaf of bread"]},
            {"name": "Plate_3", "type": "Plate", "colours": ["blue"], "pixels": 33, "aliases": ["plate"]},
            {"name": "GlassBottle", "type": "GlassBottle", "colours": ["green", "red"], "pixels": 42,
             "aliases": ["glass bottle"]}]
    said = "a grey counter with a small round fruit, a blue item, bread and a green bottle"
    p = perception_check(said, view)
    assert p["wrong"] == [] and "bread" in p["correct"]
    assert perception_check("a blue item and bread", view)["wrong"] == []  # "and" after a noun ends the item too
    bad = perception_check("a small round fruit, blue bread and a green bottle", view)
    assert bad["misperceived"] == ["bread"] and "said blue" in bad["evidence"][0]["why"]
    both = perception_check("a red and brown loaf of bread", view)  # "red and brown": two colours of one thing
    assert both["wrong"] == [] and both["evidence"][0]["words"] == "red brown loaf of bread"


def test_a_thing_the_render_draws_like_another_in_view_is_no_hallucination():
    """ALFRED visual_appearance_29: the red watering can (a red pot with a spout and a top handle at 500 px) was
    called "a red kettle"; with no watering can in view, a kettle is still a hallucination."""
    can = [{"name": "SideTable_2", "type": "SideTable", "colours": ["grey"], "pixels": 496, "aliases": ["side table"]},
           {"name": "WateringCan", "type": "WateringCan", "colours": ["red"], "pixels": 98,
            "aliases": ["watering can"]}]
    said = "a small grey side table with a red kettle"
    assert perception_check(said, can, vocabulary=["Kettle"])["hallucinated"] == []
    assert perception_check(said, can[:1], vocabulary=["Kettle"])["hallucinated"] == ["kettle"]


def test_a_colour_that_fits_only_a_lookalike_in_view_is_no_misperception():
    """Navigation long_horizon_009 (session 11 calibration, a success): "The red sofa is at my front right" for a
    red armchair filling the bottom right of the view, while a small green sofa stood across the room. The label
    said the sofa was misperceived; a colour no object of either kind has is still wrong."""
    view = [{"name": "ArmChair_31", "type": "ArmChair", "colour": "red", "colours": ["red"], "pixels": 1585,
             "aliases": ["armchair"]},
            {"name": "ArmChair_1", "type": "ArmChair", "colour": "grey", "colours": ["grey"], "pixels": 314,
             "aliases": ["armchair"]},
            {"name": "Sofa_1", "type": "Sofa", "colour": "green", "colours": ["green"], "pixels": 208,
             "aliases": ["sofa"]}]
    said = ("Image 0: the light grey mesh hamper stands almost straight ahead on the red rug, roughly 2 m away. "
            "The red sofa is at my front right, its left side just right of my centre line.")
    p = perception_check(said, view)
    assert p["misperceived"] == [] and "sofa" in p["unjudged"]
    assert perception_check("The green sofa is far ahead.", view)["correct"] == ["sofa"]
    purple = perception_check("The purple sofa is at my front right.", view)
    assert purple["misperceived"] == ["sofa"] and "said purple" in purple["evidence"][0]["why"]
    grey_seat = perception_check("A red armchair is at my front right.", view)  # the armchair's own colour
    assert grey_seat["correct"] == ["arm chair"]


def test_object_k_with_its_coordinates_is_judged_and_the_wrong_shape_fires():
    """Manipulation: "object 6 [58, 45, 17] black rounded block, the sponge, its top longer along x than along y"
    was not judged (the coordinates' commas cut the claim; "longer" read as "no longer"), yet the player had taken
    this black cylinder for the sponge and failed: a right label."""
    view = [{"name": "object 6", "type": "black cylinder"}, {"name": "object 8", "type": "sponge"},
            {"name": "object 9", "type": "yellow marked area"}]
    said = ("object 6 [58, 45, 17] black rounded block, the sponge, its top longer along x than along y; "
            "object 8 [58, 60, 17] yellow cube; object 9 [45, 75, 15] yellow marked area, arrow pointing right.")
    p = perception_check(said, view)
    assert p["misperceived"] == ["object 6"] and "object 6 is a black cylinder" in p["evidence"][0]["why"]
    assert p["evidence"][0]["words"] == "black object 6"


def test_a_wrong_shape_for_object_k_keeps_firing():
    """Manipulation complex_pick_08: "object 4 is a red cube" for the red triangle (a triangular prism, its
    triangular face plain when looked at closely): the model said something false, and the label stays."""
    pick = [{"name": "object 4", "type": "red triangle"}, {"name": "object 7", "type": "olive cube"}]
    p = perception_check("object 4 is a red cube; object 7 is a small olive cube at [33, 54, 17] (object list), "
                         "roughly axis-aligned.", pick)
    assert p["misperceived"] == ["object 4"] and p["correct"] == ["object 7"]
