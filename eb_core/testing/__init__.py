"""Test helpers for plugin authors: conformance suites and ``check_env``.

Subclass the suites in your plugin's tests::

    from eb_core.testing import EnvConformanceSuite

    class TestMyEnv(EnvConformanceSuite):
        env_class = "my_plugin.env:MyEnv"   # or the class itself
        env_params = {}                     # keyword arguments for the constructor

The pytest plugin ``eb_core.testing.pytest_plugin`` (registered automatically) adds fixtures.
"""

from eb_core.testing.check import check_env
from eb_core.testing.suites import EnvConformanceSuite, ModelBackendConformanceSuite, PluginConformanceSuite

__all__ = ["EnvConformanceSuite", "ModelBackendConformanceSuite", "PluginConformanceSuite", "check_env"]
