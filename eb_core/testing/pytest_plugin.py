"""Pytest plugin (entry point ``pytest11``): fixtures for testing EmbodiedBench plugins."""

from __future__ import annotations

import pytest


@pytest.fixture
def eb_registry():
    """A fresh registry with every installed plugin (no global state to restore)."""
    from eb_core.plugins import Registry

    return Registry.create()
