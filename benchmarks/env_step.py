"""Environment step cost per world: median step time at 500x500 vs one raw MuJoCo render of the same scene
(goal <= 1.6x), reset time, and peak RSS per env process (goal <= 600 MB; manipulation: step <= 1 s).

    python benchmarks/env_step.py [--n 30] [--envs navigation,habitat,alfred,manipulation]

Each env is measured in its own fresh process (so peak RSS is that env's), by the plugin's own
``<package>.bench.step_times(n)``; ratios are computed within one process run, so machine load cancels out.
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


def measure(env: str, n: int) -> dict:
    out = subprocess.run([sys.executable, "-c", _CHILD.format(pkg=PACKAGES[env], n=n)], capture_output=True,
                         text=True, timeout=1800)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    raise RuntimeError(f"{env}: benchmark failed: {(out.stderr or out.stdout).strip().splitlines()[-1:]}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=30)
    ap.add_argument("--envs", default=",".join(PACKAGES))
    args = ap.parse_args()
    print(f"{'env':<13} {'step ms':>8} {'raw render ms':>14} {'ratio':>6} {'reset ms':>9} {'peak RSS MB':>12}")
    for env in args.envs.split(","):
        try:
            r = measure(env, args.n)
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
