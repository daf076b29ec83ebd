"""Task files: the shipped 300 load; a malformed file fails with ONE line naming file, task and field."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from eb_habitat.tasks import SUBSETS, TASK_DIR, TaskFileError, load_task_file, load_tasks


def test_shipped_tasks_are_300_in_six_subsets() -> None:
    tasks = load_tasks()
    assert len(tasks) == 300
    assert [t.subset for t in tasks[::50]] == list(SUBSETS)
    assert len({t.id for t in tasks}) == 300
    assert len({t.instruction for t in tasks}) == 300


def _doc() -> dict:
    return json.loads((TASK_DIR / "base.json").read_text())


def _write(tmp_path: Path, doc: dict) -> Path:
    path = tmp_path / "base.json"
    path.write_text(json.dumps(doc))
    return path


def _breaks(tmp_path: Path, doc: dict, *fragments: str) -> str:
    path = _write(tmp_path, doc)
    with pytest.raises(TaskFileError) as info:
        load_task_file(path)
    msg = str(info.value)
    assert "\n" not in msg, msg
    assert str(path) in msg
    for f in fragments:
        assert f in msg, (f, msg)
    return msg


def test_unknown_receptacle(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][3]["metadata"]["objects"][1]["at"] = "bathtub"
    _breaks(tmp_path, doc, "task 'base-03'", "metadata.objects[1].at", "unknown receptacle 'bathtub'")


def test_bad_goal_predicate(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][7]["metadata"]["goal"][0] = "(on ?apple fridge)"
    _breaks(tmp_path, doc, "task 'base-07'", "metadata.goal[0]", "use (inside")


def test_missing_field(tmp_path: Path) -> None:
    doc = _doc()
    del doc["tasks"][5]["metadata"]["subgoals"]
    _breaks(tmp_path, doc, "task 'base-05'", "metadata.subgoals", "is missing")


def test_misspelled_field(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][2]["metadata"]["goals"] = doc["tasks"][2]["metadata"]["goal"]
    _breaks(tmp_path, doc, "task 'base-02'", "metadata.goals", "is not a known field")


def test_wrong_colour_and_slot(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][0]["metadata"]["objects"][0]["color"] = "tartan"
    _breaks(tmp_path, doc, "task 'base-00'", "metadata.objects[0].color", "tartan")
    doc = _doc()
    doc["tasks"][0]["metadata"]["objects"][0]["slot"] = 9
    _breaks(tmp_path, doc, "task 'base-00'", "metadata.objects[0].slot", "slot 9")


def test_goal_already_met(tmp_path: Path) -> None:
    doc = _doc()
    meta = doc["tasks"][1]["metadata"]
    obj = meta["objects"][0]
    meta["goal"] = [f"({'inside' if obj['at'] in ('fridge', 'left_drawer', 'right_drawer', 'cabinet') else 'on'} "
                    f"{obj['name']} {obj['at']})"]
    _breaks(tmp_path, doc, "task 'base-01'", "metadata.goal", "already holds")


def test_version_and_json(tmp_path: Path) -> None:
    doc = _doc()
    doc["version"] = 1  # the pre-repair task files (fixed kitchen rows, word-matchable spatial tasks)
    msg = _breaks(tmp_path, doc, "is version 1", "reads version 2", "eb tasks generate env=habitat")
    assert msg.count("regenerate") == 1
    path = tmp_path / "broken.json"
    path.write_text('{"format": "eb-habitat-tasks",')
    with pytest.raises(TaskFileError, match="not valid JSON"):
        load_task_file(path)


def test_duplicate_id_across_files(tmp_path: Path) -> None:
    doc = _doc()
    _write(tmp_path, doc)
    (tmp_path / "common_sense.json").write_text(json.dumps({**doc, "subset": "common_sense", "tasks": [
        {**doc["tasks"][0], "subset": "common_sense"}]}))
    with pytest.raises(TaskFileError, match=r"duplicate task id \(also in"):
        load_tasks(tmp_path)


CLASSIC_SHA256 = {
    "base": "2ae60ff96e4d3b5df95919ab083fc176dee8a06e15ec4a5dd46a4a500d665069",
    "common_sense": "8963bf4daf0611b8b216086c2f605734f13e7ffa40b1f58f64ae61a82298b813",
    "complex_instruction": "ab99cdb50ed42f92c48ad223bd918b0a0dd0aa9abe2788a89b3d43e74bb00995",
    "spatial_relationship": "db291e4948b656c40b410f9733dfad144f67dec4326261160f3aeb87d6e353f7",
    "visual_appearance": "e3bdd5b648b6b31dbdbf41726e01634e8f743d51944aac665d8215db07f4a505",
    "long_horizon": "068d896a3dc2b6c00d64bebc961c78c4cf24643e0c264904737bb7b44202bcfe",
}


def test_classic_task_files_are_pinned() -> None:
    """The classic files never change (issue 25): their bytes are pinned here."""
    import hashlib

    for subset, sha in CLASSIC_SHA256.items():
        assert hashlib.sha256((TASK_DIR / f"{subset}.json").read_bytes()).hexdigest() == sha, subset


def test_task_file_param_takes_a_file_or_a_folder(tmp_path: Path) -> None:
    from eb_core.taskfile import TaskFileError as Core
    from eb_habitat.env import HabitatEnv
    from eb_habitat.splits import write_split

    assert TaskFileError is Core
    paths = write_split(str(tmp_path), "val", 6)
    assert all(isinstance(p, Path) for p in paths) and len(paths) == 6
    folder = HabitatEnv.load_tasks(task_file=str(tmp_path))
    assert len(folder) == 6 and folder == HabitatEnv.load_tasks(task_dir=str(tmp_path))
    assert [t.id for t in HabitatEnv.load_tasks(task_file=str(paths[0]))] == [folder[0].id]
