"""Run-directory records: one JSON line per finished episode, written so that a crash loses nothing.

Layout of a run directory::

    manifest.json      format version, versions of the core, plugins and key libraries, the task-set digest
                       (:class:`RunManifest`; absent in runs made before format version 1)
    config.yaml        the resolved config
    plugins.json       loaded plugins and their versions
    episodes.jsonl     one line per finished episode (the source of truth for resume)
    episodes/<id>/     steps.jsonl (one :class:`StepRecord` per planner step: prompt, raw output, parsed plan,
                       the executed :class:`ActionRecord` s) and step PNGs
                       (repeat k > 0 of a task: ``episodes/<id>_repeat<k>/``)
    run.lock           held (flock) by the process running in this directory; holds its pid
    summary.json       the paper's metrics per subset and overall

Every consumer (report, viewer, export, replay, error labels, ``eb verify``) reads a run through
:func:`read_run` and :func:`read_steps`; nothing else parses these files.
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import tempfile
import weakref
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from eb_core.model import Usage
from eb_core.parsing import PlannerOutput

__all__ = ["FORMAT_VERSION", "ActionRecord", "EndReason", "EpisodeRecord", "RunDirLocked", "RunFiles", "RunLock",
           "RunLog", "RunManifest", "SeenObject", "StepRecord", "atomic_write_text", "episode_dir_name", "iter_steps",
           "read_manifest", "read_run", "read_steps"]

FORMAT_VERSION = 1
"""Version of the run-directory format this code writes (``manifest.json``). Runs without a manifest are
version 0: the same files, read the same way."""

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


class ActionRecord(BaseModel):
    """One executed action in a step's ``actions`` list.

    Written with ``exclude_unset`` so a field the episode did not set (no expert labels, no distance in this
    world) stays absent from the line, as before the records were typed. Unknown keys of newer writers are kept.
    """

    model_config = ConfigDict(extra="allow")

    env_step: int
    """1-based count of env steps in the episode after this action."""
    action: Any
    """The action as the env received it (an id, or a list for vector actions)."""
    action_name: str | None = None
    success: bool
    """Whether the world reported the action as executed."""
    feedback: str = ""
    progress: float = 0.0
    """Task progress after the action, clamped to [0, 1]."""
    failure: str | None = None
    """The world's machine-readable failure kind (``StepResult.info["failure"]``), if any."""
    expert_action: Any = None
    """``runner.expert_labels``: the first action of the expert's plan before this action (None: no plan)."""
    expert_action_name: str | None = None
    expert_reason: str | None = None
    """Why there is no ``expert_action``."""
    distance_to_goal: float | None = None
    path_distance: float | None = None
    """Metres along the shortest free path to the goal, where the world reports it (drift, eb_core.errors)."""
    wrong_target: Any = None


class SeenObject(BaseModel):
    """An object in the image the model was shown (for the perception check): from the world's segmentation
    pixels (``Observation.visible_objects``: also ``colour``, ``colours``, ``aliases``, ``pixels``, ``edge``),
    else an object with a box."""

    model_config = ConfigDict(extra="allow")

    name: str
    type: str | None = None


class StepRecord(BaseModel):
    """One line of ``episodes/<id>/steps.jsonl``: one planner step (a model call and what it executed).

    Old runs lack some fields (``sent_images``, ``visible_objects``): they load with the defaults below.
    """

    model_config = ConfigDict(extra="allow")

    planner_step: int
    env_step_before: int = 0
    """Env steps taken before this planner step."""
    prompt: str = ""
    """The text of the last message sent (the current turn)."""
    sent_images: list[str] | None = None
    """Names of the images sent with this turn (None in runs before it was recorded)."""
    visible_objects: list[SeenObject] | None = None
    scene_objects: list[str] | None = None
    """First planner step only: the types the scene holds, in view or not (``Observation.scene_objects``)."""
    image: str | None = None
    """File name of the step's primary image PNG, if saved."""
    extra_images: list[str] | None = None
    raw_output: str
    """The model's answer, verbatim."""
    usage: Usage = Field(default_factory=Usage)
    parsed: PlannerOutput | None = None
    """The answer's four fields; None when it could not be parsed."""
    error: str | None = None
    """Why the answer was unusable (an output error), else None."""
    plan_error: str | None = None
    """Why the plan was cut, else None."""
    actions: list[ActionRecord] = Field(default_factory=list)

    def to_json_line(self) -> str:
        """The line written to ``steps.jsonl`` (fields the episode did not set are left out)."""
        return json.dumps(self.model_dump(mode="json", exclude_unset=True), default=str) + "\n"

    def as_dict(self) -> dict[str, Any]:
        """The step as the plain dict of its JSON line (for code that still reads dicts)."""
        return self.model_dump(mode="json", exclude_unset=True)


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


_HELD: weakref.WeakSet[RunLock] = weakref.WeakSet()
_FORKS_WATCHED = False


def _forget_held_locks() -> None:
    for lock in list(_HELD):
        lock.forget_in_child()
    _HELD.clear()


def _watch_forks() -> None:
    global _FORKS_WATCHED
    if not _FORKS_WATCHED:
        os.register_at_fork(after_in_child=_forget_held_locks)
        _FORKS_WATCHED = True


class RunLock:
    """An exclusive ``flock`` on ``<run_dir>/run.lock``, which holds the owner's pid.

    The kernel drops the lock when the holder's last descriptor closes, so a ``kill -9``'d run never
    blocks the next one. A process forked while the lock is held closes its copy at once (an ``at fork``
    handler), so worker processes never keep it alive.
    """

    name = "run.lock"

    def __init__(self, run_dir: str | os.PathLike[str]) -> None:
        self.path = Path(run_dir) / self.name
        self.fd: int | None = None

    def acquire(self) -> RunLock:
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
        _HELD.add(self)
        _watch_forks()
        return self

    def release(self) -> None:
        _HELD.discard(self)
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

    def __enter__(self) -> RunLock:
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self.release()


# -- the run manifest and the one reader --------------------------------------------------------------


class RunManifest(BaseModel):
    """``manifest.json``: what a run was made with, written at the start of every invocation.

    A file of its own rather than a key of ``summary.json``: it exists from the first episode on (a run that
    crashed has no summary), it is never rewritten by the summary, and ``summary.json`` keeps its shape.
    """

    model_config = ConfigDict(extra="allow")

    format_version: int = FORMAT_VERSION
    created: str = ""
    """UTC time of the first invocation in this directory (ISO 8601)."""
    env: str
    model: str
    taskset: str = "classic"
    split: str = "test"
    n_tasks: int
    """Tasks in the installed task set the run selected from."""
    task_set_digest: str
    """SHA-256 of the whole installed task set (:func:`eb_core.taskfile.task_set_digest`)."""
    selected_digest: str
    """Likewise of the selected tasks, in run order."""
    task_ids: list[str] = Field(default_factory=list)
    """The ids of the selected tasks in run order: the run's own selection, which ``eb verify`` replays even if
    later code would select differently from the same config."""
    config_digest: str
    """SHA-256 of the resolved config (``config.yaml``) as canonical JSON."""
    versions: dict[str, str] = Field(default_factory=dict)
    """Versions of the core, each loaded plugin and the key libraries (python, numpy, mujoco, pydantic, ...)."""


class RunLog:
    """A run directory as read by :func:`read_run`: its manifest, config, episodes and summary."""

    def __init__(self, root: Path, manifest: RunManifest | None, config: dict[str, Any],
                 episodes: list[EpisodeRecord], summary: dict[str, Any] | None, plugins: dict[str, str]) -> None:
        self.root = root
        self.manifest = manifest
        """None for runs made before format version 1."""
        self.config = config
        self.episodes = episodes
        self.summary = summary
        self.plugins = plugins

    @property
    def format_version(self) -> int:
        return 0 if self.manifest is None else self.manifest.format_version

    def episode_dir(self, key: tuple[str, int]) -> Path:
        return self.root / "episodes" / episode_dir_name(*key)

    def steps(self, key: tuple[str, int]) -> list[StepRecord]:
        """The step records of one episode (``(task_id, repeat)``); [] when it has none."""
        return read_steps(self.episode_dir(key))


def read_steps(ep_dir: str | os.PathLike[str], *, strict: bool = False) -> list[StepRecord]:
    """The step records of ``ep_dir/steps.jsonl``, in file order; no file gives [].

    A torn or unreadable line is skipped, or with ``strict`` raises ValueError naming the file and line.
    """
    path = Path(ep_dir) / "steps.jsonl"
    if not path.is_file():
        return []
    out: list[StepRecord] = []
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip():
            continue
        try:
            out.append(StepRecord.model_validate_json(line))
        except ValueError as exc:
            if strict:
                first = str(exc).splitlines()
                raise ValueError(f"{path} line {n} is not a step record: {' '.join(first[:3])}") from None
    return out


def _read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def read_manifest(run_dir: str | os.PathLike[str]) -> RunManifest | None:
    """The run's manifest, or None when it has none (a run made before format version 1).

    Raises ValueError when the file exists but is not a manifest, or is of a newer format than this code reads.
    """
    path = Path(run_dir) / "manifest.json"
    if not path.is_file():
        return None
    manifest = RunManifest.model_validate_json(path.read_text(encoding="utf-8"))
    if manifest.format_version > FORMAT_VERSION:
        raise ValueError(f"{path} has format_version {manifest.format_version}; this EmbodiedBench reads up to "
                         f"{FORMAT_VERSION}. Fix: upgrade embodiedbench")
    return manifest


def read_run(run_dir: str | os.PathLike[str]) -> RunLog:
    """Read a run directory (any format version) without changing it."""
    import yaml  # shipped with omegaconf

    root = Path(run_dir)
    if not (root / "episodes.jsonl").is_file() and not (root / "config.yaml").is_file():
        raise FileNotFoundError(f"{root} is not a run directory (no episodes.jsonl or config.yaml)")
    episodes: list[EpisodeRecord] = []
    path = root / "episodes.jsonl"
    if path.is_file():
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.strip():
                try:
                    episodes.append(EpisodeRecord.model_validate_json(line))
                except ValueError:
                    continue  # a torn last line
    config: dict[str, Any] = {}
    if (root / "config.yaml").is_file():
        config = yaml.safe_load((root / "config.yaml").read_text(encoding="utf-8")) or {}
    return RunLog(root, read_manifest(root), config, episodes, _read_json(root / "summary.json"),
                  _read_json(root / "plugins.json") or {})


def iter_steps(run: RunLog, *, ok_only: bool = True) -> Iterator[tuple[EpisodeRecord, list[StepRecord]]]:
    """Each episode of ``run`` (``status == "ok"`` ones unless ``ok_only=False``) with its step records."""
    for rec in run.episodes:
        if ok_only and rec.status != "ok":
            continue
        yield rec, run.steps(rec.key)
