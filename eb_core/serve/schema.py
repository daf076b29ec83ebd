"""The wire schema of ``eb serve`` (version :data:`SCHEMA`): every request and response body is one of these models.

Observations travel as they come out of the Gymnasium env (:class:`eb_core.gym.EBEnv`), with every image as a
base64 PNG string: prompt mode ``{"prompt": str, "images": [png, ...]}``, raw mode ``{"image": png, "text": str}``.
``info`` is the env's info dict, JSON-encoded (numpy scalars as numbers). The schema is versioned: a breaking change
gets a new ``/vN`` prefix and a new :data:`SCHEMA`; fields are only ever added within one version.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

__all__ = [
    "SCHEMA",
    "CreateSession",
    "ErrorBody",
    "Health",
    "ResetRequest",
    "ResetResponse",
    "SessionInfo",
    "Stats",
    "StepRequest",
    "StepResponse",
]

SCHEMA = "eb-serve/1"
"""Name and version of this schema (``GET /v1/health`` says it; the client checks it)."""


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid")


class CreateSession(_Body):
    num_envs: int = Field(ge=1, le=4096)
    """How many environments the session leases from the server's pool."""
    autoreset: Literal["NextStep", "SameStep", "Disabled"] = "NextStep"
    """Gymnasium's autoreset mode, as :class:`~eb_core.gym.EBVectorEnv`'s ``autoreset_mode``."""


class SessionInfo(_Body):
    session: str
    """The session id: the path segment of every further call."""
    num_envs: int
    schema_: str = Field(SCHEMA, alias="schema")
    world: str
    obs_mode: str
    split: str
    taskset: str
    observation_space: dict[str, Any]
    """The single environment's observation space (:func:`eb_core.serve.spaces.describe`)."""
    action_space: dict[str, Any]
    session_timeout_s: float
    """Idle seconds after which the server reaps the session (any call, or ``POST .../keepalive``, resets it)."""

    model_config = ConfigDict(extra="forbid", populate_by_name=True)


class ResetRequest(_Body):
    seeds: list[int | None] | None = None
    """One seed per environment (``None`` = unseeded); the task is ``seed`` modulo the task list, as ``EBEnv``."""
    task_ids: list[str | None] | None = None
    """One task id per environment (``None`` = by seed): ``options={"task_id": ...}`` of ``EBEnv.reset``."""
    mask: list[bool] | None = None
    """Reset only these environments (default all); the others keep their episode."""


class StepRequest(_Body):
    actions: list[Any]
    """One action per environment: the answer text (prompt mode), an action id or a vector (raw mode), or
    ``null`` to leave that environment as it is."""


class ResetResponse(_Body):
    observations: list[dict[str, Any] | None]
    infos: list[dict[str, Any] | None]


class StepResponse(_Body):
    observations: list[dict[str, Any] | None]
    rewards: list[float]
    terminated: list[bool]
    truncated: list[bool]
    infos: list[dict[str, Any] | None]


class Health(_Body):
    status: str
    schema_: str = Field(SCHEMA, alias="schema")
    world: str
    obs_mode: str
    split: str
    taskset: str
    capacity: int
    free: int
    workers: int

    model_config = ConfigDict(extra="forbid", populate_by_name=True)


class Stats(_Body):
    sessions: int
    envs_leased: int
    capacity: int
    resets: int
    steps: int
    batches: int
    errors: int
    worker_restarts: int
    reaped_sessions: int
    worker_pids: list[int]
    """Process id of each worker (its actor's process under Ray)."""
    uptime_s: float
    step_latency_ms: dict[str, float]
    """p50 / p99 / mean of the server-side time of a step call (queueing included), over the last 10,000."""


class ErrorBody(_Body):
    error: str
    """One line: what was wrong, what is allowed, how to fix it."""
