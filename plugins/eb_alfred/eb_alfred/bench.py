"""Step-time benchmark for EB-ALFRED (used by ``benchmarks/env_step.py``).

``step_times(n)`` measures, at 500 x 500 by default:

* ``step_s``: median wall time of ``env.step`` with rendering (the symbolic action, syncing poses, doors and
  switches into MuJoCo, one first-person render, the segmentation pass for boxes, the text description);
* ``raw_render_s``: median time of one plain ``mujoco.Renderer`` render of the same scene from the same camera
  (``update_scene`` + ``render``) right after each step, the floor a step cannot beat
  (:func:`eb_scenekit.bench.median_step_vs_render`);
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
    from eb_scenekit.bench import median_seconds, median_step_vs_render

    from eb_alfred.env import AlfredEnv

    tasks = AlfredEnv.load_tasks()
    order = tasks[3::37]  # a spread over subsets and rooms
    env = AlfredEnv(resolution=resolution, render=True)
    plan: list[int] = []
    k = 0
    done = False

    def next_action() -> None:  # untimed: re-plan from the current state, or move on to the next task
        nonlocal plan, k, done
        while done or not plan:
            plan = [] if done else list(env.expert_plan() or [])
            if not plan:
                k += 1
                env.reset(order[k % len(order)], 0)
            done = False

    def step() -> None:
        nonlocal done
        done = env.step(plan.pop(0)).done

    try:
        reset_s = median_seconds(lambda task: env.reset(task, 0), order[: max(3, min(8, n // 5))])
        env.reset(order[0], 0)

        def scene() -> tuple[Any, Any]:  # the current renderer: a reset builds a new one and closes the old
            view = env._renderer  # noqa: SLF001 - the benchmark looks inside on purpose
            return view.model, view.data

        timing = median_step_vs_render(step, scene, "agent", n, resolution, next_action)
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
    return {"env": "alfred", "resolution": resolution, **timing, "reset_s": reset_s,
            "symbolic_step_s": statistics.median(symbolic)}


if __name__ == "__main__":
    import json
    import sys

    print(json.dumps(step_times(int(sys.argv[1]) if len(sys.argv) > 1 else 30), indent=1))
