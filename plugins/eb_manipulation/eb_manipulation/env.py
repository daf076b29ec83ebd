"""``ManipulationEnv``: EB-Manipulation's 228 tabletop tasks for a Franka Panda in MuJoCo.

One episode = one task file entry. ``reset`` builds the task's scene, ``step`` executes one discrete
7-D action ``[x, y, z, roll, pitch, yaw, gripper]`` (move along a collision-checked path, then open or
close the gripper, then let the objects settle) and reports whether the task's physical success check
holds. See the package README for coordinates, task families and the object list.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict

from eb_core.env import Action, Env, ObjectInfo, Observation, PlanItemError, PromptParts, StepResult, Task
from eb_manipulation.actions import ACTION_SPACE, pos_to_bin
from eb_manipulation.spec import SceneSpec
from eb_manipulation.tasks import load_task_file, scene_of

__all__ = ["ManipulationEnv", "ManipulationParams"]


class ManipulationParams(BaseModel):
    """The ``params:`` of ``conf/env/manipulation.yaml``."""

    model_config = ConfigDict(extra="forbid")

    render: bool = True
    """Render images. False gives text-only observations and a faster simulation (tests, oracle checks)."""
    detection_boxes: Literal["all", "target", "none"] = "all"
    """Boxes with index labels in the front image: all objects (default), only the task's objects, or none."""
    draw_axes: bool = True
    """Draw the red X/Y/Z frame at the robot base in the front image."""
    tag_layout: Literal["auto", "corner", "clear"] = "auto"
    """Where the boxes' number tags go: ``corner`` above each box's top-left corner (the classic overlay), ``clear``
    where they cover the least of any object (:mod:`eb_manipulation.tags`), ``auto`` clear in the harder sets'
    scenes (those with "only" conditions) and corner in the classic ones, whose images stay as they were."""
    task_file: str | None = None
    """Another task file (or a folder of them) made by ``eb tasks generate env=manipulation``; default: the shipped
    file of the task set."""
    task_dir: str | None = None
    """Old spelling of ``task_file`` for a folder (accepted as an alias)."""
    difficulty: Literal["classic", "medium", "hard"] | None = None
    """Difficulty of the generated ``train``/``val`` splits (a curriculum); default: that of the task set."""


class ManipulationEnv(Env):
    """EB-Manipulation in MuJoCo: Panda arm, wooden table, 4 task families, 5 subsets."""

    name = "manipulation"

    def __init__(self, resolution: int = 500, multi_view: bool = False, **params: Any):
        self.params = ManipulationParams(**params)
        self.resolution = int(resolution)
        self.multi_view = bool(multi_view)
        self._world = None
        self._renderer = None
        self._task: Task | None = None
        self._scene: SceneSpec | None = None
        self._order: list[str] = []  # object keys in index order (object 1 first), re-read every observation
        self.tags: dict[str, tuple[int, int, int, int]] = {}
        """Tag rectangle (x0, y0, x1, y1, inclusive) of each label in the last front image (tests, viewers)."""
        self._closed = False

    # --- tasks ------------------------------------------------------------------------------------------
    @classmethod
    def load_tasks(cls, taskset: str = "classic", **params: Any) -> list[Task]:
        """The tasks of a task file, or of the shipped task set ``taskset`` (``classic`` or ``hard``)."""
        known = {k: v for k, v in params.items() if k in ManipulationParams.model_fields}
        p = ManipulationParams(**known)
        return load_task_file(p.task_file or p.task_dir, taskset=taskset)

    splits = ("train", "val")

    @classmethod
    def split_tasks(cls, split: str, start: int, count: int, taskset: str = "classic", **params: Any) -> list[Task]:
        """Generated train/val tasks, disjoint from the shipped ones (:mod:`eb_manipulation.splits`); their
        difficulty is ``params.difficulty``, else that of ``taskset``."""
        from eb_manipulation.splits import split_tasks

        known = {k: v for k, v in params.items() if k in ManipulationParams.model_fields}
        p = ManipulationParams(**known)
        difficulty = p.difficulty or ("hard" if taskset == "hard" else "classic")
        return split_tasks(split, start, count, task_file=p.task_file or p.task_dir, difficulty=difficulty)

    # --- episode ----------------------------------------------------------------------------------------
    def reset(self, task: Task, seed: int) -> Observation:
        """Build the task's scene. The layout is fixed by the task file; ``seed`` does not change it."""
        from eb_manipulation.world import World

        # the previous task's renderer is closed only after the new scene is drawn, so that a renderer pooled per
        # process keeps its GL context across the reset instead of making a new one
        previous, self._renderer = self._renderer, None
        self._world = None
        try:
            self._task = task
            self._scene = scene_of(task)
            self._world = World(self._scene, resolution=self.resolution, render_meshes=self.params.render)
            self._order = []
            self._renumber()
            if self.params.render:
                from eb_manipulation.render import SceneRenderer

                self._renderer = SceneRenderer(self._world.model, self.resolution, scene_key=self._world.scene_xml)
            return self._observe()
        finally:
            if previous is not None:
                previous.close()

    def step(self, action: Action) -> StepResult:
        if self._world is None:
            raise RuntimeError("call reset() before step()")
        from eb_manipulation.world import FAILURES

        try:
            parsed = ACTION_SPACE.parse_plan_item(list(action) if not isinstance(action, dict) else action)
        except (PlanItemError, TypeError) as exc:
            obs = self._observe()
            solved, progress = self._world.evaluate()
            return StepResult(observation=obs, action_success=False, done=solved, task_success=solved,
                              progress=progress, feedback=f"The action was not executed: {exc}. The arm did not move.",
                              info={**self._info(), "failure": FAILURES["invalid"]})
        before = {o: self._world.body_pos(o) for o in self._world.free_objects}
        order_before = list(self._order)
        outcome = self._world.execute(parsed)
        self._renumber()
        solved, progress = self._world.evaluate()
        # objects are named by the list the action was chosen from; one that now has another number says so
        feedback = self._resolve(outcome.feedback, outcome.refs, order_before)
        if solved:
            feedback += " The task is complete."
        return StepResult(observation=self._observe(), action_success=outcome.ok, feedback=feedback, done=solved,
                          task_success=solved, progress=1.0 if solved else float(progress),
                          info={**self._info(), "failure": outcome.failure,
                                "wrong_target": bool(outcome.grasped
                                                     and self._world.is_wrong_grasp(outcome.grasped, before))})

    def _info(self) -> dict[str, Any]:
        world = self._world
        assert world is not None
        return {"held": self._label(world.held) if world.held else None, "gripper_open": world.gripper_open,
                "distance_to_goal": round(world.distance_to_goal(), 4)}

    def distance_to_goal(self) -> float | None:
        """Metres to the goal in the current state (README: Error labels and distance); None before reset."""
        return None if self._world is None else self._world.distance_to_goal()

    def action_space(self):
        return ACTION_SPACE

    def prompt_parts(self) -> PromptParts:
        from eb_manipulation.prompts import example_set, prompt_parts, uses_hard_examples

        family = self._scene.family if self._scene is not None else "pick"
        sizes = [o.size for o in self._scene.objects if o.kind == "area" and o.size] if self._scene else []
        kw: dict[str, Any] = {"area_cm": (round(max(sizes[0]) * 100), round(min(sizes[0]) * 100))} if sizes else {}
        if self._scene is not None and any(o.hole_yaws for o in self._scene.objects):
            kw["turned_holes"] = True
        if self._scene is not None and uses_hard_examples(self._scene):
            kw["hard_examples"] = True
            if not sizes:  # the rules speak of marked areas in every family: give the hard sets' size, not classic's
                from eb_manipulation.hard import AREA_SIZE

                kw["area_cm"] = (round(AREA_SIZE[0] * 100), round(AREA_SIZE[1] * 100))
        if self.fixed_numbers():
            kw["fixed_numbers"] = True
        if self._scene is not None and any(o.kind == "sponge" and o.height is not None for o in self._scene.objects):
            kw["sponge_look"] = True
        return prompt_parts(family, example_set(self.params.detection_boxes, self.multi_view), self.multi_view,
                            **kw)

    def expert_plan(self) -> list[Action] | None:
        """The scripted expert's plan from the current state (arm pose, gripper, held object, object poses).

        None, with :attr:`expert_reason` set, when the goal can no longer be reached (e.g. an object the goal
        needs fell off the table); an empty plan when the goal already holds.
        """
        self.expert_reason = None
        if self._world is None or self._scene is None:
            self.expert_reason = "no episode is running (call reset() first)"
            return None
        from eb_manipulation.oracle import NoPlan, expert_plan, state_of_world

        if self._world.evaluate()[0]:
            self.expert_reason = "the goal already holds"
            return []
        try:
            plan = expert_plan(self._scene, state_of_world(self._world))
        except NoPlan as exc:
            self.expert_reason = exc.reason.format(obj=self._label(exc.obj) if exc.obj else "")
            return None
        return [tuple(a) for a in plan]

    def close(self) -> None:
        self._release()
        self._closed = True

    def _release(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._world = None

    # --- observation ------------------------------------------------------------------------------------
    def fixed_numbers(self) -> bool:
        """Whether objects keep the numbers of the episode's first list (scenes with "only" conditions: hard,
        medium). A stateless player then reads the same numbers in the image, the list, its action history and
        the feedback; a plan of several actions cannot have its objects renumbered under it. Classic scenes are
        numbered again after every action, as the original re-sorts its list."""
        return self._scene is not None and bool(self._scene.goal.keep_still)

    def _renumber(self) -> None:
        """Number the objects by ascending discrete y (left to right in the front image), as the original
        orders its object list; ties by ascending x, then by id. Re-done after every action, except in scenes
        with :meth:`fixed_numbers`, which keep the numbers of the first list."""
        world = self._world
        assert world is not None
        if self._order and self.fixed_numbers():
            return
        coords = {o.key: self.discrete_position(o.key) for o in world.objects}
        self._order = sorted(coords, key=lambda k: (coords[k][1], coords[k][0], k))

    def _label(self, key: str) -> str:
        return f"object {self._order.index(key) + 1}" if key in self._order else key

    def _resolve(self, text: str, refs: dict[str, str], order_before: list[str] | None = None) -> str:
        """Fill ``{slot}`` references: ``object N`` in the numbering from before the action (the list the action
        was chosen from), with ``(object M in the new list)`` when the action changed its number."""
        names = {}
        before = order_before if order_before is not None else self._order
        for slot, key in refs.items():
            if key in before:
                n_before, n_now = before.index(key) + 1, self._order.index(key) + 1
                names[slot] = f"object {n_before}" + (f" (object {n_now} in the new list)" if n_now != n_before
                                                      else "")
            elif self._scene is not None and any(o.id == key and o.kind == "sorter" for o in self._scene.objects):
                names[slot] = "the shape sorter"
            else:
                names[slot] = "an obstacle"
        return text.format(**names) if names else text

    def discrete_position(self, key: str) -> tuple[int, int, int]:
        """Discrete [x, y, z] bins of an object's reference point (what the object list shows)."""
        assert self._world is not None, "reset() first"
        p = self._world.reference_point(key)
        return pos_to_bin(p[0], "x"), pos_to_bin(p[1], "y"), pos_to_bin(p[2], "z")

    def _is_target(self, key: str) -> bool:
        scene = self._scene
        assert scene is not None
        if key in scene.target_ids:
            return True
        if scene.family == "sorter" and "_hole" in key and scene.goal.target is not None:
            sorter_id, k = key.rsplit("_hole", 1)
            return scene.get(sorter_id).holes[int(k)] in {scene.get(t).shape for t in scene.goal.sorted_ids}
        return False

    def _observe(self) -> Observation:
        world = self._world
        assert world is not None
        descr = {o.key: o for o in world.objects}
        coords = {key: self.discrete_position(key) for key in self._order}
        boxes: dict[str, tuple[int, int, int, int]] = {}
        images: dict[str, np.ndarray] = {}
        if self._renderer is not None:
            from PIL import Image

            from eb_manipulation.render import draw_axes, draw_boxes

            groups: dict[str, set[int]] = {}
            for g in world.geom_owner:
                name = world.model.geom(g).name
                key = name.split("#")[0]
                if key in descr and (descr[key].kind != "sorter"):
                    groups.setdefault(key, set()).add(g)
            boxes, pixels = self._renderer.boxes_and_pixels(world.data, "front", groups)
            front = Image.fromarray(self._renderer.rgb(world.data, "front"))
            if self.params.draw_axes:
                draw_axes(front, world.model, world.data, "front")
            shown = [(str(i + 1), boxes[k]) for i, k in enumerate(self._order) if k in boxes
                     and (self.params.detection_boxes == "all"
                          or (self.params.detection_boxes == "target" and self._is_target(k)))]
            self.tags = {}
            if self.params.detection_boxes != "none" and self._clear_tags():
                self.tags = self._draw_clear(front, shown, list(groups), pixels)
            elif self.params.detection_boxes != "none":
                self.tags = draw_boxes(front, shown)
            images["front"] = np.asarray(front)
            if self.multi_view:
                images["wrist"] = self._renderer.rgb(world.data, "wrist")
        objects = [
            ObjectInfo(name=f"object {i + 1}", type=descr[k].description, box=boxes.get(k),
                       position=tuple(float(v) for v in coords[k]), label=str(i + 1), is_target=self._is_target(k))
            for i, k in enumerate(self._order)
        ]
        # the only scene text any model gets, language-only ones included: indices and coordinates, no colours
        # or shapes (the original's blind baseline sees exactly this list)
        listing = "{" + ", ".join(f'"object {i + 1}": [{", ".join(str(v) for v in coords[k])}]'
                                  for i, k in enumerate(self._order)) + "}"
        return Observation(images=images, primary="front" if images else None, text=listing,
                           objects=objects, extra_prompt=listing)

    def _clear_tags(self) -> bool:
        layout = self.params.tag_layout
        return layout == "clear" or (layout == "auto" and self.fixed_numbers())

    def _draw_clear(self, front, shown: list[tuple[str, tuple[int, int, int, int]]], keys: list[str],
                    pixels: np.ndarray) -> dict[str, tuple[int, int, int, int]]:
        """Boxes with tags that keep off every listed object's pixels (tagged or not); the tags' rectangles."""
        from eb_manipulation.tags import draw_clear_boxes

        index = {label: j for j, (label, _) in enumerate(shown)}
        to_shown = np.full(len(keys) + 1, -1, dtype=np.int16)  # group index + 1 -> index in ``shown``
        to_other = np.full(len(keys) + 1, -1, dtype=np.int16)
        for g, key in enumerate(keys):
            label = str(self._order.index(key) + 1) if key in self._order else None
            if label in index:
                to_shown[g + 1] = index[label]
            else:
                to_other[g + 1] = g
        placed = draw_clear_boxes(front, shown, to_shown[pixels + 1], to_other[pixels + 1])
        return {label: rect for label, rect, _ in placed}

    def describe(self) -> str:
        """Each object with its colour and shape or kind (for people: the viewer, examples, debugging).

        Never sent to a model: a language-only model gets only the coordinate list, as in the original.
        """
        world = self._world
        assert world is not None
        descr = {o.key: o for o in world.objects}
        coords = {key: self.discrete_position(key) for key in self._order}
        return self._text(coords, descr)

    def _text(self, coords: dict[str, tuple[int, int, int]], descr) -> str:
        world = self._world
        assert world is not None and self._scene is not None
        lines = ["A wooden table seen from the front; the robot arm stands at its far edge. On the table:"]
        for i, k in enumerate(self._order):
            d = descr[k]
            art = "an" if d.description[:1] in "aeiou" else "a"
            what = {"shape": f"{art} {d.description}",
                    "container": f"{art} {d.description} (open box, coordinates of the centre of its opening)",
                    "sponge": "a sponge", "hole": f"the {d.description} (coordinates of the hole's centre)"
                    }.get(d.kind, d.description)
            if d.kind == "area":
                spec = self._scene.get(k)
                dx, dy = spec.extent
                what = (f"{art} {d.description} on the table, {round(dy * 100)} cm from left to right and "
                        f"{round(dx * 100)} cm from front to back, centred at its coordinates")
            x, y, z = coords[k]
            lines.append(f"- object {i + 1}: {what} at [{x}, {y}, {z}]")
        if world.held is not None:
            lines.append(f"The gripper is closed and holds {self._label(world.held)}.")
        else:
            lines.append("The gripper is " + ("open" if world.gripper_open else "closed") + " and holds nothing.")
        return "\n".join(lines)

