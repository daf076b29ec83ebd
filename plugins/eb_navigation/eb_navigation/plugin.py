"""Registers EB-Navigation with EmbodiedBench. Imports nothing heavy (no MuJoCo): the env loads lazily."""

from __future__ import annotations

from eb_core import EnvSpec, hookimpl

SUBSETS = {
    "base": 60,
    "common_sense": 60,
    "complex_instruction": 60,
    "visual_appearance": 60,
    "long_horizon": 60,
}


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [
        EnvSpec(
            name="navigation", display_name="Navigation", visual_examples=True,
            entry_point="eb_navigation.env:NavigationEnv",
            description="EB-Navigation: walk to a named object in procedurally furnished MuJoCo rooms with 8 "
            "low-level moves (step, turn, tilt); 300 tasks in 5 subsets, success within 1 m",
            subsets=dict(SUBSETS),
            task_generator="eb_navigation.generate:generate",
            audit_probes="eb_navigation.audit:audit_probes",
            tasksets=("classic", "hard"),
            install_hint="pip install -e plugins/eb_navigation",
        )
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return ["pkg://eb_navigation.conf"]
