"""Step-time benchmark for EB-Habitat (called by ``benchmarks/env_step.py``).

``step_times(n)`` measures, at 500 x 500 by default:

* ``step_s``: median wall time of ``env.step`` (one skill in the symbolic world, posing doors, drawers,
  objects and the camera, one first-person RGB render, one segmentation render for the object boxes, and
  building the observation);
* ``raw_render_s``: median time of one plain ``mujoco.Renderer`` RGB render of the same scene from the same
  camera (``update_scene`` + ``render``), timed right after each step so both see the same viewpoints and the
  same machine load: the floor a step cannot beat;
* ``reset_s``: median ``env.reset`` time over tasks with different scenes (MJCF build, compile, GL upload,
  first render);
* ``ratio``: ``step_s / raw_render_s``.

    python -m eb_habitat.bench
"""

from __future__ import annotations

import statistics
import time
from typing import Any

__all__ = ["step_times"]


def step_times(n: int = 50, resolution: int = 500) -> dict[str, Any]:
    from eb_habitat.env import HabitatEnv
    from eb_habitat.skills import skill_id

    tasks = HabitatEnv.load_tasks()
    env = HabitatEnv(resolution=resolution, render=True)
    try:
        resets = []
        for task in tasks[: max(3, min(8, n // 6))]:
            t0 = time.perf_counter()
            env.reset(task, 0)
            resets.append(time.perf_counter() - t0)
        env.reset(tasks[0], 0)
        # walk around, open and close things: every step renders a new viewpoint
        cycle = [skill_id("navigate", k) for k in ("left_counter", "fridge", "sofa", "left_drawer", "desk")]
        cycle += [skill_id("navigate", "fridge"), skill_id("open", "fridge"), skill_id("close", "fridge")]
        from eb_scenekit._mujoco import mujoco

        scene = env._renderer  # noqa: SLF001 - the benchmark looks inside on purpose
        renderer = mujoco.Renderer(scene._model, resolution, resolution)  # noqa: SLF001
        steps, raw = [], []
        try:
            renderer.update_scene(scene._data, camera="agent")  # noqa: SLF001
            renderer.render()  # warm-up
            for k in range(n):
                t0 = time.perf_counter()
                env.step(cycle[k % len(cycle)])
                steps.append(time.perf_counter() - t0)
                # the same scene from the same camera, right after the step (same load, same viewpoint)
                t0 = time.perf_counter()
                renderer.update_scene(scene._data, camera="agent")  # noqa: SLF001
                renderer.render()
                raw.append(time.perf_counter() - t0)
        finally:
            renderer.close()
    finally:
        env.close()
    step_s, raw_s = statistics.median(steps), statistics.median(raw)
    return {"env": "habitat", "resolution": resolution, "n": n, "step_s": step_s, "raw_render_s": raw_s,
            "ratio": step_s / raw_s, "reset_s": statistics.median(resets)}


if __name__ == "__main__":  # pragma: no cover
    import json
    import resource

    out = step_times()
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out, indent=1))
