"""Builds the in-context examples (``examples.json``) from expert plans on held-out scenes of our world.

The examples have the original's form: one turn, an instruction followed by the answer with a
``language_plan`` (what the robot will do, in prose) and an ``executable_plan`` (action ids and names). They
carry no perception text and no list of the room's furniture, and keep a fixed order. The general set (10)
walks through every task type; long_horizon has its own set (7) of long, multi-stage tasks, as the original
has. Examples use un-suffixed names (whose ids are the same in every room) wherever a scene allows it.

Each example is stored with the scene and goal it was written from, so a test replays its plan in that scene
and checks that every action succeeds, every id matches the action list there, and the goal is reached.
Run ``python -m eb_alfred.examples`` to rebuild the file.
"""

from __future__ import annotations

import json
import random
from typing import Any

from eb_alfred.actions import scene_actions
from eb_alfred.catalog import KNIVES, TYPES
from eb_alfred.goals import GOAL_KINDS
from eb_alfred.oracle import expert_plan
from eb_alfred.prompts import EXAMPLES_PATH
from eb_alfred.world import World, instance_index, parse_action

__all__ = ["build_examples", "language_plan", "example_text"]

_ORDINAL = {2: "second", 3: "third", 4: "fourth", 5: "fifth", 6: "sixth", 7: "seventh", 8: "eighth"}


def _name(instance: str) -> str:
    base, idx = instance_index(instance)
    noun = TYPES[base].noun if base in TYPES else base
    if idx == 1:
        return f"the {noun}"
    return f"the {_ORDINAL[idx]} {noun}" if idx in _ORDINAL else f"{noun} number {idx}"


def _phrase(verb: str, target: str | None, world: World) -> str:
    """Our words for one action in ``world`` (the state just before it)."""
    what = _name(target) if target else ""
    if verb == "find":
        return f"go to {what}"
    if verb == "pickup":
        return f"pick up {what}"
    held = _name(world.held) if world.held else "it"
    if verb == "put":
        recep = world.target_recep
        if recep is None:
            return f"put {held} down"
        word = "in" if TYPES[world.objects[recep].type].openable or world.objects[recep].type in _INTO else "on"
        return f"put {held} {word} {_name(recep)}"
    if verb == "drop":
        return f"drop {held}"
    if verb == "open":
        return f"open {what}"
    if verb == "close":
        return f"close {what}"
    if verb == "toggle_on":
        return f"switch on {what}"
    if verb == "toggle_off":
        return f"switch off {what}"
    return f"cut {what} into slices"


_INTO = {"SinkBasin", "BathtubBasin", "GarbageCan", "Bowl", "Cup", "Mug", "Pot", "Pan", "Box", "LaundryHamper"}


def language_plan(plan: list[str], world: World) -> str:
    """A short prose version of ``plan`` in ``world``: sentences of up to three steps, in our own words."""
    phrases: list[str] = []
    sim = world.copy()
    for action in plan:
        verb, target = parse_action(action)
        if target is not None and verb != "find":
            target = sim.resolve(verb, target)  # say which one the plain name acts on
        phrases.append(_phrase(verb, target, sim))
        sim.step(action)
    chunks = [phrases[i:i + 3] for i in range(0, len(phrases), 3)]
    sentences = []
    for i, chunk in enumerate(chunks):
        body = chunk[0] if len(chunk) == 1 else ", ".join(chunk[:-1]) + " and " + chunk[-1]
        opener = "First I" if i == 0 else ("Finally I" if i == len(chunks) - 1 else "Then I")
        sentences.append(f"{opener} {body}." if len(chunks) > 1 else f"I {body}.")
    return " ".join(sentences)


def example_text(instruction: str, world: World, plan: list[str]) -> str:
    """The example as the model sees it: the instruction, then the JSON answer."""
    actions = scene_actions(world)
    answer = {
        "language_plan": language_plan(plan, world),
        "executable_plan": [{"action_id": actions.index(a), "action_name": a} for a in plan],
    }
    return f"Instruction: {instruction}\nAnswer: {json.dumps(answer, ensure_ascii=False)}"


def _plain(plan: list[str]) -> bool:
    """True if every action is un-suffixed (its id is then the same in every room)."""
    return all("_" not in a.split()[-1] for a in plan)


def _knife_in_appliance(world: World, plan: list[str]) -> bool:
    """True if the plan parks a knife in a microwave or fridge (valid, but a poor thing to teach)."""
    sim = world.copy()
    for action in plan:
        held = sim.held
        sim.step(action)
        if action == "put down the object in hand" and held and sim.objects[held].type in KNIVES:
            parent = sim.objects[held].parent
            if parent and sim.objects[parent].type in ("Microwave", "Fridge"):
                return True
    return False


def build_examples(seed: int = 7) -> dict[str, list[dict[str, Any]]]:
    from eb_alfred.draw import make_one as _make_one  # the task generator's candidate maker (scenes, goals, wording)

    from eb_alfred.tasks import load_all

    shipped = {r.instruction for r in load_all()}  # no example may read like a benchmark task
    rng = random.Random(f"eb-alfred-examples/{seed}")
    out: dict[str, list[dict[str, Any]]] = {"general": [], "long_horizon": []}
    for key, subset, count in (("general", "base", 10), ("long_horizon", "long_horizon", 7)):
        scene_seed = 900_000 + (0 if key == "general" else 50_000)
        kinds = list(GOAL_KINDS) if key == "general" else [
            "heat_and_place", "cool_and_place", "pick_two_and_place", "clean_and_place", "stack_and_place"]
        turn = 0
        while len(out[key]) < count:
            kind = kinds[turn % len(kinds)]
            turn += 1
            for tries in range(80):  # plain names where the scenes allow it, else the first that works
                scene_seed += 1
                rec = _make_one(subset, kind, scene_seed, rng)
                if rec is None or rec["instruction"] in shipped:
                    continue
                world = World.from_scene(rec["scene"])
                plan = expert_plan(world, rec["goal"])
                if not plan or (not _plain(plan) and tries < 40) or _knife_in_appliance(world, plan):
                    continue
                out[key].append({"text": example_text(rec["instruction"], world, plan), "scene": rec["scene"],
                                 "goal": rec["goal"], "scene_seed": scene_seed})
                break
    return out


if __name__ == "__main__":
    data = build_examples()
    EXAMPLES_PATH.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print("wrote", EXAMPLES_PATH, {k: len(v) for k, v in data.items()})
