"""Loading the task files shipped in ``eb_manipulation/tasks/`` through the core's one task-file mechanism.

Two task sets ship: ``classic`` (``tasks/manipulation_v2.json``, the paper's 228 tasks; its bytes never change) and
``hard`` (``tasks/hard/manipulation_hard.json``, same subsets and counts, harder scenes; README: The hard set).
New files use the core's envelope (:class:`eb_core.taskfile.TaskFileFormat`, ``format: eb-manipulation-tasks``,
``version: 3``); the classic file keeps its older envelope (``format: 2``, ``version: "v2"``), which is read by
re-wrapping it in memory and validating it the same way. Every problem is one :class:`TaskFileError` line.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

from eb_core.env import Task
from eb_core.taskfile import TaskFileError, TaskFileFormat

from eb_manipulation.spec import TASK_FORMAT, SceneSpec

__all__ = ["DEFAULT_TASK_FILE", "FORMAT", "HARD_TASK_FILE", "SUBSET_COUNTS", "TASKSETS", "TaskFileError",
           "load_task_file", "scene_of", "taskset_file"]

DEFAULT_TASK_FILE = Path(__file__).parent / "tasks" / "manipulation_v2.json"
HARD_TASK_FILE = Path(__file__).parent / "tasks" / "hard" / "manipulation_hard.json"
TASKSETS = {"classic": DEFAULT_TASK_FILE, "hard": HARD_TASK_FILE}
#: The paper's subset sizes (228 in total).
SUBSET_COUNTS = {"base": 48, "common_sense": 48, "complex": 48, "spatial": 48, "visual": 36}
#: Version of the core envelope this world writes (the classic file's own older envelope is read as well).
ENVELOPE_VERSION = 3


def _check(task: Task) -> tuple[str, str] | None:
    try:
        scene = SceneSpec.model_validate(task.metadata)
    except ValueError as exc:
        first = str(exc).splitlines()
        return "metadata", " ".join(first[1:3]).strip() or first[0]
    if scene.format != TASK_FORMAT:
        return "metadata.format", f"scene format {scene.format}, this version reads {TASK_FORMAT}"
    return None


FORMAT: TaskFileFormat[Task] = TaskFileFormat("manipulation", "eb-manipulation-tasks", ENVELOPE_VERSION, Task,
                                              check=_check, subsets=tuple(SUBSET_COUNTS))
"""The manipulation task-file format (one task = :class:`eb_core.env.Task` with a :class:`SceneSpec` in
``metadata``)."""


@lru_cache(maxsize=8)
def _load(path: str, mtime_ns: int) -> tuple[Task, ...]:
    """Read, re-wrap (classic envelope) and validate one file, cached by (path, modification time)."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise TaskFileError(f"{p}: cannot read the task file: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise TaskFileError(f"{p}: not valid JSON: {str(exc).splitlines()[0]}") from None
    fmt = doc.get("format") if isinstance(doc, dict) else None
    if isinstance(fmt, int) and fmt != TASK_FORMAT:
        raise TaskFileError(f"{p}: field format: task format {fmt}, this version reads {TASK_FORMAT} (classic) and "
                            f"{FORMAT.format!r}. Fix: regenerate it with `eb tasks generate env=manipulation`")
    if fmt == TASK_FORMAT:  # the classic file's own envelope
        doc = {"format": FORMAT.format, "version": FORMAT.version, "tasks": doc.get("tasks")}
    return tuple(FORMAT.parse(doc, p))


def _read(p: Path) -> tuple[Task, ...]:
    if not p.is_file():
        return FORMAT.read(p)  # raises the core's one-line "task file not found"
    return _load(str(p.resolve()), p.stat().st_mtime_ns)


def taskset_file(taskset: str = "classic") -> Path:
    """The shipped file of a task set."""
    if taskset not in TASKSETS:
        raise ValueError(f"manipulation: unknown taskset {taskset!r}; available: {', '.join(TASKSETS)}. "
                         f"Fix: taskset=classic or taskset=hard")
    return TASKSETS[taskset]


def load_task_file(path: str | Path | None = None, taskset: str = "classic") -> list[Task]:
    """All tasks of a task file (a file, or a folder of ``*.json`` files; default: the task set's shipped file),
    in file order."""
    p = Path(path).expanduser() if path is not None else taskset_file(taskset)
    if p.is_dir():
        files = sorted(p.glob("*.json"))
        if not files:
            raise TaskFileError(f"{p}: no task files (*.json) in this folder. Fix: give a file or a folder written "
                                f"by `eb tasks generate env=manipulation`")
        out: list[Task] = []
        where: dict[str, Path] = {}
        for f in files:
            for t in _read(f):
                if t.id in where:
                    raise TaskFileError(f"{f}: task {t.id!r}: field id: duplicate task id (also in {where[t.id]}). "
                                        f"Fix: give every task its own id")
                where[t.id] = f
                out.append(t)
        return out
    return list(_read(p))


def scene_of(task: Task) -> SceneSpec:
    """The validated scene spec stored in a task's metadata."""
    return SceneSpec.model_validate(task.metadata)


def envelope(tasks: list[dict[str, Any]], generator: dict[str, Any]) -> dict[str, Any]:
    """The JSON document of a new task file (validated)."""
    return FORMAT.envelope(tasks, generator=generator)
