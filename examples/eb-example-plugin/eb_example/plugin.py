"""Entry-point module: cheap to import (no numpy, no simulator), only specs and the config path."""

from eb_core import EnvSpec, hookimpl


@hookimpl
def eb_register_envs():
    return [
        EnvSpec(
            name="gridworld",
            entry_point="eb_example.env:GridWorld",  # imported only when a run selects env=gridworld
            description="Example plugin: walk to the green cell of a 5x5 grid",
            subsets={"base": 6, "far": 6},
        )
    ]


@hookimpl
def eb_config_searchpath():
    # Hydra finds eb_example/conf/env/gridworld.yaml, so `eb run env=gridworld` works.
    return ["pkg://eb_example.conf"]
