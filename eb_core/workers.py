"""The runner's local worker processes and the bookkeeping every executor shares.

:func:`run_workers` supervises ``runner.workers`` processes (:func:`worker_main`), each playing up to its share
of ``runner.concurrency`` episodes at once (:class:`eb_core.inflight.InflightLoop`). Jobs go out and records
come back over one private pipe per worker, so a worker that dies mid-message breaks only its own channel. A
worker that dies, or holds an episode past ``runner.episode_timeout_s``, is replaced and its episodes are
recorded as errors (redone on resume). :func:`finish_episode` writes a finished episode into the run directory;
only the run's own process calls it, under every executor.
"""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import time
from typing import Any

from eb_core.components import Components, RunError, build_registry, episode_seed
from eb_core.config import RunConfig
from eb_core.env import Task
from eb_core.episode import BudgetGuard
from eb_core.events import EpisodeEndEvent
from eb_core.inflight import error_record, node_name, with_node
from eb_core.model import ModelBudgetExceeded, ModelFatalError
from eb_core.records import EpisodeRecord, RunFiles

__all__ = ["Job", "concurrency", "finish_episode", "job_key", "run_workers", "split_slots", "worker_main"]

Job = tuple[Task, int]
"""One episode to play: a task and its repeat."""


def concurrency(cfg: RunConfig) -> int:
    """Episodes in flight: ``runner.concurrency``, or one per worker."""
    return cfg.runner.concurrency or cfg.runner.workers


def split_slots(concurrency: int, workers: int, pending: int) -> list[int]:
    """Episodes in flight per worker: ``min(concurrency, pending)`` spread evenly over at most ``workers``."""
    total = max(1, min(concurrency, pending))
    n = max(1, min(workers, total))
    return [total // n + (1 if i < total % n else 0) for i in range(n)]


def job_key(task_id: str, repeat: int) -> str:
    return f"{task_id}#{repeat}"


def kill_after(timeout: float | None) -> float | None:
    """When a supervisor kills a worker whose episode is still running: a little after the timeout (the
    worker drops an episode that waits for its model past the timeout itself)."""
    return None if timeout is None else timeout + max(1.0, 0.1 * timeout)


def finish_episode(files: RunFiles, rec: EpisodeRecord, progress: Any, hook: Any) -> None:
    """Move the episode's step files into place, append its record, report it (progress, ``eb_on_episode_end``).
    The record arrives labelled (:func:`eb_core.components.label_record`, where its steps were in memory)."""
    files.finalize_episode_dir(rec.task_id, rec.repeat)
    files.append_episode(rec)
    progress.update(rec)
    hook.eb_on_episode_end(event=EpisodeEndEvent(run_dir=str(files.root), record=rec.model_dump()))


# -- the worker process ---------------------------------------------------------------------------------


def worker_main(cfg_dict: dict[str, Any], run_dir: str, plugin_modules: list[str], conn: Any,
                shared_cost: Any, slots: int = 1) -> None:
    """A worker process: plays up to ``slots`` episodes at once, each with its own env from the process's pool;
    jobs arrive over its own pipe, labelled records go back over it."""
    from multiprocessing.connection import wait

    from eb_core.inflight import InflightLoop

    cfg = RunConfig.model_validate(cfg_dict)
    registry = build_registry(plugin_modules)
    loop = InflightLoop(Components(cfg, registry), RunFiles(run_dir), slots=slots,
                        budget=BudgetGuard(cfg.model.max_cost_usd, shared_cost), hook=registry.pm.hook,
                        seed_of=lambda t, r: episode_seed(cfg.seed, t, r),
                        on_record=lambda key, rec: conn.send(("done", rec.model_dump_json())),
                        timeout_s=cfg.runner.episode_timeout_s)
    parent = os.getppid()
    try:
        while True:
            ready = wait([conn, loop.wake_fd], timeout=0.25)
            if os.getppid() != parent:  # the run's process died (kill -9): its pipe may never report EOF
                break
            try:
                if conn in ready and not _take_jobs(conn, loop):
                    break
                loop.pump()
            except ModelFatalError as exc:
                conn.send(("fatal", str(exc)))
                break
            except ModelBudgetExceeded as exc:
                conn.send(("budget", str(exc)))
                break
    except (EOFError, OSError, KeyboardInterrupt):
        pass
    finally:
        loop.close()
        conn.close()
    # Everything is flushed and closed: skip the interpreter's slow teardown of a big process.
    os._exit(0)


def _take_jobs(conn: Any, loop: Any) -> bool:
    """Start every job waiting on ``conn``; False when the supervisor said stop (None)."""
    while conn.poll():
        item = conn.recv()
        if item is None:
            return False
        job = json.loads(item)
        loop.start(job["key"], Task.model_validate(job["task"]), int(job["repeat"]))
    return True


# -- the supervisor ---------------------------------------------------------------------------------------


class _Worker:
    """One worker process seen from the supervisor: its pipe and the jobs it holds, with their start times."""

    def __init__(self, pool: _Pool, slots: int) -> None:
        self.slots = slots
        self.conn, child = pool.ctx.Pipe(duplex=True)
        self.proc = pool.ctx.Process(target=worker_main, daemon=True,
                                     args=(pool.cfg_dict, str(pool.files.root), pool.plugin_modules, child,
                                           pool.shared_cost, slots))
        self.proc.start()
        child.close()
        self.jobs: dict[str, tuple[Job, float]] = {}

    def give(self, job: Job) -> None:
        key = job_key(job[0].id, job[1])
        self.jobs[key] = (job, time.monotonic())
        self.conn.send(json.dumps({"key": key, "task": job[0].model_dump(mode="json"), "repeat": job[1]}))

    def messages(self, ready: list[Any]) -> list[tuple[str, str]]:
        """Every message waiting on the worker's pipe (none when it is not in ``ready`` or is broken)."""
        out: list[tuple[str, str]] = []
        while self.conn in ready:
            try:
                if not self.conn.poll():
                    break
                out.append(self.conn.recv())
            except (EOFError, OSError):
                break
        return out


class _Pool:
    """The worker processes of one run and the queue of jobs they take from."""

    def __init__(self, cfg: RunConfig, cfg_dict: dict[str, Any], files: RunFiles, pending: list[Job],
                 progress: Any, hook: Any, plugin_modules: list[str]) -> None:
        self.cfg, self.cfg_dict, self.files = cfg, cfg_dict, files
        self.progress, self.hook, self.plugin_modules = progress, hook, plugin_modules
        self.ctx: Any = mp.get_context(cfg.runner.start_method)
        self.shared_cost = self.ctx.Value("d", 0.0)
        self.queue: list[Job] = list(pending)
        self.timeout = cfg.runner.episode_timeout_s
        self.kill_after = kill_after(self.timeout)
        self.workers = [_Worker(self, n) for n in split_slots(concurrency(cfg), cfg.runner.workers, len(pending))]
        self.stopped: str | None = None

    def fill(self) -> list[_Worker]:
        """Hand out queued jobs to free slots; the workers that hold jobs."""
        for w in self.workers:
            while len(w.jobs) < w.slots and self.queue:
                w.give(self.queue.pop(0))
        return [w for w in self.workers if w.jobs]

    def handle(self, w: _Worker, kind: str, payload: str) -> None:
        if kind == "done":
            rec = EpisodeRecord.model_validate_json(payload)
            w.jobs.pop(job_key(*rec.key), None)
            finish_episode(self.files, rec, self.progress, self.hook)
        elif kind == "fatal":
            raise RunError(payload)
        elif kind == "budget":
            self.stopped = f"budget: {payload}"

    def check(self, w: _Worker) -> None:
        """Replace ``w`` when it died or holds an episode past the timeout; its episodes are recorded as errors."""
        now = time.monotonic()
        hung = [k for k, (_j, t0) in w.jobs.items() if self.kill_after is not None and now - t0 > self.kill_after]
        if not hung and w.proc.is_alive():
            return
        if hung:
            w.proc.kill()
        w.proc.join(5)
        why = (f"episode exceeded runner.episode_timeout_s={self.timeout}" if hung
               else f"worker process died (exit code {w.proc.exitcode})")
        self.lost(w, why, culprit=hung[0] if hung else None)
        self.workers.remove(w)
        if self.queue:
            self.workers.append(_Worker(self, w.slots))

    def lost(self, w: _Worker, why: str, culprit: str | None = None) -> None:
        for key, ((t, repeat), _started) in list(w.jobs.items()):
            msg = why if culprit in (None, key) else (
                f"{why.split(' (', 1)[0]} -- killed with episode {culprit} of the same worker process")
            rec = error_record(t, repeat, episode_seed(self.cfg.seed, t.id, repeat), msg)
            finish_episode(self.files, with_node(rec, node_name()), self.progress, self.hook)
        w.jobs.clear()

    def run(self) -> None:
        from multiprocessing.connection import wait

        while self.stopped is None:
            busy = self.fill()
            if not busy:
                break
            ready = wait([w.conn for w in busy] + [w.proc.sentinel for w in busy], timeout=0.5)
            for w in busy:
                msgs = w.messages(ready)
                for kind, payload in msgs:
                    self.handle(w, kind, payload)
                    if self.stopped is not None:
                        break
                if not (msgs and w.proc.is_alive()):
                    self.check(w)

    def close(self) -> None:
        for w in self.workers:
            try:
                w.conn.send(None)
            except (OSError, BrokenPipeError):
                pass
        deadline = time.monotonic() + (10 if self.stopped is None else 3)
        for w in self.workers:
            w.proc.join(max(0.1, deadline - time.monotonic()))
            if w.proc.is_alive():
                w.proc.kill()
                w.proc.join(2)


def run_workers(cfg: RunConfig, cfg_dict: dict[str, Any], files: RunFiles, pending: list[Job], progress: Any,
                hook: Any, plugin_modules: list[str], preflight: Any = None) -> str | None:
    """Play ``pending`` on local worker processes (started while the preflight call is in flight); returns why
    the run stopped early, or None."""
    pool = _Pool(cfg, cfg_dict, files, pending, progress, hook, plugin_modules)
    try:
        if preflight is not None:
            cost = preflight()
            try:
                BudgetGuard(cfg.model.max_cost_usd, pool.shared_cost).add(cost)
            except ModelBudgetExceeded as exc:
                pool.stopped = f"budget: {exc}"
        pool.run()
    finally:
        pool.close()
    return pool.stopped
