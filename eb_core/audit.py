"""``eb audit``: shortcut probes that every shipped task set must pass (types shared with world plugins).

A probe runs over a world's task list and returns a :class:`ProbeResult`. The core ships the generic
probes (blind constant-action policies, instruction diversity and grammar, duplicates, the noisy-expert
curve, parallel forms); a world adds its own through :meth:`eb_core.env.Env.audit_probes`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from eb_core.env import Task

__all__ = ["AuditProbe", "ProbeResult"]


class ProbeResult(BaseModel):
    """What one probe measured, its threshold and whether the task set passed."""

    model_config = ConfigDict(extra="forbid")

    name: str
    """Short probe name, e.g. ``visible_area``."""
    passed: bool
    value: str
    """The measured figure, as printed (e.g. ``"3.3 % (worst subset: base)"``)."""
    threshold: str
    """The goal, as printed (e.g. ``"<= 5 % per subset"``)."""
    failing_tasks: list[str] = Field(default_factory=list)
    """Task ids that break the probe (printed, at most a few dozen)."""
    warning: str | None = None
    """A warning that does not fail the audit (e.g. a subset that tells models apart poorly)."""
    rows: list[dict[str, Any]] = Field(default_factory=list)
    """Optional detail table (one dict per row, e.g. per subset or per policy)."""


@dataclass(frozen=True)
class AuditProbe:
    """A named check: ``run(tasks, env_params)`` -> :class:`ProbeResult`.

    ``tasks`` are the tasks under audit (the shipped file, or ``task_file=``); ``env_params`` are the env's
    ``params`` from the config (e.g. ``task_file``). A probe must finish in a few minutes on 2 cores.
    """

    name: str
    description: str
    """One sentence: what shortcut or defect this probe guards against."""
    run: Callable[[list[Task], dict[str, Any]], ProbeResult]
