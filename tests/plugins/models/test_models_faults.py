"""Unit tests of the fault machinery: retry policy, Retry-After parsing, cache keys, secrets, limiter."""

from __future__ import annotations

import email.utils
import pickle
import random
import socket
import time

import pytest

from eb_core.model import ImagePart, Message, ModelRequest, TextPart
from eb_models._secrets import Scrubber, Secret, scrub
from eb_models.cache import ResponseCache, request_fingerprint
from eb_models.limits import RequestLimiter
from eb_models.retry import RetryPolicy, classify_status, connection_failure, retry_after_seconds


def test_backoff_is_exponential_with_jitter_and_capped():
    p = RetryPolicy(backoff_base_s=1.0, backoff_max_s=8.0)
    rng = random.Random(0)
    for retry, cap in ((1, 1), (2, 2), (3, 4), (4, 8), (9, 8)):
        waits = [p.backoff(retry, rng) for _ in range(50)]
        assert all(cap / 2 <= w <= cap for w in waits) and len(set(waits)) > 1


def test_next_wait_respects_attempts_time_and_retry_after():
    p = RetryPolicy(max_retries=2, max_seconds=10, backoff_base_s=0.1)
    assert p.next_wait(1, None, 0.0) is not None
    assert p.next_wait(3, None, 0.0) is None  # attempts spent
    assert p.next_wait(1, None, 9.99) is None  # time spent
    assert 3.0 <= p.next_wait(1, 3.0, 0.0) <= 3.1  # the server's wish wins over the backoff
    assert p.next_wait(1, 30.0, 0.0) is None  # a wish beyond the budget: give up now


def test_retry_after_forms():
    assert retry_after_seconds({"retry-after": "2"}) == 2.0
    assert retry_after_seconds({"Retry-After": "0.5"}) == 0.5
    assert retry_after_seconds({"retry-after-ms": "1500", "retry-after": "9"}) == 1.5
    now = time.time()
    date = email.utils.formatdate(now + 20, usegmt=True)
    assert 18 <= retry_after_seconds({"retry-after": date}, now=now) <= 21
    assert retry_after_seconds({"retry-after": "soon"}) is None
    assert retry_after_seconds(None) is None and retry_after_seconds({}) is None


def test_status_classes():
    assert [classify_status(s) for s in (None, 408, 429, 500, 503)] == ["retry"] * 5
    assert [classify_status(s) for s in (401, 403, 404)] == ["fatal"] * 3
    assert [classify_status(s) for s in (400, 413, 422)] == ["reject"] * 3


def _raised_from(cause_call) -> Exception:
    """What an SDK hands us: its own error (here worded as an HTTP 500) raised from the real OS error."""
    try:
        try:
            cause_call()
        except OSError as cause:
            raise RuntimeError("InternalServerError (HTTP 500): Connection error.") from cause
    except RuntimeError as exc:
        return exc
    raise AssertionError("no error")


def test_connection_failures_are_found_behind_the_sdks_wrapper():
    dns = connection_failure(_raised_from(lambda: socket.getaddrinfo("nonexistent.invalid", 80)))
    assert dns is not None and dns.kind == "dns" and dns.reason
    assert dns.describe("nonexistent.invalid").startswith("DNS error: cannot resolve the host 'nonexistent.invalid'")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    refused = connection_failure(_raised_from(lambda: socket.create_connection(("127.0.0.1", port), timeout=5)))
    assert refused is not None and refused.kind == "refused"
    assert f"refused by 127.0.0.1:{port}" in refused.describe("127.0.0.1", f"127.0.0.1:{port}")
    assert connection_failure(RuntimeError("HTTP 500 from a server that answered")) is None


def test_cache_key_is_exact():
    def req(text="hi", png=b"\x89PNG1"):
        return ModelRequest(messages=(Message(role="user", content=(ImagePart(png=png), TextPart(text=text))),))

    base = {"model_id": "m", "params": {"temperature": 0}}
    k = ResponseCache.key({**base, "messages": request_fingerprint(req())})
    assert k == ResponseCache.key({**base, "messages": request_fingerprint(req())})
    assert k != ResponseCache.key({**base, "messages": request_fingerprint(req(text="hi!"))})
    assert k != ResponseCache.key({**base, "messages": request_fingerprint(req(png=b"\x89PNG2"))})
    assert k != ResponseCache.key({**base, "model_id": "m2", "messages": request_fingerprint(req())})


def test_cache_survives_damaged_entries(tmp_path):
    cache = ResponseCache(tmp_path)
    cache.put("ab" + "0" * 62, {"text": "answer"})
    assert cache.get("ab" + "0" * 62) == {"text": "answer"}
    (tmp_path / "ab" / ("ab" + "0" * 62 + ".json")).write_text("{torn")
    assert cache.get("ab" + "0" * 62) is None
    assert cache.get("cd" + "0" * 62) is None


def test_secrets_stay_hidden():
    s = Secret("sk-abcdefgh12345")
    assert "sk-abc" not in repr(s) and "sk-abc" not in str(s) and s.get() == "sk-abcdefgh12345"
    with pytest.raises(TypeError):
        pickle.dumps(s)
    scrubber = Scrubber(["sk-abcdefgh12345"])
    assert "sk-" not in repr(scrubber)
    assert scrubber("key sk-abcdefgh12345 used") == "key *** used"
    assert scrub("Authorization: Bearer abcdefghijk", []) == "Authorization: Bearer ***"


def test_limiter_without_limits_costs_nothing(tmp_path):
    lim = RequestLimiter("m", root=tmp_path)
    with lim.slot() as waited:
        assert waited == 0.0
    assert not any(tmp_path.iterdir())


def test_a_slot_is_released_on_error(tmp_path):
    lim = RequestLimiter("m", max_concurrency=1, root=tmp_path)
    with pytest.raises(RuntimeError):
        with lim.slot():
            raise RuntimeError("boom")
    t0 = time.monotonic()
    with lim.slot():
        pass
    assert time.monotonic() - t0 < 0.5
