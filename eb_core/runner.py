"""The runner: task selection, repeats, resume, parallel workers, progress, summary.

Crash safety: an episode is appended to ``episodes.jsonl`` (one ``os.write`` + fsync, by the main
process only) after its step files were moved into place; re-running the same command skips finished
episodes, redoes unfinished and ``error`` ones, and never writes an episode twice. An episode is one
(task, repeat) pair; ``runner.repeats=N`` plays every task N times with seeds derived from the run seed,
the task id and the repeat. One process at a time owns a run directory (an ``flock`` on ``run.lock``).
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Iterable
from typing import Any, cast

from eb_core.components import Components, RunError, episode_seed, label_record, select_tasks
from eb_core.config import ConfigError, RunConfig
from eb_core.episode import BudgetGuard, EpisodeDriver, play
from eb_core.events import RunEndEvent, RunStartEvent
from eb_core.inflight import node_name, with_node
from eb_core.manifest import write_manifest
from eb_core.metrics import compute_summary
from eb_core.model import ModelBudgetExceeded, ModelFatalError, Usage
from eb_core.plugins import Registry, get_plugin_manager, plugin_versions
from eb_core.records import EpisodeRecord, RunDirLocked, RunFiles, RunLock, episode_dir_name
from eb_core.selection import selection_conflict, selection_of
from eb_core.workers import Job, concurrency, finish_episode, job_key, run_workers, split_slots

__all__ = ["RunError", "Components", "episode_seed", "job_key", "run", "select_tasks", "split_slots"]

#: Config keys whose change makes old episodes incomparable with new ones.
_FINGERPRINT_KEYS = ("env", "model", "planner", "ablation", "augmenters", "seed")


def _fingerprint(cfg_dict: dict[str, Any]) -> dict[str, Any]:
    fp = {k: cfg_dict.get(k) for k in _FINGERPRINT_KEYS}
    if cfg_dict.get("split", "test") != "test":  # runs on the shipped tasks keep their earlier fingerprint
        fp["split"] = cfg_dict["split"]
    if cfg_dict.get("taskset", "classic") != "classic":  # likewise for the classic task sets
        fp["taskset"] = cfg_dict["taskset"]
    return fp


def _diff_keys(a: Any, b: Any, prefix: str = "") -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        out: list[str] = []
        for k in sorted(set(a) | set(b)):
            out += _diff_keys(a.get(k), b.get(k), f"{prefix}{k}.")
        return out
    return [] if a == b else [prefix.rstrip(".")]


# -- progress ----------------------------------------------------------------------------------------


class _Progress:
    def __init__(self, total: int, quiet: bool, label: str) -> None:
        self.total, self.quiet, self.label = total, quiet, label
        self.done = self.succ = self.errors = 0
        self.tokens = 0
        self.cost = 0.0
        self.start = time.perf_counter()
        self._rich = None
        if not quiet and sys.stderr.isatty():
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            self._rich = Progress(
                TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                TextColumn("{task.fields[stats]}"), transient=False,
            )
            self._rich.start()
            self._task = self._rich.add_task(label, total=total, stats="")

    def update(self, rec: EpisodeRecord) -> None:
        self.done += 1
        self.succ += int(rec.success)
        self.errors += int(rec.status == "error")
        self.tokens += rec.prompt_tokens + rec.completion_tokens
        self.cost += rec.cost_usd
        measured = self.done - self.errors
        rate = 100.0 * self.succ / measured if measured else 0.0
        stats = f"success {rate:.1f}%  errors {self.errors}  tokens {self.tokens}  cost ${self.cost:.4f}"
        if self._rich is not None:
            self._rich.update(self._task, advance=1, stats=stats)
        elif not self.quiet:
            elapsed = time.perf_counter() - self.start
            eta = elapsed / self.done * (self.total - self.done)
            mark = "error" if rec.status == "error" else ("success" if rec.success else "fail")
            name = rec.task_id + (f" (repeat {rec.repeat})" if rec.repeat else "")
            print(f"[{self.done}/{self.total}] {name}: {mark} ({rec.end_reason}, {rec.env_steps} steps) | "
                  f"{stats} | eta {eta:.0f}s", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self._rich is not None:
            self._rich.stop()


# -- the run -----------------------------------------------------------------------------------------

def run(cfg: RunConfig, run_dir: str | os.PathLike[str], *, cfg_dict: dict[str, Any] | None = None,
        plugins: Iterable[Any] = (), registry: Registry | None = None) -> dict[str, Any]:
    """Run (or resume) every selected episode of ``cfg`` into ``run_dir`` and return the summary.

    ``plugins`` are extra plugin modules registered directly (tests); they must be importable by name
    so worker processes can register them too. Raises :class:`RunError` at once when another process
    is running in ``run_dir``.
    """
    lock = RunLock(run_dir)
    try:
        lock.acquire()
    except RunDirLocked as exc:
        raise RunError(str(exc)) from None
    try:
        return _run_locked(cfg, run_dir, cfg_dict=cfg_dict, plugins=plugins, registry=registry)
    finally:
        lock.release()


def _run_locked(cfg: RunConfig, run_dir: str | os.PathLike[str], *, cfg_dict: dict[str, Any] | None,
                plugins: Iterable[Any], registry: Registry | None) -> dict[str, Any]:
    if cfg.runner.executor == "ray":
        import importlib.util

        if importlib.util.find_spec("ray") is None:  # checked without importing it
            raise RunError('runner.executor=ray needs Ray, which is not installed: pip install "embodiedbench[ray]"')
    plugins = list(plugins)
    plugin_modules = [p.__name__ for p in plugins]
    registry = registry or Registry(get_plugin_manager(plugins=plugins))
    cfg_dict = cfg_dict if cfg_dict is not None else cfg.model_dump()
    files = RunFiles(run_dir)
    comps = Components(cfg, registry)
    try:
        all_tasks = comps.load_tasks()
    except (ConfigError, RunError):
        raise
    except Exception as exc:  # a malformed task file: the plugin's message names file, task and field
        raise RunError(f"cannot load the tasks of env {cfg.env.name!r}: {exc}") from None
    selected = select_tasks(all_tasks, cfg)
    repeats = cfg.runner.repeats

    # Resume bookkeeping: refuse to mix results of different configs in one directory.
    fp_path = files.root / "fingerprint.json"
    fp = _fingerprint(json.loads(json.dumps(cfg_dict, default=str)))
    if fp_path.exists() and files.episodes_path.exists() and files.episodes_path.stat().st_size > 0:
        old = json.loads(fp_path.read_text())
        old_selection = old.pop("selection", None)
        diff = _diff_keys(old, fp)
        if diff:
            raise RunError(
                f"{files.root} holds results of a different config (differs in: {', '.join(diff[:6])}); "
                f"pick a new experiment=NAME or hydra.run.dir=DIR, or delete that directory"
            )
        conflict = selection_conflict(old_selection, selection_of(cfg), files.root)
        if conflict:
            raise RunError(conflict)
    # a fresh directory, one where no episode ever finished (e.g. a missing key), or a larger limit: record it
    files.write_json("fingerprint.json", {**fp, "selection": selection_of(cfg)})
    import yaml  # shipped with omegaconf

    (files.root / "config.yaml").write_text(yaml.safe_dump(cfg_dict, sort_keys=False))
    files.write_json("plugins.json", plugin_versions(registry.pm))
    write_manifest(files, cfg, cfg_dict, all_tasks, selected, plugin_versions(registry.pm))

    previous = files.load_episodes()
    kept = [r for r in previous if r.status == "ok"]
    if len(kept) != len(previous):
        files.rewrite_episodes(kept)  # error episodes are redone
    finished = {r.key for r in kept}
    files.clean_partial({episode_dir_name(*k) for k in finished})
    # Repeat-major order: a run stopped early (budget) has whole passes over the tasks first.
    pending: list[Job] = [(t, r) for r in range(repeats) for t in selected if (t.id, r) not in finished]
    done_before = len(selected) * repeats - len(pending)
    if done_before:
        # on stdout: stderr is kept for progress and for the one line of an error
        print(f"resuming: {done_before} of {len(selected) * repeats} episodes already done"
              + ("" if pending else " (nothing left to run)"), flush=True)

    hook = registry.pm.hook
    hook.eb_on_run_start(event=RunStartEvent(run_dir=str(files.root), env=cfg.env.name, model=cfg.model.name,
                                             n_tasks=len(selected), n_pending=len(pending), config=cfg_dict))
    stopped: str | None = None
    progress = _Progress(len(pending), cfg.runner.quiet, f"{cfg.env.name} / {cfg.model.name}")
    try:
        if pending:
            stopped = _play(cfg, cfg_dict, comps, files, pending, progress, hook, plugin_modules)
    finally:
        progress.close()

    summary = _summarize(cfg, files, registry, selected, stopped, n_tasks_total=len(all_tasks))
    files.write_json("summary.json", summary)
    hook.eb_on_run_end(event=RunEndEvent(run_dir=str(files.root), summary=summary, stopped_early=stopped))
    return summary


def _summarize(cfg: RunConfig, files: RunFiles, registry: Registry, selected: list[Any],
               stopped: str | None, n_tasks_total: int) -> dict[str, Any]:
    """``summary.json``: the paper's metrics over the selected episodes in ``episodes.jsonl``, and the run's facts."""
    repeats = cfg.runner.repeats
    all_records = files.load_episodes()
    files.clean_partial({episode_dir_name(*r.key) for r in all_records})  # staging dirs of stopped episodes
    wanted = {(t.id, r) for t in selected for r in range(repeats)}
    records = [r for r in all_records if r.key in wanted]
    done_keys = {r.key for r in records}
    metric_fns = {name: spec.load() for name, spec in registry.metrics.items()}
    subsets = list(dict.fromkeys(t.subset for t in selected))
    pre = _preflight_usage(files)
    body = compute_summary(records, metric_fns, subsets)
    overall = cast(dict[str, Any], body["overall"])
    return {
        "env": cfg.env.name,
        "model": cfg.model.name,
        "ablation": cfg.ablation.name,
        "experiment": cfg.experiment,
        "n_selected": len(selected),
        "n_tasks_total": n_tasks_total,
        # partial: the selection (subset=, limit=, tasks=) covers less than the world's whole task set
        "partial": len(selected) < n_tasks_total,
        "selection": selection_of(cfg),
        "repeats": repeats,
        "n_episodes": len(wanted),
        "n_finished": sum(1 for r in records if r.status == "ok"),
        "complete": stopped is None and wanted <= done_keys,
        "stopped_early": stopped,
        **body,
        "preflight": pre,
        "model_info": _model_info(files),
        "total_cost_usd": round(float(overall.get("cost_usd", 0.0)) + pre["cost_usd"], 6),
        "plugins": plugin_versions(registry.pm),
    }


def _preflight(comps: Components, files: RunFiles) -> float:
    """The one cheap call before the first episode; returns its cost (logged in preflight.jsonl)."""
    backend = comps.make_backend()
    try:
        usage = backend.preflight()
        info = backend.info()
        if info is not None:  # what the backend settled on (e.g. its structured-output mode and why)
            files.write_json("model_info.json", info)
    except ModelFatalError as exc:
        raise RunError(str(exc)) from None
    finally:
        backend.close()
    if isinstance(usage, Usage):
        files.append_line("preflight.jsonl", json.dumps(usage.model_dump()))
        return usage.cost_usd
    return 0.0


def _play(cfg: RunConfig, cfg_dict: dict[str, Any], comps: Components, files: RunFiles, pending: list[Job],
          progress: _Progress, hook: Any, plugin_modules: list[str]) -> str | None:
    """Play ``pending`` on the configured executor (inline, local worker processes or Ray), the preflight call
    first; returns why the run stopped early, or None."""
    def preflight() -> float:
        return _preflight(comps, files)

    if cfg.runner.executor == "ray":
        from eb_core.ray_executor import run_on_ray  # imports ray; only here

        return run_on_ray(cfg, cfg_dict, files, pending, progress, hook, plugin_modules, preflight)
    if cfg.runner.workers <= 1 and concurrency(cfg) <= 1:
        return _run_inline(cfg, comps, files, pending, progress, hook, preflight)
    # workers start up while the preflight call is in flight
    return run_workers(cfg, cfg_dict, files, pending, progress, hook, plugin_modules, preflight)


def _preflight_usage(files: RunFiles) -> dict[str, Any]:
    """The preflight calls of every invocation in this directory, added up."""
    total = Usage()
    path = files.root / "preflight.jsonl"
    if path.exists():
        for line in path.read_text(encoding="utf-8").splitlines():
            try:
                total = total + Usage.model_validate_json(line)
            except ValueError:
                continue  # a torn last line
    return {"calls": total.calls, "prompt_tokens": total.prompt_tokens,
            "completion_tokens": total.completion_tokens, "cost_usd": round(total.cost_usd, 6)}


def _model_info(files: RunFiles) -> dict[str, Any] | None:
    """The backend's ``info()`` as recorded at preflight (``model_info.json``), if it has one."""
    try:
        return json.loads((files.root / "model_info.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def _run_inline(cfg: RunConfig, comps: Components, files: RunFiles, pending: list[Job], progress: _Progress,
                hook: Any, preflight: Any = None) -> str | None:
    budget = BudgetGuard(cfg.model.max_cost_usd)
    if preflight is not None:
        try:
            budget.add(preflight())
        except ModelBudgetExceeded as exc:
            return f"budget: {exc}"
    env = comps.make_env()
    backend = comps.make_backend()
    try:
        for task, repeat in pending:
            options = comps.episode_options(files, task, repeat, budget=budget, hook=hook)
            driver = EpisodeDriver(env=env, task=task, seed=episode_seed(cfg.seed, task.id, repeat),
                                   planner=comps.make_planner(backend), backend=backend, env_config=cfg.env,
                                   options=options)
            try:
                rec = play(driver, backend)
            except ModelFatalError as exc:
                raise RunError(str(exc)) from None
            except ModelBudgetExceeded as exc:
                return f"budget: {exc}"
            rec = label_record(rec.model_copy(update={"repeat": repeat}), driver.steps)
            finish_episode(files, with_node(rec, node_name()), progress, hook)
    finally:
        env.close()
        backend.close()
    return None
