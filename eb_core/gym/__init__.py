"""EmbodiedBench worlds as Gymnasium environments, for supervised fine-tuning and online RL.

``import eb_core.gym`` registers one id per installed world plugin: ``EB/Navigation-v0``, ``EB/ALFRED-v0``,
``EB/Habitat-v0``, ``EB/Manipulation-v0`` and ``EB/<Name>-v0`` for a third party's world ``<name>``::

    import gymnasium, eb_core.gym
    env = gymnasium.make("EB/Navigation-v0", split="test", obs_mode="prompt", reward="progress")
    env = gymnasium.make("eb_core.gym:EB/Habitat-v0", split="train", obs_mode="raw")

Needs the ``gym`` extra (``pip install "embodiedbench[gym]"``); ``eb list`` and ``eb run`` never import it.
docs/training.md describes observations, actions, rewards, splits and the vector env.
"""

from __future__ import annotations

import gymnasium

from eb_core.gym.env import CHARSET, IMAGE_PLACEHOLDER, EBEnv, request_observation
from eb_core.gym.rewards import PRESETS, TERMS, reward_weights
from eb_core.gym.vector import EBVectorEnv, make_vector_env

__all__ = ["CHARSET", "IMAGE_PLACEHOLDER", "PRESETS", "TERMS", "EBEnv", "EBVectorEnv", "gym_id", "make_vector_env",
           "register_worlds", "registered_ids", "request_observation", "reward_weights"]

#: How the four benchmark worlds are spelled in their ids (others: the env name with a capital letter).
DISPLAY_NAMES = {"alfred": "ALFRED", "habitat": "Habitat", "navigation": "Navigation", "manipulation": "Manipulation"}


def gym_id(world: str) -> str:
    """The Gymnasium id of a world: ``navigation`` -> ``EB/Navigation-v0``."""
    name = DISPLAY_NAMES.get(world, world[:1].upper() + world[1:])
    return f"EB/{name.replace('_', '-')}-v0" if "_" in name else f"EB/{name}-v0"


def register_worlds(registry: object = None) -> dict[str, str]:
    """Register every installed world (or those of ``registry``); returns ``{gym id: world name}``."""
    from eb_core.plugins import Registry

    reg = registry if registry is not None else Registry.create()
    out: dict[str, str] = {}
    for name in reg.envs:  # type: ignore[attr-defined]
        gid = gym_id(name)
        if gid not in gymnasium.registry:
            gymnasium.register(gid, entry_point="eb_core.gym.env:EBEnv", kwargs={"world": name},
                               disable_env_checker=True)
        out[gid] = name
    _REGISTERED.update(out)
    return out


_REGISTERED: dict[str, str] = {}
register_worlds()


def registered_ids() -> dict[str, str]:
    """``{gym id: world name}`` registered so far (at import, and by later :func:`register_worlds` calls)."""
    return dict(_REGISTERED)
