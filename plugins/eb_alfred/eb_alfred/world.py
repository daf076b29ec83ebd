"""The symbolic household world: instances, containment, states and the rules of the 8 skills.

This module knows nothing about rendering. A :class:`World` is built from a scene (plain data, as stored
in the task files), executes action names such as ``"find a Cabinet_2"`` and answers with success and a
feedback sentence that says why an action failed.

Rules, as in AI2-THOR / ALFRED:

* The agent holds at most one object.
* ``find a X`` walks to X's *place* (the piece of furniture or fixture it stands in or on) and faces X.
  Objects at the agent's place can be acted on; anything elsewhere must be found first. ``find a Cabinet``
  means the first cabinet, ``find a Cabinet_2`` the second.
* Nearest instance: an un-suffixed name in any other action (``pick up the Mug``, ``slice the Apple``,
  ``turn on the DeskLamp``, ``open the Drawer``) acts on the nearest reachable instance of that type, as
  AI2-THOR's name lookup does in the original: the instance the agent faces, else one in or on what it faces
  (the mug on the coffee machine it walked to), else one in plain view at its place, else one held, else one
  hidden at its place (lowest number first). A suffixed name means exactly that instance.
* Closed receptacles hide their contents and block picking them up.
* ``put down`` puts the held object in/on the receptacle the agent faces (the found receptacle, or the
  receptacle holding the found object). A sink or bathtub takes it into its basin. A coffee machine holds one
  cup or mug at a time.
* Slicing needs a knife in hand. Heating: inside a microwave that is turned on (the microwave must be
  closed to run and stopped to open). Cooling: inside a fridge when it is closed. Cleaning: in a sink basin
  while its faucet runs. Examining: holding the object next to a lamp that is on.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from eb_alfred.catalog import KNIVES, TYPES, fits

__all__ = ["Instance", "World", "parse_action", "instance_index", "VERBS", "FAILURES"]

#: The kinds of failure :attr:`World.failure` reports (the core's ``StepResult.info["failure"]`` values):
#: ``affordance`` -- the thing does not support the action at all (slicing without a knife, picking up a fridge,
#: opening a table, an object that does not fit the receptacle); ``precondition`` -- the right action in the
#: wrong state (not close, hidden in or blocked by something closed, hand full or empty, already open/on/sliced,
#: a running microwave); ``absent`` -- the action names a thing this room does not have (the core labels it
#: ``not_in_scene``: the action list offers every type, so trying one is a belief about the room, not a percept). The environment reports ``wrong_target`` when a failed action acts on a look-alike of
#: the thing the goal singles out.
FAILURES = ("affordance", "precondition", "absent", "wrong_target")

#: Action verb -> the type property it needs (an object without it does not afford the action).
_AFFORDS = {"pickup": "pickupable", "open": "openable", "close": "openable", "toggle_on": "toggleable",
            "toggle_off": "toggleable", "slice": "sliceable"}

#: Verb -> action-name template. ``{}`` is the instance name.
VERBS: dict[str, str] = {
    "find": "find a {}",
    "pickup": "pick up the {}",
    "put": "put down the object in hand",
    "drop": "drop the object in hand",
    "open": "open the {}",
    "close": "close the {}",
    "toggle_on": "turn on the {}",
    "toggle_off": "turn off the {}",
    "slice": "slice the {}",
}

_PATTERNS = [
    (re.compile(r"^find an? (\w+)$"), "find"),
    (re.compile(r"^pick up the (\w+)$"), "pickup"),
    (re.compile(r"^put down the object in hand$"), "put"),
    (re.compile(r"^drop the object in hand$"), "drop"),
    (re.compile(r"^open the (\w+)$"), "open"),
    (re.compile(r"^close the (\w+)$"), "close"),
    (re.compile(r"^turn on the (\w+)$"), "toggle_on"),
    (re.compile(r"^turn off the (\w+)$"), "toggle_off"),
    (re.compile(r"^slice the (\w+)$"), "slice"),
]

#: Receptacles that hold one thing at a time (a coffee machine has room for one cup under its spout).
_ONE_AT_A_TIME = frozenset({"CoffeeMachine"})

_PAST = {"pickup": "picked up", "open": "opened", "close": "closed", "toggle_on": "turned on",
         "toggle_off": "turned off", "slice": "sliced"}

_SUFFIX = re.compile(r"^([A-Za-z]+)(?:_(\d+))?$")


def parse_action(name: str) -> tuple[str, str | None]:
    """``"open the Cabinet_2"`` -> ``("open", "Cabinet_2")``; raises ValueError for unknown text."""
    for pattern, verb in _PATTERNS:
        m = pattern.match(name.strip())
        if m:
            return verb, (m.group(1) if m.groups() else None)
    raise ValueError(f"not an EB-ALFRED action: {name!r}")


def instance_index(name: str) -> tuple[str, int]:
    """``"Cabinet_2"`` -> ``("Cabinet", 2)``; ``"Cabinet"`` -> ``("Cabinet", 1)``."""
    m = _SUFFIX.match(name)
    if not m:
        raise ValueError(f"bad instance name {name!r}")
    return m.group(1), int(m.group(2) or 1)


@dataclass
class Instance:
    """One object or receptacle in the scene."""

    name: str
    type: str
    parent: str | None = None
    """The receptacle it is in/on; None for furniture standing in the room (or an object on the floor)."""
    floor_at: str | None = None
    """For an object dropped on the floor: the place it lies at."""
    slot: int = 0
    """Furniture only: position along the walls, left to right (for layout and spatial words)."""
    is_open: bool = False
    is_on: bool = False
    is_sliced: bool = False
    is_dirty: bool = False
    is_hot: bool = False
    is_cold: bool = False
    color: str | None = None
    shape: str | None = None

    def clone(self) -> Instance:
        """A shallow copy (all fields are immutable values); much faster than ``copy.copy``."""
        twin = Instance.__new__(Instance)
        twin.__dict__.update(self.__dict__)
        return twin

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "type": self.type}
        if self.parent is not None:
            out["parent"] = self.parent
        else:
            out["slot"] = self.slot
        for key in ("is_open", "is_on", "is_sliced", "is_dirty", "is_hot", "is_cold"):
            if getattr(self, key):
                out[key] = True
        if self.color:
            out["color"] = self.color
        if self.shape:
            out["shape"] = self.shape
        return out


@dataclass
class World:
    """Mutable symbolic state of one episode."""

    room: str
    objects: dict[str, Instance]
    held: str | None = None
    place: str | None = None
    """The piece of furniture the agent stands at (None at the start: the middle of the room)."""
    facing: str | None = None
    """The instance the agent last found (what the camera looks at)."""
    target_recep: str | None = None
    """Where ``put down`` puts the held object."""
    history: list[str] = field(default_factory=list)
    failure: str | None = field(default=None, compare=False)
    """Why the last action failed (see :data:`FAILURES`); None after a successful action."""
    last_target: str | None = field(default=None, compare=False)
    """The instance the last action acted on (after the nearest-instance rule), None for put down / drop."""
    touched: set[str] = field(default_factory=set, compare=False)
    """Instances a successful action has handled since the start: picked up (with what they carry), opened,
    closed, switched, sliced, or put into / dropped. Goals that ask to leave look-alikes alone read it."""

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_scene(cls, scene: dict[str, Any]) -> World:
        objs: dict[str, Instance] = {}
        for o in scene["objects"]:
            inst = Instance(**{k: v for k, v in o.items()})
            objs[inst.name] = inst
        return cls(room=scene["room"], objects=objs)

    def to_scene(self) -> dict[str, Any]:
        return {"room": self.room, "objects": [o.to_dict() for o in self.objects.values()]}

    def copy(self) -> World:
        twin = World(room=self.room, objects={k: v.clone() for k, v in self.objects.items()}, held=self.held,
                     place=self.place, facing=self.facing, target_recep=self.target_recep, history=list(self.history),
                     touched=set(self.touched))
        twin._types = self._type_index()  # types never change, so copies share the index
        return twin

    # ------------------------------------------------------------------ queries
    def _type_index(self) -> dict[str, list[str]]:
        index = self.__dict__.get("_types")
        if index is None:
            index = {}
            for n, o in self.objects.items():
                index.setdefault(o.type, []).append(n)
            self._types = index
        return index

    def of_type(self, type_name: str) -> list[str]:
        return list(self._type_index().get(type_name, ()))

    def children(self, name: str) -> list[str]:
        return [n for n, o in self.objects.items() if o.parent == name]

    def descendants(self, name: str) -> list[str]:
        out: list[str] = []
        stack = [name]
        while stack:
            cur = stack.pop()
            for c in self.children(cur):
                out.append(c)
                stack.append(c)
        return out

    def ancestors(self, name: str) -> list[str]:
        """Receptacles holding ``name``, innermost first."""
        out = []
        cur = self.objects[name].parent
        while cur is not None:
            out.append(cur)
            cur = self.objects[cur].parent
        return out

    def is_held(self, name: str) -> bool:
        """True if ``name`` is in hand or inside what is in hand."""
        return self.held is not None and (name == self.held or self.held in self.ancestors(name))

    def place_of(self, name: str) -> str | None:
        """The furniture/fixture instance where ``name`` is (the agent's place if it is in hand)."""
        if self.is_held(name):
            return self.place
        chain = [name, *self.ancestors(name)]
        top = self.objects[chain[-1]]
        if top.floor_at is not None:
            return top.floor_at
        return chain[-1]

    def closed_container(self, name: str) -> str | None:
        """The outermost closed receptacle around ``name`` (None if it is in plain view)."""
        closed = [a for a in self.ancestors(name) if TYPES[self.objects[a].type].openable and not self.objects[a].is_open]
        return closed[-1] if closed else None

    def visible(self, name: str) -> bool:
        return self.is_held(name) or self.closed_container(name) is None

    def near(self, name: str) -> bool:
        return self.place is not None and self.place_of(name) == self.place

    def put_target_for(self, name: str) -> str | None:
        """The receptacle ``put down`` uses after finding ``name``."""
        o = self.objects[name]
        t = TYPES[o.type]
        if t.receptacle:
            recep = name
        elif o.parent is not None:
            recep = o.parent
        else:
            return None
        return self._basin_of(recep)

    def _basin_of(self, recep: str) -> str:
        """A sink or bathtub takes objects into its basin (the fix for the upstream 'on top of the sink' bug)."""
        rtype = self.objects[recep].type
        if rtype in ("Sink", "Bathtub"):
            basin_type = "SinkBasin" if rtype == "Sink" else "BathtubBasin"
            for c in self.children(recep):
                if self.objects[c].type == basin_type:
                    return c
        return recep

    def faucet_of(self, basin: str) -> str | None:
        sink = self.objects[basin].parent
        if sink is None:
            return None
        for c in self.children(sink):
            if self.objects[c].type == "Faucet":
                return c
        return None

    def in_scene(self, name: str) -> bool:
        return name in self.objects

    def resolve(self, verb: str, name: str) -> str:
        """The instance an action's object name refers to (see the nearest-instance rule in the module docstring).

        ``find`` and suffixed names are exact. An un-suffixed type name in any other verb means the nearest
        reachable instance of that type; with none at the agent's place it means the first instance (the action
        then fails with a 'not close' reason).
        """
        if verb == "find" or name not in TYPES:
            return name
        same = self.of_type(name)
        if not same:
            return name
        here = [n for n in same if self.near(n)]
        if not here:
            return name if name in self.objects else min(same, key=instance_index)

        def rank(n: str) -> tuple[int, int, tuple[str, int]]:
            if self.is_held(n):
                where = 1
            elif self.closed_container(n) is not None:
                where = 2
            else:
                where = 0
            faced = 0 if n == self.facing else 1 if self.facing in self.ancestors(n) else 2
            return (faced, where, instance_index(n))

        return min(here, key=rank)

    # ------------------------------------------------------------------ stepping
    def step(self, action: str) -> tuple[bool, str]:
        """Execute one action name; return ``(success, feedback)``. A failed action changes nothing."""
        verb, target = parse_action(action)
        self.history.append(action)
        self.failure = None
        if target is not None:
            target = self.resolve(verb, target)
        self.last_target = target
        if target is not None and target not in self.objects:
            base, _ = instance_index(target)
            noun = TYPES[base].noun if base in TYPES else base
            self.failure = "absent"
            return False, f"Failed: there is no {target} here; no {noun} with that name is in this room."
        prop = _AFFORDS.get(verb)
        if target is not None and prop is not None and not getattr(TYPES[self.objects[target].type], prop):
            self.failure = "affordance"
            verb_text = VERBS[verb].format("").replace(" the ", " ").strip()
            return False, f"Failed: the {target} cannot be {_PAST[verb]}; it does not support '{verb_text}'."
        handler = getattr(self, f"_do_{verb}")
        held_before, recep_before = self.held, self.target_recep
        ok, feedback = handler(target) if target is not None else handler()
        if not ok and self.failure is None:
            self.failure = "precondition"
        if ok and verb != "find":
            self._touch(verb, target, held_before, recep_before)
        return ok, feedback

    def _touch(self, verb: str, target: str | None, held_before: str | None, recep_before: str | None) -> None:
        """Record what a successful action handled (see :attr:`touched`)."""
        if verb == "pickup" and target is not None:
            self.touched.update([target, *self.descendants(target)])
        elif verb in ("put", "drop") and held_before is not None:
            self.touched.update([held_before, *self.descendants(held_before)])
            if verb == "put" and recep_before is not None:
                self.touched.add(recep_before)
        elif target is not None:
            self.touched.add(target)

    # Every handler returns (ok, feedback). Check order: existence, hand, distance, visibility, state.
    def _not_near(self, name: str) -> tuple[bool, str]:
        kind = self.objects[name].type
        others = [n for n in self.of_type(kind) if n != name]
        if others and name == kind:  # an un-suffixed name stands for any instance of the type
            where = "you have not found one yet" if self.place is None else f"you are at the {self.place}"
            return False, (f"Failed: no {kind} is within reach ({where}). "
                           f"Use 'find a {kind}' or the find action of another {kind} to go to one first.")
        if self.place is None:
            return False, f"Failed: you have not found the {name} yet. Use 'find a {name}' to go to it first."
        return False, (f"Failed: the {name} is not close to you (you are at the {self.place}). "
                       f"Use 'find a {name}' to go to it first.")

    def _hidden(self, name: str, container: str) -> tuple[bool, str]:
        return False, f"Failed: the {name} is inside the {container}, which is closed. Open the {container} first."

    def _do_find(self, name: str) -> tuple[bool, str]:
        if self.is_held(name):
            what = "holding" if name == self.held else f"holding it inside the {self.held}"
            return False, f"Failed: you are already {what}; there is no need to find the {name}."
        self.place = self.place_of(name)
        self.facing = name
        target = self.put_target_for(name)
        if target is not None and self.is_held(target):
            target = None
        self.target_recep = target
        container = self.closed_container(name)
        if container is not None and container != name:
            return True, (f"You walked to the {container}. The {name} is inside it, but the {container} is "
                          f"closed, so you cannot see it.")
        where = "" if self.place == name else f" at the {self.place}"
        return True, f"You found the {name}{where} and are now facing it."

    def _do_pickup(self, name: str) -> tuple[bool, str]:
        if self.held == name:
            return False, f"Failed: you are already holding the {name}."
        if self.held is not None:
            return False, (f"Failed: your hand is full, you are holding the {self.held}. "
                           f"Put it down or drop it before picking up the {name}.")
        if not self.near(name):
            return self._not_near(name)
        container = self.closed_container(name)
        if container is not None:
            return self._hidden(name, container)
        o = self.objects[name]
        came_from = o.parent
        o.parent = None
        o.floor_at = None
        self.held = name
        if self.target_recep is not None and self.is_held(self.target_recep):
            self.target_recep = self._basin_of(came_from) if came_from is not None else None
        extra = ""
        inside = self.children(name)
        if inside:
            extra = " It carries " + ", ".join(f"the {c}" for c in inside) + " with it."
        return True, f"You picked up the {name}.{extra}"

    def _do_put(self) -> tuple[bool, str]:
        if self.held is None:
            return False, "Failed: you are not holding anything to put down."
        held = self.held
        recep = self.target_recep
        if recep is None:
            if self.place is None:
                return False, "Failed: you are in the middle of the room; find a receptacle to put the object in first."
            return False, (f"Failed: there is no receptacle in front of you to put the {held} in. "
                           "Find a receptacle first, or drop the object.")
        rtype = self.objects[recep].type
        container = self.closed_container(recep)
        if container is not None:
            return self._hidden(recep, container)
        if TYPES[rtype].openable and not self.objects[recep].is_open:
            return False, f"Failed: the {recep} is closed. Open the {recep} before putting the {held} in it."
        if not fits(self.objects[held].type, rtype):
            self.failure = "affordance"
            return False, f"Failed: the {held} does not fit in or on the {recep}."
        if rtype in _ONE_AT_A_TIME:
            there = [c for c in self.children(recep) if c != held]
            if there:
                return False, (f"Failed: the {recep} already holds the {there[0]}; it takes one at a time. "
                               f"Take the {there[0]} away first.")
        o = self.objects[held]
        was_dirty = o.is_dirty
        o.parent = recep
        self.held = None
        self._apply_effects_on_enter(recep)
        prep = "in" if (TYPES[rtype].openable or rtype in ("SinkBasin", "BathtubBasin", "GarbageCan", "Bowl", "Cup",
                                                            "Mug", "Pot", "Pan", "Box", "LaundryHamper")) else "on"
        note = ""
        if was_dirty and not o.is_dirty:
            note = " The running water washes it clean."
        return True, f"You put the {held} {prep} the {recep}.{note}"

    def _do_drop(self) -> tuple[bool, str]:
        if self.held is None:
            return False, "Failed: you are not holding anything to drop."
        held = self.held
        o = self.objects[held]
        o.parent = None
        o.floor_at = self.place or "room"
        self.held = None
        return True, f"You dropped the {held} on the floor."

    def _check_reach(self, name: str) -> tuple[bool, str] | None:
        if self.is_held(name):
            return None
        if not self.near(name):
            return self._not_near(name)
        container = self.closed_container(name)
        if container is not None:
            return self._hidden(name, container)
        return None

    def _do_open(self, name: str) -> tuple[bool, str]:
        bad = self._check_reach(name)
        if bad:
            return bad
        o = self.objects[name]
        if o.is_open:
            return False, f"Failed: the {name} is already open."
        if o.is_on:
            return False, f"Failed: the {name} is running. Turn it off before opening it."
        o.is_open = True
        if not TYPES[o.type].receptacle:
            return True, f"You opened the {name}."
        inside = self.children(name)
        seen = ", ".join(f"the {c}" for c in inside) if inside else "nothing"
        return True, f"You opened the {name}. Inside you see {seen}."

    def _set_temperature(self, container: str, hot: bool) -> list[str]:
        """Make everything inside ``container`` hot (microwave) or cold (fridge); return what changed."""
        inside = self.descendants(container)
        for c in inside:
            self.objects[c].is_hot, self.objects[c].is_cold = hot, not hot
        return inside

    def _do_close(self, name: str) -> tuple[bool, str]:
        bad = self._check_reach(name)
        if bad:
            return bad
        o = self.objects[name]
        if not o.is_open:
            return False, f"Failed: the {name} is already closed."
        o.is_open = False
        note = ""
        if o.type == "Fridge" and self._set_temperature(name, hot=False):
            note = " The fridge chills what is inside."
        return True, f"You closed the {name}.{note}"

    def _do_toggle_on(self, name: str) -> tuple[bool, str]:
        bad = self._check_reach(name)
        if bad:
            return bad
        o = self.objects[name]
        if o.is_on:
            return False, f"Failed: the {name} is already on."
        if o.type == "Microwave" and o.is_open:
            return False, f"Failed: the {name} is open; close it before turning it on."
        o.is_on = True
        note = ""
        if o.type == "Microwave":
            if self._set_temperature(name, hot=True):
                note = " It heats what is inside."
        elif o.type == "Faucet":
            washed = self._wash_under(name)
            if washed:
                note = (" Water runs over " + " and ".join(f"the {c}" for c in washed) + " and washes "
                        + ("them" if len(washed) > 1 else "it") + " clean.")
            else:
                note = " Water runs into the empty basin."
        elif o.type in ("DeskLamp", "FloorLamp"):
            note = " The light is on."
        return True, f"You turned on the {name}.{note}"

    def _do_toggle_off(self, name: str) -> tuple[bool, str]:
        bad = self._check_reach(name)
        if bad:
            return bad
        o = self.objects[name]
        if not o.is_on:
            return False, f"Failed: the {name} is already off."
        o.is_on = False
        return True, f"You turned off the {name}."

    def _do_slice(self, name: str) -> tuple[bool, str]:
        if self.held is None or self.objects[self.held].type not in KNIVES:
            what = "nothing" if self.held is None else f"the {self.held}"
            self.failure = "affordance"
            return False, f"Failed: slicing needs a knife in your hand, and you are holding {what}."
        bad = self._check_reach(name)
        if bad:
            return bad
        o = self.objects[name]
        if o.is_sliced:
            return False, f"Failed: the {name} is already sliced."
        o.is_sliced = True
        return True, f"You sliced the {name} with the {self.held}."

    # ------------------------------------------------------------------ effects
    def _faucet_running(self, basin: str) -> bool:
        f = self.faucet_of(basin)
        return f is not None and self.objects[f].is_on

    def _wash_under(self, faucet: str) -> list[str]:
        sink = self.objects[faucet].parent
        washed = []
        for basin in self.children(sink) if sink else []:
            if self.objects[basin].type != "SinkBasin":
                continue
            for c in self.descendants(basin):
                if self.objects[c].is_dirty:
                    self.objects[c].is_dirty = False
                    washed.append(c)
        return washed

    def _apply_effects_on_enter(self, recep: str) -> None:
        rtype = self.objects[recep].type
        if rtype == "SinkBasin" and self._faucet_running(recep):
            for c in self.descendants(recep):
                self.objects[c].is_dirty = False
