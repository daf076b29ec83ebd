"""Prompt parts: the original's structure in our wording; ten single-turn examples that replay in the world."""

from __future__ import annotations

import copy
import json

import pytest

from eb_habitat.prompts import EXAMPLES_FILE, examples, prompt_parts, render_example
from eb_habitat.skills import SKILL_NAMES


def test_ten_single_turn_examples_in_a_fixed_order() -> None:
    exs = examples()
    assert len(exs) == 10
    assert examples("visual_appearance") == exs == examples("long_horizon")  # no reordering by subset
    for text in exs:
        first, second = text.split("\n")
        assert first.startswith("Instruction: ")
        answer = json.loads(second.removeprefix("Answer: "))
        assert set(answer) == {"language_plan", "executable_plan"}
        assert answer["executable_plan"], text
        for item in answer["executable_plan"]:
            assert SKILL_NAMES[item["action_id"]] == item["action_name"]


def test_examples_carry_no_perception_or_inventory() -> None:
    joined = "\n".join(examples()).lower()
    for leak in ("perceives", "you see:", "from left to right", "the robot is holding", "in the room there"):
        assert leak not in joined


def _doc() -> dict:
    return json.loads(EXAMPLES_FILE.read_text(encoding="utf-8"))


def test_an_example_whose_plan_fails_is_refused() -> None:
    ex = copy.deepcopy(_doc()["examples"][0])
    ex["plan"] = [name for name in ex["plan"] if not name.startswith("navigate to the right counter")]
    with pytest.raises(ValueError, match="fails when replayed"):
        render_example(ex, 1)


def test_an_example_that_misses_its_goal_is_refused() -> None:
    ex = copy.deepcopy(_doc()["examples"][0])
    ex["plan"] = ex["plan"][:2]
    with pytest.raises(ValueError, match="does not reach the goal"):
        render_example(ex, 1)


def test_prompt_parts_follow_the_original_structure() -> None:
    parts = prompt_parts("base")
    rules = parts.action_rules
    for kind in ("- Navigate", "- Pick", "- Place", "- Open", "- Close"):
        assert kind in rules
    text = " ".join(parts.guidelines).lower()
    for topic in ("empty plan", "not in view", "conditions", "do not repeat", "same kind", "feedback"):
        assert topic in text, topic
    assert len(parts.examples) == 10


def test_prompt_states_the_budgets_and_that_a_failure_drops_the_rest_of_the_plan() -> None:
    """Issue 25: the episode ends at the 10th failed action, and the prompt must say so (and the 30 steps)."""
    import yaml
    from pathlib import Path

    from eb_habitat.prompts import prompt_parts

    conf = yaml.safe_load((Path(__import__("eb_habitat").__file__).parent / "conf/env/habitat.yaml").read_text())
    notes = prompt_parts("base").output_notes
    assert f"after {conf['max_steps']} actions" in notes
    assert f"{conf['max_invalid_actions']} actions have failed" in notes
    assert "rest of the plan is dropped" in notes
