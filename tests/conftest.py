import os
import sys
from pathlib import Path

# The fixture plugin module is importable by name (worker processes re-import it).
FIXTURES = Path(__file__).parent / "eb_core"
sys.path.insert(0, str(FIXTURES))
os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(FIXTURES), os.environ.get("PYTHONPATH", "")]))
os.environ.setdefault("MUJOCO_GL", "egl")

# A worker that dies in a test (a native crash, or pytest-timeout ending a hung test) fails that test, and the rest
# of the suite still runs and ends: see xdist_crash_safe.py (this directory is on sys.path, as conftest's own).
from xdist_crash_safe import pytest_xdist_make_scheduler  # noqa: F401
