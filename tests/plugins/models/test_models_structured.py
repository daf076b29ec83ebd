"""Structured-output modes, the ``auto`` probe and deterministic refusals, over real HTTP to the stub server.

The stub plays the servers measured in the issue: llama-cpp-python's (``json_schema`` refused with a
FastAPI validation error worded as HTTP 500; ``json_object`` + ``schema`` grammar-constrained), a plain
JSON-mode server and one that ignores ``response_format`` altogether.
"""

from __future__ import annotations

import json
import logging
import socket
import time

import pytest
from conftest import KEY_ENV

from eb_core.env import DiscreteActionSpace
from eb_core.model import Message, ModelFatalError, ModelRequest, ModelTransientError, TextPart, Usage
from eb_core.planner import response_schema
from eb_models.stub_server import StubOpenAIServer, StubReply
from eb_models.structured import probe_answer_ok, rejected_field, response_format

SPACE = DiscreteActionSpace(actions=("step left", "step right"))
#: What llama-cpp-python 0.3.36's server answers to response_format json_schema (HTTP 500).
LLAMA_CPP_500 = json.dumps({"error": {"message": "[{'type': 'literal_error', 'loc': ('body', 'response_format', "
                                      "'type'), 'msg': \"Input should be 'text' or 'json_object'\", 'input': "
                                      "'json_schema', 'ctx': {'expected': \"'text' or 'json_object'\"}}]",
                                      "type": "internal_server_error"}})
PLAN = json.dumps({"visual_state_description": "-", "reasoning_and_reflection": "-", "language_plan": "-",
                   "executable_plan": [{"action_id": 1, "action_name": "step right"}]})


def plan_request() -> ModelRequest:
    return ModelRequest(messages=(Message(role="user", content=(TextPart(text="Plan."),)),),
                        response_schema=response_schema(SPACE, True))


def chat(server: StubOpenAIServer) -> list:
    return [r.body for r in server.requests if r.path.endswith("/chat/completions")]


def llama_cpp_like(body):
    """Refuses json_schema like llama-cpp-python; obeys a schema sent with json_object."""
    fmt = body.get("response_format") or {}
    if fmt.get("type") == "json_schema":
        return StubReply(status=500, body=LLAMA_CPP_500)
    if fmt.get("type") == "json_object" and "schema" in fmt:
        props = fmt["schema"].get("properties", {})
        return StubReply(content='{"ok": true}' if "ok" in props else PLAN, completion_tokens=4)
    return StubReply(content="```json\n{\"thoughts\": \"I will now ramble", completion_tokens=24)


@pytest.fixture
def make(server, planted_key, tmp_path):
    from eb_models.litellm_backend import LiteLLMBackend

    def make(**over):
        kwargs = dict(model_id=f"openai/m{time.monotonic_ns()}", api_base=server.url, api_key_env=KEY_ENV,
                      timeout_s=2.0, backoff_base_s=0.01, backoff_max_s=0.05, retry_max_seconds=20,
                      limits_dir=str(tmp_path / "limits"), structured_output="auto")
        kwargs.update(over)
        return LiteLLMBackend(**kwargs)

    return make


def test_auto_settles_on_json_object_schema_for_a_llama_cpp_like_server(make, server, capsys):
    server.default = llama_cpp_like
    backend = make()
    usage = backend.preflight()
    sent = chat(server)
    assert [b["response_format"]["type"] for b in sent] == ["json_schema", "json_object"]  # refusal not retried
    assert isinstance(usage, Usage) and usage.calls == 1 and usage.completion_tokens == 4
    assert backend.structured_output == "json_object_schema" and backend.supports_json_schema is True
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert line.startswith("structured output: json_object_schema (json_schema: refused (response_format.type)")
    assert backend.info()["structured_output"] == "json_object_schema"
    resp = backend.complete(plan_request())
    assert resp.text == PLAN
    fmt = chat(server)[-1]["response_format"]
    assert fmt["type"] == "json_object" and fmt["schema"]["required"][-1] == "executable_plan"


def test_a_second_backend_of_the_run_reuses_the_settled_mode(make, server):
    server.default = llama_cpp_like
    first = make()
    first.preflight()
    n = len(chat(server))
    second = make(model_id=first.settings.model_id)
    assert second.settle() == "json_object_schema" and len(chat(server)) == n  # no second probe


def test_a_backend_without_preflight_probes_on_first_use(make, server):
    server.default = llama_cpp_like
    backend = make()
    assert backend.supports_json_schema is True  # the planner asks this first
    assert len(chat(server)) == 2


def test_auto_falls_back_to_plain_json_mode(make, server):
    def json_mode_only(body):
        fmt = body.get("response_format") or {}
        if fmt.get("type") == "json_schema":
            return StubReply(status=400, error_message="response_format.type json_schema is not supported")
        if fmt.get("type") == "json_object":  # JSON, but the schema is ignored
            return StubReply(content='{"answer": "OK"}')
        return StubReply(content="OK")

    server.default = json_mode_only
    backend = make()
    usage = backend.preflight()
    assert backend.structured_output == "json_object" and backend.supports_json_schema is False
    assert "json_object_schema: accepted but not obeyed" in backend.structured_output_why
    assert usage.calls == 2
    backend.complete(plan_request())
    assert chat(server)[-1]["response_format"] == {"type": "json_object"}


def test_auto_ends_at_none_when_the_server_ignores_response_format(make, server):
    server.default = StubReply(content="Sure! Here you go: OK")
    backend = make()
    backend.preflight()
    assert backend.structured_output == "none" and backend.supports_json_schema is False
    assert len(chat(server)) == 4
    backend.complete(plan_request())
    assert "response_format" not in chat(server)[-1]


def test_a_fixed_mode_is_sent_as_configured(make, server):
    server.default = llama_cpp_like
    backend = make(structured_output="json_object_schema")
    assert backend.preflight().calls == 1
    assert chat(server)[0]["response_format"]["type"] == "json_object"
    assert backend.info()["structured_output_why"] == "set by model.structured_output"


def test_a_500_validation_error_is_not_retried_and_names_the_field(make, server):
    server.default = llama_cpp_like
    backend = make(structured_output="json_schema")
    with pytest.raises(ModelTransientError) as err:
        backend.complete(plan_request())
    assert len(chat(server)) == 1
    msg = str(err.value)
    assert "response_format.type" in msg and "structured_output" in msg and "\n" not in msg
    with pytest.raises(ModelFatalError, match="refuses the request field 'response_format.type'"):
        backend.preflight()


@pytest.mark.parametrize("status", [400, 405, 413, 422])
def test_deterministic_refusals_are_not_retried(make, server, status):
    server.default = StubReply(status=status, error_message="max_tokens: Input should be less than 512")
    with pytest.raises(ModelTransientError, match="not retried.*'max_tokens'.*model.max_tokens"):
        make(structured_output="none").complete(plan_request())
    assert len(chat(server)) == 1


def test_a_plain_500_is_still_retried(make, server):
    server.push(StubReply(status=500, error_message="CUDA out of memory"), StubReply(content=PLAN))
    assert make(structured_output="none").complete(plan_request()).text == PLAN
    assert len(chat(server)) == 2


def test_a_refused_local_connection_fails_preflight_at_once(planted_key, tmp_path):
    from eb_models.litellm_backend import LiteLLMBackend

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"http://127.0.0.1:{port}/v1"
    backend = LiteLLMBackend(model_id="openai/x", api_base=url, max_retries=5, limits_dir=str(tmp_path))
    t0 = time.monotonic()
    with pytest.raises(ModelFatalError, match=f"nothing answers at {url}.*model.api_base") as err:
        backend.preflight()
    assert time.monotonic() - t0 < 5 and "\n" not in str(err.value)


def test_deprecated_alias_maps_with_one_warning(make, caplog):
    import eb_models.litellm_backend as lb

    lb._WARNED_ALIAS = False
    with caplog.at_level(logging.WARNING, logger="eb_models.litellm"):
        on = make(supports_json_schema=True, structured_output=None)
        off = make(supports_json_schema=False, structured_output=None)
    assert on.structured_output == "json_schema" and off.structured_output == "none"
    warnings = [r for r in caplog.records if "deprecated" in r.getMessage()]
    assert len(warnings) == 1 and "model.structured_output=json_schema" in warnings[0].getMessage()


def test_max_tokens_defaults_by_where_the_server_is(make, planted_key, tmp_path):
    from eb_models.litellm_backend import LiteLLMBackend

    assert make(structured_output="none").max_tokens == 1024
    assert make(structured_output="none", max_tokens=4096).max_tokens == 4096
    remote = LiteLLMBackend(model_id="openai/gpt-4o", api_key_env=KEY_ENV, structured_output="json_schema")
    assert remote.max_tokens == 2048


def test_a_bad_mode_is_one_clear_line(make):
    from eb_models._settings import ModelConfigError

    with pytest.raises(ModelConfigError, match="model.structured_output.*json_object_schema"):
        make(structured_output="grammar")


def test_rejected_field_reads_the_servers_wordings():
    assert rejected_field(LLAMA_CPP_500) == "response_format.type"
    assert rejected_field("response_format.type: Input should be 'text' or 'json_object'") == "response_format.type"
    assert rejected_field('{"detail":[{"loc":["body","max_tokens"],"msg":"field required"}]}') == "max_tokens"
    assert rejected_field("CUDA out of memory") is None
    assert rejected_field("Internal error in model.forward") is None


def test_response_format_of_each_mode():
    schema = {"name": "plan", "schema": {"type": "object"}}
    assert response_format("json_schema", schema)["json_schema"]["name"] == "plan"
    assert response_format("json_object_schema", schema) == {"type": "json_object", "schema": {"type": "object"}}
    assert response_format("json_object", None) == {"type": "json_object"}
    assert response_format("none", schema) is None
    assert probe_answer_ok("json_object_schema", '{"ok": false}')
    assert not probe_answer_ok("json_object_schema", '{"ok": "yes"}')
    assert not probe_answer_ok("json_object", "OK")


def _worker_settle(url: str, model_id: str, limits_dir: str, out: str) -> None:
    import os

    from eb_models.litellm_backend import LiteLLMBackend, _SETTLED

    _SETTLED.clear()  # a spawned worker starts empty; only the file written by its parent can tell it
    os.environ[KEY_ENV] = "sk-worker"
    b = LiteLLMBackend(model_id=model_id, api_base=url, api_key_env=KEY_ENV, limits_dir=limits_dir,
                       structured_output="auto")
    with open(out, "w") as fh:
        fh.write(b.settle())


def test_worker_processes_read_the_mode_their_runner_settled(make, server, tmp_path):
    import multiprocessing as mp

    server.default = llama_cpp_like
    runner_side = make()
    runner_side.preflight()
    n = len(chat(server))
    out = tmp_path / "mode.txt"
    p = mp.get_context("fork").Process(target=_worker_settle, args=(server.url, runner_side.settings.model_id,
                                                                     str(tmp_path / "limits"), str(out)))
    p.start()
    p.join(60)
    assert p.exitcode == 0 and out.read_text() == "json_object_schema"
    assert len(chat(server)) == n  # the worker did not probe again
