"""The symbolic apartment: where every object is, what is open, where the agent stands, what it holds.

This is the whole logic of EB-Habitat; rendering (:mod:`eb_habitat.render`) only draws this state.
:meth:`World.step` executes one of the 70 skills and returns whether it worked and feedback text that says
why not (our wording).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

from eb_habitat.catalog import capacity, object_type, receptacle
from eb_habitat.skills import SKILLS

__all__ = ["FAILURES", "HAND", "Item", "Outcome", "World", "item_label"]

HAND = "@hand"
"""The location of the object the agent holds."""


@dataclass
class Item:
    name: str
    """Instance name, e.g. ``mug_2``."""
    type: str
    """Object type key, e.g. ``mug``."""
    color: str
    loc: str
    """Receptacle key, or :data:`HAND`."""
    slot: int = 0
    """Position on the receptacle, 0 = leftmost as seen by the agent standing at it."""
    handle: str | None = None
    """Where a mug's handle points as the agent faces it (``left``/``right``; hard sets), None: the usual turn."""


def item_label(item: Item) -> str:
    """How feedback names an instance: with its colour when the type comes in several colours."""
    t = object_type(item.type)
    return f"{item.color} {t.name}" if t.has_variants else t.name


def _article(label: str) -> str:
    return ("an " if label[0] in "aeiou" else "a ") + label


#: Why a skill failed (the core's ``StepResult.info["failure"]`` values this world reports). Every failure of
#: the 70 skills is one of these: ``precondition`` -- the right skill in the wrong state (not standing at the
#: receptacle, hand full or empty, the container closed or already open/closed, no free slot left, the object
#: lies at another receptacle); ``absent`` -- a pick names a kind of object this apartment does not hold (the
#: core labels it ``not_in_scene``).
#: ``affordance`` never happens: the skill set has no skill that acts on something unable to take it (only the
#: four containers have open/close skills, place skills exist only for receptacles, pick skills only for
#: objects), so it is not in this tuple.
FAILURES = ("precondition", "absent")


@dataclass(frozen=True)
class Outcome:
    success: bool
    feedback: str
    failure: str | None = None
    """One of :data:`FAILURES` when the skill failed, else None."""


class World:
    """Mutable symbolic state of one episode."""

    def __init__(self, objects: list[dict], opened: list[str] | tuple[str, ...] = (), agent_at: str | None = None,
                 wide: bool = False):
        self.items: dict[str, Item] = {}
        for o in objects:
            self.items[o["name"]] = Item(o["name"], o["type"], o["color"], o["at"], int(o["slot"]), o.get("handle"))
        self.opened: set[str] = set(opened)
        self.wide = wide
        """Hard sets (version 7): the long surfaces have :data:`~eb_habitat.catalog.WIDE_CAPACITY` slots."""
        self.agent_at: str | None = agent_at
        self.held: str | None = None
        self.picks: dict[str, int] = {}
        """How often each instance has been picked up in the episode (the ``untouched`` and ``once`` goal
        predicates read it)."""

    # -- queries ---------------------------------------------------------------------------------

    def copy(self) -> World:
        return copy.deepcopy(self)

    def items_at(self, key: str) -> list[Item]:
        """Objects on/in receptacle ``key``, left to right."""
        return sorted((it for it in self.items.values() if it.loc == key), key=lambda it: it.slot)

    @property
    def held_item(self) -> Item | None:
        return None if self.held is None else self.items[self.held]

    def is_open(self, key: str) -> bool:
        return not receptacle(key).articulated or key in self.opened

    def free_slot(self, key: str) -> int | None:
        used = {it.slot for it in self.items_at(key)}
        for s in range(capacity(key, self.wide)):
            if s not in used:
                return s
        return None

    def pick_candidate(self, type_key: str) -> Item | None:
        """The instance ``pick up the <type>`` would take: the leftmost of that type where the agent is."""
        if self.agent_at is None:
            return None
        for it in self.items_at(self.agent_at):
            if it.type == type_key:
                return it
        return None

    def visible_items(self) -> list[Item]:
        """What the agent can see on the receptacle in front of it (nothing inside a closed one)."""
        if self.agent_at is None or not self.is_open(self.agent_at):
            return []
        return self.items_at(self.agent_at)

    def describe(self) -> str:
        """What the agent perceives, in words (the observation text for language-only runs)."""
        lines: list[str] = []
        if self.agent_at is None:
            lines.append("You are standing in the middle of the apartment, not next to any receptacle.")
        else:
            r = receptacle(self.agent_at)
            lines.append(f"You are at the {r.name}.")
            if r.articulated and not self.is_open(r.key):
                lines.append(f"The {r.name} is closed, so you cannot see what is inside.")
            else:
                if r.articulated:
                    lines.append(f"The {r.name} is open.")
                things = [_article(item_label(it)) for it in self.items_at(r.key)]
                if things:
                    order = " (from left to right)" if len(things) > 1 and not r.articulated else ""
                    lines.append(f"{r.preposition.capitalize()} the {r.name}{order}: {', '.join(things)}.")
                else:
                    lines.append(f"There is nothing {r.preposition} the {r.name}.")
        held = self.held_item
        lines.append(f"You are holding the {item_label(held)}." if held else "Your hand is empty.")
        return " ".join(lines)

    # -- actions ---------------------------------------------------------------------------------

    def step(self, action: int) -> Outcome:
        """Execute skill ``action`` (an id into :data:`~eb_habitat.skills.SKILLS`)."""
        skill = SKILLS[action]
        return getattr(self, "_" + skill.kind)(skill.arg)

    def _navigate(self, key: str) -> Outcome:
        r = receptacle(key)
        if self.agent_at == key:
            return Outcome(True, f"You are already standing at the {r.name}.")
        self.agent_at = key
        return Outcome(True, f"You walked over to the {r.name}.")

    def _pick(self, type_key: str) -> Outcome:
        name = object_type(type_key).name
        held = self.held_item
        if held is not None:
            return Outcome(False, f"Cannot pick up the {name}: your hand already holds the {item_label(held)}. "
                                  f"Place it somewhere first.", "precondition")
        if self.agent_at is None:
            return Outcome(False, f"Cannot pick up the {name}: you are not next to any receptacle. "
                                  f"Navigate to the place where it lies first.", "precondition")
        r = receptacle(self.agent_at)
        if not self.is_open(r.key):
            return Outcome(False, f"Cannot pick up the {name}: the {r.name} is closed, so nothing inside is "
                                  f"reachable. Open it first.", "precondition")
        item = self.pick_candidate(type_key)
        if item is None:
            # elsewhere in the apartment: go there first; nowhere: the skill names a thing that is not here
            elsewhere = any(it.type == type_key for it in self.items.values())
            return Outcome(False, f"Cannot pick up the {name}: there is no {name} {r.preposition} the {r.name} "
                                  f"where you stand. Look for it at other receptacles.",
                           "precondition" if elsewhere else "absent")
        item.loc, item.slot = HAND, 0
        self.held = item.name
        self.picks[item.name] = self.picks.get(item.name, 0) + 1
        return Outcome(True, f"You picked up the {item_label(item)} from the {r.name}; it is now in your hand.")

    def _place(self, key: str) -> Outcome:
        r = receptacle(key)
        held = self.held_item
        if held is None:
            return Outcome(False, f"Cannot place anything {r.preposition} the {r.name}: your hand is empty. "
                                  f"Pick an object up first.", "precondition")
        if self.agent_at != key:
            where = "not next to any receptacle" if self.agent_at is None else \
                f"at the {receptacle(self.agent_at).name}"
            return Outcome(False, f"Cannot place the {item_label(held)} {r.preposition} the {r.name}: you are "
                                  f"{where}. Navigate to the {r.name} first.", "precondition")
        if not self.is_open(key):
            return Outcome(False, f"Cannot place the {item_label(held)} in the {r.name}: it is closed. Open it first.",
                           "precondition")
        slot = self.free_slot(key)
        if slot is None:
            return Outcome(False, f"Cannot place the {item_label(held)} {r.preposition} the {r.name}: there is no "
                                  f"free space left. Choose another receptacle.", "precondition")
        held.loc, held.slot = key, slot
        self.held = None
        return Outcome(True, f"You put the {item_label(held)} {r.preposition} the {r.name}; your hand is empty now.")

    def _open(self, key: str) -> Outcome:
        r = receptacle(key)
        if self.agent_at != key:
            return Outcome(False, f"Cannot open the {r.name}: it is out of reach. Navigate to the {r.name} first.",
                           "precondition")
        if key in self.opened:
            return Outcome(False, f"The {r.name} is already open.", "precondition")
        self.opened.add(key)
        return Outcome(True, f"You opened the {r.name}; its contents are now reachable.")

    def _close(self, key: str) -> Outcome:
        r = receptacle(key)
        if self.agent_at != key:
            return Outcome(False, f"Cannot close the {r.name}: it is out of reach. Navigate to the {r.name} first.",
                           "precondition")
        if key not in self.opened:
            return Outcome(False, f"The {r.name} is already closed.", "precondition")
        self.opened.discard(key)
        return Outcome(True, f"You closed the {r.name}.")
