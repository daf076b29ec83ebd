"""Offline baselines that need no network: ``oracle`` (the env's expert plan) and ``random``.

Both answer with the planner's JSON format, so a run with them exercises the whole pipeline: prompt
building, parsing, execution, re-planning, records and metrics.
"""

from __future__ import annotations

import random
import time
from typing import Any

from pydantic import Field, model_validator

from eb_core.env import Action, ActionSpace, DiscreteActionSpace
from eb_core.model import EpisodeContext, ModelBackend, ModelFatalError, ModelRequest, ModelResponse, Usage
from eb_models._answer import MAX_PLAN, planner_answer
from eb_models._settings import BackendSettings, validate_settings

__all__ = ["OracleBackend", "OracleSettings", "RandomBackend", "RandomSettings", "random_action"]


class _OfflineBackend(ModelBackend):
    supports_images = True
    supports_json_schema = False
    backend_name = ""

    def __init__(self) -> None:
        self.ctx: EpisodeContext | None = None

    def start_episode(self, ctx: EpisodeContext) -> None:
        self.ctx = ctx

    def _context(self) -> EpisodeContext:
        if self.ctx is None:
            raise ModelFatalError(f"the {self.backend_name} backend needs an episode: start_episode() was not called")
        return self.ctx

    @staticmethod
    def _response(text: str, t0: float, model: str) -> ModelResponse:
        return ModelResponse(text=text, usage=Usage(latency_s=time.perf_counter() - t0, calls=1), model=model)

    def close(self) -> None:
        self.ctx = None


def random_action(space: ActionSpace, rng: random.Random) -> Action:
    """One uniformly random valid action: an id of a discrete space, or one integer per vector dimension."""
    if isinstance(space, DiscreteActionSpace):
        return rng.randrange(len(space))
    return tuple(rng.randint(lo, hi) for lo, hi in zip(space.low, space.high))


class OracleSettings(BackendSettings):
    plan_length: int = Field(default=20, ge=1, le=MAX_PLAN)
    """Actions of the expert plan sent per answer: 20 = open loop (the whole plan, as before), 1 = closed loop
    (the first action, then the expert is asked again from the new state)."""
    noise: float = Field(default=0.0, ge=0.0, le=1.0)
    """Probability that each planned action is replaced by a uniformly random valid action (seeded per episode
    and task, like ``random``): 0 = the exact expert, 1 = random actions only."""


class OracleBackend(_OfflineBackend):
    """Answers with ``env.expert_plan()`` from the current state, cut to ``plan_length`` actions, each action
    replaced by a random valid one with probability ``noise``. The noisy expert is the yardstick between
    ``random`` (noise 1) and a perfect agent (noise 0): ``eb audit`` plots success against the noise level."""

    backend_name = "oracle"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__()
        self.settings = validate_settings(OracleSettings, "oracle", kwargs)
        self.coin = random.Random(0)
        self.draws = random.Random(0)

    def start_episode(self, ctx: EpisodeContext) -> None:
        super().start_episode(ctx)
        # Two streams: whether a step is noisy, and which random action it gets (same seeds, same episode).
        self.coin = random.Random(f"eb-oracle-noise:{ctx.seed}:{ctx.task.id}")
        self.draws = random.Random(f"eb-oracle-action:{ctx.seed}:{ctx.task.id}")

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        env = self._context().env
        space = env.action_space()
        n, noise = self.settings.plan_length, self.settings.noise
        plan: list[Action]
        if noise >= 1.0:  # the expert is never followed: do not ask it
            plan = [random_action(space, self.draws) for _ in range(n)]
            text = planner_answer(space, plan, seen="(oracle, noise 1: the image is ignored)",
                                  reasoning=f"{len(plan)} uniformly random valid actions (noise=1).")
            return self._response(text, t0, "oracle")
        expert = env.expert_plan()
        if expert is None:
            why = (env.expert_reason or "the environment gives no reason").rstrip(".")
            text = planner_answer(space, [], seen="(oracle)",
                                  reasoning=f"The expert has no plan from this state: {why}.")
            return self._response(text, t0, "oracle")
        plan = []
        replaced = 0
        for action in list(expert)[:n]:
            u = self.coin.random()
            other = random_action(space, self.draws) if noise > 0 else action
            if u < noise:
                plan.append(other)
                replaced += 1
            else:
                plan.append(action)
        if not plan:
            reasoning = "The expert plan from the current state is empty."
        elif n == 1:
            reasoning = (f"A random valid action instead of the expert's next one (noise={noise:g})." if replaced
                         else "The expert's next action from the current state.")
        else:
            reasoning = f"The first {len(plan)} of the expert plan's {len(expert)} actions from the current state"
            reasoning += f"; {replaced} replaced by random actions (noise={noise:g})." if noise > 0 else "."
        text = planner_answer(space, plan, seen="(oracle: the simulator state is known exactly)",
                              reasoning=reasoning)
        return self._response(text, t0, "oracle")


class RandomSettings(BackendSettings):
    min_plan: int = Field(default=1, ge=1, le=20)
    """Shortest plan."""
    max_plan: int = Field(default=3, ge=1, le=20)
    """Longest plan (uniform length between the two)."""

    @model_validator(mode="after")
    def _order(self) -> "RandomSettings":
        if self.min_plan > self.max_plan:
            raise ValueError("min_plan must not exceed max_plan")
        return self


class RandomBackend(_OfflineBackend):
    """Plans of ``min_plan``..``max_plan`` uniformly random valid actions, seeded by the episode's seed and task."""

    backend_name = "random"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__()
        self.settings = validate_settings(RandomSettings, "random", kwargs)
        self.rng = random.Random(0)

    def start_episode(self, ctx: EpisodeContext) -> None:
        super().start_episode(ctx)
        # A string seed is hashed with SHA-512 by `random`: the same on every machine and Python run.
        self.rng = random.Random(f"eb-random:{ctx.seed}:{ctx.task.id}")

    def sample(self, n: int | None = None) -> list[Action]:
        space = self._context().env.action_space()
        if n is None:
            n = self.rng.randint(self.settings.min_plan, self.settings.max_plan)
        if isinstance(space, DiscreteActionSpace) and len(space) == 0:
            return []
        return [random_action(space, self.rng) for _ in range(n)]

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        space = self._context().env.action_space()
        plan = self.sample()
        text = planner_answer(space, plan, seen="(random baseline: the image is ignored)",
                              reasoning="Uniformly random valid actions.")
        return self._response(text, t0, "random")
