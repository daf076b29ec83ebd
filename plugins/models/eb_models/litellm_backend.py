"""The ``litellm`` backend: OpenAI, Anthropic, Gemini, Azure, Bedrock and any OpenAI-compatible server.

litellm is imported here, when a litellm model is constructed, never by the plugin's entry point (the
import alone takes seconds). ``LITELLM_LOCAL_MODEL_COST_MAP=True`` is set first so litellm reads its
bundled price map instead of fetching one: a run talks to the model endpoint and to nothing else.

Faults never loop forever and never pass silently:

* 429, 5xx, timeouts, connection errors and unreadable bodies are retried with exponential backoff and
  jitter, honouring ``Retry-After``, for at most ``max_retries`` retries and ``retry_max_seconds``;
  then :class:`~eb_core.model.ModelTransientError` (the runner records the episode as ``error``).
* 401 / 403 / 404 (bad key, no access, unknown model) raise :class:`~eb_core.model.ModelFatalError` with
  one line; :meth:`LiteLLMBackend.preflight` makes one tiny call so this happens before the first episode.
* Any other 4xx (prompt too long, content refused), and a 5xx whose body is a validation error naming a
  request field (FastAPI servers word some refusals so), is not retried: ``ModelTransientError`` at once,
  naming the field and the fix. At preflight such a refusal is fatal.
* At preflight, a refused connection to a local ``api_base`` fails at once with the URL named.

``structured_output`` picks how the planner's JSON schema is sent (see :mod:`eb_models.structured`);
``auto`` probes the server at preflight and every backend of the run then uses the mode it settled on.

API keys are read only from the environment variable named by ``api_key_env``; they are scrubbed from
every message this module raises or logs and never written anywhere.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import random
import re
import socket
import time
import warnings
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

from pydantic import Field, field_validator

from eb_models._messages import openai_parts
from eb_core.model import (
    EpisodeContext,
    ImagePart,
    ModelBackend,
    ModelFatalError,
    ModelRequest,
    ModelResponse,
    ModelTransientError,
    TextPart,
    Usage,
)
from eb_models._secrets import Scrubber, Secret, secret_values
from eb_models._info import write_model_info
from eb_models._settings import BackendSettings, ModelConfigError, validate_settings
from eb_models.cache import ResponseCache, request_fingerprint
from eb_models.limits import RequestLimiter, default_limits_dir
from eb_models.retry import ErrorKind, RetryPolicy, classify_status, connection_failure, retry_after_seconds
from eb_models.structured import (
    PROBE_ORDER,
    PROBE_PROMPT,
    StructuredOutput,
    field_fix,
    probe_answer_ok,
    probe_request_format,
    rejected_field,
    response_format,
    sends_schema,
)

__all__ = ["LOCAL_MAX_TOKENS", "LiteLLMBackend", "LiteLLMSettings", "is_local_url"]

log = logging.getLogger("eb_models.litellm")

#: Sent as the key to OpenAI-compatible servers that need none, so litellm never falls back to a real
#: ``OPENAI_API_KEY`` from the environment and hands it to a local server.
NO_KEY = "no-key"

_SECRET_PARAM_WORDS = ("key", "secret", "token", "password", "credential")

#: Output limit when ``max_tokens`` is unset: hosted APIs get the planner's 2048 (the original's), a local
#: server this many, so a small model that rambles costs seconds per call, not minutes.
LOCAL_MAX_TOKENS = 1024
HOSTED_MAX_TOKENS = 2048
_LOCAL_HOSTS = {"127.0.0.1", "localhost", "::1", "0.0.0.0", "[::1]"}


def is_local_url(url: str | None) -> bool:
    """Whether ``url`` points at this machine."""
    if not url:
        return False
    host = (urlparse(url).hostname or "").lower()
    return host in _LOCAL_HOSTS or host.startswith("127.")


#: litellm repeats the class name: "litellm.RateLimitError: RateLimitError: OpenAIException - ...".
_LITELLM_PREFIX = re.compile(r"^(?:(?:litellm\.)?\w*(?:Error|Timeout):\s*)+")


class LiteLLMSettings(BackendSettings):
    """The keys of a litellm model preset (``conf/model/<name>.yaml``)."""

    model_id: str = Field(min_length=1)
    """litellm model string ``provider/model``: ``openai/gpt-4o-2024-08-06``, ``anthropic/...``,
    ``gemini/...``, ``azure/<deployment>``, ``bedrock/...``; ``openai/<served name>`` for a local server."""
    api_base: str | None = None
    """Endpoint URL, e.g. ``http://127.0.0.1:8000/v1`` for vLLM / lmdeploy / SGLang / Ollama."""
    api_key_env: str | None = None
    """Name of the environment variable holding the API key (never the key itself)."""
    api_version: str | None = None
    """Azure API version."""
    description: str = ""
    """Human-readable model name and where it comes from (not sent anywhere)."""
    supports_images: bool = True
    """Whether the model takes images; language-only models get the observation's text instead."""
    structured_output: StructuredOutput | None = None
    """How the planner's JSON schema reaches the server: ``json_schema`` (OpenAI), ``json_object_schema``
    (llama-cpp-python, Fireworks), ``json_object`` (plain JSON mode, schema in the prompt), ``none`` (textual
    format in the prompt), or ``auto`` (probe at preflight). Unset = ``none``, as the boolean's default was."""
    supports_json_schema: bool | None = None
    """Deprecated alias (one release): true = ``structured_output: json_schema``, false = ``none``."""
    json_schema_strict: bool | None = False
    """OpenAI ``strict`` flag for the schema: false as the original (which sent none); null = on when the
    schema fits strict mode's rules."""
    max_tokens: int | None = Field(default=None, ge=1)
    """Output limit requested per call (the planner asks for 2048; the smaller of the two is sent). Unset =
    2048 for a hosted API, 1024 for a server on this machine."""
    temperature: float | None = Field(default=None, ge=0)
    """Overrides the planner's temperature (0) when set."""
    timeout_s: float = Field(default=120.0, gt=0)
    """Per-request timeout."""
    max_retries: int = Field(default=5, ge=0)
    """Retries after the first attempt on 429 / 5xx / timeouts / connection errors."""
    retry_max_seconds: float = Field(default=300.0, gt=0)
    """Total time budget of one call's retries."""
    backoff_base_s: float = Field(default=1.0, gt=0)
    backoff_max_s: float = Field(default=60.0, gt=0)
    max_concurrency: int | None = Field(default=None, ge=1)
    """Calls in flight at once for this model, across all worker processes (null = no limit)."""
    rpm: int | None = Field(default=None, ge=1)
    """Calls started per minute for this model, across all worker processes (null = no limit)."""
    limits_dir: str | None = None
    """Where the cross-process limit files live (default ``<tmp>/eb_models_limits``)."""
    cache_dir: str | None = None
    """Response cache directory (null = no cache)."""
    input_cost_per_token: float | None = Field(default=None, ge=0)
    """USD per prompt token; null = litellm's bundled price map (0 if the model is not in it)."""
    output_cost_per_token: float | None = Field(default=None, ge=0)
    """USD per completion token."""
    extra_params: dict[str, Any] = Field(default_factory=dict)
    """Further ``litellm.completion`` arguments (``aws_region_name``, ``top_p``...). No secrets here."""

    @field_validator("extra_params")
    @classmethod
    def _no_secrets(cls, value: dict[str, Any]) -> dict[str, Any]:
        for k in value:
            if any(w in k.lower() for w in _SECRET_PARAM_WORDS):
                raise ValueError(f"extra_params may not hold {k!r}: secrets come only from environment variables "
                                 f"(model.api_key_env)")
        return value


_FORK_HOOKED = False


def _forget_inherited_clients() -> None:
    """In a forked worker: drop the HTTP clients litellm cached in the parent (the preflight's among them).

    Their pooled keep-alive connections are sockets the parent and every sibling worker also hold; two processes
    writing requests on one connection get each other's answers or a closed connection ("Server disconnected
    without sending a response"), which cost an episode now and then with ``runner.workers`` > 1. The child
    builds its own clients on its first call. The parent keeps its connections (nothing is closed here)."""
    import litellm

    cache = getattr(litellm, "in_memory_llm_clients_cache", None)
    if cache is not None:
        cache.flush_cache()


def _import_litellm() -> Any:
    # Must be set before the first import: otherwise litellm downloads its price map at import time.
    os.environ["LITELLM_LOCAL_MODEL_COST_MAP"] = "True"
    # litellm's typed dicts trip a pydantic warning (at import and at the first call): not ours to fix.
    warnings.filterwarnings("ignore", message=r"Items? .* (is|are) using the `ReadOnly` qualifier", category=UserWarning)
    try:
        import litellm
    except ModuleNotFoundError as exc:
        from eb_core.specs import MissingDependencyError

        raise MissingDependencyError("the litellm backend needs litellm: pip install 'litellm==1.110.2'") from exc
    litellm.suppress_debug_info = True
    litellm.set_verbose = False
    litellm.telemetry = False
    global _FORK_HOOKED
    if not _FORK_HOOKED:
        _FORK_HOOKED = True
        os.register_at_fork(after_in_child=_forget_inherited_clients)
    # litellm and httpx log every call at INFO (and Hydra's root logger shows INFO): keep runs readable.
    for name in ("LiteLLM", "LiteLLM Router", "LiteLLM Proxy", "httpx", "httpcore", "openai"):
        logger = logging.getLogger(name)
        if logger.level < logging.WARNING:
            logger.setLevel(logging.WARNING)
    return litellm


_STRICT_UNSUPPORTED = {"minItems", "maxItems", "minLength", "maxLength", "pattern", "format", "minimum",
                       "maximum", "exclusiveMinimum", "exclusiveMaximum", "multipleOf", "minProperties",
                       "maxProperties", "uniqueItems", "patternProperties"}


def _fits_strict(schema: Any) -> bool:
    """Whether ``schema`` follows OpenAI strict mode's rules (conservatively)."""
    if isinstance(schema, list):
        return all(_fits_strict(s) for s in schema)
    if not isinstance(schema, dict):
        return True
    if _STRICT_UNSUPPORTED & schema.keys():
        return False
    if schema.get("type") == "object":
        props = schema.get("properties", {})
        if schema.get("additionalProperties") is not False or set(schema.get("required", [])) != set(props):
            return False
    subs: list[Any] = list(schema.get("properties", {}).values()) + list(schema.get("$defs", {}).values())
    subs += [v for k, v in schema.items() if k in ("items", "anyOf", "allOf", "oneOf")]
    return all(_fits_strict(v) for v in subs)


def _strict_form(schema: Any) -> Any:
    """``schema`` without the keywords OpenAI strict mode refuses (length and size bounds: the planner's
    ``minItems``/``maxItems``/``maxLength``); the ``enum`` of action ids and the structure stay."""
    if isinstance(schema, list):
        return [_strict_form(s) for s in schema]
    if not isinstance(schema, dict):
        return schema
    out = {k: v for k, v in schema.items() if k not in _STRICT_UNSUPPORTED}
    if isinstance(out.get("properties"), dict):
        out["properties"] = {name: _strict_form(sub) for name, sub in out["properties"].items()}
    if isinstance(out.get("$defs"), dict):
        out["$defs"] = {name: _strict_form(sub) for name, sub in out["$defs"].items()}
    for key in ("items", "anyOf", "allOf", "oneOf"):
        if key in out:
            out[key] = _strict_form(out[key])
    return out


class _Refused(Exception):
    """A deterministic refusal met while probing (not an error of the run)."""

    def __init__(self, status: int | None, field: str | None) -> None:
        super().__init__(field or str(status))
        self.status, self.field = status, field


# -- the mode ``auto`` settled on, shared with the run's other backends -----------------------------
# The runner's preflight backend probes; the episode backends (same process, or worker processes it
# started) read the answer instead of probing again. Keyed by model and endpoint and by the run's process.

_SETTLED: dict[str, tuple[str, str]] = {}
_WARNED_ALIAS = False


def _settled_file(key: str, pid: int, limits_dir: str | None) -> Path:
    digest = hashlib.sha256(key.encode()).hexdigest()[:16]
    return Path(limits_dir or default_limits_dir()) / f"structured-{digest}-{pid}.json"


def _store_settled(key: str, mode: str, why: str, limits_dir: str | None = None) -> None:
    _SETTLED[key] = (mode, why)
    path = _settled_file(key, os.getpid(), limits_dir)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"key": key, "mode": mode, "why": why, "time": time.time()}))
        os.replace(tmp, path)
    except OSError:
        pass  # worker processes then probe for themselves


def _load_settled(key: str, limits_dir: str | None = None) -> tuple[str, str] | None:
    if key in _SETTLED:
        return _SETTLED[key]
    path = _settled_file(key, os.getppid(), limits_dir)  # written by the runner that started this worker
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if data.get("key") != key or time.time() - float(data.get("time", 0)) > 24 * 3600:
        return None
    _SETTLED[key] = (str(data["mode"]), str(data["why"]))
    return _SETTLED[key]


class LiteLLMBackend(ModelBackend):
    """One model reached through litellm. Constructed with the preset's keys as keyword arguments."""

    def __init__(self, **kwargs: Any) -> None:
        self.settings = s = validate_settings(LiteLLMSettings, "litellm", kwargs)
        self.supports_images = s.supports_images
        mode: str = s.structured_output or "none"
        if s.supports_json_schema is not None:
            alias = "json_schema" if s.supports_json_schema else "none"
            global _WARNED_ALIAS
            if not _WARNED_ALIAS:
                _WARNED_ALIAS = True
                log.warning("model.supports_json_schema is deprecated: use model.structured_output=%s "
                            "(taken as that now)", alias)
            mode = alias
        self.structured_output: str = mode
        """The configured mode (``auto`` until :meth:`settle` has run)."""
        self.structured_output_why = "set by model.structured_output" if mode != "auto" else ""
        self.max_tokens = s.max_tokens or (LOCAL_MAX_TOKENS if is_local_url(s.api_base) else HOSTED_MAX_TOKENS)
        self._litellm = _import_litellm()
        try:
            _, self.provider, _, _ = self._litellm.get_llm_provider(s.model_id, api_base=s.api_base)
        except Exception:
            raise ModelConfigError(
                f"model.model_id {s.model_id!r} names no litellm provider; write it as 'provider/model' "
                f"(openai/gpt-4o-2024-08-06, anthropic/claude-3-7-sonnet-20250219, gemini/gemini-1.5-pro, or "
                f"openai/<served model> with model.api_base for a local server)"
            ) from None
        key: str | None = None
        if s.api_key_env:
            key = os.environ.get(s.api_key_env) or None
            if key is None:
                raise ModelConfigError(
                    f"model {s.model_id}: environment variable {s.api_key_env} is not set; export your API key "
                    f"in it (keys are read only from the environment)"
                )
        elif s.api_base:
            key = NO_KEY
        self._key = Secret(key)
        self._scrub = Scrubber(secret_values([key]))
        self._policy = RetryPolicy(max_retries=s.max_retries, max_seconds=s.retry_max_seconds,
                                   backoff_base_s=s.backoff_base_s, backoff_max_s=s.backoff_max_s)
        self._limiter = RequestLimiter(f"{s.model_id}@{s.api_base or self.provider}",
                                       max_concurrency=s.max_concurrency, rpm=s.rpm, root=s.limits_dir)
        self._cache = ResponseCache(s.cache_dir) if s.cache_dir else None
        self._rng = random.Random()
        self._warned_cost = False
        self._info_written = False

    def __repr__(self) -> str:
        return f"LiteLLMBackend(model_id={self.settings.model_id!r}, api_base={self.settings.api_base!r})"

    # -- requests -----------------------------------------------------------------------------

    def _messages(self, request: ModelRequest) -> list[dict[str, Any]]:
        out: list[dict[str, Any]] = []
        for m in request.messages:
            has_image = any(isinstance(p, ImagePart) for p in m.content)
            if has_image and not self.supports_images:
                raise ModelFatalError(
                    f"model {self.settings.model_id} takes no images (supports_images: false); "
                    f"run it with planner.language_only=true"
                )
            only = m.content[0] if len(m.content) == 1 else None
            if isinstance(only, TextPart):  # one text part: sent as a plain string
                out.append({"role": m.role, "content": only.text})
                continue
            out.append({"role": m.role, "content": openai_parts(m)})
        return out

    # -- structured output --------------------------------------------------------------------

    @property
    def supports_json_schema(self) -> bool:  # type: ignore[override]  # a property over the base's class attribute
        """Whether the schema reaches the server (the planner then leaves the textual format out)."""
        return sends_schema(self.settle())

    def settle(self) -> str:
        """The structured-output mode in use; under ``auto`` the one preflight settled on (probed now if this
        process and the run's preflight have not probed yet)."""
        if self.structured_output == "auto":
            found = _load_settled(self._settle_key(), self.settings.limits_dir)
            if found is None:
                self._probe()
            else:
                self.structured_output, self.structured_output_why = found
        return self.structured_output

    def info(self) -> dict[str, Any]:
        """What a run should record about this backend (the settled mode and why, the output limit)."""
        return {"backend": "litellm", "model_id": self.settings.model_id, "api_base": self.settings.api_base,
                "structured_output": self.settle(), "structured_output_why": self.structured_output_why,
                "max_tokens": self.max_tokens}

    def _settle_key(self) -> str:
        return f"{self.settings.model_id}@{self.settings.api_base or self.provider}"

    def _probe(self) -> Usage:
        """Try each mode in :data:`PROBE_ORDER` with a tiny request; keep the first accepted and obeyed."""
        s = self.settings
        total = Usage()
        notes: list[str] = []
        for mode in PROBE_ORDER:
            params: dict[str, Any] = {"max_tokens": 24, "temperature": 0.0}
            fmt = probe_request_format(mode)
            if fmt is not None:
                params["response_format"] = fmt
            params.update(s.extra_params)
            t0 = time.perf_counter()
            try:
                resp = self._call([{"role": "user", "content": PROBE_PROMPT}], params, probing=True)
            except _Refused as exc:
                notes.append(f"{mode}: refused ({exc.field or 'HTTP ' + str(exc.status)})")
                continue
            usage = self._usage(resp, t0)
            total = total + usage
            text = self._text(resp)
            if mode == "none" or probe_answer_ok(mode, text):
                why = "; ".join(notes + [f"{mode}: accepted and obeyed" if mode != "none" else
                                         "none: no response_format (textual format in the prompt)"])
                self.structured_output, self.structured_output_why = mode, why
                break
            shown = " ".join(text.split())[:40]
            notes.append(f"{mode}: accepted but not obeyed (answer {shown!r})")
        _store_settled(self._settle_key(), self.structured_output, self.structured_output_why, s.limits_dir)
        log.info("model %s: structured output %s (%s)", s.model_id, self.structured_output,
                 self.structured_output_why)
        print(f"structured output: {self.structured_output} ({self.structured_output_why})", flush=True)
        return total

    def _response_format(self, schema: dict[str, Any] | None) -> dict[str, Any] | None:
        mode = self.settle()
        strict = self.settings.json_schema_strict
        if mode == "json_schema" and schema is not None and strict is None:
            # strict when the schema fits once the bounds strict mode refuses are left out (the prompt still
            # states them); otherwise the whole schema, not strict
            wrapped = isinstance(schema.get("schema"), dict)
            stripped = _strict_form(schema["schema"] if wrapped else schema)
            strict = _fits_strict(stripped)
            if strict:
                schema = {**schema, "schema": stripped} if wrapped else stripped
        return response_format(mode, schema, bool(strict))

    def _settings_payload(self, request: ModelRequest) -> dict[str, Any]:
        """Everything sent besides the messages (also part of the cache key)."""
        s = self.settings
        payload: dict[str, Any] = {
            "max_tokens": min(request.max_tokens, self.max_tokens),
            "temperature": s.temperature if s.temperature is not None else request.temperature,
        }
        if request.seed is not None:
            payload["seed"] = request.seed
        fmt = self._response_format(request.response_schema)
        if fmt is not None:
            payload["response_format"] = fmt
        payload.update(s.extra_params)
        return payload

    def _call(self, messages: list[dict[str, Any]], params: dict[str, Any], probing: bool = False) -> Any:
        """One completion with retries; returns litellm's response or raises a model error.

        ``probing``: a deterministic refusal raises :class:`_Refused` (the probe tries the next mode)."""
        s = self.settings
        start = time.monotonic()
        attempt = 0
        while True:
            attempt += 1
            try:
                with self._limiter.slot():
                    return self._litellm.completion(
                        model=s.model_id,
                        messages=messages,
                        api_base=s.api_base,
                        api_key=self._key.get(),
                        api_version=s.api_version,
                        timeout=s.timeout_s,
                        num_retries=0,  # retries are ours (Retry-After, time cap, cross-process limits)
                        max_retries=0,
                        drop_params=True,
                        **params,
                    )
            except Exception as exc:  # classified below; programming errors are not retried
                kind, status, headers = self._classify(exc)
                detail = self._describe(exc, status)
                failure = connection_failure(exc)
                if failure is not None and failure.kind == "dns" and probing:
                    # the host does not resolve: retrying at preflight only delays the one line by half a minute
                    raise ModelFatalError(f"model {s.model_id}{' at ' + s.api_base if s.api_base else ''}: "
                                          f"{detail}; check model.api_base (or this machine's network)") from None
                field = rejected_field(str(exc)) if kind != "fatal" else None
                if kind == "retry" and field is not None and isinstance(status, int) and status >= 500:
                    kind = "reject"  # a validation error worded as a 500: the same request fails every time
                if kind == "fatal" and probing and status == 404 and field is not None:
                    kind = "reject"
                if kind == "fatal":
                    raise ModelFatalError(self._fatal_message(status, detail)) from None
                if kind == "reject":
                    if probing:
                        raise _Refused(status, field) from None
                    what = (f"the server refuses the request field '{field}': "
                            f"{field_fix(field, self.structured_output)}. " if field else "")
                    raise ModelTransientError(
                        f"model {s.model_id}: request rejected, not retried: {what}{detail}"
                    ) from None
                elapsed = time.monotonic() - start
                wait = self._policy.next_wait(attempt, retry_after_seconds(headers), elapsed, self._rng)
                if wait is None:
                    raise ModelTransientError(
                        f"model {s.model_id}: gave up after {attempt} attempt(s) in {elapsed:.1f}s "
                        f"(max_retries={s.max_retries}, retry_max_seconds={s.retry_max_seconds:g}); "
                        f"last error: {detail}"
                    ) from None
                log.warning("model %s: %s; retry %d/%d in %.2fs", s.model_id, detail, attempt,
                            s.max_retries, wait)
                time.sleep(wait)

    def _classify(self, exc: Exception) -> tuple[ErrorKind, int | None, Any]:
        status = getattr(exc, "status_code", None)
        response = getattr(exc, "response", None)
        headers = getattr(exc, "litellm_response_headers", None)
        if headers is None and response is not None:
            headers = getattr(response, "headers", None)
        lt = self._litellm
        failure = connection_failure(exc)
        if failure is not None and failure.kind != "timeout":  # never reached the server: no HTTP status
            return "retry", None, headers
        if isinstance(exc, (lt.Timeout, lt.APIConnectionError)):
            return "retry", status, headers
        if isinstance(exc, (lt.AuthenticationError, lt.PermissionDeniedError, lt.NotFoundError)):
            return "fatal", status, headers
        if isinstance(exc, (lt.RateLimitError, lt.InternalServerError, lt.ServiceUnavailableError,
                            lt.APIResponseValidationError)):
            return "retry", status, headers
        if isinstance(exc, lt.BadRequestError) and "LLM Provider NOT provided" in str(exc):
            return "fatal", status, headers
        if isinstance(status, int):
            return classify_status(status), status, headers
        if isinstance(exc, (lt.APIError, ConnectionError, TimeoutError)):
            return "retry", None, headers
        return "reject", None, headers

    def _describe(self, exc: Exception, status: int | None) -> str:
        failure = connection_failure(exc)
        if failure is not None and failure.kind != "timeout":  # litellm: "InternalServerError (HTTP 500): ..."
            url = urlparse(self.settings.api_base) if self.settings.api_base else None
            return self._scrub(failure.describe(url.hostname if url else None, url.netloc if url else None))
        text = " ".join(str(exc).split())
        text = _LITELLM_PREFIX.sub("", text) or "(no message)"
        if len(text) > 400:
            text = text[:397] + "..."
        where = f" (HTTP {status})" if status else ""
        return self._scrub(f"{type(exc).__name__}{where}: {text}")

    def _fatal_message(self, status: int | None, detail: str) -> str:
        s = self.settings
        if status == 401:
            why = f"authentication failed; check the API key in ${s.api_key_env}" if s.api_key_env else \
                "authentication failed; set model.api_key_env to the variable holding the key"
        elif status == 403:
            why = "access denied for this key"
        elif status == 404:
            why = "unknown model or endpoint; check model.model_id and model.api_base"
        else:
            why = "the request cannot succeed"
        where = f" at {s.api_base}" if s.api_base else ""
        return f"model {s.model_id}{where}: {why}. {detail}"

    # -- ModelBackend -------------------------------------------------------------------------

    def preflight(self) -> Usage:
        """Fail fast on a bad key, model or URL, and settle the structured-output mode.

        A fixed mode makes one tiny call (with a probe schema when the mode sends one); ``auto`` probes the
        modes in turn. Returns the calls' :class:`~eb_core.model.Usage` (counted in the run's budget).
        """
        s = self.settings
        self._check_host_resolves()
        self._check_local_server()
        try:
            if self.structured_output == "auto":
                return self._probe()
            params: dict[str, Any] = {"max_tokens": 8, "temperature": 0.0}
            fmt = probe_request_format(self.structured_output)
            if fmt is not None:
                params["response_format"] = fmt
            params.update(s.extra_params)
            t0 = time.perf_counter()
            try:
                resp = self._call([{"role": "user", "content": "Reply with OK."}], params, probing=True)
            except _Refused as exc:
                what = f"the request field '{exc.field}'" if exc.field else f"the request (HTTP {exc.status})"
                fix = field_fix(exc.field or "response_format", self.structured_output) if (
                    exc.field or fmt is not None) else "check model.extra_params"
                raise ModelFatalError(
                    f"preflight failed: model {s.model_id}{' at ' + s.api_base if s.api_base else ''} refuses "
                    f"{what} (structured_output={self.structured_output}); {fix}"
                ) from None
            return self._usage(resp, t0)
        except ModelTransientError as exc:
            raise ModelFatalError(f"preflight failed: {exc}") from None

    def _check_host_resolves(self) -> None:
        """An ``api_base`` whose host name does not resolve fails now, named as a DNS error (litellm would
        report it as "HTTP 500" and the retries would take half a minute)."""
        url = self.settings.api_base
        if not url:
            return
        parsed = urlparse(url)
        host = (parsed.hostname or "").strip("[]")
        if not host:
            raise ModelFatalError(f"preflight failed: model.api_base {url!r} has no host; give a URL such as "
                                  f"http://127.0.0.1:8000/v1")
        try:
            socket.getaddrinfo(host, parsed.port or (443 if parsed.scheme == "https" else 80),
                               type=socket.SOCK_STREAM)
        except socket.gaierror as exc:
            raise ModelFatalError(
                f"preflight failed: DNS error: cannot resolve the host {host!r} of model.api_base {url} "
                f"({exc.strerror or exc}); check the URL's spelling (or this machine's network)"
            ) from None
        except UnicodeError:
            raise ModelFatalError(f"preflight failed: model.api_base {url!r} has an invalid host name") from None

    def _check_local_server(self) -> None:
        """A local ``api_base`` nobody listens on fails now, not after a minute of retries."""
        url = self.settings.api_base
        if url is None or not is_local_url(url):
            return
        parsed = urlparse(url)
        port = parsed.port or (443 if parsed.scheme == "https" else 80)
        host = (parsed.hostname or "127.0.0.1").strip("[]")
        try:
            with socket.create_connection((host, port), timeout=min(5.0, self.settings.timeout_s)):
                pass
        except OSError as exc:
            reason = exc.strerror or type(exc).__name__
            raise ModelFatalError(
                f"preflight failed: nothing answers at {url} ({reason}); start the model server there or point "
                f"model.api_base at it"
            ) from None

    def _usage(self, resp: Any, t0: float) -> Usage:
        u = getattr(resp, "usage", None)
        pt = int(getattr(u, "prompt_tokens", 0) or 0)
        ct = int(getattr(u, "completion_tokens", 0) or 0)
        return Usage(prompt_tokens=pt, completion_tokens=ct, cost_usd=self._cost(resp, pt, ct),
                     latency_s=time.perf_counter() - t0, calls=1)

    def _text(self, resp: Any) -> str:
        try:
            text = resp.choices[0].message.content or ""
        except (AttributeError, IndexError, TypeError):
            raise ModelTransientError(f"model {self.settings.model_id}: the response held no answer "
                                      f"(no choices)") from None
        return text if isinstance(text, str) else str(text)

    def start_episode(self, ctx: EpisodeContext) -> None:
        if not self._info_written:
            self._info_written = True
            write_model_info(ctx.run_dir, self.info())

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        s = self.settings
        messages = self._messages(request)
        params = self._settings_payload(request)
        key = None
        if self._cache is not None:
            key = ResponseCache.key({"model_id": s.model_id, "api_base": s.api_base, "api_version": s.api_version,
                                     "messages": request_fingerprint(request), "params": params})
            hit = self._cache.get(key)
            if hit is not None:
                usage = Usage(prompt_tokens=int(hit.get("prompt_tokens", 0)),
                              completion_tokens=int(hit.get("completion_tokens", 0)),
                              cost_usd=0.0, latency_s=time.perf_counter() - t0, calls=1)
                return ModelResponse(text=hit["text"], usage=usage, model=str(hit.get("model", s.model_id)),
                                     cached=True)
        resp = self._call(messages, params)
        text = self._text(resp)
        usage = self._usage(resp, t0)
        pt, ct = usage.prompt_tokens, usage.completion_tokens
        usage.latency_s = time.perf_counter() - t0
        model = str(getattr(resp, "model", "") or s.model_id)
        if self._cache is not None and key is not None:
            self._cache.put(key, {"text": text, "prompt_tokens": pt, "completion_tokens": ct, "model": model,
                                  "model_id": s.model_id})
        return ModelResponse(text=text, usage=usage, model=model)

    def _cost(self, resp: Any, pt: int, ct: int) -> float:
        s = self.settings
        if s.input_cost_per_token is not None or s.output_cost_per_token is not None:
            return pt * (s.input_cost_per_token or 0.0) + ct * (s.output_cost_per_token or 0.0)
        try:
            return float(self._litellm.completion_cost(completion_response=resp, model=s.model_id) or 0.0)
        except Exception:
            if not self._warned_cost:
                self._warned_cost = True
                log.warning("model %s: no price known (set input_cost_per_token / output_cost_per_token); "
                            "cost is recorded as 0 and model.max_cost_usd cannot stop the run", s.model_id)
            return 0.0

    def close(self) -> None:
        """Nothing to release: litellm's HTTP clients are shared per process. Safe to call twice."""
