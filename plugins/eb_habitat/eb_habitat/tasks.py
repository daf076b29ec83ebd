"""Versioned task files: schema, validation with one-line errors, and loading.

A task file (``eb_habitat/tasks/<subset>.json``) looks like::

    {"format": "eb-habitat-tasks", "version": 2, "subset": "base", "generator": {...},
     "tasks": [{"id": "base-00", "subset": "base", "instruction": "...",
                "metadata": {"apartment": 0, "template": "base.move",
                             "objects": [{"name": "apple_1", "type": "apple", "color": "red",
                                          "at": "left_counter", "slot": 0}, ...],
                             "open": ["left_drawer"],
                             "goal": ["(on ?apple sofa)"],
                             "subgoals": [["(holding ?apple)"], ["(on ?apple sofa)"]],
                             "oracle_steps": 4}}]}

Files are read and written through the core's :class:`eb_core.taskfile.TaskFileFormat` (:data:`FILE_FORMAT`): any
problem raises :class:`TaskFileError` with ONE line naming the file, the task and the field.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, SerializerFunctionWrapHandler, model_serializer

from eb_core.env import Task
from eb_core.taskfile import TaskFileError as _CoreTaskFileError
from eb_core.taskfile import TaskFileFormat
from eb_habitat.catalog import N_APARTMENTS, allowed_colors, capacity, object_type, receptacle
from eb_habitat.goals import GoalTracker, Predicate, PredicateError, parse_predicate
from eb_habitat.world import World

__all__ = [
    "FILE_FORMAT",
    "FORMAT",
    "SUBSETS",
    "TASKSETS",
    "TASK_DIR",
    "VERSION",
    "TaskFileError",
    "TaskSpec",
    "load_task_file",
    "load_tasks",
    "spec_of",
    "taskset_dir",
]

FORMAT = "eb-habitat-tasks"
VERSION = 2
"""Task-file version: 2 since the repaired templates (varied layouts, spatial relations to objects).
Version-1 files are refused with a one-line message that says to regenerate them."""
SUBSETS = ("base", "common_sense", "complex_instruction", "spatial_relationship", "visual_appearance", "long_horizon")
TASK_DIR = Path(__file__).parent / "tasks"
TASKSETS = ("classic", "hard")
"""Shipped task sets: ``tasks/*.json`` (classic) and ``tasks/hard/*.json`` (:mod:`eb_habitat.hard`, seed 0)."""


TaskFileError = _CoreTaskFileError
"""The core's one task-file error (kept importable from here)."""


class ObjectSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(pattern=r"^[a-z_]+_[0-9]+$")
    """Instance name: the type key and a number, e.g. ``mug_2``."""
    type: str
    color: str
    at: str
    """Receptacle key where it starts."""
    slot: int = Field(ge=0)
    """Position on that receptacle, 0 = leftmost."""
    handle: Literal["left", "right"] | None = None
    """Hard sets (version 6), mugs only: the side (as the agent faces the receptacle) the handle points to. None:
    the type's usual turn. Left out of the file and of dumps when None, so classic files and digests are unchanged."""

    @model_serializer(mode="wrap")
    def _drop_unset_handle(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        out = handler(self)
        if out.get("handle") is None:
            out.pop("handle", None)
        return out


class TaskSpec(BaseModel):
    """The ``metadata`` of one EB-Habitat task: the initial scene and the goal."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    apartment: int = Field(ge=0, lt=N_APARTMENTS)
    """Which apartment layout is rendered (the symbolic world is the same)."""
    template: str = Field(min_length=1)
    """The generator template that produced the instruction (for analysis)."""
    objects: list[ObjectSpec] = Field(min_length=1)
    open: list[str] = Field(default_factory=list)
    """Articulated receptacles that start open."""
    goal: list[str] = Field(min_length=1)
    """PDDL-style predicates that must all hold for success."""
    subgoals: list[list[str]] = Field(min_length=1)
    """Subgoal predicate sets for the progress metric (sticky)."""
    oracle_steps: int = Field(ge=1)
    """Length of the expert plan from the initial state (recorded by the generator)."""
    wide: bool = False
    """Hard sets (version 7): the long surfaces hold up to :data:`~eb_habitat.catalog.WIDE_CAPACITY` objects, closer
    together and in two depths. Left out of the file and of dumps when false (classic files and digests unchanged)."""

    @model_serializer(mode="wrap")
    def _drop_unset_wide(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        out = handler(self)
        if not out.get("wide"):
            out.pop("wide", None)
        return out

    def world(self) -> World:
        return World([o.model_dump() for o in self.objects], self.open, wide=self.wide)

    def instances(self) -> dict[str, str]:
        return {o.name: o.type for o in self.objects}

    def goal_predicates(self) -> list[Predicate]:
        inst = self.instances()
        return [parse_predicate(g, inst) for g in self.goal]

    def subgoal_predicates(self) -> list[list[Predicate]]:
        inst = self.instances()
        return [[parse_predicate(g, inst) for g in group] for group in self.subgoals]

    def tracker(self) -> GoalTracker:
        return GoalTracker(self.goal_predicates(), self.subgoal_predicates())


class _TaskEntry(BaseModel):
    model_config = ConfigDict(extra="forbid")

    id: str = Field(min_length=1, pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    subset: str
    instruction: str = Field(min_length=1)
    metadata: TaskSpec


def _semantic_problem(entry: _TaskEntry) -> tuple[str, str] | None:
    """(field, reason) for the first rule a schema-valid task breaks, or None."""
    spec = entry.metadata
    names: set[str] = set()
    slots: set[tuple[str, int]] = set()
    for i, o in enumerate(spec.objects):
        f = f"metadata.objects[{i}]"
        if o.name in names:
            return f + ".name", f"duplicate object name {o.name!r}"
        names.add(o.name)
        try:
            t = object_type(o.type)
        except KeyError as exc:
            return f + ".type", exc.args[0]
        if not o.name.startswith(o.type + "_") or not o.name[len(o.type) + 1:].isdigit():
            return f + ".name", f"{o.name!r} must be the type key and a number, e.g. '{o.type}_1'"
        if o.color not in allowed_colors(t.key):
            return f + ".color", f"{o.color!r} is not a colour of {t.name} (have {', '.join(allowed_colors(t.key))})"
        try:
            r = receptacle(o.at)
        except KeyError as exc:
            return f + ".at", exc.args[0]
        if o.handle is not None and (o.type != "mug" or r.kind != "surface"):
            return f + ".handle", f"only a mug on a surface has a handle's side, not a {t.name} at the {r.name}"
        cap = capacity(r.key, spec.wide)
        if o.slot >= cap:
            return f + ".slot", f"slot {o.slot} but the {r.name} has {cap} slot(s)"
        if (o.at, o.slot) in slots:
            return f + ".slot", f"slot {o.slot} of the {r.name} is taken twice"
        slots.add((o.at, o.slot))
    for i, key in enumerate(spec.open):
        try:
            r = receptacle(key)
        except KeyError as exc:
            return f"metadata.open[{i}]", exc.args[0]
        if not r.articulated:
            return f"metadata.open[{i}]", f"the {r.name} cannot be opened"
    inst = spec.instances()
    for i, g in enumerate(spec.goal):
        try:
            parse_predicate(g, inst)
        except PredicateError as exc:
            return f"metadata.goal[{i}]", str(exc)
    for i, group in enumerate(spec.subgoals):
        if not group:
            return f"metadata.subgoals[{i}]", "a subgoal set must hold at least one predicate"
        for j, g in enumerate(group):
            try:
                parse_predicate(g, inst)
            except PredicateError as exc:
                return f"metadata.subgoals[{i}][{j}]", str(exc)
    if spec.tracker().success(spec.world()):
        return "metadata.goal", "the goal already holds in the initial scene"
    return None


FILE_FORMAT: TaskFileFormat[_TaskEntry] = TaskFileFormat(
    "habitat", FORMAT, VERSION, _TaskEntry, check=lambda entry: _semantic_problem(entry), subsets=SUBSETS)
"""The core's envelope reader/writer for EB-Habitat task files (one-line errors, mtime cache, atomic write)."""


def _task(entry: _TaskEntry) -> Task:
    return Task(id=entry.id, subset=entry.subset, instruction=entry.instruction, metadata=entry.metadata.model_dump())


def load_task_file(path: str | Path) -> list[Task]:
    """Read and validate one task file. Raises :class:`TaskFileError` (one line) on any problem."""
    return [_task(e) for e in FILE_FORMAT.read(path)]


def taskset_dir(taskset: str = "classic") -> Path:
    """The folder of a shipped task set: ``tasks/`` for classic, ``tasks/<name>/`` for the others."""
    if taskset not in TASKSETS:
        raise ValueError(f"habitat: unknown taskset {taskset!r}; shipped sets are {', '.join(TASKSETS)}. "
                         f"Fix: taskset=classic or taskset=hard")
    return TASK_DIR if taskset == "classic" else TASK_DIR / taskset


def load_tasks(task_dir: str | Path | None = None, taskset: str = "classic") -> list[Task]:
    """All tasks of every ``*.json`` file in ``task_dir`` (a folder, or one file; default: the shipped folder of
    ``taskset``), subsets in paper order."""
    folder = Path(task_dir) if task_dir is not None else taskset_dir(taskset)
    if folder.is_file():
        return load_task_file(folder)
    files = sorted(folder.glob("*.json"), key=lambda p: (SUBSETS.index(p.stem) if p.stem in SUBSETS else 99, p.name))
    if not files:
        raise TaskFileError(f"{folder}: no task files (*.json); create them with `eb tasks generate env=habitat`")
    return [_task(e) for e in FILE_FORMAT.read_many(files)]


def spec_of(task: Task) -> TaskSpec:
    """The validated :class:`TaskSpec` behind a task's metadata."""
    return TaskSpec.model_validate(task.metadata)
