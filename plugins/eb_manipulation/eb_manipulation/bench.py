"""Timing of one EB-Manipulation action (IK + path + physics + rendering), for ``benchmarks/env_step.py``.

``step_times(n)`` runs oracle actions on shipped tasks (one task per family, cycling) and returns median
and 90th-percentile seconds per action with and without rendering, plus the reset time.
Run directly: ``python -m eb_manipulation.bench 40``.
"""

from __future__ import annotations

import statistics
import sys
import time
from typing import Any

__all__ = ["step_times"]


def _percentile(values: list[float], q: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(round(q * (len(s) - 1))))]


def _run(n: int, render: bool, resolution: int, multi_view: bool) -> dict[str, Any]:
    from eb_manipulation.env import ManipulationEnv

    env = ManipulationEnv(resolution=resolution, multi_view=multi_view, render=render)
    tasks = env.load_tasks()
    by_family: dict[str, Any] = {}
    for t in tasks:
        by_family.setdefault(t.metadata["family"], t)
    order = list(by_family.values())
    step_s: list[float] = []
    reset_s: list[float] = []
    try:
        k = 0
        while len(step_s) < n:
            task = order[k % len(order)]
            k += 1
            t0 = time.perf_counter()
            env.reset(task, 0)
            reset_s.append(time.perf_counter() - t0)
            for action in env.expert_plan() or []:
                t0 = time.perf_counter()
                result = env.step(action)
                step_s.append(time.perf_counter() - t0)
                if result.done or len(step_s) >= n:
                    break
    finally:
        env.close()
    return {
        "median_s": statistics.median(step_s),
        "p90_s": _percentile(step_s, 0.9),
        "reset_median_s": statistics.median(reset_s),
        "n": len(step_s),
    }


def step_times(n: int = 30, resolution: int = 500) -> dict[str, Any]:
    """Seconds per action: ``render`` (front image + segmentation boxes), ``multi_view`` (plus the wrist
    image) and ``no_render`` (simulation only), each with ``median_s``, ``p90_s``, ``reset_median_s``, ``n``."""
    return {
        "render": _run(n, True, resolution, False),
        "multi_view": _run(max(4, n // 2), True, resolution, True),
        "no_render": _run(n, False, resolution, False),
        "resolution": resolution,
    }


if __name__ == "__main__":  # pragma: no cover - manual use
    import json

    print(json.dumps(step_times(int(sys.argv[1]) if len(sys.argv) > 1 else 30), indent=1))
