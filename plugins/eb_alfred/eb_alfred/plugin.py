"""Registers EB-ALFRED with EmbodiedBench. Imports nothing heavy: the env module loads only when selected."""

from __future__ import annotations

from eb_core import EnvSpec, hookimpl

SUBSETS = {
    "base": 50,
    "common_sense": 50,
    "complex_instruction": 50,
    "spatial_awareness": 50,
    "visual_appearance": 50,
    "long_horizon": 50,
}


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [
        EnvSpec(
            name="alfred", display_name="ALFRED",
            entry_point="eb_alfred.env:AlfredEnv",
            description="EB-ALFRED: household tasks with 8 high-level skills over a symbolic AI2-THOR-style world",
            subsets=dict(SUBSETS),
            task_generator="eb_alfred.generate:generate",
            audit_probes="eb_alfred.audit:probes",
            tasksets=("classic", "hard"),
            install_hint="pip install -e plugins/eb_alfred",
        )
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return ["pkg://eb_alfred.conf"]
