"""EB-Habitat for EmbodiedBench: language rearrangement in embedded MuJoCo apartments.

The env is :class:`eb_habitat.env.HabitatEnv` (registered as ``habitat``); the symbolic world, goals, expert
and task files are usable without MuJoCo.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
