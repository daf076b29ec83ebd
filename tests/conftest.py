import os
import sys
from pathlib import Path

# The fixture plugin module is importable by name (worker processes re-import it).
FIXTURES = Path(__file__).parent / "eb_core"
sys.path.insert(0, str(FIXTURES))
os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(FIXTURES), os.environ.get("PYTHONPATH", "")]))
os.environ.setdefault("MUJOCO_GL", "egl")
