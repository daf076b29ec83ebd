"""Run-directory records: one JSON line per finished episode, written so that a crash loses nothing.

Layout of a run directory::

    config.yaml        the resolved config
    plugins.json       loaded plugins and their versions
    episodes.jsonl     one line per finished episode (the source of truth for resume)
    episodes/<id>/     steps.jsonl (prompt, raw output, parsed plan, actions, feedback) and step PNGs
                       (repeat k > 0 of a task: ``episodes/<id>_repeat<k>/``)
    run.lock           held (flock) by the process running in this directory; holds its pid
    summary.json       the paper's metrics per subset and overall
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict

__all__ = ["EpisodeRecord", "RunDirLocked", "RunFiles", "RunLock", "atomic_write_text", "episode_dir_name"]

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
    repeat: int = 0
    """Which repeat of the task this is (``runner.repeats``); 0 for the first and for single-repeat runs."""
    error: str | None = None
    error_counts: dict[str, int] | None = None
    """Automatic error labels of the episode, counted per category (:mod:`eb_core.errors`); None if not labelled."""
    perception_score: float | None = None
    """Mean F1 of the objects the visual-state descriptions named against those in view; None if not measurable."""
    node: str | None = None
    """Where the episode ran: the Ray node id under ``runner.executor=ray``, the host name otherwise."""

    @property
    def key(self) -> tuple[str, int]:
        """The episode's identity in a run: task and repeat."""
        return (self.task_id, self.repeat)


def episode_dir_name(task_id: str, repeat: int = 0) -> str:
    """Directory of an episode's step files under ``episodes/``: the task id, plus ``_repeat<k>`` for k > 0."""
    return task_id if repeat == 0 else f"{task_id}_repeat{repeat}"


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

    def staging_dir(self, task_id: str, repeat: int = 0) -> Path:
        """Where a running episode writes its steps; moved into place only when it finishes."""
        d = self.episodes_dir / f".{episode_dir_name(task_id, repeat)}.partial"
        if d.exists():
            shutil.rmtree(d)
        d.mkdir(parents=True)
        return d

    def episode_dir(self, task_id: str, repeat: int = 0) -> Path:
        return self.episodes_dir / episode_dir_name(task_id, repeat)

    def finalize_episode_dir(self, task_id: str, repeat: int = 0) -> Path:
        name = episode_dir_name(task_id, repeat)
        staging = self.episodes_dir / f".{name}.partial"
        final = self.episodes_dir / name
        if final.exists():
            shutil.rmtree(final)
        if staging.exists():
            os.replace(staging, final)
        return final

    def clean_partial(self, finished: set[str]) -> None:
        """Remove leftovers of unfinished episodes (they are redone). ``finished`` holds directory names
        (:func:`episode_dir_name`)."""
        if not self.episodes_dir.exists():
            return
        for d in self.episodes_dir.iterdir():
            if d.name.startswith(".") and d.name.endswith(".partial"):
                shutil.rmtree(d, ignore_errors=True)
            elif d.is_dir() and d.name not in finished:
                shutil.rmtree(d, ignore_errors=True)

    def append_line(self, name: str, line: str) -> None:
        """Append one line to a small log in the run directory (one write + fsync)."""
        fd = os.open(self.root / name, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, (line.rstrip("\n") + "\n").encode("utf-8"))
            os.fsync(fd)
        finally:
            os.close(fd)

    def write_json(self, name: str, data: Any) -> None:
        atomic_write_text(self.root / name, json.dumps(data, indent=2, sort_keys=False, default=str) + "\n")


class RunDirLocked(RuntimeError):
    """Another process holds the run directory's lock; the message names the directory and its pid."""


class RunLock:
    """An exclusive ``flock`` on ``<run_dir>/run.lock``, which holds the owner's pid.

    The kernel drops the lock when the holder's last descriptor closes, so a ``kill -9``'d run never
    blocks the next one. Forked workers must call :meth:`forget_in_child` so they do not keep it alive.
    """

    name = "run.lock"

    def __init__(self, run_dir: str | os.PathLike[str]) -> None:
        self.path = Path(run_dir) / self.name
        self.fd: int | None = None

    def acquire(self) -> "RunLock":
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            try:
                holder = os.pread(fd, 64, 0).decode("ascii", "replace").strip() or "unknown"
            finally:
                os.close(fd)
            raise RunDirLocked(
                f"{self.path.parent} is in use by another eb run (pid {holder}); wait for it to finish, or start "
                f"a separate run with experiment=NAME or hydra.run.dir=DIR") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        self.fd = fd
        return self

    def release(self) -> None:
        if self.fd is not None:
            try:
                os.ftruncate(self.fd, 0)
                fcntl.flock(self.fd, fcntl.LOCK_UN)
            finally:
                os.close(self.fd)
                self.fd = None

    def forget_in_child(self) -> None:
        """In a forked child: close the inherited descriptor (the parent keeps the lock)."""
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def __enter__(self) -> "RunLock":
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self.release()
