"""On-disk response cache, off by default (``model.cache_dir``).

The key is a SHA-256 of the exact request (every message part; images by the hash of their PNG bytes),
the model id, the endpoint and every setting that changes the answer (temperature, max tokens, seed,
response format, extra parameters). One JSON file per answer: ``<cache_dir>/<k[:2]>/<k>.json``, written
atomically, holding only the answer text, its token counts and the model id; never the key or the prompt.
A cached answer comes back with ``cached=True`` and zero cost.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any

from eb_core.model import ImagePart, ModelRequest

__all__ = ["ResponseCache", "request_fingerprint"]

_VERSION = 1


def request_fingerprint(request: ModelRequest) -> list[Any]:
    """A JSON-able, exact description of the request's messages (images as hashes)."""
    out: list[Any] = []
    for m in request.messages:
        parts: list[Any] = []
        for p in m.content:
            if isinstance(p, ImagePart):
                parts.append({"image_sha256": hashlib.sha256(p.png).hexdigest(), "name": p.name})
            else:
                parts.append({"text": p.text})
        out.append({"role": m.role, "content": parts})
    return out


class ResponseCache:
    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root).expanduser()
        self.root.mkdir(parents=True, exist_ok=True)

    @staticmethod
    def key(payload: dict[str, Any]) -> str:
        blob = json.dumps({"v": _VERSION, **payload}, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
        return hashlib.sha256(blob.encode("utf-8")).hexdigest()

    def _path(self, key: str) -> Path:
        return self.root / key[:2] / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        path = self._path(key)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, ValueError):
            return None  # a damaged entry is a miss; it is rewritten on the next answer
        return data if isinstance(data, dict) and isinstance(data.get("text"), str) else None

    def put(self, key: str, entry: dict[str, Any]) -> None:
        path = self._path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".json")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                json.dump(entry, fh, ensure_ascii=False)
            os.replace(tmp, path)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
