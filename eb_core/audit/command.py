"""``eb audit``: compose the config like ``eb run``, run the probes, print one table; 1 if a probe fails.

The CLI calls :func:`cmd_audit` with the words after ``audit``; everything else about the command lives here.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from eb_core.audit.forms import find_form_generator, task_param
from eb_core.audit.render import format_audit
from eb_core.audit.running import run_audit
from eb_core.audit.setup import AuditSetup

__all__ = ["AUDIT_USAGE", "cmd_audit"]

AUDIT_USAGE = ("usage: eb audit env=NAME [taskset=classic|hard] [task_file=PATH] [parallel=PATH] "
               "[per_subset=N|all] [workers=N] [repeats=N] [parallel_seed=N] [key=value ...] [--quick] "
               "[--probe NAME ...]")

_OWN_KEYS = ("task_file", "parallel", "parallel_seed", "repeats", "per_subset", "workers")
"""``key=value`` words the audit reads itself (everything else is a config override)."""
_INT_KEYS = (("parallel_seed", 0), ("repeats", 10), ("per_subset", 1), ("workers", 1))
"""Integer options and their smallest allowed value."""


@dataclass
class AuditArgs:
    """The command line, split: flags, the audit's own options and the config overrides."""

    quick: bool = False
    only: list[str] = field(default_factory=list)
    overrides: list[str] = field(default_factory=list)
    extra: dict[str, str] = field(default_factory=dict)
    help: bool = False


def _config_path() -> tuple[type[Exception], Callable[..., Any], Callable[..., Any]]:
    """``(CliError, compose, validate)`` from the one config path (``eb_core.exceptions``, ``eb_core.compose``)."""
    from eb_core.compose import compose, validate
    from eb_core.exceptions import CliError

    return CliError, compose, validate


def _error(msg: str) -> Exception:
    return _config_path()[0](msg)


def parse_args(args: list[str]) -> AuditArgs:
    """Split ``eb audit``'s words; a bad one raises the CLI's one-line error."""
    out = AuditArgs()
    it = iter(args)
    for a in it:
        if a == "--quick":
            out.quick = True
        elif a == "--probe":
            name = next(it, None)
            if not name:
                raise _error(f"--probe needs a probe name. {AUDIT_USAGE}")
            out.only += name.split(",")
        elif a.startswith("--probe="):
            out.only += a.split("=", 1)[1].split(",")
        elif a in ("-h", "--help"):
            out.help = True
        elif a.startswith("-"):
            raise _error(f"unknown option {a!r} for audit; options: --quick, --probe NAME. {AUDIT_USAGE}")
        elif a.split("=", 1)[0] in _OWN_KEYS:
            key, _, value = a.partition("=")
            if not value:
                raise _error(f"{key}= needs a value, e.g. {key}=my_tasks.json")
            out.extra[key] = value
        else:
            out.overrides.append(a)
    if not out.help and not any(o.split("=", 1)[0] == "env" for o in out.overrides):
        raise _error(f"audit needs env=NAME (`eb list` shows the envs). {AUDIT_USAGE}")
    return out


def _ints(extra: dict[str, str], n_tasks: int) -> dict[str, int]:
    """The integer options, checked (``per_subset=all`` = every task)."""
    if extra.get("per_subset") == "all":
        extra["per_subset"] = str(max(n_tasks, 1))
    ints = {}
    for key, low in _INT_KEYS:
        if key in extra:
            try:
                ints[key] = int(extra[key])
            except ValueError:
                raise _error(f"{key}={extra[key]!r} is not an integer") from None
            if ints[key] < low:
                raise _error(f"{key}={ints[key]} is too small; use {key}={low} or more")
    return ints


def _composed(parsed: AuditArgs) -> Any:
    """The validated run config (no model: the probes drive the env directly, so any installed set of plugins
    can be audited), with ``task_file=`` put into the env's params."""
    _, compose, validate = _config_path()
    overrides = list(parsed.overrides)
    if not any(o.lstrip("+~").split("=", 1)[0] == "model" for o in overrides):
        overrides.append("~model")
    cfg_dict = compose(overrides)
    cfg_dict["model"] = cfg_dict.get("model") or {"name": "none", "backend": "none"}
    params = cfg_dict["env"].setdefault("params", {}) or {}
    cfg_dict["env"]["params"] = params
    if "task_file" in parsed.extra:
        path = Path(parsed.extra["task_file"])
        if not path.exists():
            raise _error(f"task_file={path} does not exist; give a task file (or folder) made by "
                         f"`eb tasks generate env={cfg_dict['env']['name']} out=...`")
        key = task_param(params)
        params[key] = str(path)
    try:
        return validate(cfg_dict)
    except ValueError as exc:  # ConfigError: one line naming the key
        raise _error(str(exc)) from None


def _load(cfg: Any) -> tuple[Any, type, list[Any]]:
    """The env's spec, its class and the selected tasks of the chosen task set (loaded as ``eb run`` does)."""
    from eb_core.config import ConfigError
    from eb_core.plugins import PluginError, Registry
    from eb_core.components import select_tasks
    from eb_core.specs import MissingDependencyError

    try:
        spec = Registry.create().env(cfg.env.name)
        env_cls = spec.load()
    except (PluginError, MissingDependencyError) as exc:
        raise _error(str(exc)) from None
    params = dict(cfg.env.params)
    if cfg.taskset != "classic":
        if cfg.taskset not in spec.tasksets:
            raise _error(f"unknown taskset {cfg.taskset!r} for env {cfg.env.name!r}; available: "
                         f"{', '.join(spec.tasksets)}. Fix: taskset=classic or one of those.")
        params["taskset"] = cfg.taskset
    try:
        all_tasks = env_cls.load_tasks(**params)
    except Exception as exc:
        raise _error(f"cannot load the tasks of env {cfg.env.name!r}: {exc}") from None
    try:
        tasks = select_tasks(all_tasks, cfg)
    except ConfigError as exc:
        raise _error(str(exc)) from None
    if not tasks:
        raise _error(f"no tasks selected for env {cfg.env.name!r}; check subset=, limit= and tasks=")
    return spec, env_cls, tasks


def build_setup(parsed: AuditArgs) -> AuditSetup:
    """The :class:`AuditSetup` the command line asks for."""
    from eb_core.specs import load_entry_point

    cfg = _composed(parsed)
    spec, env_cls, tasks = _load(cfg)
    generator = load_entry_point(spec.task_generator, spec.install_hint) if spec.task_generator else None
    probes = list(load_entry_point(spec.audit_probes, spec.install_hint)()) if spec.audit_probes else None
    ints = _ints(parsed.extra, len(tasks))
    if "parallel" in parsed.extra and not Path(parsed.extra["parallel"]).exists():
        raise _error(f"parallel={parsed.extra['parallel']} does not exist; give a task file or folder of the same "
                     f"world")
    return AuditSetup(env_name=cfg.env.name, env_cls=env_cls, tasks=tasks, max_steps=cfg.env.max_steps,
                      max_invalid_actions=cfg.env.max_invalid_actions, env_params=dict(cfg.env.params),
                      seed=cfg.seed, quick=parsed.quick, generator=generator,
                      form_generator=find_form_generator(generator), parallel_source=parsed.extra.get("parallel"),
                      parallel_seed=ints.get("parallel_seed", 2_718),
                      parallel_repeats=ints.get("repeats", 10), per_subset=ints.get("per_subset"),
                      workers=ints.get("workers", min(2, os.cpu_count() or 1)), world_probes=probes,
                      taskset=cfg.taskset)


def cmd_audit(args: list[str]) -> int:
    """``eb audit``: compose the config like ``eb run``, run the probes, print one table; 1 if a probe fails."""
    parsed = parse_args(args)
    if parsed.help:
        print(AUDIT_USAGE)
        return 0
    setup = build_setup(parsed)
    try:
        results = run_audit(setup, parsed.only or None,
                            progress=lambda msg: print(f"eb audit: {msg}", file=sys.stderr, flush=True))
    except KeyError as exc:
        raise _error(str(exc.args[0])) from None
    name = setup.env_name + (f" ({setup.taskset} task set)" if setup.taskset != "classic" else "")
    print(format_audit(name, results, len(setup.tasks), setup.sampling_note() if "cap" in setup._cache else ""))
    return 1 if any(not r.passed for _, r in results) else 0
