"""Fixtures for the eb-models tests: a real stub OpenAI-compatible server on 127.0.0.1 and a planted key."""

from __future__ import annotations

import json
import signal
import subprocess
import sys

import pytest

from eb_models.stub_server import StubOpenAIServer

#: A fake API key; the tests check it never appears in messages, logs, reprs or written files.
PLANTED_KEY = "sk-planted-7Hq2ZpX91LmVb4Rt"
KEY_ENV = "EB_MODELS_TEST_KEY"


@pytest.fixture
def server():
    with StubOpenAIServer() as s:
        yield s


@pytest.fixture
def planted_key(monkeypatch) -> str:
    monkeypatch.setenv(KEY_ENV, PLANTED_KEY)
    return PLANTED_KEY


@pytest.fixture
def make_backend(server, planted_key, tmp_path):
    """Build a litellm backend pointed at the stub server, with small timeouts and backoffs."""
    from eb_models.litellm_backend import LiteLLMBackend

    made = []

    def make(**over):
        kwargs = dict(model_id="openai/stub-model", api_base=server.url, api_key_env=KEY_ENV, timeout_s=2.0,
                      backoff_base_s=0.01, backoff_max_s=0.05, retry_max_seconds=20, limits_dir=str(tmp_path / "limits"),
                      input_cost_per_token=1e-6, output_cost_per_token=2e-6, structured_output="json_schema")
        kwargs.update(over)
        backend = LiteLLMBackend(**kwargs)
        made.append(backend)
        return backend

    yield make
    for b in made:
        b.close()


def run_isolated(code: str, timeout: float = 600) -> dict:
    """Run ``code`` in a fresh interpreter and return the JSON object its last stdout line prints.

    For native model code (llama.cpp): a segfault or a hang there fails the calling test with one line (the
    signal, or the time limit, and the end of the child's stderr) instead of killing or stalling the pytest
    worker. ``-X faulthandler`` puts the native crash's Python stack in that stderr."""
    try:
        r = subprocess.run([sys.executable, "-X", "faulthandler", "-c", code], capture_output=True, text=True,
                           timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        tail = (exc.stderr or b"")[-1500:]
        pytest.fail(f"the isolated child did not finish within {timeout:g} s (killed); stderr: {tail!r}")
    if r.returncode < 0:
        name = signal.Signals(-r.returncode).name
        pytest.fail(f"the isolated child was killed by {name} (a native crash); stderr: {r.stderr[-3000:]}")
    if r.returncode != 0:
        pytest.fail(f"the isolated child exited with {r.returncode}; stderr: {r.stderr[-3000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])
