"""``feedback_policies`` on the fixed classic task sets warns (a documented shortcut of the paper's tasks); the
same tasks given as a task file of one's own are held to the bar and fail."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import eb_habitat


def _audit(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "eb_core", "audit", "env=habitat", "--quick", "--probe",
                           "feedback_policies", *args], capture_output=True, text=True, timeout=900)


def test_classic_warns_and_an_own_copy_fails(tmp_path):
    shipped = _audit()
    assert shipped.returncode == 0, shipped.stdout[-2000:] + shipped.stderr[-2000:]
    assert "warning (feedback_policies): the classic task set is fixed" in shipped.stdout
    copy = tmp_path / "tasks"
    shutil.copytree(Path(eb_habitat.__file__).parent / "tasks", copy, ignore=shutil.ignore_patterns("hard"))
    own = _audit(f"env.params.task_dir={copy}")
    assert own.returncode == 1 and "audit FAILED: feedback_policies" in own.stdout
