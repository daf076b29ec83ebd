"""``eb audit``: shortcut probes that every shipped task set must pass.

A probe runs over a world's task list and returns a :class:`ProbeResult`. The core ships the generic probes
(blind constant-action policies, blind policies that react to feedback, instruction diversity and grammar,
duplicates, the closed-loop oracle, the noisy-expert curve, parallel forms); a world adds its own by naming a
function on its ``EnvSpec`` (``audit_probes="package.module:function"``). The probes drive the ``Env``
directly (no model server, no planner): an episode is ``reset`` then ``step`` until the world says done,
``env.max_steps`` actions were taken or ``env.max_invalid_actions`` actions failed, the same budgets ``eb run``
uses. See ``docs/audit.md``.

The package, by job:

* :mod:`~eb_core.audit.contract` -- what a world implements and returns (worlds import only this);
* :mod:`~eb_core.audit.setup` -- :class:`AuditSetup`: env class, tasks, budgets, sampling;
* :mod:`~eb_core.audit.playing` -- episodes, and batches of them in worker processes;
* :mod:`~eb_core.audit.blind`, :mod:`~eb_core.audit.instructions`, :mod:`~eb_core.audit.expert`,
  :mod:`~eb_core.audit.forms` -- the generic probes;
* :mod:`~eb_core.audit.running` -- one audit, start to end; :mod:`~eb_core.audit.render` -- its table;
* :mod:`~eb_core.audit.command` -- ``eb audit``'s arguments.

Its statistics (p50, the rise test, the permutation test) live in :mod:`eb_core.stats`.
"""

from __future__ import annotations

from eb_core.audit.blind import (
    BLIND_MAX_SUCCESS,
    CandidateSearch,
    FetchSearch,
    ReactivePolicy,
    feedback_policies,
    probe_blind_policies,
    probe_feedback_policies,
)
from eb_core.audit.command import AUDIT_USAGE, cmd_audit
from eb_core.audit.contract import (
    AuditProbe,
    BlindPolicy,
    EpisodeOutcome,
    FeedbackPolicy,
    NamedPolicy,
    Policy,
    ProbeResult,
    sample_positions,
)
from eb_core.audit.expert import P50_WARN, RISE_Z, probe_closed_loop, probe_noise_curve
from eb_core.audit.forms import PARALLEL_ALPHA, PARALLEL_NOISE, find_form_generator, probe_parallel_forms
from eb_core.audit.instructions import (
    TEMPLATES_MIN,
    UNIQUE_MIN,
    grammar_issues,
    probe_grammar,
    probe_templates,
    probe_unique_instructions,
)
from eb_core.audit.playing import noisy_expert_episode, play, play_jobs
from eb_core.audit.render import format_audit
from eb_core.audit.running import generic_probes, run_audit, world_probes
from eb_core.audit.setup import FRESH_PER_SUBSET, MAX_LISTED, NOISE_LEVELS, AuditSetup, random_action
from eb_core.stats import detectable_difference, p50, permutation_p_value

__all__ = [
    "AUDIT_USAGE",
    "AuditProbe",
    "AuditSetup",
    "BLIND_MAX_SUCCESS",
    "BlindPolicy",
    "CandidateSearch",
    "EpisodeOutcome",
    "FRESH_PER_SUBSET",
    "FetchSearch",
    "FeedbackPolicy",
    "MAX_LISTED",
    "NOISE_LEVELS",
    "NamedPolicy",
    "P50_WARN",
    "PARALLEL_ALPHA",
    "PARALLEL_NOISE",
    "Policy",
    "ProbeResult",
    "RISE_Z",
    "ReactivePolicy",
    "TEMPLATES_MIN",
    "UNIQUE_MIN",
    "cmd_audit",
    "detectable_difference",
    "feedback_policies",
    "find_form_generator",
    "format_audit",
    "generic_probes",
    "grammar_issues",
    "noisy_expert_episode",
    "p50",
    "permutation_p_value",
    "play",
    "play_jobs",
    "probe_blind_policies",
    "probe_closed_loop",
    "probe_feedback_policies",
    "probe_grammar",
    "probe_noise_curve",
    "probe_parallel_forms",
    "probe_templates",
    "probe_unique_instructions",
    "random_action",
    "run_audit",
    "sample_positions",
    "world_probes",
]
