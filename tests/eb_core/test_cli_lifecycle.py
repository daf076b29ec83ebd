"""`eb run` as a new user meets it (issue #28): failed runs, run folders, sweeps, signals, misnamed failures.

Every test drives the real `eb` command in a subprocess, with the corridor fixture world and a second fixture
plugin written here (a world with a second task set and a task generator, and a world that ships no YAML).
"""

from __future__ import annotations

import glob
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

FIXTURE_DIR = Path(__file__).parent

PLUGIN = '''
import sys
from pathlib import Path

import fixture_plugin
from eb_core import EnvSpec, hookimpl


class HallEnv(fixture_plugin.CorridorEnv):
    """The corridor with a second task set, ``hard`` (its first four tasks)."""

    @classmethod
    def load_tasks(cls, taskset="classic", **params):
        tasks = fixture_plugin.CorridorEnv.load_tasks(**params)
        return tasks if taskset == "classic" else tasks[:4]


def generate(n=3, out="tasks.json", progress=False):
    for i in range(int(n)):
        if progress:
            print(f"task {i + 1} of {n} drawn")
    return f"wrote {n} tasks to {out}"


@hookimpl
def eb_register_envs():
    return [EnvSpec(name="hall", entry_point="lifecycle_plugin:HallEnv", subsets={"near": 5, "far": 5},
                    tasksets=("classic", "hard"), task_generator="lifecycle_plugin:generate"),
            EnvSpec(name="noyaml", entry_point="fixture_plugin:CorridorEnv", subsets={"near": 5})]


@hookimpl
def eb_config_searchpath():
    return ["file://" + str(Path(__file__).parent / "lifecycle_conf")]
'''

HALL_YAML = """name: hall
max_steps: 10
max_invalid_actions: 4
replan_on_failure: true
empty_plan_ends: true
default_n_shot: 2
resolution: 64
multi_view: false
params: {}
"""


@pytest.fixture
def plugin_dir(tmp_path):
    d = tmp_path / "plugin"
    (d / "lifecycle_conf" / "env").mkdir(parents=True)
    (d / "lifecycle_plugin.py").write_text(PLUGIN)
    (d / "lifecycle_conf" / "env" / "hall.yaml").write_text(HALL_YAML)
    return d


def _env(plugin_dir: Path | None = None) -> dict[str, str]:
    paths = [str(FIXTURE_DIR)] + ([str(plugin_dir)] if plugin_dir else [])
    plugins = "fixture_plugin" + (",lifecycle_plugin" if plugin_dir else "")
    return dict(os.environ, EB_PLUGINS=plugins, EB_DISABLE_PLUGIN_AUTOLOAD="1", PYTHONPATH=os.pathsep.join(paths))


def eb(*args, cwd, plugin_dir=None, timeout=120, env=None):
    return subprocess.run([sys.executable, "-m", "eb_core", *args], capture_output=True, text=True, cwd=cwd,
                          env={**_env(plugin_dir), **(env or {})}, timeout=timeout)


def one_error_line(r) -> str:
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(lines) == 1 and lines[0].startswith("eb: error: "), (r.returncode, r.stderr)
    return lines[0]


RUN = ("run", "env=corridor", "model=scripted-oracle", "--quiet")


# -- 1. a failed run leaves nothing that breaks `eb report runs/*/*/*/default` --------------------------------


def test_a_failed_run_leaves_no_folder_and_the_readme_glob_keeps_working(tmp_path):
    bad = eb(*RUN, "+model.fail=auth", cwd=tmp_path)
    assert "authentication failed" in one_error_line(bad)
    assert not (tmp_path / "runs").exists()  # no empty run folder, no empty parents
    bad_env = eb(*RUN, "+env.params.crash_on=nonsense", "model.name=other", cwd=tmp_path)
    assert bad_env.returncode in (0, 2)
    ok = eb(*RUN, "limit=2", cwd=tmp_path)
    assert ok.returncode == 0, ok.stderr
    # a folder left by an older version (config only, no episodes) is skipped with one note
    stale = tmp_path / "runs" / "corridor" / "stale-model" / "none" / "default"
    stale.mkdir(parents=True)
    (stale / "config.yaml").write_text("env: {name: corridor}\n")
    dirs = sorted(glob.glob(str(tmp_path / "runs" / "*" / "*" / "*" / "default")))
    rep = eb("report", *dirs, "--format", "markdown", cwd=tmp_path)
    assert rep.returncode == 0 and "| corridor | scripted-oracle | none |" in rep.stdout, rep.stderr
    assert "skipped" in rep.stderr and "stale-model" in rep.stderr


def test_a_failure_after_episodes_finished_keeps_the_folder(tmp_path):
    run_dir = tmp_path / "r"
    assert eb(*RUN, "limit=2", f"hydra.run.dir={run_dir}", cwd=tmp_path).returncode == 0
    bad = eb(*RUN, "limit=3", "+model.fail=auth", f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert bad.returncode == 2 and len((run_dir / "episodes.jsonl").read_text().splitlines()) == 2


# -- 2. run folders: the selection is part of a run's identity; partial runs; task sets -------------------------


def test_a_different_selection_in_the_same_folder_is_refused_naming_the_key(tmp_path):
    d = f"hydra.run.dir={tmp_path / 'r'}"
    assert eb(*RUN, "subset=near", "limit=3", d, cwd=tmp_path).returncode == 0
    line = one_error_line(eb(*RUN, "subset=far", "limit=3", d, cwd=tmp_path))
    assert "subset=near, this one has subset=far" in line and "experiment=" in line
    line = one_error_line(eb(*RUN, "subset=near", "limit=2", d, cwd=tmp_path))
    assert "limit=3, this one has limit=2" in line
    more = eb(*RUN, "subset=near", "limit=5", d, cwd=tmp_path)  # a larger limit extends the same run
    assert more.returncode == 0 and "resuming: 3 of 5 episodes already done" in more.stdout
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["partial"] is True and summary["n_selected"] == 5 and summary["n_tasks_total"] == 10
    assert "partial: 5 of 10 tasks" in more.stdout


def test_limit_takes_the_first_tasks_subset_by_subset(tmp_path):
    r = eb(*RUN, "limit=7", f"hydra.run.dir={tmp_path / 'r'}", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ids = [json.loads(x)["task_id"] for x in (tmp_path / "r" / "episodes.jsonl").read_text().splitlines()]
    assert ids == ["near-0", "near-1", "near-2", "near-3", "near-4", "far-0", "far-1"]


def test_sample_plays_k_random_tasks_per_subset_and_is_part_of_the_runs_identity(tmp_path):
    d = f"hydra.run.dir={tmp_path / 'r'}"
    r = eb(*RUN, "sample=2", "seed=3", d, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ids = [json.loads(x)["task_id"] for x in (tmp_path / "r" / "episodes.jsonl").read_text().splitlines()]
    assert sorted(i.split("-")[0] for i in ids) == ["far", "far", "near", "near"]
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["partial"] is True and summary["selection"]["sample"] == 2 and summary["n_selected"] == 4
    line = one_error_line(eb(*RUN, "sample=3", "seed=3", d, cwd=tmp_path))
    assert "sample=2, this one has sample=3" in line
    again = eb(*RUN, "sample=2", "seed=3", f"hydra.run.dir={tmp_path / 'again'}", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert [json.loads(x)["task_id"] for x in (tmp_path / "again" / "episodes.jsonl").read_text().splitlines()] \
        == ids  # the same seed draws the same tasks
    line = one_error_line(eb(*RUN, "sample=2", "limit=3", f"hydra.run.dir={tmp_path / 'x'}", cwd=tmp_path))
    assert "sample=2 and limit=3 both choose" in line


def test_tasksets_and_slashed_model_names_each_get_one_directory_level(tmp_path, plugin_dir):
    hard = eb("run", "env=hall", "model=scripted-oracle", "taskset=hard", "--quiet", cwd=tmp_path,
              plugin_dir=plugin_dir)
    assert hard.returncode == 0, hard.stderr
    classic = eb("run", "env=hall", "model=scripted-oracle", "limit=2", "model.name=org/model-7b", "--quiet",
                 cwd=tmp_path, plugin_dir=plugin_dir)
    assert classic.returncode == 0, classic.stderr
    found = sorted(str(Path(p).relative_to(tmp_path)) for p in glob.glob(str(tmp_path / "runs/*/*/*/default")))
    assert found == ["runs/hall-hard/scripted-oracle/none/default", "runs/hall/org--model-7b/none/default"]
    assert len((tmp_path / found[0] / "episodes.jsonl").read_text().splitlines()) == 4
    listing = eb("list", cwd=tmp_path, plugin_dir=plugin_dir)
    assert "classic, hard" in listing.stdout


# -- 4. eb tasks generate shows progress on stderr ----------------------------------------------------------------


def test_tasks_generate_prints_progress_on_stderr_and_the_result_on_stdout(tmp_path, plugin_dir):
    r = eb("tasks", "generate", "env=hall", "n=3", "out=my.json", cwd=tmp_path, plugin_dir=plugin_dir)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "wrote 3 tasks to my.json"
    assert "task 1 of 3 drawn" in r.stderr and "task 3 of 3 drawn" in r.stderr and "done in" in r.stderr


# -- 5. sweeps ------------------------------------------------------------------------------------------------------


def test_a_sweep_goes_on_past_a_failed_job_and_ends_with_a_table(tmp_path):
    r = eb("run", "-m", "env=corridor", "model=scripted-oracle,scripted-garbage", "+model.fail=auth,ok",
           "limit=2", "--quiet", cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    failed = [ln for ln in r.stderr.splitlines() if ln.startswith("eb: error: [job")]
    assert len(failed) == 2 and all("authentication failed" in ln for ln in failed)
    assert "2 of 4 sweep jobs failed" in r.stderr
    rows = [ln for ln in r.stdout.splitlines() if "│ corridor" in ln]
    assert "Sweep: 4 jobs" in r.stdout and len(rows) == 4
    assert sum("│ failed: authentication" in ln for ln in rows) == 2 and sum("│ complete" in ln for ln in rows) == 2
    found = sorted(glob.glob(str(tmp_path / "runs" / "*" / "*" / "*" / "default")))
    assert [Path(p).parts[-3] for p in found] == ["scripted-garbage", "scripted-oracle"]


def test_a_sweep_value_without_m_is_one_line(tmp_path):
    line = one_error_line(eb(*RUN, "ablation=none,no_feedback", cwd=tmp_path))
    assert "ablation has several values (a sweep): add -m" in line


# -- 7. failures named as what they are -----------------------------------------------------------------------------


def test_sigterm_ends_with_one_line_and_keeps_finished_episodes(tmp_path):
    run_dir = tmp_path / "r"
    proc = subprocess.Popen([sys.executable, "-m", "eb_core", *RUN, "+env.params.sleep_s=0.2",
                             f"hydra.run.dir={run_dir}"], env=_env(), cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while time.time() < deadline and not ((run_dir / "episodes.jsonl").exists()
                                          and (run_dir / "episodes.jsonl").read_text().strip()):
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _out, err = proc.communicate(timeout=60)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert proc.returncode == 143 and lines == ["eb: error: terminated (SIGTERM); finished episodes are saved, "
                                                "re-run the same command to resume"], err
    assert (run_dir / "episodes.jsonl").read_text().strip()


def test_a_missing_ray_cluster_is_named(tmp_path):
    pytest.importorskip("ray")
    r = eb(*RUN, "runner.executor=ray", "runner.ray_address=ray://127.0.0.1:9", f"hydra.run.dir={tmp_path / 'r'}",
           cwd=tmp_path, timeout=60)
    line = one_error_line(r)
    assert "cannot reach the Ray cluster at ray://127.0.0.1:9" in line and "cannot write" not in line
    assert not (tmp_path / "r").exists()


def test_an_env_without_its_yaml_is_named(tmp_path, plugin_dir):
    line = one_error_line(eb("run", "env=noyaml", cwd=tmp_path, plugin_dir=plugin_dir))
    assert "env 'noyaml' is installed (plugin lifecycle_plugin) but its config env/noyaml.yaml is missing" in line


def test_no_empty_eb_log(tmp_path):
    assert eb(*RUN, "limit=1", f"hydra.run.dir={tmp_path / 'r'}", cwd=tmp_path).returncode == 0
    assert not (tmp_path / "r" / "eb.log").exists()
    assert (tmp_path / "r" / ".hydra" / "config.yaml").exists()


def test_cfg_job_prints_the_config_that_runs(tmp_path):
    r = eb(*RUN, "limit=4", "--cfg", "job", cwd=tmp_path)
    assert r.returncode == 0 and "limit: 4" in r.stdout and "hydra" not in r.stdout
    assert not (tmp_path / "runs").exists()
    m = eb("run", "-m", "env=corridor", "model=scripted-oracle", "ablation=none,no_feedback", "--cfg", "job",
           "-p", "ablation", cwd=tmp_path)
    assert m.returncode == 0 and "name: none" in m.stdout and "name: no_feedback" in m.stdout


def test_a_sweep_through_a_hydra_launcher_lands_in_the_same_layout(tmp_path):
    """`hydra/launcher=NAME` hands the jobs to that launcher (Hydra's basic one here: Slurm and Ray launchers
    plug in the same way); each job is still composed by eb_core.compose and failures do not stop it."""
    r = eb("run", "-m", "hydra/launcher=basic", "env=corridor", "model=scripted-oracle", "ablation=none,no_feedback",
           "+model.fail=auth,ok", "limit=2", "--quiet", cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    assert "2 of 4 sweep jobs failed" in r.stderr and "Sweep: 4 jobs" in r.stdout
    found = sorted(Path(p).parts[-2] for p in glob.glob(str(tmp_path / "runs" / "*" / "*" / "*" / "default")))
    assert found == ["no_feedback", "none"]
    for name in found:
        d = tmp_path / "runs" / "corridor" / "scripted-oracle" / name / "default"
        assert len((d / "episodes.jsonl").read_text().splitlines()) == 2
