"""``AlfredEnv``: the EB-ALFRED environment behind ``env=alfred``.

The symbolic world (:mod:`eb_alfred.world`) decides everything: what an action does, the feedback, success
and progress. Rendering is a separate, optional view of that state (:mod:`eb_alfred.render`, MuJoCo through
the scene kit); with ``render: false`` no MuJoCo is imported at all and observations carry text only.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

from pydantic import BaseModel, ConfigDict, ValidationError

from eb_core import Action, DiscreteActionSpace, Env, Observation, ObjectInfo, PromptParts, StepResult, Task

from eb_alfred.actions import scene_actions
from eb_alfred.describe import describe
from eb_alfred.goals import conditions, evaluate, failure_label
from eb_alfred.oracle import expert_plan as _expert_plan
from eb_alfred.oracle import why_unreachable
from eb_alfred.prompts import prompt_parts as _prompt_parts
from eb_alfred.tasks import load_all, load_task_file
from eb_alfred.world import World

__all__ = ["AlfredEnv", "AlfredParams"]


class AlfredParams(BaseModel):
    """The ``params:`` mapping of ``conf/env/alfred.yaml``."""

    model_config = ConfigDict(extra="forbid")

    render: bool = True
    """Render first-person images with MuJoCo; false = symbolic only (text observations, fast)."""
    task_file: str | None = None
    """Load tasks from this file, or from this folder of per-subset files, instead of the shipped set (e.g. after
    ``eb tasks generate``)."""
    task_dir: str | None = None
    """The old spelling of ``task_file`` (a folder); still accepted."""
    difficulty: str | None = None
    """Generator level of the generated train/val splits (classic, medium, hard); default: the taskset's."""

    def tasks_path(self) -> str | None:
        return self.task_file or self.task_dir


def _params(params: dict[str, Any]) -> AlfredParams:
    try:
        return AlfredParams(**params)
    except ValidationError as exc:
        err = exc.errors()[0]
        key = ".".join(str(p) for p in err["loc"])
        if err["type"] == "extra_forbidden":
            raise ValueError(f"unknown alfred param '{key}'; allowed: {', '.join(AlfredParams.model_fields)}") from None
        raise ValueError(f"invalid alfred param '{key}': {err['msg']}") from None


class AlfredEnv(Env):
    """High-level household tasks: find, pick up, put down, drop, open, close, turn on/off, slice."""

    name: ClassVar[str] = "alfred"

    def __init__(self, resolution: int = 500, multi_view: bool = False, **params: Any) -> None:
        self.params = _params(params)
        self.resolution = int(resolution)
        self.multi_view = bool(multi_view)
        self._task: Task | None = None
        self._world: World | None = None
        self._goal: dict[str, Any] | None = None
        self._space: DiscreteActionSpace | None = None
        self._renderer: Any = None
        self._closed = False

    # ------------------------------------------------------------------ tasks
    @classmethod
    def load_tasks(cls, taskset: str = "classic", **params: Any) -> list[Task]:
        p = _params(params)
        path = p.tasks_path()
        if path is not None and Path(path).is_file():
            records = load_task_file(path)
        else:
            records = load_all(Path(path) if path else None, taskset=taskset)
        return [
            Task(id=r.id, subset=r.subset, instruction=r.instruction,
                 metadata={"task_type": r.task_type, "goal": r.goal.plain(),
                           "scene": r.scene.model_dump(exclude_defaults=True), "scene_seed": r.scene_seed,
                           "oracle_steps": r.oracle_steps, "notes": r.notes, "template": r.template})
            for r in records
        ]

    splits: ClassVar[tuple[str, ...]] = ("train", "val")

    @classmethod
    def split_tasks(cls, split: str, start: int, count: int, taskset: str = "classic", **params: Any) -> list[Task]:
        """Generated train/val tasks, disjoint from the shipped ones (:mod:`eb_alfred.splits`); ``taskset=hard``
        (or ``env.params.difficulty``) draws them at that generator level."""
        from eb_alfred.splits import split_tasks

        p = _params(params)
        return split_tasks(split, start, count, task_dir=p.tasks_path(), difficulty=p.difficulty or taskset)

    # ------------------------------------------------------------------ episode
    def reset(self, task: Task, seed: int) -> Observation:
        self._task = task
        self._world = World.from_scene(task.metadata["scene"])
        self._goal = task.metadata["goal"]
        self._space = DiscreteActionSpace(actions=scene_actions(self._world))
        self.expert_reason = None
        if not self.params.render:
            return self._observe()
        from eb_alfred.render import AlfredRenderer

        # The new task's scene is built and drawn before the previous one is closed: while one scene of the
        # process still uses the pooled GL context it stays alive and is only pointed at the new model. Closing
        # first freed it, and every reset paid for a new context (measured: median reset 0.39-0.56 s -> 0.17-0.22 s
        # under load 8; images are the pool's, byte-identical).
        previous = self._renderer
        keep = {} if previous is None else {"shared_gl": previous.shared_gl}  # private GL, once asked for, stays
        self._renderer = AlfredRenderer(self.resolution, multi_view=self.multi_view, **keep)
        try:
            self._renderer.load(self._world)
            return self._observe()
        finally:
            if previous is not None:
                previous.close()

    def step(self, action: Any) -> StepResult:
        world, space = self._require()
        try:
            idx = int(action)
        except (TypeError, ValueError):
            idx = -1
        if not 0 <= idx < len(space):
            obs = self._observe()
            return StepResult(observation=obs, action_success=False,
                              feedback=f"Failed: action id {action!r} is not in the list (0..{len(space) - 1}).",
                              progress=self._progress(), info={"action_name": None})
        name = space.actions[idx]
        ok, feedback = world.step(name)
        success, progress, flags = evaluate(self._goal, world)
        obs = self._observe()
        if success:
            feedback += " The task is complete."
        return StepResult(observation=obs, action_success=ok, feedback=feedback, done=success,
                          task_success=success, progress=1.0 if success else progress,
                          info={"action_name": name, "conditions": flags, "held": world.held,
                                "place": world.place, "failure": None if ok else self._failure(world)})

    def action_space(self) -> DiscreteActionSpace:
        return self._require()[1]

    def prompt_parts(self) -> PromptParts:
        subset = self._task.subset if self._task is not None else "base"
        actions = self._space.actions if self._space is not None else None
        return _prompt_parts(subset, actions=actions, leave_alone=bool((self._goal or {}).get("untouched")))

    def expert_plan(self) -> list[Action] | None:
        """The shortest plan the expert finds from the current state (a function of the state only); None with
        :attr:`expert_reason` set when the goal can no longer be reached."""
        world, space = self._require()
        plan = _expert_plan(world, self._goal)
        if plan is None:
            self.expert_reason = why_unreachable(world, self._goal)
            return None
        self.expert_reason = None
        return [space.actions.index(a) for a in plan]

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._closed = True

    # ------------------------------------------------------------------ helpers
    @property
    def world(self) -> World:
        """The symbolic state (read it, do not change it)."""
        return self._require()[0]

    def goal_conditions(self) -> list[str]:
        return [c.text for c in conditions(self._goal)]

    def _require(self) -> tuple[World, DiscreteActionSpace]:
        if self._world is None or self._space is None:
            raise RuntimeError("call reset(task, seed) before using the environment")
        return self._world, self._space

    def _progress(self) -> float:
        return evaluate(self._goal, self._world)[1]

    def _observe(self) -> Observation:
        world = self._world
        assert world is not None
        text = describe(world)
        if self._renderer is None:
            return Observation(text=text)
        frame = self._renderer.render(world)
        objects = [ObjectInfo(name=o["name"], type=o["type"], box=o.get("box"), position=o.get("position"),
                              is_target=self._is_target(o["name"]))
                   for o in frame.objects]
        return Observation(images=frame.images, primary="first_person", text=text, objects=objects,
                           visible_objects=[_in_view(world, o) for o in frame.objects],
                           scene_objects=sorted({o.type for o in world.objects.values()}))

    def _failure(self, world: World) -> str | None:
        """The failure label of the action that just failed: the world's own reason, except that a failure in
        the wrong state on a look-alike of something the goal singles out (by instance, colour or shape) is a
        wrong target -- the state was not the agent's real mistake."""
        return failure_label(world, self._goal or {})

    def _is_target(self, name: str) -> bool:
        from eb_alfred.goals import matches

        goal = self._goal or {}
        return any(key in goal and matches(self._world, goal[key], name)
                   for key in ("object", "receptacle", "movable", "lamp"))


def _in_view(world: Any, o: dict[str, Any]) -> dict[str, Any]:
    """One object the frame's segmentation shows, with its colour and plain noun (for error analysis)."""
    from eb_alfred.catalog import TYPES

    obj = world.objects.get(o["name"])
    info = TYPES.get(o["type"])
    return {"name": o["name"], "type": o["type"], "colour": getattr(obj, "color", None),
            "colours": o.get("colours", []), "aliases": [info.noun] if info is not None else [],
            "pixels": o.get("pixels")}
