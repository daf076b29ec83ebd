"""Every script in benchmarks/ runs in its ``--quick`` mode and prints its table (no figure is checked: timings
belong to the benchmarks, not to tests). ``faults.py`` has its own test (test_faults_benchmark.py)."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def quick(script: str, *args: str) -> str:
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), "--quick", *args], capture_output=True,
                       text=True, timeout=900, cwd=ROOT, env=env)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert not re.search(r"\berror\b", r.stdout.lower()), r.stdout[-3000:]  # "output errors 0" is a column
    return r.stdout


def test_every_benchmark_has_a_quick_test():
    scripts = {p.stem for p in (ROOT / "benchmarks").glob("*.py")}
    tested = {name.removeprefix("test_").removesuffix("_quick") for name in globals() if name.startswith("test_")}
    assert scripts - {"faults"} <= tested, sorted(scripts - tested)


def test_concurrency_quick():
    out = quick("concurrency.py")
    rows = [ln.split() for ln in out.splitlines() if ln.strip()[:1].isdigit() and "|" in ln]
    assert "end-to-end s" in out and [r[0] for r in rows] == ["1", "2"]


def test_env_step_quick():
    out = quick("env_step.py")
    assert "step ms" in out and any(ln.startswith("navigation ") for ln in out.splitlines())


def test_env_step_quick_alfred():
    """The ALFRED row (it once failed with AttributeError: 'Renderer' object has no attribute '_gl_context')."""
    out = quick("env_step.py", "--envs", "alfred")
    [row] = [ln for ln in out.splitlines() if ln.startswith("alfred ")]
    assert len(row.split()) == 6, row


def test_env_step_resets_per_param_value_on_the_hard_set():
    """``--resets --taskset hard --param k=a,b`` resets the hard set's tasks once per value, in one run, and prints
    each value's rows and its ratio to the first; a malformed --param is one error line, not a traceback."""
    out = quick("env_step.py", "--resets", "--n", "1", "--envs", "manipulation", "--taskset", "hard",
                "--param", "tag_layout=corner,clear")
    assert "taskset=hard" in out
    assert "manipulation tag_layout=corner" in out and "manipulation tag_layout=clear" in out
    assert len(re.findall(r"test reset CPU time x[0-9.]+ of the first value's", out)) == 2
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "env_step.py"), "--resets", "--param", "oops"],
                       capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert r.returncode != 0 and "expected KEY=VALUE" in r.stderr and "Traceback" not in r.stderr


def test_expert_labels_quick():
    out = quick("expert_labels.py")
    assert "labels off:" in out and "labels on :" in out and "cost ratio on/off" in out


def test_gym_throughput_quick():
    out = quick("gym_throughput.py")
    assert "navigation N=1 over 1 processes" in out and "navigation N=2 over 1 processes" in out
    assert "steps/s" in out


def test_inflight_quick():
    out = quick("inflight.py")
    assert "in flight" in out and any(ln.split()[:1] == ["2"] for ln in out.splitlines())


def test_overhead_quick():
    out = quick("overhead.py")
    assert "raw env loop:" in out and "full pipeline:" in out and "ratio:" in out


@pytest.mark.skipif(importlib.util.find_spec("llama_cpp") is None,
                    reason="needs llama-cpp-python (pip install -r requirements-test.txt)")
def test_real_model_quick():
    out = quick("real_model.py")
    assert "model:" in out and "server  auto" in out and "settled" in out


@pytest.mark.skipif(importlib.util.find_spec("fastapi") is None, reason="needs the [serve] extra (fastapi, uvicorn)")
def test_serve_throughput_quick():
    out = quick("serve_throughput.py")
    assert "in-process" in out and "over HTTP" in out and "ratio (HTTP / in-process):" in out


def test_verify_quick():
    out = quick("verify.py")
    assert "verify s" in out and "10 episode(s) replayed, verified" in out
