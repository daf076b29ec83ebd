"""A scriptable OpenAI-compatible chat server on 127.0.0.1, for tests, benchmarks and offline dry runs.

It speaks real HTTP (``POST /v1/chat/completions``, ``GET /v1/models``), so the ``litellm`` backend is
exercised end to end without a network or an API key::

    with StubOpenAIServer(latency_s=0.1) as server:
        server.push(StubReply(status=429, headers={"Retry-After": "1"}), StubReply(content='{"a": 1}'))
        # point a preset at it: model=openai-compatible model.model_id=openai/stub model.api_base=<server.url>
        ...
        assert server.request_count == 2

Queued replies are used first, in order; then ``default`` (a reply, or a function of the request body).
"""

from __future__ import annotations

import json
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, Union

__all__ = ["RecordedRequest", "StubOpenAIServer", "StubReply"]

DEFAULT_ANSWER = json.dumps({
    "visual_state_description": "A stub server cannot see.",
    "reasoning_and_reflection": "This answer comes from the stub server.",
    "language_plan": "Nothing to do.",
    "executable_plan": [],
})


@dataclass
class StubReply:
    """One scripted reply."""

    content: str | None = DEFAULT_ANSWER
    """The assistant message text (ignored when ``body`` is given)."""
    status: int = 200
    body: bytes | str | None = None
    """Raw response body, sent as is (malformed or truncated JSON, an HTML error page...)."""
    headers: dict[str, str] = field(default_factory=dict)
    delay_s: float = 0.0
    """Seconds to wait before answering (added to the server's ``latency_s``)."""
    prompt_tokens: int = 10
    completion_tokens: int = 5
    error_message: str = "stub error"
    """Message of the JSON error body sent with a non-200 status when ``body`` is not given."""
    finish_reason: str = "stop"


@dataclass
class RecordedRequest:
    method: str
    path: str
    headers: dict[str, str]
    """Header names in Title-Case whatever case the client sent (HTTP names are case-insensitive)."""
    body: Any
    """The parsed JSON body (None if it was not JSON)."""
    received_at: float


Responder = Union[StubReply, Callable[[Any], StubReply]]


class StubOpenAIServer:
    """A threaded HTTP server in this process; use as a context manager or call start()/stop()."""

    def __init__(self, replies: Iterable[StubReply] = (), default: Responder | None = None,
                 latency_s: float = 0.0, host: str = "127.0.0.1", port: int = 0) -> None:
        self._queue: deque[StubReply] = deque(replies)
        self.default: Responder = default if default is not None else StubReply()
        self.latency_s = latency_s
        self.requests: list[RecordedRequest] = []
        self.in_flight = 0
        self.max_in_flight = 0
        """Most chat requests handled at the same time (checks client-side concurrency limits)."""
        self._lock = threading.Lock()
        self._server = _Server((host, port), _Handler)
        self._server.stub = self
        self._thread: threading.Thread | None = None

    # -- control ------------------------------------------------------------------------------

    @property
    def url(self) -> str:
        host, port = self._server.server_address[:2]
        return f"http://{host.decode() if isinstance(host, bytes) else host}:{port}/v1"

    @property
    def request_count(self) -> int:
        """Chat-completion requests received so far."""
        with self._lock:
            return sum(1 for r in self.requests if r.path.endswith("/chat/completions"))

    def push(self, *replies: StubReply) -> None:
        with self._lock:
            self._queue.extend(replies)

    def start(self) -> "StubOpenAIServer":
        if self._thread is None:
            self._thread = threading.Thread(target=self._server.serve_forever, kwargs={"poll_interval": 0.05},
                                            name="stub-openai-server", daemon=True)
            self._thread.start()
        return self

    def stop(self) -> None:
        if self._thread is not None:
            self._server.shutdown()
            self._thread.join()
            self._thread = None
        self._server.server_close()

    def __enter__(self) -> "StubOpenAIServer":
        return self.start()

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    # -- handling -----------------------------------------------------------------------------

    def _next_reply(self, body: Any) -> StubReply:
        with self._lock:
            if self._queue:
                return self._queue.popleft()
        return self.default(body) if callable(self.default) else self.default

    def _record(self, req: RecordedRequest) -> None:
        with self._lock:
            self.requests.append(req)


class _Server(ThreadingHTTPServer):
    daemon_threads = True
    request_queue_size = 256
    allow_reuse_address = True
    stub: StubOpenAIServer


class _Handler(BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"
    server: _Server

    def log_message(self, format: str, *args: Any) -> None:  # quiet
        pass

    def _send(self, status: int, body: bytes, headers: dict[str, str] | None = None) -> None:
        try:
            self.send_response(status)
            hdrs = {"Content-Type": "application/json", **(headers or {})}
            for k, v in hdrs.items():
                self.send_header(k, v)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client gave up (timeout): nothing to do

    def do_GET(self) -> None:
        stub = self.server.stub
        stub._record(RecordedRequest("GET", self.path, {k.title(): v for k, v in self.headers.items()}, None, time.time()))
        if self.path.rstrip("/").endswith("/models"):
            self._send(200, json.dumps({"object": "list", "data": [{"id": "stub", "object": "model"}]}).encode())
        else:
            self._send(404, b'{"error": {"message": "not found"}}')

    def do_POST(self) -> None:
        stub = self.server.stub
        length = int(self.headers.get("Content-Length") or 0)
        raw = self.rfile.read(length) if length else b""
        try:
            body: Any = json.loads(raw)
        except ValueError:
            body = None
        stub._record(RecordedRequest("POST", self.path, {k.title(): v for k, v in self.headers.items()}, body, time.time()))
        if not self.path.rstrip("/").endswith("/chat/completions"):
            self._send(404, b'{"error": {"message": "unknown path"}}')
            return
        reply = stub._next_reply(body)
        with stub._lock:
            stub.in_flight += 1
            stub.max_in_flight = max(stub.max_in_flight, stub.in_flight)
        try:
            self._answer(stub, reply, body)
        finally:
            with stub._lock:
                stub.in_flight -= 1

    def _answer(self, stub: StubOpenAIServer, reply: StubReply, body: Any) -> None:
        delay = stub.latency_s + reply.delay_s
        if delay > 0:
            time.sleep(delay)
        if reply.body is not None:
            data = reply.body.encode() if isinstance(reply.body, str) else reply.body
        elif reply.status != 200:
            data = json.dumps({"error": {"message": reply.error_message, "type": "stub_error",
                                         "code": reply.status}}).encode()
        else:
            model = body.get("model", "stub") if isinstance(body, dict) else "stub"
            data = json.dumps({
                "id": f"chatcmpl-stub-{len(stub.requests)}",
                "object": "chat.completion",
                "created": int(time.time()),
                "model": model,
                "choices": [{"index": 0, "message": {"role": "assistant", "content": reply.content},
                             "finish_reason": reply.finish_reason}],
                "usage": {"prompt_tokens": reply.prompt_tokens, "completion_tokens": reply.completion_tokens,
                          "total_tokens": reply.prompt_tokens + reply.completion_tokens},
            }).encode()
        self._send(reply.status, data, reply.headers)
