"""Loading the versioned task file(s) shipped in ``eb_manipulation/tasks/``."""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from eb_core.env import Task

from eb_manipulation.spec import TASK_FORMAT, SceneSpec

__all__ = ["DEFAULT_TASK_FILE", "SUBSET_COUNTS", "load_task_file", "scene_of"]

DEFAULT_TASK_FILE = Path(__file__).parent / "tasks" / "manipulation_v2.json"
#: The paper's subset sizes (228 in total).
SUBSET_COUNTS = {"base": 48, "common_sense": 48, "complex": 48, "spatial": 48, "visual": 36}


class TaskFileError(ValueError):
    """A task file is missing, of another format, or has an invalid task (the message says which)."""


@lru_cache(maxsize=4)
def _load(path: str, mtime: float) -> tuple[Task, ...]:
    try:
        doc = json.loads(Path(path).read_text())
    except FileNotFoundError as exc:
        raise TaskFileError(f"task file not found: {path}") from exc
    if doc.get("format") != TASK_FORMAT:
        raise TaskFileError(f"{path}: task format {doc.get('format')!r}, this version reads {TASK_FORMAT}")
    tasks = []
    for raw in doc["tasks"]:
        try:
            SceneSpec.model_validate(raw["metadata"])
            tasks.append(Task(**raw))
        except Exception as exc:  # noqa: BLE001 - re-raised with the task id
            raise TaskFileError(f"{path}: invalid task {raw.get('id')!r}: {exc}") from exc
    return tuple(tasks)


def load_task_file(path: str | Path | None = None) -> list[Task]:
    """All tasks of a task file (default: the shipped one), in file order."""
    p = Path(path) if path is not None else DEFAULT_TASK_FILE
    return list(_load(str(p.resolve()), p.stat().st_mtime if p.exists() else 0.0))


def scene_of(task: Task) -> SceneSpec:
    """The validated scene spec stored in a task's metadata."""
    return SceneSpec.model_validate(task.metadata)
