"""Reward terms and presets of the Gymnasium environments (docs/training.md has the formulas).

Every step reports the same terms in ``info["reward_terms"]``; the reward is their weighted sum:

* ``success``: 1 on the step that solves the task, else 0.
* ``progress``: the goal fraction gained this step (the paper's subgoal progress; may be negative when the
  agent undoes a goal condition).
* ``invalid``: how many invalid actions this step made (failed actions, a plan cut at an invalid item, an
  executable plan that named no valid action).
* ``format``: 1 when the answer could not be read (prompt mode), else 0.
* ``distance``: metres moved closer to the goal this step, where the world's env has ``distance_to_goal``
  (Navigation, Manipulation); 0 elsewhere.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["PRESETS", "TERMS", "reward_weights", "total_reward"]

TERMS = ("success", "progress", "invalid", "format", "distance")

PRESETS: dict[str, dict[str, float]] = {
    "success": {"success": 1.0},
    "progress": {"success": 1.0, "progress": 1.0},
    "shaped": {"success": 1.0, "progress": 1.0, "invalid": -0.1, "format": -0.1, "distance": 0.1},
}


def reward_weights(reward: str | Mapping[str, float | str]) -> dict[str, float]:
    """Weights of a preset name, or of a mapping (a preset name under ``"preset"`` plus overrides)."""
    if isinstance(reward, str):
        if reward not in PRESETS:
            raise ValueError(f"unknown reward preset {reward!r}; allowed: {', '.join(PRESETS)} "
                             f"(or a dict of weights over {', '.join(TERMS)})")
        return dict(PRESETS[reward])
    weights = dict(reward)
    base = weights.pop("preset", None)
    out = reward_weights(str(base)) if base is not None else {}
    for key, value in weights.items():
        if key not in TERMS:
            raise ValueError(f"unknown reward term {key!r}; allowed: {', '.join(TERMS)} (and 'preset')")
        out[key] = float(value)
    return out


def total_reward(terms: Mapping[str, float], weights: Mapping[str, float]) -> float:
    return float(sum(weights.get(k, 0.0) * float(v) for k, v in terms.items()))
