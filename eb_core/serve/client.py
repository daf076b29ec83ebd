"""A Gymnasium vector env over an ``eb serve`` server: code written against :class:`~eb_core.gym.EBVectorEnv` runs
unchanged against a server on another machine.

    from eb_core.serve.client import RemoteVectorEnv
    envs = RemoteVectorEnv("http://127.0.0.1:8765", num_envs=32)
    obs, infos = envs.reset(seed=0)
    obs, rewards, terminated, truncated, infos = envs.step(actions)

It needs only ``gymnasium``, ``numpy``, ``pillow`` and ``httpx`` on the trainer's side (no simulator, no MuJoCo).
Observations are decoded back to arrays, exactly as the in-process vector env returns them (``images="png"``
keeps the PNG bytes instead, for trainers that hand them to a VLM processor as they are). A background thread keeps
the session alive while the trainer is busy between steps; if the trainer process dies, the server reaps its
session after its ``session_timeout_s``.
"""

from __future__ import annotations

import base64
import threading
from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array

from eb_core.gym.vector import reset_seeds
from eb_core.serve.png import decode_png
from eb_core.serve.schema import SCHEMA
from eb_core.serve.spaces import build

__all__ = ["RemoteEnvError", "RemoteVectorEnv"]


class RemoteEnvError(RuntimeError):
    """The server refused a call (the message is the server's one line) or could not be reached."""


def _decode_png(data: str) -> np.ndarray:
    return decode_png(base64.b64decode(data))


def _to_json(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


class RemoteVectorEnv(VectorEnv):
    """``num_envs`` environments leased from an ``eb serve`` server (see the module docstring).

    Args:
        url: the server, e.g. ``http://127.0.0.1:8765``.
        num_envs: environments to lease (the server refuses more than it has free).
        token: the server's token, if it has one (default: ``$EB_SERVE_TOKEN``).
        autoreset_mode: Gymnasium's ``NextStep`` (default), ``SameStep`` or ``Disabled``.
        images: ``array`` (decoded, as the in-process env) or ``png`` (base64-decoded PNG bytes).
        timeout_s: HTTP timeout of one call (a step of many environments can take seconds).
        keepalive: ping the session from a background thread so a slow trainer is not reaped.
    """

    def __init__(self, url: str, num_envs: int, *, token: str | None = None,
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP, images: str = "array",
                 timeout_s: float = 600.0, keepalive: bool = True) -> None:
        import os

        import httpx

        if images not in ("array", "png"):
            raise ValueError(f"images must be 'array' or 'png', got {images!r}")
        self.closed = True
        self.url = url.rstrip("/")
        self.images = images
        token = token if token is not None else os.environ.get("EB_SERVE_TOKEN")
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._http = httpx.Client(base_url=self.url, headers=headers, timeout=timeout_s)
        self.autoreset_mode = autoreset_mode if isinstance(autoreset_mode, AutoresetMode) \
            else AutoresetMode(autoreset_mode)
        health = self._call("GET", "/v1/health")
        if health.get("schema") != SCHEMA:
            self._http.close()
            raise RemoteEnvError(f"{self.url} speaks {health.get('schema')!r}, this client speaks {SCHEMA!r}; "
                                 f"install the same embodiedbench version on both sides")
        info = self._call("POST", "/v1/sessions", json={"num_envs": num_envs,
                                                         "autoreset": self.autoreset_mode.value})
        self.closed = False
        self.session: str = info["session"]
        self.num_envs = int(info["num_envs"])
        self.session_timeout_s = float(info["session_timeout_s"])
        self.server_info = {k: info[k] for k in ("world", "obs_mode", "split", "taskset")}
        self.single_observation_space = build(info["observation_space"])
        self.single_action_space = build(info["action_space"])
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.metadata = {"autoreset_mode": self.autoreset_mode, "render_modes": []}
        self.render_mode = None
        self._last_obs: list[Any] = [None] * self.num_envs
        self._stop = threading.Event()
        self._pinger: threading.Thread | None = None
        if keepalive:
            self._pinger = threading.Thread(target=self._keepalive, name="eb-serve-keepalive", daemon=True)
            self._pinger.start()

    # -- transport -----------------------------------------------------------------------------------

    def _call(self, method: str, path: str, **kwargs: Any) -> Any:
        import httpx

        try:
            r = self._http.request(method, path, **kwargs)
        except httpx.HTTPError as exc:
            raise RemoteEnvError(f"cannot reach eb serve at {self.url}: {type(exc).__name__}: {exc}") from None
        if r.status_code >= 400:
            try:
                why = r.json().get("error", r.text)
            except ValueError:
                why = r.text[:300]
            raise RemoteEnvError(f"eb serve answered {r.status_code} to {method} {path}: {why}")
        return r.json() if r.content else None

    def _keepalive(self) -> None:
        period = max(0.05, self.session_timeout_s / 3)
        while not self._stop.wait(period):
            try:
                self._call("POST", f"/v1/sessions/{self.session}/keepalive")
            except RemoteEnvError:
                pass

    # -- observations --------------------------------------------------------------------------------

    def _decode(self, obs: dict[str, Any]) -> dict[str, Any]:
        dec = (lambda s: base64.b64decode(s)) if self.images == "png" else _decode_png
        out = dict(obs)
        if isinstance(out.get("images"), list):
            out["images"] = tuple(dec(s) for s in out["images"])
        if isinstance(out.get("image"), str):
            out["image"] = dec(out["image"])
        return out

    def _batch(self) -> Any:
        if self.images == "png":
            return tuple(self._last_obs)
        obs = [o if o is not None else self.single_observation_space.sample() for o in self._last_obs]
        out: Any = create_empty_array(self.single_observation_space, self.num_envs)
        return concatenate(self.single_observation_space, obs, out)

    # -- gymnasium API -------------------------------------------------------------------------------

    def reset(self, *, seed: int | Sequence[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        n = self.num_envs
        seeds = reset_seeds(seed, n)
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        task_id = options.pop("task_id", None)
        body: dict[str, Any] = {"seeds": seeds}
        if mask is not None:
            body["mask"] = [bool(m) for m in np.asarray(mask)]
        if task_id is not None:
            body["task_ids"] = [str(task_id)] * n
        res = self._call("POST", f"/v1/sessions/{self.session}/reset", json=body)
        infos: dict[str, Any] = {}
        for i, (o, info) in enumerate(zip(res["observations"], res["infos"])):
            if info is not None and o is None and "error" in info:
                raise RuntimeError(info["error"])
            if o is not None:
                self._last_obs[i] = self._decode(o)
            elif self._last_obs[i] is None:
                raise RuntimeError(f"environment {i} has never been reset; include it in reset_mask")
            if info is not None:
                infos = self._add_info(infos, info, i)
        return self._batch(), infos

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        acts = [_to_json(a) for a in list(actions)]
        if len(acts) != self.num_envs:
            raise ValueError(f"step() needs {self.num_envs} actions (one per environment), got {len(acts)}")
        res = self._call("POST", f"/v1/sessions/{self.session}/step", json={"actions": acts})
        infos: dict[str, Any] = {}
        for i, o in enumerate(res["observations"]):
            if o is not None:
                self._last_obs[i] = self._decode(o)
            if res["infos"][i] is not None:
                infos = self._add_info(infos, res["infos"][i], i)
        return (self._batch(), np.asarray(res["rewards"], dtype=np.float64),
                np.asarray(res["terminated"], dtype=np.bool_), np.asarray(res["truncated"], dtype=np.bool_), infos)

    def stats(self) -> dict[str, Any]:
        """The server's counters and latency (``GET /v1/stats``)."""
        return dict(self._call("GET", "/v1/stats"))

    def close_extras(self, **kwargs: Any) -> None:
        self._stop.set()
        try:
            self._call("DELETE", f"/v1/sessions/{self.session}")
        except RemoteEnvError:
            pass  # already reaped, or the server is gone: nothing to give back
        self._http.close()

    # close() is VectorEnv's own; gym.vector repeats __del__ so this client never imports eb_core.gym.
    def __del__(self) -> None:
        if not getattr(self, "closed", True):
            try:
                self.close()
            except Exception:
                pass
