"""``eb audit`` as a user types it: the fixture corridor (a broken task set) and the real navigation world."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

FIXTURE_DIR = Path(__file__).parent


def eb(*args: str, plugins: bool = False, timeout: int = 300) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(FIXTURE_DIR))
    if plugins:  # the installed world plugins, as a user has them
        env.pop("EB_PLUGINS", None)
        env.pop("EB_DISABLE_PLUGIN_AUTOLOAD", None)
    else:
        env.update(EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1")
    return subprocess.run([sys.executable, "-m", "eb_core.cli", "audit", *args], capture_output=True, text=True,
                          env=env, timeout=timeout)


def error_line(result: subprocess.CompletedProcess) -> str:
    assert result.returncode == 2, (result.stdout, result.stderr)
    lines = [ln for ln in result.stderr.splitlines() if ln.startswith("eb: error: ")]
    assert len(lines) == 1, result.stderr
    return lines[0]


def test_a_broken_task_set_exits_non_zero_and_names_the_failing_tasks():
    # The corridor repeats its instructions and "always step right" reaches every goal.
    r = eb("env=corridor")
    assert r.returncode == 1, (r.stdout, r.stderr)
    out = r.stdout
    assert "eb audit: corridor, 10 tasks (random-action probes: every task)" in out
    rows: dict[str, str] = {}  # the summary table's first line per probe
    for ln in out.splitlines():
        if ln and ln.split()[0].startswith(("instruction_", "blind_", "closed_", "noise_", "parallel_")):
            rows.setdefault(ln.split()[0], ln)
    assert "FAIL" in rows["instruction_unique"] and "near-3" in rows["instruction_unique"]
    assert "FAIL" in rows["blind_policies"] and "near-0" in rows["blind_policies"]
    assert "pass" in rows["closed_loop_oracle"] and "skip" in rows["parallel_forms"]
    assert "always 'step right'" in out and "100.0 %" in out
    assert "audit FAILED: instruction_unique" in out


def test_probe_selection_and_exit_zero_when_it_passes():
    r = eb("env=corridor", "--probe", "closed_loop_oracle", "--quick")
    assert r.returncode == 0, (r.stdout, r.stderr)
    assert "closed_loop_oracle" in r.stdout and "blind_policies" not in r.stdout
    assert "100.0 % (10/10)" in r.stdout and "audit passed (1/1 probes pass)" in r.stdout


def test_bad_input_is_one_clear_line(tmp_path):
    assert "audit needs env=NAME" in error_line(eb())
    line = error_line(eb("env=corridor", "--probe", "nope"))
    assert "unknown probe 'nope'" in line and "closed_loop_oracle" in line
    line = error_line(eb("env=corridor", f"task_file={tmp_path / 'missing.json'}"))
    assert "does not exist" in line and "eb tasks generate env=corridor" in line
    assert "unknown option '--fast'" in error_line(eb("env=corridor", "--fast"))
    assert "unknown env 'corridoor'" in error_line(eb("env=corridoor"))


def test_navigation_quick_audit_runs_end_to_end():
    pytest.importorskip("eb_navigation")
    r = eb("env=navigation", "--quick", "subset=base", plugins=True, timeout=600)
    assert r.returncode in (0, 1), (r.stdout, r.stderr)
    out = r.stdout
    assert "eb audit: navigation, 60 tasks" in out
    for probe in ("instruction_unique", "instruction_grammar", "blind_policies", "closed_loop_oracle", "noise_curve"):
        assert f"\n{probe}" in out
    assert "skipped (--quick)" in out and "max_steps=20" in out  # the env yaml's budget
    curve = out[out.index("noise_curve:"):].splitlines()
    assert curve[1].split() == ["subset", "p=0", "p=0.1", "p=0.2", "p=0.3", "p=0.5", "p=0.7", "p=0.9", "p=1", "p50"]
    assert curve[3].split()[0] == "base"
    mix = re.search(r"(\d+) turn, then forward", out)  # navigation-like: turn once, then forward
    assert mix and int(mix.group(1)) >= 2
