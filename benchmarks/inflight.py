"""Many EB-ALFRED episodes in flight on few worker processes: memory and wall time against the model-bound ideal.

Plays N EB-ALFRED episodes with N in flight on ``--workers`` processes (default 2) through the real runner
(``eb_core.runner.run``) and the real ``litellm`` backend against the stub OpenAI-compatible server
(``eb_models.stub_server``) answering every request after a fixed latency (default 2 s). Every answer is the
same three-action plan, so episodes step and render the world between calls (``env.max_steps`` 9 keeps them
short: at most a few calls each). Rendering is on (``env.params.render=true``, 500 px) unless ``--no-render``.

``--plan`` chooses the answers: ``fixed`` (default, the issue's set-up) is that three-action plan, whose first
action fails in most rooms, so most steps leave the view unchanged (ALFRED then reuses the last frame);
``expert`` answers one action per call, the next step of the expert's plan for the task (found from the
instruction and the successful steps in the prompt), so nearly every step changes the view and is drawn.

Printed per run:

* peak RSS of the whole process tree (this process, the workers and anything they start), sampled every
  0.2 s from /proc, and that peak divided by the episodes in flight;
* wall time of ``run()`` (start-up included), start-up (until the first episode request reached the server),
  the model-bound ideal = latency x max(most calls of one episode, ceil(all calls / in flight)), and
  ideal / (wall - start-up) as the fraction of ideal (goal: wall <= 1.5 x ideal + start-up, i.e. >= 0.67).

Usage::

    python benchmarks/inflight.py [--inflight 8,32,64,128] [--workers 2] [--latency 2.0] [--no-render]
                                  [--plan fixed|expert]
    python benchmarks/inflight.py --world-memory 16   # MB per rendered env in each world (one GL pool)
    python benchmarks/inflight.py --step-cpu 10       # CPU seconds per env step and reset in each world
    python benchmarks/inflight.py --quick             # a few seconds (what tests/benchmarks runs)
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

PLAN = json.dumps({
    "visual_state_description": "a kitchen",
    "reasoning_and_reflection": "try the first actions",
    "language_plan": "three actions",
    "executable_plan": [{"action_id": 0}, {"action_id": 1}, {"action_id": 2}],
})


def tree_rss_mb(root: int) -> float:
    """Resident memory of ``root`` and all its descendants, in MB (from /proc)."""
    total, stack, seen = 0, [root], set()
    while stack:
        pid = stack.pop()
        if pid in seen:
            continue
        seen.add(pid)
        try:
            total += int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE")
            for task in Path(f"/proc/{pid}/task").iterdir():
                kids = (task / "children").read_text().split()
                stack.extend(int(k) for k in kids)
        except (OSError, ValueError):
            continue
    return total / 2**20


class PeakSampler:
    def __init__(self, period_s: float = 0.2) -> None:
        self.period_s, self.peak, self._stop = period_s, 0.0, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.is_set():
            self.peak = max(self.peak, tree_rss_mb(os.getpid()))
            self._stop.wait(self.period_s)

    def __enter__(self) -> "PeakSampler":
        self._thread.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._stop.set()
        self._thread.join()


def alfred_env(render: bool) -> dict[str, Any]:
    import yaml

    import eb_alfred

    conf = Path(list(eb_alfred.__path__)[0]) / "conf" / "env" / "alfred.yaml"
    env = yaml.safe_load(conf.read_text())
    env["max_steps"] = 9
    env["params"] = {**env.get("params", {}), "render": render}
    return env


def expert_responder(n: int) -> Any:
    """A stub responder that plays the expert: for the first ``n`` ALFRED tasks (the ones a run with
    ``limit=n`` plays), the next action of the task's expert plan, one per call."""
    import re

    from eb_alfred.env import AlfredEnv
    from eb_models.stub_server import StubReply

    plans: dict[tuple[str, int], list[tuple[int, str]]] = {}
    for task in AlfredEnv.load_tasks()[:n]:
        env = AlfredEnv(render=False)
        env.reset(task, 0)
        names = env.action_space().actions
        # (instruction, length of the action list): the list's length tells rooms with the same instruction apart
        plans[(task.instruction, len(names))] = [(a, names[a]) for a in env.expert_plan() or [0]]

    def answer(body: Any) -> StubReply:
        text = "\n".join(part.get("text", "") if isinstance(part, dict) else str(part)
                         for m in body.get("messages", []) if m.get("role") == "user"
                         for part in (m["content"] if isinstance(m["content"], list) else [m["content"]]))
        instruction = re.findall(r"^Instruction: (.*)$", text, re.M)
        ids = [int(x) for x in re.findall(r"^action id (\d+):", text, re.M)]
        plan = plans.get((instruction[-1] if instruction else "", max(ids) + 1 if ids else 0), [(0, "")])
        history = text.rsplit("## What you have done so far", 1)[-1].split("\n## ", 1)[0]
        done = history.count("-> succeeded")
        a, name = plan[min(done, len(plan) - 1)]
        return StubReply(content=json.dumps({
            "visual_state_description": "a room", "reasoning_and_reflection": "follow the plan",
            "language_plan": f"1. {name}", "executable_plan": [{"action_id": a, "action_name": name}]}))

    return answer


def one_run(url: str, inflight: int, workers: int, root: Path, render: bool) -> dict[str, Any]:
    import eb_alfred.plugin
    import eb_models.plugin
    from eb_core.config import validate_config
    from eb_core.runner import run

    cfg = validate_config({
        "env": alfred_env(render),
        "model": {"name": "stub", "backend": "litellm", "model_id": "openai/stub-bench", "api_base": url,
                  "input_cost_per_token": 0.0, "output_cost_per_token": 0.0, "timeout_s": 120},
        "planner": {"name": "vlm"},
        "ablation": {"name": "none"},
        "limit": inflight,
        "runner": {"workers": workers, "concurrency": inflight, "quiet": True, "save_images": False},
    })
    out = root / f"inflight-{inflight}"
    t0 = time.perf_counter()
    cpu0 = _cpu()
    with PeakSampler() as sampler:
        started = time.time()
        summary = run(cfg, out, plugins=[eb_alfred.plugin, eb_models.plugin])
    wall = time.perf_counter() - t0
    cpu1 = _cpu()
    load = os.getloadavg()[0]
    recs = [json.loads(x) for x in (out / "episodes.jsonl").read_text().splitlines()]
    assert summary["n_finished"] == inflight, summary
    steps = sum(r["env_steps"] for r in recs)
    return {"wall": wall, "peak": sampler.peak, "started": started, "calls": [r["model_calls"] for r in recs],
            "steps": steps, "cpu_workers": cpu1[1] - cpu0[1], "cpu_main": cpu1[0] - cpu0[0], "load": load}


def _cpu() -> tuple[float, float]:
    """CPU seconds (user + system) of this process (run loop, stub server, sampler) and of its finished children
    (the worker processes, once joined)."""
    import resource

    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime


WORLDS = {"navigation": "eb_navigation", "alfred": "eb_alfred", "habitat": "eb_habitat",
          "manipulation": "eb_manipulation"}


def step_cpu(n: int) -> None:
    """CPU seconds per env step (render + PNG encode of the image the model sees), each world in this process."""
    import yaml

    from eb_core.plugins import Registry, get_plugin_manager
    from eb_core.planner import encode_png

    registry = Registry(get_plugin_manager())
    print(f"{'world':>12} {'CPU s/step':>10} {'reset CPU s':>11}  (500 px, rendered; PNG encode included)")
    for world, pkg in WORLDS.items():
        mod = __import__(pkg)
        conf = yaml.safe_load((Path(list(mod.__path__)[0]) / "conf" / "env" / f"{world}.yaml").read_text())
        cls = registry.get("env", world).load()
        env = cls(resolution=conf.get("resolution", 500), multi_view=False, **conf.get("params", {}))
        task = cls.load_tasks(**conf.get("params", {}))[0]
        t0 = time.process_time()
        env.reset(task, 0)
        reset_s = time.process_time() - t0
        plan = list(env.expert_plan() or [])
        t0, steps = time.process_time(), 0
        while steps < n:
            action = plan.pop(0) if plan else 0
            res = env.step(action)
            if res.observation.primary_image is not None:
                encode_png(res.observation.primary_image)
            steps += 1
            if res.done:
                env.reset(task, steps)
                plan = list(env.expert_plan() or [])
        print(f"{world:>12} {(time.process_time() - t0) / steps:>10.3f} {reset_s:>11.2f}", flush=True)
        env.close()


def world_memory(n: int) -> None:
    """Memory per rendered in-flight episode in every world: ``n`` envs of one world, each reset to another task,
    in a fresh process (one GL pool; and, for comparison, private renderers: ``EB_SCENEKIT_PRIVATE_GL=1``)."""
    import subprocess

    print(f"{'world':>12} {'GL':>8} {'process MB':>10} {'first env MB':>12} {'MB per further env':>18} "
          f"{'GL contexts':>11}  ({n} envs in one process, 500 px, rendered, each reset to another task)")
    for world in WORLDS:
        for mode in ("pooled", "private"):
            env = {**os.environ, "EB_SCENEKIT_PRIVATE_GL": "1" if mode == "private" else "0"}
            out = subprocess.run([sys.executable, __file__, "--world-memory-one", f"{world}:{n}"], env=env,
                                 capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1]
            base, first, further, contexts = json.loads(out)
            print(f"{world:>12} {mode:>8} {base:>10.0f} {first:>12.0f} {further:>18.1f} {contexts:>11}", flush=True)


def _world_memory_one(spec: str) -> None:
    import gc

    import yaml

    from eb_core.plugins import Registry, get_plugin_manager
    from eb_scenekit import pool

    world, n = spec.split(":")[0], int(spec.split(":")[1])

    def rss() -> float:
        return int(Path("/proc/self/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20

    mod = __import__(WORLDS[world])
    conf = yaml.safe_load((Path(list(mod.__path__)[0]) / "conf" / "env" / f"{world}.yaml").read_text())
    cls = Registry(get_plugin_manager()).get("env", world).load()
    tasks = cls.load_tasks(**conf.get("params", {}))
    tasks = [tasks[(i * len(tasks)) // n] for i in range(n)]  # spread over the subsets
    gc.collect()
    r0 = rss()
    envs, contexts = [], 0
    for i, task in enumerate(tasks):
        env = cls(resolution=conf.get("resolution", 500), multi_view=False, **conf.get("params", {}))
        env.reset(task, 0)
        envs.append(env)
        if i == 0:
            r1 = rss()
    r2 = rss()
    contexts = pool.pool_stats()["contexts"]  # 0 when every renderer is private
    print(json.dumps([r0, r1 - r0, (r2 - r1) / max(1, n - 1), contexts]))
    for env in envs:
        env.close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--inflight", default="8,32,64,128", help="comma-separated episodes in flight (= episodes)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--latency", type=float, default=2.0, help="seconds the stub server takes per answer")
    ap.add_argument("--no-render", action="store_true", help="env.params.render=false (text-only observations)")
    ap.add_argument("--plan", choices=("fixed", "expert"), default="fixed",
                    help="the stub's answers: fixed = one three-action plan (mostly failing: the view rarely "
                         "changes); expert = the next expert action, one per call (nearly every step is drawn)")
    ap.add_argument("--step-cpu", type=int, default=0, metavar="N",
                    help="instead: CPU seconds per env step of every world (N steps each), then exit")
    ap.add_argument("--world-memory", type=int, default=0, metavar="N",
                    help="instead: memory per rendered env in every world (N envs in one process), then exit")
    ap.add_argument("--world-memory-one", default="", help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="a few seconds: 2 episodes in flight on 1 worker, 0.1 s "
                    "latency, no rendering (checks that the benchmark runs; its figures mean little)")
    args = ap.parse_args(argv)
    if args.quick:
        args.inflight, args.workers, args.latency, args.no_render = "2", 1, 0.1, True
    if args.world_memory_one:
        _world_memory_one(args.world_memory_one)
        return 0
    if args.world_memory:
        world_memory(args.world_memory)
        return 0
    if args.step_cpu:
        step_cpu(args.step_cpu)
        return 0
    os.environ["EB_DISABLE_PLUGIN_AUTOLOAD"] = "1"
    os.environ.pop("EB_PLUGINS", None)

    from eb_models.litellm_backend import _import_litellm
    from eb_models.stub_server import StubOpenAIServer, StubReply

    _import_litellm()
    render = not args.no_render
    print(f"EB-ALFRED, {args.workers} worker processes, stub latency {args.latency:g} s, render={render}, "
          f"plan={args.plan}, {os.cpu_count()} CPU(s)")
    print(f"{'in flight':>9} {'peak MB':>8} {'MB/ep':>6} | {'wall s':>7} {'start-up s':>10} {'ideal s':>7} "
          f"{'of ideal':>8} {'calls':>5} {'max in flight':>13} {'env steps':>9} | {'CPU s':>6} {'workers':>7} "
          f"{'ms/step':>7} {'CPU budget s':>12} {'load':>5}")
    sizes = [int(x) for x in args.inflight.split(",")]
    default = StubReply(content=PLAN) if args.plan == "fixed" else expert_responder(max(sizes))
    with tempfile.TemporaryDirectory(prefix="eb_inflight_") as tmp, \
            StubOpenAIServer(default=default, latency_s=args.latency) as server:
        for n in sizes:
            first = len(server.requests)
            server.max_in_flight = 0
            r = one_run(server.url, n, args.workers, Path(tmp), render)
            reqs = [q for q in server.requests[first:] if q.path.endswith("/chat/completions")
                    and isinstance(q.body, dict) and q.body.get("max_tokens") != 8]  # leave out the preflight
            startup = min(q.received_at for q in reqs) - r["started"]
            calls = r["calls"]
            ideal = args.latency * max(max(calls), math.ceil(sum(calls) / n))
            frac = ideal / max(1e-9, r["wall"] - startup)
            cpu = r["cpu_workers"] + r["cpu_main"]
            budget = (os.cpu_count() or 1) * (1.5 * ideal + startup)  # CPU seconds the goal's wall time allows
            print(f"{n:>9} {r['peak']:>8.0f} {r['peak'] / n:>6.1f} | {r['wall']:>7.1f} {startup:>10.1f} "
                  f"{ideal:>7.1f} {frac:>8.2f} {sum(calls):>5} {server.max_in_flight:>13} {r['steps']:>9} | "
                  f"{cpu:>6.1f} {r['cpu_workers']:>7.1f} {1000 * r['cpu_workers'] / max(1, r['steps']):>7.0f} "
                  f"{budget:>12.1f} {r['load']:>5.1f}", flush=True)
    print("goals at 64 in flight: peak <= 3000 MB; wall <= 1.5 x ideal + start-up (of ideal >= 0.67)")
    print("CPU s = this process (run loop, stub server) + the worker processes; ms/step = workers' CPU per env "
          "step (reset, render, PNG, prompt, litellm call, records); CPU budget = cores x (1.5 x ideal + start-up); "
          "load = 1-min load average at the end (other jobs on the machine)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
