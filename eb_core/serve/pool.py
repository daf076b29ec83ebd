"""The environments ``eb serve`` holds: one :class:`~eb_core.gym.EBVectorEnv` whose slots sessions lease.

The pool is a vector env of ``capacity`` environments over ``workers`` processes (or Ray actors) with autoreset off;
a session leases ``num_envs`` of its slots and behaves like an :class:`~eb_core.gym.EBVectorEnv` of its own
(autoreset ``NextStep`` by default). Calls of all sessions that arrive together are merged into one exchange with
the workers (one batch), so two trainers stepping at once use the workers in parallel, as one trainer stepping all
their environments would. A worker that dies ends only the episodes of its slots (``truncated`` with
``info["error"]``, also for sessions that were not stepping at that moment: they learn it at their next step), and
is replaced. Sessions idle longer than ``session_timeout_s`` are reaped.
"""

from __future__ import annotations

import base64
import queue
import secrets
import threading
import time
from collections import deque
from collections.abc import Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any

import gymnasium
import numpy as np

from eb_core.serve.png import encode_png

__all__ = ["PoolConfig", "PoolError", "SessionPool", "encode_png"]


class PoolError(Exception):
    """A request the pool refuses; ``status`` is the HTTP status the server answers with."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


class PngObservations(gymnasium.Wrapper):
    """Runs in the worker: every image of an observation leaves the worker as PNG bytes, so the server process
    only base64-encodes (the encoding work is spread over the workers)."""

    def _png(self, obs: Any) -> Any:
        if not isinstance(obs, dict):
            return obs
        out = dict(obs)
        if "images" in out:
            out["images"] = [encode_png(im) for im in out["images"]]
        if "image" in out and isinstance(out["image"], np.ndarray):
            out["image"] = encode_png(out["image"])
        return out

    def reset(self, **kwargs: Any) -> Any:
        obs, info = self.env.reset(**kwargs)
        return self._png(obs), info

    def step(self, action: Any) -> Any:
        obs, reward, terminated, truncated, info = self.env.step(action)
        return self._png(obs), reward, terminated, truncated, info


class _ServedEnv:
    """Picklable factory of one served environment (the gym env, wrapped to send PNG)."""

    def __init__(self, make: Any) -> None:
        self.make = make

    def __call__(self) -> gymnasium.Env:
        return PngObservations(self.make())


def jsonable(value: Any) -> Any:
    """A JSON-encodable copy of an info value (numpy scalars and arrays, tuples, bytes as base64)."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, bytes):
        return base64.b64encode(value).decode("ascii")
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def wire_observation(obs: Any) -> dict[str, Any] | None:
    """An observation (images already PNG bytes) as JSON: PNG bytes become base64 strings."""
    if obs is None:
        return None
    return {k: jsonable(v) for k, v in obs.items()}


@dataclass
class PoolConfig:
    world: str
    capacity: int = 32
    workers: int = 1
    obs_mode: str = "prompt"
    split: str = "test"
    taskset: str = "classic"
    overrides: tuple[str, ...] = ()
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    executor: str = "local"
    session_timeout_s: float = 300.0
    step_timeout_s: float | None = 600.0
    max_sessions: int = 1024


@dataclass
class Session:
    id: str
    slots: list[int]
    autoreset: str
    last_seen: float
    needs_reset: np.ndarray
    busy: threading.Lock = field(default_factory=threading.Lock)


class _Batcher:
    """One thread that owns the vector env: it merges the slot operations of calls that arrive together into one
    exchange with the workers and hands each call its results."""

    def __init__(self, vec: Any, on_lost: Any) -> None:
        self.vec, self.on_lost = vec, on_lost
        self.q: queue.Queue[tuple[dict[int, Any], Future[Any]] | None] = queue.Queue()
        self.batches = 0
        self.thread = threading.Thread(target=self._loop, name="eb-serve-batcher", daemon=True)
        self.thread.start()

    def submit(self, ops: dict[int, Any]) -> dict[int, Any]:
        fut: Future[Any] = Future()
        self.q.put((ops, fut))
        return fut.result()

    def stop(self) -> None:
        self.q.put(None)
        self.thread.join(timeout=30)

    def _loop(self) -> None:
        while True:
            item = self.q.get()
            if item is None:
                return
            batch, used = [item], set(item[0])
            deferred: list[tuple[dict[int, Any], Future[Any]] | None] = []
            while True:
                try:
                    more = self.q.get_nowait()
                except queue.Empty:
                    break
                if more is None:
                    deferred.append(None)
                    break
                if used & set(more[0]):
                    deferred.append(more)  # the same slot twice: the next batch
                else:
                    batch.append(more)
                    used |= set(more[0])
            for d in deferred:
                self.q.put(d)
            ops: list[Any] = [None] * self.vec.num_envs
            for slot_ops, _ in batch:
                for slot, op in slot_ops.items():
                    ops[slot] = op
            try:
                results, lost = self.vec._exchange(ops)
            except BaseException as exc:  # noqa: BLE001 - every waiting call gets the error, the server goes on
                for _, fut in batch:
                    fut.set_exception(exc)
                continue
            self.batches += 1
            if lost:
                self.on_lost({k: why for k, why in lost.items()}, set(used))
            for slot_ops, fut in batch:
                fut.set_result({slot: results[slot] for slot in slot_ops})


class SessionPool:
    """Sessions over one pool of environments (see the module docstring)."""

    def __init__(self, cfg: PoolConfig, vec: Any | None = None) -> None:
        self.cfg = cfg
        self.vec = vec if vec is not None else self._make_vec(cfg)
        self.single_observation_space = self.vec.single_observation_space
        self.single_action_space = self.vec.single_action_space
        self.capacity = self.vec.num_envs
        self._lock = threading.Lock()
        self._free = list(range(self.capacity))
        self._sessions: dict[str, Session] = {}
        self._broken: dict[int, str] = {}
        self.counters = {"resets": 0, "steps": 0, "errors": 0, "reaped_sessions": 0}
        self.latencies: deque[float] = deque(maxlen=10_000)
        self.started = time.monotonic()
        self._batcher = _Batcher(self.vec, self._worker_lost)
        self._stop = threading.Event()
        self._reaper = threading.Thread(target=self._reap_loop, name="eb-serve-reaper", daemon=True)
        self._reaper.start()

    @staticmethod
    def _make_vec(cfg: PoolConfig) -> Any:
        from eb_core.gym import registered_ids
        from eb_core.gym.vector import EBVectorEnv, _MakeEnv, _resolve

        gid = _resolve(cfg.world)
        overrides = tuple(cfg.overrides) + ((f"taskset={cfg.taskset}",) if cfg.taskset != "classic" else ())
        kwargs = {"obs_mode": cfg.obs_mode, "split": cfg.split, "overrides": overrides, **cfg.env_kwargs}
        fns = [_ServedEnv(_MakeEnv(gid, registered_ids()[gid], dict(kwargs)))] * cfg.capacity
        return EBVectorEnv(fns, workers=cfg.workers, executor=cfg.executor, autoreset_mode="Disabled",
                           step_timeout_s=cfg.step_timeout_s)

    # -- sessions ------------------------------------------------------------------------------------

    def create(self, num_envs: int, autoreset: str = "NextStep") -> Session:
        if autoreset not in ("NextStep", "SameStep", "Disabled"):
            raise PoolError(400, f"autoreset must be NextStep, SameStep or Disabled, got {autoreset!r}")
        with self._lock:
            if len(self._sessions) >= self.cfg.max_sessions:
                raise PoolError(503, f"the server holds its maximum of {self.cfg.max_sessions} sessions; close one")
            if num_envs > len(self._free):
                raise PoolError(503, f"asked for {num_envs} environments but {len(self._free)} of "
                                     f"{self.capacity} are free; ask for fewer, close a session, or start the "
                                     f"server with a larger envs=N")
            slots, self._free = self._free[:num_envs], self._free[num_envs:]
            sid = secrets.token_urlsafe(12)
            s = Session(sid, slots, autoreset, time.monotonic(), np.ones(num_envs, dtype=bool))
            self._sessions[sid] = s
            for slot in slots:
                self._broken.pop(slot, None)
            return s

    def get(self, sid: str) -> Session:
        with self._lock:
            s = self._sessions.get(sid)
            if s is None:
                raise PoolError(404, f"no session {sid!r} (closed, reaped after {self.cfg.session_timeout_s:g} s "
                                     f"idle, or the server restarted); create a new one with POST /v1/sessions")
            s.last_seen = time.monotonic()
            return s

    def close(self, sid: str, reaped: bool = False) -> None:
        with self._lock:
            s = self._sessions.pop(sid, None)
            if s is None:
                raise PoolError(404, f"no session {sid!r}")
            self._free.extend(s.slots)
            self._free.sort()
            if reaped:
                self.counters["reaped_sessions"] += 1

    def sessions(self) -> list[Session]:
        with self._lock:
            return list(self._sessions.values())

    def _reap_loop(self) -> None:
        period = max(0.05, min(5.0, self.cfg.session_timeout_s / 4))
        while not self._stop.wait(period):
            now = time.monotonic()
            for s in self.sessions():
                if now - s.last_seen > self.cfg.session_timeout_s and not s.busy.locked():
                    try:
                        self.close(s.id, reaped=True)
                    except PoolError:
                        pass

    def _worker_lost(self, lost: dict[int, str], in_batch: set[int]) -> None:
        with self._lock:
            for k, why in lost.items():
                for slot in self.vec.slices[k]:
                    if slot not in in_batch:
                        self._broken[slot] = f"{why}; its environments were rebuilt in a new worker"

    # -- reset and step ------------------------------------------------------------------------------

    def reset(self, s: Session, seeds: Sequence[int | None] | None, task_ids: Sequence[str | None] | None,
              mask: Sequence[bool] | None) -> tuple[list[Any], list[Any]]:
        n = len(s.slots)
        seeds = list(seeds) if seeds is not None else [None] * n
        task_ids = list(task_ids) if task_ids is not None else [None] * n
        mask = list(mask) if mask is not None else [True] * n
        for name, values in (("seeds", seeds), ("task_ids", task_ids), ("mask", mask)):
            if len(values) != n:
                raise PoolError(422, f"{name} has {len(values)} entries but the session has {n} environments; "
                                     f"give one per environment")
        ops = {slot: ("reset", seeds[i], {"task_id": task_ids[i]} if task_ids[i] is not None else None)
               for i, slot in enumerate(s.slots) if mask[i]}
        with s.busy:
            results = self._batcher.submit(ops)
            retry = {slot: ops[slot] for slot, r in results.items() if r[0] == "lost"}
            if retry:  # a worker died during the reset: its replacement resets them
                results.update(self._batcher.submit(retry))
            obs: list[Any] = [None] * n
            infos: list[Any] = [None] * n
            for i, slot in enumerate(s.slots):
                if not mask[i]:
                    continue
                r = results[slot]
                if r[0] == "reset":
                    obs[i], infos[i] = wire_observation(r[1]), jsonable(r[2])
                    s.needs_reset[i] = False
                    with self._lock:
                        self._broken.pop(slot, None)
                else:
                    self.counters["errors"] += 1
                    infos[i] = {"error": f"environment {i} could not be reset: {r[1]}"}
            self.counters["resets"] += len(ops)
            return obs, infos

    def step(self, s: Session, actions: Sequence[Any]) -> dict[str, list[Any]]:
        t0 = time.perf_counter()
        n = len(s.slots)
        if len(actions) != n:
            raise PoolError(422, f"actions has {len(actions)} entries but the session has {n} environments; give "
                                 f"one per environment (null leaves one as it is)")
        same_step = s.autoreset == "SameStep"
        out: dict[str, list[Any]] = {"observations": [None] * n, "rewards": [0.0] * n, "terminated": [False] * n,
                                     "truncated": [False] * n, "infos": [None] * n}
        with s.busy:
            ops: dict[int, Any] = {}
            with self._lock:
                broken = {slot: self._broken.pop(slot) for slot in s.slots if slot in self._broken}
            for i, slot in enumerate(s.slots):
                if slot in broken:
                    out["truncated"][i], out["infos"][i] = True, {"error": broken[slot]}
                    s.needs_reset[i] = True
                elif s.needs_reset[i] and s.autoreset != "Disabled":
                    ops[slot] = ("reset", None, None)
                elif actions[i] is not None:
                    ops[slot] = ("step", actions[i], same_step)
            results = self._batcher.submit(ops) if ops else {}
            for i, slot in enumerate(s.slots):
                r = results.get(slot)
                if r is None:
                    continue
                kind = r[0]
                if kind == "reset":
                    out["observations"][i], out["infos"][i] = wire_observation(r[1]), jsonable(r[2])
                    s.needs_reset[i] = False
                elif kind == "step":
                    out["observations"][i] = wire_observation(r[1])
                    out["rewards"][i], out["terminated"][i], out["truncated"][i] = float(r[2]), bool(r[3]), bool(r[4])
                    out["infos"][i] = jsonable(r[5])
                    done = bool(r[3] or r[4])
                    s.needs_reset[i] = (done and s.autoreset == "NextStep") or bool(r[6])
                else:  # "error" (the env raised) or "lost" (its worker died): the episode ends, truncated
                    self.counters["errors"] += 1
                    out["truncated"][i], out["infos"][i] = True, {"error": r[1]}
                    s.needs_reset[i] = True
            self.counters["steps"] += len(ops)
        self.latencies.append((time.perf_counter() - t0) * 1000.0)
        return out

    # -- health --------------------------------------------------------------------------------------

    def stats(self) -> dict[str, Any]:
        lat = np.array(self.latencies) if self.latencies else np.zeros(1)
        with self._lock:
            sessions = list(self._sessions.values())
            free = len(self._free)
        return {"sessions": len(sessions), "envs_leased": self.capacity - free, "capacity": self.capacity,
                **self.counters, "batches": self._batcher.batches, "worker_restarts": int(self.vec.restarts),
                "worker_pids": [int(p) for p in self.vec.worker_pids],
                "uptime_s": round(time.monotonic() - self.started, 3),
                "step_latency_ms": {"p50": float(np.percentile(lat, 50)), "p99": float(np.percentile(lat, 99)),
                                    "mean": float(lat.mean())}}

    def free(self) -> int:
        with self._lock:
            return len(self._free)

    def shutdown(self) -> None:
        self._stop.set()
        self._batcher.stop()
        self.vec.close()
