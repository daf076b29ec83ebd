"""What a world's audit code implements and returns: probes, their results and named blind policies.

World plugins import their names from this module (``from eb_core.audit.contract import AuditProbe,
ProbeResult``), which depends on :mod:`eb_core.env` alone, so no world module and no probe module of the core
import each other. A world registers its probes on its ``EnvSpec``
(``audit_probes="package.module:function"``, a function returning ``list[AuditProbe]``) and may name blind
policies of its own through :meth:`eb_core.env.Env.audit_blind_policies`.
"""

from __future__ import annotations

import random
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from pydantic import BaseModel, ConfigDict, Field

from eb_core.env import Action, DiscreteActionSpace, Env, StepResult, Task

__all__ = ["AuditProbe", "BlindPolicy", "EpisodeOutcome", "FeedbackPolicy", "NamedPolicy", "Policy", "ProbeResult",
           "sample_positions"]


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
    skipped: bool = False
    """The probe did not apply (no template metadata, ``--quick``...); it counts as passed."""


@dataclass(frozen=True)
class AuditProbe:
    """A named check: ``run(tasks, env_params)`` -> :class:`ProbeResult`.

    ``tasks`` are the tasks under audit (the shipped file, or ``task_file=``); ``env_params`` are the env's
    ``params`` from the config (e.g. ``task_file``). A probe must finish in a few minutes on 2 cores. Within
    one audit a world's probes get the same ``tasks`` list object, so they may share work keyed by it.
    """

    name: str
    description: str
    """One sentence: what shortcut or defect this probe guards against."""
    run: Callable[[list[Task], dict[str, Any]], ProbeResult]



@dataclass(frozen=True)
class EpisodeOutcome:
    success: bool
    steps: int
    end: str
    """``success``, ``done`` (ended unsolved), ``max_steps``, ``invalid_cap``, ``no_action`` or ``error``."""
    detail: str = ""


Policy = Callable[[Env, int], "Action | None"]
"""``policy(env, step_index)`` -> the next action, or None to give up (the episode fails)."""


class FeedbackPolicy(ABC):
    """A policy that is told, after each action, what the env answered (``observe``): the blind agents that
    react to feedback (turn after a bump, try the next candidate after a failure). :func:`eb_core.audit.play`
    calls ``observe`` after every step; one object plays one episode."""

    @abstractmethod
    def __call__(self, env: Env, i: int) -> Action | None:
        """The next action (None to give up)."""

    @abstractmethod
    def observe(self, result: StepResult) -> None:
        """The env's answer to the last action."""


class NamedPolicy(Protocol):
    """A policy the blind probes play: a name for the table, and a fresh player per episode (given the task, so a
    policy may read the instruction)."""

    name: str

    def policy(self, task: Task | None = None) -> Policy | FeedbackPolicy: ...


@dataclass(frozen=True)
class BlindPolicy:
    """A policy that ignores image and instruction: ``prefix`` once, then ``cycle`` over and over.

    Items are action names (discrete spaces; a name the episode's space lacks makes the policy give up), action
    indices (ints, discrete spaces) or action vectors (vector spaces). A world may offer its own through
    :meth:`eb_core.env.Env.audit_blind_policies`.
    """

    name: str
    cycle: tuple[Any, ...]
    prefix: tuple[Any, ...] = ()

    def item(self, i: int) -> Any:
        if i < len(self.prefix):
            return self.prefix[i]
        return self.cycle[(i - len(self.prefix)) % len(self.cycle)]

    def actions(self, n: int = 20) -> list[Any]:
        """The first ``n`` items the policy plays (default 20, navigation's step budget)."""
        return [self.item(i) for i in range(n)]

    def policy(self, task: Task | None = None) -> Policy:
        """The callable :func:`eb_core.audit.play` drives (``task`` is ignored: the policy is blind)."""

        def act(env: Env, i: int) -> Action | None:
            item = self.item(i)
            space = env.action_space()
            if isinstance(space, DiscreteActionSpace):
                if isinstance(item, int):
                    return item if 0 <= item < len(space) else None
                return space.actions.index(item) if item in space.actions else None
            return tuple(item)

        return act


def sample_positions(n: int, k: int, seed: int = 0) -> list[int]:
    """The positions (0-based, ascending) that the audit's policy probes play of a subset of ``n`` tasks when
    they play ``k`` of it: a simple random sample, seeded by the audit's ``seed``, ``n`` and ``k``, so that every
    task is as likely to be played and the subset's rate is estimated without bias whatever the file's order.
    (An evenly spaced pick aliases with a file whose task types come in turn: every 2.5th task of ALFRED's
    period-5 files is one of two types. One pick in each of ``k`` stretches does not fix that: stretches of 2
    and 3 tasks give unequal chances.) Every subset of ``n`` tasks gets the same positions, so the subsets that
    share their starts (navigation's base, common_sense and complex_instruction) are sampled at the same ones.
    All ``n`` positions when ``k >= n``. A generator that keeps a rule on what ``eb audit --quick`` plays
    (navigation's) calls this with ``seed=0``, the audit's default; it lives here, in the module worlds import,
    for that."""
    if k >= n:
        return list(range(n))
    return sorted(random.Random(f"eb-audit-sample:{int(seed)}:{int(n)}:{int(k)}").sample(range(n), k))
