"""Step-time benchmark for EB-Habitat (called by ``benchmarks/env_step.py``).

``step_times(n)`` measures, at 500 x 500 by default:

* ``step_s``: median wall time of ``env.step`` (one skill in the symbolic world, posing doors, drawers,
  objects and the camera, one first-person RGB render, one segmentation render for the object boxes, and
  building the observation);
* ``raw_render_s``: median time of one plain ``mujoco.Renderer`` RGB render of the same scene from the same
  camera (``update_scene`` + ``render``), timed right after each step so both see the same viewpoints and the
  same machine load: the floor a step cannot beat (:func:`eb_scenekit.bench.median_step_vs_render`);
* ``reset_s``: median ``env.reset`` time over tasks with different scenes (MJCF build, compile, GL upload,
  first render);
* ``ratio``: ``step_s / raw_render_s``.

    python -m eb_habitat.bench
"""

from __future__ import annotations

from typing import Any

__all__ = ["step_times"]


def step_times(n: int = 50, resolution: int = 500) -> dict[str, Any]:
    from eb_scenekit.bench import median_seconds, median_step_vs_render

    from eb_habitat.env import HabitatEnv
    from eb_habitat.skills import skill_id

    tasks = HabitatEnv.load_tasks()
    env = HabitatEnv(resolution=resolution, render=True)
    # walk around, open and close things: every step renders a new viewpoint
    cycle = [skill_id("navigate", k) for k in ("left_counter", "fridge", "sofa", "left_drawer", "desk")]
    cycle += [skill_id("navigate", "fridge"), skill_id("open", "fridge"), skill_id("close", "fridge")]
    actions = iter(cycle * (n // len(cycle) + 1))
    try:
        reset_s = median_seconds(lambda task: env.reset(task, 0), tasks[: max(3, min(8, n // 6))])
        env.reset(tasks[0], 0)
        scene = env._renderer  # noqa: SLF001 - the benchmark looks inside on purpose
        timing = median_step_vs_render(lambda: env.step(next(actions)),
                                       lambda: (scene._model, scene._data), "agent", n, resolution)  # noqa: SLF001
    finally:
        env.close()
    return {"env": "habitat", "resolution": resolution, **timing, "reset_s": reset_s}


if __name__ == "__main__":  # pragma: no cover
    import json
    import resource

    out = step_times()
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out, indent=1))
