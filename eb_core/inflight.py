"""Many episodes in flight in one process: env work on one thread, model calls on a thread pool.

:class:`InflightLoop` holds up to ``slots`` episodes, each an :class:`~eb_core.episode.EpisodeDriver` with its
own env and model backend (taken from a per-process pool, so envs are built once and reused across
episodes). All env work (reset, step, render, step files, hooks) runs on the thread that calls
:meth:`InflightLoop.start` and :meth:`InflightLoop.pump` -- MuJoCo GL contexts are bound to the thread that
made them -- while each episode's pending ``backend.complete(request)`` runs on a thread pool. So while one
episode waits seconds for its model, the process steps and renders the others.

Used by the runner's local worker processes (``runner.concurrency > runner.workers``) and by the Ray env
actors (:mod:`eb_core.ray_executor`). Both report a finished episode through ``on_record``; the caller
(the run's driver process) alone writes the run directory.
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial
from typing import Any

from eb_core.components import label_record
from eb_core.env import Env, Task
from eb_core.episode import BudgetGuard, EpisodeDriver
from eb_core.model import ModelBackend, ModelBudgetExceeded, ModelFatalError
from eb_core.records import EpisodeRecord, RunFiles

__all__ = ["InflightLoop", "error_record", "node_name", "with_node"]


def node_name() -> str:
    """Where an episode ran when not under Ray: the host name."""
    return socket.gethostname()


def with_node(rec: EpisodeRecord, node: str) -> EpisodeRecord:
    """The record with its ``node`` set."""
    return rec.model_copy(update={"node": node})


def error_record(task: Task, repeat: int, seed: int, why: str) -> EpisodeRecord:
    """The record of an episode that could not be measured (redone on resume)."""
    return EpisodeRecord(task_id=task.id, subset=task.subset, instruction=task.instruction, status="error",
                         end_reason="error", error=why, seed=seed, repeat=repeat)


@dataclass
class _Episode:
    key: str
    task: Task
    repeat: int
    driver: EpisodeDriver
    env: Env
    backend: ModelBackend
    started: float = field(default_factory=time.monotonic)
    future: Future[Any] | None = None


class InflightLoop:
    """Up to ``slots`` episodes of one process in flight at once (see the module docstring).

    ``comps`` is the run's :class:`~eb_core.components.Components`; ``seed_of(task_id, repeat)`` gives the
    episode seed; ``on_record(key, record)`` receives every finished episode, ``status="error"`` ones
    included (an env that raised, a model that stayed unreachable, an episode past ``timeout_s`` while it
    waited for its model). :class:`ModelFatalError` and :class:`ModelBudgetExceeded` propagate out of
    :meth:`start` and :meth:`pump`: the caller stops.
    """

    def __init__(self, comps: Any, files: RunFiles, *, slots: int, budget: BudgetGuard, hook: Any,
                 seed_of: Callable[[str, int], int], on_record: Callable[[str, EpisodeRecord], None],
                 timeout_s: float | None = None, node: str | None = None,
                 call_wrapper: Callable[[Callable[[Any], Any]], Callable[[Any], Any]] | None = None,
                 label: bool = True) -> None:
        self.comps = comps
        self.cfg = comps.cfg
        self.files = files
        self.slots = slots
        self.budget = budget
        self.hook = hook
        self.seed_of = seed_of
        self.on_record = on_record
        self.timeout_s = timeout_s
        self.node = node or node_name()
        self.call_wrapper = call_wrapper
        """Wraps every ``backend.complete`` (the Ray executor's cluster-wide rate limit)."""
        self.label = label
        """Give every finished ``ok`` record its error labels (:func:`eb_core.components.label_record`)."""
        self.active: dict[str, _Episode] = {}
        self._free_envs: list[Env] = []
        self._free_backends: list[ModelBackend] = []
        self._envs_made = 0
        self._calls = ThreadPoolExecutor(max_workers=max(1, slots), thread_name_prefix="eb-model-call")
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)

    # -- public ---------------------------------------------------------------------------------------

    @property
    def wake_fd(self) -> int:
        """Readable when a model call has finished (wait on it together with your job channel)."""
        return self._wake_r

    @property
    def free_slots(self) -> int:
        return self.slots - len(self.active)

    @property
    def envs_made(self) -> int:
        """How many envs this process has built (at most ``slots``: they are reused)."""
        return self._envs_made

    def start(self, key: str, task: Task, repeat: int) -> None:
        """Begin an episode: reset its env and run it up to its first model call."""
        if key in self.active:
            raise ValueError(f"episode {key!r} is already in flight")
        env = self._free_envs.pop() if self._free_envs else self._make_env()
        backend = self._free_backends.pop() if self._free_backends else self.comps.make_backend()
        driver = EpisodeDriver(
            env=env, task=task, seed=self.seed_of(task.id, repeat), planner=self.comps.make_planner(backend),
            backend=backend, env_config=self.cfg.env,
            options=self.comps.episode_options(self.files, task, repeat, budget=self.budget, hook=self.hook))
        ep = _Episode(key=key, task=task, repeat=repeat, driver=driver, env=env, backend=backend)
        self.active[key] = ep
        self._advance(ep, driver.next_request)

    def pump(self) -> int:
        """Feed every finished model call back to its episode and run it to its next call (on this thread);
        drop episodes past the timeout. Returns how many episodes moved."""
        self._drain_wake()
        moved = 0
        for ep in list(self.active.values()):
            fut = ep.future
            if fut is not None and fut.done():
                ep.future = None
                exc = fut.exception()
                if exc is not None:
                    self._advance(ep, partial(ep.driver.fail, exc))
                else:
                    self._advance(ep, partial(ep.driver.submit, fut.result()))
                moved += 1
            elif self.timeout_s is not None and time.monotonic() - ep.started > self.timeout_s:
                self._time_out(ep)
                moved += 1
        return moved

    def abandon(self) -> None:
        """Drop every episode in flight (no records): the process is stopping."""
        for ep in list(self.active.values()):
            ep.driver.close()
        self.active.clear()

    def close(self) -> None:
        self.abandon()
        self._calls.shutdown(wait=False, cancel_futures=True)
        for env in self._free_envs:
            env.close()
        for backend in self._free_backends:
            backend.close()
        self._free_envs.clear()
        self._free_backends.clear()
        for fd in (self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass

    # -- internals ------------------------------------------------------------------------------------

    def _make_env(self) -> Env:
        env = self.comps.make_env()
        self._envs_made += 1
        return env

    def _advance(self, ep: _Episode, step: Callable[[], Any]) -> None:
        """Run ``step`` (env work up to the next model call) and send that call to the pool, or finish."""
        try:
            step()
        except (ModelFatalError, ModelBudgetExceeded):
            self.active.pop(ep.key, None)
            raise
        request = ep.driver.next_request()
        if request is None:
            self.active.pop(ep.key, None)
            self._free_envs.append(ep.env)
            self._free_backends.append(ep.backend)
            assert ep.driver.record is not None
            rec = ep.driver.record.model_copy(update={"repeat": ep.repeat})
            if self.label:  # here, where the steps are in memory: nothing re-reads steps.jsonl
                rec = label_record(rec, ep.driver.steps)
            self.on_record(ep.key, with_node(rec, self.node))
            return
        call = ep.backend.complete if self.call_wrapper is None else self.call_wrapper(ep.backend.complete)
        ep.future = self._calls.submit(call, request)
        ep.future.add_done_callback(self._wake)

    def _time_out(self, ep: _Episode) -> None:
        """An episode past ``timeout_s`` while its model call is in flight: recorded as an error. Its env and
        backend are not reused (the call may still be running on a pool thread)."""
        self.active.pop(ep.key, None)
        ep.driver.close()
        self.on_record(ep.key, with_node(
            error_record(ep.task, ep.repeat, self.seed_of(ep.task.id, ep.repeat),
                         f"episode exceeded runner.episode_timeout_s={self.timeout_s} (waiting for the model)"),
            self.node))

    def _wake(self, _fut: Future[Any]) -> None:
        try:
            os.write(self._wake_w, b"\0")
        except (BlockingIOError, OSError):
            pass  # the pipe is full (a wake-up is pending anyway) or closed

    def _drain_wake(self) -> None:
        try:
            while os.read(self._wake_r, 4096):
                pass
        except (BlockingIOError, OSError):
            pass
