"""``eb verify`` speed: replay a Navigation run of the oracle and check it, episode by episode.

    python benchmarks/verify.py [--episodes 300] [--render-run] [--quick]

Plays ``--episodes`` Navigation episodes with ``model=oracle`` through ``eb run`` (rendering off unless
``--render-run``: the records are the same, only the run is slower), then times ``eb verify`` on the run
directory, both as subprocesses (start-up included, as a user sees it). Goal: 300 episodes verified in under
a minute. ``--quick`` plays 10.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def eb(*args: str) -> tuple[float, subprocess.CompletedProcess[str]]:
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "eb_core.cli", *args], capture_output=True, text=True, env=env)
    return time.perf_counter() - t0, r


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=300)
    ap.add_argument("--render-run", action="store_true", help="render during the run (verify never does)")
    ap.add_argument("--quick", action="store_true", help="10 episodes")
    args = ap.parse_args()
    n = 10 if args.quick else args.episodes
    with tempfile.TemporaryDirectory(prefix="eb-verify-bench-") as tmp:
        run_dir = Path(tmp) / "run"
        extra = [] if args.render_run else ["env.params.render=false"]
        run_s, r = eb("run", "env=navigation", "model=oracle", f"limit={n}", "runner.quiet=true", *extra,
                      f"hydra.run.dir={run_dir}")
        if r.returncode:
            print(r.stderr[-2000:], file=sys.stderr)
            return 1
        verify_s, v = eb("verify", str(run_dir))
        if v.returncode:
            print(v.stdout[-2000:] + v.stderr[-2000:], file=sys.stderr)
            return 1
        print(f"{'episodes':>8} {'run s':>8} {'verify s':>9} {'episodes/s':>11}")
        print(f"{n:>8} {run_s:>8.1f} {verify_s:>9.1f} {n / verify_s:>11.1f}")
        print(v.stdout.strip().splitlines()[-1])
        print(f"goal: 300 episodes verified in under 60 s, start-up included (here {n} in {verify_s:.1f} s); "
              f"load {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
