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
            notes="Objects are numbered afresh by their position (left to right in the front image) after every "
                  "action, and each planner call gets the new list, so \"object 3\" in one call need not be "
                  "\"object 3\" in the next. An action's feedback uses the numbering from just before that action "
                  "and adds \"(object M in the new list)\" when the action changed a number; earlier actions of the "
                  "same plan may already have renumbered things (an object grasped as object 4 may be let go of as "
                  "object 3 once carried).",
        )
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return ["pkg://eb_manipulation.conf"]
