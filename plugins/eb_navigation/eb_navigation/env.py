"""EB-Navigation: walk to a named object in a furnished room with 8 low-level actions.

Rooms come from the shared scene kit (:mod:`eb_scenekit`): ``generate_room(kind, seed)`` plus the task's extra
objects. One MuJoCo model per room (compiled when the room changes, kept for the following tasks of the same
room, whose distractors are hidden when they do not use them); a step moves the agent on the free-space
lattice, moves the kit's mocap agent camera (no recompile) and renders the first-person view once with the
kit's :class:`~eb_scenekit.render.SceneRenderer`, plus a small segmentation pass for boxes and the text
description (the overhead view only when ``multi_view`` is on). With ``render: false`` nothing is rendered
and MuJoCo is never imported: the geometry alone decides collisions and success, which is how the tests run
the oracle over all 300 tasks in seconds.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from eb_core import Action, DiscreteActionSpace, Env, ObjectInfo, Observation, PromptParts, StepResult, Task
from eb_navigation.geometry import (
    ACTION_NAMES,
    FIRST_PERSON_FOVY,
    STEP,
    SUCCESS_DISTANCE,
    TILT_MAX,
    TILT_MIN,
    AgentState,
    FreeSpace,
    bearing_to,
    distance_to,
)
from eb_navigation.hard_words import hard_colour_word
from eb_navigation.instructions import display_name, with_article
from eb_navigation.prompts import prompt_parts
from eb_navigation.room import NavObject, NavRoom
from eb_navigation.splits import take_room
from eb_navigation.tasks import NavTaskSpec, TaskFileError, load_task_file, load_taskset, spec_of

__all__ = ["FAILURES", "NavigationEnv", "NavigationParams", "build_room", "check_target"]


FEEDBACK_OK = "The last action succeeded."
FEEDBACK_BLOCKED = ("The last action failed: moving that way would bump into a wall or a piece of furniture, "
                    "so you stayed where you were.")
FEEDBACK_TILT = {
    "tilt_max": f"The last action failed: the camera is already tilted up as far as it goes ({TILT_MAX} degrees).",
    "tilt_min": f"The last action failed: the camera is already tilted down as far as it goes ({-TILT_MIN} degrees).",
}
FEEDBACK_DONE = " You are now close enough to the target: the task is complete."

#: The core's ``StepResult.info["failure"]`` for each reason :meth:`FreeSpace.apply` gives: a move into a wall
#: or a piece of furniture is a ``collision``; tilting the camera past its limit is a ``precondition`` failure
#: (a fine action in another state: the camera is already at its end stop, which the observation text says).
#: Turning never fails, so nothing else can.
FAILURES = {"blocked": "collision", "tilt_max": "precondition", "tilt_min": "precondition"}


class NavigationParams(BaseModel):
    """``env.params`` of ``conf/env/navigation.yaml``."""

    model_config = ConfigDict(extra="forbid")

    task_file: str | None = None
    """Path of a task file made by ``eb tasks generate env=navigation``; None = the shipped one."""
    render: bool = True
    """False: no images at all (geometry only, text observations), for fast oracle checks."""
    difficulty: Literal["classic", "medium", "hard"] | None = None
    """Difficulty of generated ``train``/``val`` tasks (a curriculum); None = that of the task set."""


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


def check_target(room: NavRoom, spec: NavTaskSpec) -> NavObject:
    """The task's target in the rebuilt room; a one-line :class:`TaskFileError` if the room no longer matches."""
    try:
        target = room.get(spec.target.id)
    except KeyError:
        raise TaskFileError(f"task {spec.id!r}: field target.id: no object {spec.target.id!r} in "
                            f"{spec.scene.kind} scene {spec.scene.seed}") from None
    if target.type != spec.target.type or max(abs(a - b) for a, b in zip(target.centre, spec.target.position)) > 0.02:
        raise TaskFileError(f"task {spec.id!r}: field target: the room no longer matches the task file (object "
                            f"{target.id} is a {target.type} at {tuple(round(v, 2) for v in target.centre)}); "
                            f"regenerate the file with `eb tasks generate env=navigation`")
    return target


def build_room(spec: NavTaskSpec) -> NavRoom:
    """The room of a task (the kit's room plus the task's extra objects), checked against the file."""
    room = NavRoom(spec.scene.kind, spec.scene.seed, [e.spec() for e in spec.extra_objects], spec.scene.clutter)
    check_target(room, spec)
    return room


def _bearing_words(b: float) -> str:
    if abs(b) <= 10:
        return "straight ahead"
    side = "left" if b > 0 else "right"
    return f"slightly to the {side}" if abs(b) <= 30 else f"to the {side}"


class _World:
    """One room (kept while consecutive tasks share it) and, when rendering, its compiled scene."""

    def __init__(self, room: NavRoom, render: bool, resolution: int) -> None:
        self.room = room
        self.scene = None
        if render:
            from eb_navigation.scene import RoomScene

            self.scene = RoomScene(room, resolution)

    def close(self) -> None:
        if self.scene is not None:
            self.scene.close()
            self.scene = None


class NavigationEnv(Env):
    """The EB-Navigation environment (see the package README)."""

    name = "navigation"

    def __init__(self, resolution: int = 500, multi_view: bool = False, **params: Any) -> None:
        self.params = _params(params)
        self.resolution = int(resolution)
        self.multi_view = bool(multi_view)
        self._space = DiscreteActionSpace(actions=ACTION_NAMES)
        self._world: _World | None = None
        self._world_key: tuple | None = None
        self._room_extras: dict[tuple[str, int], tuple] | None = None
        self._spec: NavTaskSpec | None = None
        self._free: FreeSpace | None = None
        self._present: frozenset[str] = frozenset()
        self._in_room: list[int] = []
        self._state: AgentState | None = None
        self._target_xy: tuple[float, float] = (0.0, 0.0)
        self._done = False
        self._closed = False

    # -- contract --------------------------------------------------------------------------------

    @classmethod
    def load_tasks(cls, taskset: str = "classic", **params: Any) -> list[Task]:
        """The shipped ``classic`` or ``hard`` set, or ``env.params.task_file`` (a classic-style file or a folder
        of per-subset files)."""
        p = _params(params)
        return [t.to_task() for t in load_taskset(taskset, p.task_file)]

    splits = ("train", "val")

    @classmethod
    def split_tasks(cls, split: str, start: int, count: int, taskset: str = "classic", **params: Any) -> list[Task]:
        """Generated train/val tasks, disjoint from the shipped ones (:mod:`eb_navigation.splits`); ``taskset=hard``
        (or ``env.params.difficulty``) draws them at that difficulty."""
        from eb_navigation.splits import split_tasks

        p = _params(params)
        difficulty = p.difficulty or ("hard" if taskset == "hard" else "classic")
        return split_tasks(split, start, count, task_file=p.task_file, difficulty=difficulty)

    def action_space(self) -> DiscreteActionSpace:
        return self._space

    def prompt_parts(self) -> PromptParts:
        return prompt_parts(self._spec.subset if self._spec else None)

    def _extras_of_scene(self, spec: NavTaskSpec) -> tuple:
        """The extras to compile into the room of ``spec``: those of the task file's tasks in that room when
        they all agree (so one model serves every task of the room), else the task's own."""
        if self._room_extras is None:
            by_scene: dict[tuple[str, int], set[tuple]] = {}
            try:
                for t in load_task_file(self.params.task_file).tasks:
                    if t.extra_objects:
                        by_scene.setdefault((t.scene.kind, t.scene.seed), set()).add(t.extra_objects)
            except TaskFileError:
                pass
            self._room_extras = {k: next(iter(v)) for k, v in by_scene.items() if len(v) == 1}
        own = spec.extra_objects
        shared = self._room_extras.get((spec.scene.kind, spec.scene.seed), ())
        return shared if not own or own == shared else own

    def reset(self, task: Task, seed: int) -> Observation:
        if self._closed:
            raise RuntimeError("NavigationEnv.reset() after close()")
        spec = spec_of(task)
        extras = self._extras_of_scene(spec)
        key = (spec.scene.kind, spec.scene.seed, spec.scene.clutter, extras)
        previous = None
        try:
            if key != self._world_key or self._world is None:
                # the previous room is closed only after the new one has been drawn, so that a renderer pooled per
                # process keeps its GL context across the switch instead of making a new one
                previous, self._world, self._world_key = self._world, None, None
                wanted = tuple(e.spec() for e in extras)
                room = (take_room(spec.scene.kind, spec.scene.seed, wanted, spec.scene.clutter)
                        or NavRoom(spec.scene.kind, spec.scene.seed, list(wanted), spec.scene.clutter))
                self._world = _World(room, self.params.render, self.resolution)
                self._world_key = key
            return self._start(spec)
        finally:
            if previous is not None:
                previous.close()

    def _start(self, spec: NavTaskSpec) -> Observation:
        world = self._world
        assert world is not None
        target = check_target(world.room, spec)
        self._spec = spec
        self._present = frozenset(e.id for e in spec.extra_objects)
        self._free = world.room.free_space(self._present)
        self._in_room = world.room.visible_objects(self._present)
        if world.scene is not None:
            world.scene.show_extras(self._present)
        state = AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw, spec.start.tilt)
        if not self._free.is_free(state.i, state.j):
            raise TaskFileError(f"task {spec.id!r}: field start: ({spec.start.x}, {spec.start.y}) is inside "
                                f"furniture or too close to a wall")
        self._state = state
        self._target_xy = (target.x, target.y)
        self._done = False
        return self._observe()

    def step(self, action: Action) -> StepResult:
        if self._state is None or self._free is None:
            raise RuntimeError("NavigationEnv.step() before reset()")
        if isinstance(action, bool) or not isinstance(action, (int, np.integer)) or not 0 <= int(action) < 8:
            raise ValueError(f"navigation actions are ids 0..7, got {action!r}")
        a = int(action)
        new, ok, reason = self._free.apply(self._state, a)
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
        info = {"distance_to_goal": round(dist, 3), "distance_to_target": round(dist, 3), "position": (new.x, new.y),
                "yaw": new.yaw_deg, "tilt": new.tilt, "failure": None if ok else FAILURES[reason],
                "path_distance": self._path_distance(new)}
        return StepResult(observation=obs, action_success=ok, feedback=feedback, done=success,
                          task_success=success, progress=1.0 if success else 0.0, info=info)

    def expert_plan(self) -> list[Action] | None:
        """Shortest action sequence from the CURRENT pose into the 1 m circle around the target (whatever moves
        led there); None, with :attr:`expert_reason` saying why, when no free spot near the target can be reached."""
        if self._state is None or self._free is None or self._spec is None:
            self.expert_reason = "no episode is running: call reset() first"
            return None
        plan = self._free.shortest_plan(self._state, self._target_xy)
        if plan is None:
            s = self._state
            near = bool(self._free.goal_cells(self._target_xy).any())
            self.expert_reason = (
                f"the target {self._spec.target.id} cannot be reached from ({s.x:g}, {s.y:g}): "
                + ("every free spot within 1 m of it is cut off from here by walls or furniture" if near
                   else "there is no free floor within 1 m of it")
            )
            return None
        self.expert_reason = None
        return list(plan)

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
        self._world = None
        self._world_key = None
        self._closed = True

    # -- observation -----------------------------------------------------------------------------

    @property
    def distance_to_goal(self) -> float | None:
        """Metres from the agent to the target now (None before reset). Steps report it as
        ``info["distance_to_goal"]``; after a reset, when :class:`~eb_core.Observation` has no info to carry it,
        tools read it here."""
        if self._state is None:
            return None
        return round(distance_to(self._state, self._target_xy), 3)

    @property
    def state(self) -> AgentState | None:
        """The agent's pose (for tests and tools)."""
        return self._state

    def _observe(self) -> Observation:
        assert self._world is not None and self._state is not None and self._spec is not None
        world, s = self._world, self._state
        images: dict[str, np.ndarray] = {}
        boxes: dict[int, tuple[int, int, int, int]] = {}
        if world.scene is not None:
            world.scene.set_agent(s)
            images["first_person"] = world.scene.first_person()
            if self.multi_view:
                images["overhead"] = world.scene.overhead()
            seen = world.scene.objects_in_view(self._in_room)
            pixels = {k: area for k, (_, area) in seen.items()}
            boxes = {k: box for k, (box, _) in seen.items()}
        else:
            pixels = self._objects_in_cone()
        return Observation(images=images, primary="first_person" if images else None,
                           text=self._describe(pixels), objects=self._object_infos(pixels, boxes),
                           visible_objects=self._in_view(images["first_person"]) if world.scene is not None else None,
                           scene_objects=sorted({world.room.objects[k].type for k in self._in_room}))

    def _in_view(self, rgb: np.ndarray) -> list[dict[str, Any]]:
        """The objects the image shows, from the segmentation pixels (edge objects too): for error analysis."""
        from eb_scenekit.visibility import colours_in_view, objects_in_view

        assert self._world is not None and self._world.scene is not None
        objects, present = self._world.room.objects, set(self._in_room)
        omap = self._world.scene.object_map()
        seen = {k: v for k, v in objects_in_view(omap).items() if k in present}
        colours = colours_in_view(rgb, omap, list(seen))
        return [{"name": objects[k].id, "type": objects[k].type,
                 "colour": hard_colour_word(objects[k].type, objects[k].colour),
                 "colours": colours.get(k, []), "aliases": [display_name(objects[k].type)], "pixels": v.pixels,
                 "edge": v.edge} for k, v in sorted(seen.items(), key=lambda kv: -kv[1].pixels)]

    def _path_distance(self, s: AgentState) -> float | None:
        """Metres along the shortest free path from ``s`` to a spot within the success distance (None: cut off)."""
        assert self._free is not None
        free, goal = self._free, self._free.goal_cells(self._target_xy)
        if not goal.any():
            return None
        seen, frontier, n = {(s.i, s.j)}, [(s.i, s.j)], 0
        while frontier:
            if any(goal[i - free.i0, j - free.j0] for i, j in frontier if free._inside(i - free.i0, j - free.j0)):
                return n * STEP
            nxt = []
            for i, j in frontier:
                for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                    if (i + di, j + dj) not in seen and free.can_move(i, j, di, dj):
                        seen.add((i + di, j + dj))
                        nxt.append((i + di, j + dj))
            frontier, n = nxt, n + 1
        return None

    def _objects_in_cone(self) -> dict[int, float]:
        """Without rendering: objects within the horizontal field of view (no occlusion test)."""
        s = self._state
        assert s is not None and self._world is not None
        out = {}
        objects = self._world.room.objects
        for k in self._in_room:
            o = objects[k]
            if abs(bearing_to(s, (o.x, o.y))) <= FIRST_PERSON_FOVY / 2 and distance_to(s, (o.x, o.y)) > 0.3:
                out[k] = 100.0
        return out

    def _object_infos(self, pixels: dict[int, float], boxes: dict[int, tuple[int, int, int, int]]) -> list[ObjectInfo]:
        assert self._world is not None and self._spec is not None
        infos = []
        objects = self._world.room.objects
        target_id = self._spec.target.id
        for k in self._in_room:
            o = objects[k]
            if k not in pixels and o.id != target_id:
                continue
            infos.append(ObjectInfo(name=o.id, type=o.type, box=boxes.get(k), position=o.centre,
                                    label=display_name(o.type), is_target=o.id == target_id))
        return infos

    def _describe(self, pixels: dict[int, float]) -> str:
        assert self._world is not None and self._state is not None and self._free is not None
        s = self._state
        seen = []
        for k, n in pixels.items():
            o = self._world.room.objects[k]
            d = distance_to(s, (o.x, o.y))
            seen.append((-n, d, o, bearing_to(s, (o.x, o.y))))
        seen.sort(key=lambda t: t[:2])
        parts = []
        for _, d, o, b in seen[:8]:  # the eight biggest in the image
            dist = max(0.5, round(d * 2) / 2)
            what = with_article(hard_colour_word(o.type, o.colour) + " " + display_name(o.type))
            parts.append(f"{what} about {dist:g} m away, {_bearing_words(b)}")
        text = "In view: " + ("; ".join(parts) if parts else "nothing but the walls and the floor") + "."
        free = self._free.free_ahead(s)
        text += (f" The floor straight ahead is clear for about {free * STEP:g} m." if free
                 else " Something blocks the way straight ahead.")
        if s.tilt:
            text += f" The camera is tilted {abs(s.tilt)} degrees {'up' if s.tilt > 0 else 'down'}."
        return text
