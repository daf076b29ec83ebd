"""Prompt parts: our wording, ten examples that replay exactly in the world."""

from __future__ import annotations

from eb_habitat.prompts import examples, prompt_parts


def test_ten_examples_replay_and_put_the_subset_first() -> None:
    exs = examples()
    assert len(exs) == 10
    assert all(e.startswith("Instruction: ") for e in exs)
    first = examples("visual_appearance")[0]
    assert first.startswith("Instruction: Move the blue cup")
    assert all("The task is complete." in e for e in exs)
    # examples show failures and the feedback that explains them
    joined = "\n".join(exs)
    assert "Cannot pick up the banana: there is no banana" in joined
    assert "it is closed. Open it first." in joined


def test_prompt_parts() -> None:
    parts = prompt_parts("base")
    assert "navigate to <receptacle>" in parts.action_rules
    assert any("empty plan" in g for g in parts.guidelines)
    assert len(parts.examples) == 10
