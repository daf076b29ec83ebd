"""Build the in-context examples stored in ``examples.json`` and the visual examples' PNGs.

Each example is a held-out layout (seeds that no shipped task uses) with one of our instructions, the object
list exactly as the agent would see it, and an answer in the required JSON format whose plan is the scripted
expert's, checked in the simulator; the language plan describes each of those actions. The original's counts
per family are kept (pick 2, stack 4, sorter 4, wipe 8: four left/right strokes and four front/back ones).

Three sets per family (see :mod:`eb_manipulation.prompts` for when each is used): ``baseline`` (wiping grouped
by stroke axis), ``ablation`` (wiping alternating), ``language_only`` (baseline without the visual
description). The first two examples of the ablation set also get their front image (with boxes, labels and
axes, rendered from this world) for visual in-context learning, saved as ``visual_examples/<family>_<i>.png``.

The harder scenes get their own sets (``examples_hard.json``, ``visual_examples/hard_*.png``; same families, counts,
sets and answer format), drawn at difficulty ``hard`` from another held-out seed, because there orientation matters:
their reasoning and plans show a shape turned to its hole's outline (by how far it lies off the outline in the
image, and which way a yaw turns it), a cube turned to line up with the one below, and a stroke the way the
area's printed arrow points. The classic files are left as they are (the paper's protocol).

Rebuild with ``python -m eb_manipulation.examples`` (classic) or ``python -m eb_manipulation.examples --hard``.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from eb_manipulation.generate import make_task
from eb_manipulation.prompts import EXAMPLE_COUNTS, EXAMPLES_FILE, HARD_EXAMPLES_FILE, VISUAL_COUNT, VISUAL_DIR

__all__ = ["build_examples", "describe_action", "main"]

EXAMPLE_SEED = 7919  # never used for shipped tasks (those use seed 0)
HARD_EXAMPLE_SEED = 7927
"""Seed of the hard examples (difficulty ``hard``); never used for shipped tasks."""
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


def _turn_words(delta: int) -> str:
    """How a change of ``delta`` yaw bins turns the gripper (a larger yaw: counter-clockwise seen from above)."""
    return f"{abs(delta) * 3} degrees {'counter-clockwise' if delta > 0 else 'clockwise'}"


def describe_action(action, listing: dict[str, tuple[int, ...]], was_open: bool, held_before: str | None,
                    held_after: str | None, prev=None, say_turns: bool = False) -> str:
    """A short sentence for one 7-D action, naming the listed object it goes to (by the object list); with
    ``say_turns``, a carry that changes the yaw says how it turns the held object (the hard examples)."""
    x, y, z = action[:3]
    near = [(abs(p[0] - x) + abs(p[1] - y), name, p) for name, p in listing.items()
            if abs(p[0] - x) <= 3 and abs(p[1] - y) <= 3 and not (say_turns and name == held_before)]
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
        delta = int(action[5]) - int(prev[5]) if prev is not None else 0
        if say_turns and delta:
            return (f"carry {held_before} {where}, turning it {_turn_words(delta)} (yaw {prev[5]} to "
                    f"{action[5]})")
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


_ARROW_WORDS = {"left_to_right": "to the right", "right_to_left": "to the left",
                "front_to_back": "away from the camera", "back_to_front": "toward the camera"}


def _lies(delta: int) -> str:
    """Where a held object lies against what it must match, from the turn ``delta`` (bins) that fixes it."""
    return f"about {abs(delta) * 3} degrees {'clockwise' if delta > 0 else 'counter-clockwise'}"


def _hard_reason(scene, lab, turns: dict[str, tuple[int, int]]) -> str:
    """The reasoning of a hard example: what must be read from the image and how the plan uses it.
    ``turns``: per object the expert carried, (yaw bin when grasped, yaw bin when released)."""
    g = scene.goal
    keep = " Every other object must stay where it is, so I touch nothing else."
    if g.family == "sorter":
        sorter = next(o for o in scene.objects if o.kind == "sorter")
        parts = []
        for obj in g.sorted_ids:
            shape = scene.get(obj).shape_name
            hole = lab(f"{sorter.id}_hole{sorter.holes.index(shape)}")
            grab, drop = turns[obj]
            delta = drop - grab
            parts.append(f"{lab(obj)} ({shape}) lies {_lies(delta)} of the outline of its hole {hole} on the lid, "
                         f"so I grasp it with yaw {grab} and turn the gripper {_turn_words(delta)} to yaw {drop} "
                         f"before I drop it from just above {hole}")
        return (f"The shapes to sort are {lab(g.sorted_ids[0])} and then {lab(g.sorted_ids[1])}. Each must be turned "
                f"to match the outline drawn on the lid, and a larger yaw turns the gripper, and what it holds, "
                f"counter-clockwise seen from above. In the image, " + "; ".join(parts) + "." + keep)
    if g.family == "stack":
        lines = []
        for below, cube in zip(g.order, g.order[1:]):
            grab, drop = turns[cube]
            delta = drop - grab
            lines.append(f"{lab(cube)} sits {_lies(delta)} of {lab(below)}, so I grasp it with yaw {grab} and "
                         f"release it above {lab(below)} with yaw {drop}, turned {_turn_words(delta)}")
        return (f"The tower must be, from the bottom up: {', '.join(lab(o) for o in g.order)}, and flush: each cube "
                f"turned so its sides line up with the cube below (a larger yaw turns the gripper counter-clockwise "
                f"seen from above). In the image, " + "; ".join(lines) + "." + keep)
    if g.family == "wipe":
        start, end = _EDGES[g.stroke]
        a = lab(g.area_id)
        arrow = _ARROW_WORDS[next(o for o in scene.objects if o.id == g.area_id).arrow or g.stroke]
        return (f"The sponge is {lab(g.target_id)} and the area to clean is {a}. The arrow printed on {a} points "
                f"{arrow} in the image, so the stroke must run from its {start} edge to its {end} edge: I grasp the "
                f"sponge, put it down just outside the {start} edge of {a} at the height where I picked it up, and "
                f"drag it to the {end} edge without lifting it, keeping it off every other area.")
    return _reason(scene, lab) + keep


def _visual_line(scene, env, o, listing) -> str:
    """One object of the visual description; in a hard example an area also says where its arrow points."""
    line = f"{o.name} is {_a(o.type)} at {list(listing[o.name])}"
    key = env._order[int(o.name.split()[-1]) - 1]
    spec = next((s for s in scene.objects if s.id == key), None)
    if spec is not None and spec.arrow is not None:
        line += f" with its arrow pointing {_ARROW_WORDS[spec.arrow]}"
    return line


def _one(env, raw: dict, hard: bool = False):
    """(text without the visual description, visual description, front image or None) for one example, or None
    when the expert does not solve it."""
    from eb_core.env import Task
    from eb_manipulation.spec import SceneSpec

    task = Task(**raw)
    obs = env.reset(task, 0)
    scene = SceneSpec.model_validate(raw["metadata"])
    listing = {o.name: tuple(int(v) for v in o.position) for o in obs.objects}
    visual = "From left to right: " + "; ".join(_visual_line(scene, env, o, listing) for o in obs.objects) + "."
    turns: dict[str, tuple[int, int]] = {}  # object carried -> (yaw bin at the grasp, yaw bin at the release)
    image = obs.images.get("front")
    steps, plan, was_open, held = [], [], True, None
    result = None
    first = {key: env._label(key) for key in env._order}  # numbers of the object list the example shows
    while result is None or not result.done:  # one plan, or (two shapes to sort) one plan per part, until done
        part = env.expert_plan() or []
        if not part or len(plan) + len(part) > 15:
            return None
        for a in part:
            result = env.step(a)
            held_key = env._world.held
            held_after = first[held_key] if held_key is not None else None
            if held_key is not None and held is None:
                turns[held_key] = (int(a[5]), int(a[5]))
            elif held is not None and held_after is None:
                key = next(k for k, v in first.items() if v == held)
                turns[key] = (turns[key][0], int(a[5]))
            steps.append(describe_action(a, listing, was_open, held, held_after, prev=plan[-1] if plan else None,
                                         say_turns=hard))
            plan.append(a)
            was_open, held = result.info.get("gripper_open", was_open), held_after
            if result.done:
                break
        if not hard and (not result.done or len(plan) != len(part)):
            return None  # classic: one plan that ends exactly when the task does (how examples.json was built)
        if not result.done and not result.action_success:
            return None
    if not result.task_success:
        return None
    lab = first.get  # objects named by the list the example shows (numbers change as things move)
    reason = _hard_reason(scene, lab, turns) if hard else _reason(scene, lab)
    language = " ".join(f"{i + 1}. {s[0].upper()}{s[1:]}." for i, s in enumerate(steps))
    answer = {"reasoning_and_reflection": reason, "language_plan": language,
              "executable_plan": [{"action": list(map(int, a))} for a in plan]}
    head = f"Instruction: {raw['instruction']}\nObject list: {obs.extra_prompt}\nAnswer:\n"
    with_visual = head + json.dumps({"visual_state_description": visual, **answer})
    without = head + json.dumps(answer)
    return with_visual, without, image


def build_examples(seed: int = EXAMPLE_SEED, level: int = 0) -> tuple[dict, dict[str, list[np.ndarray]]]:
    """The example sets per family, and the front images of the visual examples; ``level`` 2: the hard sets
    (scenes of difficulty ``hard``, whose expert plans leave 4 of the 15 steps spare)."""
    from eb_manipulation.env import ManipulationEnv
    from eb_manipulation.generate import _Retry

    env = ManipulationEnv(resolution=VISUAL_RESOLUTION)
    sets: dict[str, dict[str, list[str]]] = {}
    images: dict[str, list[np.ndarray]] = {}
    try:
        for family, picks in PLAN.items():
            made = []
            for subset, k in picks:
                for attempt in range(40 if level < 2 else 300):
                    try:
                        raw = make_task(seed, subset, family, k, attempt, level)
                    except _Retry:
                        continue
                    one = _one(env, raw, hard=level >= 2)
                    if one is not None and (level < 2 or one[1].count('{"action"') <= 11):
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


def main(path: Path = EXAMPLES_FILE, hard: bool = False) -> None:
    from PIL import Image

    if hard and path == EXAMPLES_FILE:
        path = HARD_EXAMPLES_FILE
    seed = HARD_EXAMPLE_SEED if hard else EXAMPLE_SEED
    prefix = "hard_" if hard else ""
    sets, images = build_examples(seed, level=2 if hard else 0)
    VISUAL_DIR.mkdir(exist_ok=True)
    visual: dict[str, list[dict[str, str]]] = {}
    for family, imgs in images.items():
        texts = sets[family].pop("_visual_text")
        visual[family] = []
        for i, (img, text) in enumerate(zip(imgs, texts)):
            name = f"{prefix}{family}_{i + 1}.png"
            buf = io.BytesIO()  # a 256-colour palette keeps the shipped PNGs small
            Image.fromarray(img).quantize(colors=256).save(buf, format="PNG", optimize=True)
            (VISUAL_DIR / name).write_bytes(buf.getvalue())
            visual[family].append({"text": text, "image": name})
    doc = {"seed": seed, **({"difficulty": "hard"} if hard else {}), "examples": sets, "visual": visual}
    path.write_text(json.dumps(doc, indent=1) + "\n")
    n = sum(len(v["baseline"]) for v in sets.values())
    print(f"wrote {n} examples per set and {sum(len(v) for v in visual.values())} visual examples to {path.parent}")


if __name__ == "__main__":
    import sys

    main(hard="--hard" in sys.argv[1:])
