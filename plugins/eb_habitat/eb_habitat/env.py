"""``HabitatEnv``: the EB-Habitat environment (language rearrangement with 70 fixed high-level skills).

The symbolic world (:mod:`eb_habitat.world`) decides everything; with ``render=True`` (the default) a MuJoCo
apartment (:mod:`eb_habitat.render`) draws the first-person view after each step. ``render=False`` gives
text-only observations without importing MuJoCo, for fast oracle and logic checks.
"""

from __future__ import annotations

import re
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from eb_core.env import (
    Action,
    DiscreteActionSpace,
    Env,
    ObjectInfo,
    Observation,
    PromptParts,
    StepResult,
    Task,
)
from eb_habitat import prompts
from eb_habitat.catalog import DECOR, object_type
from eb_habitat.goals import GoalTracker, Predicate
from eb_habitat.oracle import OracleError, expert_plan
from eb_habitat.skills import SKILL_NAMES, SKILLS
from eb_habitat.tasks import TaskSpec, load_tasks, spec_of
from eb_habitat.world import Item, World, item_label

__all__ = ["HabitatEnv", "HabitatParams"]


class HabitatParams(BaseModel):
    """The ``params:`` of ``conf/env/habitat.yaml``."""

    model_config = ConfigDict(extra="forbid")

    render: bool = True
    """Draw first-person images with MuJoCo. False: text observations only (no MuJoCo import)."""
    task_file: str | None = None
    """A task file, or a folder of them, to load instead of the shipped ones (``eb tasks generate env=habitat
    out=...``)."""
    task_dir: str | None = None
    """The old spelling of ``task_file`` (a folder); still accepted."""
    difficulty: str | None = None
    """Generator level of the generated train/val splits (classic, medium, hard); default: the taskset's."""

    def tasks_path(self) -> str | None:
        return self.task_file or self.task_dir


def _params(params: dict[str, Any]) -> HabitatParams:
    try:
        return HabitatParams(**params)
    except ValidationError as exc:
        err = exc.errors()[0]
        key = ".".join(str(p) for p in err["loc"])
        if err["type"] == "extra_forbidden":
            raise ValueError(f"habitat env: unknown param {key!r}; allowed: "
                             f"{', '.join(HabitatParams.model_fields)}") from None
        raise ValueError(f"habitat env: param {key!r}: {err['msg']}") from None


def _wrong_target(kind: str, arg: str, held_before: Item | None, full_before: bool, world: World,
                  unmet: list[Predicate]) -> bool:
    """Whether a skill that just SUCCEEDED acted on the wrong instance relative to the goal still unmet before it:

    * a pick took an object of a kind the goal wants as one named instance (``mug_2``), but another instance of
      that kind that no goal predicate asks for (a look-alike: the other mug) -- unless it was taken off a full
      receptacle an unmet predicate needs, which makes room there (what the expert does);
    * a place put down an object an unmet goal predicate wants moved, on a receptacle none of those predicates
      names (the goal object, the wrong receptacle).

    Navigating, opening and closing never count: they pick no instance.
    """
    if kind == "pick":
        item = world.held_item
        if item is None:
            return False
        wanted = [p for p in unmet if p.name in ("on", "inside", "holding")]
        if any(p.matches(item.name, item.type) for p in wanted):
            return False
        if full_before and any(p.target == world.agent_at for p in wanted):
            return False
        return any(p.obj == inst for p in wanted for inst in world.items
                   if world.items[inst].type == item.type and inst != item.name)
    if kind == "place" and held_before is not None:
        moves = [p for p in unmet if p.name in ("on", "inside") and p.matches(held_before.name, held_before.type)]
        return bool(moves) and all(p.target != arg for p in moves)
    return False


def _scene_key(spec: TaskSpec) -> tuple[Any, ...]:
    """What :meth:`eb_habitat.render.ApartmentRenderer.load` compiles a scene for (its reuse check; that check
    still decides, this one only picks whether the previous renderer is asked first)."""
    return (spec.apartment, tuple((o.name, o.type, o.color) for o in spec.objects))


class HabitatEnv(Env):
    """EB-Habitat. One instance per worker; ``reset`` builds the task's apartment, ``step`` runs one skill."""

    name = "habitat"

    def __init__(self, resolution: int = 500, multi_view: bool = False, **params: Any) -> None:
        self.params = _params(params)
        self.resolution = int(resolution)
        self.multi_view = bool(multi_view)
        self._space = DiscreteActionSpace(actions=SKILL_NAMES)
        self._renderer: Any = None
        self._task: Task | None = None
        self._spec: TaskSpec | None = None
        self._world: World | None = None
        self._tracker: GoalTracker | None = None
        self._closed = False

    # -- tasks -----------------------------------------------------------------------------------

    @classmethod
    def load_tasks(cls, taskset: str = "classic", **params: Any) -> list[Task]:
        """The shipped tasks of ``taskset`` (``classic`` or ``hard``), or the file/folder in ``task_file``."""
        p = _params(params)
        return load_tasks(p.tasks_path(), taskset=taskset)

    # -- episode ---------------------------------------------------------------------------------

    def reset(self, task: Task, seed: int) -> Observation:
        if self._closed:
            raise RuntimeError("HabitatEnv.reset() after close()")
        self._task = task
        self._spec = spec_of(task)
        self._world = self._spec.world()
        self._tracker = self._spec.tracker()
        self._tracker.update(self._world)
        if not self.params.render:
            return self._observe()
        from eb_habitat.render import ApartmentRenderer

        previous = self._renderer
        if previous is not None and getattr(previous, "_key", None) == _scene_key(self._spec):
            previous.load(self._spec)  # the same apartment with the same objects: no recompile
            return self._observe()
        # Another scene: it is built and drawn before the previous one is closed. While one GL context of the
        # process stays alive, making the next one is cheap (and a renderer pooled per process keeps it); closing
        # first made every reset start GL from nothing.
        self._renderer = ApartmentRenderer(self.resolution, multi_view=self.multi_view)
        try:
            self._renderer.load(self._spec)
            return self._observe()
        finally:
            if previous is not None:
                previous.close()

    def step(self, action: Action) -> StepResult:
        if self._world is None or self._tracker is None:
            raise RuntimeError("HabitatEnv.step() before reset()")
        if isinstance(action, bool) or not isinstance(action, int) or not 0 <= action < len(SKILLS):
            raise ValueError(f"habitat action must be an id in 0..{len(SKILLS) - 1}, got {action!r}")
        skill = SKILLS[int(action)]
        unmet_before = self._tracker.unmet(self._world)
        held_before = self._world.held_item
        here = self._world.agent_at
        full_before = here is not None and self._world.free_slot(here) is None
        outcome = self._world.step(int(action))
        wrong = outcome.success and _wrong_target(skill.kind, skill.arg, held_before, full_before, self._world,
                                                  unmet_before)
        self._tracker.update(self._world)
        success = self._tracker.success(self._world)
        feedback = outcome.feedback
        if success:
            feedback += " Every goal of the task is now met."
        return StepResult(
            observation=self._observe(),
            action_success=outcome.success,
            feedback=feedback,
            done=success,
            task_success=success,
            progress=self._tracker.progress(self._world),
            info={
                "skill": SKILL_NAMES[int(action)],
                "agent_at": self._world.agent_at,
                "holding": self._world.held,
                "unmet_goals": [str(p) for p in self._tracker.unmet(self._world)],
                "subgoals_reached": sum(self._tracker.reached),
                "subgoals_total": len(self._tracker.subgoals),
                "failure": outcome.failure,
                **({"wrong_target": True} if wrong else {}),
            },
        )

    def _observe(self) -> Observation:
        assert self._world is not None and self._tracker is not None
        w = self._world
        targets = {p.obj for p in self._tracker.goal if p.obj is not None}
        visible = w.visible_items() + ([w.held_item] if w.held_item is not None else [])
        boxes: dict[str, tuple[int, int, int, int]] = {}
        positions: dict[str, tuple[float, float, float]] = {}
        images: dict[str, Any] = {}
        if self._renderer is not None and self.params.render:
            images = self._renderer.render(w)
            boxes = self._renderer.boxes()
            positions = self._renderer.positions()
        objects = [
            ObjectInfo(
                name=it.name,
                type=it.type,
                box=boxes.get(it.name),
                position=positions.get(it.name),
                label=item_label(it) + (" (in hand)" if it.name == w.held else ""),
                is_target=it.name in targets or f"?{it.type}" in targets,
            )
            for it in visible
        ]
        return Observation(
            images=images,
            primary="first_person" if images else None,
            text=w.describe(),
            objects=objects,
            visible_objects=[_in_view(it) for it in visible if it.name in boxes] if images else None,
            scene_objects=sorted({object_type(it.type).name for it in w.items.values()} | set(DECOR)),
        )

    # -- planner support -------------------------------------------------------------------------

    def action_space(self) -> DiscreteActionSpace:
        return self._space

    def prompt_parts(self) -> PromptParts:
        return prompts.prompt_parts(self._task.subset if self._task is not None else None)

    def expert_plan(self) -> list[Action] | None:
        """The expert's plan from the current world state only (not from the episode's history); None with
        :attr:`expert_reason` set when no plan reaches the goal from here."""
        if self._world is None or self._tracker is None:
            self.expert_reason = "no episode: call reset() first"
            return None
        try:
            plan = list(expert_plan(self._world, self._tracker.goal))
        except OracleError as exc:
            self.expert_reason = str(exc)
            return None
        self.expert_reason = None
        return plan

    splits = ("train", "val")

    @classmethod
    def split_tasks(cls, split: str, start: int, count: int, taskset: str = "classic", **params: Any) -> list[Task]:
        """Generated train/val tasks, disjoint from the shipped ones (:mod:`eb_habitat.splits`); ``taskset=hard``
        (or ``env.params.difficulty``) draws them at that generator level."""
        from eb_habitat.splits import split_tasks

        p = _params(params)
        return split_tasks(split, start, count, task_dir=p.tasks_path(), difficulty=p.difficulty or taskset)

    def close(self) -> None:
        self._closed = True
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def _in_view(item: Item) -> dict[str, Any]:
    """One item the first-person segmentation shows, with its colour and the names a person may use for it (for
    error analysis: "yellow squeeze bottle" for the mustard bottle)."""
    t = object_type(item.type)
    looks = re.split(r",| with | whose | narrow ", t.looks.format(color=item.color))[0]  # "a yellow squeeze bottle"
    return {"name": item.name, "type": t.name, "colour": item.color, "aliases": [*t.aliases, looks]}
