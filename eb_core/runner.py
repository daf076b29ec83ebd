"""The runner: task selection, repeats, resume, parallel workers, progress, summary.

Crash safety: an episode is appended to ``episodes.jsonl`` (one ``os.write`` + fsync, by the main
process only) after its step files were moved into place; re-running the same command skips finished
episodes, redoes unfinished and ``error`` ones, and never writes an episode twice. An episode is one
(task, repeat) pair; ``runner.repeats=N`` plays every task N times with seeds derived from the run seed,
the task id and the repeat. One process at a time owns a run directory (an ``flock`` on ``run.lock``).
"""

from __future__ import annotations

import hashlib
import importlib
import json
import multiprocessing as mp
import os
import sys
import time
from collections.abc import Iterable, Sequence
from typing import Any

from eb_core.config import ConfigError, RunConfig
from eb_core.env import Env, Task
from eb_core.episode import BudgetGuard, run_episode
from eb_core.inflight import error_record, node_name, with_node
from eb_core.events import EpisodeEndEvent, RunEndEvent, RunStartEvent
from eb_core.metrics import compute_summary
from eb_core.model import ModelBackend, ModelBudgetExceeded, ModelFatalError, Usage
from eb_core.plugins import Registry, get_plugin_manager, plugin_versions
from eb_core.records import EpisodeRecord, RunDirLocked, RunFiles, RunLock, episode_dir_name

__all__ = ["RunError", "Components", "episode_seed", "run", "select_tasks"]

#: Config keys whose change makes old episodes incomparable with new ones.
_FINGERPRINT_KEYS = ("env", "model", "planner", "ablation", "augmenters", "seed")


class RunError(RuntimeError):
    """The run cannot start or had to stop; the message is one line for the user."""


def _one_line(exc: BaseException) -> str:
    return "; ".join(ln.strip() for ln in str(exc).splitlines() if ln.strip())[:600]


#: The run directory's lock while this process runs; forked workers close their copy of it.
_HELD_LOCK: RunLock | None = None


def episode_seed(run_seed: int, task_id: str, repeat: int = 0) -> int:
    """Every episode is seeded from the run seed, its task id and its repeat (independent of order and
    workers). Repeat 0 keeps the seed of single-repeat runs, so their results stay valid."""
    key = f"{run_seed}:{task_id}" if repeat == 0 else f"{run_seed}:{task_id}:{repeat}"
    digest = hashlib.sha256(key.encode()).digest()
    return int.from_bytes(digest[:4], "little")


class Components:
    """Everything one process needs to play episodes, built from a validated config."""

    def __init__(self, cfg: RunConfig, registry: Registry) -> None:
        self.cfg = cfg
        self.registry = registry
        self.env_spec = registry.get("env", cfg.env.name)
        self.env_cls: type[Env] = self.env_spec.load()
        self.backend_spec = registry.get("model backend", cfg.model.backend)
        self.backend_cls: type[ModelBackend] = self.backend_spec.load()
        self.planner_cls = registry.get("planner", cfg.planner.name).load()
        self.augmenters = []
        for aug in cfg.augmenters:
            cls = registry.get("augmenter", aug.name).load()
            kwargs = {k: v for k, v in aug.model_dump().items() if k != "name"}
            try:
                self.augmenters.append(cls(**kwargs))
            except (TypeError, ValueError) as exc:
                raise ConfigError(f"augmenter {aug.name!r}: {exc}") from None

    def load_tasks(self) -> list[Task]:
        split = self.cfg.split
        params = dict(self.cfg.env.params)
        taskset = self.cfg.taskset
        if taskset != "classic":
            if taskset not in self.env_spec.tasksets:
                raise ConfigError(f"unknown taskset {taskset!r} for env {self.cfg.env.name!r}; available: "
                                  f"{', '.join(self.env_spec.tasksets)}. Fix: taskset=classic or one of those.")
            params["taskset"] = taskset
        if split == "test":
            return self.env_cls.load_tasks(**params)
        if self.cfg.limit is None:
            raise ConfigError(f"split={split} is generated on demand: say how many tasks with limit=N "
                              f"(e.g. limit=300)")
        try:
            return self.env_cls.split_tasks(split, 0, self.cfg.limit, **params)
        except ValueError as exc:
            raise ConfigError(str(exc).splitlines()[0]) from None

    def make_env(self) -> Env:
        e = self.cfg.env
        try:
            return self.env_cls(resolution=e.resolution, multi_view=e.multi_view, **e.params)
        except (TypeError, ValueError) as exc:  # includes pydantic's ValidationError of the env's params
            raise ConfigError(f"env {e.name!r} rejected its parameters (env.params={e.params}): "
                              f"{_one_line(exc)}") from None

    def make_backend(self) -> ModelBackend:
        try:
            return self.backend_cls(**self.cfg.model.backend_kwargs())
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"model {self.cfg.model.name!r} (backend {self.cfg.model.backend!r}): "
                              f"{_one_line(exc)}") from None

    def make_planner(self, backend: ModelBackend) -> Any:
        return self.planner_cls(self.cfg.planner, self.cfg.env, supports_json_schema=backend.supports_json_schema,
                                supports_images=backend.supports_images)


def select_tasks(tasks: Sequence[Task], cfg: RunConfig) -> list[Task]:
    """Apply ``tasks=``, ``subset=`` and ``limit=`` (first N of the selection, in the stable order)."""
    if cfg.tasks:
        by_id = {t.id: t for t in tasks}
        missing = [t for t in cfg.tasks if t not in by_id]
        if missing:
            raise ConfigError(f"unknown task id(s) {', '.join(missing[:5])} for env {cfg.env.name!r}; "
                              f"ids look like {tasks[0].id!r} (see the env's task file)")
        return [by_id[t] for t in cfg.tasks]
    selected = list(tasks)
    if cfg.subset is not None:
        aliases = cfg.env.subset_aliases
        wanted = [cfg.subset] if isinstance(cfg.subset, str) else list(cfg.subset)
        wanted = [aliases.get(s, s) for s in wanted]
        known = list(dict.fromkeys(t.subset for t in tasks))
        bad = [s for s in wanted if s not in known]
        if bad:
            also = f" (or the aliases {', '.join(sorted(aliases))})" if aliases else ""
            raise ConfigError(f"unknown subset {bad[0]!r} for env {cfg.env.name!r}; available: {', '.join(known)}"
                              f"{also}")
        selected = [t for t in selected if t.subset in wanted]
    if cfg.limit is not None:
        selected = selected[: cfg.limit]
    return selected


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


# -- worker processes -------------------------------------------------------------------------------


def _build_registry(plugin_modules: Sequence[str]) -> Registry:
    plugins = [importlib.import_module(m) for m in plugin_modules]
    return Registry(get_plugin_manager(plugins=plugins))


def _worker_main(cfg_dict: dict[str, Any], run_dir: str, plugin_modules: list[str], conn: Any,
                 shared_cost: Any, slots: int = 1) -> None:
    """A worker process: plays up to ``slots`` episodes at once (:class:`eb_core.inflight.InflightLoop`),
    each with its own env from the process's pool; jobs arrive over its own pipe, records go back over it.

    Each worker has a private pipe, so a worker that dies mid-message can only break its own channel.
    """
    from multiprocessing.connection import wait

    from eb_core.inflight import InflightLoop

    if _HELD_LOCK is not None:  # forked: the parent alone holds the run directory's lock
        _HELD_LOCK.forget_in_child()
    cfg = RunConfig.model_validate(cfg_dict)
    registry = _build_registry(plugin_modules)
    comps = Components(cfg, registry)
    files = RunFiles(run_dir)
    loop = InflightLoop(comps, files, slots=slots, budget=BudgetGuard(cfg.model.max_cost_usd, shared_cost),
                        hook=registry.pm.hook, seed_of=lambda t, r: episode_seed(cfg.seed, t, r),
                        on_record=lambda key, rec: conn.send(("done", rec.model_dump_json())),
                        timeout_s=cfg.runner.episode_timeout_s)
    parent = os.getppid()
    try:
        while True:
            ready = wait([conn, loop.wake_fd], timeout=0.25)
            if os.getppid() != parent:  # the run's process died (kill -9): its pipe may never report EOF
                break
            stop = False
            try:
                while conn in ready and conn.poll():
                    item = conn.recv()
                    if item is None:
                        stop = True
                        break
                    job = json.loads(item)
                    loop.start(job["key"], Task.model_validate(job["task"]), int(job["repeat"]))
                if stop:
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

Job = tuple[Task, int]
"""One episode to play: a task and its repeat."""


def run(cfg: RunConfig, run_dir: str | os.PathLike[str], *, cfg_dict: dict[str, Any] | None = None,
        plugins: Iterable[Any] = (), registry: Registry | None = None) -> dict[str, Any]:
    """Run (or resume) every selected episode of ``cfg`` into ``run_dir`` and return the summary.

    ``plugins`` are extra plugin modules registered directly (tests); they must be importable by name
    so worker processes can register them too. Raises :class:`RunError` at once when another process
    is running in ``run_dir``.
    """
    global _HELD_LOCK
    lock = RunLock(run_dir)
    try:
        lock.acquire()
    except RunDirLocked as exc:
        raise RunError(str(exc)) from None
    _HELD_LOCK = lock
    try:
        return _run_locked(cfg, run_dir, cfg_dict=cfg_dict, plugins=plugins, registry=registry)
    finally:
        _HELD_LOCK = None
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
        diff = _diff_keys(old, fp)
        if diff:
            raise RunError(
                f"{files.root} holds results of a different config (differs in: {', '.join(diff[:6])}); "
                f"pick a new experiment=NAME or hydra.run.dir=DIR, or delete that directory"
            )
    else:  # a fresh directory, or one where no episode ever finished (e.g. a missing key): take it over
        files.write_json("fingerprint.json", fp)
    import yaml  # shipped with omegaconf

    (files.root / "config.yaml").write_text(yaml.safe_dump(cfg_dict, sort_keys=False))
    files.write_json("plugins.json", plugin_versions(registry.pm))

    previous = files.load_episodes()
    kept = [r for r in previous if r.status == "ok"]
    if len(kept) != len(previous):
        files.rewrite_episodes(kept)  # error episodes are redone
    finished = {r.key for r in kept}
    files.clean_partial({episode_dir_name(*k) for k in finished})
    # Repeat-major order: a run stopped early (budget) has whole passes over the tasks first.
    pending: list[Job] = [(t, r) for r in range(repeats) for t in selected if (t.id, r) not in finished]

    hook = registry.pm.hook
    hook.eb_on_run_start(event=RunStartEvent(run_dir=str(files.root), env=cfg.env.name, model=cfg.model.name,
                                             n_tasks=len(selected), n_pending=len(pending), config=cfg_dict))
    stopped: str | None = None
    progress = _Progress(len(pending), cfg.runner.quiet, f"{cfg.env.name} / {cfg.model.name}")
    try:
        if pending:
            def preflight() -> float:
                """The one cheap call before the first episode; returns its cost (logged in preflight.jsonl)."""
                backend = comps.make_backend()
                try:
                    usage = backend.preflight()
                    info = getattr(backend, "info", None)
                    if callable(info):  # what the backend settled on (e.g. its structured-output mode and why)
                        files.write_json("model_info.json", info())
                except ModelFatalError as exc:
                    raise RunError(str(exc)) from None
                finally:
                    backend.close()
                if isinstance(usage, Usage):
                    files.append_line("preflight.jsonl", json.dumps(usage.model_dump()))
                    return usage.cost_usd
                return 0.0

            if cfg.runner.executor == "ray":
                from eb_core.ray_executor import run_on_ray  # imports ray; only here

                stopped = run_on_ray(cfg, cfg_dict, files, pending, progress, hook, plugin_modules, preflight)
            elif cfg.runner.workers <= 1 and _concurrency(cfg) <= 1:
                stopped = _run_inline(cfg, comps, files, pending, progress, hook, preflight)
            else:  # workers start up while the preflight call is in flight
                stopped = _run_workers(cfg, cfg_dict, files, pending, progress, hook, plugin_modules, preflight)
    finally:
        progress.close()

    all_records = files.load_episodes()
    files.clean_partial({episode_dir_name(*r.key) for r in all_records})  # staging dirs of stopped episodes
    wanted = {(t.id, r) for t in selected for r in range(repeats)}
    records = [r for r in all_records if r.key in wanted]
    done_keys = {r.key for r in records}
    metric_fns = {name: spec.load() for name, spec in registry.metrics.items()}
    subsets = list(dict.fromkeys(t.subset for t in selected))
    pre = _preflight_usage(files)
    body = compute_summary(records, metric_fns, subsets)
    summary: dict[str, Any] = {
        "env": cfg.env.name,
        "model": cfg.model.name,
        "ablation": cfg.ablation.name,
        "experiment": cfg.experiment,
        "n_selected": len(selected),
        "repeats": repeats,
        "n_episodes": len(wanted),
        "n_finished": sum(1 for r in records if r.status == "ok"),
        "complete": stopped is None and wanted <= done_keys,
        "stopped_early": stopped,
        **body,
        "preflight": pre,
        "model_info": _model_info(files),
        "total_cost_usd": round(float(body["overall"].get("cost_usd", 0.0)) + pre["cost_usd"], 6),
        "plugins": plugin_versions(registry.pm),
    }
    files.write_json("summary.json", summary)
    hook.eb_on_run_end(event=RunEndEvent(run_dir=str(files.root), summary=summary, stopped_early=stopped))
    return summary


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


def _finish(files: RunFiles, rec: EpisodeRecord, progress: _Progress, hook: Any) -> None:
    final = files.finalize_episode_dir(rec.task_id, rec.repeat)
    if rec.status == "ok":  # automatic error labels from the step records (docs/error_analysis.md)
        from eb_core.errors import label_episode, load_steps

        labels = label_episode(load_steps(final), rec.model_dump())
        rec = rec.model_copy(update={"error_counts": labels["counts"], "perception_score": labels["perception_score"]})
    files.append_episode(rec)
    progress.update(rec)
    hook.eb_on_episode_end(event=EpisodeEndEvent(run_dir=str(files.root), record=rec.model_dump()))


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
            try:
                rec = run_episode(
                    env=env, task=task, seed=episode_seed(cfg.seed, task.id, repeat),
                    planner=comps.make_planner(backend),
                    backend=backend, env_config=cfg.env, step_dir=files.staging_dir(task.id, repeat),
                    save_images=cfg.runner.save_images, augmenters=comps.augmenters, budget=budget, hook=hook,
                    run_dir=str(files.root), expert_labels=cfg.runner.expert_labels, repeat=repeat,
                )
            except ModelFatalError as exc:
                raise RunError(str(exc)) from None
            except ModelBudgetExceeded as exc:
                return f"budget: {exc}"
            _finish(files, with_node(rec.model_copy(update={"repeat": repeat}), node_name()), progress, hook)
    finally:
        env.close()
        backend.close()
    return None


def _concurrency(cfg: RunConfig) -> int:
    """Episodes in flight: ``runner.concurrency``, or one per worker."""
    return cfg.runner.concurrency or cfg.runner.workers


def split_slots(concurrency: int, workers: int, pending: int) -> list[int]:
    """Episodes in flight per worker: ``min(concurrency, pending)`` spread evenly over at most ``workers``."""
    total = max(1, min(concurrency, pending))
    n = max(1, min(workers, total))
    return [total // n + (1 if i < total % n else 0) for i in range(n)]


def job_key(task_id: str, repeat: int) -> str:
    return f"{task_id}#{repeat}"


def _run_workers(cfg: RunConfig, cfg_dict: dict[str, Any], files: RunFiles, pending: list[Job],
                 progress: _Progress, hook: Any, plugin_modules: list[str],
                 preflight: Any = None) -> str | None:
    from multiprocessing.connection import wait

    ctx = mp.get_context(cfg.runner.start_method)
    shared_cost = ctx.Value("d", 0.0)
    queue_: list[Job] = list(pending)
    timeout = cfg.runner.episode_timeout_s
    # A worker drops an episode that waits for its model past the timeout itself; the process is killed
    # only when an episode is still running a little after that (stuck in the env on the main thread).
    kill_after = None if timeout is None else timeout + max(1.0, 0.1 * timeout)

    class Worker:
        def __init__(self, slots: int) -> None:
            self.slots = slots
            self.conn, child = ctx.Pipe(duplex=True)
            self.proc = ctx.Process(target=_worker_main, daemon=True,
                                    args=(cfg_dict, str(files.root), plugin_modules, child, shared_cost, slots))
            self.proc.start()
            child.close()
            self.jobs: dict[str, tuple[Job, float]] = {}

        def give(self, job: Job) -> None:
            key = job_key(job[0].id, job[1])
            self.jobs[key] = (job, time.monotonic())
            self.conn.send(json.dumps({"key": key, "task": job[0].model_dump(mode="json"), "repeat": job[1]}))

    def lost(w: Worker, why: str, culprit: str | None = None) -> None:
        for key, ((t, repeat), _started) in list(w.jobs.items()):
            msg = why if culprit in (None, key) else (
                f"{why.split(' (', 1)[0]} -- killed with episode {culprit} of the same worker process")
            _finish(files, with_node(error_record(t, repeat, episode_seed(cfg.seed, t.id, repeat), msg), node_name()),
                    progress, hook)
        w.jobs.clear()

    workers = [Worker(n) for n in split_slots(_concurrency(cfg), cfg.runner.workers, len(pending))]
    stopped: str | None = None
    try:
        if preflight is not None:
            cost = preflight()
            budget = BudgetGuard(cfg.model.max_cost_usd, shared_cost)
            try:
                budget.add(cost)
            except ModelBudgetExceeded as exc:
                stopped = f"budget: {exc}"
        while stopped is None:
            for w in workers:
                while len(w.jobs) < w.slots and queue_:
                    w.give(queue_.pop(0))
            busy = [w for w in workers if w.jobs]
            if not busy:
                break
            ready = wait([w.conn for w in busy] + [w.proc.sentinel for w in busy], timeout=0.5)
            for w in list(busy):
                got_message = False
                while w.conn in ready:
                    try:
                        if not w.conn.poll():
                            break
                        msg = w.conn.recv()
                    except (EOFError, OSError):
                        break
                    got_message = True
                    kind, payload = msg
                    if kind == "done":
                        rec = EpisodeRecord.model_validate_json(payload)
                        w.jobs.pop(job_key(*rec.key), None)
                        _finish(files, rec, progress, hook)
                    elif kind == "fatal":
                        raise RunError(payload)
                    elif kind == "budget":
                        stopped = f"budget: {payload}"
                        break
                if got_message and w.proc.is_alive():
                    continue
                now = time.monotonic()
                hung = [k for k, (_j, t0) in w.jobs.items() if kill_after is not None and now - t0 > kill_after]
                if hung or not w.proc.is_alive():
                    if hung:
                        w.proc.kill()
                    w.proc.join(5)
                    why = (f"episode exceeded runner.episode_timeout_s={timeout}" if hung
                           else f"worker process died (exit code {w.proc.exitcode})")
                    lost(w, why, culprit=hung[0] if hung else None)
                    workers.remove(w)
                    if queue_:
                        workers.append(Worker(w.slots))
    finally:
        for w in workers:
            try:
                w.conn.send(None)
            except (OSError, BrokenPipeError):
                pass
        deadline = time.monotonic() + (10 if stopped is None else 3)
        for w in workers:
            w.proc.join(max(0.1, deadline - time.monotonic()))
            if w.proc.is_alive():
                w.proc.kill()
                w.proc.join(2)
    return stopped
