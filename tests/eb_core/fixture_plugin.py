"""A small fixture plugin: a corridor world and two scripted model backends.

Registered directly in unit tests (``Registry(get_plugin_manager(plugins=[fixture_plugin]))``) and via
``EB_PLUGINS=fixture_plugin`` for CLI tests. It renders real images (numpy) so the planner's image path runs.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from eb_core import (
    DiscreteActionSpace,
    Env,
    EnvSpec,
    ModelBackend,
    ModelBackendSpec,
    ModelRequest,
    ModelResponse,
    ObjectInfo,
    Observation,
    PromptParts,
    StepResult,
    Task,
    Usage,
    hookimpl,
)

CONF = Path(__file__).parent / "fixture_conf"
ACTIONS = ("step left", "step right", "wait", "explode")


class CorridorEnv(Env):
    """An agent in a corridor of ``length`` cells must reach the goal cell. ``explode`` raises (an env bug)."""

    name = "corridor"

    def __init__(self, resolution: int = 64, multi_view: bool = False, length: int = 8, crash_on: str | None = None,
                 sleep_s: float = 0.0) -> None:
        self.resolution, self.multi_view, self.length = resolution, multi_view, length
        self.crash_on = crash_on
        self.sleep_s = sleep_s
        self.pos = 0
        self.goal = 0
        self.task: Task | None = None
        self.closed = 0

    @classmethod
    def load_tasks(cls, length: int = 8, crash_on: str | None = None, sleep_s: float = 0.0) -> list[Task]:
        tasks = []
        for subset in ("near", "far"):
            for i in range(5):
                start = i % 3
                goal = start + (2 if subset == "near" else 5)
                tasks.append(Task(id=f"{subset}-{i}", subset=subset, instruction=f"walk to cell {goal}",
                                  metadata={"start": start, "goal": goal}))
        return tasks

    def _obs(self) -> Observation:
        img = np.full((self.resolution, self.resolution, 3), 30, np.uint8)
        cell = self.resolution // self.length
        img[:, self.goal * cell:(self.goal + 1) * cell, 1] = 200
        img[:, self.pos * cell:(self.pos + 1) * cell, 0] = 220
        images = {"top": img}
        if self.multi_view:
            images["side"] = img[::-1].copy()
        return Observation(images=images, primary="top", text=f"You are at cell {self.pos}; the goal is cell {self.goal}.",
                           objects=[ObjectInfo(name="goal", box=(self.goal * cell, 0, (self.goal + 1) * cell - 1, 10),
                                               is_target=True)])

    def reset(self, task: Task, seed: int) -> Observation:
        if self.crash_on == task.id:
            os._exit(3)  # a worker that dies hard
        self.task = task
        self.pos = int(task.metadata["start"])
        self.goal = int(task.metadata["goal"])
        return self._obs()

    def step(self, action: Any) -> StepResult:
        if self.sleep_s:
            time.sleep(self.sleep_s)
        a = ACTIONS[int(action)]
        ok = True
        feedback = "done"
        if a == "explode":
            raise RuntimeError("the corridor exploded")
        if a == "step left":
            ok = self.pos > 0
            self.pos = max(0, self.pos - 1)
            feedback = "moved left" if ok else "bumped into the left wall"
        elif a == "step right":
            ok = self.pos < self.length - 1
            self.pos = min(self.length - 1, self.pos + 1)
            feedback = "moved right" if ok else "bumped into the right wall"
        else:
            feedback = "waited"
        success = self.pos == self.goal
        return StepResult(observation=self._obs(), action_success=ok, feedback=feedback, done=success,
                          task_success=success, progress=1.0 if success else 0.0)

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=ACTIONS)

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="You walk along a corridor.", action_rules="Steps move one cell.",
                           guidelines=("Do not wait forever.",),
                           examples=("Instruction: walk to cell 2\n{\"executable_plan\": [{\"action_id\": 1}]}",) * 4)

    def expert_plan(self) -> list[int]:
        d = self.goal - self.pos
        return [1] * d if d > 0 else [0] * (-d)

    def close(self) -> None:
        self.closed += 1


class ScriptedBackend(ModelBackend):
    """Answers from a fixed list (cycled); ``oracle`` answers the env's expert plan."""

    supports_json_schema = True

    def __init__(self, answers: list[str] | None = None, oracle: bool = False, cost_per_call: float = 0.0,
                 fail: str | None = None) -> None:
        self.answers = answers or []
        self.oracle = oracle
        self.cost = cost_per_call
        self.fail = fail
        self.i = 0
        self.env = None
        self.requests: list[ModelRequest] = []

    def preflight(self) -> None:
        from eb_core import ModelFatalError

        if self.fail == "auth":
            raise ModelFatalError("authentication failed for model 'scripted' (check SCRIPTED_API_KEY)")

    def start_episode(self, ctx) -> None:
        self.env = ctx.env

    def complete(self, request: ModelRequest) -> ModelResponse:
        from eb_core import ModelTransientError

        self.requests.append(request)
        if self.fail == "transient":
            raise ModelTransientError("server kept answering 503 after 5 retries")
        if self.oracle:
            space = self.env.action_space()
            text = json.dumps({"visual_state_description": "a corridor", "reasoning_and_reflection": "go",
                               "language_plan": "walk", "executable_plan": [space.plan_item(a) for a in self.env.expert_plan()]})
        else:
            text = self.answers[self.i % len(self.answers)]
        self.i += 1
        return ModelResponse(text=text, usage=Usage(prompt_tokens=100, completion_tokens=20, cost_usd=self.cost,
                                                    latency_s=0.0, calls=1))


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [EnvSpec(name="corridor", entry_point="fixture_plugin:CorridorEnv", subsets={"near": 5, "far": 5},
                    description="fixture corridor")]


@hookimpl
def eb_register_model_backends() -> list[ModelBackendSpec]:
    return [ModelBackendSpec(name="scripted", entry_point="fixture_plugin:ScriptedBackend",
                             description="fixture scripted answers")]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return [f"file://{CONF}"]
