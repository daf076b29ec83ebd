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
    _breaks(tmp_path, doc, "task base-03", "metadata.objects[1].at", "unknown receptacle 'bathtub'")


def test_bad_goal_predicate(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][7]["metadata"]["goal"][0] = "(on ?apple fridge)"
    _breaks(tmp_path, doc, "task base-07", "metadata.goal[0]", "use (inside")


def test_missing_field(tmp_path: Path) -> None:
    doc = _doc()
    del doc["tasks"][5]["metadata"]["subgoals"]
    _breaks(tmp_path, doc, "task base-05", "metadata.subgoals", "Field required")


def test_misspelled_field(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][2]["metadata"]["goals"] = doc["tasks"][2]["metadata"]["goal"]
    _breaks(tmp_path, doc, "task base-02", "metadata.goals", "unknown field")


def test_wrong_colour_and_slot(tmp_path: Path) -> None:
    doc = _doc()
    doc["tasks"][0]["metadata"]["objects"][0]["color"] = "tartan"
    _breaks(tmp_path, doc, "task base-00", "metadata.objects[0].color", "tartan")
    doc = _doc()
    doc["tasks"][0]["metadata"]["objects"][0]["slot"] = 9
    _breaks(tmp_path, doc, "task base-00", "metadata.objects[0].slot", "slot 9")


def test_goal_already_met(tmp_path: Path) -> None:
    doc = _doc()
    meta = doc["tasks"][1]["metadata"]
    obj = meta["objects"][0]
    meta["goal"] = [f"({'inside' if obj['at'] in ('fridge', 'left_drawer', 'right_drawer', 'cabinet') else 'on'} "
                    f"{obj['name']} {obj['at']})"]
    _breaks(tmp_path, doc, "task base-01", "metadata.goal", "already holds")


def test_version_and_json(tmp_path: Path) -> None:
    doc = _doc()
    doc["version"] = 1  # the pre-repair task files (fixed kitchen rows, word-matchable spatial tasks)
    msg = _breaks(tmp_path, doc, "version 1 is not supported", "reads version 2", "eb tasks generate env=habitat")
    assert msg.count("Regenerate") == 1
    path = tmp_path / "broken.json"
    path.write_text('{"format": "eb-habitat-tasks",')
    with pytest.raises(TaskFileError, match="not valid JSON"):
        load_task_file(path)


def test_duplicate_id_across_files(tmp_path: Path) -> None:
    doc = _doc()
    _write(tmp_path, doc)
    (tmp_path / "common_sense.json").write_text(json.dumps({**doc, "subset": "common_sense", "tasks": [
        {**doc["tasks"][0], "subset": "common_sense"}]}))
    with pytest.raises(TaskFileError, match="also defined in"):
        load_tasks(tmp_path)
