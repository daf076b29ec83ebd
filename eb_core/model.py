"""The model-backend contract: a chat request in, a text answer with usage out.

Backends live in plugins (``plugins/models`` ships litellm, oracle, random, replay and human). The
core only knows this interface, so it never imports a model SDK.
"""

from __future__ import annotations

import base64
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

if TYPE_CHECKING:  # pragma: no cover
    from eb_core.env import ActionSpace, Env, Task

__all__ = [
    "EpisodeContext",
    "ImagePart",
    "Message",
    "ModelBackend",
    "ModelBudgetExceeded",
    "ModelError",
    "ModelFatalError",
    "ModelRequest",
    "ModelResponse",
    "ModelTransientError",
    "TextPart",
    "Usage",
]


class ModelError(RuntimeError):
    """Base class of model-backend errors."""


class ModelFatalError(ModelError):
    """The run cannot go on (bad API key, unknown model). Raised before the first episode when possible."""


class ModelTransientError(ModelError):
    """A call failed after all retries (rate limit, 5xx, timeout). The episode is recorded as ``error``."""


class ModelBudgetExceeded(ModelError):
    """``model.max_cost_usd`` was reached: the run stops cleanly with what finished saved."""


class TextPart(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["text"] = "text"
    text: str


class ImagePart(BaseModel):
    """A PNG image. ``png`` holds the encoded bytes; :meth:`data_url` is what APIs receive."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["image"] = "image"
    png: bytes
    name: str = ""
    """The image's name in the observation (``first_person``, ``overhead``...) or ``step-3``."""

    def data_url(self) -> str:
        return "data:image/png;base64," + base64.b64encode(self.png).decode("ascii")


ContentPart = TextPart | ImagePart


class Message(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")
    role: Literal["system", "user", "assistant"]
    content: tuple[ContentPart, ...]

    @property
    def text(self) -> str:
        return "\n".join(p.text for p in self.content if isinstance(p, TextPart))


class ModelRequest(BaseModel):
    """One planner call."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    messages: tuple[Message, ...]
    response_schema: dict[str, Any] | None = None
    """JSON schema of the answer, when the planner asks for constrained output."""
    temperature: float = 0.0
    max_tokens: int = 2048
    seed: int | None = None


class Usage(BaseModel):
    model_config = ConfigDict(extra="forbid")
    prompt_tokens: int = 0
    completion_tokens: int = 0
    cost_usd: float = 0.0
    latency_s: float = 0.0
    calls: int = 0

    def __add__(self, other: Usage) -> Usage:
        return Usage(
            prompt_tokens=self.prompt_tokens + other.prompt_tokens,
            completion_tokens=self.completion_tokens + other.completion_tokens,
            cost_usd=self.cost_usd + other.cost_usd,
            latency_s=self.latency_s + other.latency_s,
            calls=self.calls + other.calls,
        )


class ModelResponse(BaseModel):
    model_config = ConfigDict(extra="forbid")
    text: str
    usage: Usage = Field(default_factory=Usage)
    model: str = ""
    cached: bool = False


class EpisodeContext:
    """What a backend may know about the episode it is about to play.

    Real models ignore it; offline baselines use it: ``oracle`` asks ``env.expert_plan()``, ``random``
    samples from ``action_space`` with ``seed``, ``replay`` looks recorded answers up by ``task.id`` and
    ``repeat`` (which of the task's ``runner.repeats`` plays this is; 0 for the first).
    """

    def __init__(self, env: Env, task: Task, seed: int, run_dir: str | None = None, repeat: int = 0) -> None:
        self.env = env
        self.task = task
        self.seed = seed
        self.run_dir = run_dir
        self.repeat = repeat

    @property
    def action_space(self) -> ActionSpace:
        return self.env.action_space()


class ModelBackend(ABC):
    """Base class of model backends.

    Constructed once per worker process with the validated ``model`` config node as keyword arguments.
    """

    #: Whether the backend can take images (language-only runs work either way).
    supports_images: bool = True
    #: Whether the backend honours :attr:`ModelRequest.response_schema`.
    supports_json_schema: bool = False

    def preflight(self) -> Usage | None:
        """One cheap call before the first episode; raise :class:`ModelFatalError` on a bad key or model.

        Return the call's :class:`Usage` when it made one (the runner logs it in ``preflight.jsonl`` and
        counts its cost in ``model.max_cost_usd``); ``None`` when nothing billable happened.
        """
        return None

    def info(self) -> dict[str, Any] | None:
        """Optional: what the backend settled on at preflight (e.g. its structured-output mode and why); the
        runner writes it to ``model_info.json`` and the summary. None (the default) when there is nothing to say."""
        return None

    def start_episode(self, ctx: EpisodeContext) -> None:
        """Called before each episode's first request."""

    @abstractmethod
    def complete(self, request: ModelRequest) -> ModelResponse:
        """Answer one request. Raise :class:`ModelTransientError` once retries are exhausted."""

    def close(self) -> None:
        """Release connections; safe to call twice."""
