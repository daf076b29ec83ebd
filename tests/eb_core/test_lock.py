"""One run per directory: an flock on run.lock, released by the kernel when its holder dies."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import fixture_plugin
from eb_core.records import RunDirLocked, RunLock

FIXTURE_DIR = Path(fixture_plugin.__file__).parent


def eb_run_cmd(run_dir, *extra):
    return [sys.executable, "-m", "eb_core.cli", "run", "env=corridor", "model=scripted-oracle",
            "runner.quiet=true", f"hydra.run.dir={run_dir}", *extra]


def cli_env():
    return dict(os.environ, EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1", PYTHONPATH=str(FIXTURE_DIR))


def wait_for_episodes(run_dir, n, proc, timeout=90):
    deadline = time.time() + timeout
    path = Path(run_dir) / "episodes.jsonl"
    while time.time() < deadline:
        if path.exists() and len(path.read_text().splitlines()) >= n:
            return
        assert proc.poll() is None, "the first run ended before it was caught in the act"
        time.sleep(0.05)
    raise AssertionError(f"no {n} episodes within {timeout}s")


def test_a_second_eb_run_in_the_same_directory_exits_at_once_naming_the_holder(tmp_path):
    first = subprocess.Popen(eb_run_cmd(tmp_path, "+env.params.sleep_s=1.0"), env=cli_env(),
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_for_episodes(tmp_path, 1, first)
        second = subprocess.run(eb_run_cmd(tmp_path), env=cli_env(), capture_output=True, text=True, timeout=120)
        assert second.returncode == 2, (second.stdout, second.stderr)
        err = [ln for ln in second.stderr.splitlines() if ln.strip()]
        assert len(err) == 1 and err[0].startswith("eb: error: ")
        assert f"{tmp_path} is in use by another eb run (pid {first.pid})" in err[0]
        assert first.poll() is None, "the first run ended too early to test the lock"
        assert (tmp_path / "run.lock").read_text().strip() == str(first.pid)
    finally:
        first.kill()
        first.wait()
    # the holder is gone (SIGKILL): its lock went with it
    with RunLock(tmp_path) as lock:
        assert (tmp_path / "run.lock").read_text().strip() == str(os.getpid()) and lock.fd is not None


def test_a_kill_9d_run_with_live_workers_does_not_block_the_next(tmp_path):
    """Forked workers close their copy of the lock, so the kernel drops it when the parent dies, even while
    orphaned workers are still finishing their episodes."""
    args = ("+env.params.sleep_s=0.2", "runner.workers=2")
    first = subprocess.Popen(eb_run_cmd(tmp_path, *args), env=cli_env(), stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    wait_for_episodes(tmp_path, 2, first)
    first.send_signal(signal.SIGKILL)
    first.wait()
    lock = RunLock(tmp_path).acquire()  # at once: no retry, no wait
    lock.release()
    done = subprocess.run(eb_run_cmd(tmp_path, *args), env=cli_env(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "success rate: 100.0% (10 of 10 episodes succeeded)" in done.stdout


def test_the_lock_is_exclusive_within_one_machine(tmp_path):
    with RunLock(tmp_path):
        with pytest.raises(RunDirLocked, match=rf"pid {os.getpid()}\)"):
            RunLock(tmp_path).acquire()
    RunLock(tmp_path).acquire().release()  # released on exit
