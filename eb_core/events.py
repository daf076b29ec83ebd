"""Frozen event objects passed to the lifecycle hooks. Observers read them; they cannot change results.

New information is added as new optional fields, never by renaming, so observers keep working.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict

__all__ = ["EpisodeEndEvent", "EpisodeStartEvent", "RunEndEvent", "RunStartEvent", "StepEndEvent"]


class _Event(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class RunStartEvent(_Event):
    run_dir: str
    env: str
    model: str
    n_tasks: int
    n_pending: int
    config: dict[str, Any]


class EpisodeStartEvent(_Event):
    run_dir: str
    task_id: str
    subset: str
    instruction: str
    seed: int


class StepEndEvent(_Event):
    run_dir: str
    task_id: str
    env_step: int
    planner_step: int
    action: Any
    action_name: str
    action_success: bool
    feedback: str
    progress: float


class EpisodeEndEvent(_Event):
    run_dir: str
    record: dict[str, Any]
    """The episode's line of ``episodes.jsonl``, as a dict."""


class RunEndEvent(_Event):
    run_dir: str
    summary: dict[str, Any]
    stopped_early: str | None = None
    """Why the run stopped before all tasks (``budget``, ``fatal: ...``), or None."""
