"""Env steps per second over HTTP (``eb serve`` + RemoteVectorEnv) against the in-process vector env.

Both sides use the same world, the same number of environments and the same worker processes; images are on
(rendered, PNG over the wire, decoded back to arrays by the client). Printed: steps/s of each, their ratio (the
goal is >= 0.8 at 32 environments), and the p50/p99 latency of one batched step as the client sees it.

    python benchmarks/serve_throughput.py                    # navigation, 32 envs, 2 workers, 20 steps
    python benchmarks/serve_throughput.py --quick            # a few seconds: 4 envs, 3 steps
    python benchmarks/serve_throughput.py --world alfred --envs 32 --steps 30 --obs-mode raw

The ratio is measured in one run on this (shared) machine: the two sides run one after the other.
"""

from __future__ import annotations

import argparse
import json
import re
import signal
import subprocess
import sys
import time

import numpy as np


def _actions(obs_mode: str, space, n: int, rng: np.random.Generator) -> list:
    if obs_mode == "raw":
        return [int(rng.integers(space.n)) if hasattr(space, "n") else space.sample().tolist() for _ in range(n)]
    ids = rng.integers(0, 8, size=n)
    return [json.dumps({"visual_state_description": "", "reasoning_and_reflection": "", "language_plan": "",
                        "executable_plan": [{"action_id": int(a), "action_name": ""}]}) for a in ids]


def _play(env, obs_mode: str, steps: int, seed: int) -> tuple[float, list[float]]:
    rng = np.random.default_rng(seed)
    env.reset(seed=list(range(env.num_envs)))
    lat = []
    t0 = time.perf_counter()
    for _ in range(steps):
        acts = _actions(obs_mode, env.single_action_space, env.num_envs, rng)
        s = time.perf_counter()
        env.step(acts)
        lat.append(time.perf_counter() - s)
    return env.num_envs * steps / (time.perf_counter() - t0), lat


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--world", default="navigation")
    ap.add_argument("--envs", type=int, default=32)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--obs-mode", default="prompt", choices=("prompt", "raw"))
    ap.add_argument("--quick", action="store_true", help="4 envs, 3 steps: checks that it runs")
    a = ap.parse_args(argv)
    if a.quick:
        a.envs, a.steps = 4, 3
    from eb_core.gym import make_vector_env
    from eb_core.serve.client import RemoteVectorEnv

    vec = make_vector_env(a.world, a.envs, workers=a.workers, obs_mode=a.obs_mode)
    try:
        _play(vec, a.obs_mode, 2, 1)  # warm up: worlds built, scenes cached
        local_rate, local_lat = _play(vec, a.obs_mode, a.steps, 0)
    finally:
        vec.close()

    server = subprocess.Popen([sys.executable, "-m", "eb_core", "serve", f"env={a.world}", f"envs={a.envs}",
                               f"runner.workers={a.workers}", f"obs_mode={a.obs_mode}", "port=0"],
                              stdout=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline()
        m = re.search(r"ready at (http://\S+)", line)
        if not m:
            print(f"eb serve did not start: {line!r}", file=sys.stderr)
            return 1
        remote = RemoteVectorEnv(m.group(1), a.envs)
        try:
            _play(remote, a.obs_mode, 2, 1)
            http_rate, http_lat = _play(remote, a.obs_mode, a.steps, 0)
            stats = remote.stats()
        finally:
            remote.close()
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=60)

    def ms(x: list[float], q: float) -> float:
        return float(np.percentile(np.array(x) * 1000, q))

    print(f"{a.world}, {a.envs} environments on {a.workers} workers, {a.obs_mode} mode, images on, {a.steps} steps")
    print(f"{'':<14}{'steps/s':>10}{'p50 ms':>10}{'p99 ms':>10}")
    print(f"{'in-process':<14}{local_rate:>10.1f}{ms(local_lat, 50):>10.0f}{ms(local_lat, 99):>10.0f}")
    print(f"{'over HTTP':<14}{http_rate:>10.1f}{ms(http_lat, 50):>10.0f}{ms(http_lat, 99):>10.0f}")
    print(f"ratio (HTTP / in-process): {http_rate / local_rate:.2f}   (goal >= 0.8 at 32 environments)")
    print(f"server-side step p50 {stats['step_latency_ms']['p50']:.0f} ms, p99 {stats['step_latency_ms']['p99']:.0f} ms, "
          f"{stats['batches']} batches")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
