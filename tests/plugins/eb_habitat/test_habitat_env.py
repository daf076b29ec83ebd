"""HabitatEnv against the core's conformance suite, and its own behaviour."""

from __future__ import annotations

import pytest

from eb_core.testing import EnvConformanceSuite
from eb_habitat.env import HabitatEnv
from eb_habitat.plugin import SUBSETS


class TestHabitatConformanceSymbolic(EnvConformanceSuite):
    env_class = "eb_habitat.env:HabitatEnv"
    env_params = {"render": False}
    expect_subsets = SUBSETS
    sample_size = 12


def test_unknown_param_names_itself() -> None:
    with pytest.raises(ValueError, match="unknown param 'rendr'"):
        HabitatEnv(rendr=False)


def test_step_result_fields() -> None:
    env = HabitatEnv(render=False)
    task = HabitatEnv.load_tasks()[0]
    obs = env.reset(task, 0)
    assert obs.primary is None and "middle of the apartment" in obs.text
    plan = env.expert_plan()
    r = env.step(plan[0])
    assert r.action_success and r.info["agent_at"] and 0.0 <= r.progress < 1.0
    assert r.observation.objects and any(o.is_target for o in r.observation.objects)
    with pytest.raises(ValueError):
        env.step(70)
    env.close()
    env.close()
