"""Regenerate the look-at-it sheets: every catalogue object, and the four room kinds.

Usage: ``python -m eb_scenekit.gallery OUTDIR`` writes ``scenekit_objects.png`` and ``scenekit_rooms.png``;
``python -m eb_scenekit.gallery --bench`` prints render timings of a furnished room.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from eb_scenekit.objects import ObjectType, object_types
from eb_scenekit.render import SceneRenderer, contact_sheet, free_camera, save_png
from eb_scenekit.scene import RoomKind, SceneBuilder

__all__ = ["object_view", "render_object", "objects_sheet", "rooms_sheet", "benchmark", "main"]


def object_view(otype: ObjectType, scale: float = 1.0) -> tuple[tuple[float, float, float], float, float, float]:
    """A free-camera view (lookat, distance, azimuth, elevation) that frames one object standing at the origin."""
    hx, hy = otype.half_extents
    h = otype.height
    flat = h < 0.05
    size = max(h, 2 * hx, 2 * hy) * scale
    elevation = -55.0 if flat else (-12.0 if otype.mount == "wall" else -22.0)
    azimuth = 180.0 + (0.0 if otype.mount == "wall" else 28.0)  # camera in front (+x side), slightly to the left
    z = (1.25 + h / 2) * scale if otype.mount == "wall" else h * scale / 2
    dist = 0.7 * size / math.tan(math.radians(22.5)) + 0.15 * scale
    return (0.0, 0.0, z), dist, azimuth, elevation


def render_object(type_name: str, size: int = 240, color: str | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """Render one object alone in a studio scene; returns (rgb, segmentation, instance index)."""
    from eb_scenekit.objects import get_type

    otype = get_type(type_name)
    b = SceneBuilder(name=f"studio_{type_name}", fovy=45)
    b.add_studio()
    if otype.mount == "wall":
        b.add_static_geom("room/wall", "box", (-0.05, 0, 1.5), (0.05, 2, 1.5))
    obj = b.add_object(type_name, f"{type_name}_1", (0.0, 0.0), color=color)
    model, data = b.build()
    lookat, dist, az, el = object_view(otype)
    cam = free_camera(lookat, dist, az, el)
    with SceneRenderer(model, data, size, size) as r:
        rgb = r.rgb(cam)
        seg = r.segmentation(cam)
        return rgb, seg, r.instance_ids[obj.name]


def objects_sheet(tile: int = 200, cols: int = 10) -> np.ndarray:
    """All catalogue objects in one scene, one labelled tile each."""
    types = object_types()
    b = SceneBuilder(name="catalogue", fovy=45, shadows=True)
    b.add_studio(half_size=60.0)
    spacing = 6.0
    n = math.ceil(math.sqrt(len(types)))
    places = {}
    for i, t in enumerate(types):
        x, y = (i % n) * spacing, (i // n) * spacing
        if t.mount == "wall":
            b.add_static_geom(f"room/wall_{i}", "box", (x - 0.05, y, 1.4), (0.05, 0.8, 0.5))
        b.add_object(t.name, f"{t.name}_1", (x, y))
        places[t.name] = (x, y)
    model, data = b.build()
    images, labels = [], []
    with SceneRenderer(model, data, tile, tile) as r:
        for t in types:
            (lx, ly, lz), dist, az, el = object_view(t)
            x, y = places[t.name]
            images.append(r.rgb(free_camera((lx + x, ly + y, lz), dist, az, el)))
            labels.append(f"{t.name} ({t.category})")
    return contact_sheet(images, labels, cols=cols)


def rooms_sheet(size: int = 400) -> np.ndarray:
    """The four room kinds, each from a first-person eye height (1.5 m) and from overhead."""
    from eb_scenekit.rooms import generate_room

    images, labels = [], []
    for kind in ("kitchen", "living_room", "bedroom", "bathroom"):
        layout = generate_room(kind, seed=0)
        x, y, yaw = layout.entrance(0.35)
        eye = layout.builder.add_agent_camera("viewer", (x, y), yaw=yaw, pitch=-25, height=1.5, fovy=75)
        model, data = layout.build()
        with SceneRenderer(model, data, size, size) as r:
            images += [r.rgb(eye), r.rgb("overhead")]
        labels += [f"{kind}: eye height 1.5 m", f"{kind}: overhead"]
    return contact_sheet(images, labels, cols=4)


def benchmark(kind: RoomKind = "kitchen", seed: int = 0, size: int = 500, repeats: int = 10,
              antialias: int = 4) -> dict[str, float]:
    """Median milliseconds per 500x500 RGB / segmentation / depth frame of a furnished room (first-person view)."""
    from eb_scenekit.rooms import generate_room

    layout = generate_room(kind, seed, antialias=antialias)
    x, y, yaw = layout.entrance()
    layout.builder.add_agent_camera("agent", (x, y), yaw=yaw, pitch=-20)
    t0 = time.perf_counter()
    model, data = layout.build()
    t1 = time.perf_counter()
    out: dict[str, float] = {"compile_ms": (t1 - t0) * 1e3}
    with SceneRenderer(model, data, size, size) as r:
        r.rgb("agent")
        out["first_frame_ms"] = (time.perf_counter() - t1) * 1e3
        for name, fn in (("rgb_ms", r.rgb), ("segmentation_ms", r.segmentation), ("depth_ms", r.depth)):
            times = []
            for _ in range(repeats):
                t = time.perf_counter()
                fn("agent")
                times.append(time.perf_counter() - t)
            out[name] = float(np.median(times)) * 1e3
    out["geoms"] = float(model.ngeom)
    return out


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args and args[0] == "--bench":
        for aa in (4, 0):
            res = benchmark(antialias=aa)
            print(f"antialias={aa}: " + ", ".join(f"{k} {v:.0f}" for k, v in res.items()))
        return 0
    out = Path(args[0] if args else "docs/img")
    t0 = time.perf_counter()
    save_png(out / "scenekit_objects.png", objects_sheet())
    t1 = time.perf_counter()
    save_png(out / "scenekit_rooms.png", rooms_sheet())
    t2 = time.perf_counter()
    print(f"wrote {out / 'scenekit_objects.png'} ({t1 - t0:.1f} s) and {out / 'scenekit_rooms.png'} ({t2 - t1:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
