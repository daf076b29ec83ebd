"""The litellm backend over real HTTP against the stub OpenAI-compatible server (no client is patched)."""

from __future__ import annotations

import base64
import json
import logging
import multiprocessing as mp
import os
import socket
import sys
import time

import pytest
from conftest import KEY_ENV, PLANTED_KEY

from eb_core.env import DiscreteActionSpace
from eb_core.model import ImagePart, Message, ModelFatalError, ModelRequest, ModelTransientError, TextPart
from eb_core.parsing import parse_planner_output
from eb_core.planner import response_schema
from eb_models._settings import ModelConfigError
from eb_models.stub_server import StubOpenAIServer, StubReply

PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJRU5ErkJggg=="
)
SPACE = DiscreteActionSpace(actions=("step left", "step right", "press the button"))
PLAN = json.dumps({"visual_state_description": "a line", "reasoning_and_reflection": "go",
                   "language_plan": "right", "executable_plan": [{"action_id": 1, "action_name": "step right"}]})


def request(text: str = "Plan the next actions.", schema: bool = True, **kw) -> ModelRequest:
    content = (ImagePart(png=PNG, name="front"), TextPart(text=text))
    return ModelRequest(messages=(Message(role="user", content=content),),
                        response_schema=response_schema(SPACE, False) if schema else None, **kw)


def chat_requests(server: StubOpenAIServer) -> list:
    return [r for r in server.requests if r.path.endswith("/chat/completions")]


# -- what is sent and what comes back -----------------------------------------------------------------


def test_request_shape_and_recorded_usage(make_backend, server):
    server.push(StubReply(content=PLAN, prompt_tokens=123, completion_tokens=45))
    backend = make_backend(json_schema_strict=None)  # null = strict when the schema fits strict mode
    resp = backend.complete(request(seed=7))
    assert resp.text == PLAN and not resp.cached
    assert (resp.usage.prompt_tokens, resp.usage.completion_tokens, resp.usage.calls) == (123, 45, 1)
    assert resp.usage.cost_usd == pytest.approx(123 * 1e-6 + 45 * 2e-6)
    assert resp.usage.latency_s > 0
    [sent] = chat_requests(server)
    body = sent.body
    assert sent.headers["Authorization"] == f"Bearer {PLANTED_KEY}"  # the key is used, only on the wire
    assert body["model"] == "stub-model"
    assert body["temperature"] == 0 and body["max_tokens"] == 1024 and body["seed"] == 7
    image, text = body["messages"][0]["content"]
    assert image == {"type": "image_url", "image_url": {"url": "data:image/png;base64," + base64.b64encode(PNG).decode()}}
    assert text == {"type": "text", "text": "Plan the next actions."}
    fmt = body["response_format"]
    assert fmt["type"] == "json_schema" and fmt["json_schema"]["name"] == "embodied_plan"
    assert fmt["json_schema"]["schema"]["required"][-1] == "executable_plan"
    assert fmt["json_schema"]["strict"] is True  # the discrete plan schema fits OpenAI strict mode
    # once the bounds strict mode refuses are left out; the ids stay limited to the action list
    item = fmt["json_schema"]["schema"]["properties"]["executable_plan"]["items"]["properties"]
    assert item["action_id"]["enum"] == list(range(len(SPACE))) and "maxLength" not in item["action_name"]


def test_the_whole_schema_with_its_bounds_when_not_strict(make_backend, server):
    server.push(StubReply(content=PLAN))
    make_backend().complete(request(schema=False, seed=1).model_copy(update={"response_schema": response_schema(
        SPACE, False, max_plan_length=4, empty_plan_ok=False)}))
    fmt = chat_requests(server)[0].body["response_format"]["json_schema"]
    assert fmt["strict"] is False  # the presets' default, as the original (which sent no strict flag)
    plan = fmt["schema"]["properties"]["executable_plan"]
    assert plan["minItems"] == 1 and plan["maxItems"] == 4
    assert plan["items"]["properties"]["action_name"]["maxLength"] == max(len(a) for a in SPACE.actions)


def test_textual_format_when_the_preset_has_no_json_schema(make_backend, server):
    backend = make_backend(structured_output="none")
    assert backend.supports_json_schema is False
    backend.complete(request())
    assert "response_format" not in chat_requests(server)[0].body


def test_malformed_and_fenced_answers_come_back_verbatim(make_backend, server):
    fenced = "Here is my plan:\n```json\n" + PLAN + "\n```"
    broken = '{"executable_plan": [{"action_id": 1, "action_na'
    server.push(StubReply(content=fenced), StubReply(content=broken), StubReply(content=None))
    backend = make_backend()
    assert backend.complete(request()).text == fenced
    assert parse_planner_output(fenced, SPACE, 20).actions == [1]  # the planner's parser copes with fences
    assert backend.complete(request()).text == broken
    assert parse_planner_output(broken, SPACE, 20).error is not None
    assert backend.complete(request()).text == ""  # no content at all: an empty answer, never a crash
    assert len(chat_requests(server)) == 3  # answers are not retried: the planner decides what they are worth


def test_a_megabyte_answer(make_backend, server):
    big = "x" * 1_000_000
    server.push(StubReply(content=big, completion_tokens=250_000))
    resp = make_backend().complete(request())
    assert resp.text == big and resp.usage.completion_tokens == 250_000


# -- faults ---------------------------------------------------------------------------------------------


def test_429_waits_for_retry_after(make_backend, server):
    server.push(StubReply(status=429, headers={"Retry-After": "1"}), StubReply(content=PLAN))
    t0 = time.monotonic()
    resp = make_backend().complete(request())
    assert resp.text == PLAN
    assert time.monotonic() - t0 >= 0.95  # backoff alone would be ~0.01 s
    assert len(chat_requests(server)) == 2


def test_5xx_and_truncated_bodies_are_retried(make_backend, server):
    server.push(StubReply(status=500), StubReply(status=502, body="<html>bad gateway</html>"),
                StubReply(body='{"id": "chatcmpl-1", "object": "chat.completion", "choi'),
                StubReply(content=PLAN, prompt_tokens=9))
    resp = make_backend().complete(request())
    assert resp.text == PLAN and resp.usage.prompt_tokens == 9
    assert len(chat_requests(server)) == 4


def test_retries_are_capped_by_attempts(make_backend, server):
    server.default = StubReply(status=503)
    with pytest.raises(ModelTransientError, match=r"gave up after 4 attempt\(s\)") as info:
        make_backend(max_retries=3).complete(request())
    assert len(chat_requests(server)) == 4
    assert "HTTP 503" in str(info.value)


def test_retries_are_capped_by_time(make_backend, server):
    server.default = StubReply(status=429, headers={"Retry-After": "30"})
    t0 = time.monotonic()
    with pytest.raises(ModelTransientError, match="gave up after 1 attempt"):
        make_backend(retry_max_seconds=1.0).complete(request())
    assert time.monotonic() - t0 < 1.0  # it does not sleep 30 s to find out
    assert len(chat_requests(server)) == 1


def test_slow_answers_time_out_and_are_retried(make_backend, server):
    backend = make_backend(timeout_s=0.3, max_retries=1)
    backend.complete(request())  # warm up: litellm's first call in a process is slow on a loaded machine
    server.default = StubReply(content=PLAN, delay_s=1.0)
    t0 = time.monotonic()
    with pytest.raises(ModelTransientError, match="Timeout"):
        backend.complete(request())
    assert time.monotonic() - t0 < 1.95  # waiting for both slow answers would take 2 s
    assert len(chat_requests(server)) == 3


def test_unreachable_server_is_a_transient_error(planted_key, tmp_path):
    from eb_models.litellm_backend import LiteLLMBackend

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    backend = LiteLLMBackend(model_id="openai/stub-model", api_base=f"http://127.0.0.1:{port}/v1",
                             max_retries=2, backoff_base_s=0.01, timeout_s=1)
    with pytest.raises(ModelTransientError, match="gave up after 3 attempt"):
        backend.complete(request())


UNRESOLVABLE = "http://nonexistent.invalid/v1"  # RFC 6761: .invalid never resolves


def test_an_unresolvable_host_fails_preflight_at_once_as_a_dns_error(planted_key, caplog):
    from eb_models.litellm_backend import LiteLLMBackend

    backend = LiteLLMBackend(model_id="openai/stub-model", api_base=UNRESOLVABLE, api_key_env=KEY_ENV)
    with caplog.at_level(logging.WARNING, logger="eb_models"), pytest.raises(ModelFatalError) as err:
        backend.preflight()
    msg = str(err.value)
    assert "DNS error: cannot resolve the host 'nonexistent.invalid'" in msg and UNRESOLVABLE in msg, msg
    assert "HTTP 500" not in msg and "\n" not in msg
    assert not [r for r in caplog.records if "retry" in r.getMessage()]  # nothing was retried


def test_a_dns_failure_while_probing_is_fatal_at_once(planted_key, caplog):
    """The ``auto`` probe's own call (what a preflight without the host check would meet): no retries."""
    from eb_models.litellm_backend import LiteLLMBackend

    backend = LiteLLMBackend(model_id="openai/stub-model", api_base=UNRESOLVABLE, api_key_env=KEY_ENV,
                             structured_output="auto", max_retries=5, backoff_base_s=1.0)
    with caplog.at_level(logging.WARNING, logger="eb_models"), pytest.raises(ModelFatalError) as err:
        backend.settle()
    assert "DNS error: cannot resolve the host 'nonexistent.invalid'" in str(err.value), str(err.value)
    assert "HTTP 500" not in str(err.value)
    assert not [r for r in caplog.records if "retry" in r.getMessage()]


def test_during_a_run_a_dns_failure_is_named_not_an_http_500(planted_key, caplog):
    from eb_models.litellm_backend import LiteLLMBackend

    backend = LiteLLMBackend(model_id="openai/stub-model", api_base=UNRESOLVABLE, api_key_env=KEY_ENV,
                             max_retries=1, backoff_base_s=0.01)
    with caplog.at_level(logging.WARNING, logger="eb_models"), pytest.raises(ModelTransientError) as err:
        backend.complete(request())
    msg = str(err.value)  # mid-run the name resolved at preflight: a network blip, so retried (max_retries)
    assert "gave up after 2 attempt" in msg and "DNS error: cannot resolve the host 'nonexistent.invalid'" in msg
    assert "HTTP 500" not in msg and "InternalServerError" not in msg, msg
    retries = [r.getMessage() for r in caplog.records if "retry" in r.getMessage()]
    assert len(retries) == 1 and "DNS error" in retries[0] and "HTTP 500" not in retries[0], retries


def test_a_closed_port_is_named_connection_refused_not_an_http_500(planted_key, caplog):
    from eb_models.litellm_backend import LiteLLMBackend

    with socket.socket() as s:  # a port nothing listens on once the socket is closed
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"http://127.0.0.1:{port}/v1"
    backend = LiteLLMBackend(model_id="openai/stub-model", api_base=url, api_key_env=KEY_ENV, max_retries=1,
                             backoff_base_s=0.01)
    with pytest.raises(ModelFatalError, match=rf"nothing answers at {url} \(Connection refused\)"):
        backend.preflight()
    with caplog.at_level(logging.WARNING, logger="eb_models"), pytest.raises(ModelTransientError) as err:
        backend.complete(request())
    msg = str(err.value)
    assert f"connection refused by 127.0.0.1:{port} (Connection refused): nothing listens there" in msg, msg
    assert "HTTP 500" not in msg and "InternalServerError" not in msg, msg


def test_a_real_http_500_keeps_its_status(make_backend, server):
    server.default = StubReply(status=500, error_message="boom")
    backend = make_backend(max_retries=1)
    with pytest.raises(ModelTransientError, match=r"HTTP 500"):
        backend.complete(request())


def test_401_is_fatal_at_once_and_the_key_is_scrubbed(make_backend, server):
    server.default = StubReply(status=401, error_message=f"Incorrect API key provided: {PLANTED_KEY}.")
    backend = make_backend()
    with pytest.raises(ModelFatalError) as info:
        backend.preflight()  # before the first episode
    msg = str(info.value)
    assert PLANTED_KEY not in msg and "***" in msg
    assert "\n" not in msg and KEY_ENV in msg and "authentication failed" in msg
    assert info.value.__cause__ is None and info.value.__suppress_context__  # no chained original with the key
    with pytest.raises(ModelFatalError):
        backend.complete(request())
    assert len(chat_requests(server)) == 2  # one per call: never retried


def test_unknown_model_is_fatal(make_backend, server):
    server.default = StubReply(status=404, error_message="The model `stub-model` does not exist.")
    with pytest.raises(ModelFatalError, match="unknown model or endpoint"):
        make_backend().preflight()


def test_a_rejected_request_is_not_retried(make_backend, server):
    server.default = StubReply(status=400, error_message="This model's maximum context length is 8192 tokens.")
    with pytest.raises(ModelTransientError, match="rejected, not retried"):
        make_backend().complete(request())
    assert len(chat_requests(server)) == 1


def test_preflight_sends_the_schema_and_explains_a_refusal(make_backend, server):
    server.default = StubReply(status=400, error_message="response_format json_schema is not supported")
    with pytest.raises(ModelFatalError, match="refuses the request field 'response_format'.*structured_output"):
        make_backend().preflight()
    assert chat_requests(server)[0].body["response_format"]["type"] == "json_schema"
    assert len(chat_requests(server)) == 1


def test_preflight_ok_is_one_tiny_call(make_backend, server):
    make_backend().preflight()
    [sent] = chat_requests(server)
    assert sent.body["max_tokens"] <= 16


def test_missing_key_variable_is_fatal(server, monkeypatch):
    from eb_models.litellm_backend import LiteLLMBackend

    monkeypatch.delenv("EB_MODELS_NO_SUCH_KEY", raising=False)
    with pytest.raises(ModelFatalError, match="EB_MODELS_NO_SUCH_KEY is not set"):
        LiteLLMBackend(model_id="openai/x", api_base=server.url, api_key_env="EB_MODELS_NO_SUCH_KEY")


def test_a_local_server_never_gets_the_real_openai_key(server, monkeypatch):
    from eb_models.litellm_backend import LiteLLMBackend

    monkeypatch.setenv("OPENAI_API_KEY", PLANTED_KEY)
    LiteLLMBackend(model_id="openai/x", api_base=server.url).complete(request())
    assert chat_requests(server)[0].headers["Authorization"] == "Bearer no-key"


def test_a_typo_in_a_model_key_is_one_clear_line(server):
    from eb_models.litellm_backend import LiteLLMBackend

    with pytest.raises(ModelConfigError) as info:
        LiteLLMBackend(model_id="openai/x", api_base=server.url, max_token=100)
    msg = str(info.value)
    assert "'model.max_token'" in msg and "max_tokens" in msg and "\n" not in msg
    with pytest.raises(ModelConfigError, match="environment variable"):
        LiteLLMBackend(model_id="openai/x", api_key=PLANTED_KEY)
    with pytest.raises(ModelConfigError, match="names no litellm provider"):
        LiteLLMBackend(model_id="no-such-provider-model")
    with pytest.raises(ModelConfigError, match="extra_params"):
        LiteLLMBackend(model_id="openai/x", api_base=server.url, extra_params={"aws_secret_access_key": "x"})


def test_images_to_a_text_only_model_fail_loudly(make_backend):
    backend = make_backend(supports_images=False)
    assert backend.supports_images is False
    with pytest.raises(ModelFatalError, match="language_only"):
        backend.complete(request())


# -- cache, secrets, network ----------------------------------------------------------------------------


def test_cache_answers_identical_requests_for_free(make_backend, server, tmp_path):
    cache = tmp_path / "cache"
    server.push(StubReply(content=PLAN, prompt_tokens=50, completion_tokens=10))
    first = make_backend(cache_dir=str(cache)).complete(request(seed=1))
    again = make_backend(cache_dir=str(cache)).complete(request(seed=1))  # a re-run: a new backend
    assert not first.cached and first.usage.cost_usd > 0
    assert again.cached and again.text == PLAN and again.usage.cost_usd == 0
    assert again.usage.prompt_tokens == 50 and again.usage.calls == 1
    assert len(chat_requests(server)) == 1
    make_backend(cache_dir=str(cache)).complete(request(seed=2))  # another seed: another request
    make_backend(cache_dir=str(cache), temperature=0.5).complete(request(seed=1))  # another setting
    make_backend(cache_dir=str(cache)).complete(request("Other text.", seed=1))
    assert len(chat_requests(server)) == 4
    files = list(cache.rglob("*.json"))
    assert len(files) == 4
    assert all("Plan the next actions" not in f.read_text() for f in files)  # answers only, no prompts


def test_the_key_is_never_written_logged_or_shown(make_backend, server, tmp_path, caplog):
    leak = f"upstream said: bad key {PLANTED_KEY} (Authorization: Bearer {PLANTED_KEY})"
    server.push(StubReply(status=500, error_message=leak), StubReply(status=429, error_message=leak),
                StubReply(content=PLAN))
    caplog.set_level(logging.DEBUG)
    backend = make_backend(cache_dir=str(tmp_path / "cache"), max_concurrency=2, rpm=100)
    backend.complete(request())
    messages = []
    server.default = StubReply(status=503, error_message=leak)
    with pytest.raises(ModelTransientError) as transient:
        backend.complete(request("again"))
    messages.append(str(transient.value))
    server.default = StubReply(status=401, error_message=leak)
    with pytest.raises(ModelFatalError) as fatal:
        backend.complete(request("once more"))
    messages.append(str(fatal.value))
    assert "retry" in caplog.text  # retries are logged...
    assert PLANTED_KEY not in caplog.text  # ...without the key
    assert all(PLANTED_KEY not in m and "***" in m for m in messages)
    assert PLANTED_KEY not in repr(backend) and PLANTED_KEY not in repr(vars(backend))
    written = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert any(p.parent.parent.name == "cache" for p in written) and any("limits" in str(p) for p in written)
    for p in written:
        assert PLANTED_KEY.encode() not in p.read_bytes(), p


_connects: list[str] = []


def _audit(event: str, args: tuple) -> None:
    if event == "socket.connect" and _connects is not None:
        _connects.append(str(args[1]))


def test_litellm_touches_no_network_but_the_endpoint(make_backend, server):
    sys.addaudithook(_audit)
    _connects.clear()
    backend = make_backend()
    backend.preflight()
    backend.complete(request())
    assert os.environ["LITELLM_LOCAL_MODEL_COST_MAP"] == "True"
    assert _connects and all(c.startswith("('127.0.0.1'") for c in _connects), _connects


# -- limits across worker processes ---------------------------------------------------------------------


def _worker(url: str, limits_dir: str, n: int) -> None:
    from eb_models.litellm_backend import LiteLLMBackend

    os.environ[KEY_ENV] = PLANTED_KEY
    backend = LiteLLMBackend(model_id="openai/stub-model", api_base=url, api_key_env=KEY_ENV, max_concurrency=2,
                             limits_dir=limits_dir, timeout_s=10)
    for _ in range(n):
        backend.complete(request())


def test_max_concurrency_holds_across_processes(server, tmp_path):
    server.latency_s = 0.25
    ctx = mp.get_context("fork")  # litellm is already imported here: the children start at once
    procs = [ctx.Process(target=_worker, args=(server.url, str(tmp_path), 2)) for _ in range(4)]
    t0 = time.monotonic()
    for p in procs:
        p.start()
    for p in procs:
        p.join(30)
    assert [p.exitcode for p in procs] == [0, 0, 0, 0]
    assert len(chat_requests(server)) == 8
    assert server.max_in_flight == 2  # never more than the limit, and the limit is used
    assert time.monotonic() - t0 >= 4 * 0.25 - 0.05


def _inherited_worker(backend, n: int, q) -> None:
    from eb_models.litellm_backend import _import_litellm

    litellm = _import_litellm()
    cached = len(litellm.in_memory_llm_clients_cache.cache_dict)
    texts = [backend.complete(request()).text for _ in range(n)]
    q.put((cached, texts))
    q.close()
    q.join_thread()  # the result is on its way to the parent
    # a child forked from a threaded parent (litellm's and xdist's threads) can stall in interpreter shutdown on a
    # lock some other thread held at the fork; it has nothing left to clean up, so it leaves at once
    os._exit(0)


def test_forked_workers_do_not_share_the_parents_connections(make_backend, server):
    """A worker forked after the parent's preflight must not write on the parent's pooled keep-alive connection:
    with two workers on one socket, calls came back with "Server disconnected" now and then (and an episode
    ended in error). Each child starts with litellm's client cache empty and every call is answered."""
    from eb_models.litellm_backend import _import_litellm

    litellm = _import_litellm()
    server.latency_s = 0.05
    server.default = StubReply(content=PLAN)
    backend = make_backend()
    backend.complete(request())  # the parent now holds a pooled connection
    assert len(litellm.in_memory_llm_clients_cache.cache_dict) > 0
    ctx = mp.get_context("fork")
    q = ctx.Queue()
    procs = [ctx.Process(target=_inherited_worker, args=(backend, 4, q)) for _ in range(4)]
    for p in procs:
        p.start()
    results = [q.get(timeout=60) for _ in procs]
    for p in procs:
        p.join(30)
    assert [p.exitcode for p in procs] == [0, 0, 0, 0]
    assert [cached for cached, _ in results] == [0, 0, 0, 0]
    assert all(t == PLAN for _, texts in results for t in texts)
    assert len(chat_requests(server)) == 1 + 16
    assert backend.complete(request()).text == PLAN  # and the parent's own connection still works


def _rpm_worker(limits_dir: str, n: int, out: str) -> None:
    from eb_models.limits import RequestLimiter

    lim = RequestLimiter("m@test", rpm=3, root=limits_dir, window_s=1.0)
    for _ in range(n):
        with lim.slot():
            with open(out, "a") as fh:
                fh.write(f"{time.time()}\n")


def test_rpm_holds_across_processes(tmp_path):
    out = tmp_path / "starts.txt"
    ctx = mp.get_context("fork")
    procs = [ctx.Process(target=_rpm_worker, args=(str(tmp_path / "limits"), 3, str(out))) for _ in range(3)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(30)
    starts = sorted(float(x) for x in out.read_text().split())
    assert len(starts) == 9
    for i in range(len(starts) - 3):
        assert starts[i + 3] - starts[i] >= 1.0 - 0.02  # never 4 starts within one window
    assert starts[-1] - starts[0] < 3.5  # and it does not wait much longer than needed
