"""`eb verify` on fresh runs of every installed world, and on each kind of tampering (real `eb` subprocesses).

The runs are small (two or three tasks) with rendering off, so the whole module takes well under a minute.
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

WORLDS = ("navigation", "alfred", "habitat", "manipulation")


def _installed() -> set[str]:
    return {w for w in WORLDS if importlib.util.find_spec(f"eb_{w}") is not None}


def _env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("EB_DISABLE_PLUGIN_AUTOLOAD", "EB_PLUGINS")}
    env.setdefault("MUJOCO_GL", "egl")
    return env


def eb(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "eb_core.cli", *args], capture_output=True, text=True,
                          cwd=cwd, env=_env(), timeout=300)


def play(tmp_path: Path, name: str, *overrides: str) -> Path:
    run_dir = tmp_path / name
    res = eb("run", *overrides, "++env.params.render=false", "runner.quiet=true", f"hydra.run.dir={run_dir}",
             cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-2000:]
    return run_dir


def verify(run_dir: Path) -> subprocess.CompletedProcess[str]:
    return eb("verify", str(run_dir), cwd=run_dir.parent)


@pytest.fixture(scope="module")
def installed() -> set[str]:
    return _installed()


@pytest.mark.parametrize("world", WORLDS)
@pytest.mark.parametrize("model", ["oracle", "random"])
def test_fresh_runs_of_every_world_verify(tmp_path, world, model, installed):
    if world not in installed:
        pytest.skip(f"eb-{world} is not installed")
    run_dir = play(tmp_path, "run", f"env={world}", f"model={model}", "limit=3")
    res = verify(run_dir)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "3 episode(s) replayed, verified" in res.stdout
    assert "MISMATCH" not in res.stdout and "warning" not in res.stderr


@pytest.mark.parametrize("extra", [["runner.repeats=2"], ["model.noise=0.3"], ["runner.expert_labels=true"]],
                         ids=["repeats", "noise", "expert_labels"])
def test_runs_with_repeats_noise_and_expert_labels_verify(tmp_path, extra, installed):
    if "navigation" not in installed:
        pytest.skip("eb-navigation is not installed")
    run_dir = play(tmp_path, "run", "env=navigation", "model=oracle", "limit=2", *extra)
    res = verify(run_dir)
    assert res.returncode == 0, res.stdout + res.stderr
    n = 4 if "runner.repeats=2" in extra else 2
    assert f"{n} episode(s) replayed, verified" in res.stdout


# -- tampering ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def random_run(tmp_path_factory, installed) -> Path:
    """A navigation run of the random model: several planner steps per episode, failed actions among them."""
    if "navigation" not in installed:
        pytest.skip("eb-navigation is not installed")
    tmp = tmp_path_factory.mktemp("verify")
    return play(tmp, "random", "env=navigation", "model=random", "limit=2")


def _copy(run_dir: Path, tmp_path: Path) -> Path:
    dst = tmp_path / "copy"
    shutil.copytree(run_dir, dst, ignore=shutil.ignore_patterns("run.lock"))
    return dst


def _edit_lines(path: Path, edit) -> None:
    lines = [json.loads(x) for x in path.read_text().splitlines()]
    lines = edit(lines)
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))


def _mismatches(run_dir: Path) -> list[str]:
    res = verify(run_dir)
    assert res.returncode == 1, res.stdout + res.stderr
    return [ln for ln in res.stdout.splitlines() if ln.startswith("MISMATCH")]


def test_a_flipped_success_is_caught(random_run, tmp_path):
    run = _copy(random_run, tmp_path)

    def flip(lines):
        lines[0]["success"] = not lines[0]["success"]
        return lines

    _edit_lines(run / "episodes.jsonl", flip)
    task = json.loads((run / "episodes.jsonl").read_text().splitlines()[0])["task_id"]
    lines = _mismatches(run)
    assert lines[0] == (f"MISMATCH {task}: success recorded {not _orig(random_run, 0)['success']!r}, "
                        f"replay {_orig(random_run, 0)['success']!r}")
    assert lines[1].startswith("MISMATCH summary.json: overall ")  # the summary no longer adds up


def _orig(run_dir: Path, i: int) -> dict:
    return json.loads((run_dir / "episodes.jsonl").read_text().splitlines()[i])


def test_an_edited_action_is_caught(random_run, tmp_path):
    run = _copy(random_run, tmp_path)
    task = _orig(run, 0)["task_id"]
    steps = run / "episodes" / task / "steps.jsonl"
    first = json.loads(steps.read_text().splitlines()[0])
    action = first["actions"][0]["action"]

    def edit(lines):
        lines[0]["actions"][0]["action"] = (action + 1) % 8
        return lines

    _edit_lines(steps, edit)
    lines = _mismatches(run)
    assert lines[0] == (f"MISMATCH {task}: step 1 action 1: recorded action {(action + 1) % 8}, the answer's plan "
                        f"gives {action}")


def test_a_removed_step_is_caught(random_run, tmp_path):
    run = _copy(random_run, tmp_path)
    task = _orig(run, 0)["task_id"]
    steps = run / "episodes" / task / "steps.jsonl"
    assert len(steps.read_text().splitlines()) >= 3
    _edit_lines(steps, lambda lines: lines[:1] + lines[2:])
    lines = _mismatches(run)
    assert lines[0].startswith(f"MISMATCH {task}: step 2: recorded as planner step 3 after ")
    assert "(a step removed or reordered?)" in lines[0]


def test_a_removed_last_step_is_caught(random_run, tmp_path):
    run = _copy(random_run, tmp_path)
    task = _orig(run, 0)["task_id"]
    steps = run / "episodes" / task / "steps.jsonl"
    n = len(steps.read_text().splitlines())
    _edit_lines(steps, lambda lines: lines[:-1])
    lines = _mismatches(run)
    assert lines[0] == f"MISMATCH {task}: the recorded steps end after {n - 1} planner steps, before the episode did"


def test_a_missing_episode_is_caught(random_run, tmp_path):
    run = _copy(random_run, tmp_path)
    _edit_lines(run / "episodes.jsonl", lambda lines: lines[1:])
    lines = _mismatches(run)
    assert lines[0] == f"MISMATCH {_orig(random_run, 0)['task_id']}: missing from episodes.jsonl"
    assert lines[1].startswith("MISMATCH summary.json: overall episodes recorded 2.0, episodes.jsonl gives 1.0")


def test_another_task_set_is_caught(tmp_path, installed):
    if "navigation" not in installed:
        pytest.skip("eb-navigation is not installed")
    src = _task_file()
    task_file = tmp_path / "tasks.json"
    shutil.copyfile(src, task_file)
    run_dir = play(tmp_path, "run", "env=navigation", "model=oracle", "limit=2", f"env.params.task_file={task_file}")
    assert verify(run_dir).returncode == 0
    data = json.loads(task_file.read_text())
    tasks = data["tasks"] if isinstance(data, dict) else data
    tasks[-1]["instruction"] = tasks[-1]["instruction"] + " Quickly."
    task_file.write_text(json.dumps(data))
    lines = _mismatches(run_dir)
    assert len(lines) == 1 and lines[0].startswith(
        "MISMATCH manifest: the run was played on another task set than the installed one (")


def _task_file() -> Path:
    import eb_navigation

    return Path(eb_navigation.__file__).parent / "tasks" / "navigation_v3.json"


def test_a_run_made_before_the_manifest_verifies_with_a_warning(tmp_path, installed):
    """A real model's Navigation run recorded before format version 1 (copied: the original stays untouched)."""
    src = Path("/work/shared/real-play/navigation")
    if "navigation" not in installed or not src.is_dir():
        pytest.skip("needs eb-navigation and the recorded real-play run")
    run = tmp_path / "old"
    shutil.copytree(src, run, ignore=shutil.ignore_patterns("run.lock"))
    res = verify(run)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "episode(s) replayed, verified" in res.stdout
    assert "has no manifest.json (made before format version 1)" in res.stderr
