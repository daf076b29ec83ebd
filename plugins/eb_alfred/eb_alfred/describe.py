"""Text descriptions of what the agent sees, for language-only runs (``Observation.text``).

The text says what the image would show: where the agent stands, its neighbours along the wall, the
visible things at that place with their looks (colour, shape) and visible states (open/closed, on/off,
sliced, dirty), and what is in hand. Contents of closed receptacles are not mentioned (they are hidden).
Temperatures are not visible, so hot/cold are not described.
"""

from __future__ import annotations

from eb_alfred.catalog import TYPES
from eb_alfred.world import World

__all__ = ["describe", "looks", "visible_at_place"]


def looks(world: World, name: str) -> str:
    """``"a red Apple_2 (sliced)"``-style phrase."""
    o = world.objects[name]
    words = [w for w in (o.shape, o.color) if w]
    states = []
    t = TYPES[o.type]
    if t.openable:
        states.append("open" if o.is_open else "closed")
    if t.toggleable:
        states.append("on" if o.is_on else "off")
    if o.is_sliced:
        states.append("sliced")
    if o.is_dirty:
        states.append("dirty")
    text = " ".join([*words, name])
    if states:
        text += " (" + ", ".join(states) + ")"
    return text


def visible_at_place(world: World, place: str) -> list[str]:
    """Instances at ``place`` that can be seen (not inside something closed, not in hand), top-down order."""
    out = []

    def walk(name: str) -> None:
        for c in world.children(name):
            if world.is_held(c):
                continue
            out.append(c)
            o = world.objects[c]
            if not (TYPES[o.type].openable and not o.is_open):
                walk(c)

    out.append(place)
    o = world.objects[place]
    if not (TYPES[o.type].openable and not o.is_open):
        walk(place)
    for n, inst in world.objects.items():
        if inst.floor_at == place and inst.parent is None and not world.is_held(n):
            out.append(n)
            walk(n)
    return out


def _contents(world: World, name: str) -> str:
    kids = [c for c in world.children(name) if not world.is_held(c)]
    return ", ".join(looks(world, c) for c in kids)


def _nested(world: World, name: str) -> str:
    """``looks`` of ``name`` followed by what it visibly holds, recursively (closed things hide their contents)."""
    o = world.objects[name]
    t = TYPES[o.type]
    desc = looks(world, name)
    if not t.receptacle and not world.children(name):
        return desc
    if t.openable and not o.is_open:
        return desc + ", its contents hidden"
    kids = [c for c in world.children(name) if not world.is_held(c)]
    if kids:
        return desc + " holding [" + ", ".join(_nested(world, c) for c in kids) + "]"
    return desc + ", empty" if o.parent is None else desc


def describe(world: World) -> str:
    """One short paragraph for the current state."""
    room = world.room.replace("_", " ")
    furniture = sorted((o.slot, n) for n, o in world.objects.items() if o.parent is None and o.floor_at is None
                       and not world.is_held(n))
    lines = []
    if world.place is None:
        lines.append(f"You stand in the middle of a {room}.")
        lines.append("Along the walls, from left to right: " + ", ".join(n for _, n in furniture) + ".")
    else:
        order = [n for _, n in furniture]
        place = world.place
        facing = world.facing or place
        if not world.is_held(facing):
            facing = world.closed_container(facing) or facing  # a hidden thing cannot be seen
        lines.append(f"You are in a {room}, at the {place}, facing the {facing}.")
        if place in order:
            i = order.index(place)
            left = order[i - 1] if i > 0 else None
            right = order[i + 1] if i + 1 < len(order) else None
            nb = []
            if left:
                nb.append(f"to your left is the {left}")
            if right:
                nb.append(f"to your right is the {right}")
            if nb:
                lines.append("Next to you: " + " and ".join(nb) + ".")
        parts = [_nested(world, place)]
        parts += [_nested(world, n) + " on the floor" for n, o in world.objects.items()
                  if o.floor_at == place and o.parent is None and not world.is_held(n)]
        lines.append("You see: " + "; ".join(parts) + ".")
    if world.held is None:
        lines.append("Your hand is empty.")
    else:
        held = looks(world, world.held)
        inside = _contents(world, world.held)
        lines.append(f"You are holding the {held}" + (f" with {inside} in it" if inside else "") + ".")
    return " ".join(lines)
