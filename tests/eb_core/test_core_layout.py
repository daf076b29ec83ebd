"""The core's structure: the planner contract, no runner <-> executor cycle, module sizes, the documented fields."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from eb_core.config import EnvConfig, PlannerConfig
from eb_core.env import Observation, PromptParts, StepResult, Task
from eb_core.planner import Planner, VLMPlanner

ROOT = Path(__file__).resolve().parents[2]
CORE = ROOT / "eb_core"


def test_the_builtin_planner_meets_the_planner_protocol():
    env_cfg = EnvConfig(name="corridor", max_steps=5)
    assert isinstance(VLMPlanner(PlannerConfig(name="vlm"), env_cfg), Planner)

    class Half:  # no parse, no record_* methods
        last_primary_png = None

        def reset(self, task, parts, space, obs=None): ...

        def build_request(self, obs, seed=None): ...

    assert not isinstance(Half(), Planner)


def _imports(path: Path) -> set[str]:
    mods: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            mods.add(node.module)
        elif isinstance(node, ast.Import):
            mods.update(a.name for a in node.names)
    return mods


@pytest.mark.parametrize("module", ["ray_executor.py", "workers.py", "components.py", "inflight.py", "verify.py"])
def test_executors_and_shared_pieces_do_not_import_the_runner(module):
    assert "eb_core.runner" not in _imports(CORE / module)


OWNED = ["records.py", "episode.py", "events.py", "planner.py", "model.py", "parsing.py", "ray_executor.py",
         "inflight.py", "export.py", "html.py", "gym/env.py", "gym/vector.py", "gym/_workers.py", "verify.py",
         "components.py", "workers.py", "manifest.py", "runner.py"]


@pytest.mark.parametrize("module", OWNED)
def test_core_modules_stay_under_600_lines(module):
    assert len((CORE / module).read_text(encoding="utf-8").splitlines()) <= 600


def _section_rows(doc: str, model: str) -> set[str]:
    """Field names in the first column of the table that follows ``**`Model`**`` in the doc."""
    part = doc.split(f"**`{model}`**", 1)[1].split("\n\n**", 1)[0]
    return set(re.findall(r"^\| `([a-z_]+)` \|", part, flags=re.M))


@pytest.mark.parametrize("model", [Task, Observation, StepResult, PromptParts], ids=lambda m: m.__name__)
def test_writing_plugins_lists_every_field(model):
    doc = (ROOT / "docs" / "writing_plugins.md").read_text(encoding="utf-8")
    assert _section_rows(doc, model.__name__) == set(model.model_fields)
