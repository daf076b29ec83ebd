"""Generated train/val splits of EB-ALFRED (eb_alfred.splits): deterministic, apart from the shipped test tasks,
solvable by the expert, and played by `eb run split=val` and `eb tasks generate split=train`."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import pytest

from eb_alfred.env import AlfredEnv
from eb_alfred.splits import SEED_BASE, layout_key, scene_key
from eb_alfred.tasks import SUBSETS, TASK_DIR

N_TRAIN = 1000  # about 5 ms a task, symbolic checks only


@pytest.fixture(scope="module")
def train():
    return AlfredEnv.split_tasks("train", 0, N_TRAIN)


def test_split_task_depends_on_split_and_index_only(train):
    assert len({t.id for t in train}) == N_TRAIN
    assert AlfredEnv.split_tasks("train", 137, 3) == train[137:140]
    assert AlfredEnv.split_tasks("train", 0, 12) == train[:12]
    val = AlfredEnv.split_tasks("val", 0, 12)
    assert all(t.id.startswith("val_") for t in val)
    assert [t.instruction for t in val] != [t.instruction for t in train[:12]]
    assert {t.subset for t in train} == set(SUBSETS)


_DUMP = """
import json, sys
from eb_alfred.env import AlfredEnv
print(json.dumps([t.model_dump() for t in AlfredEnv.split_tasks(sys.argv[1], int(sys.argv[2]), 6)]))
"""


def test_same_tasks_in_a_fresh_process(train):
    out = subprocess.run([sys.executable, "-c", _DUMP, "train", "40"], capture_output=True, text=True, timeout=120,
                         env={"PYTHONHASHSEED": "7", "PATH": ""})
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [t.model_dump() for t in train[40:46]]


def test_train_tasks_are_apart_from_the_shipped_test_tasks(train):
    shipped = AlfredEnv.load_tasks()
    layouts = {layout_key(t.metadata["scene"]) for t in shipped}
    scenes = {scene_key(t.metadata["scene"]) for t in shipped}
    texts = {t.instruction for t in shipped}
    seeds = {t.metadata["scene_seed"] for t in shipped}
    assert max(seeds) < SEED_BASE
    for t in train + AlfredEnv.split_tasks("val", 0, 60):
        assert t.instruction not in texts, t.id
        assert layout_key(t.metadata["scene"]) not in layouts, t.id
        assert scene_key(t.metadata["scene"]) not in scenes, t.id
        assert t.metadata["scene_seed"] >= SEED_BASE, t.id


def test_a_draw_that_matches_a_test_task_is_drawn_again(tmp_path):
    """Put train task 0 into a copy of the test files: the split then refuses that draw and gives another."""
    first = AlfredEnv.split_tasks("train", 0, 1)[0]
    shutil.copytree(TASK_DIR, tmp_path / "tasks")
    path = tmp_path / "tasks" / "base.json"
    doc = json.loads(path.read_text())
    meta = {k: v for k, v in first.metadata.items() if k != "split"}
    doc["tasks"].append({"id": "base_injected", "subset": "base", "instruction": first.instruction, **meta})
    path.write_text(json.dumps(doc))
    again = AlfredEnv.split_tasks("train", 0, 1, task_dir=str(tmp_path / "tasks"))[0]
    assert again.instruction != first.instruction
    assert layout_key(again.metadata["scene"]) != layout_key(first.metadata["scene"])
    assert AlfredEnv.split_tasks("train", 1, 1, task_dir=str(tmp_path / "tasks"))[0] == \
        AlfredEnv.split_tasks("train", 1, 1)[0]  # other indices keep their tasks


def test_the_expert_solves_a_sample_closed_loop(train):
    env = AlfredEnv(render=False)
    sample = train[:24] + AlfredEnv.split_tasks("val", 100, 6)
    for task in sample:
        env.reset(task, seed=0)
        done, steps = False, 0
        while not done and steps < 40:
            plan = env.expert_plan()
            assert plan, (task.id, env.expert_reason)
            result = env.step(plan[0])
            assert result.action_success, (task.id, result.feedback)
            done, steps = result.done, steps + 1
        assert done and result.task_success, task.id
        assert steps == task.metadata["oracle_steps"], task.id
    env.close()


def test_unknown_split_is_one_clear_line():
    with pytest.raises(ValueError, match=r"unknown split 'dev'.*train, val") as exc:
        AlfredEnv.split_tasks("dev", 0, 1)
    assert "\n" not in str(exc.value)


def test_eb_run_plays_the_val_split_and_generate_writes_train(tmp_path):
    base = [sys.executable, "-m", "eb_core", "run", "env=alfred", "model=oracle", "--quiet", "env.params.render=false"]
    r = subprocess.run(base + ["split=val", "limit=3", f"hydra.run.dir={tmp_path / 'val'}"], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "success rate: 100.0% (3 of 3 episodes succeeded)" in r.stdout
    ids = [json.loads(x)["task_id"] for x in (tmp_path / "val" / "episodes.jsonl").read_text().splitlines()]
    assert ids == [t.id for t in AlfredEnv.split_tasks("val", 0, 3)]

    out = tmp_path / "train"
    g = subprocess.run([sys.executable, "-m", "eb_core", "tasks", "generate", "env=alfred", "split=train", "n=7",
                        "start=5", f"out={out}"], capture_output=True, text=True, timeout=300)
    assert g.returncode == 0, g.stderr
    written = [t["id"] for s in SUBSETS for t in json.loads((out / f"{s}.json").read_text())["tasks"]]
    assert sorted(written) == sorted(t.id for t in AlfredEnv.split_tasks("train", 5, 7))
    run = subprocess.run(base + [f"+env.params.task_dir={out}", f"hydra.run.dir={tmp_path / 'run'}"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "success rate: 100.0% (7 of 7 episodes succeeded)" in run.stdout
