"""Packaging: the Hydra config ships inside the core's wheel, and a third-party plugin installs by pip."""

import os
import site
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]


def test_wheel_ships_conf_and_the_hydra_searchpath_plugin(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                        "-w", str(tmp_path), str(ROOT)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    wheel = next(tmp_path.glob("embodiedbench-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    for needed in ("eb_conf/config.yaml", "eb_conf/planner/vlm.yaml", "eb_conf/ablation/none.yaml",
                   "eb_conf/ablation/no_feedback.yaml", "hydra_plugins/eb_searchpath/__init__.py",
                   "eb_core/cli/__init__.py", "eb_core/cli/run.py", "eb_core/compose.py", "eb_core/testing/suites.py"):
        assert needed in names, needed
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    text = zipfile.ZipFile(wheel).read(entry_points).decode()
    assert "eb = eb_core.cli:main" in text and "pytest11" in text


def _running_site_dirs() -> list[str]:
    """The site-packages of the interpreter running the tests (a user's venv, or the base interpreter)."""
    dirs = [p for p in site.getsitepackages() if os.path.isdir(p)]
    user = site.getusersitepackages()
    if site.ENABLE_USER_SITE and os.path.isdir(user):
        dirs.append(user)
    return dirs


@pytest.fixture(scope="module")
def plugin_venv(tmp_path_factory):
    """A fresh venv layered on the packages of the interpreter running the tests, with the example plugin
    really pip-installed into it.

    ``system_site_packages=True`` would expose the *base* interpreter's packages, not those of the venv the
    tests run in; instead a ``.pth`` file adds the running interpreter's site directories (processing their
    own ``.pth`` files, so editable installs of this project resolve) behind the new venv's own.
    """
    d = tmp_path_factory.mktemp("venv")
    venv.EnvBuilder(system_site_packages=False, with_pip=False).create(d)
    py = d / "bin" / "python"
    own = subprocess.run([str(py), "-c", "import site; print(site.getsitepackages()[0])"],
                         capture_output=True, text=True, check=True).stdout.strip()
    lines = [f"import site; site.addsitedir({p!r})" for p in _running_site_dirs()]
    (Path(own) / "zz_eb_parent_env.pth").write_text("\n".join(lines) + "\n")
    r = subprocess.run([str(py), "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
                        str(ROOT / "examples" / "eb-example-plugin")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return py


def _clean_env():
    env = dict(os.environ)
    for k in ("EB_PLUGINS", "EB_DISABLE_PLUGIN_AUTOLOAD", "PYTHONPATH"):
        env.pop(k, None)
    return env


def test_installed_third_party_plugin_appears_in_eb_list(plugin_venv, tmp_path):
    r = subprocess.run([str(plugin_venv), "-m", "eb_core", "list"], capture_output=True, text=True,
                       env=_clean_env(), cwd=tmp_path, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "gridworld" in r.stdout and "example" in r.stdout and "base (6)" in r.stdout


def test_installed_third_party_plugin_runs(plugin_venv, tmp_path):
    r = subprocess.run([str(plugin_venv), "-m", "eb_core", "run", "env=gridworld", "model=oracle",
                        "runner.quiet=true", f"hydra.run.dir={tmp_path}/run"],
                       capture_output=True, text=True, env=_clean_env(), cwd=tmp_path, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "success rate: 100.0% (12 of 12 episodes succeeded)" in r.stdout
    assert "eb-example-plugin 0.1.0" in (tmp_path / "run" / "plugins.json").read_text()


def test_installed_plugin_passes_its_own_conformance_tests(plugin_venv, tmp_path):
    r = subprocess.run([str(plugin_venv), "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        str(ROOT / "examples" / "eb-example-plugin" / "tests")],
                       capture_output=True, text=True, env=_clean_env(), cwd=tmp_path, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "9 passed" in r.stdout
