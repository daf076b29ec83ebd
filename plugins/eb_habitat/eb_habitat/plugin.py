"""Registers EB-Habitat with EmbodiedBench. Imports nothing heavy (no MuJoCo): the env loads lazily."""

from __future__ import annotations

from eb_core import EnvSpec, hookimpl

SUBSETS = {
    "base": 50,
    "common_sense": 50,
    "complex_instruction": 50,
    "spatial_relationship": 50,
    "visual_appearance": 50,
    "long_horizon": 50,
}


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [
        EnvSpec(
            name="habitat", display_name="Habitat",
            entry_point="eb_habitat.env:HabitatEnv",
            description="EB-Habitat: rearrange small objects in an apartment with 70 fixed high-level skills "
            "(navigate to receptacles only, pick, place, open, close); 300 tasks in 6 subsets",
            subsets=dict(SUBSETS),
            tasksets=("classic", "hard"),
            task_generator="eb_habitat.make:generate",
            audit_probes="eb_habitat.audit:probes",
            install_hint="pip install -e plugins/eb_scenekit -e plugins/eb_habitat",
        )
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return ["pkg://eb_habitat.conf"]
