"""Typed scene and goal specs stored in task files (``Task.metadata``) and read by the world."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from eb_manipulation.shapes import COLOURS, SHAPES

__all__ = ["DIRECTIONS", "FAMILIES", "FIT_TOLERANCE", "FLUSH_TOLERANCE", "GoalSpec", "ObjectSpec", "SceneSpec",
           "TASK_FORMAT"]

#: Version of the task-file format; bump when the meaning of a field changes.
TASK_FORMAT = 2

FAMILIES = ("pick", "stack", "sorter", "wipe")
#: Original VLMBench task ids per family (the spatial subset uses the ``_relative`` variants).
VARIANTS = {
    "pick": "pick_cube_shape",
    "stack": "stack_cubes_color",
    "sorter": "place_into_shape_sorter_color",
    "wipe": "wipe_table_direction",
}
#: Steps of the 15 a hard task leaves beyond the expert's plan (the generator keeps layouts the expert solves in
#: 11 or fewer), so a careful player has room for a correction.
HARD_SLACK = 4
#: How far (degrees) a shape may be turned away from its hole's outline and still pass (sorters with ``hole_yaws``).
FIT_TOLERANCE = 25.0
#: How far (degrees, modulo 90) a cube of a flush tower may be turned against the cube below it.
FLUSH_TOLERANCE = 20.0
#: Wiping directions, named as seen in the front image.
DIRECTIONS = ("left_to_right", "right_to_left", "front_to_back", "back_to_front")


def _need(value, what: str):
    """``value``, which the spec's kind or family guarantees; a missing one is a bug in the caller."""
    if value is None:
        raise ValueError(f"this spec has no {what}")
    return value


class ObjectSpec(BaseModel):
    """One thing on the table."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    id: str = Field(pattern=r"^[a-z][a-z0-9_]*$")
    kind: Literal["shape", "container", "sorter", "sponge", "area"]
    shape: str | None = None
    """For ``shape``: cube, cylinder, star, moon or triangle."""
    colour: str | None = None
    x: float
    y: float
    yaw: float = 0.0
    """Rotation about the vertical, degrees."""
    holes: tuple[str, ...] = ()
    """For ``sorter``: the hole shapes, along the sorter's length (its local y axis)."""
    hole_yaws: tuple[float, ...] = ()
    """For a ``sorter`` of the hard set: how each hole's outline is turned on the lid (degrees, about the vertical,
    relative to the sorter). When given, a shape passes its own hole only when it is turned to match the outline
    (within :data:`FIT_TOLERANCE`); otherwise it stays on the lid. Empty (and left out of files): any turn fits."""
    size: tuple[float, float] | None = None
    """For ``area``: extent along world x and y (m)."""
    on: str | None = None
    """For a cube: the id of the cube it rests on at the start (a tower already begun, or a cube in the way)."""
    height: float | None = None
    """For a ``sponge`` of the hard set: its height (m; 0.045, a cube's, so the object list's z does not tell it from
    the shapes). None (and left out of files): the classic 3.5 cm."""
    arrow: str | None = None
    """For an ``area`` of the hard set: the direction of the arrow printed on it (its long side lies along it).
    None (and left out of files): no arrow."""

    @model_validator(mode="after")
    def _check(self) -> "ObjectSpec":
        if self.colour is not None and self.colour not in COLOURS:
            raise ValueError(f"unknown colour {self.colour!r}")
        if self.kind == "shape" and self.shape not in SHAPES:
            raise ValueError(f"shape object {self.id} needs a shape from {sorted(SHAPES)}")
        if self.kind == "sorter" and not self.holes:
            raise ValueError("a sorter needs holes")
        if any(h not in SHAPES for h in self.holes):
            raise ValueError(f"unknown hole shape in {self.holes}")
        if self.height is not None and (self.kind != "sponge" or not 0.02 <= self.height <= 0.06):
            raise ValueError("only a sponge has a height, 0.02-0.06 m")
        if self.arrow is not None and (self.kind != "area" or self.arrow not in DIRECTIONS):
            raise ValueError(f"only an area has an arrow, pointing one of {', '.join(DIRECTIONS)}")
        if self.hole_yaws and len(self.hole_yaws) != len(self.holes):
            raise ValueError(f"hole_yaws needs one angle per hole ({len(self.holes)}), got {len(self.hole_yaws)}")
        if self.kind == "area" and self.size is None:
            raise ValueError("an area needs a size")
        return self

    @property
    def shape_name(self) -> str:
        """The shape of a ``shape`` object."""
        return str(_need(self.shape, "shape"))

    @property
    def colour_name(self) -> str:
        """The colour of a coloured object (a shape, container or area)."""
        return str(_need(self.colour, "colour"))

    @property
    def extent(self) -> tuple[float, float]:
        """The (x, y) extent of an ``area`` (m)."""
        size: tuple[float, float] = _need(self.size, "size")
        return size


class GoalSpec(BaseModel):
    """What success means, per family."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    family: Literal["pick", "stack", "sorter", "wipe"]
    target: str | None = None
    """pick / sorter: the object to move; wipe: the sponge."""
    container: str | None = None
    """pick: the container the target must end in."""
    order: tuple[str, ...] = ()
    """stack: cube ids from the bottom of the tower to its top."""
    area: str | None = None
    """wipe: the area to wipe."""
    direction: Literal["left_to_right", "right_to_left", "front_to_back", "back_to_front"] | None = None
    keep_still: tuple[str, ...] = ()
    """Objects the instruction says to leave alone ("only the red one"): a loose one must never be grasped nor
    moved by more than 2 cm, a container must receive nothing, an area must not be touched by the sponge, nothing may
    be left on the shape sorter's lid (a shape goes straight through its own hole). Once one
    of them is disturbed the task can no longer succeed. Empty in the classic set (and then left out of files)."""

    also: tuple[str, ...] = ()
    """sorter (hard set): further shapes that must also end in the compartments under their own holes (the target
    first, then these). Empty in the classic set (and left out of files)."""
    flush: bool = False
    """stack (hard set): each cube must also be turned to line up with the one below, its faces within
    :data:`FLUSH_TOLERANCE` degrees of the lower cube's (modulo 90). False in the classic set (and left out of
    files)."""

    @property
    def target_id(self) -> str:
        """pick / sorter: the object to move; wipe: the sponge."""
        return str(_need(self.target, "target"))

    @property
    def container_id(self) -> str:
        return str(_need(self.container, "container"))

    @property
    def area_id(self) -> str:
        return str(_need(self.area, "area"))

    @property
    def sorted_ids(self) -> tuple[str, ...]:
        """sorter: every shape that must end in its own compartment (the target, then ``also``)."""
        return (self.target_id, *self.also)

    @property
    def stroke(self) -> str:
        """wipe: the direction of the stroke."""
        return str(_need(self.direction, "direction"))


class SceneSpec(BaseModel):
    """The full set-up of one task (stored as ``Task.metadata``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    format: int = TASK_FORMAT
    family: Literal["pick", "stack", "sorter", "wipe"]
    variant: str
    """The original task id this mirrors (e.g. ``stack_cubes_color`` or ``pick_cube_relative``)."""
    scene_seed: int
    objects: tuple[ObjectSpec, ...]
    goal: GoalSpec
    target_ids: tuple[str, ...] = ()
    """Objects the instruction is about (for the target-only box ablation)."""
    attempt: int = 0
    """Which draw of the generator this layout is (earlier draws the oracle could not solve were dropped)."""
    oracle_steps: int | None = None
    """Env steps the scripted oracle needed when the generator verified the task."""
    template: str | None = None
    """Id of the instruction template (``family/subset/index``, stacking adds the set-up), for diversity audits."""

    @model_validator(mode="after")
    def _refs(self) -> "SceneSpec":
        ids = [o.id for o in self.objects]
        if len(ids) != len(set(ids)):
            raise ValueError("object ids must be unique")
        g = self.goal
        for o in self.objects:
            if o.on is not None and (o.on not in ids or self.get(o.on).shape != "cube" or o.shape != "cube"):
                raise ValueError(f"{o.id} can only rest on another cube, not {o.on!r}")
        for ref in [g.target, g.container, g.area, *g.order, *g.also, *self.target_ids, *g.keep_still]:
            if ref is not None and ref not in ids:
                raise ValueError(f"goal refers to unknown object {ref!r}")
        return self

    def get(self, obj_id: str | None) -> ObjectSpec:
        for o in self.objects:
            if o.id == obj_id:
                return o
        raise KeyError(obj_id)
