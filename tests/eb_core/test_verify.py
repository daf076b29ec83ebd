"""`eb verify` on the corridor fixture world (in-process): the checks one by one."""

from __future__ import annotations

import json
from pathlib import Path

import fixture_plugin
import pytest
from eb_core_testutil import make_config

from eb_core.runner import run
from eb_core.verify import cmd_verify, verify_run


@pytest.fixture
def run_dir(tmp_path) -> Path:
    run(make_config(limit=4), tmp_path / "run", plugins=[fixture_plugin])
    return tmp_path / "run"


def check(run_dir: Path):
    return verify_run(run_dir, plugins=[fixture_plugin])


def test_a_fresh_run_verifies(run_dir):
    res = check(run_dir)
    assert res.ok and res.episodes == 4 and res.warnings == []


def test_a_run_without_manifest_verifies_with_a_warning(run_dir):
    (run_dir / "manifest.json").unlink()
    res = check(run_dir)
    assert res.ok and res.episodes == 4
    assert len(res.warnings) == 1 and "has no manifest.json (made before format version 1)" in res.warnings[0]


def test_an_edited_config_is_a_mismatch(run_dir):
    path = run_dir / "config.yaml"
    path.write_text(path.read_text().replace("max_cost_usd: null", "max_cost_usd: 5.0"))
    assert check(run_dir).mismatches == [
        "manifest: config.yaml differs from the config the run was made with (config digest mismatch)"]


def _edit_record(run_dir: Path, i: int, **changes) -> str:
    path = run_dir / "episodes.jsonl"
    lines = [json.loads(x) for x in path.read_text().splitlines()]
    lines[i].update(changes)
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return lines[i]["task_id"]


def test_edited_counts_are_mismatches(run_dir):
    steps = json.loads((run_dir / "episodes.jsonl").read_text().splitlines()[1])["env_steps"]
    task = _edit_record(run_dir, 1, env_steps=steps + 1, end_reason="max_steps")
    lines = check(run_dir).mismatches
    assert [ln for ln in lines if not ln.startswith("summary.json")] == [
        f"{task}: end_reason recorded 'max_steps', replay 'success'",
        f"{task}: env_steps recorded {steps + 1}, replay {steps}"]
    # the summary was computed from the true records
    assert lines[2].startswith("summary.json: overall avg_env_steps recorded ")


def test_a_changed_seed_is_a_mismatch(run_dir):
    task = _edit_record(run_dir, 0, seed=12345)
    [line] = check(run_dir).mismatches
    assert line.startswith(f"{task}: seed recorded 12345, the run seed gives ")


def test_a_duplicated_episode_is_a_mismatch(run_dir):
    path = run_dir / "episodes.jsonl"
    first = path.read_text().splitlines()[0]
    path.write_text(path.read_text() + first + "\n")
    lines = check(run_dir).mismatches
    assert f"{json.loads(first)['task_id']}: recorded twice in episodes.jsonl" in lines


def test_a_broken_step_line_is_a_mismatch_naming_file_and_line(run_dir):
    task = json.loads((run_dir / "episodes.jsonl").read_text().splitlines()[0])["task_id"]
    steps = run_dir / "episodes" / task / "steps.jsonl"
    steps.write_text(steps.read_text() + "{not json\n")
    [line] = check(run_dir).mismatches
    assert line.startswith(f"{task}: {steps} line 2 is not a step record")


def test_missing_step_files_are_a_mismatch(run_dir):
    task = json.loads((run_dir / "episodes.jsonl").read_text().splitlines()[0])["task_id"]
    (run_dir / "episodes" / task / "steps.jsonl").unlink()
    assert check(run_dir).mismatches == [f"{task}: its steps.jsonl is missing"]


def test_the_command_prints_one_line_per_mismatch_and_exits_1(run_dir, capsys, monkeypatch):
    monkeypatch.setenv("EB_PLUGINS", "fixture_plugin")
    assert cmd_verify([str(run_dir)]) == 0
    assert capsys.readouterr().out.strip().endswith("4 episode(s) replayed, verified")
    task = _edit_record(run_dir, 2, success=False)
    assert cmd_verify([str(run_dir)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"MISMATCH {task}: success recorded False, replay True"
    assert out[1].startswith("MISMATCH summary.json: overall success_rate recorded 1.0, episodes.jsonl gives 0.75")
    assert out[2].startswith("MISMATCH summary.json: subset near success_rate recorded 1.0")
    assert out[3:] == [f"{run_dir}: 4 episode(s) replayed, FAILED (3 mismatch(es))"]
    assert cmd_verify(["--bogus"]) == 2
    assert "unknown option '--bogus'" in capsys.readouterr().err


def test_an_edited_summary_is_a_mismatch(run_dir):
    path = run_dir / "summary.json"
    summary = json.loads(path.read_text())
    summary["overall"]["success_rate"] = 0.5
    path.write_text(json.dumps(summary))
    assert check(run_dir).mismatches == [
        "summary.json: overall success_rate recorded 0.5, episodes.jsonl gives 1.0"]


def test_the_runs_own_selection_is_verified(run_dir):
    """The manifest names the run's tasks: a config that would now select others still verifies those."""
    import yaml

    from eb_core.manifest import config_digest
    from eb_core.records import read_manifest

    manifest = read_manifest(run_dir)
    recorded = (run_dir / "episodes.jsonl").read_text().splitlines()
    assert manifest.task_ids == [json.loads(x)["task_id"] for x in recorded]
    path = run_dir / "config.yaml"
    conf = yaml.safe_load(path.read_text())
    conf["limit"] = 2  # what a changed selection rule would do to this config
    path.write_text(yaml.safe_dump(conf, sort_keys=False))
    manifest.config_digest = config_digest(conf)
    (run_dir / "manifest.json").write_text(manifest.model_dump_json())
    res = check(run_dir)
    assert res.ok and res.episodes == 4
    assert res.warnings == ["config.yaml now selects other tasks than the run did (changed selection rules?); the "
                            "run's own tasks are verified"]
