"""A native crash or a hang in one test fails that test, and the suite still runs to its end.

A small suite is run by a real ``pytest -n 2 --dist loadfile`` (this suite's own setting) in a child process with
tests/xdist_crash_safe.py: one test segfaults (as llama.cpp's AMX kernels did on this kind of Xeon), in the middle
of its file; with plain xdist 3.8.0 the controller re-runs it on every replacement worker and then waits forever.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

TESTS_DIR = Path(__file__).resolve().parents[2]  # tests/, where xdist_crash_safe.py lives

SUITE = {
    "test_a.py": """
import ctypes, time
def test_a_before(): time.sleep(0.2)
def test_a_dies():
    time.sleep(3)  # the other worker has run out of work by now: the re-queued rest of this file must still run
    {death}
def test_a_after(): time.sleep(0.2)
""",
    "test_b.py": "def test_b1(): pass\ndef test_b2(): pass\n",
    "test_c.py": "def test_c1(): pass\n",
}


def _run_suite(tmp_path: Path, death: str, *extra: str) -> tuple[subprocess.CompletedProcess, dict[str, str]]:
    for name, text in SUITE.items():
        (tmp_path / name).write_text(text.replace("{death}", death))
    (tmp_path / "pytest.ini").write_text("[pytest]\n")  # not this repository's addopts
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(TESTS_DIR), os.environ.get("PYTHONPATH")])))
    r = subprocess.run([sys.executable, "-m", "pytest", "-n", "2", "--dist", "loadfile", "-p", "xdist_crash_safe",
                        "-p", "no:cacheprovider", "-rA", *extra, str(tmp_path)],
                       capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600)
    outcomes = dict((m.group(2), m.group(1)) for m in re.finditer(r"^(PASSED|FAILED) (\S+)", r.stdout, re.M))
    return r, outcomes


def test_a_segfault_fails_that_test_and_the_rest_of_its_file_still_runs(tmp_path):
    r, outcomes = _run_suite(tmp_path, "ctypes.string_at(0)")
    assert r.returncode == 1, r.stdout[-3000:]
    assert "worker 'gw0' crashed while running 'test_a.py::test_a_dies'" in r.stdout \
        or "worker 'gw1' crashed while running 'test_a.py::test_a_dies'" in r.stdout, r.stdout[-3000:]
    assert outcomes == {"test_a.py::test_a_dies": "FAILED", "test_a.py::test_a_before": "PASSED",
                        "test_a.py::test_a_after": "PASSED", "test_b.py::test_b1": "PASSED",
                        "test_b.py::test_b2": "PASSED", "test_c.py::test_c1": "PASSED"}, r.stdout[-3000:]
    assert re.search(r"=+ 1 failed, 5 passed in", r.stdout), r.stdout[-1000:]  # never re-run on a replacement


def test_a_hang_is_ended_by_the_timeout_and_the_rest_still_runs(tmp_path):
    pytest.importorskip("pytest_timeout", reason="pytest-timeout is not installed: pip install -r "
                        "requirements-test.txt")
    r, outcomes = _run_suite(tmp_path, "time.sleep(3600)", "--timeout", "20", "-o", "timeout_method=thread")
    assert r.returncode == 1, r.stdout[-3000:]
    assert "crashed while running 'test_a.py::test_a_dies'" in r.stdout, r.stdout[-3000:]  # the timeout ended it
    assert [k for k, v in outcomes.items() if v != "PASSED"] == ["test_a.py::test_a_dies"], r.stdout[-3000:]
    assert len(outcomes) == 6 and re.search(r"=+ 1 failed, 5 passed in", r.stdout), r.stdout[-1000:]
