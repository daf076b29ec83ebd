"""benchmarks/faults.py: its short version runs every fault for real and meets every goal."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_fault_table_quick_meets_every_goal():
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "faults.py"), "--quick"], capture_output=True,
                       text=True, timeout=900, cwd=ROOT)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    rows = [ln for ln in r.stdout.splitlines() if ln.startswith("[")]
    assert len(rows) == 8 and all(ln.startswith("[ok]") for ln in rows), "\n".join(rows)
    assert "0 lost, 0 doubled" in r.stdout and "0 crashes" in r.stdout
