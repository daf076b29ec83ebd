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
from eb_core.model import Usage
from eb_core.plugins import Registry, get_plugin_manager
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


def test_sample_draws_k_tasks_of_every_subset_seeded_and_independent():
    tasks = fixture_plugin.CorridorEnv.load_tasks()  # near-0..4, far-0..4
    picks = [select_tasks(tasks, make_config(sample=2, seed=s)) for s in range(40)]
    for got in picks:
        assert [t.subset for t in got] == ["near", "near", "far", "far"]  # two per subset, in file order
    assert select_tasks(tasks, make_config(sample=2, seed=7)) == picks[7]  # the same seed, the same sample
    seen = {t.id for got in picks for t in got}
    assert seen == {t.id for t in tasks}  # every task can be drawn
    # the subsets are drawn independently: the same positions in both is the exception, not the rule
    same = sum([t.id[-1] for t in got[:2]] == [t.id[-1] for t in got[2:]] for got in picks)
    assert same < 15
    assert [t.id for t in select_tasks(tasks, make_config(sample=9, subset="far"))] == [f"far-{i}" for i in range(5)]
    with pytest.raises(ConfigError, match="sample=2 and limit=3 both choose"):
        select_tasks(tasks, make_config(sample=2, limit=3))


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
    import socket
    assert {r["node"] for r in recs} == {socket.gethostname()}  # where each episode ran (a Ray node id on Ray)


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
    """A real `eb run` with two repeats killed with SIGKILL in the middle of its second repeat, then the same
    command again: nothing finished is lost or redone, and the dead run's lock does not block the new one."""
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", PYTHONPATH=str(FIXTURE_DIR))
    cmd = [sys.executable, "-m", "eb_core.cli", "run", "env=corridor", "model=scripted-oracle",
           "+env.params.sleep_s=0.1", "runner.quiet=true", "runner.repeats=2", f"hydra.run.dir={tmp_path}"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 90
    while time.time() < deadline:
        if (tmp_path / "episodes.jsonl").exists() and len((tmp_path / "episodes.jsonl").read_text().splitlines()) >= 12:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = RunFiles(tmp_path).load_episodes()
    assert 12 <= len(before) < 20 and {r.repeat for r in before} == {0, 1}  # killed mid-repeat 1
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    after = [(r["task_id"], r["repeat"]) for r in lines(tmp_path)]
    assert after[: len(before)] == [r.key for r in before]
    assert len(after) == 20 == len(set(after))
    assert "success rate: 100.0% (20 of 20 episodes succeeded)" in done.stdout
    assert sorted(p.name for p in (tmp_path / "episodes").iterdir()) == sorted(
        t if r == 0 else f"{t}_repeat{r}" for t, r in after)


def test_a_hung_episode_is_killed_at_the_timeout(tmp_path):
    cfg = make_config(runner__workers=2, runner__episode_timeout_s=1.0, limit=2, env__params={"sleep_s": 3.0})
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    recs = lines(tmp_path)
    assert len(recs) == 2 and all(r["status"] == "error" and "episode_timeout_s=1.0" in r["error"] for r in recs)
    assert summary["overall"]["error_episodes"] == 2


# -- repeats -----------------------------------------------------------------------------------------

RANDOM = {"name": "random", "backend": "random", "min_plan": 1, "max_plan": 3}


class SafeCorridor(fixture_plugin.CorridorEnv):
    """The corridor without its `explode` action, so random plans never crash the env."""

    name = "safe-corridor"

    def action_space(self):
        from eb_core import DiscreteActionSpace

        return DiscreteActionSpace(actions=fixture_plugin.ACTIONS[:3])


class PricedPreflight(fixture_plugin.ScriptedBackend):
    """The scripted backend whose preflight call costs 0.02 USD."""

    def preflight(self):
        return Usage(prompt_tokens=9, completion_tokens=1, cost_usd=0.02, calls=1)


# This test module is itself a plugin (workers import it by name): one env and one backend more.
@fixture_plugin.hookimpl
def eb_register_envs():
    from eb_core import EnvSpec

    return [EnvSpec(name="safe-corridor", entry_point=f"{__name__}:SafeCorridor", subsets={"near": 5, "far": 5})]


@fixture_plugin.hookimpl
def eb_register_model_backends():
    from eb_core import ModelBackendSpec

    return [ModelBackendSpec(name="priced", entry_point=f"{__name__}:PricedPreflight", description="test")]


def _random_plugins():
    import eb_models.plugin  # the real seeded `random` baseline

    return [fixture_plugin, eb_models.plugin, sys.modules[__name__]]


def _random_config(**over):
    return make_config(model=RANDOM, env__name="safe-corridor", **over)


def outcome(rs):
    return sorted((r["task_id"], r["repeat"], r["seed"], r["success"], r["env_steps"], r["invalid_actions"])
                  for r in rs)


def test_repeat_zero_keeps_the_single_run_seed():
    import hashlib

    legacy = int.from_bytes(hashlib.sha256(b"0:near-0").digest()[:4], "little")
    assert episode_seed(0, "near-0") == episode_seed(0, "near-0", 0) == legacy
    seeds = {episode_seed(0, "near-0", r) for r in range(5)}
    assert len(seeds) == 5


def test_repeats_with_the_seeded_random_backend_reproduce_exactly(tmp_path):
    cfg = _random_config(runner__repeats=3)
    a = run(cfg, tmp_path / "a", plugins=_random_plugins())
    b = run(_random_config(runner__repeats=3, runner__workers=2), tmp_path / "b",
            plugins=_random_plugins())
    ra, rb = lines(tmp_path / "a"), lines(tmp_path / "b")
    assert len(ra) == 30 and outcome(ra) == outcome(rb)  # independent of order and worker count
    assert all(r["seed"] == episode_seed(0, r["task_id"], r["repeat"]) for r in ra)
    # the repeats really differ (new seeds), so the between-repeat spread is measured
    by_repeat = {k: sorted((r["task_id"], r["env_steps"], r["success"]) for r in ra if r["repeat"] == k)
                 for k in range(3)}
    assert by_repeat[0] != by_repeat[1] != by_repeat[2]
    for s in (a, b):
        ci = s["overall"]["success_rate_ci"]
        assert s["repeats"] == 3 and s["n_episodes"] == 30 and s["complete"]
        assert ci["repeats"] == 3 and ci["tasks"] == 10 and ci["repeat_sd"] is not None
        assert ci["ci_low"] <= s["overall"]["success_rate"] <= ci["ci_high"]
    assert a["overall"]["success_rate_ci"] == b["overall"]["success_rate_ci"]
    assert (tmp_path / "a" / "episodes" / "near-0_repeat2" / "steps.jsonl").exists()
    # repeat 0 of a three-repeat run is exactly a single-repeat run
    single = run(_random_config(), tmp_path / "c", plugins=_random_plugins())
    assert outcome(lines(tmp_path / "c")) == [o for o in outcome(ra) if o[1] == 0]
    assert single["overall"]["success_rate_ci"]["ci_method"] == "wilson"


def test_more_repeats_extend_a_finished_run(tmp_path):
    run(_random_config(), tmp_path, plugins=_random_plugins())
    first = lines(tmp_path)
    summary = run(_random_config(runner__repeats=2), tmp_path, plugins=_random_plugins())
    recs = lines(tmp_path)
    assert recs[:10] == first and [r["repeat"] for r in recs[10:]] == [1] * 10
    assert summary["n_finished"] == 20 and summary["complete"]


def test_summary_has_intervals_per_subset_and_the_paper_subgoal_rate(tmp_path):
    # an empty plan ends the episode; the original then records progress 0
    answers = [json.dumps({"executable_plan": [{"action_id": 1}]}), json.dumps({"executable_plan": []})]
    cfg = make_config(model={"name": "s", "backend": "scripted", "answers": answers}, subset="far", limit=2)
    summary = run(cfg, tmp_path, plugins=[fixture_plugin])
    far = summary["subsets"]["far"]
    for key in ("success_rate", "subgoal_success", "subgoal_success_paper"):
        ci = far[f"{key}_ci"]
        assert ci["ci_low"] <= far[key] <= ci["ci_high"] and ci["tasks"] == 2
    assert "subgoal_success_paper" in summary["overall"]


def test_subset_alias_selects_the_subset():
    tasks = fixture_plugin.CorridorEnv.load_tasks()
    cfg = make_config(subset="distant", env__subset_aliases={"distant": "far"})
    assert [t.subset for t in select_tasks(tasks, cfg)] == ["far"] * 5
    with pytest.raises(ConfigError, match="unknown subset 'middle'.*aliases distant"):
        select_tasks(tasks, make_config(subset="middle", env__subset_aliases={"distant": "far"}))


# -- the preflight call's cost -------------------------------------------------------------------------


def test_the_preflight_cost_counts_in_the_budget_and_the_summary(tmp_path):
    registry = Registry(get_plugin_manager(plugins=[fixture_plugin, sys.modules[__name__]]))
    cfg = make_config(model={"name": "p", "backend": "priced", "oracle": True, "cost_per_call": 0.01,
                             "max_cost_usd": 0.045})
    summary = run(cfg, tmp_path, registry=registry)
    # 0.02 (preflight) + 2 episodes x 0.01 = 0.04; the third call reaches 0.05 and stops the run
    assert summary["n_finished"] == 2 and summary["stopped_early"].startswith("budget")
    assert summary["preflight"] == {"calls": 1, "prompt_tokens": 9, "completion_tokens": 1, "cost_usd": 0.02}
    assert summary["total_cost_usd"] == pytest.approx(0.04)
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk["total_cost_usd"] == pytest.approx(0.04)


def test_a_preflight_costing_the_whole_budget_plays_nothing(tmp_path):
    registry = Registry(get_plugin_manager(plugins=[fixture_plugin, sys.modules[__name__]]))
    cfg = make_config(model={"name": "p", "backend": "priced", "oracle": True, "max_cost_usd": 0.02})
    summary = run(cfg, tmp_path, registry=registry)
    assert summary["n_finished"] == 0 and summary["stopped_early"].startswith("budget")
