"""EB-Navigation: walk to a named object in a furnished room with 8 low-level actions.

One MuJoCo model per scene (compiled at reset, cached for the next tasks of the same room); a step
moves the agent on the free-space lattice, writes the camera pose into the model (no recompile) and
renders the first-person view once (plus a small segmentation pass for boxes and the text
description; the overhead view only when ``multi_view`` is on). With ``render: false`` nothing is
rendered at all: the geometry alone decides collisions and success, which is how the tests run the
oracle over all 300 tasks in seconds.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from eb_core import Action, DiscreteActionSpace, Env, ObjectInfo, Observation, PromptParts, StepResult, Task
from eb_navigation.geometry import (
    ACTION_NAMES,
    STEP,
    SUCCESS_DISTANCE,
    TILT_MAX,
    TILT_MIN,
    AgentState,
    FreeSpace,
    bearing_to,
    distance_to,
)
from eb_navigation.instructions import display_name
from eb_navigation.layout import Layout, generate_layout
from eb_navigation.mjcf import FIRST_PERSON_FOVY
from eb_navigation.prompts import prompt_parts
from eb_navigation.tasks import NavTaskSpec, TaskFileError, load_task_file, spec_of

__all__ = ["NavigationEnv", "NavigationParams", "build_world"]

FEEDBACK_OK = "The last action succeeded."
FEEDBACK_BLOCKED = ("The last action failed: moving that way would bump into a wall or a piece of furniture, "
                    "so you stayed where you were.")
FEEDBACK_TILT = {
    "tilt_max": f"The last action failed: the camera is already tilted up as far as it goes ({TILT_MAX} degrees).",
    "tilt_min": f"The last action failed: the camera is already tilted down as far as it goes ({-TILT_MIN} degrees).",
}
FEEDBACK_DONE = " You are now close enough to the target: the task is complete."


class NavigationParams(BaseModel):
    """``env.params`` of ``conf/env/navigation.yaml``."""

    model_config = ConfigDict(extra="forbid")

    task_file: str | None = None
    """Path of a task file made by ``eb tasks generate env=navigation``; None = the shipped one."""
    render: bool = True
    """False: no images at all (geometry only, text observations), for fast oracle checks."""


def _params(params: dict[str, Any]) -> NavigationParams:
    try:
        return NavigationParams.model_validate(params)
    except ValidationError as exc:
        err = exc.errors()[0]
        key = ".".join(str(p) for p in err["loc"])
        if err["type"] == "extra_forbidden":
            raise ValueError(f"unknown navigation env param {key!r}; allowed: "
                             f"{', '.join(NavigationParams.model_fields)}") from None
        raise ValueError(f"invalid navigation env param {key!r}: {err['msg']}") from None


def build_world(spec: NavTaskSpec) -> Layout:
    """The room of a task: the generated layout plus the task's extra objects, checked against the file."""
    layout = generate_layout(spec.scene.kind, spec.scene.seed)
    if spec.extra_objects:
        layout = layout.with_objects(e.placed() for e in spec.extra_objects)
    try:
        target = layout.get(spec.target.id)
    except KeyError:
        raise TaskFileError(f"task {spec.id!r}: field target.id: no object {spec.target.id!r} in "
                            f"{spec.scene.kind} scene {spec.scene.seed}") from None
    if target.type != spec.target.type or max(abs(a - b) for a, b in zip(target.centre, spec.target.position)) > 0.02:
        raise TaskFileError(f"task {spec.id!r}: field target: the room no longer matches the task file (object "
                            f"{target.id} is a {target.type} at {tuple(round(v, 2) for v in target.centre)}); "
                            f"regenerate the file with `eb tasks generate env=navigation`")
    return layout


def _bearing_words(b: float) -> str:
    if abs(b) <= 10:
        return "straight ahead"
    side = "left" if b > 0 else "right"
    return f"slightly to the {side}" if abs(b) <= 30 else f"to the {side}"


class _World:
    """Everything that belongs to one room (cached across the tasks that share it)."""

    def __init__(self, layout: Layout, render: bool, resolution: int) -> None:
        self.layout = layout
        self.free = FreeSpace(layout)
        self.scene = None
        if render:
            from eb_navigation.scene import NavScene

            self.scene = NavScene(layout, resolution)


class NavigationEnv(Env):
    """The EB-Navigation environment (see the package README)."""

    name = "navigation"

    def __init__(self, resolution: int = 500, multi_view: bool = False, **params: Any) -> None:
        self.params = _params(params)
        self.resolution = int(resolution)
        self.multi_view = bool(multi_view)
        self._space = DiscreteActionSpace(actions=ACTION_NAMES)
        self._worlds: OrderedDict[tuple, _World] = OrderedDict()
        self._renderer = None
        self._world: _World | None = None
        self._loaded_world: _World | None = None
        self._spec: NavTaskSpec | None = None
        self._state: AgentState | None = None
        self._target_xy: tuple[float, float] = (0.0, 0.0)
        self._done = False
        self._closed = False

    # -- contract --------------------------------------------------------------------------------

    @classmethod
    def load_tasks(cls, **params: Any) -> list[Task]:
        p = _params(params)
        return [t.to_task() for t in load_task_file(p.task_file).tasks]

    def action_space(self) -> DiscreteActionSpace:
        return self._space

    def prompt_parts(self) -> PromptParts:
        return prompt_parts(self._spec.subset if self._spec else None)

    def reset(self, task: Task, seed: int) -> Observation:
        if self._closed:
            raise RuntimeError("NavigationEnv.reset() after close()")
        spec = spec_of(task)
        key = (spec.scene.kind, spec.scene.seed, tuple(e.model_dump_json() for e in spec.extra_objects))
        world = self._worlds.get(key)
        if world is None:
            world = _World(build_world(spec), self.params.render, self.resolution)
            self._worlds[key] = world
            while len(self._worlds) > 3:
                self._worlds.popitem(last=False)
        else:
            self._worlds.move_to_end(key)
            build_world(spec)  # still check the target against the file
        self._world, self._spec = world, spec
        state = AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw, spec.start.tilt)
        if not world.free.is_free(state.i, state.j):
            raise TaskFileError(f"task {spec.id!r}: field start: ({spec.start.x}, {spec.start.y}) is inside "
                                f"furniture or too close to a wall")
        self._state = state
        target = world.layout.get(spec.target.id)
        self._target_xy = (target.x, target.y)
        self._done = False
        if world.scene is not None:
            if self._renderer is None:
                from eb_navigation.render import SceneRenderer

                self._renderer = SceneRenderer(self.resolution)
            if self._loaded_world is not world:
                self._renderer.load(world.scene.model)
                self._loaded_world = world
        return self._observe()

    def step(self, action: Action) -> StepResult:
        if self._state is None or self._world is None:
            raise RuntimeError("NavigationEnv.step() before reset()")
        if isinstance(action, bool) or not isinstance(action, (int, np.integer)) or not 0 <= int(action) < 8:
            raise ValueError(f"navigation actions are ids 0..7, got {action!r}")
        a = int(action)
        new, ok, reason = self._world.free.apply(self._state, a)
        self._state = new
        dist = distance_to(new, self._target_xy)
        success = dist <= SUCCESS_DISTANCE + 1e-9
        if ok:
            feedback = FEEDBACK_OK
        else:
            feedback = FEEDBACK_TILT.get(reason, FEEDBACK_BLOCKED)
        if success:
            feedback += FEEDBACK_DONE
        self._done = success
        obs = self._observe()
        info = {"distance_to_target": round(dist, 3), "position": (new.x, new.y), "yaw": new.yaw_deg,
                "tilt": new.tilt}
        return StepResult(observation=obs, action_success=ok, feedback=feedback, done=success,
                          task_success=success, progress=1.0 if success else 0.0, info=info)

    def expert_plan(self) -> list[Action] | None:
        """Shortest action sequence from the current pose into the 1 m circle around the target."""
        if self._state is None or self._world is None:
            return None
        plan = self._world.free.shortest_plan(self._state, self._target_xy)
        return None if plan is None else list(plan)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._worlds.clear()
        self._world = self._loaded_world = None
        self._closed = True

    # -- observation -----------------------------------------------------------------------------

    @property
    def state(self) -> AgentState | None:
        """The agent's pose (for tests and tools)."""
        return self._state

    def _observe(self) -> Observation:
        assert self._world is not None and self._state is not None and self._spec is not None
        world, s = self._world, self._state
        images: dict[str, np.ndarray] = {}
        pixels: dict[int, int] = {}
        boxes: dict[int, tuple[int, int, int, int]] = {}
        if world.scene is not None and self._renderer is not None:
            world.scene.set_agent(s)
            rgb, seg = self._renderer.render(world.scene.data, "first_person", groups=(0, 1), segmentation=True)
            images["first_person"] = rgb
            if self.multi_view:
                images["overhead"], _ = self._renderer.render(world.scene.data, "overhead", groups=(0, 2))
            pixels, boxes = self._objects_in(seg, world.scene.geom_object)
        else:
            pixels = self._objects_in_cone()
        return Observation(images=images, primary="first_person" if images else None,
                           text=self._describe(pixels), objects=self._object_infos(pixels, boxes))

    def _objects_in(self, seg: np.ndarray | None, geom_object: np.ndarray
                    ) -> tuple[dict[int, int], dict[int, tuple[int, int, int, int]]]:
        if seg is None:
            return {}, {}
        obj = np.where(seg >= 0, geom_object[np.clip(seg, 0, None)], -1)
        counts = np.bincount(obj.ravel() + 1)
        scale = self.resolution / seg.shape[0]
        pixels: dict[int, int] = {}
        boxes: dict[int, tuple[int, int, int, int]] = {}
        for k in np.nonzero(counts[1:])[0]:
            n = int(counts[k + 1])
            if n < 3:
                continue
            rows, cols = np.nonzero(obj == k)
            pixels[int(k)] = n
            boxes[int(k)] = (int(cols.min() * scale), int(rows.min() * scale),
                             min(self.resolution - 1, int(math.ceil((cols.max() + 1) * scale)) - 1),
                             min(self.resolution - 1, int(math.ceil((rows.max() + 1) * scale)) - 1))
        return pixels, boxes

    def _objects_in_cone(self) -> dict[int, int]:
        """Without rendering: objects within the horizontal field of view (no occlusion test)."""
        s = self._state
        assert s is not None and self._world is not None
        out = {}
        for k, o in enumerate(self._world.layout.objects):
            if abs(bearing_to(s, (o.x, o.y))) <= FIRST_PERSON_FOVY / 2 and distance_to(s, (o.x, o.y)) > 0.3:
                out[k] = 100
        return out

    def _object_infos(self, pixels: dict[int, int], boxes: dict[int, tuple[int, int, int, int]]) -> list[ObjectInfo]:
        assert self._world is not None and self._spec is not None
        infos = []
        objects = self._world.layout.objects
        target_id = self._spec.target.id
        for k, o in enumerate(objects):
            if k not in pixels and o.id != target_id:
                continue
            infos.append(ObjectInfo(name=o.id, type=o.type, box=boxes.get(k),
                                    position=tuple(round(v, 3) for v in o.centre), label=display_name(o.type),
                                    is_target=o.id == target_id))
        return infos

    def _describe(self, pixels: dict[int, int]) -> str:
        assert self._world is not None and self._state is not None
        s = self._state
        seen = []
        for k in pixels:
            o = self._world.layout.objects[k]
            d = distance_to(s, (o.x, o.y))
            seen.append((d, o, bearing_to(s, (o.x, o.y))))
        seen.sort(key=lambda t: t[0])
        parts = []
        for d, o, b in seen[:8]:
            dist = max(0.5, round(d * 2) / 2)
            parts.append(f"a {o.colour} {display_name(o.type)} about {dist:g} m away, {_bearing_words(b)}")
        text = "In view: " + ("; ".join(parts) if parts else "nothing but the walls and the floor") + "."
        free = self._world.free.free_ahead(s)
        text += (f" The floor straight ahead is clear for about {free * STEP:g} m." if free
                 else " Something blocks the way straight ahead.")
        if s.tilt:
            text += f" The camera is tilted {abs(s.tilt)} degrees {'up' if s.tilt > 0 else 'down'}."
        return text
