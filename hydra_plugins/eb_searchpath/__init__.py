"""Hydra search-path plugin: adds every EmbodiedBench plugin's config options (``conf/env/*.yaml``...)."""

from __future__ import annotations

from hydra.core.config_search_path import ConfigSearchPath
from hydra.plugins.search_path_plugin import SearchPathPlugin


class EmbodiedBenchSearchPathPlugin(SearchPathPlugin):
    def manipulate_search_path(self, search_path: ConfigSearchPath) -> None:
        # Only for our own app: other Hydra apps on the machine must not see (or pay for) our plugins.
        primary = [e for e in search_path.get_path() if e.provider == "main"]
        if not any(str(e.path).startswith("pkg://eb_conf") for e in primary):
            return
        from eb_core.plugins import Registry

        present = {str(e.path) for e in search_path.get_path()}
        for path in Registry.create().config_searchpath():
            if path not in present:
                search_path.append(provider="eb-plugin", path=path)
                present.add(path)


def ensure_registered() -> None:
    """Register the plugin with Hydra explicitly.

    Hydra discovers plugins by listing the ``hydra_plugins`` namespace, which setuptools' editable
    installs hide behind an import hook; registering by hand works for every kind of install.
    """
    from hydra.core.plugins import Plugins

    plugins = Plugins.instance()
    if EmbodiedBenchSearchPathPlugin not in plugins.discover(SearchPathPlugin):
        plugins.register(EmbodiedBenchSearchPathPlugin)
