"""Step-time benchmark for EB-ALFRED (used by ``benchmarks/env_step.py``).

``step_times(n)`` measures, at 500 x 500 by default:

* ``step_s``: median wall time of ``env.step`` with rendering (the symbolic action, syncing poses, doors and
  switches into MuJoCo, one first-person render, the segmentation pass for boxes, the text description);
* ``raw_render_s``: median time of one plain ``mujoco.Renderer`` render of the same scene from the same camera
  (``update_scene`` + ``render``), the floor a step cannot beat;
* ``ratio``: ``step_s / raw_render_s``;
* ``reset_s``: median ``env.reset`` (lay out the room, compile it, first render) over a few different tasks;
* ``symbolic_step_s``: median step with ``render=False``.

Steps replay oracle plans, so every step changes the world the way an episode does.
"""

from __future__ import annotations

import statistics
import time
from typing import Any

__all__ = ["step_times"]


def step_times(n: int = 30, resolution: int = 500) -> dict[str, Any]:
    from eb_alfred.env import AlfredEnv

    tasks = AlfredEnv.load_tasks()
    order = tasks[3::37]  # a spread over subsets and rooms
    env = AlfredEnv(resolution=resolution, render=True)
    try:
        resets = []
        for task in order[: max(3, min(8, n // 5))]:
            t0 = time.perf_counter()
            env.reset(task, 0)
            resets.append(time.perf_counter() - t0)
        steps: list[float] = []
        k = 0
        env.reset(order[0], 0)
        while len(steps) < n:
            plan = env.expert_plan() or []
            done = not plan
            for a in plan:
                t0 = time.perf_counter()
                r = env.step(a)
                steps.append(time.perf_counter() - t0)
                done = r.done
                if done or len(steps) >= n:
                    break
            if done:
                k += 1
                env.reset(order[k % len(order)], 0)
        from eb_scenekit._mujoco import mujoco

        view = env._renderer  # noqa: SLF001 - the benchmark looks inside on purpose
        renderer = mujoco.Renderer(view.model, resolution, resolution)
        try:
            raw = []
            renderer.update_scene(view.data, camera="agent")
            renderer.render()  # warm-up
            for _ in range(max(n, 10)):
                t0 = time.perf_counter()
                renderer.update_scene(view.data, camera="agent")
                renderer.render()
                raw.append(time.perf_counter() - t0)
        finally:
            renderer.close()
    finally:
        env.close()
    sym = AlfredEnv(render=False)
    symbolic: list[float] = []
    for task in order:
        sym.reset(task, 0)
        for a in sym.expert_plan() or []:
            t0 = time.perf_counter()
            sym.step(a)
            symbolic.append(time.perf_counter() - t0)
    step_s, raw_s = statistics.median(steps), statistics.median(raw)
    return {"env": "alfred", "resolution": resolution, "n": len(steps), "step_s": step_s, "raw_render_s": raw_s,
            "ratio": step_s / raw_s, "reset_s": statistics.median(resets),
            "symbolic_step_s": statistics.median(symbolic)}


if __name__ == "__main__":
    import json
    import sys

    print(json.dumps(step_times(int(sys.argv[1]) if len(sys.argv) > 1 else 30), indent=1))
