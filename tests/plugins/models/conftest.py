"""Fixtures for the eb-models tests: a real stub OpenAI-compatible server on 127.0.0.1 and a planted key."""

from __future__ import annotations

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
