"""``runner.executor=ray``: env actors on a Ray cluster, the run directory written by the driver as always.

* ``runner.workers`` env actors (``num_cpus=1`` each), each playing up to ``concurrency / workers`` episodes at
  once with :class:`eb_core.inflight.InflightLoop` (env work on the actor's one thread, model calls on its thread
  pool) and reusing its envs across episodes.
* The driver (the ``eb run`` process) hands jobs to the actors and collects finished episodes: the record, the
  Ray node id that played it, and the episode's step files (written on the actor's node into a private staging
  directory, shipped back as bytes). It alone writes ``episodes.jsonl`` and the episode directories, with the
  same crash-safe append as a local run, so re-running the command after the driver died resumes.
* A lost actor (its node removed, its process killed) loses no episode: the episodes it had in flight go back
  to the queue and are played by the remaining actors (once; an episode that takes down two actors is recorded
  as an error, redone on the next resume). Nothing is doubled: results of an actor are taken only from its
  answered calls, and an actor declared dead is never asked again.
* An episode stuck in the env past ``runner.episode_timeout_s`` kills its actor (recorded as an error; the
  actor's other episodes go back to the queue) and a new actor takes its place.
* ``model.max_concurrency`` / ``model.rpm`` hold across the cluster and across all jobs using the model (a
  sweep): one named, detached limiter actor per model (:func:`get_limiter`).
* ``model.max_cost_usd`` holds per actor and, between answers, across the run (the driver stops handing out
  work once finished episodes reach the cap).

Importing this module imports ``ray``; the runner does so only when ``runner.executor=ray``.
"""

from __future__ import annotations

import importlib
import os
import shutil
import sys
import tempfile
import time
from typing import Any

from eb_core.config import RunConfig
from eb_core.env import Task
from eb_core.records import EpisodeRecord, RunFiles

INSTALL_HINT = 'runner.executor=ray needs Ray, which is not installed: pip install "embodiedbench[ray]"'



def _import_ray() -> Any:
    """The ``ray`` module, or None without the extra (Any: Ray's own types are not checked here)."""
    try:
        return importlib.import_module("ray")
    except ImportError:  # pragma: no cover - exercised without the extra
        return None


ray = _import_ray()

__all__ = ["EnvActor", "INSTALL_HINT", "connect", "get_limiter", "run_on_ray"]


def require_ray() -> Any:
    if ray is None:
        from eb_core.components import RunError

        raise RunError(INSTALL_HINT)
    return ray


def connect(address: str | None) -> bool:
    """Join the cluster at ``address`` (or ``$RAY_ADDRESS``; a local single-machine Ray when neither is set).
    Returns whether this call started the connection (the caller then shuts it down)."""
    require_ray()
    if ray.is_initialized():
        return False
    address = address or os.environ.get("RAY_ADDRESS") or None
    ray.init(address=address, include_dashboard=False, log_to_driver=False, configure_logging=False)
    return True


class _EnvActor:
    """One Ray actor: an :class:`InflightLoop` over this node's envs. Every call runs on the actor's one
    thread (a plain, non-async actor), so all env and GL work of the actor stays on it."""

    def __init__(self, cfg_dict: dict[str, Any], plugin_modules: list[str], slots: int,
                 sys_path: list[str], limiter: Any = None) -> None:
        for p in reversed(sys_path):  # plugin modules the driver imported by name (tests, benchmarks)
            if p not in sys.path:
                sys.path.insert(0, p)
        from eb_core.components import Components, build_registry, episode_seed
        from eb_core.episode import BudgetGuard
        from eb_core.inflight import InflightLoop

        cfg = RunConfig.model_validate(cfg_dict)
        registry = build_registry(plugin_modules)
        self.node = ray.get_runtime_context().get_node_id()
        self.staging = tempfile.mkdtemp(prefix="eb_ray_actor_")
        self.done: list[tuple[str, str]] = []
        self.loop = InflightLoop(
            Components(cfg, registry), RunFiles(self.staging), slots=slots,
            budget=BudgetGuard(cfg.model.max_cost_usd), hook=registry.pm.hook,
            seed_of=lambda t, r: episode_seed(cfg.seed, t, r),
            on_record=lambda key, rec: self.done.append((key, rec.model_dump_json())),
            timeout_s=cfg.runner.episode_timeout_s, node=self.node,
            call_wrapper=None if limiter is None else limited(limiter))

    def node_id(self) -> str:
        return self.node

    def step(self, jobs: list[dict[str, Any]], wait_s: float) -> dict[str, Any]:
        """Start ``jobs``, then run the episodes until one finishes or ``wait_s`` passes. Returns the finished
        episodes (record and step files), or the reason to stop the run."""
        import select

        from eb_core.model import ModelBudgetExceeded, ModelFatalError

        try:
            for job in jobs:
                self.loop.start(job["key"], Task.model_validate(job["task"]), int(job["repeat"]))
            deadline = time.monotonic() + wait_s
            self.loop.pump()
            while not self.done and self.loop.active and time.monotonic() < deadline:
                select.select([self.loop.wake_fd], [], [], max(0.0, min(0.2, deadline - time.monotonic())))
                self.loop.pump()
        except ModelFatalError as exc:
            return {"stop": "fatal", "why": str(exc)}
        except ModelBudgetExceeded as exc:
            return {"stop": "budget", "why": str(exc)}
        out = []
        for key, rec_json in self.done:
            rec = EpisodeRecord.model_validate_json(rec_json)
            out.append({"key": key, "record": rec_json, "files": self._take_files(rec.task_id, rec.repeat)})
        self.done.clear()
        return {"done": out, "node": self.node}

    def _take_files(self, task_id: str, repeat: int) -> dict[str, bytes]:
        from eb_core.records import episode_dir_name

        d = os.path.join(self.staging, "episodes", f".{episode_dir_name(task_id, repeat)}.partial")
        files: dict[str, bytes] = {}
        if os.path.isdir(d):
            for root, _dirs, names in os.walk(d):
                for n in names:
                    path = os.path.join(root, n)
                    with open(path, "rb") as fh:
                        files[os.path.relpath(path, d)] = fh.read()
            shutil.rmtree(d, ignore_errors=True)
        return files

    def close(self) -> None:
        self.loop.close()
        shutil.rmtree(self.staging, ignore_errors=True)


class _Limiter:
    """A cluster-wide per-model limit (``model.max_concurrency`` calls in flight, ``model.rpm`` starts per 60 s):
    one named, detached actor per model key, shared by every job on the cluster that uses that model (all
    jobs of a sweep). A call takes a lease and returns it; a lease not returned within ``lease_s`` (its
    node died) expires, so a lost node never leaks a slot. The first job to create it sets the limits."""

    def __init__(self, max_concurrency: int | None, rpm: int | None, lease_s: float = 600.0,
                 window_s: float = 60.0) -> None:
        self.max_concurrency, self.rpm, self.lease_s, self.window_s = max_concurrency, rpm, lease_s, window_s
        self.leases: dict[int, float] = {}
        self.starts: list[float] = []
        self.next_id = 0

    def acquire(self) -> tuple[int | None, float]:
        """(lease id, 0) when the call may start now; (None, seconds to wait) otherwise."""
        now = time.time()
        self.leases = {k: t for k, t in self.leases.items() if now - t < self.lease_s}
        self.starts = [t for t in self.starts if now - t < self.window_s]
        if self.max_concurrency and len(self.leases) >= self.max_concurrency:
            return None, 0.05
        if self.rpm and len(self.starts) >= self.rpm:
            return None, self.starts[len(self.starts) - self.rpm] + self.window_s - now
        self.next_id += 1
        self.leases[self.next_id] = now
        self.starts.append(now)
        return self.next_id, 0.0

    def release(self, lease: int) -> None:
        self.leases.pop(lease, None)

    def limits(self) -> tuple[int | None, int | None]:
        return self.max_concurrency, self.rpm


def limiter_key(model: dict[str, Any]) -> str:
    return f"{model.get('model_id') or model.get('name')}@{model.get('api_base') or model.get('backend')}"


def get_limiter(model: dict[str, Any]) -> Any:
    """The cluster's shared limiter of this model (created by the first job), or None without limits."""
    mc, rpm = model.get("max_concurrency"), model.get("rpm")
    if not (mc or rpm):
        return None
    return ray.remote(num_cpus=0)(_Limiter).options(
        name=f"eb-limit:{limiter_key(model)}"[:120], namespace="embodiedbench", get_if_exists=True,
        lifetime="detached").remote(mc, rpm)


def limited(limiter: Any) -> Any:
    """A ``call_wrapper`` for :class:`InflightLoop`: every model call waits for a lease of ``limiter``."""

    def wrap(fn: Any) -> Any:
        def call(request: Any) -> Any:
            while True:
                lease, wait = ray.get(limiter.acquire.remote())
                if lease is not None:
                    break
                time.sleep(min(max(wait, 0.02), 1.0))
            try:
                return fn(request)
            finally:
                limiter.release.remote(lease)
        return call

    return wrap


EnvActor: Any = None if ray is None else ray.remote(num_cpus=1, max_restarts=0, max_task_retries=0)(_EnvActor)


class _Slot:
    """One env actor seen from the driver: the jobs it holds (with their start times) and its pending call."""

    def __init__(self, pool: _RayPool, slots: int) -> None:
        self.slots = slots
        self.actor = EnvActor.remote(pool.cfg_dict, pool.plugin_modules, slots, pool.sys_path, pool.limiter)
        self.jobs: dict[str, tuple[Any, float]] = {}
        self.call: Any = None

    def ask(self, pool: _RayPool) -> None:
        from eb_core.workers import job_key

        new = []
        while len(self.jobs) < self.slots and pool.queue and pool.stopped is None:
            (task, repeat) = pool.queue.pop(0)
            key = job_key(task.id, repeat)
            self.jobs[key] = ((task, repeat), time.monotonic())
            new.append({"key": key, "task": task.model_dump(mode="json"), "repeat": repeat})
        if self.call is None and (new or self.jobs):
            self.call = self.actor.step.remote(new, 1.0)


class _RayPool:
    """The env actors of one run, the queue of jobs they take from and the run's budget."""

    def __init__(self, cfg: RunConfig, cfg_dict: dict[str, Any], files: RunFiles, pending: list[Any], progress: Any,
                 hook: Any, plugin_modules: list[str]) -> None:
        from eb_core.episode import BudgetGuard
        from eb_core.workers import concurrency, kill_after, split_slots

        self.cfg, self.cfg_dict, self.files, self.progress, self.hook = cfg, cfg_dict, files, progress, hook
        self.plugin_modules = plugin_modules
        self.budget = BudgetGuard(cfg.model.max_cost_usd)
        self.stopped: str | None = None
        self.timeout = cfg.runner.episode_timeout_s
        self.kill_at = kill_after(self.timeout)
        self.queue: list[Any] = list(pending)
        self.tries: dict[str, int] = {}
        self.sys_path = [p for p in sys.path if p]
        self.limiter = get_limiter(cfg.model.model_dump())  # model.rpm / max_concurrency across cluster and sweep
        self.sizes = split_slots(concurrency(cfg), cfg.runner.workers, len(pending))
        self.slots: list[_Slot] = []

    def start(self) -> None:
        self.slots = [_Slot(self, n) for n in self.sizes]

    def fail(self, job: Any, why: str) -> None:
        from eb_core.components import episode_seed
        from eb_core.inflight import error_record
        from eb_core.workers import finish_episode

        task, repeat = job
        rec = error_record(task, repeat, episode_seed(self.cfg.seed, task.id, repeat), why)
        finish_episode(self.files, rec, self.progress, self.hook)

    def lost(self, s: _Slot, why: str, culprit: str | None = None) -> None:
        """An actor is gone: its episodes go back to the queue (an episode lost twice is an error)."""
        for key, (job, _t0) in s.jobs.items():
            self.tries[key] = self.tries.get(key, 0) + 1
            if key == culprit:
                self.fail(job, f"episode exceeded runner.episode_timeout_s={self.timeout}")
            elif self.tries[key] >= 2:
                self.fail(job, f"{why} (twice; this episode is redone on resume)")
            else:
                self.queue.insert(0, job)
        s.jobs.clear()

    def take(self, s: _Slot, out: dict[str, Any]) -> None:
        """The answer of an actor's ``step`` call: finished episodes (their files written into the run), or why
        to stop."""
        from eb_core.components import RunError
        from eb_core.model import ModelBudgetExceeded
        from eb_core.workers import finish_episode

        if "stop" in out:
            if out["stop"] == "fatal":
                raise RunError(out["why"])
            self.stopped = f"budget: {out['why']}"
            return
        for item in out["done"]:
            if s.jobs.pop(item["key"], None) is None:
                continue  # not ours any more (never happens: a dead actor is never asked again)
            rec = EpisodeRecord.model_validate_json(item["record"])
            stage = self.files.staging_dir(rec.task_id, rec.repeat)
            for rel, data in item["files"].items():
                path = stage / rel
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(data)
            finish_episode(self.files, rec, self.progress, self.hook)
            try:
                self.budget.add(rec.cost_usd)
            except ModelBudgetExceeded as exc:
                self.stopped = f"budget: {exc}"

    def kill_hung(self) -> None:
        """Kill the actors holding an episode past the timeout; replace them while there is work."""
        if self.kill_at is None:
            return
        now = time.monotonic()
        for s in list(self.slots):
            hung = [k for k, (_j, t0) in s.jobs.items() if now - t0 > self.kill_at]
            if hung:
                ray.kill(s.actor, no_restart=True)
                self.lost(s, "actor killed", culprit=hung[0])
                self.slots.remove(s)
                if self.queue or any(x.jobs for x in self.slots):
                    self.slots.append(_Slot(self, s.slots))

    def run(self) -> None:
        while self.stopped is None:
            for s in self.slots:
                s.ask(self)
            calls = {s.call: s for s in self.slots if s.call is not None}
            if not calls:
                if self.queue and not self.slots:  # every actor was lost: start one more
                    self.slots.append(_Slot(self, self.sizes[0]))
                    continue
                break
            ready, _ = ray.wait(list(calls), num_returns=1, timeout=1.0)
            for ref in ready:
                s = calls[ref]
                s.call = None
                try:
                    out = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    self.lost(s, f"Ray actor lost ({type(exc).__name__})")
                    self.slots.remove(s)
                    continue
                self.take(s, out)
                if self.stopped is not None and "stop" in out:
                    break
            self.kill_hung()

    def close(self) -> None:
        try:  # let live actors remove their staging directories
            ray.get([s.actor.close.remote() for s in self.slots], timeout=5)
        except Exception:
            pass
        for s in self.slots:
            try:
                ray.kill(s.actor, no_restart=True)
            except Exception:
                pass


def run_on_ray(cfg: RunConfig, cfg_dict: dict[str, Any], files: RunFiles, pending: list[Any], progress: Any,
               hook: Any, plugin_modules: list[str], preflight: Any = None) -> str | None:
    """Play ``pending`` (task, repeat) jobs on Ray actors; :func:`eb_core.workers.finish_episode` writes every
    record (labelled by the actor, where its steps were in memory). Returns why the run stopped early, or None."""
    require_ray()
    from eb_core.model import ModelBudgetExceeded

    started_ray = connect(cfg.runner.ray_address)
    pool = _RayPool(cfg, cfg_dict, files, pending, progress, hook, plugin_modules)
    try:
        if preflight is not None:
            try:
                pool.budget.add(preflight())
            except ModelBudgetExceeded as exc:
                return f"budget: {exc}"
        pool.start()
        pool.run()
    finally:
        pool.close()
        if started_ray:
            ray.shutdown()
    return pool.stopped
