"""`eb report`: intervals in every table, paired comparisons, subset aliases, runs stopped before their end."""

import csv
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.cli import CliError
from eb_core.report import load_run, paired_rows, render_paired, render_report
from eb_core.runner import run

FIXTURE_DIR = Path(fixture_plugin.__file__).parent
GARBAGE = {"name": "scripted-garbage", "backend": "scripted", "answers": ["no plan here"]}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    run(make_config(), root / "oracle", plugins=[fixture_plugin])
    run(make_config(), root / "oracle2", plugins=[fixture_plugin])
    run(make_config(model=GARBAGE), root / "garbage", plugins=[fixture_plugin])
    run(make_config(limit=3), root / "short", plugins=[fixture_plugin])
    return root


def test_report_tables_carry_intervals(runs, tmp_path):
    text = render_report([str(runs / "oracle"), str(runs / "garbage")], "markdown", str(tmp_path / "r.md"))
    assert "| corridor | scripted-oracle | none | 100.0 | 100.0 [72.2, 100.0] |" in text  # Wilson on 10/10
    assert "0.0 [0.0, 27.8]" in text and "Subgoal success (%)" in text and "original's rule" in text
    rows = list(csv.reader(io.StringIO(render_report([str(runs / "oracle")], "csv", str(tmp_path / "r.csv")))))
    row = dict(zip(rows[0], rows[1]))
    assert row["success:all"] == "100.0" and row["success:all:ci_low"] == "72.2" and row["success:far:ci_low"] == "56.6"


def test_paired_identical_runs_are_not_significant(runs):
    rows = paired_rows(load_run(runs / "oracle"), load_run(runs / "oracle2"))
    assert {(r["subset"], r["metric"]) for r in rows} >= {("all", "success_rate"), ("far", "subgoal_success")}
    for r in rows:
        assert r["diff"] == 0 and not r["significant"] and r["p_value"] == 1.0


def test_paired_test_needs_enough_tasks(runs, tmp_path):
    rows = {(r["subset"], r["metric"]): r for r in paired_rows(load_run(runs / "oracle"), load_run(runs / "garbage"))}
    far, overall = rows[("far", "success_rate")], rows[("all", "success_rate")]
    # 5 of 5 tasks flipped: exact McNemar p = 2 / 2^5, not below 0.05; 10 of 10: significant
    assert far["test"] == "mcnemar-exact" and far["p_value"] == pytest.approx(0.0625) and not far["significant"]
    assert overall["p_value"] == pytest.approx(2 / 2 ** 10) and overall["significant"] and overall["diff"] == -1.0
    text = render_paired([str(runs / "oracle"), str(runs / "garbage")], "markdown", str(tmp_path / "p.md"))
    assert "| far | success_rate | 5 | 100.0 | 0.0 | -100.0 [-100.0, -100.0] | mcnemar-exact | 0.0625 | n.s." in text
    assert "| all | success_rate | 10 |" in text and "| significant |" in text


def test_paired_refuses_different_task_sets_in_one_line(runs):
    with pytest.raises(CliError, match=r"task sets differ \(only in B \(7\): near-3, near-4, far-0, far-1, \.\.\.\)"):
        render_paired([str(runs / "short"), str(runs / "oracle")])
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1", PYTHONPATH=str(FIXTURE_DIR))
    r = subprocess.run([sys.executable, "-m", "eb_core.cli", "report", str(runs / "oracle"), str(runs / "short"),
                        "--paired"], capture_output=True, text=True, env=env, timeout=120)
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(lines) == 1 and "only in A (7): near-3" in lines[0], r.stderr


def test_subset_aliases_merge_under_one_name(runs, tmp_path):
    """An older run that recorded the alias name is reported under the subset's real name."""
    old = tmp_path / "old"
    run(make_config(env__subset_aliases={"distant": "far"}), old, plugins=[fixture_plugin])
    text = (old / "episodes.jsonl").read_text().replace('"subset":"far"', '"subset":"distant"')
    (old / "episodes.jsonl").write_text(text)
    (old / "summary.json").unlink()
    assert list(load_run(old)["subsets"]) == ["near", "far"]
    table = render_report([str(runs / "oracle"), str(old)], "csv", str(tmp_path / "t.csv"))
    header = next(csv.reader(io.StringIO(table)))
    assert "success:far" in header and not any("distant" in h for h in header)


def test_a_run_stopped_before_its_end_is_reported_from_its_episodes(runs, tmp_path):
    cut = tmp_path / "cut"
    run(make_config(limit=4), cut, plugins=[fixture_plugin])
    (cut / "summary.json").unlink()  # as after a kill -9
    r = load_run(cut)
    assert (r["env"], r["model"], r["ablation"]) == ("corridor", "scripted-oracle", "none")
    assert r["overall"]["episodes"] == 4 and not r["complete"]
    assert "none (incomplete)" in render_report([str(cut)], "markdown", str(tmp_path / "c.md"))


def test_repeats_show_the_between_repeat_spread(tmp_path):
    answers = [json.dumps({"executable_plan": [{"action_id": 1}] * 2}), "nonsense"]  # alternating per call
    cfg = make_config(model={"name": "alt", "backend": "scripted", "answers": answers}, runner__repeats=2,
                      subset="near", env__max_steps=2)
    run(cfg, tmp_path, plugins=[fixture_plugin])
    r = load_run(tmp_path)
    ci = r["overall"]["success_rate_ci"]
    assert r["repeats"] == 2 and ci["repeats"] == 2 and ci["ci_method"] in ("cluster-bootstrap", "wilson")
    assert ci["repeat_sd"] is not None
    text = render_report([str(tmp_path)], "markdown", str(tmp_path / "r.md"))
    assert "| 2 |" in text
