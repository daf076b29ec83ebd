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

Any problem raises :class:`TaskFileError` with ONE line naming the file, the task and the field.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from eb_core.env import Task
from eb_habitat.catalog import N_APARTMENTS, object_type, receptacle
from eb_habitat.goals import GoalTracker, Predicate, PredicateError, parse_predicate
from eb_habitat.world import World

__all__ = [
    "FORMAT",
    "SUBSETS",
    "TASK_DIR",
    "VERSION",
    "TaskFileError",
    "TaskSpec",
    "load_task_file",
    "load_tasks",
    "spec_of",
]

FORMAT = "eb-habitat-tasks"
VERSION = 2
"""Task-file version: 2 since the repaired templates (varied layouts, spatial relations to objects).
Version-1 files are refused with a one-line message that says to regenerate them."""
SUBSETS = ("base", "common_sense", "complex_instruction", "spatial_relationship", "visual_appearance", "long_horizon")
TASK_DIR = Path(__file__).parent / "tasks"


class TaskFileError(ValueError):
    """A task file is malformed; the message is one line: file, task, field, reason."""


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

    def world(self) -> World:
        return World([o.model_dump() for o in self.objects], self.open)

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


class _TaskFile(BaseModel):
    model_config = ConfigDict(extra="forbid")

    format: Literal["eb-habitat-tasks"]
    version: Literal[2]
    subset: str
    generator: dict[str, Any] = Field(default_factory=dict)
    tasks: list[_TaskEntry] = Field(min_length=1)


def _fail(path: Path, task: str, field: str, reason: str) -> TaskFileError:
    return TaskFileError(f"{path}: task {task}: field '{field}': {reason}")


def _semantic_check(path: Path, entry: _TaskEntry, file_subset: str) -> None:
    tid, spec = entry.id, entry.metadata

    def fail(field: str, reason: str) -> TaskFileError:
        return _fail(path, tid, field, reason)

    if entry.subset != file_subset:
        raise fail("subset", f"{entry.subset!r} differs from the file's subset {file_subset!r}")
    names: set[str] = set()
    slots: set[tuple[str, int]] = set()
    for i, o in enumerate(spec.objects):
        f = f"metadata.objects[{i}]"
        if o.name in names:
            raise fail(f + ".name", f"duplicate object name {o.name!r}")
        names.add(o.name)
        try:
            t = object_type(o.type)
        except KeyError as exc:
            raise fail(f + ".type", exc.args[0]) from None
        if not o.name.startswith(o.type + "_") or not o.name[len(o.type) + 1:].isdigit():
            raise fail(f + ".name", f"{o.name!r} must be the type key and a number, e.g. '{o.type}_1'")
        if o.color not in t.colors:
            raise fail(f + ".color", f"{o.color!r} is not a colour of {t.name} (have {', '.join(t.colors)})")
        try:
            r = receptacle(o.at)
        except KeyError as exc:
            raise fail(f + ".at", exc.args[0]) from None
        if o.slot >= r.capacity:
            raise fail(f + ".slot", f"slot {o.slot} but the {r.name} has {r.capacity} slot(s)")
        if (o.at, o.slot) in slots:
            raise fail(f + ".slot", f"slot {o.slot} of the {r.name} is taken twice")
        slots.add((o.at, o.slot))
    for i, key in enumerate(spec.open):
        try:
            r = receptacle(key)
        except KeyError as exc:
            raise fail(f"metadata.open[{i}]", exc.args[0]) from None
        if not r.articulated:
            raise fail(f"metadata.open[{i}]", f"the {r.name} cannot be opened")
    inst = spec.instances()
    for i, g in enumerate(spec.goal):
        try:
            parse_predicate(g, inst)
        except PredicateError as exc:
            raise fail(f"metadata.goal[{i}]", str(exc)) from None
    for i, group in enumerate(spec.subgoals):
        if not group:
            raise fail(f"metadata.subgoals[{i}]", "a subgoal set must hold at least one predicate")
        for j, g in enumerate(group):
            try:
                parse_predicate(g, inst)
            except PredicateError as exc:
                raise fail(f"metadata.subgoals[{i}][{j}]", str(exc)) from None
    if spec.tracker().success(spec.world()):
        raise fail("metadata.goal", "the goal already holds in the initial scene")


def load_task_file(path: str | Path) -> list[Task]:
    """Read and validate one task file. Raises :class:`TaskFileError` (one line) on any problem."""
    path = Path(path)
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise TaskFileError(f"{path}: cannot read the task file: {exc.strerror or exc}") from None
    except json.JSONDecodeError as exc:
        raise TaskFileError(f"{path}: not valid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}") from None
    if isinstance(raw, dict) and raw.get("format") == FORMAT and raw.get("version") not in (None, VERSION):
        raise TaskFileError(f"{path}: task file version {raw.get('version')!r} is not supported; this eb-habitat "
                            f"reads version {VERSION}. Regenerate it with `eb tasks generate env=habitat`.")
    try:
        data = _TaskFile.model_validate(raw)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = list(err["loc"])
        task = "-"
        if len(loc) >= 2 and loc[0] == "tasks" and isinstance(loc[1], int):
            try:
                task = str(raw["tasks"][loc[1]].get("id", f"#{loc[1]}"))
            except (AttributeError, IndexError, KeyError, TypeError):
                task = f"#{loc[1]}"
            loc = loc[2:]
        field = "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if i else str(p)) for i, p in enumerate(loc))
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown field (check its spelling)"
        raise _fail(path, task, field or "(file)", f"{msg} (got {str(err.get('input'))[:60]!r})"
                    if err["type"] != "missing" else msg) from None
    if data.subset not in SUBSETS:
        raise _fail(path, "-", "subset", f"unknown subset {data.subset!r}; known: {', '.join(SUBSETS)}")
    seen: set[str] = set()
    tasks: list[Task] = []
    for entry in data.tasks:
        if entry.id in seen:
            raise _fail(path, entry.id, "id", "duplicate task id")
        seen.add(entry.id)
        _semantic_check(path, entry, data.subset)
        tasks.append(Task(id=entry.id, subset=entry.subset, instruction=entry.instruction,
                          metadata=entry.metadata.model_dump()))
    return tasks


def load_tasks(task_dir: str | Path | None = None) -> list[Task]:
    """All tasks of every ``*.json`` file in ``task_dir`` (default: the shipped ones), subsets in paper order."""
    folder = Path(task_dir) if task_dir is not None else TASK_DIR
    files = sorted(folder.glob("*.json"), key=lambda p: (SUBSETS.index(p.stem) if p.stem in SUBSETS else 99, p.name))
    if not files:
        raise TaskFileError(f"{folder}: no task files (*.json); create them with `eb tasks generate env=habitat`")
    tasks: list[Task] = []
    ids: dict[str, Path] = {}
    for f in files:
        for t in load_task_file(f):
            if t.id in ids:
                raise TaskFileError(f"{f}: task {t.id}: field 'id': also defined in {ids[t.id]}")
            ids[t.id] = f
            tasks.append(t)
    return tasks


def spec_of(task: Task) -> TaskSpec:
    """The validated :class:`TaskSpec` behind a task's metadata."""
    return TaskSpec.model_validate(task.metadata)
