"""The in-context examples: the original's form, our world, and plans that really work when replayed."""

from __future__ import annotations

import json

import pytest

from eb_alfred.actions import GLOBAL_ACTIONS, scene_actions
from eb_alfred.env import AlfredEnv
from eb_alfred.goals import evaluate
from eb_alfred.prompts import ACTION_RULES, load_example_records, load_examples
from eb_alfred.world import World

RECORDS = load_example_records()
ALL = [(key, i) for key in ("general", "long_horizon") for i in range(len(RECORDS[key]))]


def _answer(text: str) -> dict:
    head, answer = text.split("\nAnswer: ")
    assert head.startswith("Instruction: ") and "\n" not in head and "\n" not in answer  # one turn only
    return json.loads(answer)


def test_sets_and_order() -> None:
    texts = load_examples()
    assert len(texts["general"]) == 10 and len(texts["long_horizon"]) == 7
    assert list(texts["general"]) == [r["text"] for r in RECORDS["general"]]  # fixed order, as shipped
    kinds = {r["goal"]["kind"] for r in RECORDS["general"]}
    assert len(kinds) == 7  # the general set walks through every task type


@pytest.mark.parametrize(("key", "i"), ALL)
def test_example_has_the_originals_form(key: str, i: int) -> None:
    text = RECORDS[key][i]["text"]
    answer = _answer(text)
    assert set(answer) == {"language_plan", "executable_plan"}
    assert answer["language_plan"] and answer["executable_plan"]
    # No perception text and no inventory of the room inside an example.
    for banned in ("perceive", "You see", "You stand", "Along the walls", "visual_state_description"):
        assert banned not in text


@pytest.mark.parametrize(("key", "i"), ALL)
def test_example_replays_in_its_scene(key: str, i: int) -> None:
    rec = RECORDS[key][i]
    world = World.from_scene(rec["scene"])
    actions = scene_actions(world)
    for item in _answer(rec["text"])["executable_plan"]:
        assert actions[item["action_id"]] == item["action_name"]
        if item["action_name"] in GLOBAL_ACTIONS:  # plain names keep their id in every room
            assert GLOBAL_ACTIONS.index(item["action_name"]) == item["action_id"]
        ok, feedback = world.step(item["action_name"])
        assert ok, f"{key}[{i}] {item['action_name']}: {feedback}"
    assert evaluate(rec["goal"], world)[0]


def test_long_horizon_examples_are_long() -> None:
    assert all(len(_answer(r["text"])["executable_plan"]) > 15 for r in RECORDS["long_horizon"])


def test_examples_are_not_benchmark_tasks() -> None:
    shipped = {t.instruction for t in AlfredEnv.load_tasks()}
    seeds = {t.metadata["scene_seed"] for t in AlfredEnv.load_tasks()}
    for key, i in ALL:
        rec = RECORDS[key][i]
        assert rec["text"].split("\n")[0][len("Instruction: "):] not in shipped
        assert rec["scene_seed"] not in seeds


def test_rules_explain_the_nearest_instance() -> None:
    assert "nearest" in ACTION_RULES and "Apple_2" in ACTION_RULES
