"""Entry-point module of the eb-manipulation plugin (imports nothing heavy: no MuJoCo, no simulator)."""

from eb_core import EnvSpec, hookimpl

SUBSETS = {"base": 48, "common_sense": 48, "complex": 48, "spatial": 48, "visual": 36}


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [
        EnvSpec(
            name="manipulation", display_name="Manipulation", visual_examples=True,
            entry_point="eb_manipulation.env:ManipulationEnv",
            description="EB-Manipulation: 228 tabletop tasks for a Franka Panda in MuJoCo (pick & place, stacking, "
                        "shape sorter, wiping; classic and hard sets); discrete 7-D gripper poses",
            subsets=dict(SUBSETS),
            tasksets=("classic", "hard"),
            task_generator="eb_manipulation.generate:generate",
            audit_probes="eb_manipulation.audit:audit_probes",
            install_hint="pip install -e plugins/eb_manipulation",
        )
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return ["pkg://eb_manipulation.conf"]
