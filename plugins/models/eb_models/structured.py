"""Structured-output dialects: how the planner's JSON schema reaches a chat server.

Servers disagree on the request field that turns on constrained decoding:

* ``json_schema`` - OpenAI's ``{"type": "json_schema", "json_schema": {"name", "schema", "strict"}}``
  (OpenAI, Gemini, vLLM, SGLang, lmdeploy, Ollama, llama.cpp's llama-server);
* ``json_object_schema`` - ``{"type": "json_object", "schema": {...}}`` (llama-cpp-python's server, Fireworks);
* ``json_object`` - plain JSON mode ``{"type": "json_object"}``: valid JSON, but the schema travels in the prompt;
* ``none`` - no ``response_format``; the prompt carries the textual answer format (the original's choice for
  Claude and InternVL).

``auto`` probes them in that order at preflight and keeps the first the server both accepts and obeys.
Pure functions, no SDK import: easy to test and shared by the backends.
"""

from __future__ import annotations

import json
import re
from typing import Any, Literal

__all__ = ["MODES", "PROBE_ORDER", "Mode", "StructuredOutput", "probe_answer_ok", "probe_request_format",
           "rejected_field", "response_format", "sends_schema"]

Mode = Literal["json_schema", "json_object_schema", "json_object", "none"]
StructuredOutput = Literal["auto", "json_schema", "json_object_schema", "json_object", "none"]

MODES: tuple[str, ...] = ("auto", "json_schema", "json_object_schema", "json_object", "none")
PROBE_ORDER: tuple[Mode, ...] = ("json_schema", "json_object_schema", "json_object", "none")

#: The probe's schema: one boolean; small enough for any model to fill within a few tokens.
PROBE_SCHEMA: dict[str, Any] = {
    "name": "probe",
    "schema": {"type": "object", "properties": {"ok": {"type": "boolean"}}, "required": ["ok"],
               "additionalProperties": False},
}
PROBE_PROMPT = 'Answer with the JSON object {"ok": true} and nothing else.'


def sends_schema(mode: str) -> bool:
    """Whether the mode carries the schema to the server (so the prompt needs no textual format)."""
    return mode in ("json_schema", "json_object_schema")


def _split(schema: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    if isinstance(schema.get("schema"), dict):
        return str(schema.get("name") or "response"), schema["schema"]
    return "response", schema


def response_format(mode: str, schema: dict[str, Any] | None, strict: bool = False) -> dict[str, Any] | None:
    """The ``response_format`` request field of ``mode`` for ``schema`` (the planner's, or None)."""
    if mode == "json_object":
        return {"type": "json_object"}  # the answer is always a JSON object, schema or not
    if mode == "none" or schema is None:
        return None
    name, body = _split(schema)
    if mode == "json_schema":
        return {"type": "json_schema", "json_schema": {"name": name, "schema": body, "strict": bool(strict)}}
    if mode == "json_object_schema":
        return {"type": "json_object", "schema": body}
    raise ValueError(f"unknown structured-output mode {mode!r}; allowed: {', '.join(MODES)}")


def probe_request_format(mode: str) -> dict[str, Any] | None:
    return response_format(mode, PROBE_SCHEMA)


def _first_json_object(text: str) -> Any:
    text = text.strip()
    fence = re.match(r"^```(?:json)?\s*(.*?)\s*```$", text, re.S)
    if fence:
        text = fence.group(1)
    try:
        return json.loads(text)
    except ValueError:
        return None


def probe_answer_ok(mode: str, text: str) -> bool:
    """Whether the probe's answer shows the server obeyed ``mode``.

    ``json_schema`` / ``json_object_schema`` must give exactly ``{"ok": <bool>}``; plain JSON mode any JSON
    object; ``none`` is always fine (nothing was asked of the server).
    """
    if mode == "none":
        return True
    value = _first_json_object(text)
    if mode == "json_object":
        return isinstance(value, dict)
    return isinstance(value, dict) and set(value) == {"ok"} and isinstance(value["ok"], bool)


#: A request field in a validation error: ``response_format.type: Input should be ...`` (pydantic/FastAPI, as
#: llama-cpp-python's server words it), ``'loc': ('body', 'response_format', 'type')`` or
#: ``"loc":["body","max_tokens"]``.
_FIELD_DOTTED = re.compile(r"\b([a-z_][a-z0-9_]*(?:\.[a-z0-9_]+)*)\s*[:\n]\s*(?:Input should|Field required|"
                           r"Extra inputs|value is not|Value error|String should|unexpected value)", re.I)
_FIELD_LOC = re.compile(r"""['"]loc['"]\s*:\s*[\[(]\s*['"]body['"]\s*,\s*((?:['"]?[\w-]+['"]?\s*,?\s*)+)[\])]""")
_VALIDATION_WORDS = ("validation error", "input should be", "field required", "extra inputs are not permitted",
                     "unprocessable", "invalid request", "is not supported", "unsupported")
#: Top-level request fields a client may send; a validation error naming one of them is our request's fault.
REQUEST_FIELDS = ("response_format", "max_tokens", "max_completion_tokens", "temperature", "seed", "messages",
                  "model", "top_p", "stop", "tools", "tool_choice", "n", "stream", "logprobs")


def rejected_field(text: str) -> str | None:
    """The request field a server's validation error names (``response_format.type``), or None.

    Used to tell a deterministic refusal (worded as a 500 by some FastAPI servers) from a server fault.
    """
    m = _FIELD_LOC.search(text)
    if m:
        parts = [p.strip(" '\"") for p in m.group(1).split(",") if p.strip(" '\"")]
        if parts and parts[0] in REQUEST_FIELDS:
            return ".".join(parts)
    for m in _FIELD_DOTTED.finditer(text):
        field = m.group(1)
        if field.split(".")[0] in REQUEST_FIELDS:
            return field
    low = text.lower()
    if any(w in low for w in _VALIDATION_WORDS):
        for field in REQUEST_FIELDS:
            if re.search(rf"\b{field}\b", text) and field not in ("model", "messages", "n", "stop"):
                return field
    return None


def field_fix(field: str, mode: str | None) -> str:
    """How to stop sending what the server refuses."""
    top = field.split(".")[0]
    if top == "response_format":
        others = [m for m in PROBE_ORDER if m != mode]
        return (f"set model.structured_output to one the server accepts ({', '.join(others)}) or to auto, "
                f"which probes them at preflight")
    if top in ("max_tokens", "max_completion_tokens"):
        return "lower model.max_tokens to what the server allows"
    if top in ("temperature", "seed", "top_p"):
        return f"drop or change {top} (model.temperature / model.extra_params)"
    return f"remove or change '{top}' (model.extra_params)"
