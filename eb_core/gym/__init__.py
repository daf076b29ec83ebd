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

from eb_core.gym.env import CHARSET, IMAGE_PLACEHOLDER, EBEnv, request_observation
from eb_core.gym.ids import gym_id, register_worlds, registered_ids
from eb_core.gym.rewards import PRESETS, TERMS, reward_weights
from eb_core.gym.vector import EBVectorEnv, make_vector_env

__all__ = ["CHARSET", "IMAGE_PLACEHOLDER", "PRESETS", "TERMS", "EBEnv", "EBVectorEnv", "gym_id", "make_vector_env",
           "register_worlds", "registered_ids", "request_observation", "reward_weights"]

register_worlds()
