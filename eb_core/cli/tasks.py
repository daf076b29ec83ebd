"""``eb tasks generate env=NAME [key=value ...]``: write a task file with the env's generator.

Progress goes to stderr: the generator's own lines when it takes ``progress`` (one per task, room or subset),
and otherwise a heartbeat line every :data:`HEARTBEAT_S` seconds, so a long generation is never silent. The
result line (what was written) is the only line on stdout.
"""

from __future__ import annotations

import contextlib
import inspect
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

from eb_core.exceptions import CliError

USAGE = "usage: eb tasks generate env=NAME [key=value ...] [out=PATH]"
HEARTBEAT_S = 15.0


def _parse(args: list[str]) -> dict[str, Any]:
    import yaml

    kwargs: dict[str, Any] = {}
    for a in args:
        key, sep, value = a.partition("=")
        if not sep or not key:
            raise CliError(f"expected key=value, got {a!r}; {USAGE}")
        kwargs[key] = yaml.safe_load(value) if value else ""
    return kwargs


@contextlib.contextmanager
def _heartbeat(label: str, every_s: float) -> Iterator[None]:
    """Print ``label: still working (N s)`` to stderr every ``every_s`` seconds until the block ends."""
    stop = threading.Event()
    start = time.monotonic()

    def beat() -> None:
        while not stop.wait(every_s):
            print(f"{label}: still generating ({time.monotonic() - start:.0f} s)", file=sys.stderr, flush=True)

    thread = threading.Thread(target=beat, daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(1)


def _check_split(spec: Any, split: Any) -> None:
    if split is None or split == "test":
        return
    env_cls = spec.load()
    if split not in getattr(env_cls, "splits", ()):
        try:
            env_cls.split_tasks(str(split), 0, 1)
        except ValueError as exc:
            raise CliError(str(exc)) from None


def _call(fn: Callable[..., Any], kwargs: dict[str, Any], label: str) -> Any:
    """Run the generator; its progress lines (``progress=True`` where it takes it) go to stderr."""
    try:
        takes_progress = "progress" in inspect.signature(fn).parameters
    except (TypeError, ValueError):
        takes_progress = False
    if takes_progress:
        kwargs.setdefault("progress", True)
    start = time.monotonic()
    with _heartbeat(label, HEARTBEAT_S), contextlib.redirect_stdout(sys.stderr):
        result = fn(**kwargs)
    print(f"{label}: done in {time.monotonic() - start:.1f} s", file=sys.stderr, flush=True)
    return result


def cmd_tasks(args: list[str]) -> int:
    from eb_core.plugins import PluginError, Registry
    from eb_core.specs import load_entry_point

    if not args or args[0] != "generate":
        raise CliError(USAGE)
    kwargs = _parse(args[1:])
    env_name = kwargs.pop("env", None)
    if not env_name:
        raise CliError("tasks generate needs env=NAME (`eb list` shows the envs)")
    try:
        spec = Registry.create().env(str(env_name))
    except PluginError as exc:
        raise CliError(str(exc)) from None
    if not spec.task_generator:
        raise CliError(f"env {env_name!r} (plugin {spec.plugin}) ships no task generator")
    _check_split(spec, kwargs.get("split"))
    fn = load_entry_point(spec.task_generator, spec.install_hint)
    try:
        result = _call(fn, kwargs, f"eb tasks generate env={env_name}")
    except (TypeError, ValueError) as exc:
        raise CliError(f"{spec.task_generator}: {exc}") from None
    if result is not None:
        print(result if isinstance(result, str) else f"generated {result}")
    return 0
