"""The oracle's knobs: ``plan_length`` (open or closed loop) and ``noise`` (the noisy expert), in the real loop."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest
from models_toyenv import ButtonLine, VectorReach

from eb_core.config import EnvConfig, PlannerConfig
from eb_core.episode import run_episode
from eb_core.model import EpisodeContext, ModelRequest
from eb_core.planner import VLMPlanner
from eb_models._settings import ModelConfigError
from eb_models.baselines import OracleBackend

ENV_CFG = EnvConfig(name="button-line", max_steps=30, max_invalid_actions=None, replan_on_failure=True,
                    empty_plan_ends=True, default_n_shot=0, resolution=64)


class LongLine(ButtonLine):
    """The button line with room to wander, so noisy runs differ visibly."""

    def __init__(self, resolution: int = 16, multi_view: bool = False) -> None:
        super().__init__(resolution, multi_view, length=12)


class NoExpert(ButtonLine):
    """A world whose expert gives up and says why."""

    def expert_plan(self):
        self.expert_reason = "the button was unplugged"
        return None


class AskCounter(ButtonLine):
    asked = 0

    def expert_plan(self):
        type(self).asked += 1
        return super().expert_plan()


def play(backend, task, seed: int = 5, env_cls=LongLine, step_dir: Path | None = None):
    env = env_cls()
    planner = VLMPlanner(PlannerConfig(), ENV_CFG, supports_json_schema=backend.supports_json_schema)
    rec = run_episode(env=env, task=task, seed=seed, planner=planner, backend=backend, env_config=ENV_CFG,
                      step_dir=step_dir, save_images=False)
    env.close()
    return rec


def actions_of(step_dir: Path) -> list[list]:
    rows = [json.loads(x) for x in (step_dir / "steps.jsonl").read_text().splitlines()]
    return [[a["action"] for a in r["actions"]] for r in rows]


def answer(backend, env_cls=LongLine, seed: int = 0, i: int = 0) -> dict:
    env = env_cls()
    task = env_cls.load_tasks()[i]
    env.reset(task, seed)
    backend.start_episode(EpisodeContext(env=env, task=task, seed=seed))
    return json.loads(backend.complete(ModelRequest(messages=())).text)


def test_same_seed_same_episode_other_seed_other_episode(tmp_path):
    task = LongLine.load_tasks()[2]
    runs = {}
    for name, seed in (("a", 7), ("b", 7), ("c", 8)):
        rec = play(OracleBackend(plan_length=1, noise=0.5), task, seed=seed, step_dir=tmp_path / name)
        runs[name] = (rec.model_dump(exclude={"wall_time_s", "model_latency_s", "seed"}), actions_of(tmp_path / name))
    assert runs["a"] == runs["b"]
    assert runs["a"][1] != runs["c"][1]
    assert sum(len(a) for a in runs["a"][1]) >= 3


def test_plan_length_one_is_closed_loop():
    AskCounter.asked = 0
    for task in AskCounter.load_tasks():
        rec = play(OracleBackend(plan_length=1), task, env_cls=AskCounter)
        assert rec.success and rec.planner_steps == rec.env_steps >= 2
    assert AskCounter.asked == sum(play(OracleBackend(plan_length=1), t, env_cls=ButtonLine).env_steps
                                   for t in ButtonLine.load_tasks())
    assert len(answer(OracleBackend(plan_length=1))["executable_plan"]) == 1
    assert len(answer(OracleBackend(plan_length=2))["executable_plan"]) == 2
    # the default is today's open loop: the whole plan in one answer
    assert len(answer(OracleBackend())["executable_plan"]) == 3


def test_noise_one_is_random_and_never_asks_the_expert():
    AskCounter.asked = 0
    backend = OracleBackend(plan_length=5, noise=1.0)
    ids = Counter()
    for seed in range(40):
        plan = answer(backend, AskCounter, seed=seed)["executable_plan"]
        assert len(plan) == 5
        ids.update(item["action_id"] for item in plan)
    assert AskCounter.asked == 0
    assert set(ids) == {0, 1, 2} and min(ids.values()) > 40  # 200 draws, every action well represented
    vec = answer(OracleBackend(plan_length=3, noise=1.0), VectorReach)["executable_plan"]
    assert len(vec) == 3 and all(len(a["action"]) == 3 and all(0 <= v <= 10 for v in a["action"]) for a in vec)
    # in the loop it plays like random: far below the expert's 100 %
    wins = sum(play(OracleBackend(plan_length=3, noise=1.0), t, seed=s).success
               for t in LongLine.load_tasks() for s in range(5))
    assert wins < 15


def test_noise_replaces_about_that_share_of_actions():
    backend = OracleBackend(plan_length=20, noise=0.3)
    replaced = total = 0
    for seed in range(60):
        env = LongLine()
        task = LongLine.load_tasks()[2]
        env.reset(task, seed)
        expert = env.expert_plan()
        backend.start_episode(EpisodeContext(env=env, task=task, seed=seed))
        plan = [item["action_id"] for item in json.loads(backend.complete(ModelRequest(messages=())).text)
                ["executable_plan"]]
        assert len(plan) == len(expert)
        # a replacement may draw the expert's own action; count differences against that 2/3 chance
        replaced += sum(a != b for a, b in zip(plan, expert))
        total += len(plan)
    share = replaced / total / (2 / 3)
    assert 0.2 < share < 0.4


def test_no_expert_plan_sends_an_empty_plan_and_says_why():
    text = answer(OracleBackend(), NoExpert)
    assert text["executable_plan"] == []
    assert "the button was unplugged" in text["reasoning_and_reflection"]
    rec = play(OracleBackend(noise=0.5), NoExpert.load_tasks()[0], env_cls=NoExpert)
    assert rec.end_reason == "empty_plan" and not rec.success and rec.env_steps == 0


def test_oracle_settings_are_validated():
    with pytest.raises(ModelConfigError, match="'model.noise'"):
        OracleBackend(noise=1.5)
    with pytest.raises(ModelConfigError, match="'model.plan_length'"):
        OracleBackend(plan_length=0)
    with pytest.raises(ModelConfigError, match="allowed keys: max_cost_usd, noise, plan_length"):
        OracleBackend(plan_len=1)
