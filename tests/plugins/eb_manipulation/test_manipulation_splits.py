"""Generated train/val splits of EB-Manipulation: deterministic, apart from the shipped test tasks, solvable."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from eb_manipulation.env import ManipulationEnv
from eb_manipulation.generate import verify_task
from eb_manipulation.splits import COMBOS, layout_key, split_tasks
from eb_manipulation.tasks import load_task_file

SAMPLE = 200  # train tasks checked against the shipped ones


@pytest.fixture(scope="module")
def train() -> list:
    return ManipulationEnv.split_tasks("train", 0, SAMPLE, render=False)


def test_split_task_is_a_pure_function_of_split_and_index(train):
    again = split_tasks("train", 37, 3)
    assert [t.model_dump() for t in again] == [t.model_dump() for t in train[37:40]]
    code = ("import json; from eb_manipulation.splits import split_tasks; "
            "print(json.dumps([t.model_dump() for t in split_tasks('train', 37, 3)]))")
    fresh = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert fresh.returncode == 0, fresh.stderr
    assert json.loads(fresh.stdout) == [t.model_dump() for t in again]
    val = split_tasks("val", 37, 3)
    assert [t.metadata["scene_seed"] for t in val] != [t.metadata["scene_seed"] for t in again]
    assert all(t.id.startswith("val_") for t in val) and all(t.id.startswith("train_") for t in again)


def test_split_tasks_are_disjoint_from_the_shipped_tasks(train):
    shipped = load_task_file()
    seeds = {t.metadata["scene_seed"] for t in shipped}
    layouts = {layout_key(t.metadata) for t in shipped}
    instructions = {t.instruction for t in shipped}
    val = split_tasks("val", 0, 40)
    for t in [*train, *val]:
        assert t.metadata["scene_seed"] not in seeds, t.id
        assert layout_key(t.metadata) not in layouts, t.id
        assert t.instruction not in instructions, t.id
    assert not {t.metadata["scene_seed"] for t in train} & {t.metadata["scene_seed"] for t in val}
    # every (subset, family) pair of the shipped file is covered, in the shipped proportions
    assert {(t.subset, t.metadata["family"]) for t in train} == set(COMBOS)
    assert {(t.subset, t.metadata["family"]) for t in shipped} == set(COMBOS)


def test_the_expert_solves_a_sample_closed_loop(train):
    for t in train[::10]:
        ok, steps = verify_task(t.model_dump(), closed_loop=True)
        assert ok and steps == t.metadata["oracle_steps"], t.id


def test_bad_split_gives_one_clear_line():
    with pytest.raises(ValueError, match="generated splits are train, val"):
        ManipulationEnv.split_tasks("dev", 0, 1)
    with pytest.raises(ValueError, match="start >= 0"):
        ManipulationEnv.split_tasks("train", -1, 1)


def test_eb_run_oracle_plays_the_val_split(tmp_path):
    r = subprocess.run([sys.executable, "-m", "eb_core", "run", "env=manipulation", "model=oracle", "--quiet",
                        "+env.params.render=false", "split=val", "limit=3", f"hydra.run.dir={tmp_path / 'run'}"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "success rate: 100.0% (3 of 3 episodes succeeded)" in r.stdout
    ids = [json.loads(x)["task_id"] for x in (tmp_path / "run" / "episodes.jsonl").read_text().splitlines()]
    assert ids == [t.id for t in split_tasks("val", 0, 3)]


def test_eb_tasks_generate_writes_a_train_file_that_eb_run_plays(tmp_path):
    out = tmp_path / "train.json"
    r = subprocess.run([sys.executable, "-m", "eb_core", "tasks", "generate", "env=manipulation", "split=train", "n=3",
                        "start=19", f"out={out}"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text())
    assert [t["id"] for t in doc["tasks"]] == [t.id for t in split_tasks("train", 19, 3)]
    assert [t.id for t in load_task_file(out)] == [t["id"] for t in doc["tasks"]]


def test_split_files_use_the_core_envelope_and_old_ones_still_load(tmp_path):
    """Issue 27: ``write_split`` writes the core's envelope (format eb-manipulation-tasks, version 3); a split file
    of the older envelope (format 2, version s1) still loads, task for task."""
    from eb_manipulation.splits import write_split
    from eb_manipulation.tasks import FORMAT

    paths = write_split(str(tmp_path), "val", 2, start=5)
    assert paths == [tmp_path / "manipulation_val.json"]
    doc = json.loads(paths[0].read_text())
    assert (doc["format"], doc["version"]) == (FORMAT.format, FORMAT.version)
    assert doc["generator"]["split"] == "val" and doc["generator"]["start"] == 5
    tasks = load_task_file(paths[0])
    assert [t.id for t in tasks] == [t.id for t in split_tasks("val", 5, 2)]
    old = tmp_path / "old_split.json"
    old.write_text(json.dumps({"format": 2, "version": "s1", "generator": "eb_manipulation.splits:write_split",
                               "split": "val", "start": 5, "n": 2, "verified": True, "count": 2,
                               "tasks": [t.model_dump() for t in tasks]}, indent=1) + "\n")
    assert [t.model_dump() for t in load_task_file(old)] == [t.model_dump() for t in tasks]


def test_split_scene_seeds_come_from_the_cores_split_rng():
    from eb_core.taskfile import split_rng

    task = split_tasks("train", 3, 1)[0]
    stream = split_rng("manipulation", "train", 3)
    seeds = [int(stream.integers(2**32)) for _ in range(task.metadata["attempt"] + 1)]
    assert task.metadata["scene_seed"] == seeds[-1]
