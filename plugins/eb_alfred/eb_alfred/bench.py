"""Timing of EB-ALFRED steps, for ``benchmarks/env_step.py`` (``step_times(n)``)."""

from __future__ import annotations

import statistics
import time
from typing import Any

__all__ = ["step_times"]


def step_times(n: int = 20, resolution: int = 500, task_id: str = "base_03") -> dict[str, Any]:
    """Median wall time of one env step with rendering at ``resolution``, against one raw render of the same scene.

    Steps replay the task's oracle plan (re-planned after the end, cycling through tasks if needed) so every
    step changes the state the way a real episode does. Returns milliseconds.
    """
    from eb_alfred.env import AlfredEnv

    env = AlfredEnv(resolution=resolution, render=True)
    tasks = AlfredEnv.load_tasks()
    order = [t for t in tasks if t.id == task_id] + [t for t in tasks if t.id != task_id]
    try:
        t0 = time.perf_counter()
        env.reset(order[0], 0)
        first_reset = time.perf_counter() - t0
        t0 = time.perf_counter()
        env.reset(order[0], 0)
        reset_s = time.perf_counter() - t0
        steps: list[float] = []
        symbolic: list[float] = []
        k = 0
        while len(steps) < n:
            plan = env.expert_plan() or []
            if not plan:
                k += 1
                env.reset(order[k % len(order)], 0)
                continue
            for a in plan:
                t0 = time.perf_counter()
                r = env.step(a)
                steps.append(time.perf_counter() - t0)
                if r.done or len(steps) >= n:
                    break
            if r.done:
                k += 1
                env.reset(order[k % len(order)], 0)
        raw = env._renderer.raw_render_ms(repeats=max(5, n // 4))  # noqa: SLF001 (same scene, no state sync)
        # the symbolic step alone, for comparison
        sym = AlfredEnv(render=False)
        sym.reset(order[0], 0)
        for a in (sym.expert_plan() or [])[:n]:
            t0 = time.perf_counter()
            sym.step(a)
            symbolic.append(time.perf_counter() - t0)
        return {
            "env": "alfred",
            "resolution": resolution,
            "n_steps": len(steps),
            "step_ms_median": round(statistics.median(steps) * 1000, 1),
            "raw_render_ms_median": round(raw, 1),
            "symbolic_step_ms_median": round(statistics.median(symbolic) * 1000, 3) if symbolic else None,
            "reset_s": round(reset_s, 2),
            "first_reset_s": round(first_reset, 2),
        }
    finally:
        env.close()


if __name__ == "__main__":
    import json
    import sys

    print(json.dumps(step_times(int(sys.argv[1]) if len(sys.argv) > 1 else 20), indent=1))
