"""Contact sheets of first-person views from real episodes, labelled with the ground truth to check by eye.

    python -m eb_habitat.gallery docs/img/habitat_views.png
    python -m eb_habitat.gallery --spatial docs/img/habitat_spatial.png

For twelve receptacles, finds the fullest view the expert reaches in the shipped tasks and renders it. Each
label names the task, the apartment, the receptacle and what lies on/in it (and what is in the hand) according
to the symbolic world, so a reader can check that the picture shows exactly that.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from eb_habitat.catalog import receptacle
from eb_habitat.world import item_label

__all__ = ["collect_views", "main", "spatial_views"]


#: Receptacles shown on the sheet, in order (12 of the 15).
SHEET = ("left_counter", "right_counter", "sink", "fridge", "left_drawer", "cabinet", "sofa", "tv_stand",
         "coffee_table", "dining_table", "desk", "brown_table")


def _candidates() -> dict[str, tuple[int, int, int, int]]:
    """Per receptacle, the (items seen, apartment spread, task index, steps) of the fullest view the expert
    reaches in the shipped tasks (symbolic pass, no rendering)."""
    from eb_habitat.oracle import expert_plan
    from eb_habitat.tasks import load_tasks, spec_of

    best: dict[str, tuple[int, int, int, int]] = {}
    for ti, task in enumerate(load_tasks()):
        spec = spec_of(task)
        world = spec.world()
        plan = expert_plan(world, spec.goal_predicates())
        for k, action in enumerate(plan):
            world.step(action)
            key = world.agent_at
            if key is None:
                continue
            seen = len(world.visible_items())
            score = (seen, -abs(spec.apartment - len(best) % 3), ti, k + 1)
            if seen and (key not in best or score[:1] > best[key][:1]):
                best[key] = score
    return best


def collect_views(n: int = 12, resolution: int = 500) -> list[tuple[np.ndarray, str]]:
    """Render the fullest expert view of each receptacle in :data:`SHEET` with a ground-truth label."""
    from eb_habitat.env import HabitatEnv

    tasks = HabitatEnv.load_tasks()
    best = _candidates()
    env = HabitatEnv(resolution=resolution, render=True)
    views: list[tuple[np.ndarray, str]] = []
    try:
        for key in SHEET[:n]:
            if key not in best:
                continue
            _, _, ti, steps = best[key]
            task = tasks[ti]
            env.reset(task, 0)
            result = None
            for action in (env.expert_plan() or [])[:steps]:
                result = env.step(action)
            assert result is not None and env._world is not None
            w = env._world
            r = receptacle(key)
            state = " (open)" if r.articulated else ""
            label = (f"{task.id} apt {task.metadata['apartment']}, {r.name}{state}: "
                     + ", ".join(item_label(it) for it in w.visible_items()))
            if w.held_item is not None:
                label += f"; in hand: {item_label(w.held_item)}"
            views.append((result.observation.images["first_person"], label))
    finally:
        env.close()
    return views


#: Row templates whose answer is seen in the view of the source receptacle.
_ROW_TEMPLATES = ("spatial.beside", "spatial.between", "spatial.ordinal", "spatial.end")


def spatial_views(resolution: int = 500) -> list[tuple[np.ndarray, str]]:
    """Per apartment: the overhead plan, the starting view, and the view of a spatial task's row, labelled with
    the layout facts and the object the instruction means (ground truth from the symbolic world)."""
    from eb_habitat.catalog import FRIDGE_END, KITCHEN_SIDE_CHAIR
    from eb_habitat.env import HabitatEnv
    from eb_habitat.skills import skill_id
    from eb_habitat.tasks import spec_of

    tasks = [t for t in HabitatEnv.load_tasks() if t.subset == "spatial_relationship"]
    env = HabitatEnv(resolution=resolution, render=True, multi_view=True)
    views: list[tuple[np.ndarray, str]] = []
    try:
        for apt in range(3):
            task = next(t for t in tasks if t.metadata["apartment"] == apt
                        and t.metadata["template"].startswith(_ROW_TEMPLATES))
            obs = env.reset(task, 0)
            chair = receptacle(KITCHEN_SIDE_CHAIR[apt]).name
            views.append((obs.images["overhead"], f"apartment {apt} from above: fridge at the {FRIDGE_END[apt]} end "
                                                  f"of the kitchen row; {chair} on the kitchen side"))
            views.append((obs.images["first_person"], f"apartment {apt}: the starting view"))
            spec = spec_of(task)
            goal = spec.goal_predicates()[0]
            src = next(o.at for o in spec.objects if o.name == goal.obj)
            result = env.step(skill_id("navigate", src))
            assert env._world is not None
            row = ", ".join(item_label(it) for it in env._world.visible_items())
            meant = item_label(env._world.items[goal.obj])
            views.append((result.observation.images["first_person"],
                          f"{task.id}: {receptacle(src).name} (left to right: {row}); meant: {meant}"))
            print(f"{task.id}: {task.instruction}")
    finally:
        env.close()
    return views


def main(argv: list[str] | None = None) -> None:
    from eb_scenekit.render import contact_sheet, save_png

    args = list(sys.argv[1:] if argv is None else argv)
    spatial = "--spatial" in args
    args = [a for a in args if a != "--spatial"]
    out = Path(args[0] if args else ("docs/img/habitat_spatial.png" if spatial else "docs/img/habitat_views.png"))
    views = spatial_views() if spatial else collect_views()
    sheet = contact_sheet([v[0] for v in views], [v[1] for v in views], cols=3 if spatial else 4, label_height=16)
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
