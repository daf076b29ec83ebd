import json
import random
import string

import pytest

from eb_core.env import DiscreteActionSpace, VectorActionSpace
from eb_core.parsing import extract_json_object, parse_planner_output

SPACE = DiscreteActionSpace(actions=("find a Apple", "pick up the Apple", "put down the object in hand"))
VEC = VectorActionSpace(names=("x", "y", "z", "roll", "pitch", "yaw", "gripper"), low=(0,) * 7,
                        high=(100, 100, 100, 120, 120, 120, 1))
GOOD = {"visual_state_description": "a kitchen", "reasoning_and_reflection": "r", "language_plan": "l",
        "executable_plan": [{"action_id": 0, "action_name": "find a Apple"}, {"action_id": 1, "action_name": "pick up the Apple"}]}


@pytest.mark.parametrize("text", [
    json.dumps(GOOD),
    "```json\n" + json.dumps(GOOD) + "\n```",
    "Sure! Here is my plan:\n" + json.dumps(GOOD, indent=2) + "\nGood luck.",
    json.dumps(GOOD).replace("]}", "],}").replace("}, {", "}, {"),  # trailing comma
    json.dumps(GOOD).replace('"', "'"),  # single quotes
    # a raw newline and tab inside a string (what llama.cpp's JSON grammar let a real local model write)
    json.dumps(GOOD).replace('"r"', '"the last action failed;\n\tstart again"'),
])
def test_tolerant_forms_parse(text):
    r = parse_planner_output(text, SPACE)
    assert r.error is None
    assert r.actions == [0, 1]
    assert r.output.visual_state_description == "a kitchen"


def test_plan_as_string_and_ids_as_strings():
    obj = dict(GOOD, executable_plan=json.dumps([{"action_id": "2", "action_name": "x"}]))
    assert parse_planner_output(json.dumps(obj), SPACE).actions == [2]


def test_out_of_range_id_truncates_plan():
    obj = dict(GOOD, executable_plan=[{"action_id": 1}, {"action_id": 7}, {"action_id": 0}])
    r = parse_planner_output(json.dumps(obj), SPACE)
    assert r.actions == [1]
    assert r.truncated_at == 1 and "out of range" in r.plan_error


def test_plan_length_cap():
    obj = dict(GOOD, executable_plan=[{"action_id": 0}] * 30)
    r = parse_planner_output(json.dumps(obj), SPACE, max_plan_length=20)
    assert len(r.actions) == 20 and r.truncated_at == 20


def test_empty_plan_is_not_an_error():
    r = parse_planner_output(json.dumps(dict(GOOD, executable_plan=[])), SPACE)
    assert r.error is None and r.actions == [] and r.truncated_at is None


@pytest.mark.parametrize("text,why", [
    ("I will pick up the apple.", "no JSON"),
    ('{"language_plan": "x"}', "no 'executable_plan'"),
    ('{"executable_plan": 5}', "must be a list"),
    ('{"executable_plan": "not a list ["}', "not a JSON list"),
    ('{"executable_plan": [{"action_id": 1}', "no JSON"),  # truncated
])
def test_unusable_answers_are_output_errors(text, why):
    r = parse_planner_output(text, SPACE)
    assert r.error is not None and why.split()[0] in r.error


def test_vector_plans():
    obj = {"executable_plan": [{"action": [1, 2, 3, 60, 60, 60, 1]}, [5, 5, 5, 5, 5, 5, 0], "[1,1,1,1,1,1,1]"]}
    r = parse_planner_output(json.dumps(obj), VEC)
    assert r.actions == [(1, 2, 3, 60, 60, 60, 1), (5, 5, 5, 5, 5, 5, 0), (1, 1, 1, 1, 1, 1, 1)]
    bad = parse_planner_output(json.dumps({"executable_plan": [[1, 2, 3, 60, 60, 60, 7]]}), VEC)
    assert bad.actions == [] and "gripper" in bad.plan_error


def test_braces_inside_strings_do_not_confuse_extraction():
    text = 'prefix {"language_plan": "use } and {", "executable_plan": []} suffix {"other": 1}'
    assert extract_json_object(text)["language_plan"] == "use } and {"


def _random_json(rng: random.Random, depth: int = 0):
    kind = rng.randrange(7 if depth < 3 else 4)
    if kind == 0:
        return rng.randint(-10**6, 10**6)
    if kind == 1:
        return "".join(rng.choice(string.printable) for _ in range(rng.randrange(12)))
    if kind == 2:
        return rng.choice([None, True, False, 1.5, float("1e308")])
    if kind == 3:
        return rng.choice([[], {}, ""])
    if kind == 4:
        return [_random_json(rng, depth + 1) for _ in range(rng.randrange(5))]
    keys = ["executable_plan", "action_id", "action_name", "action", "language_plan", "x"]
    return {rng.choice(keys): _random_json(rng, depth + 1) for _ in range(rng.randrange(5))}


def test_fuzz_1000_inputs_never_crash_and_are_all_counted():
    rng = random.Random(1234)
    outcomes = {"error": 0, "plan": 0, "empty": 0}
    for i in range(1000):
        if i % 2:
            text = "".join(rng.choice(string.printable + "{}[]\"':,") for _ in range(rng.randrange(200)))
        else:
            text = json.dumps(_random_json(rng))
            if i % 4 == 0:
                text = text[: rng.randrange(len(text) + 1)]  # truncated JSON
        for space in (SPACE, VEC):
            r = parse_planner_output(text, space)
            if r.error is not None:
                outcomes["error"] += 1
            elif r.actions:
                outcomes["plan"] += 1
            else:
                outcomes["empty"] += 1
    assert sum(outcomes.values()) == 2000
    assert outcomes["error"] > 500  # most garbage is recognised as garbage


# -- the original protocol's formats (issue 11) ------------------------------------------------------------

D4 = DiscreteActionSpace(actions=("a", "b", "c", "d"))


def test_the_object_holding_executable_plan_wins_over_earlier_objects():
    text = ('Following the example {"instruction": "walk", "note": {"x": 1}} I answer:\n'
            '{"reasoning_and_reflection": "r", "executable_plan": [{"action_id": 2, "action_name": "c"}]}\n'
            'and a schema echo {"type": "object"}')
    r = parse_planner_output(text, D4)
    assert r.error is None and r.actions == [2] and r.output.reasoning_and_reflection == "r"
    assert extract_json_object('{"a": 1} {"b": 2}') == {"a": 1}  # no plan anywhere: the first object


def test_nested_plan_lists_and_id_name_pairs():
    assert parse_planner_output('{"executable_plan": [[{"action_id": 1}, {"action_id": 3}]]}', D4).actions == [1, 3]
    # the original's visual-ICL format, as a list and as a string
    assert parse_planner_output('{"executable_plan": [[3, "d"], [0, "a"]]}', D4).actions == [3, 0]
    assert parse_planner_output('{"executable_plan": [[[3, "d"], [0, "a"]]]}', D4).actions == [3, 0]
    assert parse_planner_output('{"executable_plan": "[[3, \'d\'], [0, \'a\']]"}', D4).actions == [3, 0]
    bad = parse_planner_output('{"executable_plan": [[9, "z"]]}', D4)
    assert bad.actions == [] and bad.truncated_at == 0 and "out of range" in bad.plan_error


def test_vector_plans_in_the_original_manipulation_shapes():
    v = VectorActionSpace(names=tuple("xyzabcg"), low=(0,) * 7, high=(99,) * 6 + (1,))
    text = '{"executable_plan": [[{"action": [1, 2, 3, 4, 5, 6, 1]}], [[7, 8, 9, 10, 11, 12, 0]]]}'
    assert parse_planner_output(text, v).actions == [(1, 2, 3, 4, 5, 6, 1), (7, 8, 9, 10, 11, 12, 0)]
    assert parse_planner_output('{"executable_plan": [[1, 2, 3, 4, 5, 6, 1]]}', v).actions == [(1, 2, 3, 4, 5, 6, 1)]


@pytest.mark.parametrize("text", [
    # Claude / InternVL style: single quotes with an apostrophe inside, fenced
    "```json\n{'visual_state_description': 'the robot's arm is up', 'executable_plan': "
    "[{'action_id': 1, 'action_name': 'b'}]}\n```",
    # a Python literal with a double quote inside a single-quoted string
    "{'language_plan': 'say \"hi\"', 'executable_plan': [{'action_id': 1, 'action_name': 'b'}],}",
])
def test_quote_and_fence_fixup(text):
    r = parse_planner_output(text, D4)
    assert r.error is None and r.actions == [1]
    assert "robot's arm" in r.output.visual_state_description or 'say "hi"' in r.output.language_plan
