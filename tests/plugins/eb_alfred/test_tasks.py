"""Shipped task files: counts, validation errors, the oracle on all 300, a random agent, the action range."""

from __future__ import annotations

import json
import random
import shutil
from pathlib import Path

import pytest

from eb_alfred.env import AlfredEnv
from eb_alfred.generate import make_tasks
from eb_alfred.tasks import TASK_DIR, TaskFileError, load_task_file
from eb_alfred.plugin import SUBSETS


@pytest.fixture(scope="module")
def tasks():
    return AlfredEnv.load_tasks()


def test_six_subsets_of_fifty(tasks) -> None:
    counts: dict[str, int] = {}
    for t in tasks:
        counts[t.subset] = counts.get(t.subset, 0) + 1
    assert counts == SUBSETS


def test_every_task_type_in_every_short_subset(tasks) -> None:
    for subset in ("base", "common_sense", "complex_instruction", "spatial_awareness", "visual_appearance"):
        kinds = {t.metadata["task_type"] for t in tasks if t.subset == subset}
        assert len(kinds) == 7, subset


def test_step_ranges(tasks) -> None:
    for t in tasks:
        n = t.metadata["oracle_steps"]
        if t.subset == "base":
            assert n < 15
        if t.subset == "long_horizon":
            assert n > 15
        assert n <= 26


def test_oracle_solves_all_300(tasks) -> None:
    env = AlfredEnv(render=False)
    sizes = []
    for task in tasks:
        env.reset(task, 0)
        sizes.append(len(env.action_space()))
        steps, result = 0, None
        while steps < 30:
            for a in env.expert_plan() or []:
                result = env.step(a)
                steps += 1
                if result.done or not result.action_success:
                    break
            if result is not None and result.done:
                break
        assert result is not None and result.task_success and result.progress == 1.0, task.id
        assert steps <= 30
    assert 171 <= min(sizes) and max(sizes) <= 298
    assert max(sizes) - min(sizes) > 80  # spans most of the paper's 171-298


def test_seeded_random_agent_stays_low(tasks) -> None:
    env = AlfredEnv(render=False)
    rng = random.Random(0)
    wins = 0
    for task in tasks:
        env.reset(task, 0)
        n = len(env.action_space())
        for _ in range(30):
            result = env.step(rng.randrange(n))
            if result.done:
                break
        wins += result.task_success
    assert wins / len(tasks) < 0.05


def test_generator_is_deterministic_and_matches_shipped() -> None:
    shipped = json.loads((TASK_DIR / "base.json").read_text())["tasks"][:5]
    again = make_tasks("base", seed=0, n=5)
    assert again == shipped


def _broken_copy(tmp_path: Path, mutate) -> Path:
    path = tmp_path / "base.json"
    shutil.copy(TASK_DIR / "base.json", path)
    data = json.loads(path.read_text())
    mutate(data)
    path.write_text(json.dumps(data))
    return path


def test_malformed_file_fails_with_one_clear_line(tmp_path: Path) -> None:
    def bad_type(d):
        d["tasks"][3]["goal"]["receptacle"] = {"type": "Fridgee"}
    with pytest.raises(TaskFileError) as err:
        load_task_file(_broken_copy(tmp_path, bad_type))
    msg = str(err.value)
    assert "\n" not in msg and "base.json" in msg and "base_03" in msg and "goal.receptacle" in msg

    def bad_parent(d):
        d["tasks"][1]["scene"]["objects"][-1]["parent"] = "Nowhere_9"
    with pytest.raises(TaskFileError, match=r"base.json: task .?base_01.?: field scene.objects.\d+.parent"):
        load_task_file(_broken_copy(tmp_path, bad_parent))

    def missing(d):
        del d["tasks"][0]["instruction"]
    with pytest.raises(TaskFileError, match="base.json: task .?base_00.?: field instruction"):
        load_task_file(_broken_copy(tmp_path, missing))

    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(TaskFileError, match="bad.json: not valid JSON"):
        load_task_file(tmp_path / "bad.json")


def test_generate_writes_a_loadable_file(tmp_path: Path) -> None:
    from eb_alfred.generate import generate

    out = generate(out=str(tmp_path / "vis.json"), subset="visual_appearance", n=3, seed=1)
    recs = load_task_file(out[0])
    assert len(recs) == 3 and all(r.subset == "visual_appearance" for r in recs)


def test_unknown_param_is_named() -> None:
    with pytest.raises(ValueError, match="unknown alfred param 'rendr'"):
        AlfredEnv(rendr=False)
