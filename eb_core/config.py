"""Pydantic models that validate the composed Hydra config (``extra="forbid"``: a typo names its key)."""

from __future__ import annotations

import sys
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from eb_core.exceptions import ConfigError

__all__ = ["AblationConfig", "EnvConfig", "ModelConfig", "PlannerConfig", "RunConfig", "RunnerConfig", "ConfigError",
           "validate_config"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class EnvConfig(_Strict):
    """``conf/env/<name>.yaml``, shipped by the env plugin."""

    name: str
    """Registered env name (``eb list`` shows them)."""
    max_steps: int = Field(gt=0)
    """Environment-step budget per episode (ALFRED 30, Habitat 30, Navigation 20, Manipulation 15)."""
    max_invalid_actions: int | None = None
    """End the episode after this many invalid actions (10 for ALFRED and Habitat); None = no cap."""
    replan_on_failure: bool = True
    """Stop executing a plan at its first failed action and ask the model again."""
    empty_plan_ends: bool = True
    """An empty plan ends the episode (ALFRED, Habitat, Manipulation); else it counts as an output error."""
    default_n_shot: int = Field(default=3, ge=0)
    """In-context examples shown when ``planner.n_shot`` is null."""
    resolution: int = Field(default=500, ge=64, le=2048)
    """Image side in pixels (the paper's ablation uses 300, 500, 700)."""
    multi_view: bool = False
    """Render the extra view (navigation: overhead; manipulation: wrist) and send it to the model."""
    output_error_uses_step: bool = True
    """An unparsable answer uses one step of the budget (Navigation, Manipulation); False: it counts as an
    invalid output only (ALFRED, Habitat, as the original)."""
    chat_history_window: int | None = None
    """Messages kept under ``chat_history`` (the original: 5 for Navigation); None = the whole episode."""
    subset_aliases: dict[str, str] = Field(default_factory=dict)
    """Other names accepted for subsets (``spatial`` -> ``spatial_awareness``), in ``subset=`` and reports."""
    params: dict[str, Any] = Field(default_factory=dict)
    """Env-specific constructor arguments, validated by the env itself."""


class ModelConfig(BaseModel):
    """``conf/model/<name>.yaml``. Common keys are checked here; the backend validates the rest."""

    model_config = ConfigDict(extra="allow")

    name: str
    """Preset name (``gpt-4o``, ``oracle``...)."""
    backend: str
    """Registered model backend (``litellm``, ``oracle``, ``random``, ``replay``, ``human``)."""
    max_cost_usd: float | None = Field(default=None, gt=0)
    """Stop the run cleanly (finished episodes kept) once model calls have cost this much."""

    def backend_kwargs(self) -> dict[str, Any]:
        return {k: v for k, v in self.model_dump().items() if k not in ("name", "backend", "max_cost_usd")}


class PlannerConfig(_Strict):
    """``conf/planner/vlm.yaml``: the paper's agent pipeline and its ablation switches."""

    name: str = "vlm"
    n_shot: int | None = Field(default=None, ge=0)
    """In-context examples to show; null = the env's default."""
    feedback: bool = True
    """Show the environment's feedback text in the action history."""
    chat_history: bool = False
    """Send earlier turns as chat messages (the paper found this can hurt; off by default)."""
    history_window: int | None = Field(default=None, ge=1)
    """Messages kept under ``chat_history`` (the current one included); null = ``env.chat_history_window``."""
    multi_step_images: int = Field(default=1, ge=1)
    """Send the frames after the last k environment steps instead of only the current one."""
    language_only: bool = False
    """The paper's blind baseline: no image and no scene text (``Observation.extra_prompt`` is still shown)."""
    text_state: bool = False
    """Our upper-bound ablation: no image, the env's symbolic ``Observation.text`` instead (perfect perception)."""
    visual_icl: bool = False
    """The paper's visual in-context learning: the world's examples with their images, no text examples."""
    json_schema: Literal["auto", "always", "never"] = "auto"
    """Ask for schema-constrained output: auto = when the backend supports it."""
    max_plan_length: int = Field(default=20, ge=1)
    """Plans longer than this are cut (the guidelines tell the model so)."""
    answer_format: Literal["json", "think"] = "json"
    """``json``: the benchmark's answer, one JSON object. ``think``: reasoning first, then the JSON object,
    as ``<think>...</think><answer>{...}</answer>`` (R1-style RL-trained models); the JSON is read from the
    answer tags, and an answer without them is an output error."""

    @model_validator(mode="after")
    def _one_observation_mode(self) -> PlannerConfig:
        if self.language_only and self.text_state:
            raise ValueError("language_only (blind) and text_state (scene text) exclude each other; set one of them")
        return self


class AblationConfig(_Strict):
    name: str = "none"
    description: str = ""


class AugmenterConfig(BaseModel):
    model_config = ConfigDict(extra="allow")
    name: str


class RunnerConfig(_Strict):
    workers: int = Field(default=1, ge=1, le=256)
    """Environment processes (Ray actors under ``executor: ray``). Each drives ``concurrency / workers``
    episodes at once, with one env per episode in flight, stepping them on its main thread while their
    model calls wait on a thread pool."""
    concurrency: int | None = Field(default=None, ge=1, le=4096)
    """Episodes in flight across all workers; null = ``workers`` (one episode per process, as before)."""
    executor: Literal["local", "ray"] = "local"
    """``local``: worker processes on this machine. ``ray``: env actors on a Ray cluster (``pip install
    "embodiedbench[ray]"``); the driver (this process) still writes the run directory. See docs/scaling.md."""
    ray_address: str | None = None
    """Ray cluster to join under ``executor: ray``: ``auto`` on a cluster node, ``ray://host:10001``...;
    null = ``$RAY_ADDRESS``, or a local single-machine Ray started for the run when that is unset too."""
    repeats: int = Field(default=1, ge=1, le=100)
    """Play every task this many times (seeds from the run seed, task id and repeat; repeat 0 keeps the
    single-run seed). Intervals then also reflect within-task noise; see docs/statistics.md."""
    save_images: bool = True
    """Write the image the model saw at every planner step as PNG."""
    quiet: bool = False
    """Plain progress lines instead of the live display."""
    episode_timeout_s: float | None = Field(default=None, gt=0)
    """An episode running longer than this is recorded as an error (redone on resume): its worker drops it
    while it waits for the model, and the worker process is killed if it is stuck in the env (its other
    in-flight episodes are then recorded as errors too)."""
    expert_labels: bool = False
    """Record in every step what the world's expert would do from the state the agent was in
    (``expert_action`` in steps.jsonl), for error analysis and expert relabelling."""
    start_method: Literal["fork", "spawn", "forkserver"] = "fork" if sys.platform == "linux" else "spawn"
    """How worker processes start. ``fork`` (Linux default) inherits the already imported model SDK and
    simulator modules, so a worker is ready at once; ``spawn`` starts each from scratch."""


class RunConfig(_Strict):
    env: EnvConfig
    model: ModelConfig
    planner: PlannerConfig
    ablation: AblationConfig
    augmenters: list[AugmenterConfig] = Field(default_factory=list)
    runner: RunnerConfig = Field(default_factory=RunnerConfig)
    seed: int = 0
    subset: str | list[str] | None = None
    """One subset name, a list, or null for all."""
    limit: int | None = Field(default=None, ge=1)
    """Take the first N tasks of the selection in their stable order."""
    sample: int | None = Field(default=None, ge=1)
    """Play K tasks of every selected subset: a simple random sample drawn with ``seed`` (a cheap, unbiased
    estimate of each subset's rate, e.g. ``sample=2`` for 12 tasks of a six-subset world)."""
    tasks: list[str] | None = None
    """Explicit task ids (overrides subset and limit)."""
    experiment: str = "default"
    """Part of the run directory name; re-running the same command with it resumes."""
    split: str = "test"
    """``test`` = the shipped benchmark tasks; ``train``/``val`` = tasks generated by worlds that have such
    splits (:meth:`eb_core.env.Env.split_tasks`), the first ``limit`` of them."""
    taskset: str = Field(default="classic", pattern=r"^[a-z][a-z0-9_]*$")
    """Which shipped task set of the world: ``classic`` (the paper's 1,128 tasks, the default) or another set the
    world lists in :attr:`eb_core.specs.EnvSpec.tasksets` (``hard``). Same protocol, other scenes and
    instructions."""


def _loc(err: Any) -> str:
    return ".".join(str(p) for p in err["loc"])


def validate_config(cfg: dict[str, Any]) -> RunConfig:
    """Validate a plain-dict config; raise :class:`ConfigError` with one line on the first problem."""
    try:
        return RunConfig.model_validate(cfg)
    except ValidationError as exc:
        err = exc.errors()[0]
        key = _loc(err)
        if err["type"] == "extra_forbidden":
            parent = key.rsplit(".", 1)[0] if "." in key else ""
            model: Any = RunConfig
            for part in parent.split(".") if parent else []:
                field = model.model_fields.get(part)
                model = field.annotation if field is not None else None
                if not (isinstance(model, type) and issubclass(model, BaseModel)):
                    model = None
                    break
            allowed = ", ".join(model.model_fields) if model is not None else "see --cfg job"
            raise ConfigError(f"unknown config key '{key}'; allowed here: {allowed}. Fix the spelling.") from None
        raise ConfigError(f"invalid config value for '{key}': {err['msg']} (got {err.get('input')!r})") from None
