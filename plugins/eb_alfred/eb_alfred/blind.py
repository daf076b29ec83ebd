"""Players that cannot see, for measuring how much a task set needs the image (tests, ``scripts/difficulty.py``).

All play the symbolic world with the benchmark's budgets (30 actions, 10 failed ones) and are scored by the
task's own goal:

* :func:`guess_episode` -- a blind player that reads the instruction's nouns (which types are wanted) and the
  action list (how many of each there are), picks one candidate of each role at random and carries the task out
  perfectly for that choice (the expert's plan);
* :func:`sweep_episode` -- the same, reacting to feedback: when a choice does not end the episode with success,
  it tries the next candidates in turn until the budget is spent;
* :func:`text_rule_episode` -- a rule agent with the scene text of ``ablation=text_state`` (no image): it reads
  colour and shape words, wall order and left/right neighbours from the text observation, pays one ``find`` for
  each candidate it inspects, and then plays the expert's plan for the binding it read;
* :func:`random_episode` and :func:`noisy_expert_episode` (the noise curve).
"""

from __future__ import annotations

import itertools
import random
import re
from typing import Any

from eb_alfred.actions import scene_actions
from eb_alfred.catalog import TYPES
from eb_alfred.goals import evaluate
from eb_alfred.instructions import noun
from eb_alfred.oracle import expert_plan
from eb_alfred.world import World

__all__ = ["MAX_STEPS", "MAX_INVALID", "guess_episode", "sweep_episode", "text_rule_episode", "random_episode",
           "noisy_expert_episode"]

MAX_STEPS, MAX_INVALID = 30, 10
_ROLES = ("object", "receptacle", "movable")


class _Budget:
    """A world with the episode's budgets: :meth:`do` returns False once the episode is over."""

    def __init__(self, scene: dict[str, Any], goal: dict[str, Any]) -> None:
        self.w = World.from_scene(scene)
        self.goal = goal
        self.steps = self.invalid = 0
        self.success = False

    @property
    def over(self) -> bool:
        return self.success or self.steps >= MAX_STEPS or self.invalid >= MAX_INVALID

    def do(self, action: str) -> bool:
        if self.over:
            return False
        ok, _ = self.w.step(action)
        self.steps += 1
        self.invalid += not ok
        self.success = evaluate(self.goal, self.w)[0]
        return not self.over


def _type(world: World, ref: dict[str, str]) -> str:
    return ref["type"] if "type" in ref else world.objects[ref["instance"]].type


def _candidates(world: World, goal: dict[str, Any]) -> dict[str, list[str]]:
    """What a player without the image can tell apart: every instance of each wanted type."""
    return {role: world.of_type(_type(world, goal[role])) for role in _ROLES if role in goal}


def _bound(goal: dict[str, Any], choice: dict[str, Any]) -> dict[str, Any]:
    """The goal as the player understands it for one choice of instances (no untouched rule: it does not know
    which are the others)."""
    g = {k: v for k, v in goal.items() if k != "untouched"}
    for role, pick in choice.items():
        if role == "object" and isinstance(pick, tuple):
            continue  # pick two: the player's two picks are bound below by playing them in turn
        g[role] = {"instance": pick}
    return g


def _play_choice(b: _Budget, goal: dict[str, Any], choice: dict[str, Any]) -> None:
    if isinstance(choice.get("object"), tuple):  # pick two: deliver each chosen instance
        for x in choice["object"]:
            g = dict(_bound(goal, {k: v for k, v in choice.items() if k != "object"}), kind="pick_and_place",
                     object={"instance": x})
            plan = expert_plan(b.w, g, limit=MAX_STEPS)
            for a in plan or []:
                if not b.do(a):
                    return
        return
    plan = expert_plan(b.w, _bound(goal, choice), limit=MAX_STEPS)
    for a in plan or []:
        if not b.do(a):
            return


def _choices(world: World, goal: dict[str, Any], rng: random.Random | None) -> list[dict[str, Any]]:
    cands = _candidates(world, goal)
    pools: list[tuple[str, list[Any]]] = []  # (role, its candidates: names, or pairs of names)
    for role, names in cands.items():
        if role == "object" and goal["kind"] == "pick_two_and_place":
            pools.append((role, list(itertools.combinations(names, 2))))
        else:
            pools.append((role, list(names)))
    combos = [dict(zip([r for r, _ in pools], c)) for c in itertools.product(*[p for _, p in pools])]
    if rng is not None:
        rng.shuffle(combos)
    return combos


def guess_episode(scene: dict[str, Any], goal: dict[str, Any], rng: random.Random) -> bool:
    """One blind guess among the candidates, carried out perfectly."""
    b = _Budget(scene, goal)
    _play_choice(b, goal, _choices(b.w, goal, rng)[0])
    return b.success


def sweep_episode(scene: dict[str, Any], goal: dict[str, Any], rng: random.Random) -> bool:
    """Blind guesses in turn, reacting to the absence of success, until the budget runs out."""
    b = _Budget(scene, goal)
    for choice in _choices(b.w, goal, rng):
        if b.over:
            break
        _play_choice(b, goal, choice)
    return b.success


def random_episode(scene: dict[str, Any], goal: dict[str, Any], rng: random.Random) -> bool:
    b = _Budget(scene, goal)
    actions = scene_actions(b.w)
    while b.do(rng.choice(actions)):
        pass
    return b.success


def noisy_expert_episode(scene: dict[str, Any], goal: dict[str, Any], noise: float, rng: random.Random) -> bool:
    """The closed-loop expert, with a random action instead of its own at rate ``noise``."""
    b = _Budget(scene, goal)
    actions = scene_actions(b.w)
    while not b.over:
        if rng.random() < noise:
            b.do(rng.choice(actions))
            continue
        plan = expert_plan(b.w, goal, limit=MAX_STEPS)
        if not plan:
            break
        b.do(plan[0])
    return b.success


# ------------------------------------------------------------------------------------- the text rule agent
def _words_for(text: str, t: str) -> dict[str, str]:
    """Colour/shape words the instruction ties to type ``t`` ("the red mug", "two blue cloths", "the red
    handled cup...": the first look word of the type's palette anywhere in the sentence)."""
    low = text.lower()
    out = {}
    for attr, values in (("shape", TYPES[t].shapes), ("color", TYPES[t].colors)):
        for v in values:
            if re.search(rf"\b{v} (\w+ )?{re.escape(noun(t).split()[-1])}", low):
                out[attr] = v
    return out


def _relation_target(world: World, text: str, t: str) -> str | None:
    """The furniture of type ``t`` a spatial phrase points at, read from the wall order the text shows."""
    low = text.lower()
    order = [n for _, n in sorted((o.slot, n) for n, o in world.objects.items() if o.parent is None)]
    same = [n for n in order if world.objects[n].type == t]
    name = noun(t)
    if f"leftmost {name}" in low:
        return same[0] if same else None
    if f"rightmost {name}" in low:
        return same[-1] if same else None
    m = re.search(rf"{re.escape(name)} just to the (left|right) of the ([a-z ]+?)(?: in| on|[.,]| and|$)", low)
    if not m:
        return None
    side, other = m.group(1), m.group(2).strip()
    for i, n in enumerate(order):
        if world.objects[n].type != t:
            continue
        j = i + 1 if side == "left" else i - 1
        if 0 <= j < len(order) and noun(world.objects[order[j]].type) == other:
            return n
    return None


def text_rule_episode(scene: dict[str, Any], goal: dict[str, Any], instruction: str) -> bool:
    """The rule agent with the scene text (see the module docstring)."""
    b = _Budget(scene, goal)
    w = b.w
    choice: dict[str, Any] = {}
    for role, names in _candidates(w, goal).items():
        t = w.objects[names[0]].type
        if len(names) == 1:
            choice[role] = names[0]
            continue
        fixture = not TYPES[t].pickupable
        want = _words_for(instruction, t)
        if fixture:
            hit = _relation_target(w, instruction, t) if not want else next(
                (n for n in names if all(getattr(w.objects[n], k) == v for k, v in want.items())), None)
            choice[role] = hit or names[0]
            continue
        # objects: inspect each candidate with a find (the text then names its looks and its place)
        host_type = next((ht for ht in ("cabinet", "drawer", "shelf", "side table", "counter", "dresser")
                          if re.search(rf"that is (in|on) the (leftmost |rightmost )?{ht}", instruction.lower())),
                         None)
        host = None
        if host_type is not None:
            ht = next(k for k, v in TYPES.items() if v.noun == host_type)
            host = _relation_target(w, instruction.split(" that is ", 1)[1], ht)
        hits = []
        for n in names:
            if not b.do(f"find a {n}"):
                return b.success
            o = w.objects[n]
            if host is not None and w.place_of(n) == host:
                hits.append(n)
            elif host is None and want and all(getattr(o, k) == v for k, v in want.items()):
                hits.append(n)
        need = 2 if role == "object" and goal["kind"] == "pick_two_and_place" else 1
        if len(hits) < need:
            hits += [n for n in names if n not in hits][: need - len(hits)]
        choice[role] = tuple(hits[:2]) if need == 2 else hits[0]
    _play_choice(b, goal, choice)
    return b.success
