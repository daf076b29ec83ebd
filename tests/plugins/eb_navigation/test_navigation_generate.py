"""The task generator: a small file through the real code path, loadable and solvable."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from eb_navigation.env import NavigationEnv
from eb_navigation.generate import generate
from eb_navigation.tasks import DEFAULT_TASK_FILE, SUBSETS, load_task_file


@pytest.fixture(scope="module")
def small_file(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("gen") / "nav_small.json"
    summary = generate(seed=7, scenes=2, min_distance=2.5, max_distance=3.5, out=str(out))
    assert "wrote 10 tasks" in summary
    return out


def test_generated_file_records_parameters_and_validates(small_file: Path) -> None:
    tf = load_task_file(small_file)
    assert tf.generator["seed"] == 7 and tf.generator["scenes"] == 2
    assert [t.subset for t in tf.tasks] == list(SUBSETS) * 2  # room by room
    assert {t.scene.kind for t in tf.tasks} == {"kitchen", "living_room"}


def test_shipped_file_is_what_the_generator_makes(tmp_path: Path) -> None:
    """The first rooms of ``generate(seed=0)`` reproduce the shipped file's first tasks exactly."""
    out = tmp_path / "again.json"
    generate(seed=0, scenes=2, out=str(out), blind_cap=2, rule_cap=6)  # the caps of the 60-room file
    made = {t["id"]: t for t in json.loads(out.read_text())["tasks"]}
    shipped = {t["id"]: t for t in json.loads(DEFAULT_TASK_FILE.read_text())["tasks"]}
    assert made and all(made[k] == shipped[k] for k in made)
    params = json.loads(DEFAULT_TASK_FILE.read_text())["generator"]
    assert params["seed"] == 0 and params["scenes"] == 60


def test_generated_tasks_are_solved_by_the_oracle(small_file: Path) -> None:
    env = NavigationEnv(task_file=str(small_file), render=False)
    for task in NavigationEnv.load_tasks(task_file=str(small_file)):
        env.reset(task, 0)
        m = task.metadata
        d = math.hypot(m["start"]["x"] - m["target"]["position"][0], m["start"]["y"] - m["target"]["position"][1])
        assert 2.5 - 1e-6 <= d <= (4.5 if task.subset == "long_horizon" else 3.5) + 1e-6
        result = None
        for a in env.expert_plan():
            result = env.step(a)
        assert result is not None and result.task_success
    env.close()


def test_generator_refuses_starts_a_blind_policy_would_solve_too_often(tmp_path: Path) -> None:
    """With a cap of 1, no blind policy and no rule agent solves two tasks of a subset (re-measured here)."""
    from eb_navigation.baselines import blind_successes, rule_agent_successes
    from eb_navigation.env import build_room
    from eb_navigation.geometry import AgentState

    out = tmp_path / "capped.json"
    generate(seed=3, scenes=3, out=str(out), blind_cap=1, rule_cap=1)
    tf = load_task_file(out)
    for subset in SUBSETS:
        blind, rules = 0, 0
        for t in (t for t in tf.tasks if t.subset == subset):
            room = build_room(t)
            free = room.free_space(room.extra_ids)
            s = AgentState.from_pose(t.start.x, t.start.y, t.start.yaw)
            blind = blind + blind_successes(free, s, t.target.position[:2]).astype(int)
            rules = rules + np.array(list(rule_agent_successes(free, s, t.target.position[:2]).values()), int)
        assert blind.max() <= 1 and rules.max() <= 1, subset


def test_bad_arguments_are_named(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="min_distance"):
        generate(scenes=1, min_distance=3.0, max_distance=2.0, out=str(tmp_path / "x.json"))
