"""Timing helpers for the worlds' step benchmarks (each world's ``bench.step_times``, run by
``benchmarks/env_step.py``).

The number every world reports is how much an ``env.step`` costs compared with the floor it cannot beat: one
plain ``mujoco.Renderer`` render of the same scene from the same camera. :func:`median_step_vs_render` times
both, interleaved (each raw render follows the step it is compared with, so both see the same viewpoint and the
same machine load), and :func:`median_seconds` times anything else (resets).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

__all__ = ["median_seconds", "median_step_vs_render"]

T = TypeVar("T")


def median_seconds(fn: Callable[[T], object], args: Iterable[T]) -> float:
    """Median wall time (seconds) of ``fn(a)`` over ``args``, e.g. ``median_seconds(lambda t: env.reset(t, 0),
    tasks)``."""
    times = []
    for a in args:
        t0 = time.perf_counter()
        fn(a)
        times.append(time.perf_counter() - t0)
    if not times:
        raise ValueError("median_seconds needs at least one argument")
    return statistics.median(times)


def median_step_vs_render(step: Callable[[], object], scene: Callable[[], tuple[Any, Any]], camera: str, n: int,
                          resolution: int = 500, before: Callable[[], object] | None = None,
                          scene_option: Any = None) -> dict[str, float]:
    """Time ``n`` steps, each followed by one plain render of the scene it left, and compare the medians.

    Args:
        step: one environment step (timed), e.g. ``lambda: env.step(next(actions))``.
        scene: the current ``(MjModel, MjData)`` of the environment (asked after every step: a world that
            recompiles on reset hands out a new model, and gets a new raw renderer).
        camera: the model camera the environment renders its main view from, e.g. ``"agent"``.
        n: number of steps.
        resolution: square size of the raw render, the environment's resolution.
        before: untimed preparation before each step (pick the next action, reset when a task is done).
        scene_option: an ``MjvOption`` for the raw render, so it draws the same geom groups as the step.

    Returns:
        ``{"n", "step_s", "raw_render_s", "ratio"}``: median seconds of a step, median seconds of a raw
        render (``update_scene`` + ``render``, after an untimed warm-up per model), and their ratio.
    """
    from eb_scenekit._mujoco import mujoco

    steps: list[float] = []
    raws: list[float] = []
    renderer = None
    model = None
    try:
        for _ in range(n):
            if before is not None:
                before()
            t0 = time.perf_counter()
            step()
            steps.append(time.perf_counter() - t0)
            m, d = scene()
            if renderer is None or m is not model:  # a new scene: a new renderer (creation and upload untimed)
                if renderer is not None:
                    renderer.close()
                model, renderer = m, mujoco.Renderer(m, resolution, resolution)
                renderer.update_scene(d, camera=camera, scene_option=scene_option)
                renderer.render()
            t0 = time.perf_counter()
            renderer.update_scene(d, camera=camera, scene_option=scene_option)
            renderer.render()
            raws.append(time.perf_counter() - t0)
    finally:
        if renderer is not None:
            renderer.close()
    if not steps:
        raise ValueError("median_step_vs_render needs n >= 1")
    step_s, raw_s = statistics.median(steps), statistics.median(raws)
    return {"n": len(steps), "step_s": step_s, "raw_render_s": raw_s, "ratio": step_s / raw_s}
