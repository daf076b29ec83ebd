"""The HTTP face of ``eb serve``: a FastAPI (ASGI) app over a :class:`~eb_core.serve.pool.SessionPool`.

Endpoints (schema :data:`~eb_core.serve.schema.SCHEMA`; OpenAPI at ``/openapi.json``, browsable at ``/docs``)::

    GET    /v1/health                      status, world, capacity, free slots (no token needed)
    GET    /v1/stats                       counters and step latency p50/p99
    POST   /v1/sessions                    {"num_envs": n, "autoreset": "NextStep"} -> session id and spaces
    DELETE /v1/sessions/{id}               close a session (its environments go back to the pool)
    POST   /v1/sessions/{id}/reset         {"seeds": [...], "task_ids": [...], "mask": [...]} -> observations, infos
    POST   /v1/sessions/{id}/step          {"actions": [...]} -> observations, rewards, terminated, truncated, infos
    POST   /v1/sessions/{id}/keepalive     keep an idle session from being reaped

Every error is a 4xx/5xx with ``{"error": "<one line>"}``. A token (``EB_SERVE_TOKEN``) is checked on every endpoint
but health, as ``Authorization: Bearer <token>``.
"""

from __future__ import annotations

import hmac
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from eb_core.serve.pool import PoolError, SessionPool
from eb_core.serve.schema import (
    SCHEMA,
    CreateSession,
    Health,
    ResetRequest,
    ResetResponse,
    SessionInfo,
    Stats,
    StepRequest,
    StepResponse,
)
from eb_core.serve.spaces import describe

__all__ = ["MAX_BODY_BYTES", "create_app"]

MAX_BODY_BYTES = 16 * 1024 * 1024
"""Largest request body accepted (a step of 4,096 answer texts fits); larger gets 413."""


class _BodyLimit:
    """ASGI middleware: a request body over ``limit`` bytes is answered 413 without reading the rest."""

    def __init__(self, app: ASGIApp, limit: int) -> None:
        self.app, self.limit = app, limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope.get("headers") or []).get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.limit:
            await _too_large(send, self.limit)
            return
        seen = 0

        async def limited() -> Message:
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > self.limit:
                    raise _TooLarge()
            return message

        try:
            await self.app(scope, limited, send)
        except _TooLarge:
            await _too_large(send, self.limit)


class _TooLarge(Exception):
    pass


async def _too_large(send: Send, limit: int) -> None:
    body = (f'{{"error": "request body larger than {limit} bytes; send fewer environments per call"}}').encode()
    await send({"type": "http.response.start", "status": 413,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})


def _one_line_validation(exc: RequestValidationError) -> str:
    err = exc.errors()[0] if exc.errors() else {"loc": (), "msg": "invalid request"}
    loc = ".".join(str(p) for p in err.get("loc", ()) if p != "body") or "body"
    if err.get("type") == "json_invalid":
        return "the request body is not valid JSON; send a JSON object (see /docs)"
    if loc == "body" and err.get("type") in ("model_attributes_type", "dict_type"):
        return "the request body must be a JSON object; see /docs for the request's fields"
    if err.get("type") == "missing":
        return f"field {loc} is missing; see /docs for the request's fields"
    if err.get("type") == "extra_forbidden":
        return f"field {loc} is not known; see /docs for the request's fields"
    return f"field {loc}: {err.get('msg', 'invalid')}; see /docs for the request's fields"


def create_app(pool: SessionPool, *, token: str | None = None, world: str = "", title: str = "eb serve") -> Any:
    """The ASGI app serving ``pool``; ``token`` (when set) is required on every endpoint but health."""
    app = FastAPI(title=title, version=SCHEMA, docs_url="/docs", redoc_url=None)
    cfg = pool.cfg

    @app.exception_handler(PoolError)
    async def _pool_error(_: Request, exc: PoolError) -> JSONResponse:
        return JSONResponse({"error": str(exc)}, status_code=exc.status)

    @app.exception_handler(RequestValidationError)
    async def _invalid(_: Request, exc: RequestValidationError) -> JSONResponse:
        return JSONResponse({"error": _one_line_validation(exc)}, status_code=422)

    @app.exception_handler(StarletteHTTPException)
    async def _http(_: Request, exc: StarletteHTTPException) -> JSONResponse:
        return JSONResponse({"error": str(exc.detail)}, status_code=exc.status_code)

    @app.exception_handler(Exception)
    async def _crash(_: Request, exc: Exception) -> JSONResponse:
        return JSONResponse({"error": f"server error: {type(exc).__name__}: {exc}".splitlines()[0]}, status_code=500)

    @app.middleware("http")
    async def _auth(request: Request, call_next: Any) -> Any:
        if token and request.url.path.startswith("/v1/") and request.url.path != "/v1/health":
            given = request.headers.get("authorization", "")
            if not hmac.compare_digest(given.encode(), f"Bearer {token}".encode()):
                return JSONResponse({"error": "missing or wrong token; send 'Authorization: Bearer <token>' "
                                              "(the server's EB_SERVE_TOKEN)"}, status_code=401)
        return await call_next(request)

    @app.get("/v1/health", response_model=Health, response_model_by_alias=True)
    def health() -> Health:
        return Health(status="ok", schema=SCHEMA, world=cfg.world, obs_mode=cfg.obs_mode, split=cfg.split,
                      taskset=cfg.taskset, capacity=pool.capacity, free=pool.free(), workers=len(pool.vec.workers))

    @app.get("/v1/stats", response_model=Stats)
    def stats() -> Stats:
        return Stats(**pool.stats())

    @app.post("/v1/sessions", response_model=SessionInfo, response_model_by_alias=True, status_code=201)
    def create(body: CreateSession) -> SessionInfo:
        s = pool.create(body.num_envs, body.autoreset)
        return SessionInfo(session=s.id, num_envs=len(s.slots), schema=SCHEMA, world=cfg.world, obs_mode=cfg.obs_mode,
                           split=cfg.split, taskset=cfg.taskset,
                           observation_space=describe(pool.single_observation_space),
                           action_space=describe(pool.single_action_space),
                           session_timeout_s=cfg.session_timeout_s)

    @app.delete("/v1/sessions/{sid}", status_code=204)
    def close(sid: str) -> None:
        pool.close(sid)

    @app.post("/v1/sessions/{sid}/keepalive", status_code=204)
    def keepalive(sid: str) -> None:
        pool.get(sid)

    @app.post("/v1/sessions/{sid}/reset", response_model=ResetResponse)
    def reset(sid: str, body: ResetRequest) -> ResetResponse:
        s = pool.get(sid)
        obs, infos = pool.reset(s, body.seeds, body.task_ids, body.mask)
        return ResetResponse(observations=obs, infos=infos)

    @app.post("/v1/sessions/{sid}/step", response_model=StepResponse)
    def step(sid: str, body: StepRequest) -> StepResponse:
        s = pool.get(sid)
        return StepResponse(**pool.step(s, body.actions))

    return _BodyLimit(app, MAX_BODY_BYTES)
