"""EB-Navigation for EmbodiedBench: find and approach a named object in a furnished MuJoCo room.

Heavy modules (MuJoCo) are imported only by :mod:`eb_navigation.env` when a run selects the env.
"""

__version__ = "0.2.0"
__all__ = ["__version__"]
