"""Pipeline overhead: the same episodes through the full pipeline (planner, parser, records, step PNGs) with
a zero-latency model (the oracle backend) vs a raw loop that drives the env with the same expert actions.

    python benchmarks/overhead.py [--env navigation] [--limit 20] [--no-images]
    python benchmarks/overhead.py --quick   # a few seconds (what tests/benchmarks runs)

Prints both times, their ratio (goal <= 1.10) and the peak RSS of this process. Both loops run in this one
process, back to back, so machine noise affects them alike; run it twice if the machine is busy.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time

from eb_core.config import validate_config
from eb_core.plugins import Registry
from eb_core.runner import episode_seed, run, select_tasks


def _env_config(registry: Registry, env_name: str) -> dict:
    from eb_core.compose import compose

    cfg = compose([f"env={env_name}", "model=oracle"])
    return cfg


def raw_loop(cfg, env_cls, tasks) -> tuple[float, int]:
    e = cfg.env
    env = env_cls(resolution=e.resolution, multi_view=e.multi_view, **e.params)
    steps = 0
    start = time.perf_counter()
    for task in tasks:
        env.reset(task, episode_seed(cfg.seed, task.id))
        used = 0
        done = False
        while not done and used < e.max_steps:
            plan = env.expert_plan() or []
            if not plan:
                break
            for action in plan[: e.max_steps - used]:
                r = env.step(action)
                used += 1
                if r.done or (not r.action_success and e.replan_on_failure):
                    done = r.done
                    break
        steps += used
    elapsed = time.perf_counter() - start
    env.close()
    return elapsed, steps


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", default="navigation")
    ap.add_argument("--limit", type=int, default=20)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--no-images", action="store_true", help="do not save step PNGs in the pipeline run")
    ap.add_argument("--quick", action="store_true", help="a few seconds: 1 episode at 64 px, once (checks that the "
                    "benchmark runs; its figures mean little)")
    args = ap.parse_args(argv)
    if args.quick:
        args.limit, args.repeat = 1, 1

    registry = Registry.create()
    cfg_dict = _env_config(registry, args.env)
    cfg_dict["limit"] = args.limit
    cfg_dict["runner"]["quiet"] = True
    cfg_dict["runner"]["save_images"] = not args.no_images
    if args.quick:
        cfg_dict["env"]["resolution"] = 64
    cfg = validate_config(cfg_dict)
    env_cls = registry.get("env", cfg.env.name).load()
    tasks = select_tasks(env_cls.load_tasks(**cfg.env.params), cfg)

    raw_loop(cfg, env_cls, tasks[:1])  # warm-up: imports, GL context, caches
    raw_times, pipe_times = [], []
    for _ in range(args.repeat):  # alternate so that load on the machine hits both alike; keep the best
        raw_s, raw_steps = raw_loop(cfg, env_cls, tasks)
        raw_times.append(raw_s)
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            summary = run(cfg, d, cfg_dict=cfg_dict, registry=registry)
            pipe_times.append(time.perf_counter() - t0)
    raw_s, pipe_s = min(raw_times), min(pipe_times)
    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    ratio = pipe_s / raw_s
    print(f"env={cfg.env.name} episodes={len(tasks)} raw env steps={raw_steps} "
          f"pipeline success={summary['overall']['success_rate']:.3f} "
          f"env steps={summary['overall']['avg_env_steps'] * len(tasks):.0f}")
    print(f"raw env loop: {raw_s:.2f} s   full pipeline: {pipe_s:.2f} s   ratio: {ratio:.3f} (goal <= 1.10)")
    print(f"peak RSS: {rss_mb:.0f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
