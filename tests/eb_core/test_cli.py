"""The `eb` command as a user types it (real subprocesses, real files)."""

import csv
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

FIXTURE_DIR = Path(__file__).parent


def eb(*args, cwd=None, timeout=120):
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1",
               PYTHONPATH=str(FIXTURE_DIR))
    return subprocess.run([sys.executable, "-m", "eb_core.cli", *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=timeout)


def one_error_line(result):
    assert result.returncode == 2, (result.stdout, result.stderr)
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("eb: error: ")
    return lines[0]


def test_run_and_report(tmp_path):
    r = eb("run", "env=corridor", "model=scripted-oracle", "subset=far", "runner.quiet=true", f"hydra.run.dir={tmp_path}/a")
    assert r.returncode == 0, r.stderr
    assert "success rate: 100.0% (5 of 5 episodes succeeded; partial: 5 of 10 tasks)" in r.stdout
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert list(summary["subsets"]) == ["far"]
    assert (tmp_path / "a" / ".hydra" / "config.yaml").exists()
    r = eb("run", "env=corridor", "model=scripted-garbage", "limit=2", "runner.quiet=true", f"hydra.run.dir={tmp_path}/b")
    assert "success rate: 0.0% (0 of 2 episodes succeeded; partial: 2 of 10 tasks)" in r.stdout
    md = eb("report", str(tmp_path / "a"), str(tmp_path / "b"), "--format", "markdown")
    assert md.returncode == 0, md.stderr
    assert "| corridor | scripted-oracle | none | 100.0 |" in md.stdout
    c = eb("report", str(tmp_path / "a"), str(tmp_path / "b"), "--format", "csv", "--out", str(tmp_path / "t.csv"))
    rows = list(csv.reader(io.StringIO((tmp_path / "t.csv").read_text())))
    assert rows[0][:4] == ["env", "model", "ablation", "avg"] and len(rows) == 3 and c.returncode == 0
    rich = eb("report", str(tmp_path / "a"))
    assert "Success rate" in rich.stdout and "100.0" in rich.stdout


def test_default_run_dir_names_env_model_ablation_and_resumes(tmp_path):
    args = ("run", "env=corridor", "model=scripted-oracle", "ablation=no_feedback", "limit=2", "runner.quiet=true")
    assert eb(*args, cwd=tmp_path).returncode == 0
    d = tmp_path / "runs" / "corridor" / "scripted-oracle" / "no_feedback" / "default"
    assert len((d / "episodes.jsonl").read_text().splitlines()) == 2
    again = eb(*args, cwd=tmp_path)
    assert again.returncode == 0 and len((d / "episodes.jsonl").read_text().splitlines()) == 2


def test_multirun_sweep(tmp_path):
    r = eb("run", "-m", "env=corridor", "model=scripted-oracle", "ablation=none,no_feedback", "limit=1",
           "runner.quiet=true", f"hydra.sweep.dir={tmp_path}")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "corridor" / "scripted-oracle").iterdir()) == ["no_feedback", "none"]


def test_cfg_job_shows_the_resolved_config():
    r = eb("run", "env=corridor", "model=scripted-oracle", "ablation=language_only", "--cfg", "job")
    assert r.returncode == 0 and "language_only: true" in r.stdout and "name: corridor" in r.stdout


@pytest.mark.parametrize("args,expected", [
    (("run", "env=corridr"), "unknown env 'corridr'; available: corridor. Did you mean 'corridor'?"),
    (("run", "env=corridor", "model=gpt-5"), "unknown model 'gpt-5'; available:"),
    (("run", "env=corridor", "model=scripted-oracle", "limt=3"), "unknown config key 'limt'"),
    (("run", "env=corridor", "model=scripted-oracle", "planner.n_shot=many"), "invalid config value for 'planner.n_shot'"),
    (("run", "env=corridor", "model=scripted-oracle", "ablation=no_feedbak"), "Did you mean 'no_feedback'?"),
    (("run", "env=corridor", "model=scripted-oracle", "subset=middle", "hydra.run.dir=/tmp/eb-sub"),
     "unknown subset 'middle' for env 'corridor'; available: near, far"),
    (("rnu",), "unknown command 'rnu'"),
    (("run", "env=corridor", "model=scripted-oracle", "+model.api_key=sk-live-123"), "refusing 'model.api_key=...'"),
    (("report", "/nonexistent/run"), "is not a run directory"),
    (("tasks", "generate", "env=corridor"), "ships no task generator"),
])
def test_bad_input_gives_one_clear_line(args, expected):
    line = one_error_line(eb(*args))
    assert expected in line


def test_model_fatal_error_is_one_line_and_nothing_is_written(tmp_path):
    r = eb("run", "env=corridor", "model=scripted-oracle", "+model.fail=auth", f"hydra.run.dir={tmp_path}")
    assert "authentication failed" in one_error_line(r)
    assert not (tmp_path / "episodes.jsonl").exists()


def test_list_shows_components_with_their_plugins():
    r = eb("list")
    assert r.returncode == 0, r.stderr
    for text in ("corridor", "fixture_plugin", "near (5)", "scripted-oracle", "vlm", "detection_boxes",
                 "success_rate", "no_feedback", "language_only"):
        assert text in r.stdout, text
