"""The example plugin's own tests: one subclass of the core's conformance suite."""

from eb_core.testing import EnvConformanceSuite


class TestGridWorld(EnvConformanceSuite):
    env_class = "eb_example.env:GridWorld"
    env_params = {"resolution": 100}
    expect_subsets = {"base": 6, "far": 6}
    max_env_steps = 12
