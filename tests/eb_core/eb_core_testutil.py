"""Helpers for the core's tests (a uniquely named module: several test folders have a conftest)."""

from __future__ import annotations

from eb_core.config import validate_config


def make_config(**over):
    """A valid RunConfig for the corridor fixture env, with dotted-key overrides."""
    cfg = {
        "env": {"name": "corridor", "max_steps": 10, "max_invalid_actions": 4, "replan_on_failure": True,
                "empty_plan_ends": True, "default_n_shot": 2, "resolution": 64, "multi_view": False, "params": {}},
        "model": {"name": "scripted-oracle", "backend": "scripted", "oracle": True},
        "planner": {"name": "vlm"},
        "ablation": {"name": "none"},
        "runner": {"workers": 1, "quiet": True},
    }
    for key, value in over.items():
        node = cfg
        parts = key.split("__")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = value
    return validate_config(cfg)
