"""Builds the in-context examples (``examples.json``) from oracle traces on held-out scenes.

Each example is a full worked episode: the instruction, then the JSON answer the model should give. Some
examples also show a second turn: a failed action with its feedback and the corrected answer, so the model
sees how to learn from feedback. Run ``python -m eb_alfred.examples`` to rebuild the file.
"""

from __future__ import annotations

import json
import random
from typing import Any

from eb_alfred.actions import scene_actions
from eb_alfred.describe import describe
from eb_alfred.generate import _make_one
from eb_alfred.goals import GOAL_KINDS
from eb_alfred.oracle import expert_plan
from eb_alfred.prompts import EXAMPLES_PATH
from eb_alfred.world import World

__all__ = ["build_examples"]

_WHY = {
    "pick_and_place": "The {x} has to end up {p} the {r}. I get it and put it there.",
    "pick_two_and_place": "Two {x} instances have to end up {p} the {r}. I move them there one at a time, since I can only hold one object.",
    "stack_and_place": "The {x} has to be inside the {m}, and the {m} {p} the {r}. I put the {x} into the {m} first, then carry the {m} (with the {x} in it) to the {r}.",
    "clean_and_place": "The {x} must be washed and then placed {p} the {r}. Washing means putting it in the sink basin and running the faucet; then I take it out and bring it over.",
    "heat_and_place": "The {x} must be hot and end up {p} the {r}. I heat it in the microwave: open it, put the {x} in, close it, switch it on and off, open it and take the {x} out; then I bring it over.",
    "cool_and_place": "The {x} must be cold and end up {p} the {r}. I cool it in the fridge: open it, put the {x} in, close it so it chills, open it again and take it out; then I bring it over.",
    "examine_in_light": "I must hold the {x} next to a lit {l}. I pick up the {x}, go to the {l} and switch it on while holding it.",
}
_SLICE = " The task wants it sliced, so first I pick up a knife, slice it where it lies, and put the knife down before taking the slices."


def _words(goal: dict[str, Any], world: World) -> dict[str, str]:
    def name(ref: dict[str, str]) -> str:
        return ref.get("instance") or ref["type"]
    w = {"x": name(goal["object"]), "p": "in/on"}
    if "receptacle" in goal:
        from eb_alfred.instructions import prep
        rt = goal["receptacle"].get("type") or world.objects[goal["receptacle"]["instance"]].type
        w["r"], w["p"] = name(goal["receptacle"]), prep(rt)
    if "movable" in goal:
        w["m"] = name(goal["movable"])
    if "lamp" in goal:
        w["l"] = name(goal["lamp"])
    return w


def _answer(world: World, goal: dict[str, Any], plan: list[str], reflection: str = "") -> str:
    actions = scene_actions(world)
    text = describe(world)
    visual = text.split(" Your hand")[0]
    why = _WHY[goal["kind"]].format(**_words(goal, world))
    if goal.get("sliced") and not all(world.objects[x].is_sliced for x in world.of_type(goal["object"].get("type", "")) or []):
        why += _SLICE
    body = {
        "visual_state_description": visual,
        "reasoning_and_reflection": (reflection + " " if reflection else "") + why,
        "language_plan": " ".join(f"{i}. {a[0].upper() + a[1:]}." for i, a in enumerate(plan, 1)),
        "executable_plan": [{"action_id": actions.index(a), "action_name": a} for a in plan],
    }
    return json.dumps(body, ensure_ascii=False)


def _mistake(plan: list[str]) -> int | None:
    """Index of an 'open' step that, if skipped, makes the next action fail (to show a feedback turn)."""
    for i, a in enumerate(plan[:-1]):
        if a.startswith("open the "):
            return i
    return None


def _episode(n: int, rec: dict[str, Any], with_feedback: bool, plain_names: bool) -> str | None:
    world = World.from_scene(rec["scene"])
    goal = rec["goal"]
    plan = expert_plan(world, goal)
    if not plan or (plain_names and any("_" in a.split()[-1] for a in plan)):
        return None  # general examples use unsuffixed names, whose ids are the same in every scene
    head = f"Instruction: {rec['instruction']}\n"
    skip = _mistake(plan) if with_feedback else None
    if skip is None:
        return head + "Answer: " + _answer(world, goal, plan)
    first = plan[:skip] + plan[skip + 1:]
    out = head + "Answer: " + _answer(world, goal, first) + "\n"
    sim = world.copy()
    actions = scene_actions(world)
    history = []
    for a in first:
        ok, fb = sim.step(a)
        history.append(f"action id {actions.index(a)}: {a}, feedback: {fb}")
        if not ok:
            break
    rest = expert_plan(sim, goal)
    if not rest:
        return None
    out += "Execution stopped at the failed action. Action history:\n" + "\n".join(history) + "\n"
    reflection = ("The last action failed because " + fb.split(": ", 1)[-1][0].lower() + fb.split(": ", 1)[-1][1:]
                  + " I fix that first and continue from the current state.")
    sim.history.clear()
    out += "Answer: " + _answer(sim, goal, rest, reflection)
    return out


def build_examples(seed: int = 7) -> dict[str, list[str]]:
    rng = random.Random(f"eb-alfred-examples/{seed}")
    out: dict[str, list[str]] = {"general": [], "long_horizon": []}
    for key, subset, count in (("general", "base", 10), ("long_horizon", "long_horizon", 7)):
        scene_seed = 900_000 + (0 if key == "general" else 50_000)
        i = 0
        while len(out[key]) < count:
            kind = GOAL_KINDS[len(out[key]) % len(GOAL_KINDS)] if subset == "base" else rng.choice(
                ["heat_and_place", "cool_and_place", "clean_and_place", "pick_two_and_place"])
            scene_seed += 1
            i += 1
            rec = _make_one(subset, kind, scene_seed, rng)
            if rec is None:
                continue
            ep = _episode(len(out[key]) + 1, rec, with_feedback=len(out[key]) % 3 == 2,
                          plain_names=False)
            if ep is not None:
                out[key].append(ep)
    return out


if __name__ == "__main__":
    data = build_examples()
    EXAMPLES_PATH.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print("wrote", EXAMPLES_PATH, {k: len(v) for k, v in data.items()})
