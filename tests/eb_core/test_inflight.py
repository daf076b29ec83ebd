"""Many episodes in flight per process: the episode driver, the in-flight runner, its faults."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.episode import EpisodeDriver, run_episode
from eb_core.model import ModelTransientError
from eb_core.records import RunFiles
from eb_core.runner import run, split_slots

FIXTURE_DIR = Path(fixture_plugin.__file__).parent


def lines(run_dir):
    return [json.loads(x) for x in (Path(run_dir) / "episodes.jsonl").read_text().splitlines()]


def outcome(rs):
    return sorted((r["task_id"], r["repeat"], r["seed"], r["success"], r["env_steps"], r["planner_steps"],
                   r["invalid_actions"]) for r in rs)


class SlowScripted(fixture_plugin.ScriptedBackend):
    """The scripted oracle, taking ``delay_s`` per call and logging each call's (pid, start, end) to ``log``."""

    def __init__(self, delay_s: float = 0.2, log: str | None = None, **kw):
        super().__init__(**kw)
        self.delay_s, self.log = delay_s, log

    def complete(self, request):
        t0 = time.time()
        time.sleep(self.delay_s)
        out = super().complete(request)
        if self.log:
            fd = os.open(self.log, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            os.write(fd, f"{os.getpid()} {t0} {time.time()}\n".encode())
            os.close(fd)
        return out


@fixture_plugin.hookimpl
def eb_register_model_backends():
    from eb_core import ModelBackendSpec

    return [ModelBackendSpec(name="slow-scripted", entry_point=f"{__name__}:SlowScripted", description="test")]


PLUGINS = [fixture_plugin, sys.modules[__name__]]


def slow(delay_s=0.2, log=None):
    return {"name": "slow", "backend": "slow-scripted", "oracle": True, "delay_s": delay_s, "log": log}


# -- the driver ----------------------------------------------------------------------------------------


def _episode_kwargs(tmp_path, task, name):
    cfg = make_config()
    backend = fixture_plugin.ScriptedBackend(oracle=True)
    from eb_core.planner import VLMPlanner

    return dict(env=fixture_plugin.CorridorEnv(), task=task, seed=7, backend=backend, env_config=cfg.env,
                planner=VLMPlanner(cfg.planner, cfg.env, supports_json_schema=True), step_dir=tmp_path / name)


def test_interleaved_drivers_give_the_records_of_run_episode(tmp_path):
    tasks = fixture_plugin.CorridorEnv.load_tasks()[4:7]  # near-4, far-0, far-1: 2 to 5 steps each
    expected = [run_episode(**_episode_kwargs(tmp_path, t, f"ref-{t.id}")) for t in tasks]
    kws = [_episode_kwargs(tmp_path, t, f"drv-{t.id}") for t in tasks]
    drivers = [EpisodeDriver(**kw) for kw in kws]
    calls = 0
    while not all(d.done for d in drivers):
        for d, kw in zip(drivers, kws):  # round robin: one model call of each episode in turn
            req = d.next_request()
            if req is not None:
                assert d.waiting
                d.submit(kw["backend"].complete(req))
                calls += 1
    assert calls == sum(r.model_calls for r in expected) >= 3
    strip = lambda r: r.model_dump(exclude={"wall_time_s", "model_latency_s"})
    assert [strip(d.record) for d in drivers] == [strip(r) for r in expected]
    for t in tasks:  # the same step files too
        ref = (tmp_path / f"ref-{t.id}" / "steps.jsonl").read_text()
        assert (tmp_path / f"drv-{t.id}" / "steps.jsonl").read_text() == ref


def test_a_failed_call_is_an_error_episode_and_submit_needs_a_pending_request(tmp_path):
    kw = _episode_kwargs(tmp_path, fixture_plugin.CorridorEnv.load_tasks()[0], "x")
    d = EpisodeDriver(**kw)
    with pytest.raises(RuntimeError, match="next_request"):
        d.submit(None)
    assert d.next_request() is not None
    d.fail(ModelTransientError("server kept answering 503"))
    assert d.done and d.next_request() is None
    assert d.record.status == "error" and "503" in d.record.error


def test_slots_are_spread_over_the_workers():
    assert split_slots(64, 2, 1000) == [32, 32]
    assert split_slots(5, 2, 1000) == [3, 2]
    assert split_slots(64, 2, 3) == [2, 1]
    assert split_slots(2, 8, 100) == [1, 1]


# -- the runner ----------------------------------------------------------------------------------------


def test_many_episodes_in_one_process_overlap_their_calls_and_match_inline(tmp_path):
    log = tmp_path / "calls.log"
    a = run(make_config(model=slow(0.0)), tmp_path / "a", plugins=PLUGINS)
    b = run(make_config(model=slow(0.3, str(log)), runner__concurrency=4), tmp_path / "b", plugins=PLUGINS)
    assert outcome(lines(tmp_path / "a")) == outcome(lines(tmp_path / "b"))
    assert a["overall"]["success_rate"] == b["overall"]["success_rate"] == 1.0
    calls = [tuple(map(float, ln.split()[1:])) for ln in log.read_text().splitlines()]
    pids = {ln.split()[0] for ln in log.read_text().splitlines()}
    assert len(pids) == 1 and str(os.getpid()) not in pids  # one worker process played them all
    # the calls of different episodes were in flight at the same time (not one after the other)
    most = max(sum(1 for s, e in calls if s <= t < e) for t, _ in calls)
    assert most >= 2


def test_two_workers_with_several_episodes_each(tmp_path):
    cfg = make_config(model=slow(0.05), runner__workers=2, runner__concurrency=6, runner__repeats=2)
    summary = run(cfg, tmp_path, plugins=PLUGINS)
    keys = [(r["task_id"], r["repeat"]) for r in lines(tmp_path)]
    assert len(keys) == 20 == len(set(keys)) and summary["complete"]


def test_a_dying_process_turns_its_in_flight_episodes_into_errors_redone_on_resume(tmp_path):
    cfg = make_config(model=slow(0.2), runner__concurrency=3, env__params={"crash_on": "near-2"})
    summary = run(cfg, tmp_path, plugins=PLUGINS)
    recs = {r["task_id"]: r for r in lines(tmp_path)}
    assert len(recs) == 10
    errors = {k for k, r in recs.items() if r["status"] == "error"}
    assert "near-2" in errors and all("exit code 3" in recs[k]["error"] for k in errors)
    assert len(errors) >= 2  # the episodes in flight next to it died with the process
    assert summary["n_finished"] == 10 - len(errors)
    # resume: the lost episodes are played again (near-2 crashes again, alone now), the rest are kept
    one_at_a_time = make_config(model=slow(0.2), runner__workers=2, runner__concurrency=1,
                                env__params={"crash_on": "near-2"})  # one worker process, one slot
    again = run(one_at_a_time, tmp_path, plugins=PLUGINS)
    recs2 = {r["task_id"]: r for r in lines(tmp_path)}
    assert len(lines(tmp_path)) == 10 == len(recs2)
    assert {k for k, r in recs2.items() if r["status"] == "error"} == {"near-2"}
    assert again["n_finished"] == 9


def test_an_episode_stuck_in_the_env_is_killed_at_the_timeout(tmp_path):
    cfg = make_config(runner__concurrency=2, runner__episode_timeout_s=1.0, limit=2, env__params={"sleep_s": 3.0})
    summary = run(cfg, tmp_path, plugins=PLUGINS)
    recs = lines(tmp_path)
    assert len(recs) == 2 and all(r["status"] == "error" and "episode_timeout_s=1.0" in r["error"] for r in recs)
    assert summary["overall"]["error_episodes"] == 2


def test_an_episode_waiting_too_long_for_its_model_is_dropped_without_killing_the_others(tmp_path):
    log = tmp_path / "calls.log"
    cfg = make_config(model=slow(3.0, str(log)), runner__concurrency=2, runner__episode_timeout_s=0.5, limit=2)
    run(cfg, tmp_path / "run", plugins=PLUGINS)
    recs = lines(tmp_path / "run")
    assert len(recs) == 2
    assert all(r["status"] == "error" and "waiting for the model" in r["error"] for r in recs)


def test_kill_9_of_an_in_flight_run_loses_nothing_finished(tmp_path):
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", PYTHONPATH=str(FIXTURE_DIR))
    cmd = [sys.executable, "-m", "eb_core.cli", "run", "env=corridor", "model=scripted-oracle",
           "+env.params.sleep_s=0.05", "runner.quiet=true", "runner.repeats=2", "runner.concurrency=4",
           f"hydra.run.dir={tmp_path}"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 90
    path = tmp_path / "episodes.jsonl"
    while time.time() < deadline:
        if path.exists() and len(path.read_text().splitlines()) >= 6:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = RunFiles(tmp_path).load_episodes()
    assert 6 <= len(before) < 20
    # its worker process notices and exits (no orphan holding envs, writing on)
    def orphans():
        out = []
        for d in Path("/proc").iterdir():
            try:
                if d.name.isdigit() and str(tmp_path).encode() in (d / "cmdline").read_bytes():
                    out.append(d.name)
            except OSError:
                pass
        return out
    deadline = time.time() + 20
    while orphans() and time.time() < deadline:
        time.sleep(0.1)
    assert not orphans()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    after = [(r["task_id"], r["repeat"]) for r in lines(tmp_path)]
    assert after[: len(before)] == [r.key for r in before]
    assert len(after) == 20 == len(set(after))
