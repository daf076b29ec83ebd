"""Gymnasium ids of the installed worlds: ``EB/<DisplayName>-v0`` (the spelling from ``EnvSpec.display_name``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import gymnasium

if TYPE_CHECKING:
    from eb_core.plugins import Registry

__all__ = ["gym_id", "register_worlds", "registered_ids", "world_of"]

_REGISTERED: dict[str, str] = {}


def gym_id(world: str, display_name: str = "") -> str:
    """The Gymnasium id of a world: ``navigation`` -> ``EB/Navigation-v0`` (``display_name`` from its spec)."""
    if not display_name:
        display_name = next((gid for gid, name in _REGISTERED.items() if name == world), "")
        if display_name:
            return display_name
    name = display_name or world[:1].upper() + world[1:]
    return f"EB/{name.replace('_', '-')}-v0"


def register_worlds(registry: Registry | None = None) -> dict[str, str]:
    """Register every installed world (or those of ``registry``); returns ``{gym id: world name}``."""
    from eb_core.plugins import Registry

    reg = registry if registry is not None else Registry.create()
    out: dict[str, str] = {}
    for name, spec in reg.envs.items():
        gid = gym_id(name, spec.display_name)
        if gid not in gymnasium.registry:
            gymnasium.register(gid, entry_point="eb_core.gym.env:EBEnv", kwargs={"world": name},
                               disable_env_checker=True)
        out[gid] = name
    _REGISTERED.update(out)
    return out


def registered_ids() -> dict[str, str]:
    """``{gym id: world name}`` registered so far (at import, and by later :func:`register_worlds` calls)."""
    return dict(_REGISTERED)


def world_of(gid: str) -> str | None:
    """The world name behind a registered id."""
    return _REGISTERED.get(gid)
