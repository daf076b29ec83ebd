"""Pytest plugin (entry point ``pytest11``): fixtures for testing EmbodiedBench plugins."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from eb_core.plugins import Registry


@pytest.fixture
def eb_registry() -> Registry:
    """A fresh registry with every installed plugin (no global state to restore)."""
    from eb_core.plugins import Registry

    return Registry.create()
