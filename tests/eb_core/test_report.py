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
from eb_core.paired import paired_rows, render_paired
from eb_core.report import load_run, render_report
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
    # the interval is McNemar's own (exact): it holds 0 because the test is not significant (issue #28, item 6)
    assert "| far | success_rate | 5 | 100.0 | 0.0 | -100.0 [-100.0, +4.4] | mcnemar-exact | 0.0625 | n.s." in text
    assert "| all | success_rate | 10 |" in text and "| significant |" in text


def test_paired_compares_overlapping_task_sets_on_the_shared_tasks(runs, tmp_path):
    rows = {(r["subset"], r["metric"]): r for r in paired_rows(load_run(runs / "short"), load_run(runs / "oracle"))}
    assert rows[("all", "success_rate")]["tasks"] == 3 and ("far", "success_rate") not in rows
    text = render_paired([str(runs / "short"), str(runs / "oracle")], "markdown", str(tmp_path / "p.md"))
    assert "Compared on the 3 tasks both runs played (0 only in A, 7 only in B, left out)." in text
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1", PYTHONPATH=str(FIXTURE_DIR))
    other = tmp_path / "far"
    run(make_config(subset="far"), other, plugins=[fixture_plugin])
    r = subprocess.run([sys.executable, "-m", "eb_core.cli", "report", str(runs / "short"), str(other),
                        "--paired"], capture_output=True, text=True, env=env, timeout=120)
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(lines) == 1 and "they share no task (A has 3, B 5)" in lines[0], r.stderr


def test_paired_interval_and_test_agree_on_every_row(runs):
    """One method per row: a row is significant exactly when its interval leaves out 0."""
    for a, b in (("oracle", "garbage"), ("short", "garbage"), ("oracle", "oracle2")):
        for r in paired_rows(load_run(runs / a), load_run(runs / b)):
            excludes_zero = r["ci_low"] > 0 or r["ci_high"] < 0
            assert excludes_zero == r["significant"] or r["ci_low"] == r["ci_high"] == r["diff"], r


def test_report_skips_folders_without_episodes_with_one_note(runs, tmp_path):
    empty = tmp_path / "failed"
    empty.mkdir()
    (empty / "config.yaml").write_text("env: {name: corridor}\n")  # what a run that failed at start leaves
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1", PYTHONPATH=str(FIXTURE_DIR))
    r = subprocess.run([sys.executable, "-m", "eb_core.cli", "report", str(runs / "oracle"), str(empty),
                        "--format", "markdown"], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0 and "| corridor | scripted-oracle | none | 100.0 |" in r.stdout, r.stderr
    assert r.stderr.strip() == f"eb report: note: skipped 1 folder(s) with no finished episodes: {empty}"
    alone = subprocess.run([sys.executable, "-m", "eb_core.cli", "report", str(empty)], capture_output=True,
                           text=True, env=env, timeout=120)
    assert alone.returncode == 2 and "is not a run directory" in alone.stderr


def test_partial_runs_are_marked(runs, tmp_path):
    summary = json.loads((runs / "short" / "summary.json").read_text())
    assert summary["partial"] is True and summary["n_selected"] == 3 and summary["n_tasks_total"] == 10
    assert json.loads((runs / "oracle" / "summary.json").read_text())["partial"] is False
    text = render_report([str(runs / "short")], "markdown", str(tmp_path / "s.md"))
    assert "| 3 (partial: 3 of 10 tasks) |" in text and "Partial runs" in text
    rows = list(csv.reader(io.StringIO(render_report([str(runs / "short")], "csv", str(tmp_path / "s.csv")))))
    assert dict(zip(rows[0], rows[1]))["partial"] == "true"


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
