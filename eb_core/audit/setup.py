"""What one audit runs with (:class:`AuditSetup`: env class, tasks, budgets, sampling) and small shared helpers."""

from __future__ import annotations

import random
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from eb_core.audit.contract import sample_positions
from eb_core.env import Action, ActionSpace, DiscreteActionSpace, Env, Task, VectorActionSpace

if TYPE_CHECKING:
    from eb_core.audit.contract import AuditProbe, BlindPolicy

__all__ = ["AuditSetup", "FRESH_PER_SUBSET", "NOISE_LEVELS", "random_action", "random_vector"]

#: Noise levels of the noisy-expert curve (probability that a step is a uniformly random valid action).
NOISE_LEVELS: tuple[float, ...] = (0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0)

FRESH_PER_SUBSET = 20
"""Tasks per subset of the fresh form the parallel-forms probe generates (docs/audit.md: its power)."""
MAX_LISTED = 40


@dataclass
class AuditSetup:
    """Everything the generic probes need: the env class, the tasks and the episode budgets of the config."""

    env_name: str
    env_cls: type[Env]
    tasks: list[Task]
    max_steps: int
    max_invalid_actions: int | None = None
    env_params: dict[str, Any] = field(default_factory=dict)
    """The env's ``params`` from the composed config (what ``load_tasks`` and the constructor get)."""
    seed: int = 0
    """Base seed of every random choice the probes make (reset seeds, noise, policy samples)."""
    quick: bool = False
    """Fewer tasks per subset for the episode probes, fewer blind cycles, no parallel forms."""
    quick_per_subset: int = 20
    generator: Callable[..., Any] | None = None
    """The world's ``eb tasks generate`` function, for the parallel-forms probe."""
    form_generator: Callable[..., Any] | None = None
    """The world's ``audit_form(out, seed, per_subset)`` (beside its generator, see :func:`find_form_generator`):
    writes a fresh form of only ``per_subset`` tasks per subset. Without it the whole task set is generated."""
    parallel_per_subset: int | None = None
    """Tasks per subset of the fresh form; None = :data:`FRESH_PER_SUBSET`, at most as many as the shipped form
    plays (see :meth:`fresh_per_subset`)."""
    parallel_source: str | None = None
    """A task file or folder to compare with instead of generating one."""
    parallel_seed: int = 2_718
    """Generation seed of the fresh form (the shipped files use other seeds)."""
    parallel_repeats: int = 10
    curve_repeats: int = 2
    """Episodes per task and noise level on the noisy-expert curve."""
    blind_policies: list["BlindPolicy"] | None = None
    """Extra named blind policies (default: the env class's :meth:`~eb_core.env.Env.audit_blind_policies`)."""
    world_probes: list["AuditProbe"] | None = None
    """The world's own probes (``EnvSpec.audit_probes``); None = the env class's ``audit_probes()``."""
    taskset: str = "classic"
    """The task set under audit (``taskset=``); the parallel-forms probe draws its fresh form at the matching
    difficulty when the world's form generator takes ``difficulty``."""
    per_subset: int | None = None
    """Tasks per subset for the probes that play many random actions (blind policies, noise curve, parallel
    forms); None = all of them, unless a random step is slow (see :meth:`sampled_tasks`)."""
    workers: int = 1
    """Processes that play episodes (forked; each builds its own env)."""
    budget_s: float = 150.0
    """Rough wall time those probes may take together on ``workers`` cores when ``per_subset`` is None (the
    rest of the audit -- closed loop, the world's probes, the fresh form's generation -- comes on top)."""
    _cache: dict[Any, Any] = field(default_factory=dict, repr=False)

    def task_file_is_shipped(self) -> bool:
        """The audit reads the world's shipped tasks (no ``task_file``/``task_dir`` given)."""
        return not any(self.env_params.get(k) for k in ("task_file", "task_dir"))

    def episode_tasks(self) -> list[Task]:
        """The tasks the closed-loop oracle plays: all of them, or under quick ``quick_per_subset`` per subset,
        drawn as :meth:`sampled_tasks` draws them."""
        return _sampled(self.tasks, self.quick_per_subset, self.seed) if self.quick else list(self.tasks)

    def sampled_tasks(self, tasks: list[Task] | None = None) -> list[Task]:
        """The tasks of the random-action probes (blind and feedback policies, the noise curve): ``per_subset``
        per subset, a seeded simple random sample (:func:`sample_positions`, the same positions in every subset of
        one size), which no order of the file can bias. With ``per_subset`` None the cap follows from the measured
        cost of a random step and :attr:`budget_s` (all tasks when steps are cheap)."""
        tasks = list(self.tasks if tasks is None else tasks)
        k = self.cap()
        return _sampled(tasks, k, self.seed) if k is not None else tasks

    def forms_sample(self, tasks: list[Task]) -> list[Task]:
        """The tasks the parallel-forms probe compares, from either form: as many per subset as
        :meth:`sampled_tasks` plays, but drawn at random (seeded by the audit's seed and the subset), because the
        permutation test assumes random samples, and an evenly spaced pick aliases with a file whose task types
        come in turn (every 2.5th task of a file that cycles through five types is always one of two types)."""
        k = self.cap()
        return _random_sample(tasks, k, f"eb-audit-forms:{self.seed}") if k is not None else list(tasks)

    def fresh_per_subset(self) -> int:
        """Tasks per subset of the fresh parallel form: ``parallel_per_subset``, else :data:`FRESH_PER_SUBSET` but
        no more than the shipped form plays per subset."""
        if self.parallel_per_subset is not None:
            return self.parallel_per_subset
        shipped = max((len(ts) for ts in _by_subset(self.tasks).values()), default=1)
        return min(FRESH_PER_SUBSET, self.cap() or shipped, shipped)

    def cap(self) -> int | None:
        if "cap" not in self._cache:
            k = self.per_subset
            if k is None:
                groups = _by_subset(self.tasks)
                cost = self.random_step_seconds()
                blind = 40 if isinstance(self._cache.get("space"), DiscreteActionSpace) else 12
                # blind policies, the noise curve and both parallel forms (the fresh one about as large)
                per_task = self.max_steps * cost * (blind + 4 * self.curve_repeats + 2 * self.parallel_repeats)
                fit = int(self.budget_s * max(1, self.workers) / max(per_task * max(len(groups), 1), 1e-9))
                k = max(5, fit)
            if k >= max(len(ts) for ts in _by_subset(self.tasks).values()):
                k = None
            if self.quick:
                k = min(k or self.quick_per_subset, self.quick_per_subset)
            self._cache["cap"] = k
        return self._cache["cap"]

    def random_step_seconds(self) -> float:
        """Median wall time of a random valid step (a few steps on three tasks), measured once."""
        if "step_s" not in self._cache:
            import time

            rng = random.Random(f"eb-audit-calibrate:{self.seed}")
            times: list[float] = []
            env = self.make_env()
            try:
                for t in self.tasks[:: max(1, len(self.tasks) // 3)][:3]:
                    try:
                        env.reset(t, _reset_seed(self.seed, t.id))
                        self._cache["space"] = env.action_space()
                        for _ in range(6):
                            a = random_action(env.action_space(), rng)
                            t0 = time.perf_counter()
                            done = env.step(a).done
                            times.append(time.perf_counter() - t0)
                            if done:
                                break
                    except Exception:  # noqa: BLE001 - the closed-loop probe reports env errors
                        continue
            finally:
                env.close()
            self._cache["step_s"] = float(np.median(times)) if times else 0.0
        return self._cache["step_s"]

    def sampling_note(self) -> str:
        k = self.cap()
        if k is None:
            return "every task"
        slow = "" if self.per_subset is not None or self.quick else \
            f"; a random step takes {1000 * self.random_step_seconds():.0f} ms, per_subset=N to change"
        return f"{k} tasks per subset, drawn at random (seed {self.seed}){slow}"

    def make_env(self, params: dict[str, Any] | None = None) -> Env:
        """The env without rendering when it accepts ``render=False`` (geometry or symbolic mode)."""
        params = dict(self.env_params if params is None else params)
        build: Callable[..., Env] = self.env_cls  # every world's __init__ takes resolution, multi_view, params
        try:
            return build(resolution=64, multi_view=False, **{**params, "render": False})
        except (TypeError, ValueError):  # the world has no render switch
            return build(resolution=64, multi_view=False, **params)


def _sampled(tasks: Sequence[Task], k: int, seed: int) -> list[Task]:
    """``k`` tasks of each subset at :func:`sample_positions` (all when it has no more), in the file's order."""
    out = []
    for ts in _by_subset(tasks).values():
        out += [ts[i] for i in sample_positions(len(ts), k, seed)]
    return out


def _random_sample(tasks: Sequence[Task], k: int, salt: str) -> list[Task]:
    """``k`` tasks of each subset at seeded random positions, in the file's order (all when it has no more)."""
    out = []
    for subset, ts in _by_subset(tasks).items():
        if len(ts) <= k:
            out += ts
        else:
            picks = random.Random(f"{salt}:{subset}").sample(range(len(ts)), k)
            out += [ts[i] for i in sorted(picks)]
    return out


def _reset_seed(seed: int, task_id: str) -> int:
    from eb_core.components import episode_seed

    return episode_seed(seed, task_id)


def random_action(space: ActionSpace, rng: random.Random) -> Action:
    """A uniformly random valid action of ``space`` (one integer per dimension for vector spaces)."""
    if isinstance(space, DiscreteActionSpace):
        return rng.randrange(len(space))
    return random_vector(space, rng)


def random_vector(space: VectorActionSpace, rng: random.Random) -> tuple[int, ...]:
    """A uniformly random action of a vector space: one integer per dimension."""
    return tuple(rng.randint(lo, hi) for lo, hi in zip(space.low, space.high))



def _mean(xs: Sequence[float]) -> float:
    return sum(xs) / len(xs) if xs else 0.0



def _by_subset(tasks: Iterable[Task]) -> dict[str, list[Task]]:
    out: dict[str, list[Task]] = defaultdict(list)
    for t in tasks:
        out[t.subset].append(t)
    return dict(out)


def _pct(x: float) -> str:
    return f"{100 * x:.1f} %"


def _listed(ids: Iterable[str]) -> list[str]:
    return list(dict.fromkeys(ids))[:MAX_LISTED]

