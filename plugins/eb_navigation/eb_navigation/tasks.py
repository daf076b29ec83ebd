"""The navigation task file: schema, loading and one-line validation errors.

A task file is JSON written by :mod:`eb_navigation.generate`::

    {"format": "eb-navigation-tasks", "version": 3,
     "generator": {...the parameters it was made with...},
     "tasks": [{"id": "base_000", "subset": "base", "instruction": "...", "template": "base.03",
                "scene": {"kind": "kitchen", "seed": 3},
                "start": {"x": 1.25, "y": -0.5, "yaw": 90, "tilt": 0},
                "target": {"id": "Fridge_1", "type": "Fridge", "colour": "white", "position": [x, y, z]},
                "extra_objects": [...], "oracle_steps": 9}, ...]}

Rooms are the scene kit's ``generate_room(kind, seed)`` (centred on the origin); types and colours are the kit
catalogue's names.

Reading, validating (ONE error line naming the file, the task and the field), caching and writing are the core's
:mod:`eb_core.taskfile` (:data:`FORMAT`); this module keeps the task model and the per-subset folder layout.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_serializer, model_validator

from eb_core import Task
from eb_core.taskfile import TaskFileError as _CoreTaskFileError
from eb_core.taskfile import TaskFileFormat
from eb_scenekit.objects import CATALOGUE

from eb_navigation.geometry import STEP
from eb_navigation.room import CLUTTER, KINDS, ExtraSpec

__all__ = ["DEFAULT_TASK_FILE", "FORMAT", "HARD_DIR", "SUBSETS", "TASKSETS", "TASK_FILE_FORMAT", "TASK_FILE_VERSION",
           "TaskFileError", "NavTaskSpec", "load_task_file", "load_taskset", "spec_of", "task_file_path",
           "write_subset_files"]

TASK_FILE_FORMAT = "eb-navigation-tasks"
SUBSETS: tuple[str, ...] = ("base", "common_sense", "complex_instruction", "visual_appearance", "long_horizon")
TASK_FILE_VERSION = 3
DEFAULT_TASK_FILE = Path(__file__).parent / "tasks" / f"navigation_v{TASK_FILE_VERSION}.json"


TaskFileError = _CoreTaskFileError
"""The one task-file error of the project (:class:`eb_core.taskfile.TaskFileError`): one line naming file, task and
field."""

TASKSETS: tuple[str, ...] = ("classic", "hard")
"""The shipped task sets: ``classic`` (the paper's protocol, one file) and ``hard`` (one file per subset)."""
HARD_DIR = Path(__file__).parent / "tasks" / "hard"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SceneRef(_Strict):
    kind: Literal["kitchen", "living_room", "bedroom", "bathroom"]
    seed: int = Field(ge=0)
    clutter: int = Field(default=CLUTTER, ge=0, le=60)
    """Small objects the kit puts on the furniture; left out of the file when it is the classic
    :data:`~eb_navigation.room.CLUTTER` (so the classic file and its tasks read and dump exactly as before)."""

    @model_serializer(mode="wrap")
    def _omit_classic_clutter(self, handler: Any) -> dict[str, Any]:
        out = handler(self)
        if out.get("clutter") == CLUTTER:
            out.pop("clutter")
        return out


class StartPose(_Strict):
    x: float
    y: float
    yaw: int
    """Heading in degrees counter-clockwise from +x: 0, 90, 180 or 270."""
    tilt: int = 0

    @field_validator("x", "y")
    @classmethod
    def _on_grid(cls, v: float) -> float:
        if abs(round(v / STEP) * STEP - v) > 1e-6:
            raise ValueError(f"must be a multiple of {STEP} m (the agent moves on a {STEP} m grid)")
        return v

    @field_validator("yaw")
    @classmethod
    def _quarter(cls, v: int) -> int:
        if v not in (0, 90, 180, 270):
            raise ValueError("must be 0, 90, 180 or 270")
        return v

    @field_validator("tilt")
    @classmethod
    def _tilt(cls, v: int) -> int:
        if v not in (-60, -30, 0, 30):
            raise ValueError("must be -60, -30, 0 or 30")
        return v


def _check_type_and_colour(type_name: str, colour: str) -> None:
    if type_name not in CATALOGUE:
        raise ValueError(f"unknown object type {type_name!r} (not in the scene kit's catalogue)")
    if colour not in CATALOGUE[type_name].colors:
        raise ValueError(f"{type_name} has no colour {colour!r}; available: {', '.join(CATALOGUE[type_name].colors)}")


class _KitObject(_Strict):
    """A scene-kit object type with one of its colours (both checked against the kit's catalogue)."""

    type: str
    """Scene kit type, e.g. ``Fridge``."""
    colour: str

    @field_validator("type")
    @classmethod
    def _known_type(cls, v: str) -> str:
        if v not in CATALOGUE:
            raise ValueError(f"unknown object type {v!r} (not in the scene kit's catalogue)")
        return v

    @model_validator(mode="after")
    def _colour(self) -> "_KitObject":
        _check_type_and_colour(self.type, self.colour)
        return self


class TargetRef(_KitObject):
    id: str = Field(min_length=1)
    """Instance name in the room, e.g. ``Fridge_1``."""
    position: tuple[float, float, float]
    """Centre of the object (metres, room frame)."""


class ExtraObject(_KitObject):
    """An object added to the generated room for this task (visual-appearance distractors), on the floor."""

    id: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_]+$")
    x: float
    y: float
    yaw: float = 0.0
    """Degrees; the object's front faces its local +x (the kit's convention)."""

    def spec(self) -> ExtraSpec:
        return ExtraSpec(self.id, self.type, self.colour, self.x, self.y, self.yaw)


class NavTaskSpec(_Strict):
    """One task as stored in the file."""

    id: str = Field(min_length=1, pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    subset: Literal["base", "common_sense", "complex_instruction", "visual_appearance", "long_horizon"]
    instruction: str = Field(min_length=1)
    template: str = Field(pattern=r"^[a-z_]+\.[0-9]{2}$")
    """Id of the instruction template the generator used (``<subset>.<index>``, :mod:`eb_navigation.instructions`)."""
    scene: SceneRef
    start: StartPose
    target: TargetRef
    extra_objects: tuple[ExtraObject, ...] = ()
    oracle_steps: int = Field(ge=0)
    """Length of the oracle's shortest plan from the start (recorded by the generator)."""

    def to_task(self) -> Task:
        meta = self.model_dump(mode="json", exclude={"id", "subset", "instruction"})
        return Task(id=self.id, subset=self.subset, instruction=self.instruction, metadata=meta)


@dataclass(frozen=True)
class TaskFile:
    """A single-file task set (the classic file, a generated file or split): its validated tasks, read through the
    core's :data:`FORMAT`, and the envelope's ``format``, ``version`` and ``generator`` parameters."""

    path: Path
    tasks: tuple[NavTaskSpec, ...]

    @property
    def format(self) -> str:
        return str(self._head()["format"])

    @property
    def version(self) -> int:
        return int(self._head()["version"])

    @property
    def generator(self) -> dict[str, Any]:
        """The parameters the file was made with (its envelope's ``generator`` block)."""
        gen = self._head().get("generator")
        return dict(gen) if isinstance(gen, dict) else {}

    def _head(self) -> dict[str, Any]:
        return _envelope_head(str(self.path), self.path.stat().st_mtime_ns)


@lru_cache(maxsize=8)
def _envelope_head(path_str: str, _mtime_ns: int) -> dict[str, Any]:
    """The envelope of a file the core has validated, without its tasks (cached by modification time)."""
    raw = json.loads(Path(path_str).read_text(encoding="utf-8"))
    return {k: v for k, v in raw.items() if k != "tasks"}


def task_file_path(task_file: str | Path | None) -> Path:
    return DEFAULT_TASK_FILE if task_file is None else Path(task_file).expanduser()


def load_task_file(task_file: str | Path | None = None) -> TaskFile:
    """The tasks of one task file (default: the shipped classic file), validated by the core's
    :class:`~eb_core.taskfile.TaskFileFormat` (one-line :class:`TaskFileError` naming file, task and field; cached
    by modification time)."""
    path = task_file_path(task_file)
    return TaskFile(path, FORMAT.read(path))


def spec_of(task: Task) -> NavTaskSpec:
    """Rebuild the typed spec from a :class:`~eb_core.Task` (what the runner hands to ``reset``)."""
    try:
        return NavTaskSpec.model_validate({"id": task.id, "subset": task.subset, "instruction": task.instruction,
                                           **task.metadata})
    except ValidationError as exc:
        err = exc.errors()[0]
        field = ".".join(str(p) for p in err["loc"])
        raise TaskFileError(f"task {task.id!r}: field {field}: {err['msg']}") from None


FORMAT: TaskFileFormat[NavTaskSpec] = TaskFileFormat("navigation", TASK_FILE_FORMAT, TASK_FILE_VERSION, NavTaskSpec,
                                                     subsets=SUBSETS)
"""The core's task-file mechanism for navigation's per-subset files (the hard set, generated levels)."""


def _subset_files(folder: Path) -> list[Path]:
    files = [folder / f"{s}.json" for s in SUBSETS if (folder / f"{s}.json").is_file()]
    if not files:
        raise TaskFileError(f"{folder}: no task files (expected {', '.join(s + '.json' for s in SUBSETS)}). Fix: "
                            f"give a folder written by `eb tasks generate env=navigation difficulty=hard out=...`")
    return files


def load_taskset(taskset: str = "classic", task_file: str | Path | None = None) -> list[NavTaskSpec]:
    """The tasks of a shipped set, or of ``task_file``: a classic file, or a folder of per-subset files."""
    if taskset not in TASKSETS:
        raise ValueError(f"navigation: unknown taskset {taskset!r}; available: {', '.join(TASKSETS)}. Fix: "
                         f"taskset=classic or taskset=hard")
    if task_file is not None and Path(task_file).expanduser().is_dir():
        return FORMAT.read_many(_subset_files(Path(task_file).expanduser()))
    if taskset == "hard" and task_file is None:
        return FORMAT.read_many(_subset_files(HARD_DIR))
    return list(load_task_file(task_file).tasks)


def write_subset_files(folder: Path, tasks: list[dict[str, Any]], generator: dict[str, Any]) -> list[Path]:
    """Write ``<folder>/<subset>.json`` per subset (core envelope, atomically); returns the paths."""
    out = []
    for s in SUBSETS:
        mine = [t for t in tasks if t["subset"] == s]
        if mine:
            out.append(FORMAT.write(Path(folder) / f"{s}.json", mine, generator=generator, subset=s))
    return out


assert set(KINDS) == {"kitchen", "living_room", "bedroom", "bathroom"}
