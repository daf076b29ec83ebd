"""Runner: selection, resume, crash safety, workers, budget, summary."""

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
from eb_core.config import ConfigError
from eb_core.records import RunFiles
from eb_core.runner import RunError, episode_seed, run, select_tasks

FIXTURE_DIR = Path(fixture_plugin.__file__).parent


def lines(run_dir):
    return [json.loads(x) for x in (Path(run_dir) / "episodes.jsonl").read_text().splitlines()]


def test_subset_limit_and_task_selection():
    tasks = fixture_plugin.CorridorEnv.load_tasks()
    assert [t.id for t in select_tasks(tasks, make_config(subset="far", limit=2))] == ["far-0", "far-1"]
    assert [t.id for t in select_tasks(tasks, make_config(tasks=["near-3"]))] == ["near-3"]
    with pytest.raises(ConfigError, match="unknown subset 'middle'.*available: near, far"):
        select_tasks(tasks, make_config(subset="middle"))


def test_run_writes_summary_and_records(tmp_path):
    summary = run(make_config(), tmp_path, plugins=[fixture_plugin])
    assert summary["overall"]["success_rate"] == 1.0 and summary["n_finished"] == 10 and summary["complete"]
    assert set(summary["subsets"]) == {"near", "far"}
    assert summary["subsets"]["far"]["avg_env_steps"] == 5.0
    assert (tmp_path / "episodes" / "near-0" / "steps.jsonl").exists()
    assert "fixture_plugin" in json.loads((tmp_path / "plugins.json").read_text())
    assert (tmp_path / "config.yaml").read_text().startswith("env:")
    recs = lines(tmp_path)
    assert {r["task_id"] for r in recs} == {t.id for t in fixture_plugin.CorridorEnv.load_tasks()}
    assert all(r["seed"] == episode_seed(0, r["task_id"]) for r in recs)


def test_rerun_resumes_and_never_duplicates(tmp_path):
    run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    assert len(lines(tmp_path)) == 3
    summary = run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    assert len(lines(tmp_path)) == 3 and summary["n_finished"] == 3
    run(make_config(), tmp_path, plugins=[fixture_plugin])
    ids = [r["task_id"] for r in lines(tmp_path)]
    assert len(ids) == 10 == len(set(ids))


def test_a_different_config_in_the_same_dir_is_refused(tmp_path):
    run(make_config(limit=1), tmp_path, plugins=[fixture_plugin])
    with pytest.raises(RunError, match=r"differs in: planner.n_shot"):
        run(make_config(limit=1, planner__n_shot=0), tmp_path, plugins=[fixture_plugin])


def test_torn_last_line_is_dropped_and_redone(tmp_path):
    run(make_config(limit=2), tmp_path, plugins=[fixture_plugin])
    with open(tmp_path / "episodes.jsonl", "ab") as fh:
        fh.write(b'{"task_id": "near-2", "subs')  # a kill in the middle of a write
    run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    ids = [r["task_id"] for r in lines(tmp_path)]
    assert ids == ["near-0", "near-1", "near-2"]


def test_error_episodes_are_recorded_then_redone_on_resume(tmp_path):
    cfg = make_config(model={"name": "s", "backend": "scripted", "fail": "transient"})
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    assert summary["overall"]["error_episodes"] == 10 and summary["n_finished"] == 0
    assert all(r["status"] == "error" and "503" in r["error"] for r in lines(tmp_path))
    # the model is back: only the error episodes are redone, no duplicates
    ok = make_config(model={"name": "s", "backend": "scripted", "oracle": True})
    (tmp_path / "fingerprint.json").unlink()  # same experiment, fixed model settings
    summary = run(ok, tmp_path, plugins=[fixture_plugin])
    assert summary["n_finished"] == 10 and len(lines(tmp_path)) == 10


def test_fatal_model_error_fails_before_the_first_episode(tmp_path):
    cfg = make_config(model={"name": "s", "backend": "scripted", "fail": "auth"})
    with pytest.raises(RunError, match="authentication failed"):
        run(cfg, tmp_path, plugins=[fixture_plugin])
    assert not (tmp_path / "episodes.jsonl").exists()


def test_a_failed_start_does_not_lock_the_directory(tmp_path):
    bad = make_config(model={"name": "s", "backend": "scripted", "fail": "auth"})
    with pytest.raises(RunError):
        run(bad, tmp_path, plugins=[fixture_plugin])
    summary = run(make_config(limit=1), tmp_path, plugins=[fixture_plugin])  # different config, same dir
    assert summary["n_finished"] == 1


def test_budget_cap_stops_cleanly_with_finished_episodes_saved(tmp_path):
    cfg = make_config(model={"name": "s", "backend": "scripted", "oracle": True, "cost_per_call": 0.01,
                             "max_cost_usd": 0.035})
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    assert summary["stopped_early"].startswith("budget") and not summary["complete"]
    assert summary["n_finished"] == 3 and len(lines(tmp_path)) == 3
    assert not any(p.name.endswith(".partial") for p in (tmp_path / "episodes").iterdir() if p.name != "")


def test_workers_give_the_same_results_as_inline(tmp_path):
    a = run(make_config(), tmp_path / "a", plugins=[fixture_plugin])
    b = run(make_config(runner__workers=2), tmp_path / "b", plugins=[fixture_plugin])
    strip = lambda rs: sorted((r["task_id"], r["success"], r["env_steps"], r["seed"]) for r in rs)
    assert strip(lines(tmp_path / "a")) == strip(lines(tmp_path / "b"))
    assert a["overall"]["success_rate"] == b["overall"]["success_rate"]


def test_a_crashed_worker_marks_its_episode_error_and_the_run_goes_on(tmp_path):
    cfg = make_config(runner__workers=2, env__params={"crash_on": "near-2"})
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    recs = {r["task_id"]: r for r in lines(tmp_path)}
    assert len(recs) == 10
    assert recs["near-2"]["status"] == "error" and "exit code 3" in recs["near-2"]["error"]
    assert summary["n_finished"] == 9 and summary["overall"]["error_episodes"] == 1


def test_kill_9_loses_nothing_finished_and_resume_completes(tmp_path):
    """A real `eb run` killed with SIGKILL mid-run, then the same command again."""
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", PYTHONPATH=str(FIXTURE_DIR))
    cmd = [sys.executable, "-m", "eb_core.cli", "run", "env=corridor", "model=scripted-oracle",
           "+env.params.sleep_s=0.15", "runner.quiet=true", f"hydra.run.dir={tmp_path}"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while time.time() < deadline:
        if (tmp_path / "episodes.jsonl").exists() and len((tmp_path / "episodes.jsonl").read_text().splitlines()) >= 3:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = RunFiles(tmp_path).load_episodes()
    assert 3 <= len(before) < 10
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    after = [r["task_id"] for r in lines(tmp_path)]
    assert after[: len(before)] == [r.task_id for r in before]
    assert len(after) == 10 == len(set(after))
    assert "success rate: 100.0% (10/10 episodes)" in done.stdout


def test_a_hung_episode_is_killed_at_the_timeout(tmp_path):
    cfg = make_config(runner__workers=2, runner__episode_timeout_s=1.0, limit=2, env__params={"sleep_s": 3.0})
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    recs = lines(tmp_path)
    assert len(recs) == 2 and all(r["status"] == "error" and "episode_timeout_s=1.0" in r["error"] for r in recs)
    assert summary["overall"]["error_episodes"] == 2
