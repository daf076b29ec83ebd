"""Contact sheets for the docs: front and wrist images of one task per family, before/during/after.

Usage: python plugins/eb_manipulation/scripts/contact_sheets.py [out_dir] [resolution]
Writes <out_dir>/manipulation_<family>.png (default out_dir: docs/img of the repository), and
manipulation_hard.png: the first front image of one hard task per family (turned sorter holes, arrows on the areas).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from eb_manipulation.env import ManipulationEnv

TASKS = {"pick": "base_pick_00", "stack": "base_stack_01", "sorter": "base_sorter_00", "wipe": "base_wipe_00"}
HARD_TASKS = ("base_pick_00", "base_stack_01", "base_sorter_00", "base_wipe_00")


def _caption(img: np.ndarray, text: str) -> np.ndarray:
    pil = Image.fromarray(img)
    draw = ImageDraw.Draw(pil)
    font = ImageFont.load_default(size=max(12, img.shape[0] // 28))
    tb = draw.textbbox((0, 0), text, font=font)
    draw.rectangle([0, img.shape[0] - (tb[3] - tb[1]) - 10, tb[2] - tb[0] + 12, img.shape[0]], fill=(0, 0, 0))
    draw.text((6, img.shape[0] - (tb[3] - tb[1]) - 6 - tb[1]), text, fill=(255, 255, 255), font=font)
    return np.asarray(pil)


def main(out_dir: Path, resolution: int) -> None:
    env = ManipulationEnv(resolution=resolution, multi_view=True)
    tasks = {t.id: t for t in env.load_tasks()}
    out_dir.mkdir(parents=True, exist_ok=True)
    try:
        for family, task_id in TASKS.items():
            obs = env.reset(tasks[task_id], 0)
            frames = [(obs, "start")]
            plan = env.expert_plan() or []
            result, during = None, None
            for i, action in enumerate(plan, start=1):
                result = env.step(action)
                if result.done:
                    break
                if result.info.get("held"):  # the last frame with something in the gripper
                    during = (result.observation, f"after action {i}")
            assert result is not None and result.task_success and during is not None, task_id
            frames += [during, (result.observation, f"solved after {i} actions")]
            top = np.hstack([_caption(o.images["front"], f"front, {c}") for o, c in frames])
            bottom = np.hstack([_caption(o.images["wrist"], f"wrist, {c}") for o, c in frames])
            sheet = Image.fromarray(np.vstack([top, bottom]))
            path = out_dir / f"manipulation_{family}.png"
            sheet.save(path, optimize=True)
            print(f"{path}  ({path.stat().st_size // 1024} KB)  {tasks[task_id].instruction}")
    finally:
        env.close()
    hard_sheet(out_dir, resolution)


def hard_sheet(out_dir: Path, resolution: int) -> None:
    """The first front image of one hard task per family, 2 x 2, each captioned with its instruction's start."""
    env = ManipulationEnv(resolution=resolution)
    tasks = {t.id: t for t in env.load_tasks(taskset="hard")}
    try:
        tiles = []
        for task_id in HARD_TASKS:
            obs = env.reset(tasks[task_id], 0)
            tiles.append(_caption(obs.images["front"], f"hard {task_id}"))
            print(f"  {task_id}: {tasks[task_id].instruction}")
        sheet = Image.fromarray(np.vstack([np.hstack(tiles[:2]), np.hstack(tiles[2:])]))
        path = out_dir / "manipulation_hard.png"
        sheet.save(path, optimize=True)
        print(f"{path}  ({path.stat().st_size // 1024} KB)")
    finally:
        env.close()


if __name__ == "__main__":
    root = Path(__file__).resolve().parents[3]
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "docs" / "img"
    main(out, int(sys.argv[2]) if len(sys.argv) > 2 else 400)
