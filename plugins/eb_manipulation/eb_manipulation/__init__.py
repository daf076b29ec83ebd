"""EB-Manipulation for EmbodiedBench: a Franka Panda on a wooden table in MuJoCo, 228 tasks in 5 subsets.

The env class lives in :mod:`eb_manipulation.env` (imported lazily by the core); this package's top level
imports nothing heavy.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
