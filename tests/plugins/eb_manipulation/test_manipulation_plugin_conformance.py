"""The world's registration passes the core's plugin conformance suite."""

from eb_core.testing import PluginConformanceSuite


class TestPluginConformance(PluginConformanceSuite):
    plugin_module = "eb_manipulation.plugin"
    env_name = "manipulation"
