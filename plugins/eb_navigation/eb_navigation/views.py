"""Contact sheets of first-person start views: ``python -m eb_navigation.views OUT.png [task ids...]``.

Used to check by eye that a person can name the target in every view (docs/img/navigation_views.png) and to
show the subsets side by side (docs/img/navigation_subsets.png: ``python -m eb_navigation.views --subsets OUT``).
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path


__all__ = ["contact_sheet", "subsets_sheet"]


def contact_sheet(task_ids: list[str] | None = None, out: str | Path = "navigation_views.png", cell: int = 400,
                  cols: int = 4, multi_view: bool = False, task_file: str | None = None,
                  taskset: str = "classic") -> Path:
    from PIL import Image, ImageDraw, ImageFont

    from eb_navigation.env import NavigationEnv

    tasks = {t.id: t for t in NavigationEnv.load_tasks(taskset=taskset, task_file=task_file)}
    if not task_ids:
        task_ids = [f"base_{n:03d}" for n in range(12)]
    env = NavigationEnv(resolution=500, multi_view=multi_view, task_file=task_file)
    font = ImageFont.load_default(size=15)
    label_h = 44
    tiles = []
    try:
        for tid in task_ids:
            task = tasks[tid]
            obs = env.reset(task, 0)
            img = Image.fromarray(obs.images["overhead" if multi_view else "first_person"]).resize((cell, cell))
            tile = Image.new("RGB", (cell, cell + label_h), "white")
            tile.paste(img, (0, label_h))
            d = ImageDraw.Draw(tile)
            meta = task.metadata
            head = f"{tid}  ({meta['scene']['kind'].replace('_', ' ')}, target: {meta['target']['id']})"
            d.text((4, 2), head, fill=(0, 0, 0), font=font)
            d.text((4, 22), textwrap.shorten(task.instruction, 52), fill=(40, 40, 160), font=font)
            tiles.append(tile)
    finally:
        env.close()
    rows = (len(tiles) + cols - 1) // cols
    sheet = Image.new("RGB", (cols * cell + (cols - 1) * 4, rows * (cell + label_h) + (rows - 1) * 4), "white")
    for k, tile in enumerate(tiles):
        sheet.paste(tile, ((k % cols) * (cell + 4), (k // cols) * (cell + label_h + 4)))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out, optimize=True)
    return out


def subsets_sheet(numbers: tuple[int, ...] = (1, 6, 9), out: str | Path = "navigation_subsets.png",
                  cell: int = 360, task_file: str | None = None) -> Path:
    """Rows of one room each: base, visual_appearance and long_horizon start views, then the overhead view."""
    from PIL import Image, ImageDraw, ImageFont

    from eb_navigation.env import NavigationEnv

    tasks = {t.id: t for t in NavigationEnv.load_tasks(task_file=task_file)}
    env = NavigationEnv(resolution=500, multi_view=True, task_file=task_file)
    font = ImageFont.load_default(size=14)
    label_h = 40
    rows = []
    try:
        for n in numbers:
            tiles = []
            for subset, key in (("base", "first_person"), ("visual_appearance", "first_person"),
                                ("long_horizon", "first_person"), ("visual_appearance", "overhead")):
                task = tasks[f"{subset}_{n:03d}"]
                obs = env.reset(task, 0)
                tile = Image.new("RGB", (cell, cell + label_h), "white")
                tile.paste(Image.fromarray(obs.images[key]).resize((cell, cell)), (0, label_h))
                d = ImageDraw.Draw(tile)
                d.text((4, 2), f"{task.id} ({key.replace('_', ' ')})", fill=(0, 0, 0), font=font)
                d.text((4, 20), textwrap.shorten(task.instruction, 50), fill=(40, 40, 160), font=font)
                tiles.append(tile)
            rows.append(tiles)
    finally:
        env.close()
    sheet = Image.new("RGB", (4 * cell + 12, len(rows) * (cell + label_h + 4) - 4), "white")
    for r, tiles in enumerate(rows):
        for c, tile in enumerate(tiles):
            sheet.paste(tile, (c * (cell + 4), r * (cell + label_h + 4)))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out, optimize=True)
    return out


if __name__ == "__main__":  # pragma: no cover
    args = sys.argv[1:]
    if args[:1] == ["--hard"]:  # python -m eb_navigation.views --hard out.png [task ids]
        print(contact_sheet(args[2:] or None, args[1] if len(args) > 1 else "navigation_hard.png", taskset="hard"))
    elif args[:1] == ["--subsets"]:
        print(subsets_sheet(out=args[1] if len(args) > 1 else "navigation_subsets.png"))
    else:
        print(contact_sheet(args[1:] or None, args[0] if args else "navigation_views.png"))
