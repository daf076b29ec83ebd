"""N EmbodiedBench environments stepped together on worker processes.

:func:`make_vector_env` builds a Gymnasium ``AsyncVectorEnv`` (one worker process per environment) with
``shared_memory=False``: the prompt and text observations are ``Text`` spaces, which Gymnasium's shared memory
would corrupt. Observations come back batched (a tuple of prompts, a tuple of image sequences, a stacked image
array in raw mode). :class:`~eb_core.gym.env.EBEnv` never raises from ``step``: a world that crashes ends its
episode with ``truncated=True`` and ``info["error"]``, and is rebuilt on the autoreset that follows, so one
broken environment never takes the trainer down.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gymnasium
from gymnasium.vector import AsyncVectorEnv, AutoresetMode

__all__ = ["make_vector_env"]


def _resolve(world: str) -> str:
    """Accept ``EB/Navigation-v0``, ``eb_core.gym:EB/Navigation-v0`` or the env name ``navigation``."""
    from eb_core.gym import gym_id, registered_ids

    if ":" in world:
        world = world.split(":", 1)[1]
    if world in registered_ids():
        return world
    gid = gym_id(world)
    if gid in registered_ids():
        return gid
    raise ValueError(f"unknown world {world!r}; registered: {', '.join(registered_ids())} "
                     f"(is its plugin installed? `eb list` shows the worlds)")


def make_vector_env(world: str, num_envs: int, *, context: str | None = "forkserver",
                    autoreset_mode: str = "NextStep", env_fns: list[Callable[[], gymnasium.Env]] | None = None,
                    **kwargs: Any) -> AsyncVectorEnv:
    """``num_envs`` copies of ``world`` (an id or env name) with ``kwargs`` for :class:`EBEnv`, each in its own
    worker process. ``autoreset_mode``: Gymnasium's ``NextStep`` (default), ``SameStep`` or ``Disabled``.

    ``context="forkserver"`` (default): workers fork from a clean server process that has imported the core,
    never from a process holding an OpenGL context (a forked EGL context hangs the worker's first render).
    As with any non-fork start method, a script must build the vector env under ``if __name__ == "__main__":``.
    ``context="fork"`` is faster to start and safe when this process has not rendered yet."""
    import multiprocessing

    if context == "forkserver":
        multiprocessing.get_context("forkserver").set_forkserver_preload(["eb_core.gym"])
    if num_envs < 1:
        raise ValueError(f"num_envs must be >= 1, got {num_envs}")
    if env_fns is None:
        gid = _resolve(world)

        def make() -> gymnasium.Env:
            import eb_core.gym  # noqa: F401  (registers the ids in a spawned worker)

            return gymnasium.make(gid, **kwargs)

        env_fns = [make] * num_envs
    return AsyncVectorEnv(env_fns, shared_memory=False, context=context, autoreset_mode=AutoresetMode(autoreset_mode))
