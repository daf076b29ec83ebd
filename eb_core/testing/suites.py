"""Conformance suites that plugin authors subclass (the Gymnasium ``check_env`` / Hydra ``LauncherTestSuite`` idea)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, ClassVar

import pytest

from eb_core.env import Env, Observation, StepResult, Task
from eb_core.model import EpisodeContext, Message, ModelBackend, ModelRequest, ModelResponse, TextPart
from eb_core.specs import load_entry_point
from eb_core.testing.check import check_env


def _resolve(cls_or_path: Any) -> Any:
    return load_entry_point(cls_or_path) if isinstance(cls_or_path, str) else cls_or_path


class EnvConformanceSuite:
    """Every environment plugin runs these against its own env.

    Set ``env_class`` (class or ``"module:Class"``), optionally ``env_params`` and ``sample_size``.
    ``expect_subsets`` (subset name -> count), when set, is checked against ``load_tasks``.
    """

    env_class: ClassVar[Any] = None
    env_params: ClassVar[dict[str, Any]] = {}
    sample_size: ClassVar[int] = 3
    expect_subsets: ClassVar[dict[str, int] | None] = None
    oracle_solves: ClassVar[bool] = True
    """Whether ``expert_plan`` must solve the sampled tasks when followed (with re-planning)."""
    max_env_steps: ClassVar[int] = 30

    @pytest.fixture(scope="class")
    def env_cls(self) -> type[Env]:
        cls = _resolve(self.env_class)
        assert isinstance(cls, type) and issubclass(cls, Env), f"{cls!r} is not an eb_core.Env subclass"
        return cls

    @pytest.fixture(scope="class")
    def tasks(self, env_cls: type[Env]) -> list[Task]:
        return env_cls.load_tasks(**self.env_params.get("task_params", {}))

    @pytest.fixture(scope="class")
    def env(self, env_cls: type[Env]) -> Iterator[Env]:
        params = {k: v for k, v in self.env_params.items() if k != "task_params"}
        env = env_cls(**params)
        yield env
        env.close()

    def sample(self, tasks: list[Task]) -> list[Task]:
        by_subset: dict[str, list[Task]] = {}
        for t in tasks:
            by_subset.setdefault(t.subset, []).append(t)
        picked: list[Task] = []
        i = 0
        while len(picked) < self.sample_size and any(i < len(v) for v in by_subset.values()):
            for subset_tasks in by_subset.values():
                if i < len(subset_tasks) and len(picked) < self.sample_size:
                    picked.append(subset_tasks[i * 7 % len(subset_tasks)])
            i += 1
        return picked

    def test_env_has_a_name(self, env_cls: type[Env]) -> None:
        assert env_cls.name, "set the class attribute `name`"

    def test_tasks_are_valid_and_unique(self, tasks: list[Task]) -> None:
        assert tasks, "load_tasks() returned no tasks"
        ids = [t.id for t in tasks]
        assert len(ids) == len(set(ids)), "task ids must be unique"
        assert all(isinstance(t, Task) for t in tasks)
        if self.expect_subsets is not None:
            counts: dict[str, int] = {}
            for t in tasks:
                counts[t.subset] = counts.get(t.subset, 0) + 1
            assert counts == self.expect_subsets

    def test_load_tasks_is_stable(self, env_cls: type[Env], tasks: list[Task]) -> None:
        again = env_cls.load_tasks(**self.env_params.get("task_params", {}))
        assert [t.id for t in again] == [t.id for t in tasks]

    def test_check_env(self, env: Env, tasks: list[Task]) -> None:
        for task in self.sample(tasks):
            check_env(env, task, seed=0)

    def test_reset_gives_observation(self, env: Env, tasks: list[Task]) -> None:
        obs = env.reset(tasks[0], 0)
        assert isinstance(obs, Observation)
        assert obs.primary is None or obs.primary in obs.images

    def test_text_observation_for_language_only(self, env: Env, tasks: list[Task]) -> None:
        obs = env.reset(tasks[0], 0)
        assert obs.text, "language-only runs need Observation.text describing what the agent perceives"

    def test_invalid_action_is_rejected_cleanly(self, env: Env, tasks: list[Task]) -> None:
        from eb_core.env import DiscreteActionSpace, PlanItemError

        env.reset(tasks[0], 0)
        space = env.action_space()
        bad = {"action_id": 10**6} if isinstance(space, DiscreteActionSpace) else {"action": [10**6] * len(space.names)}
        with pytest.raises(PlanItemError):
            space.parse_plan_item(bad)

    def test_expert_plan_solves_sampled_tasks(self, env: Env, tasks: list[Task]) -> None:
        if not self.oracle_solves:
            pytest.skip("this env declares no oracle")
        for task in self.sample(tasks):
            env.reset(task, 0)
            result: StepResult | None = None
            steps = 0
            while steps < self.max_env_steps:
                plan = env.expert_plan()
                assert plan, f"expert_plan() returned nothing for unsolved task {task.id}"
                for action in plan:
                    result = env.step(action)
                    steps += 1
                    if result.done or not result.action_success or steps >= self.max_env_steps:
                        break
                if result is not None and result.done:
                    break
            assert result is not None and result.task_success, f"oracle failed task {task.id}"
            assert result.progress == 1.0

    def test_close_is_idempotent(self, env_cls: type[Env]) -> None:
        params = {k: v for k, v in self.env_params.items() if k != "task_params"}
        env = env_cls(**params)
        env.close()
        env.close()


class ModelBackendConformanceSuite:
    """Every model backend runs these. Override :meth:`make_backend` (and :meth:`make_context` if the
    backend needs an episode, like ``oracle``)."""

    def make_backend(self) -> ModelBackend:  # pragma: no cover - abstract
        raise NotImplementedError

    def make_context(self) -> EpisodeContext | None:
        return None

    def make_request(self) -> ModelRequest:
        return ModelRequest(messages=(Message(role="user", content=(TextPart(text="Reply with a JSON object."),)),))

    @pytest.fixture
    def backend(self) -> Iterator[ModelBackend]:
        backend = self.make_backend()
        yield backend
        backend.close()

    def test_is_a_backend(self, backend: ModelBackend) -> None:
        assert isinstance(backend, ModelBackend)

    def test_complete_returns_text_and_usage(self, backend: ModelBackend) -> None:
        ctx = self.make_context()
        if ctx is not None:
            backend.start_episode(ctx)
        response = backend.complete(self.make_request())
        assert isinstance(response, ModelResponse)
        assert isinstance(response.text, str) and response.text
        u = response.usage
        assert u.prompt_tokens >= 0 and u.completion_tokens >= 0 and u.cost_usd >= 0 and u.latency_s >= 0

    def test_close_twice(self) -> None:
        backend = self.make_backend()
        backend.close()
        backend.close()


#: Modules a plugin's entry-point module must not pull in: registration is cheap, construction is lazy.
HEAVY_MODULES = ("mujoco", "litellm", "openai", "llama_cpp", "ray", "torch", "gymnasium", "eb_scenekit._mujoco")


class PluginConformanceSuite:
    """Every world plugin runs these on its registration (``eb.plugins`` entry point, ``EnvSpec``, Hydra option).

    Set ``plugin_module`` (the entry point's module, ``"eb_navigation.plugin"``) and ``env_name``. Checks: importing
    the entry point loads no simulator or model SDK (:data:`HEAVY_MODULES`, in a fresh interpreter); the plugin is
    registered under the ``eb.plugins`` group; its ``EnvSpec`` is registered with that name, and the env class it
    names has the same ``name``; the world's ``conf/env/<name>.yaml`` composes and validates, and its ``name`` is the
    spec's; each task set the spec lists loads with the subset counts of the classic set.
    """

    plugin_module: ClassVar[str] = ""
    env_name: ClassVar[str] = ""

    def test_entry_point_imports_nothing_heavy(self) -> None:
        import json
        import subprocess
        import sys

        code = (f"import sys, json; import {self.plugin_module}; "
                f"print(json.dumps(sorted(m for m in {list(HEAVY_MODULES)!r} if m in sys.modules)))")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        assert out.returncode == 0, out.stderr[-2000:]
        heavy = json.loads(out.stdout.strip().splitlines()[-1])
        assert heavy == [], f"importing {self.plugin_module} loaded {heavy}: import them where the env is built"

    def test_registered_as_an_entry_point(self) -> None:
        from importlib import metadata

        from eb_core.plugins import ENTRY_POINT_GROUP

        values = [ep.value for ep in metadata.entry_points(group=ENTRY_POINT_GROUP)]
        assert any(v.split(":")[0] == self.plugin_module for v in values), (self.plugin_module, values)

    def test_spec_and_env_share_the_name(self) -> None:
        from eb_core.plugins import Registry

        spec = Registry.create().envs.get(self.env_name)
        assert spec is not None and spec.name == self.env_name
        env_cls = spec.load()
        assert isinstance(env_cls, type) and issubclass(env_cls, Env) and env_cls.name == spec.name

    def test_yaml_composes_and_validates(self) -> None:
        from eb_core.compose import compose, validate

        cfg = validate(compose([f"env={self.env_name}"]))
        assert cfg.env.name == self.env_name

    def test_every_task_set_loads_with_the_classic_counts(self) -> None:
        from collections import Counter

        from eb_core.plugins import Registry

        spec = Registry.create().envs[self.env_name]
        env_cls = spec.load()
        assert "classic" in spec.tasksets
        for taskset in spec.tasksets:
            tasks = env_cls.load_tasks() if taskset == "classic" else env_cls.load_tasks(taskset=taskset)
            counts = dict(Counter(t.subset for t in tasks))
            assert counts == dict(spec.subsets), (taskset, counts, spec.subsets)
            assert len({t.id for t in tasks}) == len(tasks), taskset
