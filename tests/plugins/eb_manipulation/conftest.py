"""Shared fixtures of the EB-Manipulation tests: one geometry-mode env and the shipped tasks per test module."""

from __future__ import annotations

import pytest

from eb_manipulation.env import ManipulationEnv


@pytest.fixture(scope="module")
def env():
    e = ManipulationEnv(render=False)
    yield e
    e.close()


@pytest.fixture(scope="module")
def tasks(env):
    return {t.id: t for t in env.load_tasks()}
