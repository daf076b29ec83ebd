"""The environment contract every world plugin implements.

An environment is a small object with :meth:`Env.reset`, :meth:`Env.step` and :meth:`Env.close`
(the Gymnasium shape), typed with pydantic. It also supplies what the planner needs to talk about
it: the action space of the current episode and the prompt parts (role, action rules, guidelines,
in-context examples) written for that world.

Nothing here imports a simulator: plugins import theirs inside their own ``Env`` subclass, which the
core only imports when a run selects it.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar, Literal, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

__all__ = [
    "Action",
    "ActionSpace",
    "DiscreteActionSpace",
    "Env",
    "ObjectInfo",
    "Observation",
    "PlanItemError",
    "PromptParts",
    "StepResult",
    "VisualExample",
    "Task",
    "VectorActionSpace",
]

#: An action is an action id for discrete spaces, or a tuple of ints for vector spaces.
Action = Union[int, tuple[int, ...]]


def _index(action: Action) -> int:
    """A discrete space's action: its index (a vector is a TypeError, as ``int()`` of one always was)."""
    if isinstance(action, tuple):
        raise TypeError(f"a discrete action space takes an action index, got the vector {action!r}")
    return int(action)


def _vector(action: Action) -> tuple[int, ...]:
    """A vector space's action: its components (an index is a TypeError, as iterating one always was)."""
    if isinstance(action, int):
        raise TypeError(f"a vector action space takes a list of integers, got the index {action!r}")
    return action


class PlanItemError(ValueError):
    """A plan item from the model does not name a valid action. The plan is cut at that item."""


class Task(BaseModel):
    """One benchmark task. Tasks are data: plugins load them from versioned task files."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    id: str = Field(min_length=1, max_length=120, pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    """Stable id, unique within its environment (used for resume, seeding, file names and reports)."""
    subset: str = Field(min_length=1)
    """The evaluation subset, e.g. ``base`` or ``long_horizon``."""
    instruction: str = Field(min_length=1)
    """The natural-language instruction shown to the model."""
    metadata: dict[str, Any] = Field(default_factory=dict)
    """Everything else the environment needs to set the task up (scene seed, start pose, goal...)."""


class ObjectInfo(BaseModel):
    """What an augmenter or a report may know about one object in view."""

    model_config = ConfigDict(extra="forbid")

    name: str
    """Instance name as the world calls it, e.g. ``Apple_2`` or ``object 3``."""
    type: str | None = None
    box: tuple[int, int, int, int] | None = None
    """2-D box ``(x0, y0, x1, y1)`` in pixels of the primary image, if visible."""
    position: tuple[float, ...] | None = None
    """3-D position in the world frame (metres), or in the env's discrete frame if it says so."""
    label: str | None = None
    """Short text drawn beside the box (manipulation draws object indices)."""
    is_target: bool = False
    """True for the object(s) the task is about (for the target-only box ablation)."""


class Observation(BaseModel):
    """What the agent perceives after a reset or a step."""

    model_config = ConfigDict(arbitrary_types_allowed=True, extra="forbid")

    images: dict[str, Any] = Field(default_factory=dict)
    """Named RGB images, ``HxWx3`` uint8 numpy arrays (``first_person``, ``overhead``, ``front``, ``wrist``...)."""
    primary: str | None = None
    """Key of the main image in ``images``; the others are extra views for the multi-view ablation."""
    text: str | None = None
    """A text description of what the agent perceives, for language-only runs."""
    objects: list[ObjectInfo] = Field(default_factory=list)
    """Per-object metadata (names, boxes, positions) that augmenters can draw."""
    extra_prompt: str | None = None
    """Text the env adds to every prompt for this observation (manipulation's object coordinates)."""
    visible_objects: list[dict[str, Any]] | None = None
    """What the primary image shows, from segmentation pixels (partial objects at the edge included): one dict
    per object with ``name``, ``type`` and optionally ``colour``, ``aliases`` (the world's names for it),
    ``pixels``, ``edge``. None: the world does not count pixels, and objects with a box stand for it."""
    scene_objects: list[str] | None = None
    """Types of every object the scene holds, in view or not (for error analysis: naming one that is out of view
    is no hallucination; naming a type the scene lacks is). None: the world does not say."""

    @field_validator("images")
    @classmethod
    def _rgb_images(cls, images: dict[str, Any]) -> dict[str, Any]:
        for key, img in images.items():
            if not isinstance(img, np.ndarray) or img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] != 3:
                raise ValueError(f"image {key!r} must be an HxWx3 uint8 numpy array")
        return images

    @property
    def primary_image(self) -> np.ndarray | None:
        if self.primary is None:
            return None
        return self.images.get(self.primary)


class StepResult(BaseModel):
    """The outcome of one :meth:`Env.step`."""

    model_config = ConfigDict(arbitrary_types_allowed=True, extra="forbid")

    observation: Observation
    action_success: bool
    """Whether the action could be executed (a collision, a closed receptacle... make it False)."""
    feedback: str
    """Text feedback from the world, in our wording (why an action failed, what is now held...)."""
    done: bool = False
    """The world ended the episode (task solved or a terminal state). Step limits are the runner's."""
    task_success: bool = False
    progress: float = Field(default=0.0, ge=0.0, le=1.0)
    """Fraction of goal conditions met so far (the paper's subgoal success); 1.0 when solved."""
    info: dict[str, Any] = Field(default_factory=dict)
    """Free-form world state. Keys the core reads (docs/error_analysis.md):

    * ``failure``: why a failed action failed, one of ``"affordance"`` (the object does not support the
      action), ``"precondition"`` (right action, wrong state: closed, hand full, not near), ``"wrong_target"``
      (a look-alike or wrong instance), ``"absent"`` (the action names a thing the scene does not have: a
      wrong belief about the scene, ``not_in_scene``), ``"collision"``, ``"grasp"`` (manipulation); None or
      absent when the action succeeded or the world cannot tell. Recorded per action in ``steps.jsonl``.
    * ``distance_to_goal``: metres (or the world's unit) from the agent to its goal after the action, for the
      navigation-drift label.
    """


class DiscreteActionSpace(BaseModel):
    """Named actions with ids ``0..n-1`` (ALFRED, Habitat, Navigation)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    kind: Literal["discrete"] = "discrete"
    actions: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.actions)

    def describe(self) -> str:
        """The numbered list shown to the model, one ``action id i: name`` line each."""
        return "\n".join(f"action id {i}: {name}" for i, name in enumerate(self.actions))

    def plan_item_schema(self) -> dict[str, Any]:
        return {
            "type": "object",
            "properties": {
                "action_id": {"type": "integer", "description": "The id of the action in the action list."},
                "action_name": {"type": "string", "description": "The action's name, exactly as in the list."},
            },
            "required": ["action_id", "action_name"],
            "additionalProperties": False,
        }

    def plan_item_example(self) -> Any:
        return {"action_id": 0, "action_name": self.actions[0] if self.actions else "..."}

    def plan_item(self, action: Action) -> dict[str, Any]:
        """The JSON plan item a model should write for ``action`` (used by offline baselines)."""
        index = _index(action)
        return {"action_id": index, "action_name": self.actions[index]}

    def parse_plan_item(self, item: Any) -> int:
        """Turn one model plan item into an action id, or raise :class:`PlanItemError`."""
        if isinstance(item, (list, tuple)) and len(item) == 2 and isinstance(item[1], str):
            item = item[0]  # the original's visual-ICL format: [id, name]
        if isinstance(item, dict):
            raw = item.get("action_id", item.get("id"))
            if raw is None and isinstance(item.get("action_name"), str):
                name = item["action_name"].strip()
                if name in self.actions:
                    return self.actions.index(name)
                raise PlanItemError(f"unknown action name {name!r} and no action_id")
        else:
            raw = item
        if isinstance(raw, bool):
            raise PlanItemError(f"action id must be an integer, got {raw!r}")
        if isinstance(raw, str) and raw.strip().lstrip("-").isdigit():
            raw = int(raw.strip())
        if isinstance(raw, float) and raw.is_integer():
            raw = int(raw)
        if not isinstance(raw, int):
            raise PlanItemError(f"action id must be an integer, got {raw!r}")
        if not 0 <= raw < len(self.actions):
            raise PlanItemError(f"action id {raw} is out of range 0..{len(self.actions) - 1}")
        return raw

    def name_of(self, action: Action) -> str:
        return self.actions[_index(action)]


class VectorActionSpace(BaseModel):
    """A fixed-length vector of bounded integers (manipulation's ``[x, y, z, roll, pitch, yaw, gripper]``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    kind: Literal["vector"] = "vector"
    names: tuple[str, ...]
    low: tuple[int, ...]
    high: tuple[int, ...]
    """Inclusive upper bounds."""

    def describe(self) -> str:
        parts = [f"{n} in [{lo}, {hi}]" for n, lo, hi in zip(self.names, self.low, self.high)]
        return "Each action is a list of integers [" + ", ".join(self.names) + "]: " + "; ".join(parts) + "."

    def plan_item_schema(self) -> dict[str, Any]:
        n = len(self.names)
        return {
            "type": "object",
            "properties": {"action": {"type": "array", "items": {"type": "integer"}, "minItems": n, "maxItems": n,
                                      "description": f"One {n}-dimensional action: [" + ", ".join(self.names)
                                      + "], integers within the bounds of the action format."}},
            "required": ["action"],
            "additionalProperties": False,
        }

    def plan_item_example(self) -> Any:
        return {"action": [(lo + hi) // 2 for lo, hi in zip(self.low, self.high)]}

    def plan_item(self, action: Action) -> dict[str, Any]:
        return {"action": [int(v) for v in _vector(action)]}

    def parse_plan_item(self, item: Any) -> tuple[int, ...]:
        if isinstance(item, (list, tuple)) and len(item) == 1 and isinstance(item[0], dict):
            item = item[0]  # [{"action": [...]}], accepted by the original manipulation planner
        if isinstance(item, dict):
            item = item.get("action", item.get("action_id"))
        if isinstance(item, str):
            import json

            try:
                item = json.loads(item)
            except ValueError as exc:
                raise PlanItemError(f"action {item!r} is not a list of integers") from exc
        if not isinstance(item, (list, tuple)) or len(item) != len(self.names):
            raise PlanItemError(f"action must be a list of {len(self.names)} integers, got {item!r}")
        out = []
        for name, value, lo, hi in zip(self.names, item, self.low, self.high):
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            if isinstance(value, bool) or not isinstance(value, int):
                raise PlanItemError(f"{name} must be an integer, got {value!r}")
            if not lo <= value <= hi:
                raise PlanItemError(f"{name}={value} is outside [{lo}, {hi}]")
            out.append(value)
        return tuple(out)

    def name_of(self, action: Action) -> str:
        return "[" + ", ".join(str(int(v)) for v in _vector(action)) + "]"


ActionSpace = Union[DiscreteActionSpace, VectorActionSpace]


class VisualExample(BaseModel):
    """One visual in-context example (``ablation=visual_icl``): text with images, rendered from the world.

    ``text`` is the example's walk-through; ``images`` are PNG bytes shown in order, each where the text has
    the marker ``<image>`` (images without a marker follow the text). Plugins ship the PNGs inside their package.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    text: str
    images: tuple[bytes, ...] = ()


class PromptParts(BaseModel):
    """The world-specific text the planner assembles into a prompt (our wording, the paper's structure)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    role: str
    """Who the agent is and what it is asked to do."""
    action_rules: str = ""
    """How each kind of action works and when it is valid."""
    guidelines: tuple[str, ...] = ()
    """Numbered advice lines (no empty plan, find before interacting, learn from feedback...)."""
    examples: tuple[str, ...] = ()
    """In-context examples, most useful first; the planner shows the first ``n_shot``."""
    output_notes: str = ""
    """Extra notes on the answer format for this world (e.g. how to write a 7-D action)."""
    examples_language_only: tuple[str, ...] | None = None
    """Examples used instead of ``examples`` under ``language_only`` (the original switches sets; None = same)."""
    role_language_only: str | None = None
    """``role`` under ``language_only`` (no image: a blind prompt should not speak of a camera); None = same."""
    action_rules_language_only: str | None = None
    """``action_rules`` under ``language_only``; None = same."""
    guidelines_language_only: tuple[str, ...] | None = None
    """``guidelines`` under ``language_only`` (no "find the target in the image first"); None = same."""
    visual_examples: tuple[VisualExample, ...] = ()
    """Examples with images for ``ablation=visual_icl`` (the paper's visual in-context learning)."""
    first_step_guidance: str = ""
    """A line shown only on the first planner call (navigation: aim for about 1-2 actions)."""
    later_step_guidance: str = ""
    """A line shown on every later planner call (navigation: aim for about 5-6 actions)."""
    text_before_images: bool = False
    """Put the prompt text before the image(s) in the user message (manipulation, as the original)."""
    view_descriptions: dict[str, str] = Field(default_factory=dict)
    """What each image key shows, said in the prompt when it is sent (e.g. the overhead view under multi_view)."""
    field_descriptions: dict[str, str] = Field(default_factory=dict)
    """The world's own wording for answer fields (``visual_state_description``...), in the prompt and the schema
    (the original's manipulation guide asks for each boxed object's colour, shape and coordinates)."""


class Env(ABC):
    """Base class for benchmark environments.

    Subclasses set :attr:`name` and implement the abstract methods. The runner creates one instance
    per worker process with the ``env.params`` mapping of the config as keyword arguments, then calls
    ``reset(task, seed)`` / ``step(action)`` until the episode ends, and ``close()`` at the end.
    """

    #: Registered name, e.g. ``"navigation"``.
    name: ClassVar[str] = ""

    @classmethod
    @abstractmethod
    def load_tasks(cls, **params: Any) -> list[Task]:
        """All tasks of the environment in their stable order, without starting a simulator."""

    @abstractmethod
    def reset(self, task: Task, seed: int) -> Observation:
        """Set the world up for ``task`` and return the first observation."""

    @abstractmethod
    def step(self, action: Action) -> StepResult:
        """Execute one action."""

    @abstractmethod
    def action_space(self) -> ActionSpace:
        """The action space of the current episode (ALFRED's depends on the scene)."""

    @abstractmethod
    def prompt_parts(self) -> PromptParts:
        """Role, action rules, guidelines and examples for the current episode's subset."""

    #: Why the last :meth:`expert_plan` returned None (e.g. "the only Apple was sliced before it was rinsed").
    expert_reason: str | None = None

    def expert_plan(self) -> list[Action] | None:
        """A plan from the CURRENT state (whatever actions led there) that reaches the goal, shortest or close
        to it; None when the goal can no longer be reached or no expert exists, with :attr:`expert_reason` set."""
        return None

    @classmethod
    def audit_probes(cls) -> list[Any]:
        """World-specific shortcut probes for ``eb audit`` (:class:`eb_core.audit.contract.AuditProbe` objects).

        Worlds name theirs on their ``EnvSpec`` instead (``audit_probes="module:function"``), which the audit
        prefers; this class-level hook stays for plugins written before that field."""
        return []

    @classmethod
    def audit_blind_policies(cls) -> list[Any]:
        """Named blind policies for ``eb audit``'s ``blind_policies`` probe, beside the generic ones
        (:class:`eb_core.audit.contract.BlindPolicy` objects, e.g. a keypad's factory code). Default: none."""
        return []

    #: Generated task splits besides ``test`` (the shipped tasks) that :meth:`split_tasks` serves.
    splits: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def split_tasks(cls, split: str, start: int, count: int, **params: Any) -> list[Task]:
        """Tasks ``start .. start + count - 1`` of a generated split (``train``, ``val``) for training.

        Task ``i`` must be fixed by ``(world, split, i)`` alone, drawn from scene and generator seeds disjoint
        from the shipped test tasks, with no test instruction verbatim. Worlds that implement it list the split
        names in :attr:`splits`. The default has none."""
        others = ", ".join(_worlds_with_splits()) or "none installed"
        raise ValueError(f"env {cls.name or cls.__name__!r} has no generated {split!r} split (only 'test', its "
                         f"shipped tasks); worlds with train/val splits: {others}. Use split=test or one of those.")

    def close(self) -> None:
        """Release simulator resources. Called once; must be safe to call again."""


def _worlds_with_splits() -> list[str]:
    """Names of the installed worlds whose env class serves ``train``/``val`` (for the error above)."""
    try:
        from eb_core.plugins import Registry

        names = []
        for name, spec in Registry.create().envs.items():
            try:
                if "train" in getattr(spec.load(), "splits", ()):
                    names.append(name)
            except Exception:  # a broken plugin must not hide the real error
                continue
        return names
    except Exception:
        return []
