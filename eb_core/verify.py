"""``eb verify RUN``: replay every episode of a run from its task and seed and check the records against it.

No model is called. For each measured episode the world is reset with the recorded task and seed, each
recorded answer is parsed again against the world's action space, and the recorded actions are executed;
success, progress, steps, invalid actions, output errors and the end reason are recomputed by the rules of
:mod:`eb_core.episode` and compared with ``episodes.jsonl`` and ``steps.jsonl``, one line per mismatch. The
manifest is checked too: its format version, the digest of the task set against the installed one, the
config against ``config.yaml``, and the versions it was made with (a different version is a warning: the
replay decides). Rendering is turned off where the world has a ``render`` parameter.

Runs made before the manifest existed (format version 0) verify with a warning.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from eb_core.components import Components, episode_seed, select_tasks
from eb_core.config import ConfigError, RunConfig
from eb_core.env import Env, Task
from eb_core.manifest import config_digest, library_versions
from eb_core.planner import Planner
from eb_core.plugins import Registry, get_plugin_manager, plugin_versions
from eb_core.records import FORMAT_VERSION, ActionRecord, EpisodeRecord, RunLog, StepRecord, read_run, read_steps
from eb_core.taskfile import task_set_digest

__all__ = ["VerifyResult", "verify_run"]

#: Episode-record fields the replay recomputes.
CHECKED_FIELDS = ("success", "progress", "end_reason", "env_steps", "planner_steps", "invalid_actions",
                  "output_errors", "empty_plan")


@dataclass
class VerifyResult:
    """What ``eb verify`` found: mismatches (any makes it fail) and warnings."""

    run_dir: str
    mismatches: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    episodes: int = 0
    """Episodes replayed."""

    @property
    def ok(self) -> bool:
        return not self.mismatches


def _name(key: tuple[str, int]) -> str:
    return key[0] + (f" (repeat {key[1]})" if key[1] else "")


# -- the manifest -------------------------------------------------------------------------------------------


def _check_manifest(run: RunLog, comps: Components, all_tasks: Sequence[Task], selected: Sequence[Task],
                    registry: Registry, out: VerifyResult) -> None:
    m = run.manifest
    if m is None:
        out.warnings.append(f"{run.root} has no manifest.json (made before format version {FORMAT_VERSION}): the "
                            f"task set, config and versions are not checked, only the episodes")
        return
    if m.env != comps.cfg.env.name:
        out.mismatches.append(f"manifest: env {m.env!r}, config.yaml says {comps.cfg.env.name!r}")
    if m.config_digest != config_digest(json.loads(json.dumps(run.config, default=str))):
        out.mismatches.append("manifest: config.yaml differs from the config the run was made with "
                              "(config digest mismatch)")
    digest = task_set_digest(all_tasks)
    if m.task_set_digest != digest or m.n_tasks != len(all_tasks):
        out.mismatches.append(f"manifest: the run was played on another task set than the installed one "
                              f"({m.n_tasks} tasks, digest {m.task_set_digest[:12]}; installed: {len(all_tasks)} "
                              f"tasks, digest {digest[:12]})")
    elif m.selected_digest != task_set_digest(selected):
        out.mismatches.append("manifest: the run's tasks differ from the installed tasks of the same ids")
    now = {**{f"plugin:{k}": v for k, v in plugin_versions(registry.pm).items()}, **library_versions()}
    for key in sorted(set(m.versions) | set(now)):
        if key in m.versions and m.versions.get(key) != now.get(key):
            out.warnings.append(f"manifest: {key} was {m.versions[key]!r} for the run, installed is "
                                f"{now.get(key, 'absent')!r}")


# -- one episode ------------------------------------------------------------------------------------------


class _Replay:
    """One episode replayed by the rules of :mod:`eb_core.episode` from its step records."""

    def __init__(self, env: Env, planner: Planner, cfg: RunConfig, key: tuple[str, int], out: list[str]) -> None:
        self.env, self.planner, self.cfg, self.ecfg, self.key, self.out = env, planner, cfg, cfg.env, key, out
        self.env_steps = self.invalid = self.output_errors = self.charged = 0
        self.progress, self.success, self.empty_plan, self.done = 0.0, False, False, False
        self.end_reason = "max_steps"
        self.uses_step = self.ecfg.output_error_uses_step
        self.cap = self.ecfg.max_invalid_actions
        if self.cap is None and not self.uses_step:
            self.cap = self.ecfg.max_steps

    def bad(self, msg: str) -> None:
        self.out.append(f"{_name(self.key)}: {msg}")

    def budget_left(self) -> int:
        return self.ecfg.max_steps - self.env_steps - self.charged

    def capped(self) -> bool:
        return self.cap is not None and self.invalid >= self.cap

    def run(self, task: Task, seed: int, steps: Sequence[StepRecord]) -> dict[str, Any] | None:
        """Replay; returns the recomputed record fields, or None when the steps stopped making sense."""
        self.env.reset(task, seed)
        for i, step in enumerate(steps, 1):
            if step.planner_step != i or step.env_step_before != self.env_steps:
                self.bad(f"step {i}: recorded as planner step {step.planner_step} after {step.env_step_before} env "
                         f"steps, the replay is at planner step {i} after {self.env_steps} (a step removed or "
                         f"reordered?)")
                return None
            if self.done or self.budget_left() <= 0 or self.capped():
                self.bad(f"step {i}: recorded after the episode had ended")
                return None
            if not self.step(i, step):
                return None
        if not self.done and self.budget_left() > 0 and not self.capped():
            self.bad(f"the recorded steps end after {len(steps)} planner steps, before the episode did")
            return None
        end = self.end_reason if self.done else ("invalid_cap" if self.capped() else "max_steps")
        return {"success": bool(self.success), "progress": 1.0 if self.success else self.progress,
                "end_reason": end, "env_steps": self.env_steps, "planner_steps": len(steps),
                "invalid_actions": self.invalid, "output_errors": self.output_errors, "empty_plan": self.empty_plan}

    def output_error(self, count_invalid: bool = True) -> None:
        self.output_errors += 1
        if count_invalid or not self.uses_step:
            self.invalid += 1
        if self.uses_step:
            self.charged += 1

    def step(self, i: int, step: StepRecord) -> bool:
        space = self.env.action_space()
        self.planner.set_action_space(space)
        parsed = self.planner.parse(step.raw_output)  # the run's planner reads the answer again
        if parsed.error != step.error:
            self.bad(f"step {i}: the recorded answer parses to error {parsed.error!r}, recorded {step.error!r}")
            return False
        if parsed.error is not None:
            self.output_error()
        elif not parsed.actions and parsed.truncated_at is None:
            self.empty_plan = True
            if self.ecfg.empty_plan_ends:
                self.end_reason, self.done = "empty_plan", True
            else:
                self.output_error(count_invalid=False)
        elif not parsed.actions:
            self.invalid += 1
            if self.uses_step:
                self.charged += 1
        else:
            return self.execute(i, step, space, parsed.actions)
        if step.actions:
            self.bad(f"step {i}: {len(step.actions)} action(s) recorded where the answer gives none to execute")
            return False
        return True

    def execute(self, i: int, step: StepRecord, space: Any, planned: Sequence[Any]) -> bool:
        """Execute the recorded actions, checking each against the parsed plan and the world's outcome."""
        allowed = list(planned[: max(0, self.budget_left())])
        if not step.actions or len(step.actions) > len(allowed):
            self.bad(f"step {i}: {len(step.actions)} action(s) recorded, the answer allows 1 to {len(allowed)}")
            return False
        for j, (act, want) in enumerate(zip(step.actions, allowed), 1):
            if _plain(act.action) != _plain(want):
                self.bad(f"step {i} action {j}: recorded action {json.dumps(_plain(act.action))}, the answer's "
                         f"plan gives {json.dumps(_plain(want))}")
                return False
            self.execute_one(i, j, act, space)
            last = j == len(step.actions)
            stop = (self.done or (not act.success and self.ecfg.replan_on_failure) or self.capped()
                    or self.budget_left() <= 0)
            if stop != last and not (last and len(step.actions) == len(allowed)):
                self.bad(f"step {i} action {j}: the plan " + ("went on after" if stop else "stopped at")
                         + " this action, against the rules")
                return False
        return True

    def execute_one(self, i: int, j: int, act: ActionRecord, space: Any) -> None:
        if "expert_action" in act.model_fields_set:  # the run asked the expert here: ask it too (same state)
            try:
                plan = self.env.expert_plan()
            except Exception:
                plan = None
            first = _plain(plan[0]) if plan else None
            if first != _plain(act.expert_action):
                self.bad(f"step {i} action {j}: expert_action recorded {json.dumps(_plain(act.expert_action))}, "
                         f"the expert now gives {json.dumps(first)}")
        result = self.env.step(act.action)
        self.env_steps += 1
        progress = max(0.0, min(1.0, result.progress))
        name = space.name_of(act.action)
        got = {"env_step": self.env_steps, "action_name": name, "success": result.action_success,
               "feedback": result.feedback, "progress": progress}
        for k, v in got.items():
            rec_v = getattr(act, k)
            if not _same(rec_v, v):
                self.bad(f"step {i} action {j}: {k} recorded {rec_v!r}, replay {v!r}")
        self.progress, self.success = progress, result.task_success
        if not result.action_success:
            self.invalid += 1
        if result.done:
            self.done = True
            self.end_reason = "success" if result.task_success else "done"


def _plain(x: Any) -> Any:
    """An action as JSON would hold it (tuples as lists, numpy scalars as numbers)."""
    return json.loads(json.dumps(x, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-9)
        except (TypeError, ValueError):
            return False
    return bool(a == b)


def _check_usage(rec: EpisodeRecord, steps: Sequence[StepRecord], out: list[str]) -> None:
    prompt = sum(s.usage.prompt_tokens for s in steps)
    completion = sum(s.usage.completion_tokens for s in steps)
    if (prompt, completion) != (rec.prompt_tokens, rec.completion_tokens):
        out.append(f"{_name(rec.key)}: tokens recorded {rec.prompt_tokens}+{rec.completion_tokens}, the steps add up "
                   f"to {prompt}+{completion}")


def _verify_episode(env: Env, planner: Planner, cfg: RunConfig, task: Task, rec: EpisodeRecord,
                    steps: Sequence[StepRecord], out: list[str]) -> None:
    expected_seed = episode_seed(cfg.seed, rec.task_id, rec.repeat)
    if rec.seed != expected_seed:
        out.append(f"{_name(rec.key)}: seed recorded {rec.seed}, the run seed gives {expected_seed}")
        return
    replay = _Replay(env, planner, cfg, rec.key, out)
    got = replay.run(task, rec.seed, steps)
    if got is None:
        return
    for k in CHECKED_FIELDS:
        if not _same(getattr(rec, k), got[k]):
            out.append(f"{_name(rec.key)}: {k} recorded {getattr(rec, k)!r}, replay {got[k]!r}")
    _check_usage(rec, steps, out)


# -- the run ----------------------------------------------------------------------------------------------


def _check_summary(run: RunLog, registry: Registry, selected: Sequence[Task], repeats: int,
                   out: VerifyResult) -> None:
    """``summary.json``'s metric blocks against those recomputed from ``episodes.jsonl`` (which the replay checks)."""
    from eb_core.metrics import compute_summary

    if run.summary is None:
        out.warnings.append("no summary.json (the run was stopped before its end): only the episodes are checked")
        return
    wanted = {(t.id, r) for t in selected for r in range(repeats)}
    records = [r for r in run.episodes if r.key in wanted]
    metric_fns = {name: spec.load() for name, spec in registry.metrics.items()}
    body = json.loads(json.dumps(compute_summary(records, metric_fns, list(dict.fromkeys(t.subset for t in selected))),
                                 default=str))
    # a run made before the manifest may predate today's metric code: its summary differences are warnings
    report = out.mismatches if run.manifest is not None else out.warnings
    blocks = [("overall", run.summary.get("overall"), body["overall"])]
    blocks += [(f"subset {k}", (run.summary.get("subsets") or {}).get(k), v) for k, v in body["subsets"].items()]
    for name, recorded, recomputed in blocks:
        if not isinstance(recorded, dict):
            report.append(f"summary.json: no {name} block")
            continue
        differ = [k for k in recomputed if k in recorded and not _close(recorded[k], recomputed[k])]
        if differ:
            k = differ[0]
            report.append(f"summary.json: {name} {k} recorded {recorded[k]!r}, episodes.jsonl gives "
                                  f"{recomputed[k]!r}" + (f" (and {len(differ) - 1} more)" if len(differ) > 1 else ""))


def _close(a: Any, b: Any) -> bool:
    """Equal, with floats compared to 1e-9 at any depth (a summary's numbers went through JSON)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b))
    return _same(a, b)


def _episodes(run: RunLog, selected: Sequence[Task], repeats: int, out: VerifyResult) -> list[EpisodeRecord]:
    """The measured episodes to replay; missing, duplicated and unexpected episodes are mismatches."""
    wanted = [(t.id, r) for r in range(repeats) for t in selected]
    by_key: dict[tuple[str, int], EpisodeRecord] = {}
    for rec in run.episodes:
        if rec.key in by_key:
            out.mismatches.append(f"{_name(rec.key)}: recorded twice in episodes.jsonl")
        by_key[rec.key] = rec
    for key in wanted:
        if key not in by_key:
            out.mismatches.append(f"{_name(key)}: missing from episodes.jsonl")
        elif by_key[key].status != "ok":
            out.warnings.append(f"{_name(key)}: not measured (status error); it is redone when the run is resumed")
    extra = sorted(set(by_key) - set(wanted))
    for key in extra:
        out.mismatches.append(f"{_name(key)}: in episodes.jsonl but not among the tasks the config selects")
    return [by_key[k] for k in wanted if k in by_key and by_key[k].status == "ok"]


def _selection(run: RunLog, all_tasks: Sequence[Task], cfg: RunConfig, out: VerifyResult) -> list[Task]:
    """The run's tasks: those its manifest lists (looked up in the installed set), else what its config selects."""
    by_config = select_tasks(all_tasks, cfg)
    if run.manifest is None or not run.manifest.task_ids:
        return by_config
    by_id = {t.id: t for t in all_tasks}
    missing = [i for i in run.manifest.task_ids if i not in by_id]
    if missing:
        out.mismatches.append(f"manifest: {len(missing)} task(s) of the run are not in the installed task set "
                              f"({', '.join(missing[:3])})")
    selected = [by_id[i] for i in run.manifest.task_ids if i in by_id]
    if [t.id for t in by_config] != run.manifest.task_ids:
        out.warnings.append("config.yaml now selects other tasks than the run did (changed selection rules?); the "
                            "run's own tasks are verified")
    return selected


def _replay_env(comps: Components, render: bool) -> Env:
    """The run's env for replay: with ``render: false`` where the world takes that parameter (every world here
    does; one that rejects it renders)."""
    if not render and comps.cfg.env.params.get("render", True) is not False:
        try:
            return comps.make_env(render=False)
        except ConfigError:
            pass
    return comps.make_env()


def verify_run(run_dir: str | Path, *, render: bool = False, plugins: Iterable[Any] = (),
               registry: Registry | None = None) -> VerifyResult:
    """Verify the run in ``run_dir`` (see the module docstring). ``plugins``: extra plugin modules (tests)."""
    run = read_run(run_dir)
    out = VerifyResult(str(run.root))
    cfg = RunConfig.model_validate(run.config)
    registry = registry or Registry(get_plugin_manager(plugins=list(plugins)))
    comps = Components(cfg, registry)
    all_tasks = comps.load_tasks()
    selected = _selection(run, all_tasks, cfg, out)
    _check_manifest(run, comps, all_tasks, selected, registry, out)
    records = _episodes(run, selected, cfg.runner.repeats, out)
    tasks = {t.id: t for t in selected}
    env = _replay_env(comps, render)
    # only the planner's parse is used: its prompt settings (json schema, images) do not matter here
    planner = comps.planner_cls(cfg.planner, cfg.env)
    try:
        for rec in records:
            if not (run.episode_dir(rec.key) / "steps.jsonl").is_file():
                out.mismatches.append(f"{_name(rec.key)}: its steps.jsonl is missing")
                continue
            try:
                steps = read_steps(run.episode_dir(rec.key), strict=True)
            except ValueError as exc:
                out.mismatches.append(f"{_name(rec.key)}: {exc}")
                continue
            _verify_episode(env, planner, cfg, tasks[rec.task_id], rec, steps, out.mismatches)
            out.episodes += 1
    finally:
        env.close()
    _check_summary(run, registry, selected, cfg.runner.repeats, out)
    return out


def cmd_verify(args: list[str]) -> int:
    """``eb verify RUN_DIR [RUN_DIR ...] [--render]``: exit 0 when every run verifies, 1 on any mismatch."""
    import sys

    from eb_core.config import ConfigError

    usage = "usage: eb verify RUN_DIR [RUN_DIR ...] [--render] (a directory holding episodes.jsonl)"
    render = "--render" in args
    dirs = [a for a in args if a != "--render"]
    bad = [a for a in dirs if a.startswith("-")]
    if bad or not dirs:
        print(f"eb: error: {'unknown option ' + repr(bad[0]) + '; ' if bad else ''}{usage}", file=sys.stderr)
        return 2
    failed = False
    for d in dirs:
        if not (Path(d) / "episodes.jsonl").is_file():
            print(f"eb: error: {d} is not a run directory (no episodes.jsonl); {usage}", file=sys.stderr)
            return 2
        try:
            res = verify_run(d, render=render)
        except (ConfigError, ValueError, FileNotFoundError) as exc:
            print(f"eb: error: cannot verify {d}: {str(exc).splitlines()[0]}", file=sys.stderr)
            return 2
        for w in res.warnings:
            print(f"warning: {w}", file=sys.stderr)
        for m in res.mismatches:
            print(f"MISMATCH {m}")
        verdict = "verified" if res.ok else f"FAILED ({len(res.mismatches)} mismatch(es))"
        print(f"{d}: {res.episodes} episode(s) replayed, {verdict}")
        failed |= not res.ok
    return 1 if failed else 0
