"""Environment step cost per world: median step time at 500x500 vs one raw MuJoCo render of the same scene
(goal <= 1.6x), reset time, and peak RSS per env process (goal <= 600 MB; manipulation: step <= 1 s).

    python benchmarks/env_step.py [--n 30] [--envs navigation,habitat,alfred,manipulation]
    python benchmarks/env_step.py --resets [--n 12]     # reset time per world, rendered (goal: median <= 0.25 s)
    python benchmarks/env_step.py --resets --envs manipulation --taskset hard --param tag_layout=clear,corner
                                                        # one row group per param value: the ratio is its cost
    python benchmarks/env_step.py --quick               # a few seconds (what tests/benchmarks runs)

Each env is measured in its own fresh process (so peak RSS is that env's), by the plugin's own
``<package>.bench.step_times(n)``; ratios are computed within one process run, so machine load cancels out.

``--resets`` times ``env.reset`` with rendering at 500 px, as a trainer or ``eb run`` meets it: ``test`` resets
``n`` shipped tasks spread over the task list (each a different scene), ``train`` draws ``n`` fresh tasks of the
generated train split and resets them (generation + reset, as ``gymnasium.make(..., split="train")`` does), and
``again`` resets the first test task again (a group of rollouts from one task). Each row gives the median and
worst wall time and the median CPU time (all threads of the process, the renderer's included: the figure that
other load on the machine changes least); the load average is printed beside them. ``--taskset hard`` times the
hard set's tasks (and train tasks of its difficulty); ``--param key=v1,v2`` sets an env parameter (e.g.
manipulation's ``tag_layout``) and measures once per value, in the same run, then prints each value's median
test reset as a ratio of the first value's.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

PACKAGES = {"navigation": "eb_navigation", "alfred": "eb_alfred", "habitat": "eb_habitat",
            "manipulation": "eb_manipulation"}

_CHILD = """
import json, resource, sys
from {pkg}.bench import step_times
r = step_times({n})
r["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print("RESULT " + json.dumps(r, default=str))
"""


CLASSES = {"navigation": "NavigationEnv", "alfred": "AlfredEnv", "habitat": "HabitatEnv",
           "manipulation": "ManipulationEnv"}

_RESETS = """
import json, statistics, time
from {pkg}.env import {cls} as Env
env = Env(resolution={res}, render=True, **{params!r})
tasks = Env.load_tasks(taskset={taskset!r})
step = max(1, len(tasks) // {n})
def timed(make):
    wall, cpu = [], []
    for i in range({n}):
        w0, c0 = time.perf_counter(), time.process_time()
        make(i)
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return {{"median_s": statistics.median(wall), "max_s": max(wall), "cpu_median_s": statistics.median(cpu)}}
out = {{}}
w0 = time.perf_counter(); env.reset(tasks[-1], 0); out["first_s"] = time.perf_counter() - w0
out["test"] = timed(lambda i: env.reset(tasks[(i * step + 1) % len(tasks)], 0))
out["train"] = timed(lambda i: env.reset(Env.split_tasks("train", 500_000 + 7 * i, 1, taskset={taskset!r})[0], 0))
out["again"] = timed(lambda i: env.reset(tasks[1], 0))
env.close()
print("RESULT " + json.dumps(out))
"""


def measure_resets(env: str, n: int, resolution: int = 500, taskset: str = "classic",
                   params: dict | None = None) -> dict:
    code = _RESETS.format(pkg=PACKAGES[env], cls=CLASSES[env], n=n, res=resolution, taskset=taskset,
                          params=dict(params or {}))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=1800)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    raise RuntimeError(f"{env}: reset benchmark failed: {_last_error(out.stderr or out.stdout)}")


def parse_param(text: str | None) -> tuple[str, list[str]] | None:
    """``key=v1,v2`` -> ("key", ["v1", "v2"]); None for no option. A malformed value is one clear error."""
    if text is None:
        return None
    key, sep, values = text.partition("=")
    if not sep or not key or not values:
        raise SystemExit(f"--param {text!r}: expected KEY=VALUE[,VALUE...], e.g. --param tag_layout=clear,corner")
    return key, values.split(",")


def reset_table(envs: list[str], n: int, taskset: str = "classic",
                param: tuple[str, list[str]] | None = None) -> None:
    import os

    print(f"{'env':<13} {'kind':<6} {'median s':>9} {'max s':>7} {'cpu median s':>13}   (n={n} each, 500 px, "
          f"rendered, taskset={taskset})")
    variants: list[dict] = [{param[0]: v} for v in param[1]] if param else [{}]
    for env in envs:
        first: float | None = None
        for params in variants:
            label = env + "".join(f" {k}={v}" for k, v in params.items())
            load = os.getloadavg()[0]
            try:
                r = measure_resets(env, n, taskset=taskset, params=params)
            except Exception as exc:  # one broken world must not hide the others' numbers
                print(f"{label}: error: {exc}")
                continue
            if params:
                print(label)
            for kind in ("test", "train", "again"):
                m = r[kind]
                print(f"{env:<13} {kind:<6} {m['median_s']:9.3f} {m['max_s']:7.3f} {m['cpu_median_s']:13.3f}")
            print(f"{env:<13} first reset of the process {r['first_s']:.3f} s; load average {load:.1f} -> "
                  f"{os.getloadavg()[0]:.1f}")
            if params:
                first = first or r["test"]["cpu_median_s"]
                print(f"{env:<13} test reset CPU time x{r['test']['cpu_median_s'] / first:.2f} of the first value's")
    print("goal: median reset <= 0.25 s in every world (issue 19)")


def measure(env: str, n: int) -> dict:
    out = subprocess.run([sys.executable, "-c", _CHILD.format(pkg=PACKAGES[env], n=n)], capture_output=True,
                         text=True, timeout=1800)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    raise RuntimeError(f"{env}: benchmark failed: {_last_error(out.stderr or out.stdout)}")


def _last_error(text: str) -> str:
    """The child's own error line: the last line before any "Exception ignored in" report of a destructor that
    ran at exit (which would otherwise hide the error that stopped the child)."""
    head = text.split("Exception ignored in")[0].strip() or text.strip()
    return head.splitlines()[-1] if head else "no output"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=None, help="steps per world (default 30); with --resets: resets "
                    "per kind (default 12)")
    ap.add_argument("--envs", default=",".join(PACKAGES))
    ap.add_argument("--resets", action="store_true", help="time env.reset (test, train, same task again) instead")
    ap.add_argument("--taskset", default="classic", help="with --resets: the shipped task set to reset "
                    "(classic or hard)")
    ap.add_argument("--param", default=None, metavar="KEY=V1[,V2...]", help="with --resets: an env parameter; "
                    "each value is measured in the same run")
    ap.add_argument("--quick", action="store_true", help="a few seconds: 3 steps of navigation only (checks that "
                    "the benchmark runs; its figures mean little)")
    args = ap.parse_args(argv)
    if args.quick:
        args.n, args.envs = args.n or 3, "navigation" if args.envs == ",".join(PACKAGES) else args.envs
    if args.resets:
        reset_table(args.envs.split(","), args.n or 12, args.taskset, parse_param(args.param))
        return 0
    print(f"{'env':<13} {'step ms':>8} {'raw render ms':>14} {'ratio':>6} {'reset ms':>9} {'peak RSS MB':>12}")
    for env in args.envs.split(","):
        try:
            r = measure(env, args.n or 30)
        except Exception as exc:  # one broken world must not hide the others' numbers
            print(f"{env:<13} error: {exc}")
            continue
        if "render" in r and isinstance(r["render"], dict):  # manipulation: IK + motion + render per action
            m = r["render"]
            print(f"{env:<13} {1000 * m['median_s']:8.1f} {'-':>14} {'-':>6} {1000 * m['reset_median_s']:9.1f} "
                  f"{r['peak_rss_mb']:12.0f}   (action = IK + motion + render; goal <= 1000 ms; "
                  f"p90 {1000 * m['p90_s']:.0f} ms; no-render {1000 * r['no_render']['median_s']:.0f} ms)")
        else:
            print(f"{env:<13} {1000 * r['step_s']:8.1f} {1000 * r['raw_render_s']:14.1f} {r['ratio']:6.2f} "
                  f"{1000 * r['reset_s']:9.1f} {r['peak_rss_mb']:12.0f}")
    print("goals: ratio <= 1.6, peak RSS <= 600 MB per env process, manipulation action <= 1 s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
