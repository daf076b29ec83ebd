"""Run-directory records: one JSON line per finished episode, written so that a crash loses nothing.

Layout of a run directory::

    config.yaml        the resolved config
    plugins.json       loaded plugins and their versions
    episodes.jsonl     one line per finished episode (the source of truth for resume)
    episodes/<id>/     steps.jsonl (prompt, raw output, parsed plan, actions, feedback) and step PNGs
    summary.json       the paper's metrics per subset and overall
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict

__all__ = ["EpisodeRecord", "RunFiles", "atomic_write_text"]

EndReason = Literal[
    "success", "done", "max_steps", "invalid_cap", "empty_plan", "error", "budget",
]


class EpisodeRecord(BaseModel):
    """One line of ``episodes.jsonl``."""

    model_config = ConfigDict(extra="forbid")

    task_id: str
    subset: str
    instruction: str
    status: Literal["ok", "error"]
    """``error``: the episode could not be measured (model unreachable, a crashed worker); redone on resume."""
    success: bool = False
    progress: float = 0.0
    end_reason: EndReason = "max_steps"
    env_steps: int = 0
    planner_steps: int = 0
    invalid_actions: int = 0
    output_errors: int = 0
    empty_plan: bool = False
    prompt_tokens: int = 0
    completion_tokens: int = 0
    model_calls: int = 0
    cost_usd: float = 0.0
    model_latency_s: float = 0.0
    wall_time_s: float = 0.0
    seed: int = 0
    error: str | None = None


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` via a temporary file and ``os.replace`` (never a half-written file)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


class RunFiles:
    """Reads and writes one run directory."""

    def __init__(self, run_dir: str | os.PathLike[str]) -> None:
        self.root = Path(run_dir)
        self.root.mkdir(parents=True, exist_ok=True)
        self.episodes_path = self.root / "episodes.jsonl"
        self.episodes_dir = self.root / "episodes"

    # -- episodes.jsonl ---------------------------------------------------------------------------

    def load_episodes(self) -> list[EpisodeRecord]:
        """Finished episodes. A torn last line (a kill during a write) is dropped from the file."""
        if not self.episodes_path.exists():
            return []
        raw = self.episodes_path.read_bytes()
        records: list[EpisodeRecord] = []
        good_len = 0
        for line in raw.splitlines(keepends=True):
            if not line.endswith(b"\n"):
                break
            try:
                records.append(EpisodeRecord.model_validate_json(line))
            except ValueError:
                break
            good_len += len(line)
        if good_len != len(raw):
            with open(self.episodes_path, "r+b") as fh:
                fh.truncate(good_len)
        return records

    def rewrite_episodes(self, records: list[EpisodeRecord]) -> None:
        atomic_write_text(self.episodes_path, "".join(r.model_dump_json() + "\n" for r in records))

    def append_episode(self, record: EpisodeRecord) -> None:
        line = (record.model_dump_json() + "\n").encode("utf-8")
        fd = os.open(self.episodes_path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, line)
            os.fsync(fd)
        finally:
            os.close(fd)

    # -- per-episode step files ---------------------------------------------------------------

    def staging_dir(self, task_id: str) -> Path:
        """Where a running episode writes its steps; moved into place only when it finishes."""
        d = self.episodes_dir / f".{task_id}.partial"
        if d.exists():
            shutil.rmtree(d)
        d.mkdir(parents=True)
        return d

    def finalize_episode_dir(self, task_id: str) -> Path:
        staging = self.episodes_dir / f".{task_id}.partial"
        final = self.episodes_dir / task_id
        if final.exists():
            shutil.rmtree(final)
        if staging.exists():
            os.replace(staging, final)
        return final

    def clean_partial(self, finished: set[str]) -> None:
        """Remove leftovers of unfinished episodes (they are redone)."""
        if not self.episodes_dir.exists():
            return
        for d in self.episodes_dir.iterdir():
            if d.name.startswith(".") and d.name.endswith(".partial"):
                shutil.rmtree(d, ignore_errors=True)
            elif d.is_dir() and d.name not in finished:
                shutil.rmtree(d, ignore_errors=True)

    def write_json(self, name: str, data: Any) -> None:
        atomic_write_text(self.root / name, json.dumps(data, indent=2, sort_keys=False, default=str) + "\n")
