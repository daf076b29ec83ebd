"""The ``replay`` backend: answers with the raw outputs recorded in an earlier run directory.

For each episode it reads the recorded episode of the same task and repeat
(``<run_dir>/episodes/<task_id>/steps.jsonl``, ``<task_id>_repeat<k>/`` for repeat k > 0 of
``runner.repeats``) through the run reader (:func:`eb_core.records.read_steps`) and returns the steps'
``raw_output`` in ``planner_step`` order. With the same env, planner settings and seed, the replayed run comes out
identical to the recorded one, without calling a model (re-scoring, debugging, demos). Asking
for more answers than were recorded means the runs diverged: that is an error, never a made-up answer.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from pydantic import Field

from eb_core.model import (
    EpisodeContext,
    ModelBackend,
    ModelFatalError,
    ModelRequest,
    ModelResponse,
    ModelTransientError,
    Usage,
)
from eb_core.records import StepRecord, episode_dir_name, read_steps
from eb_models._settings import BackendSettings, ModelConfigError, validate_settings

__all__ = ["ReplayBackend", "ReplaySettings", "load_recorded_outputs"]


class ReplaySettings(BackendSettings):
    run_dir: str = Field(min_length=1)
    """The earlier run directory (the one holding ``episodes.jsonl`` and ``episodes/``)."""


def load_recorded_outputs(steps_file: Path) -> list[StepRecord]:
    """The recorded planner steps of one episode (typed, via the run reader), sorted by ``planner_step``."""
    try:
        rows = read_steps(steps_file.parent, strict=True)
    except ValueError as exc:
        raise ModelTransientError(f"replay: {exc}") from None
    rows.sort(key=lambda r: r.planner_step)
    return rows


class ReplayBackend(ModelBackend):
    supports_images = True
    supports_json_schema = False

    def __init__(self, **kwargs: Any) -> None:
        self.settings = validate_settings(ReplaySettings, "replay", kwargs)
        self.run_dir = Path(self.settings.run_dir).expanduser().resolve()
        if not (self.run_dir / "episodes").is_dir():
            raise ModelConfigError(
                f"replay: model.run_dir {str(self.run_dir)!r} has no episodes/ directory; point it at an earlier "
                f"run directory"
            )
        self.task_id: str | None = None
        self.steps_file: Path | None = None
        self.rows: list[StepRecord] = []
        self.next_index = 0
        self.load_error: str | None = None

    def __repr__(self) -> str:
        return f"ReplayBackend(run_dir={str(self.run_dir)!r})"

    def start_episode(self, ctx: EpisodeContext) -> None:
        if ctx.run_dir and Path(ctx.run_dir).expanduser().resolve() == self.run_dir:
            raise ModelFatalError("replay: model.run_dir is the run being written; replay into another directory "
                                  "(set experiment=<new name>)")
        self.task_id = ctx.task.id
        repeat = ctx.repeat
        self.steps_file = self.run_dir / "episodes" / episode_dir_name(ctx.task.id, repeat) / "steps.jsonl"
        self.next_index = 0
        self.rows = []
        self.load_error = None
        if not self.steps_file.is_file():
            which = f"task {ctx.task.id!r}" + (f" repeat {repeat}" if repeat else "")
            more = (" (the recorded run has fewer runner.repeats?)" if repeat else "")
            self.load_error = f"replay: no recorded steps for {which} ({self.steps_file} is missing){more}"
            return
        self.rows = load_recorded_outputs(self.steps_file)

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        if self.task_id is None:
            raise ModelFatalError("the replay backend needs an episode: start_episode() was not called")
        if self.load_error:
            raise ModelTransientError(self.load_error)
        if self.next_index >= len(self.rows):
            raise ModelTransientError(
                f"replay: task {self.task_id!r} asked for answer {self.next_index + 1} but {self.steps_file} holds "
                f"only {len(self.rows)}; this run diverged from the recorded one (other env version, planner "
                f"settings or seed?)"
            )
        row = self.rows[self.next_index]
        self.next_index += 1
        usage = Usage(prompt_tokens=row.usage.prompt_tokens, completion_tokens=row.usage.completion_tokens,
                      cost_usd=0.0, latency_s=time.perf_counter() - t0, calls=1)
        return ModelResponse(text=row.raw_output, usage=usage, model="replay")

    def close(self) -> None:
        self.rows = []
