"""The contact sheet of first-person views in the docs (``python -m eb_alfred.gallery``).

It replays oracle plans of a few shipped tasks with rendering on and keeps the frame after chosen actions, so the
sheet shows what a model sees: the found object in view, doors open or closed, objects held, sliced, inside
receptacles, appliances on.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

__all__ = ["views", "main", "audit_views", "audit_sheets"]

# (task type or subset filter, room, action prefix whose frame to keep, label)
_SHOTS = [
    ("start", "kitchen", None, "start: middle of a kitchen"),
    ("visual_appearance", None, "twins", "two look-alikes in view"),
    ("cool_and_place", "kitchen", "open the Fridge", "fridge open"),
    ("heat_and_place", "kitchen", "put down the object in hand", "in the open microwave"),
    ("heat_and_place", "kitchen", "turn on the Microwave", "microwave closed, on"),
    ("clean_and_place", "kitchen", "turn on the Faucet", "faucet running"),
    ("long_horizon", "kitchen", "sliced", "holding slices"),
    ("pick_and_place", None, "open the Drawer", "drawer open"),
    ("examine_in_light", "bedroom", "turn on the DeskLamp", "held under a lit desk lamp"),
    ("examine_in_light", "living_room", "turn on the FloorLamp", "floor lamp on"),
    ("stack_and_place", None, "carry", "carrying a dish with a thing in it"),
    ("pick_and_place", "bathroom", "find a", "bathroom"),
]


def _twins_in_view(env) -> bool:
    """Two visible instances of one pickupable type at the agent's place."""
    from eb_alfred.catalog import TYPES
    from eb_alfred.describe import visible_at_place

    w = env.world
    if w.place is None:
        return False
    seen = [n for n in visible_at_place(w, w.place) if TYPES[w.objects[n].type].pickupable]
    types = [w.objects[n].type for n in seen]
    return any(types.count(t) >= 2 for t in types)


def views(resolution: int = 500) -> tuple[list[np.ndarray], list[str]]:
    from eb_alfred.env import AlfredEnv

    env = AlfredEnv(resolution=resolution, render=True)
    tasks = AlfredEnv.load_tasks()
    images, labels = [], []
    used: set[str] = set()
    try:
        for kind, room, prefix, label in _SHOTS:
            got = None
            for t in tasks:
                if t.id in used:
                    continue
                if kind == "start":
                    if t.metadata["scene"]["room"] != room:
                        continue
                elif kind in ("visual_appearance", "long_horizon"):
                    if t.subset != kind:
                        continue
                elif t.metadata["task_type"] != kind or t.subset not in ("base", "spatial_awareness"):
                    continue
                if room and t.metadata["scene"]["room"] != room:
                    continue
                obs = env.reset(t, 0)
                if prefix is None:
                    got = obs.images["first_person"]
                else:
                    names = env.action_space().actions
                    for a in env.expert_plan() or []:
                        name = names[a]
                        r = env.step(a)
                        if prefix == "twins":
                            hit = _twins_in_view(env)
                        elif prefix == "sliced":
                            hit = env.world.held is not None and env.world.objects[env.world.held].is_sliced
                        elif prefix == "carry":
                            hit = env.world.held is not None and bool(env.world.children(env.world.held))
                        else:
                            hit = name.startswith(prefix)
                        if hit and r.action_success:
                            got = r.observation.images["first_person"]
                            label = f"{label}: {name}"
                            break
                if got is not None:
                    used.add(t.id)
                    break
            if got is not None:
                images.append(got)
                labels.append(label)
    finally:
        env.close()
    return images, labels


def main(out: str = "docs/img/alfred_views.png", resolution: int = 500, scale: float = 0.5) -> Path:
    from PIL import Image

    from eb_scenekit.render import contact_sheet, save_png

    images, labels = views(resolution)
    size = int(resolution * scale)
    small = [np.asarray(Image.fromarray(im).resize((size, size), Image.Resampling.LANCZOS)) for im in images]
    return save_png(out, contact_sheet(small, labels, cols=4, label_height=14))


def audit_views(which: str, n: int = 8, resolution: int = 320) -> tuple[list[np.ndarray], list[str]]:
    """Images behind the generator's checks (:mod:`eb_alfred.audit`), from the shipped tasks.

    ``shapes``: visual tasks with a shape word, the view after finding the target (its look-alike is next to
    it); ``dirty``: visual tasks whose target or look-alikes are dirty, after finding the target; ``spatial``:
    spatial tasks, the image in which the relation the instruction names is seen.
    """
    from eb_alfred.audit import Views, candidate_phrases, world_of
    from eb_alfred.catalog import TYPES
    from eb_alfred.env import AlfredEnv
    from eb_alfred.render import AlfredRenderer

    tasks = AlfredEnv.load_tasks()
    renderer = AlfredRenderer(resolution)
    images: list[np.ndarray] = []
    labels: list[str] = []
    try:
        for t in tasks:
            if len(images) >= n:
                break
            goal, world = t.metadata["goal"], world_of(t)
            xt = goal["object"].get("type") or world.objects[goal["object"]["instance"]].type
            if which in ("shapes", "dirty") and t.subset != "visual_appearance":
                continue
            if which == "shapes" and not any(f" {s} " in t.instruction for s in TYPES[xt].shapes):
                continue
            if which == "dirty" and not any(world.objects[x].is_dirty for x in world.of_type(xt)):
                continue
            if which == "spatial" and t.subset != "spatial_awareness":
                continue
            views = Views(world, renderer)
            if which == "spatial":
                role = "object" if "instance" in goal["object"] else "receptacle"
                cands = [(p, r) for p, r in candidate_phrases(world, goal, role) if p in t.instruction]
                if not cands:
                    continue
                phrase, refs = cands[0]
                where = views.together(refs) if len(refs) > 1 else f"after find {refs[0]}"
                if where is None:
                    continue
                shot = None if where == "start" else where.split()[-1]
                label = f"{t.id.split('_')[-1]}: '{phrase}' ({where.replace('after find ', 'find ')})"
            else:
                shot = goal["object"].get("instance") or next(
                    x for x in world.of_type(xt)
                    if all(getattr(world.objects[x], k) == v for k, v in goal["object"].items() if k != "type"))
                label = f"{t.id.split('_')[-1]}: {t.instruction}"
            w = views.world_after(shot)
            images.append(renderer.render(w).images["first_person"])
            labels.append(label if len(label) <= 54 else label[:53] + "…")
    finally:
        renderer.close()
    return images, labels


def audit_sheets(out_dir: str = "docs/img", resolution: int = 320) -> list[Path]:
    """Write ``alfred_shapes.png``, ``alfred_dirty.png`` and ``alfred_spatial.png``."""
    from eb_scenekit.render import contact_sheet, save_png

    out = []
    for which in ("shapes", "dirty", "spatial"):
        images, labels = audit_views(which, resolution=resolution)
        out.append(save_png(Path(out_dir) / f"alfred_{which}.png", contact_sheet(images, labels, cols=4,
                                                                                  label_height=14)))
    return out


if __name__ == "__main__":
    if sys.argv[1:2] == ["audit"]:
        for p in audit_sheets():
            print("wrote", p)
    else:
        print("wrote", main(sys.argv[1]) if len(sys.argv) > 1 else main())
