"""How well do parallel workers hide model latency?

Plays N one-call episodes (default 32) through the real runner (``eb_core.runner.run``) and the real
``litellm`` backend against the stub OpenAI-compatible server (``eb_models.stub_server``) answering every
request after a fixed latency (default 2 s): first serially, then with 8 and 32 worker processes.
Prints each run's wall time and its speed-up over the serial run as a fraction of the ideal
(``min(workers, episodes)``); the goal is >= 0.85.

Two numbers per run:

* end to end: the whole ``run()`` call, including the preflight call and starting the worker
  processes (each worker is a fresh ``spawn``-ed interpreter that imports litellm: seconds of CPU each);
* model phase: from the first episode request the server received to the last answer it sent, i.e.
  how well the runner keeps the workers busy once they are up.

Usage::

    python benchmarks/concurrency.py [--episodes 32] [--latency 2.0] [--workers 1,8,32]
    python benchmarks/concurrency.py --quick   # a few seconds (what tests/benchmarks runs)

The module is also the benchmark's env plugin (a one-action world), registered directly with the
runner; worker processes import it by name, so it must stay importable as ``concurrency``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from eb_core import DiscreteActionSpace, Env, EnvSpec, Observation, PromptParts, StepResult, Task, hookimpl

PLAN = json.dumps({
    "visual_state_description": "a grey square",
    "reasoning_and_reflection": "one action finishes the task",
    "language_plan": "finish",
    "executable_plan": [{"action_id": 0, "action_name": "finish"}],
})


class OneCallEnv(Env):
    """Every task is solved by the single action ``finish``: one model call per episode."""

    name = "one-call"

    def __init__(self, resolution: int = 64, multi_view: bool = False, n_tasks: int = 32) -> None:
        self.resolution = resolution

    @classmethod
    def load_tasks(cls, n_tasks: int = 32) -> list[Task]:
        return [Task(id=f"t{i:03d}", subset="base", instruction="finish the task") for i in range(n_tasks)]

    def _obs(self) -> Observation:
        img = np.full((self.resolution, self.resolution, 3), 128, np.uint8)
        return Observation(images={"front": img}, primary="front", text="a grey square")

    def reset(self, task: Task, seed: int) -> Observation:
        return self._obs()

    def step(self, action: Any) -> StepResult:
        return StepResult(observation=self._obs(), action_success=True, feedback="finished", done=True,
                          task_success=True, progress=1.0)

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=("finish",))

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="You finish tasks.")


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [EnvSpec(name="one-call", entry_point="concurrency:OneCallEnv", subsets={"base": 32},
                    description="benchmark world: one model call per episode")]


def _one_run(plugin: Any, url: str, workers: int, episodes: int, root: Path) -> float:
    import eb_models.plugin
    from eb_core.config import validate_config
    from eb_core.runner import run

    cfg = validate_config({
        "env": {"name": "one-call", "max_steps": 3, "resolution": 64, "params": {"n_tasks": episodes}},
        "model": {"name": "stub", "backend": "litellm", "model_id": "openai/stub-bench", "api_base": url,
                  "input_cost_per_token": 0.0, "output_cost_per_token": 0.0, "timeout_s": 60},
        "planner": {"name": "vlm"},
        "ablation": {"name": "none"},
        "runner": {"workers": workers, "quiet": True, "save_images": False},
    })
    t0 = time.perf_counter()
    summary = run(cfg, root / f"workers-{workers}", plugins=[plugin, eb_models.plugin])
    elapsed = time.perf_counter() - t0
    assert summary["n_finished"] == episodes, summary
    assert summary["overall"]["success_rate"] == 1.0, summary["overall"]
    return elapsed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--episodes", type=int, default=32)
    ap.add_argument("--latency", type=float, default=2.0, help="seconds the stub server takes per answer")
    ap.add_argument("--workers", default="1,8,32", help="comma-separated worker counts; 1 (serial) comes first")
    ap.add_argument("--verbose", action="store_true", help="also print when the first request came and the last ended")
    ap.add_argument("--quick", action="store_true", help="a few seconds: 4 episodes, 0.2 s latency, workers 1,2 "
                    "(checks that the benchmark runs; its figures mean little)")
    args = ap.parse_args(argv)
    if args.quick:
        args.episodes, args.latency, args.workers = 4, 0.2, "1,2"
    counts = [int(w) for w in args.workers.split(",")]
    if counts[0] != 1:
        counts = [1] + counts

    # Only this module and eb-models: other installed plugins play no part (and cost no start-up time).
    os.environ["EB_DISABLE_PLUGIN_AUTOLOAD"] = "1"
    os.environ.pop("EB_PLUGINS", None)
    here = str(Path(__file__).resolve().parent)
    if here not in sys.path:
        sys.path.insert(0, here)
    import concurrency as plugin  # by name, so worker processes can import it too

    from eb_models.litellm_backend import _import_litellm
    from eb_models.stub_server import StubOpenAIServer, StubReply

    _import_litellm()  # warm: the serial run must not pay the main process's one-off import alone

    print(f"{args.episodes} episodes, one model call each, stub latency {args.latency:g} s, "
          f"{os.cpu_count()} CPU(s)")
    print(f"{'workers':>7} {'end-to-end s':>12} {'speed-up':>8} {'of ideal':>8} | {'model phase s':>13} "
          f"{'speed-up':>8} {'of ideal':>8} {'max in flight':>13}")
    base_total = base_phase = None
    with tempfile.TemporaryDirectory(prefix="eb_bench_") as tmp, \
            StubOpenAIServer(default=StubReply(content=PLAN), latency_s=args.latency) as server:
        for w in counts:
            first = len(server.requests)
            server.max_in_flight = 0
            started = time.time()
            total = _one_run(plugin, server.url, w, args.episodes, Path(tmp))
            reqs = [r for r in server.requests[first:] if r.path.endswith("/chat/completions")
                    and isinstance(r.body, dict) and r.body.get("max_tokens") != 8]  # leave out the preflight
            phase = max(r.received_at for r in reqs) + args.latency - min(r.received_at for r in reqs)
            if args.verbose:
                print(f"   debug: run started {started:.1f}, first episode request +{min(r.received_at for r in reqs) - started:.1f} s, "
                      f"last answer +{max(r.received_at for r in reqs) + args.latency - started:.1f} s")
            if base_total is None:
                base_total, base_phase = total, phase
            ideal = min(w, args.episodes)
            s_total, s_phase = base_total / total, base_phase / phase
            print(f"{w:>7} {total:>12.1f} {s_total:>8.2f} {s_total / ideal:>8.2f} | {phase:>13.1f} "
                  f"{s_phase:>8.2f} {s_phase / ideal:>8.2f} {server.max_in_flight:>13}", flush=True)
    print("goal: speed-up >= 0.85 of ideal")
    return 0


if __name__ == "__main__":
    sys.exit(main())
