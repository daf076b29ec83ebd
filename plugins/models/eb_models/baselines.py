"""Offline baselines that need no network: ``oracle`` (the env's expert plan) and ``random``.

Both answer with the planner's JSON format, so a run with them exercises the whole pipeline: prompt
building, parsing, execution, re-planning, records and metrics.
"""

from __future__ import annotations

import random
import time
from typing import Any

from pydantic import Field, model_validator

from eb_core.env import Action, DiscreteActionSpace
from eb_core.model import EpisodeContext, ModelBackend, ModelFatalError, ModelRequest, ModelResponse, Usage
from eb_models._answer import planner_answer
from eb_models._settings import BackendSettings, validate_settings

__all__ = ["OracleBackend", "RandomBackend", "RandomSettings"]


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


class OracleBackend(_OfflineBackend):
    """Answers every request with ``env.expert_plan()`` from the current state (the first 20 actions)."""

    backend_name = "oracle"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__()
        self.settings = validate_settings(BackendSettings, "oracle", kwargs)

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        ctx = self._context()
        space = ctx.env.action_space()
        plan = ctx.env.expert_plan()
        if plan is None:
            text = planner_answer(space, [], seen="(oracle)",
                                  reasoning="The environment offers no expert plan from this state.")
        else:
            text = planner_answer(space, plan, seen="(oracle: the simulator state is known exactly)",
                                  reasoning=f"Following the expert plan from the current state ({len(plan)} actions).")
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
        if isinstance(space, DiscreteActionSpace):
            if len(space) == 0:
                return []
            return [self.rng.randrange(len(space)) for _ in range(n)]
        return [tuple(self.rng.randint(lo, hi) for lo, hi in zip(space.low, space.high)) for _ in range(n)]

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        space = self._context().env.action_space()
        plan = self.sample()
        text = planner_answer(space, plan, seen="(random baseline: the image is ignored)",
                              reasoning="Uniformly random valid actions.")
        return self._response(text, t0, "random")
