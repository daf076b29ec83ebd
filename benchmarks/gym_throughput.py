"""Throughput of the Gymnasium vector env (eb_core.gym): env steps per second, reset time, memory per env.

    python benchmarks/gym_throughput.py [--worlds navigation,habitat,manipulation,alfred] [--sizes 1,8,32,128]
                                        [--workers 2] [--steps 10] [--max-env-steps 640] [--resets 10]
                                        [--resolution 500] [--private-gl] [--json out.json]
    python benchmarks/gym_throughput.py --quick   # a few seconds (what tests/benchmarks runs)

Raw mode with rendering on (every step renders the world's first-person image unless it changed nothing the
renderer reads). For each world, in this process with one env:

* ``render_s``: one raw render of the same scenes the vector env plays (``mujoco.Renderer.render`` of the
  pooled renderer at the observation's size, colour only; mean over the scenes of seeds 0-7, each after its
  reset and after two random steps, two renders each); **the bound** = cores / ``render_s`` -- the issue's
  definition, the most steps per second this machine could give if a step were nothing but its picture.
* ``one_env_steps_per_s``: random raw steps of the single env, resets on episode ends included (the same play
  the vector env gets); ``cores x`` that is what N perfectly parallel single envs would give, so
  ``scaling`` = rate / (cores x one-env rate) says what the vector env loses to batching, IPC and model switches.
* ``reset_median_s`` / ``reset_max_s``: ``reset()`` of one env over ``--resets`` different tasks.
* for each size N: an :class:`~eb_core.gym.EBVectorEnv` of N environments over ``--workers`` worker processes
  (default: the cores; N / workers environments in each), ``min(--steps, --max-env-steps / N)`` (at least 2)
  batched random steps after a warm-up step; ``steps_per_s`` = N x steps / wall time, ``ratio`` = that / the
  bound measured again just before this size (the machine's load changes between sizes), ``scaling`` as above;
  ``pss_mb_per_env`` = proportional set size of the worker processes after the steps / N (pages the workers
  share with each other and the fork server are split between them, so the sum is the memory they really take).

A size whose memory (the previous size's PSS per env x N) would exceed 60 % of the available memory is skipped
and says so. ``load_avg_1min``: the machine's load average when a figure was taken (other jobs on the machine make every
figure, the bound included, noisy). With ``--private-gl`` there is no pooled renderer to time: the bound is then
taken from the median random step instead (said in the output).

Steps that end an episode are followed by Gymnasium's next-step autoreset, so reset cost is inside the rate.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from typing import Any

import numpy as np


def _pss_mb(pid: int) -> float:
    try:
        with open(f"/proc/{pid}/smaps_rollup") as fh:
            for line in fh:
                if line.startswith("Pss:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return float("nan")


def _available_mb() -> float:
    with open("/proc/meminfo") as fh:
        for line in fh:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) / 1024
    return float("inf")


def bench_world(world: str, sizes: list[int], steps: int, resets: int, resolution: int, workers: int,
                max_env_steps: int) -> dict[str, Any]:
    import gymnasium

    import eb_core.gym as ebgym

    kwargs = dict(obs_mode="raw", expert_labels=False, overrides=(f"env.resolution={resolution}",))
    gid = ebgym.gym_id(world)
    env = gymnasium.make(gid, **kwargs)
    times = []
    for seed in range(resets):
        t = time.perf_counter()
        env.reset(seed=seed)
        times.append(time.perf_counter() - t)
    env.reset(seed=0)
    env.action_space.seed(0)


    def one_env() -> tuple[float, float]:
        """Random raw steps of the single env in this process, now: (steps per second with resets on episode
        ends, median step seconds)."""
        step_times = []
        t0 = time.perf_counter()
        for _ in range(3 * steps):
            t = time.perf_counter()
            _, _, term, trunc, _ = env.step(env.action_space.sample())
            step_times.append(time.perf_counter() - t)
            if term or trunc:
                env.reset()
        return 3 * steps / (time.perf_counter() - t0), statistics.median(step_times)

    def raw_render_s(scenes: int) -> float | None:
        """Mean seconds of one raw render (colour only, the observation's size) over the scenes of seeds
        0 .. ``scenes`` - 1 -- those the vector env's first environments play -- each after a reset and after two
        random steps; None without a pooled renderer to time."""
        from eb_scenekit import pool

        renders: list[float] = []
        probe = gymnasium.make(gid, **kwargs)
        probe.action_space.seed(1)
        try:
            for seed in range(scenes):
                probe.reset(seed=seed)
                for k in range(3):
                    if k:
                        probe.step(probe.action_space.sample())
                    r = pool.thread_renderer(resolution, resolution)
                    if r is None:
                        continue
                    r.disable_depth_rendering()
                    r.disable_segmentation_rendering()
                    for _ in range(2):
                        t = time.perf_counter()
                        r.render()
                        renders.append(time.perf_counter() - t)
        finally:
            probe.close()
        return statistics.mean(renders) if renders else None

    cores = os.cpu_count() or 1

    def bound_now(scenes: int) -> tuple[float, float, float, float, bool]:
        rate, step_s = one_env()
        render_s = raw_render_s(scenes)
        return cores / (render_s or step_s), rate, step_s, render_s or step_s, render_s is not None

    bound, one_rate, step_s, render_s, from_render = bound_now(min(8, max(sizes)))
    out: dict[str, Any] = {"world": world, "gym_id": gid, "resolution": resolution, "cores": cores,
                           "render_s": round(render_s, 4), "bound_steps_per_s": round(bound, 1),
                           "bound_from": "raw render" if from_render else "median step",
                           "step_median_s": round(step_s, 4), "one_env_steps_per_s": round(one_rate, 1),
                           "reset_median_s": round(statistics.median(times), 3), "reset_max_s": round(max(times), 3),
                           "load_avg_1min": round(os.getloadavg()[0], 1), "sizes": {}}
    per_env_mb = 0.0
    for n in sizes:
        w = min(workers, n)
        need, avail = per_env_mb * n, _available_mb()
        if need > 0.6 * avail:  # a shared machine: do not push it into the OOM killer
            out["sizes"][n] = {"skipped": f"would need ~{need / 1024:.1f} GB ({per_env_mb:.0f} MB x {n}), "
                                          f"{avail / 1024:.1f} GB available"}
            print(f"  {world} N={n}: skipped, {out['sizes'][n]['skipped']}", flush=True)
            continue
        n_steps = max(2, min(steps, max_env_steps // n))
        bound_n, one_rate_n, _, _, _ = bound_now(min(8, n))  # again, under the machine's load of this moment
        t = time.perf_counter()
        vec = ebgym.make_vector_env(world, n, workers=w, **kwargs)
        try:
            start_s = time.perf_counter() - t
            t = time.perf_counter()
            vec.reset(seed=list(range(n)))
            reset_s = time.perf_counter() - t
            vec.action_space.seed(1)
            vec.step(vec.action_space.sample())  # warm-up
            t = time.perf_counter()
            ended = 0
            for _ in range(n_steps):
                _, _, term, trunc, _ = vec.step(vec.action_space.sample())
                ended += int(np.sum(term | trunc))
            wall = time.perf_counter() - t
            pss = [_pss_mb(pid) for pid in vec.worker_pids]
        finally:
            vec.close()
        rate = n * n_steps / wall
        per_env = float(np.nansum(pss)) / n
        per_env_mb = per_env  # per-env memory falls with N: the last size's figure bounds the next one
        out["sizes"][n] = {"workers": w, "steps": n_steps, "steps_per_s": round(rate, 1),
                           "bound_steps_per_s": round(bound_n, 1), "ratio_to_bound": round(rate / bound_n, 2),
                           "one_env_steps_per_s": round(one_rate_n, 1),
                           "scaling": round(rate / (cores * one_rate_n), 2),
                           "episodes_ended": ended, "pss_mb_per_env": round(per_env, 1),
                           "pss_mb_workers": round(float(np.nansum(pss)), 1), "start_s": round(start_s, 2),
                           "vector_reset_s": round(reset_s, 2), "load_avg_1min": round(os.getloadavg()[0], 1)}
        print(f"  {world} N={n} over {w} processes: {rate:.1f} steps/s ({rate / bound_n:.2f} of the bound "
              f"{bound_n:.1f} measured just before, {rate / (cores * one_rate_n):.2f} of {cores} x one env's "
              f"{one_rate_n:.1f}; {ended} episodes ended and were reset inside the timed "
              f"steps), {per_env:.0f} MB PSS per env ({np.nansum(pss):.0f} MB in all); start {start_s:.1f} s, "
              f"reset of all {reset_s:.1f} s; load {os.getloadavg()[0]:.1f}", flush=True)
    env.close()
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--worlds", default="navigation,habitat,manipulation,alfred")
    ap.add_argument("--sizes", default="1,8,32,128")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="worker processes (default: cores)")
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--max-env-steps", type=int, default=640, help="cap on N x steps at each size")
    ap.add_argument("--resets", type=int, default=10)
    ap.add_argument("--resolution", type=int, default=500)
    ap.add_argument("--private-gl", action="store_true",
                    help="every env its own GL state (EB_SCENEKIT_PRIVATE_GL=1) instead of one pooled renderer per "
                         "worker process: more memory, no model switch between the envs a worker steps in turn")
    ap.add_argument("--json", default=None, help="write the results to this file")
    ap.add_argument("--quick", action="store_true", help="a few seconds: navigation, sizes 1 and 2 on one worker, "
                    "2 steps, 1 reset, 64 px (checks that the benchmark runs; its figures mean little)")
    args = ap.parse_args(argv)
    if args.quick:
        args.worlds, args.sizes, args.workers, args.steps, args.resets, args.resolution = \
            "navigation", "1,2", 1, 2, 1, 64
    if args.private_gl:
        os.environ["EB_SCENEKIT_PRIVATE_GL"] = "1"  # the workers take this process's environment
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    results = []
    for world in [w.strip() for w in args.worlds.split(",") if w.strip()]:
        print(f"{world}:", flush=True)
        r = bench_world(world, sizes, args.steps, args.resets, args.resolution, args.workers, args.max_env_steps)
        print(f"  one {r['bound_from']} {r['render_s'] * 1000:.0f} ms -> bound {r['bound_steps_per_s']} steps/s on "
              f"{r['cores']} cores (median step {r['step_median_s'] * 1000:.0f} ms; one env alone "
              f"{r['one_env_steps_per_s']} steps/s with its resets); reset median {r['reset_median_s']} s, "
              f"max {r['reset_max_s']} s", flush=True)
        results.append(r)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=2)


if __name__ == "__main__":
    main()
