"""The ``eb`` command: ``run`` (a Hydra app), ``list``, ``report`` and ``tasks``.

Bad input ends with one line on stderr that says what was wrong, what is allowed and how to fix it.
"""

from __future__ import annotations

import difflib
import os
import sys
from collections.abc import Sequence
from typing import Any

USAGE = """usage: eb <command> [args]

commands:
  run [key=value ...]        run a benchmark (a Hydra app: -m sweeps, --cfg job shows the config)
                             e.g. eb run env=navigation model=oracle limit=10
  list                       installed envs (subsets, task counts), models, planners, augmenters,
                             metrics and ablations, each with its plugin
  report RUN_DIR [...]       paper-style tables of runs with 95% intervals, ablation deltas and the
                             automatic error analysis [--format rich|markdown|csv|latex|html] [--out FILE]
                             [--plot FILE.png|.svg] [--errors: relabel from the step files, per subset];
                             `report A B --paired`: is B's difference to A real?
  show RUN_DIR [RUN_DIR ...] write RUN_DIR/index.html: every episode, step, image, answer, feedback and
                             error label, with filters; several runs: a side-by-side comparison [--out DIR];
                             --bundle OUT RUN...: a static results site (leaderboards, capabilities, viewers)
  export RUN_DIR --out DIR   planner steps as a dataset [--format parquet|chat] [--images embed|paths]
                             [--only-success]; with a dataset card (README.md); --format video: one replayed,
                             captioned MP4 (or --gif) per episode; RUN... --format matrix: task x run table
  prompt env=NAME task=ID [step=N] [ablation=NAME] [out=DIR]   print what the model receives at planner
                             call N (the expert plays the earlier ones); images saved as PNG beside prompt.txt
  tasks generate env=NAME [key=value ...]   write a task file with the env's generator
  audit env=NAME [task_file=PATH] [--quick] [--probe NAME]   shortcut probes of a task set; exit 1 on a failure
  verify RUN_DIR [...] [--render]   replay every episode from its task, seed and recorded actions (no model)
                             and check the records and manifest; one line per mismatch, exit 1 on any
  plan env=NAME target=width:PTS|diff:PTS [subset=...] [from=RUN]   tasks, repeats and cost a measurement needs
  serve env=NAME [taskset=...] [split=...] [runner.workers=N] [port=...]   the worlds as an HTTP service
"""

GROUPS = ("env", "model", "planner", "ablation")


class CliError(Exception):
    """One line for the user."""


def _fail(msg: str, code: int = 2) -> int:
    print(f"eb: error: {msg}", file=sys.stderr)
    return code


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0 if argv else 2
    cmd, rest = argv[0], argv[1:]
    try:
        if cmd == "run":
            return cmd_run(rest)
        if cmd == "list":
            return cmd_list(rest)
        if cmd == "report":
            return cmd_report(rest)
        if cmd == "tasks":
            return cmd_tasks(rest)
        if cmd == "show":
            return cmd_show(rest)
        if cmd == "prompt":
            from eb_core.prompt_view import cmd_prompt

            return cmd_prompt(rest)
        if cmd == "export":
            from eb_core.export import cmd_export

            return cmd_export(rest)
        if cmd == "audit":
            from eb_core.audit import cmd_audit

            return cmd_audit(rest)
        if cmd == "plan":
            from eb_core.budget import cmd_plan

            return cmd_plan(rest)
        if cmd == "verify":
            from eb_core.verify import cmd_verify

            return cmd_verify(rest)
        if cmd == "serve":
            from eb_core.serve.command import main as cmd_serve

            return cmd_serve(rest)
    except CliError as exc:
        return _fail(str(exc))
    except KeyboardInterrupt:
        return _fail("interrupted; finished episodes are saved, re-run the same command to resume", 130)
    hint = difflib.get_close_matches(cmd, ["run", "list", "report", "show", "export", "tasks", "audit", "verify", "plan",
                                           "serve"], n=1)
    return _fail(f"unknown command {cmd!r}; commands: run, list, report, show, export, tasks, audit, verify, plan, "
                 "serve"
                 + (f" (did you mean {hint[0]!r}?)" if hint else ""))


# -- config composition (shared by run, list and tasks) -----------------------------------------------


def _group_options(group: str) -> list[str]:
    from hydra.core.global_hydra import GlobalHydra

    return sorted(GlobalHydra.instance().config_loader().get_group_options(group))


def _hydra_context():
    from hydra import initialize_config_module

    from hydra_plugins.eb_searchpath import ensure_registered

    ensure_registered()
    return initialize_config_module(config_module="eb_conf", version_base=None)


def _check_overrides(overrides: list[str]) -> list[str]:
    """Validate overrides (expanding sweeps) and return one override list to compose with."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    try:
        parsed = OverridesParser.create().parse_overrides(overrides)
    except Exception as exc:
        raise CliError(f"cannot parse overrides {' '.join(overrides)!r}: {str(exc).splitlines()[0]}. "
                       f"Write key=value, e.g. env=navigation limit=5") from None
    first: list[str] = []
    for ov in parsed:
        key = ov.get_key_element()
        values: list[str]
        if ov.is_sweep_override():
            values = [str(v) for v in ov.sweep_string_iterator()]
        else:
            values = [ov.get_value_element_as_str()]
        if key in GROUPS:
            options = _group_options(key)
            for v in values:
                if v not in options:
                    raise CliError(_unknown_option_message(key, v, options))
        first.append(f"{key}={values[0]}" if ov.is_sweep_override() else ov.input_line)
    return first


def _unknown_option_message(group: str, value: str, options: list[str]) -> str:
    close = difflib.get_close_matches(value, options, n=1)
    hint = f" Did you mean {close[0]!r}?" if close else ""
    plugin = {"env": " Is its plugin installed? (pip install a plugin, e.g. plugins/eb_navigation, then `eb list`)",
              "model": " For any other model use model=openai-compatible model.name=... model.api_base=...",
              }.get(group, "")
    return f"unknown {group} {value!r}; available: {', '.join(options) or 'none'}.{hint}{plugin}"


def compose(overrides: list[str]) -> dict[str, Any]:
    """Compose the config for ``overrides`` and return it as a resolved plain dict (run dir excluded)."""
    from hydra import compose as hydra_compose
    from omegaconf import OmegaConf

    with _hydra_context():
        checked = _check_overrides(overrides)
        try:
            cfg = hydra_compose(config_name="config", overrides=checked)
        except Exception as exc:
            raise CliError(_hydra_error_line(exc)) from None
        cfg_dict = OmegaConf.to_container(cfg, resolve=True)
    assert isinstance(cfg_dict, dict)
    cfg_dict.pop("hydra", None)
    return cfg_dict


def _hydra_error_line(exc: Exception) -> str:
    text = str(exc)
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    import re

    m = re.search(r"Key '([^']+)' is not in struct", text) or re.search(r"Could not override '([^']+)'", text)
    if m:
        key = m.group(1)
        full = re.search(r"full_key: (\S+)", text)
        full_key = full.group(1) if full else key
        return (f"unknown config key '{full_key}'. Check the spelling; `eb run --cfg job` prints every key "
                f"(add a new key with +{full_key}=VALUE only if a plugin reads it)")
    return (lines[0] if lines else type(exc).__name__) + " (see `eb run --cfg job`)"


def _validate(cfg_dict: dict[str, Any]):
    from eb_core.config import ConfigError, validate_config

    try:
        return validate_config(cfg_dict)
    except ConfigError as exc:
        raise CliError(str(exc)) from None


# -- eb run --------------------------------------------------------------------------------------------


def _split_hydra_args(args: list[str]) -> tuple[list[str], bool]:
    """Config overrides (for pre-validation) and whether Hydra flags make this a non-run call."""
    overrides: list[str] = []
    info_only = False
    skip_next = False
    for i, a in enumerate(args):
        if skip_next:
            skip_next = False
            continue
        if a in ("--cfg", "-c", "--package", "-p", "--info", "-i", "--help", "-h", "--hydra-help", "--shell-completion",
                 "-sc"):
            info_only = info_only or a not in ("--package", "-p")
            if a in ("--cfg", "-c", "--package", "-p", "--info", "-i") and i + 1 < len(args) \
                    and not args[i + 1].startswith("-") and "=" not in args[i + 1]:
                skip_next = True
            continue
        if a.startswith("-"):
            continue
        if a.startswith("hydra.") or a.startswith("hydra/") or a.startswith("+hydra") or a.startswith("~hydra"):
            continue
        overrides.append(a)
    return overrides, info_only


_SECRET_LEAVES = {"api_key", "apikey", "key", "secret", "password", "token", "access_key", "secret_key",
                  "auth_token", "access_token", "bearer"}


def _refuse_secrets(overrides: list[str]) -> None:
    """API keys on the command line would be saved in config.yaml and .hydra/: refuse before composing."""
    for ov in overrides:
        key = ov.split("=", 1)[0].lower().lstrip("+~")
        leaf = key.rsplit(".", 1)[-1]
        if leaf in _SECRET_LEAVES or leaf.endswith(("_api_key", "_secret", "_password", "_access_token")):
            raise CliError(f"refusing '{key}=...': keys and secrets never go on the command line or in config "
                           f"files (they would be saved with the run). Export the key in an environment variable "
                           f"and name it with model.api_key_env=VAR_NAME")


def cmd_run(args: list[str]) -> int:
    # `--quiet` is a friendlier spelling of runner.quiet=true (plain lines instead of the live display).
    args = ["runner.quiet=true" if a in ("--quiet", "-q") else a for a in args]
    overrides, info_only = _split_hydra_args(args)
    _refuse_secrets(overrides)
    cfg_dict = compose(overrides)
    _validate(cfg_dict)
    # Fail fast on unknown components before Hydra starts a job.
    from eb_core.plugins import PluginError, Registry

    try:
        registry = Registry.create()
        registry.get("env", cfg_dict["env"]["name"])
        registry.get("model backend", cfg_dict["model"]["backend"])
        registry.get("planner", cfg_dict["planner"]["name"])
        for aug in cfg_dict.get("augmenters") or []:
            registry.get("augmenter", aug["name"])
    except PluginError as exc:
        raise CliError(str(exc)) from None
    if not info_only and not ({"-m", "--multirun"} & set(args)):
        _check_run_dir_writable(_run_dir_of(args))
    return _hydra_main(args)


def _run_dir_of(args: list[str]) -> str:
    """The run directory Hydra will use for a single run with ``args``."""
    from hydra import compose as hydra_compose

    with _hydra_context():
        checked = _check_overrides([a for a in args if not a.startswith("-")])
        cfg = hydra_compose(config_name="config", overrides=checked, return_hydra_config=True)
        return str(cfg.hydra.run.dir)


def _check_run_dir_writable(run_dir: str) -> None:
    """Fail with one line, before anything is written, when the run directory cannot take files
    (read-only file system, no permission, no space or a file-size limit). Nothing finished is touched."""
    path = os.path.abspath(run_dir)
    probe = os.path.join(path, f".eb_write_probe.{os.getpid()}")
    try:
        os.makedirs(path, exist_ok=True)
        with open(probe, "wb") as fh:
            fh.write(b"\0" * 16384)  # larger than any file Hydra writes before the run starts
            fh.flush()
            os.fsync(fh.fileno())
    except OSError as exc:
        raise CliError(f"cannot write to the run directory {path}: {exc.strerror or exc}. Finished episodes "
                       f"there are kept: fix it (space, permissions, a read-only mount) and run the same "
                       f"command again to resume, or choose another directory with hydra.run.dir=...") from None
    finally:
        try:
            os.unlink(probe)
        except OSError:
            pass


def _hydra_main(args: list[str]) -> int:
    import hydra

    from hydra_plugins.eb_searchpath import ensure_registered

    ensure_registered()
    saved = sys.argv
    sys.argv = ["eb run", *args]
    try:
        app = hydra.main(version_base=None, config_path="pkg://eb_conf", config_name="config")(_hydra_task)
        app()
    finally:
        sys.argv = saved
    return 0


def _hydra_task(cfg: Any) -> None:
    """The Hydra job: validate, run, print the summary. Known errors become one line and exit 2."""
    from hydra.core.hydra_config import HydraConfig
    from omegaconf import OmegaConf

    from eb_core.config import ConfigError
    from eb_core.plugins import PluginError
    from eb_core.runner import RunError, run
    from eb_core.specs import MissingDependencyError

    run_dir = HydraConfig.get().runtime.output_dir
    cfg_dict = OmegaConf.to_container(cfg, resolve=True)
    assert isinstance(cfg_dict, dict)
    cfg_dict.pop("hydra", None)
    try:
        rc = _validate(cfg_dict)
        summary = run(rc, run_dir, cfg_dict=cfg_dict)
    except (CliError, ConfigError, PluginError, RunError, MissingDependencyError) as exc:
        print(f"eb: error: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    except OSError as exc:  # the disk filled up or the directory became unwritable during the run
        where = exc.filename or run_dir
        print(f"eb: error: cannot write {where}: {exc.strerror or exc}. Episodes already in episodes.jsonl are "
              f"kept; fix it and run the same command again to resume.", file=sys.stderr)
        raise SystemExit(2) from None
    from eb_core.report import print_summary

    print_summary(summary, run_dir)


# -- eb list -------------------------------------------------------------------------------------------


def cmd_list(args: list[str]) -> int:
    from rich.console import Console
    from rich.table import Table

    from eb_core.plugins import PluginError, Registry

    try:
        registry = Registry.create()
    except PluginError as exc:
        raise CliError(str(exc)) from None
    console = Console(width=max(100, Console().width))
    t = Table(title="Environments", show_lines=False)
    for col in ("name", "plugin", "subsets (tasks)", "description"):
        t.add_column(col)
    for name, spec in registry.envs.items():
        subsets = ", ".join(f"{k} ({v})" for k, v in spec.subsets.items())
        total = sum(spec.subsets.values())
        t.add_row(name, spec.plugin, f"{subsets}\n= {total} tasks" if subsets else "", spec.description)
    console.print(t)

    with _hydra_context():
        from hydra.core.global_hydra import GlobalHydra

        repo = GlobalHydra.instance().config_loader().repository
        presets = {p: _load_option(repo, "model", p) for p in _group_options("model")}
        ablations = {a: _load_option(repo, "ablation", a) for a in _group_options("ablation")}
    m = Table(title="Models (model=NAME)")
    for col in ("preset", "backend", "model id / description", "plugin"):
        m.add_column(col)
    for p, node in presets.items():
        b = str(node.get("backend", "(invalid preset)"))
        spec = registry.model_backends.get(b)
        m.add_row(p, b, str(node.get("model_id") or node.get("description") or ""),
                  spec.plugin if spec else "[red]backend not installed[/red]")
    console.print(m)
    for title, specs in (("Planners", registry.planners), ("Augmenters", registry.augmenters),
                         ("Metrics", registry.metrics)):
        tt = Table(title=title)
        for col in ("name", "plugin", "description"):
            tt.add_column(col)
        for name, spec in specs.items():
            tt.add_row(name, spec.plugin, spec.description)
        console.print(tt)
    a = Table(title="Ablations (ablation=NAME)")
    a.add_column("name")
    a.add_column("what changes")
    for name, node in ablations.items():
        a.add_row(name, str((node.get("ablation") or {}).get("description", "")))
    console.print(a)
    return 0


def _load_option(repo: Any, group: str, name: str) -> dict[str, Any]:
    """The raw YAML of a config option (no composition), or {} if it cannot be read."""
    from omegaconf import OmegaConf

    try:
        result = repo.load_config(config_path=f"{group}/{name}")
        return OmegaConf.to_container(result.config, resolve=False) if result is not None else {}
    except Exception:  # a broken option is listed, not hidden
        return {}


# -- eb report -----------------------------------------------------------------------------------------


def cmd_report(args: list[str]) -> int:
    from eb_core.report import render_paired, render_report

    fmt, out, dirs, paired, plot, errors = "rich", None, [], False, None, False
    it = iter(args)
    for a in it:
        if a == "--paired":
            paired = True
        elif a == "--errors":
            errors = True
        elif a == "--plot":
            plot = next(it, "")
            if not plot or plot.startswith("-"):
                raise CliError("--plot needs a file name ending in .png or .svg, e.g. --plot report.png")
        elif a.startswith("--plot="):
            plot = a.split("=", 1)[1]
        elif a == "--format":
            fmt = next(it, "")
        elif a.startswith("--format="):
            fmt = a.split("=", 1)[1]
        elif a == "--out":
            out = next(it, None)
        elif a.startswith("--out="):
            out = a.split("=", 1)[1]
        elif a.startswith("-"):
            raise CliError(f"unknown option {a!r} for report; options: --format rich|markdown|csv|latex|html, "
                           f"--out FILE, --plot FILE.png|.svg, --errors, --paired")
        else:
            dirs.append(a)
    if fmt not in ("rich", "markdown", "csv", "latex", "html"):
        raise CliError(f"unknown --format {fmt!r}; use rich, markdown, csv, latex or html")
    if plot is not None and not plot.lower().endswith((".png", ".svg")):
        raise CliError(f"--plot {plot!r}: the file must end in .png or .svg, e.g. --plot report.png")
    if not dirs:
        raise CliError("report needs at least one run directory, e.g. eb report runs/navigation/oracle/none/default")
    if paired:
        if fmt in ("latex", "html"):
            raise CliError(f"--paired prints rich, markdown or csv (got --format {fmt})")
        render_paired(dirs, fmt, out)
    else:
        render_report(dirs, fmt, out, plot=plot, errors=errors)
        if plot:
            print(f"plot -> {plot}", file=sys.stderr)
    return 0


# -- eb show ----------------------------------------------------------------------------------------------


def cmd_show(args: list[str]) -> int:
    from pathlib import Path

    from eb_core.html import write_compare, write_html

    usage = ("usage: eb show RUN_DIR (a directory holding episodes.jsonl), or eb show RUN_A RUN_B ... [--out DIR], "
             "or eb show --bundle OUT RUN...")
    dirs, out, bundle = [], None, None
    it = iter(args)
    for a in it:
        if a == "--bundle" or a.startswith("--bundle="):
            bundle = a.split("=", 1)[1] if "=" in a else next(it, "")
            if not bundle:
                raise CliError(f"--bundle needs a new folder; {usage}")
        elif a == "--out" or a.startswith("--out="):
            out = a.split("=", 1)[1] if "=" in a else next(it, "")
            if not out:
                raise CliError(f"--out needs a directory; {usage}")
        elif a.startswith("-"):
            raise CliError(f"unknown option {a!r} for show; {usage}")
        else:
            dirs.append(a)
    if not dirs:
        raise CliError(usage)
    for d in dirs:
        if not (Path(d) / "episodes.jsonl").exists():
            raise CliError(f"{d} is not a run directory (no episodes.jsonl)")
    if bundle is not None:
        from eb_core.bundle import write_bundle

        try:
            print(write_bundle(dirs, bundle))
        except (FileExistsError, ValueError) as exc:
            raise CliError(str(exc)) from None
        return 0
    if len(dirs) == 1:
        if out:
            raise CliError("--out is for comparing several runs; one run's viewer is written into RUN_DIR")
        print(write_html(dirs[0]))
        return 0
    try:
        print(write_compare(dirs, out or str(Path(dirs[0]) / "compare")))
    except ValueError as exc:
        raise CliError(str(exc)) from None
    return 0


# -- eb tasks ------------------------------------------------------------------------------------------


def cmd_tasks(args: list[str]) -> int:
    import yaml

    from eb_core.plugins import PluginError, Registry
    from eb_core.specs import load_entry_point

    if not args or args[0] != "generate":
        raise CliError("usage: eb tasks generate env=NAME [key=value ...] [out=PATH]")
    kwargs: dict[str, Any] = {}
    for a in args[1:]:
        key, sep, value = a.partition("=")
        if not sep or not key:
            raise CliError(f"expected key=value, got {a!r}")
        kwargs[key] = yaml.safe_load(value) if value else ""
    env_name = kwargs.pop("env", None)
    if not env_name:
        raise CliError("tasks generate needs env=NAME (`eb list` shows the envs)")
    try:
        spec = Registry.create().get("env", str(env_name))
    except PluginError as exc:
        raise CliError(str(exc)) from None
    if not spec.task_generator:
        raise CliError(f"env {env_name!r} (plugin {spec.plugin}) ships no task generator")
    split = kwargs.get("split")
    if split is not None and split != "test":
        env_cls = spec.load()
        if split not in getattr(env_cls, "splits", ()):
            try:
                env_cls.split_tasks(str(split), 0, 1)
            except ValueError as exc:
                raise CliError(str(exc)) from None
    fn = load_entry_point(spec.task_generator, spec.install_hint)
    try:
        result = fn(**kwargs)
    except (TypeError, ValueError) as exc:
        raise CliError(f"{spec.task_generator}: {exc}") from None
    if result is not None:
        print(result if isinstance(result, str) else f"generated {result}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    # Import by name so exceptions raised in other modules match this module's classes.
    from eb_core.cli import main as _main

    raise SystemExit(_main())
