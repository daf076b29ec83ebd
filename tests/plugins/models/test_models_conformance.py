"""Every backend of the plugin passes the core's ModelBackendConformanceSuite."""

from __future__ import annotations

import io
import json

import pytest
from conftest import KEY_ENV, PLANTED_KEY
from models_toyenv import ButtonLine, VectorReach

from eb_core.model import EpisodeContext
from eb_core.testing import ModelBackendConformanceSuite
from eb_models.baselines import OracleBackend, RandomBackend
from eb_models.human import HumanBackend
from eb_models.replay import ReplayBackend
from eb_models.stub_server import StubOpenAIServer


def _context(env_cls=ButtonLine) -> EpisodeContext:
    env = env_cls()
    task = env_cls.load_tasks()[0]
    env.reset(task, 0)
    return EpisodeContext(env=env, task=task, seed=0)


class TestLiteLLMConformance(ModelBackendConformanceSuite):
    @pytest.fixture(autouse=True)
    def _server(self, monkeypatch, tmp_path):
        monkeypatch.setenv(KEY_ENV, PLANTED_KEY)
        with StubOpenAIServer() as server:
            self.url = server.url
            self.limits = str(tmp_path)
            yield

    def make_backend(self):
        from eb_models.litellm_backend import LiteLLMBackend

        return LiteLLMBackend(model_id="openai/stub-model", api_base=self.url, api_key_env=KEY_ENV,
                              limits_dir=self.limits, input_cost_per_token=0.0, output_cost_per_token=0.0)


class TestOracleConformance(ModelBackendConformanceSuite):
    def make_backend(self):
        return OracleBackend()

    def make_context(self):
        return _context()


class TestRandomConformance(ModelBackendConformanceSuite):
    def make_backend(self):
        return RandomBackend()

    def make_context(self):
        return _context()


class TestRandomVectorConformance(ModelBackendConformanceSuite):
    def make_backend(self):
        return RandomBackend(min_plan=2, max_plan=2)

    def make_context(self):
        return _context(VectorReach)


class TestReplayConformance(ModelBackendConformanceSuite):
    @pytest.fixture(autouse=True)
    def _recorded_run(self, tmp_path):
        steps = tmp_path / "recorded" / "episodes" / ButtonLine.load_tasks()[0].id / "steps.jsonl"
        steps.parent.mkdir(parents=True)
        steps.write_text(json.dumps({"planner_step": 1, "raw_output": '{"executable_plan": []}', "usage": {}}) + "\n")
        self.run_dir = str(tmp_path / "recorded")

    def make_backend(self):
        return ReplayBackend(run_dir=self.run_dir)

    def make_context(self):
        return _context()


class TestHumanConformance(ModelBackendConformanceSuite):
    @pytest.fixture(autouse=True)
    def _dirs(self, tmp_path):
        self.image_dir = str(tmp_path / "images")

    def make_backend(self):
        return HumanBackend(stdin=io.StringIO("1 2\n"), stdout=io.StringIO(), image_dir=self.image_dir)

    def make_context(self):
        return _context()
