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
    long = env.prompt_parts().examples
    assert len(long) == 7 and not set(long) & set(general.examples)


def test_env_yaml_follows_the_original_accounting() -> None:
    """An unparsable answer uses no env step in ALFRED; ``spatial`` is accepted for ``spatial_awareness``."""
    from pathlib import Path

    import yaml

    import eb_alfred.env as env_module
    from eb_core.config import EnvConfig

    raw = yaml.safe_load((Path(env_module.__file__).parent / "conf" / "env" / "alfred.yaml").read_text())
    cfg = EnvConfig(**raw)
    assert cfg.output_error_uses_step is False
    assert cfg.subset_aliases == {"spatial": "spatial_awareness"}
    assert (cfg.max_steps, cfg.max_invalid_actions, cfg.default_n_shot) == (30, 10, 10)


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
