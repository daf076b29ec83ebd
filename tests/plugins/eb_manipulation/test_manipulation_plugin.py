"""Registration, the env yaml, the light entry-point module and the benchmark hook."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import yaml

import eb_manipulation
from eb_core.config import EnvConfig


def test_registered_with_subsets_and_generator(eb_registry) -> None:
    spec = eb_registry.get("env", "manipulation")
    assert spec.entry_point == "eb_manipulation.env:ManipulationEnv"
    assert spec.task_generator == "eb_manipulation.generate:generate"
    assert spec.subsets == {"base": 48, "common_sense": 48, "complex": 48, "spatial": 48, "visual": 36}


def test_plugin_module_imports_nothing_heavy() -> None:
    code = "import sys, eb_manipulation.plugin; print('mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_env_yaml_has_the_papers_rules() -> None:
    raw = yaml.safe_load((Path(eb_manipulation.__file__).parent / "conf" / "env" / "manipulation.yaml").read_text())
    cfg = EnvConfig.model_validate(raw)
    assert (cfg.name, cfg.max_steps, cfg.max_invalid_actions, cfg.replan_on_failure, cfg.empty_plan_ends,
            cfg.default_n_shot) == ("manipulation", 15, None, False, True, 4)
    from eb_manipulation.env import ManipulationParams

    ManipulationParams.model_validate(cfg.params)


def test_panda_comes_from_the_installed_gymnasium_robotics() -> None:
    from eb_manipulation.robot import load_panda_parts, panda_asset_dir

    assert "gymnasium_robotics" in str(panda_asset_dir())
    parts = load_panda_parts()
    assert "panda0_link7" in parts.body and 'name="tcp"' in parts.body and len(parts.mesh_files) >= 10
    root = panda_asset_dir().resolve()
    for name, path in parts.mesh_files.items():  # read in place from the package, never copied
        assert Path(path).is_file() and Path(path).is_relative_to(root), (name, path)
        assert f'file="{path}"' in parts.assets


def test_bench_step_times_shape() -> None:
    from eb_manipulation.bench import step_times

    out = step_times(2, resolution=96)
    for key in ("render", "multi_view", "no_render"):
        assert out[key]["median_s"] > 0 and out[key]["n"] >= 2
