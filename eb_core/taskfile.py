"""One task-file and split mechanism for every world.

A task file is a versioned JSON envelope::

    {"format": "eb-<world>-tasks", "version": N, "subset": "base" (optional), "generator": {...}, "tasks": [...]}

A world keeps only its task model (a pydantic model of one entry of ``tasks``) and its draw function; reading,
validating with one-line errors, caching by modification time, writing, and the generated ``train``/``val``
splits live here. Every problem raises :class:`TaskFileError` with ONE line naming the file, the task and the
field — never the file's contents.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterable, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any, Generic, TypeVar

import numpy as np
from pydantic import BaseModel, ValidationError

__all__ = [
    "SPLITS",
    "SplitSource",
    "TaskFileError",
    "TaskFileFormat",
    "split_rng",
    "task_set_digest",
]

SPLITS = ("train", "val")
"""The generated splits a world may serve besides ``test`` (its shipped tasks)."""

T = TypeVar("T", bound=BaseModel)


class TaskFileError(ValueError):
    """A task file is missing, unreadable, of another format or version, or holds an invalid task."""


def _field_error(exc: ValidationError) -> tuple[str, str]:
    """(dotted field, short reason) of the first pydantic error."""
    err = exc.errors()[0]
    field = ".".join(str(p) for p in err["loc"]) or "(the whole entry)"
    if err["type"] == "missing":
        reason = "is missing"
    elif err["type"] == "extra_forbidden":
        reason = "is not a known field"
    else:
        shown = repr(err.get("input"))
        reason = f"{err['msg']} (got {shown[:80]}{'...' if len(shown) > 80 else ''})"
    return field, reason


class TaskFileFormat(Generic[T]):
    """How one world's task files look: the envelope's ``format`` and ``version`` and the model of one task.

    ``check`` (optional) returns ``(field, reason)`` for a semantic rule a valid-looking task breaks, or None.
    ``subsets`` (optional) restricts ``subset`` fields to known names.
    """

    def __init__(self, world: str, fmt: str, version: int, task_model: type[T], *,
                 check: Callable[[T], tuple[str, str] | None] | None = None,
                 subsets: Sequence[str] | None = None) -> None:
        self.world, self.format, self.version, self.task_model = world, fmt, version, task_model
        self.check, self.subsets = check, tuple(subsets) if subsets is not None else None
        self._cached = lru_cache(maxsize=16)(self._read_uncached)

    # ------------------------------------------------------------------ reading
    def read(self, path: str | Path) -> tuple[T, ...]:
        """The validated tasks of one file, cached by (path, modification time): a file edited on disk is read
        again, an unchanged one is not. Callers must not mutate the returned models."""
        p = Path(path).expanduser()
        if not p.is_file():
            raise TaskFileError(f"{p}: task file not found. Fix: give an existing file (or folder) written by "
                                f"`eb tasks generate env={self.world} out=...`")
        return self._cached(str(p.resolve()), p.stat().st_mtime_ns)

    def read_many(self, paths: Iterable[str | Path]) -> list[T]:
        """Tasks of several files in order; a task id defined twice is an error naming both files."""
        out: list[T] = []
        where: dict[str, Path] = {}
        for path in paths:
            for task in self.read(path):
                tid = str(getattr(task, "id"))
                if tid in where:
                    raise TaskFileError(f"{Path(path)}: task {tid!r}: field id: duplicate task id (also in "
                                        f"{where[tid]}). Fix: give every task its own id")
                where[tid] = Path(path)
                out.append(task)
        return out

    def _read_uncached(self, path_str: str, _mtime: int) -> tuple[T, ...]:
        path = Path(path_str)
        try:
            raw = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise TaskFileError(f"{path}: cannot read the task file: {exc.strerror or exc}") from None
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            detail = f"{exc.msg} at line {exc.lineno} column {exc.colno}" if isinstance(exc, json.JSONDecodeError) \
                else str(exc)
            raise TaskFileError(f"{path}: not valid JSON: {detail}") from None
        return tuple(self.parse(raw, path))

    def parse(self, raw: Any, path: str | Path = "<task file>") -> list[T]:
        """Validate an already decoded envelope (what :meth:`read` does after JSON decoding)."""
        if not isinstance(raw, dict):
            raise TaskFileError(f"{path}: field (top level): must be a JSON object with format, version and tasks")
        if raw.get("format") != self.format:
            raise TaskFileError(f"{path}: field format: {raw.get('format')!r} is not {self.format!r}. Fix: give "
                                f"an eb-{self.world} task file")
        if "version" not in raw:
            raise TaskFileError(f"{path}: field version: is missing; this eb-{self.world} reads version "
                                f"{self.version}. Fix: regenerate it with `eb tasks generate env={self.world}`")
        if raw.get("version") != self.version:
            raise TaskFileError(f"{path}: field version: the file is version {raw.get('version')!r} but this "
                                f"eb-{self.world} reads version {self.version}. Fix: regenerate it with "
                                f"`eb tasks generate env={self.world}`")
        entries = raw.get("tasks")
        if not isinstance(entries, list):
            raise TaskFileError(f"{path}: field tasks: must be a list of tasks")
        file_subset = raw.get("subset")
        tasks: list[T] = []
        seen: set[str] = set()
        for i, entry in enumerate(entries):
            tid = entry.get("id") if isinstance(entry, dict) else None
            where = f"task {tid!r}" if tid is not None else f"task #{i}"
            try:
                task = self.task_model.model_validate(entry)
            except ValidationError as exc:
                field, reason = _field_error(exc)
                raise TaskFileError(f"{path}: {where}: field {field}: {reason}") from None
            problem = self.check(task) if self.check is not None else None
            if problem is not None:
                raise TaskFileError(f"{path}: {where}: field {problem[0]}: {problem[1]}")
            subset = getattr(task, "subset", None)
            if file_subset is not None and subset is not None and subset != file_subset:
                raise TaskFileError(f"{path}: {where}: field subset: {subset!r} in a {file_subset!r} file")
            if self.subsets is not None and subset is not None and subset not in self.subsets:
                raise TaskFileError(f"{path}: {where}: field subset: unknown subset {subset!r}; allowed: "
                                    f"{', '.join(self.subsets)}")
            if str(tid) in seen:
                raise TaskFileError(f"{path}: {where}: field id: duplicate task id. Fix: give every task its own id")
            seen.add(str(tid))
            tasks.append(task)
        return tasks

    # ------------------------------------------------------------------ writing
    def envelope(self, tasks: Iterable[BaseModel | dict[str, Any]], *, generator: dict[str, Any] | None = None,
                 subset: str | None = None) -> dict[str, Any]:
        """The JSON document of a task file (validated before it is returned)."""
        entries = [t.model_dump(mode="json") if isinstance(t, BaseModel) else dict(t) for t in tasks]
        doc: dict[str, Any] = {"format": self.format, "version": self.version}
        if subset is not None:
            doc["subset"] = subset
        doc["generator"] = dict(generator or {})
        doc["tasks"] = entries
        self.parse(doc, f"<new {self.world} task file>")
        return doc

    def write(self, path: str | Path, tasks: Iterable[BaseModel | dict[str, Any]], *,
              generator: dict[str, Any] | None = None, subset: str | None = None) -> Path:
        """Write a task file atomically (a temporary file renamed into place); returns its path."""
        p = Path(path).expanduser()
        doc = self.envelope(tasks, generator=generator, subset=subset)
        p.parent.mkdir(parents=True, exist_ok=True)
        tmp = p.with_name(p.name + ".tmp")
        tmp.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
        tmp.replace(p)
        return p


# ---------------------------------------------------------------------- splits
def split_rng(world: str, split: str, index: int) -> np.random.Generator:
    """The random stream of task ``index`` of a generated split: fixed by ``(world, split, index)`` alone."""
    digest = hashlib.sha256(f"{world}:{split}:{index}".encode()).digest()
    return np.random.default_rng(int.from_bytes(digest[:16], "big"))


class SplitSource(Generic[T]):
    """Serves tasks ``start .. start + count - 1`` of a world's generated ``train``/``val`` splits.

    ``draw(split, index, **context)`` makes task ``index`` (deterministically, e.g. from :func:`split_rng`);
    ``context`` is whatever the draw needs to stay disjoint from the test tasks (their rooms, instructions) and must
    be hashable. The last ``memo`` tasks made in this process are kept: a reset of the same task, a group of
    rollouts from one task or ``options={"task_id": ...}`` is a look-up. Callers get deep copies.
    """

    def __init__(self, world: str, draw: Callable[..., T], *, splits: Sequence[str] = SPLITS, memo: int = 512) -> None:
        self.world, self.splits = world, tuple(splits)
        self._draw = lru_cache(maxsize=memo)(draw)

    def check(self, split: str, start: int, count: int) -> None:
        if split not in self.splits:
            raise ValueError(f"{self.world}: unknown split {split!r}; generated splits are {', '.join(self.splits)} "
                             f"('test' is the shipped task set). Fix: split=test or one of those")
        if start < 0 or count < 0:
            raise ValueError(f"{self.world}: split tasks need start >= 0 and count >= 0, got start={start}, "
                             f"count={count}")

    def tasks(self, split: str, start: int, count: int, **context: Any) -> list[T]:
        self.check(split, start, count)
        return [self._draw(split, i, **context).model_copy(deep=True) for i in range(start, start + count)]


# ---------------------------------------------------------------------- digests
def task_set_digest(tasks: Iterable[BaseModel]) -> str:
    """SHA-256 of the tasks' canonical JSON (ids, instructions, scenes): two task sets with the same digest are the
    same tasks in the same order. ``eb verify`` compares a run's digest with the installed set's."""
    h = hashlib.sha256()
    for task in tasks:
        h.update(json.dumps(task.model_dump(mode="json"), sort_keys=True, separators=(",", ":")).encode())
        h.update(b"\n")
    return h.hexdigest()
