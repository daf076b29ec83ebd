"""What one process needs to play a run's episodes, shared by the runner, its worker processes, the Ray actors,
the gym env and ``eb verify``: the built components of a config, task selection, episode seeds, the labels of a
finished episode.

It holds the pieces :mod:`eb_core.runner` and :mod:`eb_core.ray_executor` both use, so neither imports the other.
"""

from __future__ import annotations

import hashlib
import importlib
import random
from collections.abc import Sequence
from typing import Any

from eb_core.config import ConfigError, RunConfig
from eb_core.env import Env, Task
from eb_core.episode import BudgetGuard, EpisodeOptions
from eb_core.model import ModelBackend
from eb_core.plugins import Registry, get_plugin_manager
from eb_core.records import EpisodeRecord, RunFiles, StepRecord

__all__ = ["Components", "RunError", "build_registry", "episode_seed", "label_record", "one_line", "select_tasks"]


class RunError(RuntimeError):
    """The run cannot start or had to stop; the message is one line for the user."""


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (at most 600 characters)."""
    return "; ".join(ln.strip() for ln in str(exc).splitlines() if ln.strip())[:600]


def episode_seed(run_seed: int, task_id: str, repeat: int = 0) -> int:
    """Every episode is seeded from the run seed, its task id and its repeat (independent of order and
    workers). Repeat 0 keeps the seed of single-repeat runs, so their results stay valid."""
    key = f"{run_seed}:{task_id}" if repeat == 0 else f"{run_seed}:{task_id}:{repeat}"
    digest = hashlib.sha256(key.encode()).digest()
    return int.from_bytes(digest[:4], "little")


def build_registry(plugin_modules: Sequence[str]) -> Registry:
    """A registry with the default plugins plus ``plugin_modules`` imported by name (in a worker process)."""
    plugins = [importlib.import_module(m) for m in plugin_modules]
    return Registry(get_plugin_manager(plugins=plugins))


class Components:
    """Everything one process needs to play episodes, built from a validated config."""

    def __init__(self, cfg: RunConfig, registry: Registry) -> None:
        self.cfg = cfg
        self.registry = registry
        self.env_spec: Any = registry.get("env", cfg.env.name)  # an EnvSpec
        self.env_cls: Any = self.env_spec.load()  # a subclass of Env, built with resolution, multi_view, params
        self.backend_spec = registry.get("model backend", cfg.model.backend)
        self.backend_cls: type[ModelBackend] = self.backend_spec.load()
        self.planner_cls = registry.get("planner", cfg.planner.name).load()
        self.augmenters = []
        for aug in cfg.augmenters:
            cls = registry.get("augmenter", aug.name).load()
            kwargs = {k: v for k, v in aug.model_dump().items() if k != "name"}
            try:
                self.augmenters.append(cls(**kwargs))
            except (TypeError, ValueError) as exc:
                raise ConfigError(f"augmenter {aug.name!r}: {exc}") from None

    def task_params(self) -> dict[str, Any]:
        """The keyword arguments of ``Env.load_tasks``/``split_tasks``: ``env.params`` plus ``taskset`` when it is
        not the classic set (checked against the world's :attr:`~eb_core.specs.EnvSpec.tasksets`)."""
        params = dict(self.cfg.env.params)
        taskset = self.cfg.taskset
        if taskset != "classic":
            if taskset not in self.env_spec.tasksets:
                raise ConfigError(f"unknown taskset {taskset!r} for env {self.cfg.env.name!r}; available: "
                                  f"{', '.join(self.env_spec.tasksets)}. Fix: taskset=classic or one of those.")
            params["taskset"] = taskset
        return params

    def load_tasks(self) -> list[Task]:
        split = self.cfg.split
        params = self.task_params()
        if split == "test":
            return self.env_cls.load_tasks(**params)
        if self.cfg.limit is None:
            raise ConfigError(f"split={split} is generated on demand: say how many tasks with limit=N "
                              f"(e.g. limit=300)")
        try:
            return self.env_cls.split_tasks(split, 0, self.cfg.limit, **params)
        except ValueError as exc:
            raise ConfigError(str(exc).splitlines()[0]) from None

    def make_env(self, **param_overrides: Any) -> Env:
        """The configured env; ``param_overrides`` replace some of ``env.params`` (``eb verify``: render off)."""
        e = self.cfg.env
        params = {**e.params, **param_overrides}
        try:
            return self.env_cls(resolution=e.resolution, multi_view=e.multi_view, **params)
        except (TypeError, ValueError) as exc:  # includes pydantic's ValidationError of the env's params
            raise ConfigError(f"env {e.name!r} rejected its parameters (env.params={params}): "
                              f"{one_line(exc)}") from None

    def make_backend(self) -> ModelBackend:
        try:
            return self.backend_cls(**self.cfg.model.backend_kwargs())
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"model {self.cfg.model.name!r} (backend {self.cfg.model.backend!r}): "
                              f"{one_line(exc)}") from None

    def make_planner(self, backend: ModelBackend) -> Any:
        return self.planner_cls(self.cfg.planner, self.cfg.env, supports_json_schema=backend.supports_json_schema,
                                supports_images=backend.supports_images)

    def episode_options(self, files: RunFiles, task: Task, repeat: int, *, budget: BudgetGuard | None,
                        hook: Any) -> EpisodeOptions:
        """The options of one episode of the run: its staging directory and the run's recording settings."""
        cfg = self.cfg
        return EpisodeOptions(step_dir=files.staging_dir(task.id, repeat), save_images=cfg.runner.save_images,
                              augmenters=self.augmenters, budget=budget, hook=hook, run_dir=str(files.root),
                              expert_labels=cfg.runner.expert_labels, repeat=repeat)


def select_tasks(tasks: Sequence[Task], cfg: RunConfig) -> list[Task]:
    """Apply ``tasks=``, ``subset=``, ``sample=`` and ``limit=``: ``sample=K`` keeps a seeded simple random
    sample of K tasks of every selected subset (:func:`sample_of_subsets`); ``limit=N`` takes the first N of the
    selection in one stable order in every world: subset by subset (in the world's subset order), each in its
    task file's order."""
    if cfg.tasks:
        by_id = {t.id: t for t in tasks}
        missing = [t for t in cfg.tasks if t not in by_id]
        if missing:
            raise ConfigError(f"unknown task id(s) {', '.join(missing[:5])} for env {cfg.env.name!r}; "
                              f"ids look like {tasks[0].id!r} (see the env's task file)")
        return [by_id[t] for t in cfg.tasks]
    selected = list(tasks)
    if cfg.subset is not None:
        aliases = cfg.env.subset_aliases
        wanted = [cfg.subset] if isinstance(cfg.subset, str) else list(cfg.subset)
        wanted = [aliases.get(s, s) for s in wanted]
        known = list(dict.fromkeys(t.subset for t in tasks))
        bad = [s for s in wanted if s not in known]
        if bad:
            also = f" (or the aliases {', '.join(sorted(aliases))})" if aliases else ""
            raise ConfigError(f"unknown subset {bad[0]!r} for env {cfg.env.name!r}; available: {', '.join(known)}"
                              f"{also}")
        selected = [t for t in selected if t.subset in wanted]
    if cfg.sample is not None:
        if cfg.limit is not None:
            raise ConfigError(f"sample={cfg.sample} and limit={cfg.limit} both choose how many tasks to play; "
                              f"keep one of them (sample=K: K random tasks per subset; limit=N: the first N)")
        selected = sample_of_subsets(selected, cfg.sample, cfg.seed)
    if cfg.limit is not None:
        rank = {s: i for i, s in enumerate(dict.fromkeys(t.subset for t in tasks))}
        selected = sorted(selected, key=lambda t: rank[t.subset])[: cfg.limit]  # stable: file order in a subset
    return selected


def sample_of_subsets(tasks: Sequence[Task], k: int, seed: int) -> list[Task]:
    """``k`` tasks of every subset of ``tasks`` (all of a smaller subset), a simple random sample drawn per
    subset from its own seeded stream (the seed, the subset's name and size), so every task of a subset is as
    likely to be played, the subsets' draws are independent, and the same seed gives the same sample on every
    machine. Kept in the input's order."""
    by_subset: dict[str, list[int]] = {}
    for i, t in enumerate(tasks):
        by_subset.setdefault(t.subset, []).append(i)
    keep: set[int] = set()
    for name, idx in by_subset.items():
        rng = random.Random(f"eb-run-sample:{int(seed)}:{name}:{len(idx)}")
        keep.update(idx if k >= len(idx) else rng.sample(idx, k))
    return [t for i, t in enumerate(tasks) if i in keep]


def label_record(rec: EpisodeRecord, steps: Sequence[StepRecord]) -> EpisodeRecord:
    """The record with its automatic error labels (docs/error_analysis.md), computed from the episode's step
    records as the driver kept them in memory; records of unmeasured episodes are returned unchanged."""
    if rec.status != "ok":
        return rec
    from eb_core.errors import label_episode

    labels = label_episode(list(steps), rec.model_dump())
    return rec.model_copy(update={"error_counts": labels["counts"], "perception_score": labels["perception_score"]})
