"""Rules over the executed actions: refused actions and their reasons, repetition, loops, drift, the expert.

:class:`ActionRules` walks one episode's actions in order and returns each action's labels; it keeps the little
state the rules need (the last failure of every action, how many actions have succeeded, the distances).
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field
from typing import Any

from eb_core.errors.taxonomy import DRIFT_WINDOW, FAILURE_LABELS, make_label

__all__ = ["DISTANCE_KEYS", "PATH_KEYS", "ActionRules", "agent_name", "expert_name"]

#: Info keys read for the straight-line distance to the goal (the contract's name first; navigation's own name).
DISTANCE_KEYS = ("distance_to_goal", "distance_to_target")
#: Info key for the length of the shortest free path to the goal (around furniture), when the world reports it.
PATH_KEYS = ("path_distance",)


def _number(action: dict[str, Any], keys: tuple[str, ...]) -> float | None:
    for key in keys:
        value = action.get(key)
        if value is None and isinstance(action.get("info"), dict):
            value = action["info"].get(key)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return float(value)
    return None


def expert_name(action: dict[str, Any]) -> str | None:
    if action.get("expert_action_name") is not None:
        return str(action["expert_action_name"])
    if action.get("expert_action") is not None:
        return json.dumps(action["expert_action"])
    return None


def agent_name(action: dict[str, Any]) -> str:
    return str(action.get("action_name") if action.get("action_name") is not None
               else json.dumps(action.get("action")))


@dataclass
class _Move:
    name: str
    ok: bool
    env_step: int | None
    dist: float | None
    path: float | None
    located: bool = False
    """The world recorded the agent's own ``position`` or its free path to the goal: the agent walks toward its goal
    (navigation). Elsewhere a rising distance is an arm or an object on its way (manipulation lifts a shape off the
    lid before it moves it closer), which is no drift."""


@dataclass
class ActionRules:
    """The per-action rules of docs/error_analysis.md, applied in episode order."""

    successes: int = 0  # successful actions so far: the state changes only with them
    last_failure: dict[str, tuple[int, int | None]] = field(default_factory=dict)  # name -> (successes, env_step)
    moves: list[_Move] = field(default_factory=list)
    drift_streak: int = 0
    progress: float = 0.0

    def label(self, a: dict[str, Any], planned: list[str], j: int) -> list[dict[str, Any]]:
        name, ok, failure = agent_name(a), bool(a.get("success")), a.get("failure")
        env_step = a.get("env_step")
        progress = float(a.get("progress") or 0.0)
        before, self.progress = self.progress, progress
        feedback = str(a.get("feedback") or "")
        labels: list[dict[str, Any]] = []
        if not ok:
            labels += self._failed(name, failure, feedback, env_step)
        if ok and failure == "grasp":
            # executed as asked, but the grasp it was for did not happen (manipulation's empty close)
            labels.append(make_label("grasp_failure", feedback or "the gripper holds nothing", env_step,
                                     action=name, state=feedback or None))
        if ok and a.get("wrong_target"):
            labels.append(make_label("wrong_target", f"{name!r} succeeded on an object or place the goal does not "
                                     "name", env_step, action=name))
        expert = expert_name(a)
        agrees = expert is not None and expert == name
        move = _Move(name, ok, env_step, _number(a, DISTANCE_KEYS), _number(a, PATH_KEYS),
                     located=a.get("position") is not None or _number(a, PATH_KEYS) is not None)
        if ok and not agrees:
            labels += self._loop(move, progress, before)
        if expert is not None and not agrees:
            labels += self._against_expert(name, ok, expert, planned, j, progress, before, env_step)
        self.moves.append(move)
        labels += self._drift(agrees)
        if ok:
            self.successes += 1
        return labels

    def _failed(self, name: str, failure: Any, feedback: str, env_step: int | None) -> list[dict[str, Any]]:
        reason = FAILURE_LABELS.get(failure) if isinstance(failure, str) else None
        # a refused action: one label saying why (docs/error_analysis.md, "Invalid actions")
        out = [make_label(reason or "failed_action", feedback or "the action failed", env_step, action=name,
                          reason=failure, state=feedback or None)]
        prev = self.last_failure.get(name)
        if prev is not None and prev[0] == self.successes:
            out.append(make_label("repetition", f"{name!r} failed again from the same state (it failed at step "
                                  f"{prev[1]} and no action succeeded since)", env_step, action=name,
                                  failed_before_at=prev[1], state=feedback or None))
        self.last_failure[name] = (self.successes, env_step)
        return out

    def _loop(self, move: _Move, progress: float, before: float) -> list[dict[str, Any]]:
        """A two-action cycle A B A B back to the same state: same distances where the world reports them, no
        progress."""
        if len(self.moves) < 3 or progress > before:
            return []
        m1, m2, m3 = self.moves[-3:]
        if not (m1.ok and m2.ok and m3.ok) or m1.name != m3.name or m2.name != move.name or m1.name == m2.name:
            return []
        for key in ("dist", "path"):
            vals = [getattr(m, key) for m in (m1, m2, m3, move)]
            if all(v is not None for v in vals) and (abs(vals[0] - vals[2]) > 1e-6 or abs(vals[1] - vals[3]) > 1e-6):
                return []  # the cycle moved somewhere: not back to the same state
        return [make_label("repetition", f"a loop: {m1.name!r}, {m2.name!r}, {m1.name!r}, {m2.name!r} came back to "
                           "the same state with no progress", move.env_step, action=f"{m1.name} / {m2.name}",
                           loop=[m1.env_step, m2.env_step, m3.env_step, move.env_step])]

    def _against_expert(self, name: str, ok: bool, expert: str, planned: list[str], j: int, progress: float,
                        before: float, env_step: int | None) -> list[dict[str, Any]]:
        if not ok:
            rest = planned[planned.index(name) + 1:] if name in planned else planned[j + 1:]
            if expert in rest:
                return [make_label("wrong_order", f"{name!r} came before {expert!r}, which the expert does first",
                                   env_step, action=name, expert=expert)]
            return [make_label("missing_step", f"the expert would {expert!r} first; the plan skips it", env_step,
                               action=name, expert=expert)]
        if progress <= before:
            return [make_label("extra_step", f"{name!r} is not needed (the expert would {expert!r}) and made no "
                               "progress", env_step, action=name, expert=expert)]
        return []

    def _drift(self, agrees: bool) -> list[dict[str, Any]]:
        """Rising distance over DRIFT_WINDOW actions that no detour explains: where the world reports the free
        path's length, it rose too; where it does not, no move failed (met an obstacle) in or just before the
        window. Once per rising stretch."""
        if agrees or self.moves[-1].dist is None or not self.moves[-1].located:
            return []
        measured = [(m, m.dist) for m in self.moves if m.dist is not None and m.located]
        if len(measured) < DRIFT_WINDOW + 1:
            return []
        window = [m for m, _ in measured[-(DRIFT_WINDOW + 1):]]
        dists = [d for _, d in measured[-(DRIFT_WINDOW + 1):]]
        rising = all(b > a + 1e-9 for a, b in itertools.pairwise(dists))
        if not rising:
            self.drift_streak = 0
            return []
        paths = [m.path for m in window]
        known = [p for p in paths if p is not None]
        if len(known) == len(paths):
            if not (known[-1] > known[0] + 1e-6 and all(b >= a - 1e-6 for a, b in itertools.pairwise(known))):
                return []  # the free path did not get longer: a detour around furniture
            why = f"the free path to the goal grew too ({known[0]:.2f} -> {known[-1]:.2f} m)"
        else:
            start = self.moves.index(window[0])
            if any(not m.ok for m in self.moves[max(0, start - 3):]):
                return []  # the agent met an obstacle: stepping away from the goal may be the way round it
            why = "no move was blocked before or during it"
        self.drift_streak += 1
        if self.drift_streak > 1:
            return []
        last = window[-1]
        return [make_label("navigation_drift", f"the distance to the goal grew for {DRIFT_WINDOW} actions "
                           f"({dists[0]:.2f} -> {dists[-1]:.2f} m); {why}", last.env_step,
                           actions=[m.name for m in window[1:]],
                           distances=[round(d, 3) for d in dists],
                           path_distances=[round(p, 3) for p in known] or None)]
