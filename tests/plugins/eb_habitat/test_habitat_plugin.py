"""The plugin registers the env and its config without importing MuJoCo."""

from __future__ import annotations

import subprocess
import sys

import eb_habitat.plugin
from eb_core.plugins import Registry, get_plugin_manager


def test_registered_with_subsets_and_generator() -> None:
    registry = Registry(get_plugin_manager(load_entrypoints=False, plugins=[eb_habitat.plugin]))
    spec = registry.get("env", "habitat")
    assert spec.entry_point == "eb_habitat.env:HabitatEnv"
    assert sum(spec.subsets.values()) == 300
    assert spec.task_generator == "eb_habitat.make:generate"
    assert "pkg://eb_habitat.conf" in registry.config_searchpath()
    assert spec.load().name == "habitat"


def test_plugin_and_env_module_do_not_import_mujoco() -> None:
    code = ("import sys, eb_habitat.plugin, eb_habitat.env; "
            "from eb_habitat.env import HabitatEnv; e = HabitatEnv(render=False); "
            "e.reset(HabitatEnv.load_tasks()[0], 0); print('mujoco' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_env_yaml_matches_the_paper() -> None:
    from pathlib import Path

    import yaml

    cfg = yaml.safe_load((Path(eb_habitat.plugin.__file__).parent / "conf" / "env" / "habitat.yaml").read_text())
    assert cfg["name"] == "habitat"
    assert (cfg["max_steps"], cfg["max_invalid_actions"], cfg["default_n_shot"]) == (30, 10, 10)
    assert cfg["replan_on_failure"] is True and cfg["empty_plan_ends"] is True
