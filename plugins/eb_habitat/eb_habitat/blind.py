"""Players without the image, for measuring what the hard set leaves to guessing (symbolic world, benchmark budgets).

* :func:`blind_guess`: knows, generously, the types of the objects the goal moves where words can tell them (the
  hard set hides them behind use and looks descriptions, which a model decodes without the image) and the
  destination when the instruction names its receptacle; where only a relation in the image tells the object
  (hard spatial tasks) it guesses one of the types in the apartment (generously: it knows which are there). It
  searches the receptacles in a random order (navigate, open a closed one, ``pick up the <type>``), takes the
  first instance the pick gives, and puts it at the named destination or at a random surface.
* :func:`blind_sweep`: the same, reacting to feedback: the pick feedback names the colour, so when that is not
  the instruction's colour it puts the object back and searches on (what the classic set let through).
* :func:`text_rule_agent`: a rule agent with the scene text of ``ablation=text_state`` (what lies on the
  receptacle it stands at, with colours, left to right). It reads "<colour> <type>" phrases: the first is the
  object, the second the landmark (or the named receptacle); it does not read use or looks descriptions or
  relations. It visits receptacles in catalogue order, opens closed ones, and picks only what it has seen.

All play with 30 steps and 10 failed actions, like ``conf/env/habitat.yaml``.
"""

from __future__ import annotations

import random
import re

from eb_core.env import Task
from eb_habitat.catalog import COLORS, OBJECT_TYPES, RECEPTACLES, receptacle
from eb_habitat.skills import skill_id
from eb_habitat.tasks import spec_of
from eb_habitat.world import World

__all__ = ["MAX_FAILURES", "MAX_STEPS", "blind_guess", "blind_sweep", "text_rule_agent"]

MAX_STEPS = 30
MAX_FAILURES = 10
SURFACES = [r.key for r in RECEPTACLES if r.kind == "surface"]


class _Episode:
    def __init__(self, task: Task) -> None:
        spec = spec_of(task)
        self.world: World = spec.world()
        self.tracker = spec.tracker()
        self.steps = self.failures = 0
        self.feedback = ""

    @property
    def over(self) -> bool:
        return self.steps >= MAX_STEPS or self.failures >= MAX_FAILURES or self.tracker.success(self.world)

    def do(self, kind: str, arg: str) -> bool:
        if self.over:
            return False
        out = self.world.step(skill_id(kind, arg))
        self.steps += 1
        self.failures += not out.success
        self.feedback = out.feedback
        return out.success

    def go(self, key: str) -> None:
        self.do("navigate", key)
        if receptacle(key).articulated and not self.world.is_open(key):
            self.do("open", key)

    @property
    def success(self) -> bool:
        return self.tracker.success(self.world)


def _moves(task: Task) -> list[tuple[str, str]]:
    """(type key, receptacle key) of every object the goal moves."""
    spec = spec_of(task)
    types = spec.instances()
    return [(types.get(p.args[0], p.args[0].lstrip("?")), p.args[1])
            for p in spec.goal_predicates() if p.name in ("on", "inside")]


def _named(task: Task, key: str) -> bool:
    return receptacle(key).name.lower() in task.instruction.lower()


def _play_blind(task: Task, rng: random.Random, sweep: bool) -> bool:
    ep = _Episode(task)
    colors = [c for c in sorted(COLORS, key=len, reverse=True) if re.search(rf"\b{c}\b", task.instruction)]
    spec = spec_of(task)
    named_types = {k for _, k in _phrases(task.instruction)}
    for type_key, dest in _moves(task):
        if type_key not in named_types and spec.template.startswith("hard.spatial"):
            # the instruction hides the type (a relation names the object): guess one of the apartment's types
            type_key = rng.choice(sorted({o.type for o in spec.objects} - named_types))
        order = [r.key for r in RECEPTACLES]
        rng.shuffle(order)
        while order and not ep.over and ep.world.held is None:
            here = order.pop()
            ep.go(here)
            if ep.do("pick", type_key) and sweep:
                held = ep.world.held_item
                if held is not None and colors and held.color not in colors:
                    ep.do("place", here)  # the wrong colour, by the feedback: put it back, search on
        if ep.world.held is None:
            break
        if _named(task, dest):
            ep.go(dest)
            ep.do("place", dest)
        else:
            for guess in rng.sample(SURFACES, len(SURFACES)):
                ep.go(guess)
                if ep.do("place", guess) or ep.over:
                    break
    return ep.success


def blind_guess(task: Task, seed: int = 0) -> bool:
    """One episode of the blind guesser (see the module docstring); True on success."""
    return _play_blind(task, random.Random(f"habitat-blind-guess/{task.id}/{seed}"), sweep=False)


def blind_sweep(task: Task, seed: int = 0) -> bool:
    """One episode of the feedback-reading blind player (see the module docstring); True on success."""
    return _play_blind(task, random.Random(f"habitat-blind-sweep/{task.id}/{seed}"), sweep=True)


_TYPE_WORDS = sorted(((t.name, t.key) for t in OBJECT_TYPES), key=lambda p: -len(p[0]))
_COLOR_RE = "|".join(sorted((re.escape(c) for c in COLORS), key=len, reverse=True))
_TYPE_RE = "|".join(re.escape(n) for n, _ in _TYPE_WORDS)


def _phrases(text: str) -> list[tuple[str | None, str]]:
    """(colour or None, type key) of every "[<colour>] <type name>" in ``text``, in order."""
    return [(m.group(1), next(k for n, k in _TYPE_WORDS if n == m.group(2)))
            for m in re.finditer(rf"\b(?:({_COLOR_RE}) )?({_TYPE_RE})\b", text.lower())]


def _destinations(text: str) -> list[str]:
    """Receptacles named as a destination ("on/in/to the <receptacle>"), in the order of the text."""
    hits = []
    for r in RECEPTACLES:
        for m in re.finditer(rf"\b(?:on|in|to|into) the {re.escape(r.name.lower())}\b", text.lower()):
            hits.append((m.start(), r.key))
    return [k for _, k in sorted(hits)]


def text_rule_agent(task: Task) -> bool:
    """One episode of the text-only rule agent (see the module docstring); True on success."""
    ep = _Episode(task)
    phrases = _phrases(task.instruction)
    named = _destinations(task.instruction)
    if not phrases:
        return False
    several = named and len(phrases) >= 2 and len(named) <= 1 and not any(c is None for c, _ in phrases)
    wanted = phrases if several or len(named) >= 2 else phrases[:1]
    landmark = None if named else (phrases[1] if len(phrases) > 1 else None)
    seen: list[tuple[str, str, str]] = []

    def look() -> None:
        for it in ep.world.visible_items():
            seen.append((it.color, it.type, it.loc))

    def where(key: tuple[str | None, str]) -> str | None:
        return next((loc for c, t, loc in seen if t == key[1] and (key[0] is None or c == key[0])), None)

    def find(key: tuple[str | None, str]) -> str | None:
        for r in RECEPTACLES:
            if where(key) is not None or ep.over:
                break
            ep.go(r.key)
            look()
        return where(key)

    for i, (color, type_key) in enumerate(wanted):
        src = find((color, type_key))
        if landmark is not None:
            dest = find(landmark)
        else:
            dest = named[min(i, len(named) - 1)] if named else None
        if src is None or dest is None:
            return False
        ep.go(src)
        cand = ep.world.pick_candidate(type_key)
        if cand is None or (color is not None and cand.color != color):
            return False  # the one it wants is not the one ``pick up`` would take
        ep.do("pick", type_key)
        ep.go(dest)
        ep.do("place", dest)
    return ep.success
