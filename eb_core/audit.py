"""``eb audit``: shortcut probes that every shipped task set must pass (types shared with world plugins).

A probe runs over a world's task list and returns a :class:`ProbeResult`. The core ships the generic
probes (blind constant-action policies, instruction diversity and grammar, duplicates, the closed-loop
oracle, the noisy-expert curve, parallel forms); a world adds its own through
:meth:`eb_core.env.Env.audit_probes`. The probes drive the ``Env`` directly (no model server, no planner):
an episode is ``reset`` then ``step`` until the world says done, ``env.max_steps`` actions were taken or
``env.max_invalid_actions`` actions failed, the same budgets ``eb run`` uses. See ``docs/audit.md``.
"""

from __future__ import annotations

import contextlib
import io
import math
import random
import re
import tempfile
from collections import Counter, defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from eb_core.env import Action, ActionSpace, DiscreteActionSpace, Env, Task

__all__ = [
    "AuditProbe",
    "AuditSetup",
    "BlindPolicy",
    "NOISE_LEVELS",
    "ProbeResult",
    "EpisodeOutcome",
    "detectable_difference",
    "generic_probes",
    "grammar_issues",
    "noisy_expert_episode",
    "p50",
    "permutation_p_value",
    "play",
    "play_jobs",
    "random_action",
    "run_audit",
    "find_form_generator",
    "format_audit",
]


class ProbeResult(BaseModel):
    """What one probe measured, its threshold and whether the task set passed."""

    model_config = ConfigDict(extra="forbid")

    name: str
    """Short probe name, e.g. ``visible_area``."""
    passed: bool
    value: str
    """The measured figure, as printed (e.g. ``"3.3 % (worst subset: base)"``)."""
    threshold: str
    """The goal, as printed (e.g. ``"<= 5 % per subset"``)."""
    failing_tasks: list[str] = Field(default_factory=list)
    """Task ids that break the probe (printed, at most a few dozen)."""
    warning: str | None = None
    """A warning that does not fail the audit (e.g. a subset that tells models apart poorly)."""
    rows: list[dict[str, Any]] = Field(default_factory=list)
    """Optional detail table (one dict per row, e.g. per subset or per policy)."""
    skipped: bool = False
    """The probe did not apply (no template metadata, ``--quick``...); it counts as passed."""


@dataclass(frozen=True)
class AuditProbe:
    """A named check: ``run(tasks, env_params)`` -> :class:`ProbeResult`.

    ``tasks`` are the tasks under audit (the shipped file, or ``task_file=``); ``env_params`` are the env's
    ``params`` from the config (e.g. ``task_file``). A probe must finish in a few minutes on 2 cores. Within
    one audit a world's probes get the same ``tasks`` list object, so they may share work keyed by it.
    """

    name: str
    description: str
    """One sentence: what shortcut or defect this probe guards against."""
    run: Callable[[list[Task], dict[str, Any]], ProbeResult]


#: Noise levels of the noisy-expert curve (probability that a step is a uniformly random valid action).
NOISE_LEVELS: tuple[float, ...] = (0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0)

BLIND_MAX_SUCCESS = 0.05
UNIQUE_MIN = 0.95
TEMPLATES_MIN = 10
P50_WARN = 0.8
RISE_Z = 3.09  # one-sided p < 0.001 for each pair of noise levels
PARALLEL_ALPHA = 0.01
PARALLEL_NOISE = 0.5
FRESH_PER_SUBSET = 20
"""Tasks per subset of the fresh form the parallel-forms probe generates (docs/audit.md: its power)."""
MAX_LISTED = 40


# -- episodes -----------------------------------------------------------------------------------------------


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
    """Extra named blind policies (default: the env class's ``audit_blind_policies()`` when it has one)."""
    per_subset: int | None = None
    """Tasks per subset for the probes that play many random actions (blind policies, noise curve, parallel
    forms); None = all of them, unless a random step is slow (see :meth:`sampled_tasks`)."""
    workers: int = 1
    """Processes that play episodes (forked; each builds its own env)."""
    budget_s: float = 150.0
    """Rough wall time those probes may take together on ``workers`` cores when ``per_subset`` is None (the
    rest of the audit -- closed loop, the world's probes, the fresh form's generation -- comes on top)."""
    _cache: dict[Any, Any] = field(default_factory=dict, repr=False)

    def episode_tasks(self) -> list[Task]:
        """The tasks the closed-loop oracle plays: all of them, or the first few per subset under quick."""
        return _spread(self.tasks, self.quick_per_subset) if self.quick else list(self.tasks)

    def sampled_tasks(self, tasks: list[Task] | None = None) -> list[Task]:
        """The tasks of the random-action probes: ``per_subset`` per subset, spread evenly over each subset's
        order (task files are often ordered by family). With ``per_subset`` None the cap follows from the
        measured cost of a random step and :attr:`budget_s` (all tasks when steps are cheap)."""
        tasks = list(self.tasks if tasks is None else tasks)
        k = self.cap()
        return _spread(tasks, k) if k is not None else tasks

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
        return f"{k} tasks per subset, spread over each subset{slow}"

    def make_env(self, params: dict[str, Any] | None = None) -> Env:
        """The env without rendering when it accepts ``render=False`` (geometry or symbolic mode)."""
        params = dict(self.env_params if params is None else params)
        try:
            return self.env_cls(resolution=64, multi_view=False, **{**params, "render": False})
        except (TypeError, ValueError):  # the world has no render switch
            return self.env_cls(resolution=64, multi_view=False, **params)


def _spread(tasks: Sequence[Task], k: int) -> list[Task]:
    """``k`` tasks of each subset at evenly spaced positions of its order (all when it has no more)."""
    out = []
    for ts in _by_subset(tasks).values():
        if len(ts) <= k:
            out += ts
        else:
            out += [ts[(i * len(ts)) // k] for i in range(k)]
    return out


def _reset_seed(seed: int, task_id: str) -> int:
    from eb_core.runner import episode_seed

    return episode_seed(seed, task_id)


def random_action(space: ActionSpace, rng: random.Random) -> Action:
    """A uniformly random valid action of ``space`` (one integer per dimension for vector spaces)."""
    if isinstance(space, DiscreteActionSpace):
        return rng.randrange(len(space))
    return tuple(rng.randint(lo, hi) for lo, hi in zip(space.low, space.high))


@dataclass(frozen=True)
class EpisodeOutcome:
    success: bool
    steps: int
    end: str
    """``success``, ``done`` (ended unsolved), ``max_steps``, ``invalid_cap``, ``no_action`` or ``error``."""
    detail: str = ""


Policy = Callable[[Env, int], "Action | None"]
"""``policy(env, step_index)`` -> the next action, or None to give up (the episode fails)."""


def play(env: Env, task: Task, policy: Policy, *, max_steps: int, max_invalid_actions: int | None,
         seed: int) -> EpisodeOutcome:
    """One episode under the benchmark's budgets, driving the env directly."""
    try:
        env.reset(task, seed)
        invalid = 0
        for i in range(max_steps):
            action = policy(env, i)
            if action is None:
                return EpisodeOutcome(False, i, "no_action", getattr(env, "expert_reason", None) or "")
            result = env.step(action)
            if result.task_success:
                return EpisodeOutcome(True, i + 1, "success")
            if result.done:
                return EpisodeOutcome(False, i + 1, "done", result.feedback)
            if not result.action_success:
                invalid += 1
                if max_invalid_actions is not None and invalid >= max_invalid_actions:
                    return EpisodeOutcome(False, i + 1, "invalid_cap", result.feedback)
        return EpisodeOutcome(False, max_steps, "max_steps")
    except Exception as exc:  # an env bug is a finding, not a crash of the audit
        return EpisodeOutcome(False, 0, "error", f"{type(exc).__name__}: {exc}")


def noisy_expert_episode(setup: AuditSetup, env: Env, task: Task, noise: float, repeat: int = 0) -> EpisodeOutcome:
    """The closed-loop expert (re-asked after every action) whose steps are replaced, each with probability
    ``noise``, by a uniformly random valid action. Noise decisions and random actions come from two streams
    seeded by task and repeat, so curves at different noise levels share their random numbers."""
    coin = random.Random(f"eb-audit-noise:{setup.seed}:{task.id}:{repeat}")
    draws = random.Random(f"eb-audit-action:{setup.seed}:{task.id}:{repeat}")

    def policy(e: Env, i: int) -> Action | None:
        u = coin.random()
        rand = random_action(e.action_space(), draws)
        if u < noise:
            return rand
        plan = e.expert_plan()
        return plan[0] if plan else None

    return play(env, task, policy, max_steps=setup.max_steps, max_invalid_actions=setup.max_invalid_actions,
                seed=_reset_seed(setup.seed, task.id))


@dataclass(frozen=True)
class _Job:
    """One episode to play: a blind policy, or the noisy expert at ``noise`` (repeat ``repeat``)."""

    task: Task
    policy: "BlindPolicy | None" = None
    noise: float = 0.0
    repeat: int = 0
    params: str = ""
    """JSON of other env params (a fresh form's task file); empty = the setup's."""


_POOL_SETUP: AuditSetup | None = None
_POOL_ENVS: dict[str, Env] = {}


def _play_job(setup: AuditSetup, envs: dict[str, Env], job: _Job) -> EpisodeOutcome:
    if job.params not in envs:
        import json

        envs[job.params] = setup.make_env(json.loads(job.params) if job.params else None)
    env = envs[job.params]
    if job.policy is not None:
        return play(env, job.task, job.policy.policy(), max_steps=setup.max_steps,
                    max_invalid_actions=setup.max_invalid_actions, seed=_reset_seed(setup.seed, job.task.id))
    return noisy_expert_episode(setup, env, job.task, job.noise, job.repeat)


def _play_chunk(chunk: list[_Job]) -> list[EpisodeOutcome]:
    assert _POOL_SETUP is not None
    return [_play_job(_POOL_SETUP, _POOL_ENVS, job) for job in chunk]


def play_jobs(setup: AuditSetup, jobs: list[_Job]) -> list[EpisodeOutcome]:
    """Play ``jobs`` in order, in ``setup.workers`` forked processes (each with its own env) when there are
    enough of them. Results do not depend on the number of workers: every episode seeds itself."""
    global _POOL_SETUP
    if setup.workers <= 1 or len(jobs) < 40:
        envs: dict[str, Env] = {}
        try:
            return [_play_job(setup, envs, job) for job in jobs]
        finally:
            for env in envs.values():
                env.close()
    import multiprocessing

    size = max(1, len(jobs) // (setup.workers * 8))
    chunks = [jobs[i:i + size] for i in range(0, len(jobs), size)]
    _POOL_SETUP = setup
    try:
        with multiprocessing.get_context("fork").Pool(setup.workers) as pool:
            return [o for part in pool.map(_play_chunk, chunks, chunksize=1) for o in part]
    finally:
        _POOL_SETUP = None


# -- statistics ---------------------------------------------------------------------------------------------


def _mean(xs: Sequence[float]) -> float:
    return sum(xs) / len(xs) if xs else 0.0


def p50(curve: Sequence[tuple[float, float]]) -> float | None:
    """Noise level where success first falls to 50 % (linear between grid points); None if it never does."""
    prev_p, prev_s = curve[0]
    if prev_s <= 0.5:
        return prev_p
    for p, s in curve[1:]:
        if s <= 0.5:
            return prev_p + (p - prev_p) * (prev_s - 0.5) / (prev_s - s)
        prev_p, prev_s = p, s
    return None


def _rise_z(lo: tuple[int, int], hi: tuple[int, int]) -> float:
    """One-sided two-proportion z statistic for success rising from ``lo`` to ``hi`` ((successes, n) pairs)."""
    (s1, n1), (s2, n2) = lo, hi
    pooled = (s1 + s2) / (n1 + n2)
    var = pooled * (1 - pooled) * (1 / n1 + 1 / n2)
    if var == 0:
        return 0.0
    return (s2 / n2 - s1 / n1) / math.sqrt(var)


def permutation_p_value(a: Sequence[float], b: Sequence[float], *, permutations: int = 20000,
                        seed: int = 0) -> float:
    """Two-sided permutation test on the difference of means of two samples of task scores.

    Tasks are the sampling units: under the null hypothesis both forms draw tasks from one population, so
    shuffling the form labels gives the difference that task sampling alone explains.
    """
    x = np.asarray(list(a) + list(b), dtype=float)
    n = len(a)
    if n == 0 or len(b) == 0:
        return 1.0
    observed = abs(x[:n].mean() - x[n:].mean())
    rng = np.random.default_rng(seed)
    hits = 0
    done = 0
    while done < permutations:
        k = min(2000, permutations - done)
        idx = np.argsort(rng.random((k, len(x))), axis=1)
        perm = x[idx]
        diff = np.abs(perm[:, :n].mean(axis=1) - perm[:, n:].mean(axis=1))
        hits += int((diff >= observed - 1e-12).sum())
        done += k
    return (hits + 1) / (permutations + 1)


def _by_subset(tasks: Iterable[Task]) -> dict[str, list[Task]]:
    out: dict[str, list[Task]] = defaultdict(list)
    for t in tasks:
        out[t.subset].append(t)
    return dict(out)


def _pct(x: float) -> str:
    return f"{100 * x:.1f} %"


def _listed(ids: Iterable[str]) -> list[str]:
    return list(dict.fromkeys(ids))[:MAX_LISTED]


# -- blind policies -----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BlindPolicy:
    """A policy that ignores image and instruction: ``prefix`` once, then ``cycle`` over and over.

    Items are action names (discrete spaces; a name the episode's space lacks makes the policy give up) or
    action vectors (vector spaces). A world may offer its own through a classmethod
    ``audit_blind_policies() -> list[BlindPolicy]`` on its ``Env`` class.
    """

    name: str
    cycle: tuple[Any, ...]
    prefix: tuple[Any, ...] = ()

    def item(self, i: int) -> Any:
        if i < len(self.prefix):
            return self.prefix[i]
        return self.cycle[(i - len(self.prefix)) % len(self.cycle)]

    def policy(self) -> Policy:
        def act(env: Env, i: int) -> Action | None:
            item = self.item(i)
            space = env.action_space()
            if isinstance(space, DiscreteActionSpace):
                return space.actions.index(item) if item in space.actions else None
            return tuple(item)

        return act


_TURN = re.compile(r"\b(turn|rotate)\b", re.I)
_FORWARD = re.compile(r"\b(forward|ahead)\b", re.I)


def _blind_policies(setup: AuditSetup, spaces: dict[str, ActionSpace]) -> list[BlindPolicy]:
    rng = random.Random(f"eb-audit-blind:{setup.seed}")
    n_cycles = 12 if setup.quick else 24
    policies: list[BlindPolicy] = []
    first = next(iter(spaces.values()), None)
    if isinstance(first, DiscreteActionSpace):
        freq: Counter[str] = Counter()
        for sp in spaces.values():
            if isinstance(sp, DiscreteActionSpace):
                freq.update(list(dict.fromkeys(sp.actions)))  # in list order: no set order (hash seeds differ)
        ranked = sorted(freq, key=lambda a: (-freq[a], rng.random()))
        constant = ranked if len(ranked) <= 16 else ranked[:16]
        policies += [BlindPolicy(f"always '{a}'", (a,)) for a in constant]
        turns = [a for a in ranked if _TURN.search(a)]
        forwards = [a for a in ranked if _FORWARD.search(a)]
        policies += [BlindPolicy(f"'{t}' once, then '{f}'", (f,), (t,)) for t in turns for f in forwards]
        pool = ranked[:8]
        seen: set[tuple[str, ...]] = set()
        all_cycles = [c for k in (2, 3, 4) for c in _cycles(pool, k)]
        if len(all_cycles) > n_cycles:
            all_cycles = rng.sample(all_cycles, n_cycles)
        for c in all_cycles:
            if c not in seen:
                seen.add(c)
                policies.append(BlindPolicy("cycle " + " > ".join(f"'{a}'" for a in c), c))
    elif first is not None:  # vector space: a few fixed vectors and cycles of them
        vec_rng = random.Random(f"eb-audit-vectors:{setup.seed}")
        mid = tuple((lo + hi) // 2 for lo, hi in zip(first.low, first.high))
        vectors = [mid] + [random_action(first, vec_rng) for _ in range(5)]
        policies += [BlindPolicy(f"always {list(v)}", (v,)) for v in vectors]
        for j in range(n_cycles // 4):
            k = 2 + j % 3
            c = tuple(random_action(first, vec_rng) for _ in range(k))
            policies.append(BlindPolicy(f"cycle of {k} fixed vectors #{j + 1}", c))
    extra = setup.blind_policies
    if extra is None:
        hook = getattr(setup.env_cls, "audit_blind_policies", None)
        extra = list(hook()) if callable(hook) else []
    return policies + list(extra)


def _cycles(pool: list[str], k: int) -> list[tuple[str, ...]]:
    """Cycles of length ``k`` over ``pool`` that are not a shorter cycle repeated (one per rotation class)."""
    import itertools

    out = []
    for c in itertools.product(pool, repeat=k):
        if len(set(c)) < 2:
            continue
        if any(k % d == 0 and c == c[:d] * (k // d) for d in range(1, k)):
            continue
        if c != min(c[i:] + c[:i] for i in range(k)):
            continue
        out.append(c)
    return out


def probe_blind_policies(setup: AuditSetup) -> ProbeResult:
    tasks = setup.sampled_tasks()
    env = setup.make_env()
    try:
        spaces: dict[str, ActionSpace] = {}
        for t in tasks:
            try:
                env.reset(t, _reset_seed(setup.seed, t.id))
                spaces[t.id] = env.action_space()
            except Exception:  # noqa: BLE001 - the closed-loop probe reports env errors
                continue
    finally:
        env.close()
    policies = _blind_policies(setup, spaces)
    jobs = [_Job(t, policy=pol) for t in tasks for pol in policies]
    solved: dict[str, list[str]] = defaultdict(list)  # policy name -> solved task ids
    for job, out in zip(jobs, play_jobs(setup, jobs)):
        if out.success:
            solved[job.policy.name].append(job.task.id)  # type: ignore[union-attr]
    groups = _by_subset(tasks)
    rows = []
    failing: list[str] = []
    worst = (0.0, "", "")
    for pol in policies:
        ids = set(solved.get(pol.name, []))
        rates = {s: sum(t.id in ids for t in ts) / len(ts) for s, ts in groups.items()}
        best_subset = max(rates, key=lambda s: rates[s]) if rates else ""
        best = rates.get(best_subset, 0.0)
        if best > worst[0] or not worst[1]:
            worst = (best, pol.name, best_subset)
        if best > BLIND_MAX_SUCCESS:
            failing += [t.id for s, ts in groups.items() if rates[s] > BLIND_MAX_SUCCESS for t in ts if t.id in ids]
        rows.append({"policy": pol.name, "best subset": best_subset, "success": _pct(best),
                     "solved": len(ids), "_rate": best})
    rows.sort(key=lambda r: -r["_rate"])
    shown = [{k: v for k, v in r.items() if k != "_rate"} for r in rows[:8]]
    bad = [r for r in rows if r["_rate"] > BLIND_MAX_SUCCESS]
    kinds = Counter("turn, then forward" if p.prefix else "cycle" if p.name.startswith("cycle") else
                    "constant" if p.name.startswith("always") else "named by the world" for p in policies)
    mix = ", ".join(f"{v} {k}" for k, v in kinds.items())
    value = (f"{len(policies)} policies ({mix}); worst {_pct(worst[0])} ({worst[1]} on {worst[2]})" if policies
             else "no policies (no actions)")
    if bad:
        value = (f"{len(bad)} of {len(policies)} policies ({mix}) above 5 %; worst {_pct(worst[0])} "
                 f"({worst[1]} on {worst[2]})")
    return ProbeResult(name="blind_policies", passed=not bad, value=value,
                       threshold="<= 5 % success per subset, every policy", failing_tasks=_listed(failing),
                       rows=shown)


# -- instructions -------------------------------------------------------------------------------------------


def probe_unique_instructions(setup: AuditSetup) -> ProbeResult:
    rows, failing, worst = [], [], (1.0, "")
    dup_note = []
    for subset, ts in _by_subset(setup.tasks).items():
        norm = [" ".join(t.instruction.lower().split()) for t in ts]
        counts = Counter(norm)
        unique = len(counts) / len(ts)
        first: dict[str, str] = {}
        dups = []
        for t, n in zip(ts, norm):
            if counts[n] > 1:
                if n in first:
                    dups.append(t.id)
                    dup_note.append(f"{t.id} = {first[n]}")
                else:
                    first[n] = t.id
        rows.append({"subset": subset, "tasks": len(ts), "unique": _pct(unique), "duplicates": len(dups)})
        if unique < worst[0]:
            worst = (unique, subset)
        failing += dups
    value = f"worst {_pct(worst[0])} unique ({worst[1]})" if worst[1] else "100 % unique in every subset"
    warning = None
    passed = worst[0] >= UNIQUE_MIN
    if failing:
        note = ", ".join(dup_note[:4]) + (" ..." if len(dup_note) > 4 else "")
        value += f"; duplicates: {note}"
        if passed:
            warning = f"{len(failing)} duplicate instructions (same words, ignoring case and spacing): {note}"
    return ProbeResult(name="instruction_unique", passed=passed, value=value,
                       threshold=">= 95 % unique per subset (duplicates named)", failing_tasks=_listed(failing),
                       warning=warning, rows=rows)


def probe_templates(setup: AuditSetup) -> ProbeResult:
    groups = _by_subset(setup.tasks)
    if not any("template" in t.metadata for t in setup.tasks):
        return ProbeResult(name="instruction_templates", passed=True, skipped=True,
                           value="n/a (tasks carry no metadata['template'])",
                           threshold=f">= {TEMPLATES_MIN} templates per subset")
    rows, bad, failing = [], [], []
    for subset, ts in groups.items():
        n = len({str(t.metadata.get("template")) for t in ts if "template" in t.metadata})
        rows.append({"subset": subset, "templates": n, "tasks": len(ts)})
        if n < TEMPLATES_MIN:
            bad.append(f"{subset} ({n})")
            failing += [t.id for t in ts]
    worst = min(rows, key=lambda r: r["templates"])
    value = f"fewest: {worst['templates']} ({worst['subset']})" + (f"; below: {', '.join(bad)}" if bad else "")
    return ProbeResult(name="instruction_templates", passed=not bad, value=value,
                       threshold=f">= {TEMPLATES_MIN} templates per subset", failing_tasks=_listed(failing), rows=rows)


_SILENT_H = ("hour", "honest", "honor", "honour", "heir")
_CONSONANT_U = ("use", "usu", "usa", "ute", "uti", "ura", "ure", "uri", "uro", "ufo", "uk", "ubiq", "uku", "uvu")
_LETTER_VOWEL_SOUND = set("AEFHILMNORSX")
_DOUBLED_OK = {"that", "had", "is", "bye", "no", "very", "so"}


def _vowel_sound(word: str) -> bool | None:
    """Whether ``word`` starts with a vowel sound (for a/an); None when unsure."""
    w = word.strip("\"'()[]{}.,;:!?")
    if not w:
        return None
    if w[0].isdigit():
        return w.startswith("8") or w in ("11", "18") or w.startswith(("11,", "18,"))
    if (len(w) == 1 or (w.isupper() and len(w) <= 4)) and w[0].isalpha():
        return w[0].upper() in _LETTER_VOWEL_SOUND
    lw = w.lower()
    if lw.startswith(_SILENT_H):
        return True
    if lw.startswith("herb"):
        return None
    if lw[0] not in "aeiou":
        return False
    if lw.startswith(("one", "once", "eu", "ewe")):
        return False
    if lw.startswith("uni"):  # unique, unit, uniform ... but uninteresting, unimportant, unidentified
        return lw.startswith(("unin", "unim", "unid"))
    if lw.startswith(_CONSONANT_U):
        return False
    return True


def grammar_issues(text: str) -> list[str]:
    """Mechanical writing defects: a/an before the wrong sound, doubled words, stray spaces, unbalanced
    brackets or quotes, an empty sentence."""
    issues: list[str] = []
    if text != text.strip():
        issues.append("leading or trailing whitespace")
    if "  " in text:
        issues.append("double space")
    if re.search(r"\s[,.;:!?](?!\w)", text):
        issues.append("space before punctuation")
    if re.search(r"[,;:]{2,}|\.\.(?!\.)|[,;:]\.", text):
        issues.append("doubled punctuation")
    words = re.findall(r"[A-Za-z0-9'\-]+|[^\sA-Za-z0-9]", text)
    for i, w in enumerate(words[:-1]):
        nxt = words[i + 1]
        lw = w.lower()
        if lw in ("a", "an") and re.match(r"[A-Za-z0-9]", nxt):
            vowel = _vowel_sound(nxt)
            if vowel is True and lw == "a":
                issues.append(f"'a {nxt}' (use 'an')")
            elif vowel is False and lw == "an":
                issues.append(f"'an {nxt}' (use 'a')")
    for m in re.finditer(r"\b([A-Za-z]+)\s+\1\b", text, re.I):
        if m.group(1).lower() not in _DOUBLED_OK:
            issues.append(f"doubled word '{m.group(0)}'")
    for open_, close in (("(", ")"), ("[", "]")):
        if text.count(open_) != text.count(close):
            issues.append(f"unbalanced '{open_}{close}'")
    if text.count('"') % 2:
        issues.append("unbalanced '\"'")
    if re.search(r"[.!?]\s+[a-z]", text):
        issues.append("sentence starts lowercase")
    return issues


def probe_grammar(setup: AuditSetup) -> ProbeResult:
    rows, failing = [], []
    kinds: Counter[str] = Counter()
    for t in setup.tasks:
        found = grammar_issues(t.instruction)
        if found:
            failing.append(t.id)
            kinds.update("a/an" if "(use '" in f else "doubled word" if f.startswith("doubled word") else f
                         for f in found)
            if len(rows) < 10:
                rows.append({"task": t.id, "issues": "; ".join(found), "instruction": t.instruction[:90]})
    value = (f"{len(failing)} instructions with issues (" + ", ".join(f"{k}: {v}" for k, v in kinds.most_common(4))
             + ")") if failing else f"no issues in {len(setup.tasks)} instructions"
    return ProbeResult(name="instruction_grammar", passed=not failing, value=value,
                       threshold="no a/an, doubled-word, spacing or bracket defects", failing_tasks=_listed(failing),
                       rows=rows)


# -- the expert ---------------------------------------------------------------------------------------------


def _curve_key(params_key: str, noise: float, repeat: int) -> tuple[Any, ...]:
    return ("curve", noise, repeat) if not params_key else ("curve", params_key, noise, repeat)


def _curve_outcomes(setup: AuditSetup, levels: list[tuple[float, int]], tasks: list[Task] | None = None,
                    params_key: str = "") -> dict[tuple[float, int], dict[str, EpisodeOutcome]]:
    """Noisy-expert outcomes per (noise, repeat) and task, played in one batch and cached on the setup (so the
    noise curve, the closed loop and the parallel forms share episodes). ``params_key`` is the JSON of another
    form's env params (empty: the tasks under audit)."""
    tasks = setup.sampled_tasks() if tasks is None else tasks
    todo = [_Job(t, noise=noise, repeat=rep, params=params_key) for noise, rep in levels for t in tasks
            if t.id not in setup._cache.get(_curve_key(params_key, noise, rep), {})]
    for job, out in zip(todo, play_jobs(setup, todo)):
        setup._cache.setdefault(_curve_key(params_key, job.noise, job.repeat), {})[job.task.id] = out
    return {lv: {t.id: setup._cache[_curve_key(params_key, *lv)][t.id] for t in tasks} for lv in levels}


def probe_closed_loop(setup: AuditSetup) -> ProbeResult:
    outcomes = _curve_outcomes(setup, [(0.0, 0)], setup.episode_tasks())[(0.0, 0)]
    failed = [(tid, o) for tid, o in outcomes.items() if not o.success]
    rows = [{"task": tid, "end": o.end, "steps": o.steps, "detail": o.detail[:100]} for tid, o in failed[:10]]
    ends = Counter(o.end for _, o in failed)
    n = len(outcomes)
    value = f"{_pct((n - len(failed)) / n if n else 1.0)} ({n - len(failed)}/{n})"
    if failed:
        value += "; failures: " + ", ".join(f"{k} {v}" for k, v in ends.most_common())
    return ProbeResult(name="closed_loop_oracle", passed=not failed, value=value,
                       threshold=f"100 % within max_steps={setup.max_steps}",
                       failing_tasks=_listed(tid for tid, _ in failed), rows=rows)


def probe_noise_curve(setup: AuditSetup) -> ProbeResult:
    tasks = setup.sampled_tasks()
    groups = _by_subset(tasks)
    reps = 1 if setup.quick else setup.curve_repeats
    wins: dict[float, Counter[str]] = {p: Counter() for p in NOISE_LEVELS}  # p -> task id -> successes
    levels = [(p, r) for p in NOISE_LEVELS for r in range(reps)]
    for (p, _), outcomes in _curve_outcomes(setup, levels, tasks).items():
        for tid, o in outcomes.items():
            wins[p][tid] += int(o.success)
    rows, rises, warns, failing = [], [], [], []
    p50s = {}
    for subset, ts in groups.items():
        n = len(ts) * reps
        succ = {p: sum(wins[p][t.id] for t in ts) for p in NOISE_LEVELS}
        curve = [(p, succ[p] / n) for p in NOISE_LEVELS]
        for i, lo in enumerate(NOISE_LEVELS):
            for hi in NOISE_LEVELS[i + 1:]:
                z = _rise_z((succ[lo], n), (succ[hi], n))
                if z > RISE_Z:
                    rises.append(f"{subset}: {_pct(succ[lo] / n)} at p={lo} -> {_pct(succ[hi] / n)} at p={hi}")
                    failing += [t.id for t in ts if wins[hi][t.id] > wins[lo][t.id]]
        half = p50(curve)
        p50s[subset] = half
        if half is None or half > P50_WARN:
            warns.append(f"{subset} (p50 {'> 1' if half is None else f'{half:.2f}'})")
        row: dict[str, Any] = {"subset": subset}
        row.update({f"p={p:g}": f"{100 * s:.0f}" for p, s in curve})
        row["p50"] = "> 1" if half is None else f"{half:.2f}"
        rows.append(row)
    rises = list(dict.fromkeys(rises))
    p50_text = ", ".join(f"{s} {'>1' if v is None else f'{v:.2f}'}" for s, v in p50s.items())
    value = f"p50: {p50_text}"
    if rises:
        value = "success rises with noise: " + "; ".join(rises[:3]) + f" | {value}"
    warning = (f"p50 > {P50_WARN} (the subset tells models apart poorly): " + ", ".join(warns)) if warns else None
    return ProbeResult(name="noise_curve", passed=not rises, value=value,
                       threshold=f"no rise with p beyond noise (z > {RISE_Z}); warn p50 > {P50_WARN}",
                       failing_tasks=_listed(failing), warning=warning, rows=rows)


# -- parallel forms -----------------------------------------------------------------------------------------


def find_form_generator(generator: Callable[..., Any] | None) -> Callable[..., Any] | None:
    """The ``audit_form(out, seed, per_subset)`` function defined beside a world's task generator (in the same
    module), or None. It writes a fresh form with ``per_subset`` tasks of every subset, drawn the way the
    shipped set is drawn, to ``out`` (a task file or folder ``load_tasks`` reads): the parallel-forms probe
    then generates only what it plays instead of the whole task set."""
    import inspect

    if generator is None:
        return None
    fn = getattr(inspect.getmodule(generator), "audit_form", None)
    return fn if callable(fn) else None


def _write_fresh_form(setup: AuditSetup, workdir: Path) -> tuple[str, str, bool]:
    """Generate a fresh form in ``workdir``: (its path, how it was made, whether it is a per-subset sample)."""
    if setup.generator is None and setup.form_generator is None:
        raise LookupError("the world registers no task generator")
    src = workdir / "parallel"
    sample = setup.form_generator is not None
    with contextlib.redirect_stdout(io.StringIO()):
        if sample:
            k = setup.fresh_per_subset()
            setup.form_generator(out=str(src), seed=setup.parallel_seed, per_subset=k)  # type: ignore[misc]
            how = f"generated with seed={setup.parallel_seed}, {k} tasks per subset"
        else:
            setup.generator(out=str(src), seed=setup.parallel_seed)  # type: ignore[misc]
            how = f"generated with seed={setup.parallel_seed}"
    if src.is_file():
        src = src.rename(workdir / "parallel.json")
    return str(src), how, sample


def _fresh_form(setup: AuditSetup, workdir: Path) -> tuple[list[Task], dict[str, Any], str, bool]:
    """Tasks of another form (``parallel_source``, or a fresh one from the world's generator, made here or already
    under way in the background), its env params, how it was made and whether it is a per-subset sample."""
    params = dict(setup.env_params)
    sample = False
    if setup.parallel_source:
        src = Path(setup.parallel_source)
        how = f"given {src}"
    else:
        pending = setup._cache.pop("fresh_pending", None)
        if pending is not None:
            path, how, sample = pending.result()
            setup._cache["fresh_took"] = (pending.wall, pending.cpu)
        else:
            path, how, sample = _write_fresh_form(setup, workdir)
        src = Path(path)
    if src.is_dir():
        params["task_dir"] = str(src)
        params.pop("task_file", None)
    elif src.is_file():
        params["task_file"] = str(src)
        params.pop("task_dir", None)
    else:
        raise FileNotFoundError(f"no task file or folder at {src}")
    return setup.env_cls.load_tasks(**params), params, how, sample


def probe_parallel_forms(setup: AuditSetup) -> ProbeResult:
    import json

    threshold = (f"no subset differs at p < {PARALLEL_ALPHA} (noise {PARALLEL_NOISE}, "
                 f"{setup.parallel_repeats} runs/task)")
    if setup.quick:
        return ProbeResult(name="parallel_forms", passed=True, skipped=True, value="skipped (--quick)",
                           threshold=threshold)
    levels = [(PARALLEL_NOISE, r) for r in range(setup.parallel_repeats)]
    with tempfile.TemporaryDirectory(prefix="eb-audit-") as tmp:
        try:
            fresh, params, how, sample = _fresh_form(setup, Path(tmp))
        except LookupError as exc:
            return ProbeResult(name="parallel_forms", passed=True, skipped=True, value=f"n/a ({exc})",
                               threshold=threshold)
        # an audit of some subsets (subset=...) compares with the same subsets of the fresh form
        audited = {t.subset for t in setup.tasks}
        fresh = [t for t in fresh if t.subset in audited]
        ours, theirs = setup.sampled_tasks(), setup.sampled_tasks(fresh)
        # the shipped form's episodes at p = 0.5 are shared with the noise curve (same seeds per repeat)
        shipped_scores = _scores(_curve_outcomes(setup, levels, ours))
        key = "" if params == setup.env_params else json.dumps(params, sort_keys=True)
        fresh_scores = _scores(_curve_outcomes(setup, levels, theirs, key))
    a_groups, b_groups = _by_subset(ours), _by_subset(theirs)
    counts_a, counts_b = Counter(t.subset for t in setup.tasks), Counter(t.subset for t in fresh)
    rows, bad, failing = [], [], []
    for subset in list(dict.fromkeys([*a_groups, *b_groups])):
        a = [shipped_scores[t.id] for t in a_groups.get(subset, [])]
        b = [fresh_scores[t.id] for t in b_groups.get(subset, [])]
        if not a or not b:
            bad.append(f"{subset} (only in {'the shipped' if a else 'the fresh'} form)")
            rows.append({"subset": subset, "shipped": len(a), "fresh": len(b)})
            continue
        pv = permutation_p_value(a, b, seed=setup.seed)
        rows.append({"subset": subset, "tasks": f"{len(a)} / {len(b)}", "shipped": _pct(_mean(a)),
                     "fresh": _pct(_mean(b)), "difference": f"{100 * (_mean(a) - _mean(b)):+.1f} pt",
                     "detectable": f"{100 * detectable_difference(a, b):.0f} pt", "p-value": f"{pv:.4f}"})
        if pv < PARALLEL_ALPHA:
            bad.append(f"{subset} ({_pct(_mean(a))} vs {_pct(_mean(b))}, p={pv:.4f})")
            # the shipped tasks furthest from the fresh form's mean explain the gap
            mb = _mean(b)
            far = sorted(a_groups[subset], key=lambda t: -abs(shipped_scores[t.id] - mb))
            failing += [t.id for t in far[:5]]
        if not sample and counts_a[subset] != counts_b[subset]:  # a sample form has fewer tasks by design
            bad.append(f"{subset} (counts differ: {counts_a[subset]} vs {counts_b[subset]})")
    value = f"fresh form {how}; " + ("differs: " + "; ".join(bad) if bad else "every subset within task sampling")
    return ProbeResult(name="parallel_forms", passed=not bad, value=value, threshold=threshold,
                       failing_tasks=_listed(failing), rows=rows)


def detectable_difference(a: Sequence[float], b: Sequence[float], alpha: float = PARALLEL_ALPHA,
                          power: float = 0.8) -> float:
    """The difference of means the two-sided test at ``alpha`` finds with probability ``power``, for samples the
    size and spread of ``a`` and ``b`` (normal approximation: (z_{1-alpha/2} + z_power) * standard error)."""
    from statistics import NormalDist

    z = NormalDist().inv_cdf(1 - alpha / 2) + NormalDist().inv_cdf(power)
    var = sum(float(np.var(x, ddof=1)) / len(x) if len(x) > 1 else 0.25 / max(len(x), 1) for x in (a, b))
    return z * math.sqrt(var)


def _scores(outcomes: dict[tuple[float, int], dict[str, EpisodeOutcome]]) -> dict[str, float]:
    """Each task's success rate over the given levels' episodes."""
    wins: dict[str, list[float]] = defaultdict(list)
    for per_task in outcomes.values():
        for tid, out in per_task.items():
            wins[tid].append(float(out.success))
    return {tid: _mean(v) for tid, v in wins.items()}


# -- running ------------------------------------------------------------------------------------------------

_GENERIC: list[tuple[str, str, Callable[[AuditSetup], ProbeResult]]] = [
    ("instruction_unique", "Near-duplicate instructions shrink the effective task set and inflate agreement.",
     probe_unique_instructions),
    ("instruction_templates", "Few templates let a model learn the wording, not the task.", probe_templates),
    ("instruction_grammar", "Broken wording (a/an, doubled words, stray spaces) is a generator bug a model sees.",
     probe_grammar),
    ("blind_policies", "A fixed action sequence that ignores image and instruction must not solve tasks.",
     probe_blind_policies),
    ("closed_loop_oracle", "Every task must be solvable from its start within the step budget.", probe_closed_loop),
    ("noise_curve", "Success must fall as the expert's actions are randomised; a flat curve separates models poorly.",
     probe_noise_curve),
    ("parallel_forms", "A fresh task file from the generator must be as hard as the shipped one.",
     probe_parallel_forms),
]


def generic_probes(setup: AuditSetup) -> list[AuditProbe]:
    """The core's probes bound to ``setup`` (each ignores the ``run`` arguments in favour of the setup)."""
    return [AuditProbe(name=name, description=desc, run=(lambda tasks, params, fn=fn: fn(setup)))
            for name, desc, fn in _GENERIC]


class _Background:
    """``fn(*args)`` in a forked process; :meth:`result` waits for its return value (pickled back)."""

    def __init__(self, fn: Callable[..., Any], *args: Any) -> None:
        import multiprocessing

        ctx = multiprocessing.get_context("fork")
        self._recv, send = ctx.Pipe(duplex=False)
        self._proc = ctx.Process(target=_background_main, args=(send, fn, args))
        self._proc.start()
        send.close()

    wall: float = 0.0
    cpu: float = 0.0
    """Wall and CPU seconds the function took in its process (children included), known after :meth:`result`."""

    def result(self) -> Any:
        try:
            ok, value, self.wall, self.cpu = self._recv.recv()
        except EOFError:
            self._proc.join()
            raise RuntimeError(f"the background process ended without a result (exit code "
                               f"{self._proc.exitcode})") from None
        finally:
            self._recv.close()
        self._proc.join()
        if not ok:
            raise RuntimeError(value)
        return value

    def cancel(self) -> None:
        if self._proc.is_alive():
            self._proc.terminate()
        self._proc.join()
        self._recv.close()


def _background_main(send: Any, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
    clock = _Clock()
    try:
        out: tuple[Any, ...] = (True, fn(*args))
    except BaseException as exc:  # noqa: BLE001 - reported by the parent
        out = (False, f"{type(exc).__name__}: {exc}")
    send.send((*out, *clock.read()))
    send.close()


class _Clock:
    """Wall and CPU seconds since creation; CPU counts this process and its finished children (the pools)."""

    def __init__(self) -> None:
        import time

        self._t0, self._c0 = time.perf_counter(), self._cpu()

    @staticmethod
    def _cpu() -> float:
        import resource

        own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

    def read(self) -> tuple[float, float]:
        import time

        return time.perf_counter() - self._t0, self._cpu() - self._c0


def _run_probe(probe: AuditProbe, tasks: list[Task], params: dict[str, Any]) -> ProbeResult:
    try:
        return probe.run(tasks, dict(params))
    except Exception as exc:  # a crashing probe fails the audit, the others still run
        return ProbeResult(name=probe.name, passed=False, value=f"probe crashed: {type(exc).__name__}: {exc}",
                           threshold="runs to the end")


def _run_probes(probes: list[AuditProbe], tasks: list[Task],
                params: dict[str, Any]) -> list[tuple[ProbeResult, float, float]]:
    """The probes in turn, all handed one task list (a world may share work between its probes by it); each
    result with its wall and CPU seconds."""
    tasks = list(tasks)
    out = []
    for p in probes:
        clock = _Clock()
        res = _run_probe(p, tasks, params)
        out.append((res, *clock.read()))
    return out


def run_audit(setup: AuditSetup, only: Sequence[str] | None = None,
              progress: Callable[[str], None] | None = None) -> list[tuple[AuditProbe, ProbeResult]]:
    """Run the generic probes, then the world's own (``env_cls.audit_probes()``); ``only`` selects by name.
    ``progress`` gets a line as each probe starts and ends (with its wall and CPU seconds).

    With ``setup.workers > 1`` the work that runs on one core is moved beside the episode probes (which use
    ``workers`` processes): the world's probes run in one forked process and the parallel-forms probe's fresh
    form is generated in another, both started first. Results do not depend on it.
    """
    def say(msg: str) -> None:
        if progress is not None:
            progress(msg)

    generic = generic_probes(setup)
    own = list(setup.env_cls.audit_probes())
    probes = generic + own
    if only:
        names = [p.name for p in probes]
        unknown = [n for n in only if n not in names]
        if unknown:
            raise KeyError(f"unknown probe {unknown[0]!r}; probes of {setup.env_name}: {', '.join(names)}")
        probes = [p for p in probes if p.name in only]
    chosen = {p.name for p in probes}
    own_ids = {id(p) for p in own}
    side = [i for i, p in enumerate(probes) if id(p) in own_ids]  # the world's probes
    results: dict[int, ProbeResult] = {}
    background = setup.workers > 1
    pending: _Background | None = None
    tmp: str | None = None
    try:
        if (background and "parallel_forms" in chosen and not setup.quick and not setup.parallel_source
                and (setup.generator is not None or setup.form_generator is not None)):
            setup.fresh_per_subset()  # the sample size (and a cost measurement) are made here, once
            tmp = tempfile.mkdtemp(prefix="eb-audit-form-")
            setup._cache["fresh_pending"] = _Background(_write_fresh_form, setup, Path(tmp))
        if background and side:
            say(f"running {', '.join(probes[i].name for i in side)} in the background ...")
            pending = _Background(_run_probes, [probes[i] for i in side], list(setup.tasks), dict(setup.env_params))
        shared = list(setup.tasks)  # one list for the world's probes (they may share work by it)
        for i, probe in enumerate(probes):
            if pending is not None and i in side:
                continue
            say(f"running {probe.name} ...")
            clock = _Clock()
            results[i] = _run_probe(probe, shared if i in side else list(setup.tasks), setup.env_params)
            wall, cpu = clock.read()
            fresh = setup._cache.get("fresh_took") if probe.name == "parallel_forms" else None
            say(_took(probe.name, wall, cpu - (fresh[1] if fresh else 0.0)))  # the form's process ended in it
            if fresh:
                say(_took("the fresh form's generation (in the background)", *fresh))
        if pending is not None:
            try:
                for i, (res, wall, cpu) in zip(side, pending.result()):
                    results[i] = res
                    say(_took(f"{probes[i].name} (in the background)", wall, cpu))
            except RuntimeError as exc:
                for i in side:
                    results[i] = ProbeResult(name=probes[i].name, passed=False, value=f"probe crashed: {exc}",
                                             threshold="runs to the end")
            pending = None
    finally:
        if pending is not None:
            pending.cancel()
        left = setup._cache.pop("fresh_pending", None)
        if left is not None:
            left.cancel()
        if tmp is not None:
            import shutil

            shutil.rmtree(tmp, ignore_errors=True)
    return [(p, results[i]) for i, p in enumerate(probes)]


def _took(what: str, wall: float, cpu: float) -> str:
    return f"{what}: {wall:.1f} s wall, {cpu:.1f} s CPU"


def _status(res: ProbeResult) -> str:
    if not res.passed:
        return "FAIL"
    if res.warning:
        return "warn"
    return "skip" if res.skipped else "pass"


def _text_table(headers: list[str], rows: list[list[str]], widths: dict[int, int] | None = None) -> list[str]:
    """A plain-text table; a cell longer than its column's limit in ``widths`` wraps onto more lines."""
    import textwrap

    widths = widths or {}
    wrapped = [[textwrap.wrap(str(c), widths[i], break_on_hyphens=False) or [""] if i in widths else [str(c)]
                for i, c in enumerate(r)] for r in rows]
    w = [max([len(h)] + [len(ln) for r in wrapped for ln in r[i]]) for i, h in enumerate(headers)]
    out = ["  ".join(h.ljust(w[i]) for i, h in enumerate(headers)).rstrip(), "  ".join("-" * x for x in w)]
    for r in wrapped:
        for k in range(max(len(c) for c in r)):
            out.append("  ".join((c[k] if k < len(c) else "").ljust(w[i]) for i, c in enumerate(r)).rstrip())
    return out


def format_audit(env_name: str, results: list[tuple[AuditProbe, ProbeResult]], n_tasks: int,
                 note: str = "") -> str:
    """The audit as plain text: one summary table, then each probe's detail rows and warnings."""
    rows = []
    for probe, res in results:
        shown = ", ".join(res.failing_tasks[:5])
        more = len(res.failing_tasks) - 5
        if more > 0:
            shown += f" (+{more} more)"
        rows.append([res.name, probe.description, res.value, res.threshold, _status(res), shown])
    lines = [f"eb audit: {env_name}, {n_tasks} tasks" + (f" (random-action probes: {note})" if note else ""), ""]
    lines += _text_table(["probe", "guards against", "measured", "threshold", "status", "failing tasks"], rows,
                         widths={1: 36, 2: 56, 3: 34, 5: 44})
    for probe, res in results:
        if res.rows:
            keys = list(dict.fromkeys(k for r in res.rows for k in r))
            lines += ["", f"{res.name}:"]
            cells = [[str(r.get(k, "")) for k in keys] for r in res.rows]
            lines += _text_table(keys, cells, widths={len(keys) - 1: 100})
        if res.warning:
            lines += ["", f"warning ({res.name}): {res.warning}"]
        if not res.passed and len(res.failing_tasks) > 5:
            lines += ["", f"{res.name} failing tasks: {', '.join(res.failing_tasks)}"]
    failed = [r.name for _, r in results if not r.passed]
    lines += ["", f"audit {'FAILED: ' + ', '.join(failed) if failed else 'passed'} "
                  f"({len(results) - len(failed)}/{len(results)} probes pass)"]
    return "\n".join(lines)


# -- the command --------------------------------------------------------------------------------------------

AUDIT_USAGE = ("usage: eb audit env=NAME [task_file=PATH] [parallel=PATH] [per_subset=N|all] [workers=N] "
               "[repeats=N] [parallel_seed=N] [key=value ...] [--quick] [--probe NAME ...]")


def cmd_audit(args: list[str]) -> int:
    """``eb audit``: compose the config like ``eb run``, run the probes, print one table; 1 if a probe fails."""
    import os
    import sys

    from eb_core.cli import CliError, _validate, compose
    from eb_core.config import ConfigError
    from eb_core.plugins import PluginError, Registry
    from eb_core.runner import select_tasks
    from eb_core.specs import MissingDependencyError, load_entry_point

    quick, only, overrides = False, [], []
    extra: dict[str, str] = {}
    it = iter(args)
    for a in it:
        if a == "--quick":
            quick = True
        elif a == "--probe":
            name = next(it, None)
            if not name:
                raise CliError(f"--probe needs a probe name. {AUDIT_USAGE}")
            only += name.split(",")
        elif a.startswith("--probe="):
            only += a.split("=", 1)[1].split(",")
        elif a in ("-h", "--help"):
            print(AUDIT_USAGE)
            return 0
        elif a.startswith("-"):
            raise CliError(f"unknown option {a!r} for audit; options: --quick, --probe NAME. {AUDIT_USAGE}")
        elif a.split("=", 1)[0] in ("task_file", "parallel", "parallel_seed", "repeats", "per_subset", "workers"):
            key, sep, value = a.partition("=")
            if not value:
                raise CliError(f"{key}= needs a value, e.g. {key}=my_tasks.json")
            extra[key] = value
        else:
            overrides.append(a)
    if not any(o.split("=", 1)[0] == "env" for o in overrides):
        raise CliError(f"audit needs env=NAME (`eb list` shows the envs). {AUDIT_USAGE}")
    # The probes drive the env directly: no model is composed, so any installed set of plugins can be audited.
    if not any(o.lstrip("+~").split("=", 1)[0] == "model" for o in overrides):
        overrides.append("~model")
    cfg_dict = compose(overrides)
    cfg_dict["model"] = cfg_dict.get("model") or {"name": "none", "backend": "none"}
    params = cfg_dict["env"].setdefault("params", {}) or {}
    cfg_dict["env"]["params"] = params
    if "task_file" in extra:
        path = Path(extra["task_file"])
        if not path.exists():
            raise CliError(f"task_file={path} does not exist; give a task file (or folder) made by "
                           f"`eb tasks generate env={cfg_dict['env']['name']} out=...`")
        key = "task_dir" if ("task_dir" in params and "task_file" not in params) or path.is_dir() else "task_file"
        params[key] = str(path)
    cfg = _validate(cfg_dict)
    try:
        spec = Registry.create().get("env", cfg.env.name)
        env_cls = spec.load()
    except (PluginError, MissingDependencyError) as exc:
        raise CliError(str(exc)) from None
    try:
        all_tasks = env_cls.load_tasks(**cfg.env.params)
    except Exception as exc:
        raise CliError(f"cannot load the tasks of env {cfg.env.name!r}: {exc}") from None
    try:
        tasks = select_tasks(all_tasks, cfg)
    except ConfigError as exc:
        raise CliError(str(exc)) from None
    if not tasks:
        raise CliError(f"no tasks selected for env {cfg.env.name!r}; check subset=, limit= and tasks=")
    generator = load_entry_point(spec.task_generator, spec.install_hint) if spec.task_generator else None
    ints = {}
    if extra.get("per_subset") == "all":
        extra["per_subset"] = str(max(len(tasks), 1))
    for key, low in (("parallel_seed", 0), ("repeats", 10), ("per_subset", 1), ("workers", 1)):
        if key in extra:
            try:
                ints[key] = int(extra[key])
            except ValueError:
                raise CliError(f"{key}={extra[key]!r} is not an integer") from None
            if ints[key] < low:
                raise CliError(f"{key}={ints[key]} is too small; use {key}={low} or more")
    if "parallel" in extra and not Path(extra["parallel"]).exists():
        raise CliError(f"parallel={extra['parallel']} does not exist; give a task file or folder of the same world")
    setup = AuditSetup(env_name=cfg.env.name, env_cls=env_cls, tasks=tasks, max_steps=cfg.env.max_steps,
                       max_invalid_actions=cfg.env.max_invalid_actions, env_params=dict(cfg.env.params),
                       seed=cfg.seed, quick=quick, generator=generator,
                       form_generator=find_form_generator(generator), parallel_source=extra.get("parallel"),
                       parallel_seed=ints.get("parallel_seed", 2_718),
                       parallel_repeats=ints.get("repeats", 10), per_subset=ints.get("per_subset"),
                       workers=ints.get("workers", min(2, os.cpu_count() or 1)))
    try:
        results = run_audit(setup, only or None,
                            progress=lambda msg: print(f"eb audit: {msg}", file=sys.stderr, flush=True))
    except KeyError as exc:
        raise CliError(str(exc.args[0])) from None
    print(format_audit(cfg.env.name, results, len(tasks), setup.sampling_note() if "cap" in setup._cache else ""))
    return 1 if any(not r.passed for _, r in results) else 0
