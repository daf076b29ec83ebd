"""The task model and the shipped task sets (``eb_alfred/tasks/<subset>.json``, ``tasks/hard/<subset>.json``).

Files are read and written through the core's :class:`eb_core.taskfile.TaskFileFormat`: every task is checked
against the pydantic schema below and a few semantic rules (types exist, parents exist, goal references name
things in the scene). A malformed file fails with ONE line naming the file, the task and the field, e.g.
``base.json: task 'base_07': field goal.receptacle.type: unknown type 'Fridgee'``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, model_validator

from eb_core.taskfile import TaskFileError as _CoreTaskFileError
from eb_core.taskfile import TaskFileFormat

from eb_alfred.catalog import LAMPS, TYPES, Room
from eb_alfred.goals import GoalKind

__all__ = ["SUBSETS", "TASK_DIR", "TASKSETS", "TaskFileError", "TaskRecord", "load_task_file", "load_all", "FORMAT",
           "VERSION", "FILE_FORMAT", "taskset_dir"]

Subset = Literal["base", "common_sense", "complex_instruction", "spatial_awareness", "visual_appearance",
                 "long_horizon"]
SUBSETS: tuple[Subset, ...] = get_args(Subset)
TASK_DIR = Path(__file__).parent / "tasks"
FORMAT = "eb-alfred-tasks"
VERSION = 2
"""2: shape words drawn, referring phrases checked, objects and relations visible, template ids."""
TASKSETS = ("classic", "hard")
"""Shipped task sets: ``classic`` (the paper's protocol, ``tasks/``) and ``hard`` (``tasks/hard/``)."""


TaskFileError = _CoreTaskFileError
"""The core's one task-file error (kept importable from here)."""

class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Ref(_Strict):
    type: str | None = None
    instance: str | None = None
    color: str | None = None
    """With ``type``: only instances of this colour count (visual_appearance)."""
    shape: str | None = None

    @model_validator(mode="after")
    def _one(self) -> Ref:
        if self.type is not None and self.instance is not None:
            raise ValueError("give exactly one of 'type' or 'instance'")
        if self.type is not None:
            base = self.type
        elif self.instance is not None:
            base = self.instance.split("_")[0]
        else:
            raise ValueError("give exactly one of 'type' or 'instance'")
        if base not in TYPES:
            raise ValueError(f"unknown type {base!r}")
        if (self.color or self.shape) and self.type is None:
            raise ValueError("color/shape only go with 'type'")
        if self.color is not None and self.color not in TYPES[base].colors:
            raise ValueError(f"{base} has no colour {self.color!r}")
        if self.shape is not None and self.shape not in TYPES[base].shapes:
            raise ValueError(f"{base} has no shape {self.shape!r}")
        return self

    def plain(self) -> dict[str, str]:
        if self.instance is not None:
            return {"instance": self.instance}
        out = {"type": str(self.type)}  # a Ref without an instance has a type (checked by _one)
        for key in ("color", "shape"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        return out


class Goal(_Strict):
    kind: GoalKind
    object: Ref
    receptacle: Ref | None = None
    movable: Ref | None = None
    lamp: Ref | None = None
    sliced: bool = False
    also: list[Literal["clean", "hot", "cold"]] = []
    """Extra preparation of the object (long_horizon): washed, heated, chilled; not both hot and cold."""
    untouched: list[Literal["object", "receptacle", "movable"]] = []
    """Hard set: roles whose look-alikes (other instances of the role's type) must never be handled."""

    @model_validator(mode="after")
    def _fields_for_kind(self) -> Goal:
        own = {"heat_and_place": "hot", "cool_and_place": "cold", "clean_and_place": "clean"}.get(self.kind)
        if {"hot", "cold"} <= {*self.also, own}:
            raise ValueError("also cannot ask for both 'hot' and 'cold' (chilling undoes heating)")
        if len(set(self.also)) != len(self.also):
            raise ValueError("also lists a property twice")
        need = {"examine_in_light": ("lamp",), "stack_and_place": ("movable", "receptacle")}.get(
            self.kind, ("receptacle",))
        for key in need:
            if getattr(self, key) is None:
                raise ValueError(f"{key} is required for {self.kind}")
        for role in self.untouched:
            if getattr(self, role) is None:
                raise ValueError(f"untouched names {role!r}, which this goal does not have")
        if self.lamp is not None:
            lamp_type = self.lamp.type or (self.lamp.instance or "").split("_")[0]
            if lamp_type not in LAMPS:
                raise ValueError(f"lamp must be one of {', '.join(LAMPS)}")
        return self

    def plain(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": self.kind, "object": self.object.plain()}
        for key in ("receptacle", "movable", "lamp"):
            ref = getattr(self, key)
            if ref is not None:
                out[key] = ref.plain()
        if self.sliced:
            out["sliced"] = True
        if self.also:
            out["also"] = list(self.also)
        if self.untouched:
            out["untouched"] = list(self.untouched)
        return out


class SceneObject(_Strict):
    name: str = Field(pattern=r"^[A-Za-z]+(_[0-9]+)?$")
    type: str
    parent: str | None = None
    slot: int | None = None
    is_open: bool = False
    is_on: bool = False
    is_sliced: bool = False
    is_dirty: bool = False
    is_hot: bool = False
    is_cold: bool = False
    color: str | None = None
    shape: str | None = None


class Scene(_Strict):
    room: Room
    objects: list[SceneObject] = Field(min_length=1)


class TaskRecord(_Strict):
    id: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    subset: Subset
    instruction: str = Field(min_length=1)
    task_type: GoalKind
    goal: Goal
    scene: Scene
    scene_seed: int
    oracle_steps: int = Field(ge=1)
    notes: str = ""
    """How the instruction refers to things (e.g. which relation or colour), for readers of the file."""
    template: str = ""
    """Id of the instruction template (``<subset>.<kind>[.sliced].<n>``), so audits can count templates."""


def _semantic_problem(rec: TaskRecord) -> tuple[str, str] | None:
    """(field, reason) for the first rule the task breaks, or None."""
    names: dict[str, str] = {}
    for i, o in enumerate(rec.scene.objects):
        if o.type not in TYPES:
            return f"scene.objects.{i}.type", f"unknown type {o.type!r}"
        if o.name.split("_")[0] != o.type:
            return f"scene.objects.{i}.name", f"{o.name!r} does not match its type {o.type!r}"
        if o.name in names:
            return f"scene.objects.{i}.name", f"duplicate instance {o.name!r}"
        names[o.name] = o.type
    for i, o in enumerate(rec.scene.objects):
        if o.parent is not None:
            if o.parent not in names:
                return f"scene.objects.{i}.parent", f"unknown parent {o.parent!r}"
            if not TYPES[names[o.parent]].receptacle:
                return f"scene.objects.{i}.parent", f"{o.parent!r} is not a receptacle"
        elif o.slot is None:
            return f"scene.objects.{i}.slot", "furniture standing in the room needs a slot"
    goal = rec.goal
    if goal.kind != rec.task_type:
        return "task_type", f"{rec.task_type!r} differs from goal.kind {goal.kind!r}"
    for key in ("object", "receptacle", "movable", "lamp"):
        ref = getattr(goal, key)
        if ref is None:
            continue
        if ref.instance is not None and ref.instance not in names:
            return f"goal.{key}.instance", f"{ref.instance!r} is not in the scene"
        if ref.type is not None and ref.type not in names.values():
            return f"goal.{key}.type", f"no {ref.type!r} in the scene"
    return None


FILE_FORMAT: TaskFileFormat[TaskRecord] = TaskFileFormat(
    "alfred", FORMAT, VERSION, TaskRecord, check=lambda rec: _semantic_problem(rec), subsets=SUBSETS)
"""The core's envelope reader/writer for EB-ALFRED task files (one-line errors, mtime cache, atomic write)."""


def taskset_dir(taskset: str = "classic") -> Path:
    """The folder of a shipped task set: ``tasks/`` for classic, ``tasks/<name>/`` for the others."""
    if taskset not in TASKSETS:
        raise ValueError(f"alfred: unknown taskset {taskset!r}; shipped sets are {', '.join(TASKSETS)}. "
                         f"Fix: taskset=classic or taskset=hard")
    return TASK_DIR if taskset == "classic" else TASK_DIR / taskset


def load_task_file(path: str | Path) -> list[TaskRecord]:
    """Read and validate one task file; raise :class:`TaskFileError` (one line) on the first problem."""
    return list(FILE_FORMAT.read(path))


def load_all(task_dir: str | Path | None = None, taskset: str = "classic") -> list[TaskRecord]:
    """All tasks in subset order (base first), each file validated. ``task_dir`` (a folder of per-subset files)
    overrides the shipped folder of ``taskset``."""
    root = Path(task_dir) if task_dir is not None else taskset_dir(taskset)
    return FILE_FORMAT.read_many(root / f"{subset}.json" for subset in SUBSETS)
