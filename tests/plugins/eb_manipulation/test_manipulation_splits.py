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
