"""Generated train/val splits of EB-Navigation (eb_navigation.splits): determinism, apartness from the shipped
test tasks, closed-loop solvability by the expert, and the CLI paths that play them."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from eb_navigation.env import NavigationEnv
from eb_navigation.geometry import AgentState, bearing_to
from eb_navigation import splits as nav_splits
from eb_navigation.splits import SEED_RANGE, SPLITS, split_tasks
from eb_navigation.tasks import SUBSETS, load_task_file
from eb_navigation.visual_icl import EPISODES

N_TRAIN = 200
N_VAL = 50


@pytest.fixture(scope="module")
def train():
    return NavigationEnv.split_tasks("train", 0, N_TRAIN)


@pytest.fixture(scope="module")
def val():
    return NavigationEnv.split_tasks("val", 0, N_VAL)


def test_env_lists_its_splits():
    assert NavigationEnv.splits == SPLITS == ("train", "val")


def test_split_task_depends_on_split_and_index_only(train, val):
    again = split_tasks("train", 7, 3)
    assert [t.model_dump() for t in again] == [t.model_dump() for t in train[7:10]]
    assert [t.model_dump() for t in split_tasks("val", 3, 2)] == [t.model_dump() for t in val[3:5]]
    assert [t.subset for t in train[:10]] == list(SUBSETS) * 2
    assert train[0].metadata["scene"] != val[0].metadata["scene"]
    assert len({t.id for t in train} | {t.id for t in val}) == N_TRAIN + N_VAL


def test_same_tasks_in_a_fresh_process(train):
    code = ("import json; from eb_navigation.splits import split_tasks; "
            "print(json.dumps([t.model_dump() for t in split_tasks('train', 11, 2)]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert json.loads(out.stdout) == [t.model_dump() for t in train[11:13]]


def test_split_tasks_are_apart_from_the_shipped_test_tasks(train, val):
    shipped = load_task_file().tasks
    test_rooms = {(t.scene.kind, t.scene.seed) for t in shipped}
    test_texts = {t.instruction for t in shipped}
    icl_rooms = {(kind, seed) for kind, seed, _ in EPISODES}
    assert test_rooms and test_texts
    for t in [*train, *val]:
        scene = t.metadata["scene"]
        assert SEED_RANGE[0] <= scene["seed"] < SEED_RANGE[1]
        assert (scene["kind"], scene["seed"]) not in test_rooms | icl_rooms
        assert t.instruction not in test_texts, t.id
    # train and val do not share rooms either
    assert not ({(t.metadata["scene"]["kind"], t.metadata["scene"]["seed"]) for t in train}
                & {(t.metadata["scene"]["kind"], t.metadata["scene"]["seed"]) for t in val})


def test_a_split_avoids_the_rooms_and_wording_of_the_task_file_it_is_given(tmp_path, train):
    """Point the split at a task file that holds train task 0 itself: task 0 must then be drawn again."""
    first = train[0]
    doc = {"format": "eb-navigation-tasks", "version": 3, "generator": {},
           "tasks": [{"id": "t0", "subset": first.subset, "instruction": first.instruction, **first.metadata}]}
    path = tmp_path / "tasks.json"
    path.write_text(json.dumps(doc))
    rooms, texts = nav_splits.test_keys(str(path))
    assert (first.metadata["scene"]["kind"], first.metadata["scene"]["seed"]) in rooms
    redrawn = NavigationEnv.split_tasks("train", 0, 1, task_file=str(path))[0]
    assert redrawn.metadata["scene"] != first.metadata["scene"]
    assert redrawn.instruction != first.instruction


def test_subset_rules_hold(train, val):
    for t in [*train, *val]:
        m = t.metadata
        s = AgentState.from_pose(m["start"]["x"], m["start"]["y"], m["start"]["yaw"])
        b = abs(bearing_to(s, tuple(m["target"]["position"][:2])))
        if t.subset == "long_horizon":
            assert b >= 100.0, t.id
        else:
            assert b <= 40.0, t.id
        assert bool(m["extra_objects"]) == (t.subset == "visual_appearance"), t.id
        assert 1 <= m["oracle_steps"] <= 17


def test_the_expert_solves_a_sample_closed_loop(train, val):
    """Geometry mode: replan with expert_plan() after every step, inside the 20-step budget."""
    env = NavigationEnv(render=False)
    try:
        for task in train[::4] + val[::2]:
            env.reset(task, seed=0)
            done = False
            for _ in range(20):
                plan = env.expert_plan()
                assert plan, (task.id, env.expert_reason)
                r = env.step(plan[0])
                assert r.action_success
                if r.done:
                    done = r.task_success
                    break
            assert done, task.id
    finally:
        env.close()


def test_unknown_split_and_bad_range_are_one_clear_line():
    with pytest.raises(ValueError, match=r"unknown split 'test'.*train, val") as e:
        NavigationEnv.split_tasks("test", 0, 1)
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="start >= 0"):
        split_tasks("train", -1, 2)


def test_eb_run_plays_the_val_split_and_generate_writes_train(tmp_path):
    run = subprocess.run([sys.executable, "-m", "eb_core", "run", "env=navigation", "model=oracle", "--quiet",
                          "split=val", "limit=3", "env.params.render=false", f"hydra.run.dir={tmp_path / 'run'}"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "success rate: 100.0% (3 of 3 episodes succeeded)" in run.stdout
    ids = [json.loads(x)["task_id"] for x in (tmp_path / "run" / "episodes.jsonl").read_text().splitlines()]
    assert ids == [t.id for t in split_tasks("val", 0, 3)]
    gen = subprocess.run([sys.executable, "-m", "eb_core", "tasks", "generate", "env=navigation", "split=train", "n=5",
                          f"out={tmp_path / 'gen'}"], capture_output=True, text=True, timeout=300)
    assert gen.returncode == 0, gen.stderr
    written = tmp_path / "gen" / "navigation_train.json"
    assert [t.id for t in load_task_file(written).tasks] == [t.id for t in split_tasks("train", 0, 5)]
    bad = subprocess.run([sys.executable, "-m", "eb_core", "tasks", "generate", "env=navigation", "split=train",
                          f"out={tmp_path / 'x'}"], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "n=" in bad.stderr
