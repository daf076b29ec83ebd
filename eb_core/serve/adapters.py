"""Trainer-side shapes over ``eb serve``: the batch-service interface VAGEN-style trainers call.

VAGEN-style environment services are driven with dictionaries keyed by the trainer's environment ids::

    service.create_environments_batch({"e0": cfg, "e1": cfg})
    service.reset_batch({"e0": seed, "e1": seed})       -> {id: (obs, info)}
    service.step_batch({"e0": answer, "e1": answer})    -> {id: (obs, reward, done, info)}
    service.close_batch(["e0", "e1"])

with ``obs = {"obs_str": <prompt with <image> placeholders>, "multi_modal_data": {"<image>": [PIL images]}}``.
:class:`BatchService` gives exactly that over one ``eb serve`` server: each ``create_environments_batch`` call
leases one session holding those environments, and a reset or step of ids from several sessions becomes one
batched call per session. ``done`` is ``terminated or truncated``.
"""

from __future__ import annotations

import base64
import io
from collections import defaultdict
from collections.abc import Iterable
from typing import Any

__all__ = ["BatchService"]


class BatchService:
    """A VAGEN-style batch environment service backed by an ``eb serve`` server at ``url``."""

    def __init__(self, url: str, *, token: str | None = None, timeout_s: float = 600.0) -> None:
        import os

        import httpx

        token = token if token is not None else os.environ.get("EB_SERVE_TOKEN")
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._http = httpx.Client(base_url=url.rstrip("/"), headers=headers, timeout=timeout_s)
        self._where: dict[Any, tuple[str, int]] = {}
        self._size: dict[str, int] = {}

    def _call(self, method: str, path: str, **kw: Any) -> Any:
        from eb_core.serve.client import RemoteEnvError

        r = self._http.request(method, path, **kw)
        if r.status_code >= 400:
            raise RemoteEnvError(f"eb serve answered {r.status_code} to {method} {path}: "
                                 f"{r.json().get('error', r.text) if r.content else ''}")
        return r.json() if r.content else None

    @staticmethod
    def _obs(obs: dict[str, Any] | None) -> dict[str, Any] | None:
        if obs is None:
            return None
        from PIL import Image

        from eb_core.gym import IMAGE_PLACEHOLDER

        pngs: list[str] = list(obs.get("images") or []) if "images" in obs else [obs["image"]]
        images = [Image.open(io.BytesIO(base64.b64decode(p))).convert("RGB") for p in pngs]
        text = obs.get("prompt", obs.get("text", ""))
        return {"obs_str": text.replace(IMAGE_PLACEHOLDER, "<image>"), "multi_modal_data": {"<image>": images}}

    def _by_session(self, ids: Iterable[Any]) -> dict[str, list[tuple[Any, int]]]:
        groups: dict[str, list[tuple[Any, int]]] = defaultdict(list)
        for env_id in ids:
            if env_id not in self._where:
                raise KeyError(f"unknown environment id {env_id!r}; create it with create_environments_batch")
            sid, i = self._where[env_id]
            groups[sid].append((env_id, i))
        return groups

    def create_environments_batch(self, ids2configs: dict[Any, Any]) -> None:
        """Lease one session with an environment per id (the world and its settings are the server's)."""
        if not ids2configs:
            return
        info = self._call("POST", "/v1/sessions", json={"num_envs": len(ids2configs), "autoreset": "Disabled"})
        sid = info["session"]
        self._size[sid] = len(ids2configs)
        for i, env_id in enumerate(ids2configs):
            self._where[env_id] = (sid, i)

    def reset_batch(self, ids2seeds: dict[Any, int | None]) -> dict[Any, tuple[Any, dict[str, Any]]]:
        out: dict[Any, tuple[Any, dict[str, Any]]] = {}
        for sid, members in self._by_session(ids2seeds).items():
            n = self._size[sid]
            seeds: list[int | None] = [None] * n
            mask = [False] * n
            for env_id, i in members:
                seeds[i], mask[i] = ids2seeds[env_id], True
            res = self._call("POST", f"/v1/sessions/{sid}/reset", json={"seeds": seeds, "mask": mask})
            for env_id, i in members:
                out[env_id] = (self._obs(res["observations"][i]), res["infos"][i] or {})
        return out

    def step_batch(self, ids2actions: dict[Any, Any]) -> dict[Any, tuple[Any, float, bool, dict[str, Any]]]:
        out: dict[Any, tuple[Any, float, bool, dict[str, Any]]] = {}
        for sid, members in self._by_session(ids2actions).items():
            actions: list[Any] = [None] * self._size[sid]
            for env_id, i in members:
                actions[i] = ids2actions[env_id]
            res = self._call("POST", f"/v1/sessions/{sid}/step", json={"actions": actions})
            for env_id, i in members:
                done = bool(res["terminated"][i] or res["truncated"][i])
                out[env_id] = (self._obs(res["observations"][i]), float(res["rewards"][i]), done,
                               res["infos"][i] or {})
        return out

    def close_batch(self, env_ids: Iterable[Any] | None = None) -> None:
        """Forget these ids (all when None); a session is closed once none of its ids is left."""
        ids = list(self._where) if env_ids is None else list(env_ids)
        for env_id in ids:
            self._where.pop(env_id, None)
        live = {sid for sid, _ in self._where.values()}
        for sid in [s for s in self._size if s not in live]:
            self._size.pop(sid)
            self._call("DELETE", f"/v1/sessions/{sid}")
        if env_ids is None:
            self._http.close()
