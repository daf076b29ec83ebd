"""Step-time benchmark for EB-Navigation (used by ``benchmarks/env_step.py``).

``step_times(n)`` measures, at 500 x 500 by default:

* ``step_s``: median wall time of ``env.step`` (move/turn/tilt + one first-person render + the small
  segmentation pass + observation building);
* ``raw_render_s``: median time of one plain ``mujoco.Renderer`` render of the same scene from the same
  camera with the same geoms shown (``update_scene`` + ``render``);
* ``reset_s``: median ``env.reset`` time on tasks whose room differs from the previous one (the scene kit's
  room generation, compile, the renderer's GL contexts, first render);
* ``reset_same_room_s``: median ``env.reset`` time on the next task of the same room (no recompile);
* ``ratio``: ``step_s / raw_render_s``.
"""

from __future__ import annotations

import statistics
import time
from typing import Any

__all__ = ["step_times"]


def step_times(n: int = 50, resolution: int = 500) -> dict[str, Any]:
    from eb_scenekit.bench import median_step_vs_render
    from eb_scenekit.scene import CEILING_GROUP

    from eb_navigation.env import NavigationEnv
    from eb_navigation.scene import AGENT_CAMERA, mujoco

    tasks = NavigationEnv.load_tasks()
    env = NavigationEnv(resolution=resolution)
    try:
        resets: list[float] = []
        same: list[float] = []
        previous = None
        for task in tasks[: max(10, min(30, n // 2))]:
            t0 = time.perf_counter()
            env.reset(task, 0)
            dt = time.perf_counter() - t0
            room = (task.metadata["scene"]["kind"], task.metadata["scene"]["seed"])
            (same if room == previous else resets).append(dt)
            previous = room
        env.reset(tasks[0], 0)
        cycle = (5, 0, 4, 4, 0, 5, 6, 7, 7, 6, 1, 3, 2)
        actions = iter(cycle * (n // len(cycle) + 1))
        option = mujoco.MjvOption()
        option.geomgroup[CEILING_GROUP] = 1  # the same geoms a step draws (the ceiling is in view)
        world = env._world  # noqa: SLF001 - the benchmark looks inside on purpose
        assert world is not None and world.scene is not None, "reset() builds the scene"
        scene = world.scene
        # Each raw render follows the step it is compared with: same viewpoint, same machine load.
        timing = median_step_vs_render(lambda: env.step(next(actions)), lambda: (scene.model, scene.data),
                                       AGENT_CAMERA, n, resolution, scene_option=option)
    finally:
        env.close()
    step_s, raw_s = timing["step_s"], timing["raw_render_s"]
    return {"env": "navigation", "resolution": resolution, "n": n, "step_s": step_s, "raw_render_s": raw_s,
            "ratio": step_s / raw_s, "reset_s": statistics.median(resets),
            "reset_same_room_s": statistics.median(same) if same else None}


if __name__ == "__main__":  # pragma: no cover
    import json
    import resource

    out = step_times()
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out, indent=1))
