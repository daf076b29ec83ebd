"""Contact sheets of first-person views from real episodes, labelled with the ground truth to check by eye.

    python -m eb_habitat.gallery docs/img/habitat_views.png

Follows the expert through shipped tasks (cycling over the three apartments) and keeps the first view of each
receptacle with something on it, plus a view while holding an object, until it has ``n`` views. Each label
names the receptacle and what lies on/in it according to the symbolic world, so a reader can check that the
picture shows exactly that.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from eb_habitat.catalog import receptacle
from eb_habitat.world import item_label

__all__ = ["collect_views", "main"]


def collect_views(n: int = 12, resolution: int = 500) -> list[tuple[np.ndarray, str]]:
    from eb_habitat.env import HabitatEnv

    env = HabitatEnv(resolution=resolution, render=True)
    tasks = HabitatEnv.load_tasks()
    by_apartment: dict[int, list] = {}
    for t in tasks:
        by_apartment.setdefault(t.metadata["apartment"], []).append(t)
    order = [t for group in zip(*by_apartment.values()) for t in group]
    views: list[tuple[np.ndarray, str]] = []
    seen: set[str] = set()
    held_done = False
    try:
        for task in order:
            env.reset(task, 0)
            for action in env.expert_plan() or []:
                result = env.step(action)
                w = env._world
                assert w is not None
                key = w.agent_at
                things = w.visible_items()
                img = result.observation.images["first_person"]
                apt = task.metadata["apartment"]
                if key is not None and key not in seen and things:
                    r = receptacle(key)
                    state = " (open)" if r.articulated else ""
                    label = f"apt {apt}, {r.name}{state}: " + ", ".join(item_label(it) for it in things)
                    if w.held_item is not None:
                        label += f"; in hand: {item_label(w.held_item)}"
                    views.append((img, label))
                    seen.add(key)
                elif w.held is not None and not held_done and key is not None and not things:
                    views.append((img, f"apt {apt}, {receptacle(key).name}, holding the {item_label(w.held_item)}"))
                    held_done = True
                if len(views) >= n:
                    return views
    finally:
        env.close()
    return views


def main(argv: list[str] | None = None) -> None:
    from eb_scenekit.render import contact_sheet, save_png

    args = sys.argv[1:] if argv is None else argv
    out = Path(args[0] if args else "docs/img/habitat_views.png")
    views = collect_views()
    sheet = contact_sheet([v[0] for v in views], [v[1] for v in views], cols=4, label_height=16)
    from PIL import Image

    img = Image.fromarray(sheet)
    img = img.resize((img.width * 3 // 4, img.height * 3 // 4), Image.LANCZOS)
    out.parent.mkdir(parents=True, exist_ok=True)
    save_png(out, np.asarray(img))
    for _, label in views:
        print(label)
    print(out)


if __name__ == "__main__":
    main()
