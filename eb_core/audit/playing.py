"""Playing episodes for the probes: one episode under ``eb run``'s budgets, batches of them in forked worker
processes, and a function run in a background process (the world's probes, the fresh form's generation)."""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from eb_core.audit.contract import EpisodeOutcome, FeedbackPolicy, NamedPolicy, Policy
from eb_core.audit.setup import AuditSetup, _reset_seed, random_action
from eb_core.env import Action, Env, Task

__all__ = ["play", "play_jobs", "noisy_expert_episode"]


def play(env: Env, task: Task, policy: Policy, *, max_steps: int, max_invalid_actions: int | None,
         seed: int) -> EpisodeOutcome:
    """One episode under the benchmark's budgets, driving the env directly."""
    try:
        env.reset(task, seed)
        invalid = 0
        for i in range(max_steps):
            action = policy(env, i)
            if action is None:
                return EpisodeOutcome(False, i, "no_action", env.expert_reason or "")
            result = env.step(action)
            if isinstance(policy, FeedbackPolicy):
                policy.observe(result)
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
    policy: NamedPolicy | None = None
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
        return play(env, job.task, job.policy.policy(job.task), max_steps=setup.max_steps,
                    max_invalid_actions=setup.max_invalid_actions, seed=_reset_seed(setup.seed, job.task.id))
    return noisy_expert_episode(setup, env, job.task, job.noise, job.repeat)


def _play_chunk(chunk: list[_Job]) -> list[EpisodeOutcome]:
    assert _POOL_SETUP is not None
    return [_play_job(_POOL_SETUP, _POOL_ENVS, job) for job in chunk]


def _worker_init() -> None:
    """A pool worker dies quietly when the pool ends it: the ``eb`` command's SIGTERM handler (which turns the
    signal into an exception with a traceback, for the command itself) is not the worker's."""
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_DFL)


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
        with multiprocessing.get_context("fork").Pool(setup.workers, initializer=_worker_init) as pool:
            return [o for part in pool.map(_play_chunk, chunks, chunksize=1) for o in part]
    finally:
        _POOL_SETUP = None



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

