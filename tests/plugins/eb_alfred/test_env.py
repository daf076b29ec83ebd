"""AlfredEnv through the core's conformance suite (symbolic mode) plus prompt and plugin checks."""

from __future__ import annotations

from eb_core.testing import EnvConformanceSuite

from eb_alfred.env import AlfredEnv
from eb_alfred.plugin import SUBSETS


class TestAlfredConformanceSymbolic(EnvConformanceSuite):
    env_class = "eb_alfred.env:AlfredEnv"
    env_params = {"render": False}
    expect_subsets = dict(SUBSETS)
    sample_size = 6


def test_text_observation_describes_place_and_hand() -> None:
    env = AlfredEnv(render=False)
    task = AlfredEnv.load_tasks()[0]
    obs = env.reset(task, 0)
    assert "middle of" in obs.text and "hand is empty" in obs.text
    plan = env.expert_plan()
    result = env.step(plan[0])
    assert result.action_success and "You are in a" in result.observation.text


def test_prompt_parts_examples_per_subset() -> None:
    env = AlfredEnv(render=False)
    tasks = AlfredEnv.load_tasks()
    env.reset(next(t for t in tasks if t.subset == "base"), 0)
    general = env.prompt_parts()
    assert len(general.examples) == 10 and all('"executable_plan"' in e for e in general.examples)
    env.reset(next(t for t in tasks if t.subset == "long_horizon"), 0)
    assert len(env.prompt_parts().examples) == 7


def test_invalid_action_id_gives_feedback() -> None:
    env = AlfredEnv(render=False)
    env.reset(AlfredEnv.load_tasks()[0], 0)
    result = env.step(10_000)
    assert not result.action_success and "not in the list" in result.feedback


def test_plugin_registers_env_and_config(eb_registry) -> None:
    from eb_alfred import plugin

    spec = plugin.eb_register_envs()[0]
    assert spec.name == "alfred" and spec.subsets == SUBSETS and spec.load() is AlfredEnv
    assert plugin.eb_config_searchpath() == ["pkg://eb_alfred.conf"]


def test_examples_are_full_episodes_with_valid_actions() -> None:
    import json

    from eb_alfred.actions import GLOBAL_ACTIONS
    from eb_alfred.prompts import load_examples
    from eb_alfred.world import parse_action

    data = load_examples()
    assert len(data["general"]) == 10 and len(data["long_horizon"]) == 7
    for text in data["general"] + data["long_horizon"]:
        assert text.startswith("Instruction: ")
        answers = [line[len("Answer: "):] for line in text.splitlines() if line.startswith("Answer: ")]
        assert answers
        for raw in answers:
            answer = json.loads(raw)
            assert set(answer) == {"visual_state_description", "reasoning_and_reflection", "language_plan",
                                   "executable_plan"}
            for item in answer["executable_plan"]:
                parse_action(item["action_name"])
                if item["action_name"] in GLOBAL_ACTIONS:  # unnumbered names have the same id everywhere
                    assert GLOBAL_ACTIONS.index(item["action_name"]) == item["action_id"]
