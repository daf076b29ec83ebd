"""Build the in-context examples (four per family) stored in ``examples.json``.

Each example is a held-out layout (seeds that no shipped task uses) with one of our instructions, the object
list exactly as the agent would see it, and an answer in the required JSON format whose plan is the scripted
oracle's, checked in the simulator. The explanatory text is written from per-family templates.

Rebuild with ``python -m eb_manipulation.examples``.
"""

from __future__ import annotations

import json
from pathlib import Path

from eb_manipulation.generate import make_task
from eb_manipulation.prompts import EXAMPLES_FILE

__all__ = ["build_examples", "main"]

EXAMPLE_SEED = 7919  # never used for shipped tasks (those use seed 0)
#: (subset, k) per example: mostly plain wording, with one other kind each, so the model sees variety.
PLAN = {
    "pick": [("base", 0), ("spatial", 1), ("common_sense", 2), ("base", 3)],
    "stack": [("base", 1), ("base", 0), ("spatial", 2), ("common_sense", 3)],
    "sorter": [("base", 0), ("visual", 1), ("base", 2), ("spatial", 3)],
    "wipe": [("base", 0), ("base", 1), ("spatial", 2), ("common_sense", 3)],
}

_STEP_TEXT = {
    "pick": ["move above {t} with the gripper open", "lower to the centre of {t}", "close the gripper on {t}",
             "lift {t}", "move it over {c}", "open the gripper to drop it in"],
    "sorter": ["move above {t} with the gripper open", "lower to the centre of {t}", "close the gripper on {t}",
               "lift {t}", "carry it over {h}, turned to line up with the hole", "lower it just above {h}",
               "open the gripper so it drops through"],
    "wipe": ["move above {t} with the gripper open", "lower to the sponge", "close the gripper on the sponge",
             "carry it over the {start} edge of {a}", "lower it until it touches the table",
             "sweep it across {a} to the {end} edge"],
}
_EDGES = {"left_to_right": ("left", "right"), "right_to_left": ("right", "left"),
          "front_to_back": ("front", "back"), "back_to_front": ("back", "front")}


def _a(noun: str) -> str:
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def _answer(task: dict, obs, env, plan: list[tuple[int, ...]]) -> dict:
    from eb_manipulation.spec import SceneSpec

    scene = SceneSpec.model_validate(task["metadata"])
    g = scene.goal
    lab = env._label
    seen = "; ".join(f"{o.name} is {_a(o.type)}" for o in obs.objects)
    visual = f"I see {len(obs.objects)} numbered objects: {seen}."
    steps: list[str] = []
    if g.family == "stack":
        pairs = list(zip(g.order[:-1], g.order[1:]))
        reason = (f"The tower must be, from the bottom up: {', '.join(lab(o) for o in g.order)}. "
                  f"I pick each cube from above and release it just above the previous one, "
                  f"turning it to match the cube below.")
        for below, above in pairs:
            steps += [f"move above {lab(above)} with the gripper open", f"lower to {lab(above)}",
                      f"close the gripper on {lab(above)}", f"carry it over {lab(below)}",
                      f"lower it onto {lab(below)}", "open the gripper"]
        if len(steps) != len(plan):  # the oracle skipped a step because a cube was already in place
            steps = [f"action {i + 1}" for i in range(len(plan))]
    elif g.family == "pick":
        t, c = lab(g.target), lab(g.container)  # type: ignore[arg-type]
        reason = (f"The object to move is {t} and the container is {c}. I grasp {t} at its centre from above, lift "
                  f"it clear of the other objects and release it a few centimetres above the opening of {c}.")
        steps = [s.format(t=t, c=c) for s in _STEP_TEXT["pick"]]
    elif g.family == "sorter":
        t = lab(g.target)  # type: ignore[arg-type]
        shape = scene.get(g.target).shape  # type: ignore[arg-type]
        sorter = next(o for o in scene.objects if o.kind == "sorter")
        h = lab(f"{sorter.id}_hole{sorter.holes.index(shape)}")  # type: ignore[arg-type]
        reason = (f"The object I need is {t}; its shape matches the hole {h}. I pick it up, turn it to fit the hole "
                  f"and drop it in from just above the lid.")
        steps = [s.format(t=t, h=h) for s in _STEP_TEXT["sorter"]]
    else:
        a = lab(g.area)  # type: ignore[arg-type]
        start, end = _EDGES[g.direction]  # type: ignore[index]
        t = lab(g.target)  # type: ignore[arg-type]
        reason = (f"The sponge is {t} and the area to clean is {a}. I grasp the sponge across its short side, put it "
                  f"down just outside the {start} edge of {a} at the height where I picked it up, and drag it to "
                  f"the {end} edge without lifting it.")
        steps = [s.format(t=t, a=a, start=start, end=end) for s in _STEP_TEXT["wipe"]]
    if len(steps) != len(plan):
        steps = [f"action {i + 1}" for i in range(len(plan))]
    language = " ".join(f"{i + 1}. {s[0].upper()}{s[1:]}." for i, s in enumerate(steps))
    return {
        "visual_state_description": visual,
        "reasoning_and_reflection": reason,
        "language_plan": language,
        "executable_plan": [{"action": list(map(int, a))} for a in plan],
    }


def build_examples(seed: int = EXAMPLE_SEED) -> dict[str, list[str]]:
    """Four verified examples per family, as prompt-ready text."""
    from eb_core.env import Task

    from eb_manipulation.env import ManipulationEnv
    from eb_manipulation.generate import _Retry

    env = ManipulationEnv(render=False)
    out: dict[str, list[str]] = {}
    try:
        for family, picks in PLAN.items():
            texts: list[str] = []
            for subset, k in picks:
                for attempt in range(40):
                    try:
                        raw = make_task(seed, subset, family, k, attempt)
                    except _Retry:
                        continue
                    task = Task(**raw)
                    obs = env.reset(task, 0)
                    plan = env.expert_plan() or []
                    result = None
                    for a in plan:
                        result = env.step(a)
                        if result.done or not result.action_success:
                            break
                    if result is None or not result.task_success:
                        continue
                    obs = env.reset(task, 0)
                    answer = _answer(raw, obs, env, plan)
                    texts.append(f"Instruction: {raw['instruction']}\n{obs.extra_prompt}\nAnswer:\n"
                                 + json.dumps(answer))
                    break
                else:
                    raise RuntimeError(f"no solvable example for {family}/{subset}/{k}")
            out[family] = texts
    finally:
        env.close()
    return out


def main(path: Path = EXAMPLES_FILE) -> None:
    examples = build_examples()
    path.write_text(json.dumps({"seed": EXAMPLE_SEED, "examples": examples}, indent=1) + "\n")
    print(f"wrote {sum(len(v) for v in examples.values())} examples to {path}")


if __name__ == "__main__":
    main()
