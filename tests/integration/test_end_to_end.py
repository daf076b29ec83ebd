"""The whole benchmark as a researcher runs it: `eb run` on a real world (navigation, real MuJoCo images)
with the litellm backend talking real HTTP to an OpenAI-compatible server on 127.0.0.1."""

import base64
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from eb_models.stub_server import StubOpenAIServer, StubReply

KEY = "sk-planted-e2e-0123456789abcdef"


def _answer(body):
    """Answer like a model would: read the action list from the prompt and plan two moves forward."""
    content = body["messages"][-1]["content"]
    text = content if isinstance(content, str) else next(p["text"] for p in content if p["type"] == "text")
    actions = dict(re.findall(r"^action id (\d+): (.+)$", text, flags=re.M))
    if not actions:  # the one-call preflight
        return StubReply(content="ok", prompt_tokens=1, completion_tokens=1)
    plan = [{"action_id": 0, "action_name": actions["0"]}] * 2
    content = json.dumps({"visual_state_description": "a room", "reasoning_and_reflection": "walk ahead",
                          "language_plan": "two steps forward", "executable_plan": plan})
    return StubReply(content="```json\n" + content + "\n```", prompt_tokens=1000, completion_tokens=50)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("e2e") / "run"
    with StubOpenAIServer(default=_answer) as server:
        env = dict(os.environ, E2E_KEY=KEY)
        env.pop("EB_DISABLE_PLUGIN_AUTOLOAD", None)
        env.pop("EB_PLUGINS", None)
        r = subprocess.run(
            [sys.executable, "-m", "eb_core", "run", "env=navigation", "model=openai-compatible",
             "model.name=stub-vlm", f"model.api_base={server.url}", "model.api_key_env=E2E_KEY",
             "model.input_cost_per_token=0.000001", "model.output_cost_per_token=0.000002",
             "subset=base", "limit=2", "--quiet", f"hydra.run.dir={d}"],
            capture_output=True, text=True, env=env, timeout=600)
        assert r.returncode == 0, r.stderr[-2000:]
        # the episodes' requests (they carry the image); preflight and structured-output probes are text only
        requests = [q for q in server.requests if q.path.endswith("/chat/completions")
                    and isinstance(q.body, dict) and isinstance(q.body["messages"][-1]["content"], list)]
    return d, requests, r


def test_requests_carry_the_image_first_then_the_prompt(run_dir):
    _, requests, _ = run_dir
    first = requests[0].body
    parts = first["messages"][-1]["content"]
    assert parts[0]["type"] == "image_url" and parts[-1]["type"] == "text"
    png = base64.b64decode(parts[0]["image_url"]["url"].split(",", 1)[1])
    assert png.startswith(b"\x89PNG") and len(png) > 20_000  # a real 500x500 render, not a blank
    text = parts[-1]["text"]
    for section in ("## Action list", "action id 7:", "## Guidelines", "Instruction:", "## Answer format",
                    '"executable_plan"', "Example 1:"):
        assert section in text
    assert first["temperature"] == 0 and first["max_tokens"] == 1024  # a server on this machine: 1024 by default
    assert requests[0].headers.get("Authorization") == f"Bearer {KEY}"


def test_history_and_feedback_reach_the_next_prompt(run_dir):
    _, requests, _ = run_dir
    later = [q.body for q in requests[1:]]
    texts = [next(p["text"] for p in b["messages"][-1]["content"] if p["type"] == "text") for b in later]
    assert any("Step 1: action 0" in t and "Feedback:" in t for t in texts)


def test_results_tokens_and_cost_are_recorded(run_dir):
    d, requests, r = run_dir
    eps = [json.loads(x) for x in (d / "episodes.jsonl").read_text().splitlines()]
    assert len(eps) == 2 and all(e["status"] == "ok" for e in eps)
    assert sum(e["model_calls"] for e in eps) == len(requests)  # the episodes' calls (not preflight, not probes)
    assert all(e["prompt_tokens"] == 1000 * e["model_calls"] and e["completion_tokens"] == 50 * e["model_calls"]
               for e in eps)
    assert abs(sum(e["cost_usd"] for e in eps) - len(requests) * (1000e-6 + 50 * 2e-6)) < 1e-9
    assert all(e["output_errors"] == 0 for e in eps)  # the fenced JSON was parsed
    summary = json.loads((d / "summary.json").read_text())
    assert summary["n_finished"] == 2 and "success rate:" in r.stdout
    # what the backend settled on at preflight is part of the run's summary
    assert summary["model_info"]["backend"] == "litellm" and summary["model_info"]["structured_output"]


def test_the_api_key_is_written_nowhere(run_dir):
    d, _, r = run_dir
    for path in Path(d).rglob("*"):
        if path.is_file():
            assert KEY.encode() not in path.read_bytes(), path
    assert KEY not in r.stdout and KEY not in r.stderr
