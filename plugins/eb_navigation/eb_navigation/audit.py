"""EB-Navigation's own audit probes (``eb audit env=navigation``), beside the core's generic ones.

* ``text_only_rule_agent``: agents that get what a language-only model gets when the scene is not described --
  the instruction and whether each action worked -- and walk forward, turning or side-stepping on a bump (see
  :data:`eb_navigation.baselines.RULE_AGENTS`). If one of them solves many tasks, the starts give the answer away
  without looking. Threshold: at most 15 % per subset (the paper's blind GPT-4o solves 17.4 % of its tasks).
* ``target_visible_at_start``: the subsets that promise the target in view at the start (all but long_horizon)
  must show at least :data:`~eb_navigation.generate.MIN_VISIBLE_PIXELS` target pixels in a 128 x 128
  segmentation of the first view, and long_horizon must show none (its target is behind the agent).

Both run on the task list they are given (the shipped file or ``task_file=``); the first on geometry only
(seconds), the second renders one small image per task (about a minute for 300 tasks).
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

from eb_core.audit.contract import AuditProbe, ProbeResult
from eb_core.env import Task

__all__ = ["MAX_RULE_AGENT_RATE", "audit_probes", "target_visible_probe", "text_only_rule_agent_probe"]

MAX_RULE_AGENT_RATE = 0.15
"""Most a feedback-only rule agent may solve in any subset."""
PROMISED_VISIBLE = ("base", "common_sense", "complex_instruction", "visual_appearance")
PROMISED_HIDDEN = ("long_horizon",)


def _rooms():
    """Rooms by (kind, seed, extras), built once per probe run."""
    from eb_navigation.room import NavRoom

    cache: dict[tuple, Any] = {}

    def get(spec):
        key = (spec.scene.kind, spec.scene.seed, spec.scene.clutter, spec.extra_objects)
        if key not in cache:
            cache[key] = NavRoom(spec.scene.kind, spec.scene.seed, [e.spec() for e in spec.extra_objects],
                                 spec.scene.clutter)
        return cache[key]

    return get


def text_only_rule_agent_probe(tasks: list[Task], env_params: dict[str, Any]) -> ProbeResult:
    """Success of each feedback-only rule agent per subset; fails if any exceeds :data:`MAX_RULE_AGENT_RATE`."""
    from eb_navigation.baselines import RULE_AGENTS, rule_agent_successes
    from eb_navigation.geometry import AgentState
    from eb_navigation.tasks import spec_of

    room_of = _rooms()
    solved: dict[str, dict[str, list[str]]] = defaultdict(lambda: {name: [] for name in RULE_AGENTS})
    totals: dict[str, int] = defaultdict(int)
    for task in tasks:
        spec = spec_of(task)
        room = room_of(spec)
        free = room.free_space(room.extra_ids)
        start = AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw, spec.start.tilt)
        totals[spec.subset] += 1
        for name, ok in rule_agent_successes(free, start, spec.target.position[:2]).items():
            if ok:
                solved[spec.subset][name].append(task.id)
    rows, worst, failing = [], (0.0, "", ""), []
    for subset, n in totals.items():
        for name, ids in solved[subset].items():
            rate = len(ids) / n
            rows.append({"subset": subset, "agent": name, "solved": len(ids), "tasks": n,
                         "rate": f"{100 * rate:.1f} %"})
            if rate > worst[0]:
                worst = (rate, subset, name)
            if rate > MAX_RULE_AGENT_RATE:
                failing.extend(ids)
    value = (f"{100 * worst[0]:.1f} % (worst: '{worst[2]}' on {worst[1]})" if worst[1] else "0.0 %")
    return ProbeResult(name="text_only_rule_agent", passed=not failing, value=value,
                       threshold=f"<= {100 * MAX_RULE_AGENT_RATE:.0f} % per subset and agent",
                       failing_tasks=sorted(set(failing))[:40], rows=rows)


def target_visible_probe(tasks: list[Task], env_params: dict[str, Any]) -> ProbeResult:
    """Target pixels at the start: enough where the subset promises the target in view, none in long_horizon."""
    from eb_navigation.generate import MIN_VISIBLE_PIXELS
    from eb_navigation.hard import LEVELS
    from eb_navigation.geometry import AgentState
    from eb_navigation.tasks import spec_of
    from eb_navigation.visibility import VIS_SIZE, Visibility

    room_of = _rooms()
    vis = Visibility()
    failing: list[str] = []
    per_subset: dict[str, list[int]] = defaultdict(list)
    try:
        for task in tasks:
            spec = spec_of(task)
            if spec.subset not in PROMISED_VISIBLE + PROMISED_HIDDEN:
                continue
            room = room_of(spec)
            start = AgentState.from_pose(spec.start.x, spec.start.y, spec.start.yaw, spec.start.tilt)
            px = vis.pixels(room, start, spec.target.id)
            per_subset[spec.subset].append(px)
            least = next((lv.min_target_pixels for lv in LEVELS.values() if lv.clutter == spec.scene.clutter),
                         MIN_VISIBLE_PIXELS)  # a harder level promises a smaller (partly hidden) target
            if (px < least) if spec.subset in PROMISED_VISIBLE else (px > 0):
                failing.append(task.id)
    finally:
        vis.close()
    rows = [{"subset": s, "tasks": len(v), "min_pixels": min(v), "max_pixels": max(v),
             "promise": "in view" if s in PROMISED_VISIBLE else "out of view"} for s, v in per_subset.items()]
    return ProbeResult(name="target_visible_at_start", passed=not failing,
                       value=f"{len(failing)} task(s) break their subset's promise",
                       threshold=(f">= {MIN_VISIBLE_PIXELS} target pixels of {VIS_SIZE} x {VIS_SIZE} (hard set: "
                                  f"{LEVELS['hard'].min_target_pixels}) at the start "
                                  f"({', '.join(PROMISED_VISIBLE)}); 0 in long_horizon"),
                       failing_tasks=failing[:40], rows=rows)


def audit_probes() -> list[AuditProbe]:
    return [
        AuditProbe("text_only_rule_agent",
                   "A language-only agent that sees only the instruction and action feedback (walk forward, turn "
                   "or side-step on a bump) must do badly: the start poses must not give the target away.",
                   text_only_rule_agent_probe),
        AuditProbe("target_visible_at_start",
                   "Subsets that promise the target in view at the start show it clearly (rendered pixel count); "
                   "long_horizon starts keep it out of view.",
                   target_visible_probe),
    ]
