"""The parallel-forms probe: a fresh form from the world's generator must be as hard as the shipped one."""

from __future__ import annotations

import contextlib
import inspect
import io
import json
import tempfile
from collections import Counter, defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

from eb_core.audit.contract import EpisodeOutcome, ProbeResult
from eb_core.audit.expert import _curve_outcomes
from eb_core.audit.setup import AuditSetup, _by_subset, _listed, _mean, _pct
from eb_core.env import Task
from eb_core.stats import detectable_difference, permutation_p_value

__all__ = ["find_form_generator", "probe_parallel_forms"]

PARALLEL_ALPHA = 0.01
PARALLEL_NOISE = 0.5


def find_form_generator(generator: Callable[..., Any] | None) -> Callable[..., Any] | None:
    """The ``audit_form(out, seed, per_subset)`` function defined beside a world's task generator (in the same
    module), or None. It writes a fresh form with ``per_subset`` tasks of every subset, drawn the way the
    shipped set is drawn, to ``out`` (a task file or folder ``load_tasks`` reads): the parallel-forms probe
    then generates only what it plays instead of the whole task set."""
    if generator is None:
        return None
    fn = getattr(inspect.getmodule(generator), "audit_form", None)
    return fn if callable(fn) else None


def _write_fresh_form(setup: AuditSetup, workdir: Path) -> tuple[str, str, bool]:
    """Generate a fresh form in ``workdir``: (its path, how it was made, whether it is a per-subset sample).

    Another task set than ``classic`` is drawn at its difficulty: by the world's ``audit_form`` when it takes
    ``difficulty``, else by its whole task generator when that does; when neither does, the default draw (the
    value says so: such a comparison tells little)."""
    form, whole = setup.form_generator, setup.generator
    src = workdir / "parallel"
    if form is not None and (setup.taskset == "classic" or _difficulty(form, setup.taskset)
                             or not _difficulty(whole, setup.taskset)):
        sample, fn = True, form
    elif whole is not None:  # no sampler, or only the whole generator draws at this difficulty
        sample, fn = False, whole
    else:
        raise LookupError("the world registers no task generator")
    more = _difficulty(fn, setup.taskset)
    with contextlib.redirect_stdout(io.StringIO()):
        if sample:
            k = setup.fresh_per_subset()
            fn(out=str(src), seed=setup.parallel_seed, per_subset=k, **more)
            how = f"generated with seed={setup.parallel_seed}, {k} tasks per subset"
        else:
            fn(out=str(src), seed=setup.parallel_seed, **more)
            how = f"generated with seed={setup.parallel_seed}"
        if more:
            how += f", difficulty={more['difficulty']}"
        elif setup.taskset != "classic":
            how += f", at the generator's default difficulty (it takes no difficulty={setup.taskset})"
    if src.is_file():
        src = src.rename(workdir / "parallel.json")
    return str(src), how, sample


def _difficulty(fn: Callable[..., Any] | None, taskset: str) -> dict[str, Any]:
    """``{"difficulty": taskset}`` when a non-classic task set is audited and ``fn`` takes ``difficulty`` (the
    fresh form is then drawn as hard as the set under audit), else nothing: the generator's default draw."""
    if fn is None or taskset == "classic":
        return {}
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return {}
    takes = "difficulty" in params or any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
    return {"difficulty": taskset} if takes else {}


def task_param(params: dict[str, Any]) -> str:
    """The env param a task file or folder goes in: ``task_file`` (every world of this project reads a folder there
    too; navigation knows no ``task_dir``, and a fresh hard form -- one file per subset in a folder -- crashed its
    probe), or ``task_dir`` for a world whose config knows only that older name."""
    return "task_dir" if "task_dir" in params and "task_file" not in params else "task_file"


def _fresh_form(setup: AuditSetup, workdir: Path) -> tuple[list[Task], dict[str, Any], str, bool]:
    """Tasks of another form (``parallel_source``, or a fresh one from the world's generator, made here or already
    under way in the background), its env params, how it was made and whether it is a per-subset sample."""
    params = dict(setup.env_params)
    sample = False
    if setup.parallel_source:
        src = Path(setup.parallel_source)
        how = f"given {src}"
    else:
        pending = setup._cache.pop("fresh_pending", None)
        if pending is not None:
            path, how, sample = pending.result()
            setup._cache["fresh_took"] = (pending.wall, pending.cpu)
        else:
            path, how, sample = _write_fresh_form(setup, workdir)
        src = Path(path)
    if not src.exists():
        raise FileNotFoundError(f"no task file or folder at {src}")
    key = task_param(params)
    params.pop("task_dir" if key == "task_file" else "task_file", None)
    params[key] = str(src)
    return setup.env_cls.load_tasks(**params), params, how, sample


def probe_parallel_forms(setup: AuditSetup) -> ProbeResult:
    threshold = (f"no subset differs at p < {PARALLEL_ALPHA} (noise {PARALLEL_NOISE}, "
                 f"{setup.parallel_repeats} runs/task)")
    if setup.quick:
        return ProbeResult(name="parallel_forms", passed=True, skipped=True, value="skipped (--quick)",
                           threshold=threshold)
    levels = [(PARALLEL_NOISE, r) for r in range(setup.parallel_repeats)]
    with tempfile.TemporaryDirectory(prefix="eb-audit-") as tmp:
        try:
            fresh, params, how, sample = _fresh_form(setup, Path(tmp))
        except LookupError as exc:
            return ProbeResult(name="parallel_forms", passed=True, skipped=True, value=f"n/a ({exc})",
                               threshold=threshold)
        # an audit of some subsets (subset=...) compares with the same subsets of the fresh form
        audited = {t.subset for t in setup.tasks}
        fresh = [t for t in fresh if t.subset in audited]
        ours, theirs = setup.forms_sample(list(setup.tasks)), setup.forms_sample(fresh)
        # the shipped form's episodes at p = 0.5 are shared with the noise curve (same seeds per repeat)
        shipped_scores = _scores(_curve_outcomes(setup, levels, ours))
        key = "" if params == setup.env_params else json.dumps(params, sort_keys=True)
        fresh_scores = _scores(_curve_outcomes(setup, levels, theirs, key))
    a_groups, b_groups = _by_subset(ours), _by_subset(theirs)
    counts_a, counts_b = Counter(t.subset for t in setup.tasks), Counter(t.subset for t in fresh)
    rows, bad, failing = [], [], []
    for subset in list(dict.fromkeys([*a_groups, *b_groups])):
        a = [shipped_scores[t.id] for t in a_groups.get(subset, [])]
        b = [fresh_scores[t.id] for t in b_groups.get(subset, [])]
        if not a or not b:
            bad.append(f"{subset} (only in {'the shipped' if a else 'the fresh'} form)")
            rows.append({"subset": subset, "shipped": len(a), "fresh": len(b)})
            continue
        pv = permutation_p_value(a, b, seed=setup.seed)
        rows.append({"subset": subset, "tasks": f"{len(a)} / {len(b)}", "shipped": _pct(_mean(a)),
                     "fresh": _pct(_mean(b)), "difference": f"{100 * (_mean(a) - _mean(b)):+.1f} pt",
                     "detectable": f"{100 * detectable_difference(a, b):.0f} pt", "p-value": f"{pv:.4f}"})
        if pv < PARALLEL_ALPHA:
            bad.append(f"{subset} ({_pct(_mean(a))} vs {_pct(_mean(b))}, p={pv:.4f})")
            # the shipped tasks furthest from the fresh form's mean explain the gap
            mb = _mean(b)
            far = sorted(a_groups[subset], key=lambda t: -abs(shipped_scores[t.id] - mb))
            failing += [t.id for t in far[:5]]
        if not sample and counts_a[subset] != counts_b[subset]:  # a sample form has fewer tasks by design
            bad.append(f"{subset} (counts differ: {counts_a[subset]} vs {counts_b[subset]})")
    value = f"fresh form {how}; " + ("differs: " + "; ".join(bad) if bad else "every subset within task sampling")
    return ProbeResult(name="parallel_forms", passed=not bad, value=value, threshold=threshold,
                       failing_tasks=_listed(failing), rows=rows)




def _scores(outcomes: dict[tuple[float, int], dict[str, EpisodeOutcome]]) -> dict[str, float]:
    """Each task's success rate over the given levels' episodes."""
    wins: dict[str, list[float]] = defaultdict(list)
    for per_task in outcomes.values():
        for tid, out in per_task.items():
            wins[tid].append(float(out.success))
    return {tid: _mean(v) for tid, v in wins.items()}

