"""The action list of an episode: a fixed global part plus one entry per extra instance in the scene.

The global part (the same ids in every scene, so in-context examples stay valid) has one ``find`` per type,
one ``pick up`` per pickupable type, the single ``put down`` and ``drop``, ``open``/``close`` per openable,
``turn on``/``turn off`` per toggleable and ``slice`` per sliceable type. Each additional instance of a type in
the scene (``Cabinet_2``, ``Apple_3``) appends only ``find`` (and ``open``/``close`` for openables), as in the
original: picking up, switching and slicing use the un-suffixed name, which acts on the nearest instance
(:meth:`eb_alfred.world.World.resolve`). The list's length depends on the scene.
"""

from __future__ import annotations

from eb_alfred.catalog import TYPES
from eb_alfred.world import VERBS, World, instance_index

__all__ = ["GLOBAL_ACTIONS", "scene_actions", "actions_for", "extra_actions_for"]


def actions_for(name: str, type_name: str) -> list[str]:
    """Every action kind that applies to a type, written with ``name`` (used for the global list)."""
    t = TYPES[type_name]
    out = [VERBS["find"].format(name)]
    if t.pickupable:
        out.append(VERBS["pickup"].format(name))
    if t.openable:
        out += [VERBS["open"].format(name), VERBS["close"].format(name)]
    if t.toggleable:
        out += [VERBS["toggle_on"].format(name), VERBS["toggle_off"].format(name)]
    if t.sliceable:
        out.append(VERBS["slice"].format(name))
    return out


def extra_actions_for(name: str, type_name: str) -> list[str]:
    """The actions an additional instance (``Cabinet_2``) adds: find, and open/close if it opens."""
    out = [VERBS["find"].format(name)]
    if TYPES[type_name].openable:
        out += [VERBS["open"].format(name), VERBS["close"].format(name)]
    return out


def _global() -> tuple[str, ...]:
    names = sorted(TYPES)
    acts = [VERBS["find"].format(n) for n in names]
    acts += [VERBS["pickup"].format(n) for n in names if TYPES[n].pickupable]
    acts += [VERBS["put"], VERBS["drop"]]
    acts += [VERBS["open"].format(n) for n in names if TYPES[n].openable]
    acts += [VERBS["close"].format(n) for n in names if TYPES[n].openable]
    acts += [VERBS["toggle_on"].format(n) for n in names if TYPES[n].toggleable]
    acts += [VERBS["toggle_off"].format(n) for n in names if TYPES[n].toggleable]
    acts += [VERBS["slice"].format(n) for n in names if TYPES[n].sliceable]
    return tuple(acts)


GLOBAL_ACTIONS: tuple[str, ...] = _global()


def scene_actions(world: World) -> tuple[str, ...]:
    """Global actions followed by the suffixed actions of every extra instance, in name order."""
    extra: list[str] = []
    keyed = sorted((instance_index(n), n) for n in world.objects)
    for (base, idx), name in keyed:
        if idx >= 2:
            extra += extra_actions_for(name, world.objects[name].type)
    return GLOBAL_ACTIONS + tuple(extra)
