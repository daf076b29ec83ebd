"""Per-model request limits that hold across processes: at most ``max_concurrency`` calls in flight and
at most ``rpm`` calls started in any 60-second window.

The runner plays episodes in separate worker processes, each with its own backend, so the limits live in
files under one directory per model (default ``<tmp>/eb_models_limits/<model>-<hash>``), coordinated with
``fcntl.flock``:

* ``slot-<i>.lock`` for ``i < max_concurrency``: a call holds an exclusive lock on one slot file while its
  HTTP request is in flight. The kernel drops the lock if the process dies, so a killed worker never leaks
  a slot.
* ``rpm.json``: the start times of the calls of the last 60 s, read and rewritten under an exclusive lock
  (a sliding-window log, so no 60-second window ever holds more than ``rpm`` starts).

Every process on the machine that uses the same model id and endpoint shares the limits, including two
runs started side by side, which is what a provider's per-key limit needs. POSIX only (Linux, macOS).
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import random
import re
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["RequestLimiter", "default_limits_dir"]

_WINDOW_S = 60.0


def default_limits_dir() -> Path:
    return Path(tempfile.gettempdir()) / "eb_models_limits"


def _key_dir(root: Path, key: str) -> Path:
    safe = re.sub(r"[^A-Za-z0-9._-]+", "_", key)[:60]
    digest = hashlib.sha256(key.encode()).hexdigest()[:10]
    return root / f"{safe}-{digest}"


class RequestLimiter:
    """Cross-process concurrency and requests-per-minute limits for one model (``key``)."""

    def __init__(self, key: str, *, max_concurrency: int | None = None, rpm: int | None = None,
                 root: str | os.PathLike[str] | None = None, poll_s: float = 0.02, window_s: float = _WINDOW_S) -> None:
        self.key = key
        self.window_s = window_s
        self.max_concurrency = max_concurrency
        self.rpm = rpm
        self.poll_s = poll_s
        self.dir = _key_dir(Path(root) if root else default_limits_dir(), key)
        if max_concurrency or rpm:
            self.dir.mkdir(parents=True, exist_ok=True)

    @property
    def active(self) -> bool:
        return bool(self.max_concurrency or self.rpm)

    @contextmanager
    def slot(self) -> Iterator[float]:
        """Wait for a free concurrency slot and an rpm token; yields the seconds spent waiting."""
        if not self.active:
            yield 0.0
            return
        t0 = time.monotonic()
        fd = self._acquire_slot() if self.max_concurrency else None
        try:
            if self.rpm:
                self._take_token()
            yield time.monotonic() - t0
        finally:
            if fd is not None:
                fcntl.flock(fd, fcntl.LOCK_UN)
                os.close(fd)

    def _acquire_slot(self) -> int:
        assert self.max_concurrency
        n = self.max_concurrency
        paths = [self.dir / f"slot-{i}.lock" for i in range(n)]
        start = random.randrange(n)  # spread processes over the slots
        while True:
            for j in range(n):
                fd = os.open(paths[(start + j) % n], os.O_RDWR | os.O_CREAT, 0o600)
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    return fd
                except BlockingIOError:
                    os.close(fd)
            time.sleep(self.poll_s * (0.5 + random.random()))

    def _take_token(self) -> None:
        assert self.rpm
        path = self.dir / "rpm.json"
        while True:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o600)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)
                with os.fdopen(os.dup(fd), "r+", encoding="utf-8") as fh:
                    raw = fh.read()
                    try:
                        starts = [float(t) for t in json.loads(raw)] if raw.strip() else []
                    except (ValueError, TypeError):
                        starts = []  # a corrupt file only loses the window, never blocks
                    now = time.time()
                    starts = sorted(t for t in starts if now - t < self.window_s and t <= now + 1.0)
                    wait = 0.0
                    if len(starts) < self.rpm:
                        starts.append(now)
                    else:
                        wait = starts[len(starts) - self.rpm] + self.window_s - now
                    fh.seek(0)
                    fh.truncate()
                    fh.write(json.dumps(starts))
            finally:
                fcntl.flock(fd, fcntl.LOCK_UN)
                os.close(fd)
            if wait <= 0:
                return
            time.sleep(min(max(wait, self.poll_s), 1.0) + random.random() * self.poll_s)
