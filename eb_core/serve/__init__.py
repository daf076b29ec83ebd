"""The worlds as a service for trainers: ``eb serve`` (an HTTP server over a pool of environments) and
:class:`~eb_core.serve.client.RemoteVectorEnv` (a Gymnasium vector env over it). See docs/training.md.

The server side needs the ``[serve]`` extra (FastAPI, uvicorn); the client needs only gymnasium, numpy, pillow and
httpx.
"""

from __future__ import annotations

from typing import Any

__all__ = ["RemoteVectorEnv", "SCHEMA"]

from eb_core.serve.schema import SCHEMA


def __getattr__(name: str) -> Any:  # the client without importing the server's stack
    if name == "RemoteVectorEnv":
        from eb_core.serve.client import RemoteVectorEnv

        return RemoteVectorEnv
    raise AttributeError(name)
