"""Running an audit: the core's probes, then the world's, with single-core work moved beside the episode pools."""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from eb_core.audit.blind import probe_blind_policies, probe_feedback_policies
from eb_core.audit.contract import AuditProbe, ProbeResult
from eb_core.audit.expert import probe_closed_loop, probe_noise_curve
from eb_core.audit.forms import _write_fresh_form, probe_parallel_forms
from eb_core.audit.instructions import probe_grammar, probe_templates, probe_unique_instructions
from eb_core.audit.playing import _Background, _Clock
from eb_core.audit.setup import AuditSetup
from eb_core.env import Task

__all__ = ["generic_probes", "run_audit", "world_probes"]

_GENERIC: list[tuple[str, str, Callable[[AuditSetup], ProbeResult]]] = [
    ("instruction_unique", "Near-duplicate instructions shrink the effective task set and inflate agreement.",
     probe_unique_instructions),
    ("instruction_templates", "Few templates let a model learn the wording, not the task.", probe_templates),
    ("instruction_grammar", "Broken wording (a/an, doubled words, stray spaces) is a generator bug a model sees.",
     probe_grammar),
    ("blind_policies", "A fixed action sequence that ignores image and instruction must not solve tasks.",
     probe_blind_policies),
    ("feedback_policies", "A policy that ignores the image but reacts to feedback (turn or side-step after a "
     "bump; the next candidate after a failure) must not solve tasks.", probe_feedback_policies),
    ("closed_loop_oracle", "Every task must be solvable from its start within the step budget.", probe_closed_loop),
    ("noise_curve", "Success must fall as the expert's actions are randomised; a flat curve separates models poorly.",
     probe_noise_curve),
    ("parallel_forms", "A fresh task file from the generator must be as hard as the shipped one.",
     probe_parallel_forms),
]


def generic_probes(setup: AuditSetup) -> list[AuditProbe]:
    """The core's probes bound to ``setup`` (each ignores the ``run`` arguments in favour of the setup)."""
    return [AuditProbe(name=name, description=desc, run=_bound(fn, setup)) for name, desc, fn in _GENERIC]


def _bound(fn: Callable[[AuditSetup], ProbeResult],
           setup: AuditSetup) -> Callable[[list[Task], dict[str, Any]], ProbeResult]:
    """``fn`` as an :attr:`AuditProbe.run` that ignores its arguments and reads ``setup`` instead."""
    def run(tasks: list[Task], params: dict[str, Any]) -> ProbeResult:
        return fn(setup)
    return run


def world_probes(setup: AuditSetup) -> list[AuditProbe]:
    """The world's own probes: ``setup.world_probes`` (from ``EnvSpec.audit_probes``), else the env class's
    :meth:`~eb_core.env.Env.audit_probes`."""
    return list(setup.world_probes) if setup.world_probes is not None else list(setup.env_cls.audit_probes())


def _run_probe(probe: AuditProbe, tasks: list[Task], params: dict[str, Any]) -> ProbeResult:
    try:
        return probe.run(tasks, dict(params))
    except Exception as exc:  # a crashing probe fails the audit, the others still run
        return ProbeResult(name=probe.name, passed=False, value=f"probe crashed: {type(exc).__name__}: {exc}",
                           threshold="runs to the end")


def _run_probes(probes: list[AuditProbe], tasks: list[Task],
                params: dict[str, Any]) -> list[tuple[ProbeResult, float, float]]:
    """The probes in turn, all handed one task list (a world may share work between its probes by it); each
    result with its wall and CPU seconds."""
    tasks = list(tasks)
    out = []
    for p in probes:
        clock = _Clock()
        res = _run_probe(p, tasks, params)
        out.append((res, *clock.read()))
    return out


def _select(setup: AuditSetup, only: Sequence[str] | None) -> tuple[list[AuditProbe], list[int]]:
    """The probes to run (``only`` by name, KeyError naming the choices for an unknown one) and the positions of
    the world's own among them."""
    own = world_probes(setup)
    probes = generic_probes(setup) + own
    if only:
        names = [p.name for p in probes]
        unknown = [n for n in only if n not in names]
        if unknown:
            raise KeyError(f"unknown probe {unknown[0]!r}; probes of {setup.env_name}: {', '.join(names)}")
        probes = [p for p in probes if p.name in only]
    own_ids = {id(p) for p in own}
    return probes, [i for i, p in enumerate(probes) if id(p) in own_ids]


def _start_fresh_form(setup: AuditSetup, chosen: set[str]) -> str | None:
    """Start generating the parallel-forms probe's fresh form in a background process when it will be needed;
    returns the folder it is written to (None when not started)."""
    if (setup.workers > 1 and "parallel_forms" in chosen and not setup.quick and not setup.parallel_source
            and (setup.generator is not None or setup.form_generator is not None)):
        setup.fresh_per_subset()  # the sample size (and a cost measurement) are made here, once
        tmp = tempfile.mkdtemp(prefix="eb-audit-form-")
        setup._cache["fresh_pending"] = _Background(_write_fresh_form, setup, Path(tmp))
        return tmp
    return None


def _collect(pending: _Background, probes: list[AuditProbe], side: list[int], results: dict[int, ProbeResult],
             say: Callable[[str], None]) -> None:
    """The background process's results for the world's probes (each fails when the process crashed)."""
    try:
        for i, (res, wall, cpu) in zip(side, pending.result()):
            results[i] = res
            say(_took(f"{probes[i].name} (in the background)", wall, cpu))
    except RuntimeError as exc:
        for i in side:
            results[i] = ProbeResult(name=probes[i].name, passed=False, value=f"probe crashed: {exc}",
                                     threshold="runs to the end")


def run_audit(setup: AuditSetup, only: Sequence[str] | None = None,
              progress: Callable[[str], None] | None = None) -> list[tuple[AuditProbe, ProbeResult]]:
    """Run the generic probes, then the world's own (:func:`world_probes`); ``only`` selects by name.
    ``progress`` gets a line as each probe starts and ends (with its wall and CPU seconds).

    With ``setup.workers > 1`` the work that runs on one core is moved beside the episode probes (which use
    ``workers`` processes): the world's probes run in one forked process and the parallel-forms probe's fresh
    form is generated in another, both started first. Results do not depend on it.
    """
    def say(msg: str) -> None:
        if progress is not None:
            progress(msg)

    probes, side = _select(setup, only)
    results: dict[int, ProbeResult] = {}
    pending: _Background | None = None
    tmp: str | None = None
    try:
        tmp = _start_fresh_form(setup, {p.name for p in probes})
        if setup.workers > 1 and side:
            say(f"running {', '.join(probes[i].name for i in side)} in the background ...")
            pending = _Background(_run_probes, [probes[i] for i in side], list(setup.tasks), dict(setup.env_params))
        shared = list(setup.tasks)  # one list for the world's probes (they may share work by it)
        for i, probe in enumerate(probes):
            if pending is not None and i in side:
                continue
            say(f"running {probe.name} ...")
            clock = _Clock()
            results[i] = _run_probe(probe, shared if i in side else list(setup.tasks), setup.env_params)
            wall, cpu = clock.read()
            fresh = setup._cache.get("fresh_took") if probe.name == "parallel_forms" else None
            say(_took(probe.name, wall, cpu - (fresh[1] if fresh else 0.0)))  # the form's process ended in it
            if fresh:
                say(_took("the fresh form's generation (in the background)", *fresh))
        if pending is not None:
            _collect(pending, probes, side, results, say)
            pending = None
    finally:
        if pending is not None:
            pending.cancel()
        left = setup._cache.pop("fresh_pending", None)
        if left is not None:
            left.cancel()
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    return [(p, results[i]) for i, p in enumerate(probes)]


def _took(what: str, wall: float, cpu: float) -> str:
    return f"{what}: {wall:.1f} s wall, {cpu:.1f} s CPU"
