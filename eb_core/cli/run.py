"""``eb run [key=value ...]``: compose once (:mod:`eb_core.compose`), run, print the summary.

``-m`` runs a sweep (``ablation=none,no_feedback``): Hydra's sweeper expands it into jobs that land in the same
layout as single runs; one job's failure is reported and the sweep goes on, with a combined table at the end.
``--cfg job`` prints the resolved config that would run, and runs nothing.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any, NoReturn

from eb_core.compose import ComposedRun, compose_run, expand_sweep, refuse_secrets, sweep_keys
from eb_core.exceptions import CliError, UserError


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, raised instead of exit(2)
        raise CliError(f"run: {message}; usage: eb run [-m] [--cfg job|hydra|all] [--quiet] key=value ...")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="eb run", allow_abbrev=False,
                description="Run a benchmark. Overrides are Hydra's: key=value, +key=value, ~key; -m sweeps a=x,y.")
    p.add_argument("overrides", nargs="*", help="config overrides, e.g. env=navigation model=oracle limit=10")
    p.add_argument("-m", "--multirun", action="store_true", help="sweep: one job per combination of a=x,y values")
    p.add_argument("-c", "--cfg", choices=("job", "hydra", "all"), help="print the resolved config, run nothing")
    p.add_argument("-p", "--package", help="with --cfg: print only this key (e.g. -p model)")
    p.add_argument("--resolve", action="store_true", help="accepted for Hydra's habit: --cfg always resolves")
    p.add_argument("-q", "--quiet", action="store_true", help="plain progress lines (runner.quiet=true)")
    return p


def cmd_run(args: list[str]) -> int:
    ns = _parser().parse_intermixed_args(args)
    overrides: list[str] = list(ns.overrides) + (["runner.quiet=true"] if ns.quiet else [])
    refuse_secrets(overrides)
    swept = sweep_keys(overrides)
    if swept and not ns.multirun:
        raise CliError(f"{swept[0]} has several values (a sweep): add -m to run one job per value, e.g. "
                       f"eb run -m {' '.join(overrides)}")
    jobs = [compose_run(o, multirun=ns.multirun) for o in (expand_sweep(overrides) if ns.multirun else [overrides])]
    for job in jobs:  # every job's components exist before the first one starts
        _check_components(job)
    if ns.cfg:
        for i, job in enumerate(jobs):
            if len(jobs) > 1:
                print(f"# job {i + 1} of {len(jobs)}: {' '.join(job.overrides)}")
            print(_cfg_text(job, ns.cfg, ns.package), end="")
        return 0
    if not ns.multirun:
        summary = run_job(jobs[0])
        _print_summary(summary, str(jobs[0].run_dir))
        return 0
    if any(o.lstrip("+").startswith(("hydra/launcher=", "hydra/sweeper=")) for o in overrides):
        return _launcher_sweep(overrides)
    return _sweep(jobs)


# -- one job -------------------------------------------------------------------------------------------------


def _check_components(job: ComposedRun) -> None:
    from eb_core.plugins import PluginError, Registry

    cfg = job.config
    try:
        registry = Registry.create()
        registry.get("env", cfg.env.name)
        registry.get("model backend", cfg.model.backend)
        registry.get("planner", cfg.planner.name)
        for aug in cfg.augmenters:
            registry.get("augmenter", aug.name)
    except PluginError as exc:
        raise CliError(str(exc)) from None


def _cfg_text(job: ComposedRun, which: str, package: str | None) -> str:
    from omegaconf import OmegaConf

    if which == "job":
        node: Any = OmegaConf.create(job.cfg_dict)
    elif which == "hydra":
        node = OmegaConf.create({"hydra": OmegaConf.to_container(job.node.hydra, resolve=False)})
    else:
        node = OmegaConf.create({**job.cfg_dict, "hydra": OmegaConf.to_container(job.node.hydra, resolve=False)})
    if package:
        picked = OmegaConf.select(node, package, default=None)
        if picked is None:
            raise CliError(f"--package {package!r}: no such key in the config (see eb run --cfg {which})")
        node = picked if OmegaConf.is_config(picked) else OmegaConf.create({package: picked})
    return OmegaConf.to_yaml(node)


def _check_run_dir_writable(path: Path) -> None:
    """Fail with one line, before anything is written, when the run directory cannot take files
    (read-only file system, no permission, no space or a file-size limit). Nothing finished is touched."""
    probe = path / f".eb_write_probe.{os.getpid()}"
    try:
        path.mkdir(parents=True, exist_ok=True)
        with open(probe, "wb") as fh:
            fh.write(b"\0" * 16384)  # larger than any file written before the run starts
            fh.flush()
            os.fsync(fh.fileno())
    except OSError as exc:
        raise CliError(f"cannot write to the run directory {path.resolve()}: {exc.strerror or exc}. Finished "
                       f"episodes there are kept: fix it (space, permissions, a read-only mount) and run the same "
                       f"command again to resume, or choose another directory with hydra.run.dir=...") from None
    finally:
        with contextlib.suppress(OSError):
            probe.unlink()


def _save_hydra_files(job: ComposedRun) -> None:
    """``.hydra/config.yaml`` and ``overrides.yaml``, as a Hydra app writes them (``hydra.output_subdir``)."""
    from omegaconf import OmegaConf

    sub = job.node.hydra.get("output_subdir")
    if not sub:
        return
    d = job.run_dir / str(sub)
    d.mkdir(parents=True, exist_ok=True)
    (d / "config.yaml").write_text(OmegaConf.to_yaml(OmegaConf.create(job.cfg_dict)))
    (d / "overrides.yaml").write_text(OmegaConf.to_yaml(OmegaConf.create(list(job.overrides))))


@contextlib.contextmanager
def _logging(run_dir: Path) -> Iterator[None]:
    """Log records at INFO and above go to stderr and to ``eb.log`` (created only when something is logged)."""
    root = logging.getLogger()
    fmt = logging.Formatter("[%(asctime)s][%(name)s][%(levelname)s] - %(message)s")
    console = logging.StreamHandler(sys.stderr)
    file = logging.FileHandler(run_dir / "eb.log", delay=True, encoding="utf-8")
    for h in (console, file):
        h.setFormatter(fmt)
        root.addHandler(h)
    old_level = root.level
    root.setLevel(logging.INFO)
    logging.getLogger("OpenGL").setLevel(logging.WARNING)  # announces a missing optional accelerator at INFO
    try:
        yield
    finally:
        root.setLevel(old_level)
        for h in (console, file):
            root.removeHandler(h)
            h.close()


def _holds_no_results(run_dir: Path) -> bool:
    episodes = run_dir / "episodes.jsonl"
    return not (episodes.exists() and episodes.stat().st_size > 0)


def _first_missing(path: Path) -> Path | None:
    """The highest directory of ``path`` (itself included) that does not exist yet."""
    missing = None
    for p in [path, *path.parents]:
        if p.exists():
            break
        missing = p
    return missing


def _discard_empty(run_dir: Path, created: Path) -> None:
    """A run that failed before its first episode leaves no folder behind (the README's globs stay true):
    ``run_dir`` and the empty parents this call created, up to ``created``. Only called for a directory this
    invocation created, so everything in it was written by this run (config, manifest, lock...)."""
    with contextlib.suppress(OSError):
        if run_dir.is_dir() and _holds_no_results(run_dir):
            shutil.rmtree(run_dir)
            for parent in run_dir.parents:
                if parent != created and created not in parent.parents:
                    break
                parent.rmdir()  # only if empty


def _one_line(exc: BaseException) -> str:
    return "; ".join(ln.strip() for ln in str(exc).splitlines() if ln.strip())[:600]


def _ray_error(job: ComposedRun, exc: BaseException) -> CliError:
    where = job.config.runner.ray_address or os.environ.get("RAY_ADDRESS") or "a local Ray started for the run"
    return CliError(f"runner.executor=ray: cannot reach the Ray cluster at {where}: {_one_line(exc)}. Start it "
                    f"(ray start --head), fix runner.ray_address / $RAY_ADDRESS, or use runner.executor=local")


def _translate(job: ComposedRun, exc: BaseException) -> BaseException:
    """A known failure as one line for the user; anything else unchanged (a bug: its traceback is shown)."""
    from eb_core.plugins import PluginError
    from eb_core.runner import RunError
    from eb_core.specs import MissingDependencyError

    if isinstance(exc, UserError):
        return exc
    if isinstance(exc, (RunError, PluginError, MissingDependencyError)):
        return CliError(str(exc))
    if job.config.runner.executor == "ray" and (isinstance(exc, ConnectionError)
                                                 or type(exc).__module__.startswith("ray")):
        return _ray_error(job, exc)
    if isinstance(exc, OSError):  # the disk filled up or the directory became unwritable during the run
        where = exc.filename or job.run_dir
        return CliError(f"cannot write {where}: {exc.strerror or exc}. Episodes already in episodes.jsonl are "
                        f"kept; fix it and run the same command again to resume.")
    return exc


def _check_ray_reachable(job: ComposedRun) -> None:
    """Under ``runner.executor=ray`` with a cluster address: a cluster that does not answer is one line at once
    (Ray itself waits minutes, then fails with a connection error)."""
    import importlib.util
    import socket

    if job.config.runner.executor != "ray" or importlib.util.find_spec("ray") is None:
        return  # the runner says how to install Ray
    address = job.config.runner.ray_address or os.environ.get("RAY_ADDRESS") or ""
    hostport = address.removeprefix("ray://").rsplit("/", 1)[0]
    host, sep, port = hostport.rpartition(":")
    if not sep or not port.isdigit() or address in ("auto", "local"):
        return  # "auto", or no address: a local Ray (Ray's own error names what is missing)
    try:
        socket.create_connection((host or "127.0.0.1", int(port)), timeout=5).close()
    except OSError as exc:
        raise _ray_error(job, exc) from None


def run_job(job: ComposedRun) -> dict[str, Any]:
    """Run (or resume) one composed job in its directory; a failure before the first finished episode leaves
    no folder behind when this call created it."""
    from eb_core.runner import run

    _check_ray_reachable(job)
    created = _first_missing(job.run_dir.absolute())
    _check_run_dir_writable(job.run_dir)
    try:
        _save_hydra_files(job)
        with _logging(job.run_dir):
            return run(job.config, str(job.run_dir), cfg_dict=job.cfg_dict)
    except BaseException as exc:
        if created is not None:
            _discard_empty(job.run_dir.absolute(), created)
        translated = _translate(job, exc)
        if translated is exc:
            raise
        raise translated from None


def _print_summary(summary: dict[str, Any], run_dir: str) -> None:
    from eb_core.report import print_summary

    print_summary(summary, run_dir)


# -- sweeps ----------------------------------------------------------------------------------------------------


#: One finished sweep job: its config, run directory, summary (None if it failed) and error line.
JobResult = tuple[Any, str, "dict[str, Any] | None", "str | None"]


def _one_sweep_job(job: ComposedRun, label: str) -> JobResult:
    """Run one job of a sweep; its failure is one line on stderr and is returned, never raised."""
    print(f"eb run -m {label} -> {job.run_dir}", file=sys.stderr, flush=True)
    try:
        summary = run_job(job)
    except UserError as exc:
        print(f"eb: error: {label}: {exc}", file=sys.stderr, flush=True)
        return job.config, str(job.run_dir), None, str(exc)
    _print_summary(summary, str(job.run_dir))
    return job.config, str(job.run_dir), summary, None


def _sweep(jobs: list[ComposedRun]) -> int:
    """Every job in turn; a job's failure is one line and the sweep goes on. Exit 1 if any job failed."""
    results = [_one_sweep_job(job, f"[job {i + 1}/{len(jobs)}] {' '.join(job.overrides)}")
               for i, job in enumerate(jobs)]
    return _finish_sweep(results)


def _finish_sweep(results: list[JobResult]) -> int:
    _print_sweep_table(results)
    failed = sum(1 for *_rest, err in results if err)
    if failed:
        print(f"eb: error: {failed} of {len(results)} sweep jobs failed (their lines above say why); the others "
              f"finished. Fix it and re-run the same command: finished jobs resume at once", file=sys.stderr)
        return 1
    return 0


def _launched_job(cfg: Any) -> JobResult:
    """A sweep job started by a Hydra launcher (``hydra/launcher=...``): composed by our one path from the
    job's overrides, in the directory the launcher chose."""
    import dataclasses

    from hydra.core.hydra_config import HydraConfig

    hc = HydraConfig.get()
    job = compose_run(list(hc.overrides.task), multirun=True)
    job = dataclasses.replace(job, run_dir=Path(hc.runtime.output_dir))
    return _one_sweep_job(job, f"[job {hc.job.num + 1}] {' '.join(job.overrides)}")


def _launcher_sweep(overrides: list[str]) -> int:
    """``eb run -m hydra/launcher=NAME ...``: the sweep handed to that Hydra launcher (Slurm, Ray...)."""
    from hydra._internal.hydra import Hydra
    from hydra._internal.utils import create_config_search_path
    from hydra.core.global_hydra import GlobalHydra

    from eb_core.compose import hydra_context

    with hydra_context():  # registers the search-path plugin and the resolvers
        pass
    GlobalHydra.instance().clear()
    hydra = Hydra.create_main_hydra2(task_name="eb", config_search_path=create_config_search_path("pkg://eb_conf"))
    try:
        batches = hydra.multirun(config_name="config", task_function=_launched_job, overrides=overrides)
    finally:
        GlobalHydra.instance().clear()
    return _finish_sweep([r.return_value for batch in batches for r in batch])


def _print_sweep_table(results: list[JobResult]) -> None:
    from rich.console import Console
    from rich.table import Table

    t = Table(title=f"Sweep: {len(results)} jobs")
    for col in ("env", "model", "ablation", "experiment", "success % [95% CI]", "episodes", "status", "run dir"):
        t.add_column(col, justify="right" if col in ("episodes",) else "left")
    for c, run_dir, summary, err in results:
        if summary is None:
            t.add_row(c.env.name, c.model.name, c.ablation.name, c.experiment, "-", "-",
                      f"[red]failed[/red]: {(err or '')[:60]}", run_dir)
            continue
        o = summary["overall"]
        ci = o.get("success_rate_ci") or {}
        rate = f"{100 * o.get('success_rate', 0):.1f}"
        if ci.get("ci_low") is not None:
            rate += f" [{100 * ci['ci_low']:.1f}, {100 * ci['ci_high']:.1f}]"
        status = "complete" if summary.get("complete") else "incomplete"
        if summary.get("partial"):
            status += " (partial)"
        t.add_row(c.env.name, c.model.name, c.ablation.name, c.experiment, rate,
                  f"{summary['n_finished']}/{summary.get('n_episodes', summary['n_selected'])}", status, run_dir)
    Console(width=max(150, Console().width)).print(t)
