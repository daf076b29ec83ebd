"""Check every mug with a handle's side in a task set (hard version 6): is its handle drawn on that side, in view?

    MUJOCO_GL=egl python plugins/eb_habitat/scripts/handles.py [--taskset hard] [--save DIR]

For each task with a handle pair, the agent stands at the pair's receptacle and the first-person view is rendered
at 500 x 500 (the model's size). From the segmentation, per mug: its visible pixels, its width, and how far the
centroid of its mask lies from the centre of its box (positive: the mask reaches further left than the body's
weight, i.e. a handle on the left). A mug fails when it shows fewer than ``--min-pixels`` pixels or its offset is
under ``--min-offset`` pixels or on the wrong side. ``--save DIR`` writes each view as ``<task id>.png`` to look at.
Exit status 1 if any mug fails.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from eb_habitat.env import HabitatEnv
from eb_habitat.render import AGENT, ApartmentRenderer
from eb_habitat.tasks import spec_of


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--taskset", default="hard")
    ap.add_argument("--save", default=None, help="folder for the rendered views")
    ap.add_argument("--min-pixels", type=int, default=800)
    ap.add_argument("--min-offset", type=float, default=1.0)
    args = ap.parse_args(argv)
    renderer = ApartmentRenderer(500)
    failed = checked = 0
    offsets: list[float] = []
    for task in HabitatEnv.load_tasks(taskset=args.taskset):
        spec = spec_of(task)
        mugs = [o for o in spec.objects if o.handle is not None]
        if not mugs:
            continue
        renderer.load(spec)
        world = spec.world()
        world.agent_at = mugs[0].at
        image = renderer.render(world)["first_person"]
        assert renderer._renderer is not None
        seg = renderer._renderer.segmentation(AGENT)
        names = renderer._renderer.instance_names
        for o in mugs:
            mask = seg == names.index(o.name)
            checked += 1
            if mask.sum() < args.min_pixels:
                failed += 1
                print(f"{task.id} {o.name}: only {int(mask.sum())} px in view")
                continue
            cols = np.nonzero(mask.any(axis=0))[0]
            offset = float(np.nonzero(mask)[1].mean() - (cols[0] + cols[-1]) / 2)
            signed = offset if o.handle == "left" else -offset
            offsets.append(signed)
            if signed < args.min_offset:
                failed += 1
                print(f"{task.id} {o.name}: handle {o.handle} but mask offset {offset:+.1f} px")
        if args.save:
            from PIL import Image

            Path(args.save).mkdir(parents=True, exist_ok=True)
            Image.fromarray(image).save(Path(args.save) / f"{task.id}.png")
    renderer.close()
    low = f"{min(offsets):.1f}" if offsets else "-"
    print(f"{checked} mugs with a handle's side, {failed} failed; smallest offset towards the body {low} px")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
