"""Build the in-context examples stored in ``examples.json`` and the visual examples' PNGs.

Each example is a held-out layout (seeds that no shipped task uses) with one of our instructions, the object
list exactly as the agent would see it, and an answer in the required JSON format whose plan is the scripted
expert's, checked in the simulator; the language plan describes each of those actions. The original's counts
per family are kept (pick 2, stack 4, sorter 4, wipe 8: four left/right strokes and four front/back ones).

Three sets per family (see :mod:`eb_manipulation.prompts` for when each is used): ``baseline`` (wiping grouped
by stroke axis), ``ablation`` (wiping alternating), ``language_only`` (baseline without the visual
description). The first two examples of the ablation set also get their front image (with boxes, labels and
axes, rendered from this world) for visual in-context learning, saved as ``visual_examples/<family>_<i>.png``.

Rebuild with ``python -m eb_manipulation.examples``.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from eb_manipulation.generate import make_task
from eb_manipulation.prompts import EXAMPLE_COUNTS, EXAMPLES_FILE, VISUAL_COUNT, VISUAL_DIR

__all__ = ["build_examples", "describe_action", "main"]

EXAMPLE_SEED = 7919  # never used for shipped tasks (those use seed 0)
#: Resolution of the visual examples' images (small PNGs shipped in the package).
VISUAL_RESOLUTION = 336
#: (subset, k) per example: mostly plain wording, with other kinds mixed in so the model sees variety. For wiping
#: the direction is DIRECTIONS[k % 4]: k % 4 in (0, 1) strokes left/right, (2, 3) front/back.
PLAN = {
    "pick": [("base", 0), ("spatial", 1)],
    "stack": [("base", 1), ("base", 0), ("common_sense", 3), ("spatial", 2)],
    "sorter": [("base", 0), ("visual", 1), ("base", 2), ("spatial", 3)],
    "wipe": [("base", 0), ("base", 1), ("common_sense", 4), ("spatial", 5),
             ("base", 2), ("base", 3), ("common_sense", 6), ("spatial", 7)],
}

_EDGES = {"left_to_right": ("left", "right"), "right_to_left": ("right", "left"),
          "front_to_back": ("front", "back"), "back_to_front": ("back", "front")}


def _a(noun: str) -> str:
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def describe_action(action, listing: dict[str, tuple[int, ...]], was_open: bool, held_before: str | None,
                    held_after: str | None, prev=None) -> str:
    """A short sentence for one 7-D action, naming the listed object it goes to (by the object list)."""
    x, y, z = action[:3]
    near = [(abs(p[0] - x) + abs(p[1] - y), name, p) for name, p in listing.items()
            if abs(p[0] - x) <= 3 and abs(p[1] - y) <= 3]
    where = f"to [{x}, {y}, {z}]"
    if near:
        _, name, p = min(near)
        where = f"{'above' if z >= p[2] + 4 else 'down to'} {name} ([{x}, {y}, {z}])"
    stays = prev is not None and tuple(prev[:6]) == tuple(action[:6])
    move = "" if stays else f"move {where} and "
    want_open = bool(action[6])
    if held_before is not None and held_after is None:
        return f"{move}open the gripper to let go of {held_before}"
    if held_after is not None and held_before is None:
        return f"{move}close the gripper on {held_after}"
    if want_open != was_open:
        return f"{move}{'open' if want_open else 'close'} the gripper"
    if held_before is not None:
        return f"carry {held_before} {where}"
    return f"move the open gripper {where}" if want_open else f"move the closed gripper {where}"


def _reason(scene, lab) -> str:
    g = scene.goal
    if g.family == "stack":
        return (f"The tower must be, from the bottom up: {', '.join(lab(o) for o in g.order)}. I take each cube "
                f"from above and release it just above the one below, turned to match it; a cube already in place "
                f"stays, and anything in the way is put aside first.")
    if g.family == "pick":
        t, c = lab(g.target), lab(g.container)
        return (f"The object to move is {t} and the container is {c}. I grasp {t} at its centre from above and "
                f"release it a few centimetres above the opening of {c}.")
    if g.family == "sorter":
        sorter = next(o for o in scene.objects if o.kind == "sorter")
        shape = scene.get(g.target).shape
        h = lab(f"{sorter.id}_hole{sorter.holes.index(shape)}")
        return (f"The object I need is {lab(g.target)}; its shape matches the hole {h}. I pick it up, turn it to "
                f"fit the hole and drop it in from just above the lid.")
    start, end = _EDGES[g.direction]
    a = lab(g.area)
    return (f"The sponge is {lab(g.target)} and the area to clean is {a}. I grasp the sponge, put it down just "
            f"outside the {start} edge of {a} at the height where I picked it up, and drag it to the {end} edge "
            f"without lifting it.")


def _one(env, raw: dict):
    """(text without the visual description, visual description, front image or None) for one example, or None
    when the expert does not solve it."""
    from eb_core.env import Task

    from eb_manipulation.spec import SceneSpec

    task = Task(**raw)
    obs = env.reset(task, 0)
    listing = {o.name: tuple(int(v) for v in o.position) for o in obs.objects}
    visual = "From left to right: " + "; ".join(f"{o.name} is {_a(o.type)} at {list(listing[o.name])}"
                                                for o in obs.objects) + "."
    reason = _reason(SceneSpec.model_validate(raw["metadata"]), env._label)
    image = obs.images.get("front")
    plan = env.expert_plan() or []
    steps, steps_actions, was_open, held = [], [], True, None
    result = None
    first = {key: env._label(key) for key in env._order}  # numbers of the object list the example shows
    for a in plan:
        result = env.step(a)
        held_after = first[env._world.held] if env._world.held is not None else None
        steps.append(describe_action(a, listing, was_open, held, held_after, prev=steps_actions[-1] if steps_actions
                                     else None))
        steps_actions.append(a)
        was_open, held = result.info.get("gripper_open", was_open), held_after
        if result.done:
            break
    if result is None or not result.task_success or len(steps) != len(plan):
        return None
    language = " ".join(f"{i + 1}. {s[0].upper()}{s[1:]}." for i, s in enumerate(steps))
    answer = {"reasoning_and_reflection": reason, "language_plan": language,
              "executable_plan": [{"action": list(map(int, a))} for a in plan]}
    head = f"Instruction: {raw['instruction']}\nObject list: {obs.extra_prompt}\nAnswer:\n"
    with_visual = head + json.dumps({"visual_state_description": visual, **answer})
    without = head + json.dumps(answer)
    return with_visual, without, image


def build_examples(seed: int = EXAMPLE_SEED) -> tuple[dict, dict[str, list[np.ndarray]]]:
    """The example sets per family, and the front images of the visual examples."""
    from eb_manipulation.env import ManipulationEnv
    from eb_manipulation.generate import _Retry

    env = ManipulationEnv(resolution=VISUAL_RESOLUTION)
    sets: dict[str, dict[str, list[str]]] = {}
    images: dict[str, list[np.ndarray]] = {}
    try:
        for family, picks in PLAN.items():
            made = []
            for subset, k in picks:
                for attempt in range(40):
                    try:
                        raw = make_task(seed, subset, family, k, attempt)
                    except _Retry:
                        continue
                    one = _one(env, raw)
                    if one is not None:
                        made.append(one)
                        break
                else:
                    raise RuntimeError(f"no solvable example for {family}/{subset}/{k}")
            assert len(made) == EXAMPLE_COUNTS[family]
            order = list(range(len(made)))
            if family == "wipe":  # alternate the stroke axis: 0, 4, 1, 5, ...
                half = len(made) // 2
                ablation = [i for pair in zip(range(half), range(half, len(made))) for i in pair]
            else:
                ablation = order
            sets[family] = {"baseline": [made[i][0] for i in order], "ablation": [made[i][0] for i in ablation],
                            "language_only": [made[i][1] for i in order]}
            images[family] = [made[i][2] for i in ablation[:VISUAL_COUNT]]
            sets[family]["_visual_text"] = [made[i][0] for i in ablation[:VISUAL_COUNT]]
    finally:
        env.close()
    return sets, images


def main(path: Path = EXAMPLES_FILE) -> None:
    from PIL import Image

    sets, images = build_examples()
    VISUAL_DIR.mkdir(exist_ok=True)
    visual: dict[str, list[dict[str, str]]] = {}
    for family, imgs in images.items():
        texts = sets[family].pop("_visual_text")
        visual[family] = []
        for i, (img, text) in enumerate(zip(imgs, texts)):
            name = f"{family}_{i + 1}.png"
            buf = io.BytesIO()  # a 256-colour palette keeps the shipped PNGs small
            Image.fromarray(img).quantize(colors=256).save(buf, format="PNG", optimize=True)
            (VISUAL_DIR / name).write_bytes(buf.getvalue())
            visual[family].append({"text": text, "image": name})
    path.write_text(json.dumps({"seed": EXAMPLE_SEED, "examples": sets, "visual": visual}, indent=1) + "\n")
    n = sum(len(v["baseline"]) for v in sets.values())
    print(f"wrote {n} examples per set and {sum(len(v) for v in visual.values())} visual examples to {path.parent}")


if __name__ == "__main__":
    main()
