"""Registration, the env yaml and the CLI entry points (``eb list``, ``eb tasks generate``)."""

from __future__ import annotations

import subprocess
import sys
import sysconfig
from pathlib import Path

import eb_navigation
import yaml

from eb_core.config import EnvConfig


def test_registered_with_subsets_and_generator(eb_registry) -> None:
    spec = eb_registry.get("env", "navigation")
    assert spec.entry_point == "eb_navigation.env:NavigationEnv"
    assert spec.task_generator == "eb_navigation.generate:generate"
    assert spec.subsets == {"base": 60, "common_sense": 60, "complex_instruction": 60, "visual_appearance": 60,
                            "long_horizon": 60}


def test_plugin_module_imports_nothing_heavy() -> None:
    code = "import sys, eb_navigation.plugin; print('mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_env_yaml_has_the_papers_rules() -> None:
    raw = yaml.safe_load((Path(eb_navigation.__file__).parent / "conf" / "env" / "navigation.yaml").read_text())
    cfg = EnvConfig.model_validate(raw)
    assert (cfg.name, cfg.max_steps, cfg.max_invalid_actions, cfg.replan_on_failure, cfg.empty_plan_ends,
            cfg.default_n_shot) == ("navigation", 20, None, True, False, 3)
    from eb_navigation.env import NavigationParams

    NavigationParams.model_validate(cfg.params)


def test_eb_tasks_generate_cli(tmp_path: Path) -> None:
    # The console script installed beside this interpreter, so the test holds when pytest runs as
    # `venv/bin/python -m pytest` without the venv on PATH.
    eb = Path(sysconfig.get_path("scripts")) / "eb"
    assert eb.is_file(), f"the `eb` console script is not installed in {eb.parent}"
    out = tmp_path / "cli.json"
    proc = subprocess.run([str(eb), "tasks", "generate", "env=navigation", "seed=3", "scenes=1", "min_distance=2.5",
                           f"out={out}"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "wrote 5 tasks" in proc.stdout and out.is_file()
