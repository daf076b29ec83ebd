from __future__ import annotations

import pytest

import fixture_plugin
from eb_core.plugins import Registry, get_plugin_manager


@pytest.fixture(autouse=True)
def _only_fixture_plugins(monkeypatch):
    """Core tests see the built-ins and the fixture plugin only, whatever else is installed."""
    monkeypatch.setenv("EB_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setenv("EB_PLUGINS", "fixture_plugin")


@pytest.fixture
def registry() -> Registry:
    return Registry(get_plugin_manager(plugins=[fixture_plugin]))
