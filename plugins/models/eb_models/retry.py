"""Retry policy: exponential backoff with jitter, ``Retry-After`` honoured, capped by attempts and by time.

Pure functions on purpose (no SDK import), so the policy is easy to test and to reuse in other backends.
"""

from __future__ import annotations

import email.utils
import random
import socket
import time
from dataclasses import dataclass
from typing import Any, Literal

__all__ = ["ConnectionFailure", "ErrorKind", "RetryPolicy", "classify_status", "connection_failure",
           "retry_after_seconds"]

#: ``fatal``: stop the run (bad key, unknown model); ``retry``: try again later; ``reject``: this request
#: will never succeed (400: too long, unsupported content) - the episode is recorded as an error.
ErrorKind = Literal["fatal", "retry", "reject"]


@dataclass(frozen=True)
class RetryPolicy:
    max_retries: int = 5
    """Retries after the first attempt (so at most ``max_retries + 1`` requests)."""
    max_seconds: float = 300.0
    """Give up when the next wait would end later than this many seconds after the first attempt."""
    backoff_base_s: float = 1.0
    """First backoff; doubled each retry."""
    backoff_max_s: float = 60.0
    """Largest backoff (before jitter)."""

    def backoff(self, retry: int, rng: random.Random | None = None) -> float:
        """Seconds to wait before retry number ``retry`` (1-based): half fixed, half random ("equal jitter")."""
        uniform = rng.uniform if rng is not None else random.uniform
        cap = min(self.backoff_max_s, self.backoff_base_s * (2 ** (retry - 1)))
        return cap / 2 + uniform(0, cap / 2)

    def next_wait(self, retry: int, retry_after: float | None, elapsed: float,
                  rng: random.Random | None = None) -> float | None:
        """The wait before retry ``retry``, or None when the attempt or time budget is spent."""
        if retry > self.max_retries:
            return None
        wait = self.backoff(retry, rng)
        if retry_after is not None:
            wait = max(retry_after, 0.0) + (rng or random).uniform(0, min(0.25, self.backoff_base_s))
        if elapsed + wait > self.max_seconds:
            return None
        return wait


def classify_status(status: int | None) -> ErrorKind:
    """How to treat an HTTP status (None = no response at all: connection error or timeout)."""
    if status is None or status in (408, 409, 425, 429) or status >= 500:
        return "retry"
    if status in (401, 403, 404):
        return "fatal"
    return "reject"


def retry_after_seconds(headers: Any, now: float | None = None) -> float | None:
    """Seconds asked for by ``retry-after-ms`` / ``Retry-After`` (delta seconds or an HTTP date), if any."""
    if headers is None:
        return None
    try:
        get = headers.get
    except AttributeError:
        return None
    ms = get("retry-after-ms") or get("Retry-After-Ms")
    if ms:
        try:
            return max(0.0, float(ms) / 1000.0)
        except ValueError:
            pass
    value = get("retry-after") or get("Retry-After")
    if not value:
        return None
    value = str(value).strip()
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    if when is None:
        return None
    return max(0.0, when.timestamp() - (now if now is not None else time.time()))


@dataclass(frozen=True)
class ConnectionFailure:
    """The server was never reached, so there is no HTTP status (SDKs may still word it as "HTTP 500")."""

    kind: Literal["dns", "refused", "connect", "timeout"]
    """``dns``: the host name does not resolve; ``refused``: nothing listens at the port; ``connect``: another
    socket-level failure (unreachable network, reset); ``timeout``: no answer in time."""
    reason: str
    """The operating system's words (``Name or service not known``, ``Connection refused``...)."""

    def describe(self, host: str | None = None, address: str | None = None) -> str:
        """One phrase for a log or error line; ``host`` is the URL's host name, ``address`` its ``host:port``."""
        if self.kind == "dns":
            return f"DNS error: cannot resolve the host{' ' + repr(host) if host else ''} ({self.reason}); " \
                   f"no HTTP response"
        at = f" {address or host}" if (address or host) else " the server"
        if self.kind == "refused":
            return f"connection refused by{at} ({self.reason}): nothing listens there; no HTTP response"
        if self.kind == "timeout":
            return f"no answer from{at} in time ({self.reason})"
        return f"connection error reaching{at} ({self.reason}); no HTTP response"


def _os_reason(exc: BaseException) -> str:
    return getattr(exc, "strerror", None) or " ".join(str(exc).split()) or type(exc).__name__


def connection_failure(exc: BaseException) -> ConnectionFailure | None:
    """The failure to reach the server behind ``exc``, if there is one, found by walking the chain of exceptions
    it was raised from (litellm wraps httpx's ``ConnectError``, itself wrapping ``socket.gaierror``, into an
    ``InternalServerError`` with status 500). None when the server answered (a real HTTP status)."""
    found: dict[str, BaseException] = {}  # kind -> innermost exception of that kind (the most precise words)
    seen: set[int] = set()
    cur: BaseException | None = exc
    while cur is not None and id(cur) not in seen and len(seen) < 16:
        seen.add(id(cur))
        name = type(cur).__name__
        if isinstance(cur, socket.gaierror):
            found["dns"] = cur
        elif isinstance(cur, ConnectionRefusedError):
            found["refused"] = cur
        elif isinstance(cur, TimeoutError) or name.endswith("Timeout"):  # httpx's ConnectTimeout, litellm's Timeout
            found["timeout"] = cur
        elif isinstance(cur, ConnectionError) or name in ("ConnectError", "APIConnectionError", "RemoteProtocolError"):
            found["connect"] = cur
        cur = cur.__cause__ or cur.__context__
    for kind in ("dns", "refused", "timeout", "connect"):
        if kind in found:
            return ConnectionFailure(kind, _os_reason(found[kind]))
    return None
