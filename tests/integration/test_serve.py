"""``eb serve`` as a real server process on 127.0.0.1, driven by the real client and by raw HTTP."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time

import httpx
import numpy as np
import pytest

pytest.importorskip("fastapi", reason="eb serve needs the [serve] extra (fastapi, uvicorn)")

TOKEN = "test-token-not-a-secret"
ANSWER = json.dumps({"visual_state_description": "", "reasoning_and_reflection": "", "language_plan": "",
                     "executable_plan": [{"action_id": 0, "action_name": "Move forward by 0.25"}]})


class Server:
    def __init__(self, *args: str, env: dict[str, str] | None = None) -> None:
        full_env = {**os.environ, **(env or {})}
        self.proc = subprocess.Popen([sys.executable, "-m", "eb_core", "serve", *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, env=full_env)
        line = self.proc.stdout.readline()  # the ready line (or nothing if it failed)
        m = re.search(r"ready at (http://[^ ]+)", line)
        if not m:
            self.proc.kill()
            raise AssertionError(f"eb serve did not start: {line!r} {self.proc.stderr.read()[-2000:]}")
        self.url = m.group(1)
        self.http = httpx.Client(base_url=self.url, headers={"Authorization": f"Bearer {TOKEN}"}, timeout=300)

    def stats(self) -> dict:
        return self.http.get("/v1/stats").json()

    def stop(self) -> str:
        self.http.close()
        self.proc.send_signal(signal.SIGTERM)
        try:
            _, err = self.proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise
        return err


@pytest.fixture(scope="module")
def server():
    s = Server("env=navigation", "envs=6", "port=0", "runner.workers=2", "session_timeout_s=3",
               env={"EB_SERVE_TOKEN": TOKEN})
    yield s
    err = s.stop()
    assert s.proc.returncode == 0, err
    assert "stopped" in err and TOKEN not in err


def _client(server: Server, n: int, **kw):
    from eb_core.serve.client import RemoteVectorEnv

    return RemoteVectorEnv(server.url, n, token=TOKEN, **kw)


def test_first_observation_is_the_in_process_one(server):
    from eb_core.gym import EBEnv

    local = EBEnv("navigation")
    want, want_info = local.reset(seed=7)
    local.close()
    v = _client(server, 1)
    try:
        got, info = v.reset(seed=[7])
    finally:
        v.close()
    assert got["prompt"][0] == want["prompt"]
    assert info["task_id"][0] == want_info["task_id"]
    assert len(got["images"][0]) == len(want["images"]) >= 1
    for a, b in zip(got["images"][0], want["images"]):
        assert a.shape == b.shape and np.array_equal(a, b)  # PNG is lossless: the same pixels


def test_two_clients_in_parallel_and_autoreset(server):
    out: dict[str, object] = {}

    def play(name: str) -> None:
        v = _client(server, 2)
        try:
            obs, _ = v.reset(seed=[0, 1] if name == "a" else [2, 3])
            rewards, dones = [], 0
            for _ in range(3):
                obs, r, term, trunc, info = v.step([ANSWER, ANSWER])
                assert "error" not in info, info.get("error")
                rewards.append(r)
                dones += int(np.sum(term | trunc))
            out[name] = (obs["prompt"], np.array(rewards).shape)
        except BaseException as exc:  # noqa: BLE001 - re-raised in the test thread
            out[name] = exc
        finally:
            v.close()

    threads = [threading.Thread(target=play, args=(k,)) for k in ("a", "b")]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=600)
    for k in ("a", "b"):
        assert not isinstance(out[k], BaseException), out[k]
        prompts, shape = out[k]
        assert shape == (3, 2) and len(prompts) == 2
        assert all("Move forward" in p for p in prompts)  # the executed action is in each prompt's history
    st = server.stats()
    assert st["steps"] >= 12 and st["envs_leased"] == 0


def test_bad_requests_get_one_line_4xx(server):
    h = server.http
    r = h.post("/v1/sessions", content=b"{not json", headers={"content-type": "application/json"})
    assert r.status_code == 422 and "not valid JSON" in r.json()["error"]
    r = h.post("/v1/sessions", json=[1, 2])
    assert r.status_code == 422 and "must be a JSON object" in r.json()["error"]
    r = h.post("/v1/sessions", json={"num_envs": 2, "colour": "red"})
    assert r.status_code == 422 and "colour" in r.json()["error"]
    r = h.post("/v1/sessions", json={"num_envs": 99})
    assert r.status_code == 503 and "are free" in r.json()["error"]
    r = h.post("/v1/sessions/nope/step", json={"actions": [ANSWER]})
    assert r.status_code == 404 and "no session 'nope'" in r.json()["error"]
    sid = h.post("/v1/sessions", json={"num_envs": 1}).json()["session"]
    try:
        r = h.post(f"/v1/sessions/{sid}/step", json={"actions": [ANSWER, ANSWER]})
        assert r.status_code == 422 and "one per environment" in r.json()["error"]
        r = h.post(f"/v1/sessions/{sid}/step", content=b'{"actions": ["' + b"x" * (17 * 1024 * 1024) + b'"]}',
                   headers={"content-type": "application/json"})
        assert r.status_code == 413 and "larger than" in r.json()["error"]
        r = httpx.post(f"{server.url}/v1/sessions/{sid}/keepalive")  # no token
        assert r.status_code == 401 and "token" in r.json()["error"]
        assert httpx.get(f"{server.url}/v1/health").json()["status"] == "ok"  # health needs none
    finally:
        assert h.delete(f"/v1/sessions/{sid}").status_code == 204


def test_a_killed_client_is_reaped(server):
    before = server.stats()
    script = textwrap.dedent(f"""
        import sys, time
        from eb_core.serve.client import RemoteVectorEnv
        v = RemoteVectorEnv({server.url!r}, 2, token={TOKEN!r})
        v.reset(seed=0)
        v.step([{ANSWER!r}] * 2)
        print("mid-episode", flush=True)
        time.sleep(600)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "mid-episode"
        assert server.stats()["envs_leased"] == before["envs_leased"] + 2
        child.kill()  # no close(): the keep-alive thread dies with it
        child.wait(timeout=30)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and server.stats()["envs_leased"] > before["envs_leased"]:
            time.sleep(0.5)
        st = server.stats()
        assert st["envs_leased"] == before["envs_leased"]
        assert st["reaped_sessions"] == before["reaped_sessions"] + 1
    finally:
        child.kill()


def test_a_slow_client_is_kept_alive(server):
    v = _client(server, 1)
    try:
        v.reset(seed=0)
        time.sleep(5)  # longer than session_timeout_s=3: the keep-alive thread holds the session
        _, _, _, trunc, info = v.step([ANSWER])
        assert not trunc[0] and "error" not in info
    finally:
        v.close()


def test_a_worker_killed_mid_step_ends_only_its_episodes(server):
    v = _client(server, 6)  # every slot: three on each of the two workers
    try:
        v.reset(seed=0)
        st = server.stats()
        victim = st["worker_pids"][0]
        os.kill(victim, signal.SIGKILL)
        _, _, _, trunc, info = v.step([ANSWER] * 6)
        lost = [i for i in range(6) if "_error" in info and info["_error"][i]]
        assert trunc[lost].all() and 0 < len(lost) < 6, (trunc, info.get("error"))
        after = server.stats()
        assert after["worker_restarts"] == st["worker_restarts"] + 1 and victim not in after["worker_pids"]
        _, _, _, trunc, info = v.step([ANSWER] * 6)  # autoreset brings the lost ones back
        assert "_error" not in info or not info["_error"].any()
    finally:
        v.close()


def test_refuses_a_public_bind_without_flag_and_token():
    p = subprocess.run([sys.executable, "-m", "eb_core", "serve", "env=navigation", "host=0.0.0.0"],
                       capture_output=True, text=True, timeout=120, env={**os.environ, "EB_SERVE_TOKEN": ""})
    assert p.returncode == 2
    assert p.stderr.strip().count("\n") == 0 and "allow_remote=true" in p.stderr
    p = subprocess.run([sys.executable, "-m", "eb_core", "serve", "env=navigation", "host=0.0.0.0",
                        "allow_remote=true"], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "EB_SERVE_TOKEN": ""})
    assert p.returncode == 2 and "EB_SERVE_TOKEN" in p.stderr
    p = subprocess.run([sys.executable, "-m", "eb_core", "serve", "env=navigaton"], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "navigation" in p.stderr


def test_vagen_style_batch_service(server):
    from eb_core.serve.adapters import BatchService

    svc = BatchService(server.url, token=TOKEN)
    svc.create_environments_batch({"a": {}, "b": {}})
    svc.create_environments_batch({"c": {}})
    assert server.stats()["sessions"] >= 2
    first = svc.reset_batch({"a": 0, "c": 5})
    assert set(first) == {"a", "c"}
    obs, info = first["a"]
    assert "<image>" in obs["obs_str"] and obs["multi_modal_data"]["<image>"][0].size == (500, 500)
    assert info["task_id"] and first["c"][1]["task_id"] != info["task_id"]
    stepped = svc.step_batch({"a": ANSWER, "c": ANSWER})
    for env_id in ("a", "c"):
        obs, reward, done, info = stepped[env_id]
        assert isinstance(reward, float) and done in (True, False) and "error" not in info
    with pytest.raises(KeyError, match="unknown environment id 'zz'"):
        svc.step_batch({"zz": ANSWER})
    svc.close_batch()
    assert server.stats()["envs_leased"] == 0
