"""Gymnasium spaces as JSON and back, so a client in another venv rebuilds the server's spaces exactly."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces

__all__ = ["build", "describe"]


def describe(space: spaces.Space[Any]) -> dict[str, Any]:
    """A JSON description of the spaces EmbodiedBench uses (Dict, Sequence, Box, Text, Discrete, MultiDiscrete)."""
    from eb_core.gym import CHARSET

    if isinstance(space, spaces.Dict):
        return {"type": "Dict", "spaces": {k: describe(v) for k, v in space.spaces.items()}}
    if isinstance(space, spaces.Sequence):
        return {"type": "Sequence", "space": describe(space.feature_space)}
    if isinstance(space, spaces.Box):
        return {"type": "Box", "shape": list(space.shape), "dtype": str(space.dtype),
                "low": float(np.min(space.low)), "high": float(np.max(space.high))}
    if isinstance(space, spaces.Text):
        charset = "".join(sorted(space.character_set))
        return {"type": "Text", "min_length": space.min_length, "max_length": space.max_length,
                "charset": "eb" if set(charset) == set(CHARSET) else charset}
    if isinstance(space, spaces.Discrete):
        return {"type": "Discrete", "n": int(space.n), "start": int(space.start)}
    if isinstance(space, spaces.MultiDiscrete):
        return {"type": "MultiDiscrete", "nvec": space.nvec.tolist(), "start": space.start.tolist()}
    raise TypeError(f"cannot describe a {type(space).__name__} space")


def build(desc: dict[str, Any]) -> spaces.Space[Any]:
    """The space :func:`describe` described."""
    from eb_core.gym import CHARSET

    kind = desc.get("type")
    if kind == "Dict":
        return spaces.Dict({k: build(v) for k, v in desc["spaces"].items()})
    if kind == "Sequence":
        return spaces.Sequence(build(desc["space"]))
    if kind == "Box":
        return spaces.Box(desc["low"], desc["high"], shape=tuple(desc["shape"]), dtype=np.dtype(desc["dtype"]))
    if kind == "Text":
        charset = CHARSET if desc["charset"] == "eb" else desc["charset"]
        return spaces.Text(max_length=desc["max_length"], min_length=desc["min_length"], charset=charset)
    if kind == "Discrete":
        return spaces.Discrete(desc["n"], start=desc.get("start", 0))
    if kind == "MultiDiscrete":
        return spaces.MultiDiscrete(np.array(desc["nvec"]), start=np.array(desc["start"]))
    raise ValueError(f"unknown space type {kind!r} in a space description")
