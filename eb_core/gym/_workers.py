"""The vector env's workers: a group of environments (:class:`EnvGroup`) in a local process or a Ray actor,
and the trainer-side handles that send it batches of operations and notice when it is lost.

Private to :mod:`eb_core.gym.vector` (and the ``eb serve`` session pool, which uses the same workers).
"""

from __future__ import annotations

import os
import signal
import sys
import traceback
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium

#: Environment variables a Ray actor takes from the trainer (plugin selection; the renderer's GL backend).
_RAY_ENV_VARS = ("EB_", "MUJOCO_GL", "PYOPENGL_PLATFORM")


def _error_line(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".splitlines()[0]


class EnvGroup:
    """The environments of one worker (a process or a Ray actor), stepped in turn on the caller's thread.

    :meth:`run` takes one operation per environment -- ``None`` (leave it), ``("reset", seed, options)``,
    ``("step", action, same_step)`` or ``("call", name, args, kwargs)`` -- and returns one result each. An
    environment that raises is closed and built again; its result is ``("error", message)``."""

    def __init__(self, env_fns: Sequence[Callable[[], gymnasium.Env]]) -> None:
        self.env_fns = list(env_fns)
        self.envs: list[gymnasium.Env | None] = []
        for fn in self.env_fns:
            self.envs.append(fn())

    def describe(self) -> dict[str, Any]:
        env = self.envs[0]
        assert env is not None  # just built
        return {"observation_space": env.observation_space, "action_space": env.action_space,
                "metadata": dict(getattr(env, "metadata", {}) or {}), "render_mode": env.render_mode,
                "pid": os.getpid(), "spec": env.spec}

    def run(self, ops: Sequence[Any]) -> list[Any]:
        return [None if op is None else self._one(i, op) for i, op in enumerate(ops)]

    def _env(self, i: int) -> gymnasium.Env:
        env = self.envs[i]
        if env is None:
            env = self.envs[i] = self.env_fns[i]()
        return env

    def _rebuild(self, i: int) -> None:
        env, self.envs[i] = self.envs[i], None
        if env is not None:
            try:
                env.close()
            except Exception:
                pass

    def _one(self, i: int, op: tuple[Any, ...]) -> Any:
        kind = op[0]
        try:
            if kind == "reset":
                return ("reset", *self._reset(i, op[1], op[2]))
            if kind == "step":
                obs, reward, terminated, truncated, info = self._env(i).step(op[1])
                if op[2] and (terminated or truncated):  # SameStep autoreset
                    final_obs, final_info = obs, info
                    try:
                        obs, info = self._reset(i, None, None)
                    except Exception as exc:
                        info = dict(final_info)
                        info["error"] = f"autoreset failed: {_error_line(exc)}"
                        return ("step", final_obs, float(reward), bool(terminated), True, info, True)
                    info = {"final_info": final_info, "final_obs": final_obs, **info}
                return ("step", obs, float(reward), bool(terminated), bool(truncated), info, False)
            if kind == "call":
                attr = getattr(self._env(i), op[1])
                return ("call", attr(*op[2], **op[3]) if callable(attr) else attr)
            raise ValueError(f"unknown operation {kind!r}")
        except Exception as exc:
            self._rebuild(i)
            return ("error", _error_line(exc), traceback.format_exc(limit=8))

    def _reset(self, i: int, seed: int | None, options: dict[str, Any] | None) -> tuple[Any, dict[str, Any]]:
        try:
            return self._env(i).reset(seed=seed, options=options)
        except Exception:  # a broken world: build it again and try once more
            self._rebuild(i)
            return self._env(i).reset(seed=seed, options=options)

    def close(self) -> None:
        for i in range(len(self.envs)):
            self._rebuild(i)


# -- workers -----------------------------------------------------------------------------------------


def _apply_context(environ: dict[str, str], prefixes: tuple[str, ...] | None, path: list[str]) -> None:
    """Take the trainer's environment variables (those starting with ``prefixes``, or all) and import path."""
    for key in list(os.environ):
        if (prefixes is None or key.startswith(prefixes)) and key not in environ:
            del os.environ[key]
    os.environ.update(environ)
    for p in reversed(path):
        if p not in sys.path:
            sys.path.insert(0, p)


def _process_main(conn: Any, payload: bytes) -> None:
    """A local worker process: build the group, then answer ``run`` messages until ``close`` or the pipe ends."""
    import pickle

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the trainer's; it closes the workers
    try:
        env_fns, environ, path = pickle.loads(payload)
        _apply_context(environ, None, path)
        import cloudpickle

        group = EnvGroup(cloudpickle.loads(env_fns))
        conn.send(("ready", group.describe()))
    except BaseException as exc:
        conn.send(("failed", f"{_error_line(exc)}\n{traceback.format_exc(limit=8)}"))
        return
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):  # the trainer is gone
            break
        if msg[0] == "run":
            conn.send(("ok", group.run(msg[1])))
        elif msg[0] == "close":
            group.close()
            conn.send(("closed", None))
            break
    group.close()


class _WorkerLost(Exception):
    """A worker process or actor died or stopped answering."""


class _ProcessWorker:
    """One local worker process holding a group of environments."""

    def __init__(self, payload: bytes, context: str | None, start_timeout_s: float | None) -> None:
        import multiprocessing as mp

        ctx: Any = mp.get_context(context)
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_process_main, args=(child, payload), daemon=True, name="eb-gym-worker")
        self.proc.start()
        child.close()  # so the parent sees EOF when the child dies
        self.pid = self.proc.pid
        self.start_timeout_s = start_timeout_s
        self.info: dict[str, Any] = {}

    def wait_ready(self) -> None:
        """Wait until the worker has built its environments (workers build theirs at the same time)."""
        self.info = self._ready(self.start_timeout_s)

    def _ready(self, timeout: float | None) -> dict[str, Any]:
        try:
            if not self.conn.poll(timeout):
                raise _WorkerLost(f"no answer within {timeout} s of starting")
            kind, data = self.conn.recv()
        except (EOFError, OSError) as exc:
            self.kill()
            raise _WorkerLost(f"the worker process exited while starting (exit code {self.proc.exitcode})") from exc
        if kind != "ready":
            self.kill()
            raise RuntimeError(f"building the environments failed in the worker process: {data}")
        return data

    def send(self, ops: list[Any]) -> None:
        try:
            self.conn.send(("run", ops))
        except (BrokenPipeError, OSError):
            pass  # recv reports the death

    def recv(self, timeout: float | None) -> list[Any]:
        try:
            if not self.conn.poll(timeout):
                self.kill()
                raise _WorkerLost(f"worker process {self.pid} gave no answer within {timeout} s and was killed")
            kind, data = self.conn.recv()
        except (EOFError, OSError, BrokenPipeError):
            self.proc.join(timeout=5)
            code = self.proc.exitcode
            why = f"signal {-code}" if code is not None and code < 0 else f"exit code {code}"
            raise _WorkerLost(f"worker process {self.pid} died ({why})") from None
        return data

    def kill(self) -> None:
        if self.proc.is_alive():
            self.proc.kill()
        self.proc.join(timeout=10)
        self.conn.close()

    def close(self, timeout: float = 10.0) -> None:
        try:
            self.conn.send(("close", None))
            if self.conn.poll(timeout):
                self.conn.recv()
        except (EOFError, OSError, BrokenPipeError):
            pass
        self.proc.join(timeout=timeout)
        self.kill()


class _GroupActor:
    """The Ray actor body: an :class:`EnvGroup` on the actor's one thread (a plain, non-async actor, so every
    env and GL call of the actor stays on one thread)."""

    def __init__(self, payload: bytes) -> None:
        import pickle

        env_fns, environ, path = pickle.loads(payload)
        _apply_context(environ, _RAY_ENV_VARS, path)
        import cloudpickle

        self.group = EnvGroup(cloudpickle.loads(env_fns))

    def describe(self) -> dict[str, Any]:
        return self.group.describe()

    def run(self, ops: list[Any]) -> list[Any]:
        return self.group.run(ops)

    def close(self) -> None:
        self.group.close()


_ACTOR_CLS: Any = None


class _RayWorker:
    """One Ray actor holding a group of environments."""

    def __init__(self, payload: bytes, options: dict[str, Any], start_timeout_s: float | None) -> None:
        global _ACTOR_CLS
        import ray

        if _ACTOR_CLS is None:
            _ACTOR_CLS = ray.remote(_GroupActor)
        self.ray = ray
        self.actor = _ACTOR_CLS.options(**options).remote(payload)
        self.ref: Any = self.actor.describe.remote()
        self.start_timeout_s = start_timeout_s
        self.info: dict[str, Any] = {}
        self.pid = -1

    def wait_ready(self) -> None:
        ray = self.ray
        try:
            self.info = ray.get(self.ref, timeout=self.start_timeout_s)
        except ray.exceptions.GetTimeoutError:
            self.kill()
            raise _WorkerLost(f"the Ray actor gave no answer within {self.start_timeout_s} s of starting") from None
        except ray.exceptions.RayActorError as exc:
            self.kill()
            raise RuntimeError(f"building the environments failed in the Ray actor: {_error_line(exc)}") from None
        self.pid = self.info["pid"]

    def send(self, ops: list[Any]) -> None:
        self.ref = self.actor.run.remote(ops)

    def recv(self, timeout: float | None) -> list[Any]:
        ray = self.ray
        try:
            return ray.get(self.ref, timeout=timeout)
        except ray.exceptions.GetTimeoutError:
            self.kill()
            raise _WorkerLost(f"Ray actor (pid {self.pid}) gave no answer within {timeout} s and was killed") from None
        except (ray.exceptions.RayActorError, ray.exceptions.ObjectLostError) as exc:
            raise _WorkerLost(f"Ray actor (pid {self.pid}) died: {_error_line(exc)}") from None

    def kill(self) -> None:
        try:
            self.ray.kill(self.actor, no_restart=True)
        except Exception:
            pass

    def close(self, timeout: float = 10.0) -> None:
        try:
            self.ray.get(self.actor.close.remote(), timeout=timeout)
        except Exception:
            pass
        self.kill()


# -- the vector env ----------------------------------------------------------------------------------
