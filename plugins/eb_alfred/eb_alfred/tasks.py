"""Loading and validating the shipped task files (``eb_alfred/tasks/<subset>.json``).

Every file is checked against a pydantic schema and a few semantic rules (types exist, parents exist,
goal references name things in the scene). A malformed file fails with ONE line naming the file, the task
and the field, e.g. ``base.json: task base_07: field goal.receptacle.type: unknown type 'Fridgee'``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from eb_alfred.catalog import LAMPS, ROOMS, TYPES
from eb_alfred.goals import GOAL_KINDS

__all__ = ["SUBSETS", "TASK_DIR", "TaskFileError", "TaskRecord", "load_task_file", "load_all", "FORMAT", "VERSION"]

SUBSETS = ("base", "common_sense", "complex_instruction", "spatial_awareness", "visual_appearance", "long_horizon")
TASK_DIR = Path(__file__).parent / "tasks"
FORMAT = "eb-alfred-tasks"
VERSION = 2
"""2: shape words drawn, referring phrases checked, objects and relations visible, template ids."""


class TaskFileError(ValueError):
    """A task file is malformed; the message is one line naming file, task and field."""


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
        if (self.type is None) == (self.instance is None):
            raise ValueError("give exactly one of 'type' or 'instance'")
        base = self.type if self.type is not None else self.instance.split("_")[0]  # type: ignore[union-attr]
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
        out = {"type": self.type}
        for key in ("color", "shape"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        return out  # type: ignore[return-value]


class Goal(_Strict):
    kind: Literal[GOAL_KINDS]  # type: ignore[valid-type]
    object: Ref
    receptacle: Ref | None = None
    movable: Ref | None = None
    lamp: Ref | None = None
    sliced: bool = False
    also: list[Literal["clean", "hot", "cold"]] = []
    """Extra preparation of the object (long_horizon): washed, heated, chilled; not both hot and cold."""

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
    room: Literal[ROOMS]  # type: ignore[valid-type]
    objects: list[SceneObject] = Field(min_length=1)


class TaskRecord(_Strict):
    id: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    subset: Literal[SUBSETS]  # type: ignore[valid-type]
    instruction: str = Field(min_length=1)
    task_type: Literal[GOAL_KINDS]  # type: ignore[valid-type]
    goal: Goal
    scene: Scene
    scene_seed: int
    oracle_steps: int = Field(ge=1)
    notes: str = ""
    """How the instruction refers to things (e.g. which relation or colour), for readers of the file."""
    template: str = ""
    """Id of the instruction template (``<subset>.<kind>[.sliced].<n>``), so audits can count templates."""


class TaskFile(_Strict):
    format: Literal["eb-alfred-tasks"]
    version: Literal[2]
    subset: Literal[SUBSETS]  # type: ignore[valid-type]
    generator: dict[str, Any] = Field(default_factory=dict)
    tasks: list[TaskRecord]


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


def load_task_file(path: str | Path) -> list[TaskRecord]:
    """Read and validate one task file; raise :class:`TaskFileError` (one line) on the first problem."""
    path = Path(path)
    fname = path.name
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise TaskFileError(f"{path}: task file not found") from None
    except json.JSONDecodeError as exc:
        raise TaskFileError(f"{fname}: not valid JSON (line {exc.lineno}, column {exc.colno}): {exc.msg}") from None
    if isinstance(raw, dict) and "version" in raw and raw["version"] != VERSION:
        raise TaskFileError(f"{fname}: file version {raw['version']!r} but this eb-alfred reads version {VERSION}; "
                            f"regenerate it with `eb tasks generate env=alfred`")
    if isinstance(raw, dict) and isinstance(raw.get("tasks"), list):
        for i, t in enumerate(raw["tasks"]):
            tid = t.get("id", f"#{i}") if isinstance(t, dict) else f"#{i}"
            try:
                rec = TaskRecord.model_validate(t)
            except ValidationError as exc:
                err = exc.errors()[0]
                loc = ".".join(str(p) for p in err["loc"])
                raise TaskFileError(f"{fname}: task {tid}: field {loc}: {err['msg']}") from None
            problem = _semantic_problem(rec)
            if problem:
                raise TaskFileError(f"{fname}: task {tid}: field {problem[0]}: {problem[1]}")
    try:
        tf = TaskFile.model_validate(raw)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = ".".join(str(p) for p in err["loc"])
        raise TaskFileError(f"{fname}: field {loc}: {err['msg']}") from None
    for rec in tf.tasks:
        if rec.subset != tf.subset:
            raise TaskFileError(f"{fname}: task {rec.id}: field subset: {rec.subset!r} in a {tf.subset!r} file")
    return tf.tasks


def load_all(task_dir: str | Path | None = None) -> list[TaskRecord]:
    """All tasks in subset order (base first), each file validated."""
    root = Path(task_dir) if task_dir is not None else TASK_DIR
    out: list[TaskRecord] = []
    seen: set[str] = set()
    for subset in SUBSETS:
        recs = load_task_file(root / f"{subset}.json")
        for r in recs:
            if r.id in seen:
                raise TaskFileError(f"{subset}.json: task {r.id}: field id: duplicate task id")
            seen.add(r.id)
        out += recs
    return out
