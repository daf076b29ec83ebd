"""The conformance suite and check_env catch broken environments (they are tests too)."""

import numpy as np
import pytest

import fixture_plugin
from eb_core.testing import EnvConformanceSuite, check_env
from eb_core.testing.check import EnvCheckError


class TestCorridorConformance(EnvConformanceSuite):
    env_class = "fixture_plugin:CorridorEnv"
    env_params = {"resolution": 64}
    expect_subsets = {"near": 5, "far": 5}
    max_env_steps = 10


class NoisyCorridor(fixture_plugin.CorridorEnv):
    def _obs(self):
        obs = super()._obs()
        obs.images["top"][0, 0] = np.random.randint(0, 255, 3)
        return obs


class LyingCorridor(fixture_plugin.CorridorEnv):
    def step(self, action):
        r = super().step(action)
        return r.model_copy(update={"task_success": True, "progress": 0.5})


def test_check_env_passes_a_good_env():
    env = fixture_plugin.CorridorEnv()
    report = check_env(env, env.load_tasks()[0])
    assert report["steps"] == 2 and report["n_actions"] == 4


def test_check_env_catches_nondeterministic_resets():
    env = NoisyCorridor()
    with pytest.raises(EnvCheckError, match="same primary image"):
        check_env(env, env.load_tasks()[0])


def test_check_env_catches_success_without_full_progress():
    env = LyingCorridor()
    with pytest.raises(EnvCheckError, match="progress 1.0"):
        check_env(env, env.load_tasks()[0])
