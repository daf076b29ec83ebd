"""``eb serve env=<world> [taskset=...] [split=...] [runner.workers=N] [port=...] ...``: the worlds as an HTTP service.

Serve options (the rest are Hydra overrides, as for ``eb run``)::

    port=8765             0 = any free port (the ready line says which)
    host=127.0.0.1        anything but loopback also needs allow_remote=true and $EB_SERVE_TOKEN set
    envs=32               environments in the pool, leased by sessions
    obs_mode=prompt       prompt (the answer text is the action) | raw (ids or vectors)
    reward=progress       success | progress | shaped (eb_core.gym.rewards)
    session_timeout_s=300 idle sessions are reaped after this long
    step_timeout_s=600    a worker silent this long is killed and replaced
    allow_remote=false
"""

from __future__ import annotations

import os
import signal
import socket
import sys
from collections.abc import Sequence
from typing import Any

__all__ = ["SERVE_KEYS", "main", "parse"]

SERVE_KEYS = {"port": int, "host": str, "envs": int, "obs_mode": str, "reward": str, "session_timeout_s": float,
              "step_timeout_s": float, "allow_remote": bool, "split": str, "env": str, "taskset": str}
_LOOPBACK = ("127.0.0.1", "localhost", "::1")


class ServeError(ValueError):
    """A bad ``eb serve`` argument (one line)."""


def _value(key: str, raw: str) -> Any:
    kind = SERVE_KEYS[key]
    if kind is bool:
        if raw.lower() not in ("true", "false", "1", "0", "yes", "no"):
            raise ServeError(f"{key}={raw!r}: expected true or false")
        return raw.lower() in ("true", "1", "yes")
    try:
        return kind(raw)
    except ValueError:
        raise ServeError(f"{key}={raw!r}: expected a {kind.__name__}") from None


def parse(argv: Sequence[str]) -> tuple[dict[str, Any], list[str]]:
    """Split ``key=value`` arguments into serve options and Hydra overrides."""
    opts: dict[str, Any] = {"port": 8765, "host": "127.0.0.1", "envs": 32, "obs_mode": "prompt",
                            "reward": "progress", "session_timeout_s": 300.0, "step_timeout_s": 600.0,
                            "allow_remote": False, "split": "test", "env": None, "taskset": "classic"}
    overrides: list[str] = []
    for arg in argv:
        key, sep, raw = arg.partition("=")
        if not sep:
            raise ServeError(f"unexpected argument {arg!r}; eb serve takes key=value arguments, e.g. "
                             f"`eb serve env=navigation port=8765`")
        if key in SERVE_KEYS:
            opts[key] = _value(key, raw)
        else:
            overrides.append(arg)
    if not opts["env"]:
        raise ServeError("eb serve needs env=<world>, e.g. `eb serve env=navigation` (`eb list` shows the worlds)")
    if opts["obs_mode"] not in ("prompt", "raw"):
        raise ServeError(f"obs_mode={opts['obs_mode']!r}: expected prompt or raw")
    if opts["envs"] < 1:
        raise ServeError(f"envs={opts['envs']}: expected at least 1")
    if opts["host"] not in _LOOPBACK:
        if not opts["allow_remote"]:
            raise ServeError(f"host={opts['host']} exposes the worlds beyond this machine; say allow_remote=true "
                             f"and set EB_SERVE_TOKEN to a secret the clients send")
        if not os.environ.get("EB_SERVE_TOKEN"):
            raise ServeError("a server reachable from other machines needs a token: set EB_SERVE_TOKEN "
                             "(clients send it as 'Authorization: Bearer <token>')")
    return opts, overrides


def build_pool(opts: dict[str, Any], overrides: Sequence[str]) -> Any:
    """Check the config in this process (one-line errors), then start the pool's workers."""
    from eb_core.gym.env import _compose
    from eb_core.serve.pool import PoolConfig, SessionPool

    taskset = opts["taskset"]
    full = [*overrides, *([f"taskset={taskset}"] if taskset != "classic" else [])]
    cfg = _compose(opts["env"], tuple(full))
    pc = PoolConfig(world=opts["env"], capacity=opts["envs"], workers=int(cfg.runner.workers),
                    obs_mode=opts["obs_mode"], split=opts["split"], taskset=taskset, overrides=tuple(overrides),
                    env_kwargs={"reward": opts["reward"]}, executor=cfg.runner.executor,
                    session_timeout_s=opts["session_timeout_s"], step_timeout_s=opts["step_timeout_s"])
    return SessionPool(pc)


def _server_class() -> Any:
    import contextlib

    import uvicorn

    class Server(uvicorn.Server):
        """uvicorn's server, but SIGINT and SIGTERM end it gracefully and the process exits 0 (uvicorn itself
        re-raises the signal after its shutdown, which would skip closing the pool's workers)."""

        @contextlib.contextmanager
        def capture_signals(self) -> Any:
            def stop(signum: int, _frame: Any) -> None:
                self.should_exit = True

            old = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
            try:
                yield
            finally:
                for sig, handler in old.items():
                    signal.signal(sig, handler)

    return Server


def main(argv: Sequence[str]) -> int:
    try:
        import fastapi  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError as exc:
        print(f"eb serve: needs the [serve] extra ({exc.name} is missing): pip install 'embodiedbench[serve]'",
              file=sys.stderr)
        return 2
    from eb_core.serve.app import create_app

    _Server = _server_class()

    try:
        opts, overrides = parse(argv)
        pool = build_pool(opts, overrides)
    except (ValueError, RuntimeError) as exc:
        print(f"eb serve: {str(exc).splitlines()[0]}", file=sys.stderr)
        return 2
    family = socket.AF_INET6 if ":" in opts["host"] else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((opts["host"], opts["port"]))
    except OSError as exc:
        pool.shutdown()
        print(f"eb serve: cannot listen on {opts['host']}:{opts['port']}: {exc.strerror}; pick another port=",
              file=sys.stderr)
        return 2
    port = sock.getsockname()[1]
    app = create_app(pool, token=os.environ.get("EB_SERVE_TOKEN") or None, world=opts["env"])
    config = uvicorn.Config(app, log_level="warning", access_log=False, timeout_graceful_shutdown=5)
    server = _Server(config)
    host = f"[{opts['host']}]" if family == socket.AF_INET6 else opts["host"]
    print(f"eb serve: {opts['env']} ({opts['obs_mode']} mode, split={opts['split']}, taskset={opts['taskset']}), "
          f"{pool.capacity} environments on {len(pool.vec.workers)} worker(s); ready at http://{host}:{port} "
          f"(API docs at /docs)", flush=True)
    try:
        server.run(sockets=[sock])
    finally:
        pool.shutdown()
        print("eb serve: stopped; every session was closed", file=sys.stderr, flush=True)
    return 0
