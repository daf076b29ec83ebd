"""The core's task-file envelope, its one-line errors, its cache and the generated-split source."""

from __future__ import annotations

import json
import os

import pytest
from pydantic import BaseModel, ConfigDict

from eb_core.taskfile import SplitSource, TaskFileError, TaskFileFormat, split_rng, task_set_digest


class Toy(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    id: str
    subset: str
    instruction: str
    size: int = 1


def _no_giants(t: Toy) -> tuple[str, str] | None:
    return ("size", f"{t.size} is larger than the room") if t.size > 10 else None


FMT = TaskFileFormat("toy", "eb-toy-tasks", 2, Toy, check=_no_giants, subsets=("base", "hard_one"))


def _tasks(n: int = 3) -> list[Toy]:
    return [Toy(id=f"base_{i}", subset="base", instruction=f"go to thing {i}") for i in range(n)]


def test_round_trip_and_cache(tmp_path):
    path = FMT.write(tmp_path / "t.json", _tasks(), generator={"seed": 7})
    first = FMT.read(path)
    assert [t.id for t in first] == ["base_0", "base_1", "base_2"]
    assert FMT.read(path) is first  # unchanged file: cached
    doc = json.loads(path.read_text())
    doc["tasks"] = doc["tasks"][:1]
    path.write_text(json.dumps(doc))
    os.utime(path, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns + 10_000_000))
    assert [t.id for t in FMT.read(path)] == ["base_0"]  # edited on disk: read again


@pytest.mark.parametrize(("mutate", "expected"), [
    (lambda d: d.update(version=1), "field version: the file is version 1 but this eb-toy reads version 2"),
    (lambda d: d.update(format="other"), "field format: 'other' is not 'eb-toy-tasks'"),
    (lambda d: d["tasks"][1].pop("instruction"), "task 'base_1': field instruction: is missing"),
    (lambda d: d["tasks"][0].update(colour="red"), "task 'base_0': field colour: is not a known field"),
    (lambda d: d["tasks"][2].update(size=11), "task 'base_2': field size: 11 is larger than the room"),
    (lambda d: d["tasks"][2].update(subset="nope"), "task 'base_2': field subset: unknown subset 'nope'"),
    (lambda d: d["tasks"][2].update(id="base_0"), "task 'base_0': field id: duplicate task id"),
    (lambda d: d.update(tasks={"a": 1}), "field tasks: must be a list"),
])
def test_each_problem_is_one_line_naming_file_task_and_field(tmp_path, mutate, expected):
    doc = FMT.envelope(_tasks())
    mutate(doc)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc) + "\n" + " " * 200_000)  # a big file is never echoed back
    with pytest.raises(TaskFileError) as info:
        FMT.read(path)
    msg = str(info.value)
    assert "\n" not in msg and len(msg) < 400
    assert msg.startswith(str(path)) and expected in msg


def test_missing_file_and_bad_json(tmp_path):
    with pytest.raises(TaskFileError, match="task file not found. Fix: "):
        FMT.read(tmp_path / "nope.json")
    (tmp_path / "b.json").write_text("{\"format\": ")
    with pytest.raises(TaskFileError, match=r"not valid JSON: .* line 1 column"):
        FMT.read(tmp_path / "b.json")


def test_read_many_names_both_files_of_a_duplicate(tmp_path):
    a = FMT.write(tmp_path / "a.json", _tasks(2), subset="base")
    b = FMT.write(tmp_path / "b.json", _tasks(1), subset="base")
    with pytest.raises(TaskFileError, match=r"b\.json: task 'base_0': field id: duplicate task id \(also in .*a\.json\)"):
        FMT.read_many([a, b])


def test_subset_of_a_per_subset_file_must_match(tmp_path):
    doc = FMT.envelope(_tasks(), subset="base")
    doc["subset"] = "hard_one"
    (tmp_path / "s.json").write_text(json.dumps(doc))
    with pytest.raises(TaskFileError, match="field subset: 'base' in a 'hard_one' file"):
        FMT.read(tmp_path / "s.json")


def test_split_source_is_deterministic_disjoint_and_copies():
    calls = []

    def draw(split: str, index: int, banned: frozenset[str] = frozenset()) -> Toy:
        calls.append((split, index))
        rng = split_rng("toy", split, index)
        return Toy(id=f"{split}_{index}", subset="base", instruction=f"thing {int(rng.integers(1_000_000))}")

    src = SplitSource("toy", draw)
    a = src.tasks("train", 0, 3, banned=frozenset({"x"}))
    b = src.tasks("train", 1, 2, banned=frozenset({"x"}))
    assert [t.id for t in a] == ["train_0", "train_1", "train_2"] and a[1] == b[0] and a[1] is not b[0]
    assert len(calls) == 3  # memoised
    assert src.tasks("val", 0, 1)[0].instruction != a[0].instruction
    with pytest.raises(ValueError, match="unknown split 'test'"):
        src.tasks("test", 0, 1)
    with pytest.raises(ValueError, match="start >= 0"):
        src.tasks("train", -1, 1)


def test_task_set_digest_changes_with_any_field():
    base = _tasks()
    assert task_set_digest(base) == task_set_digest(list(_tasks()))
    edited = list(base)
    edited[1] = edited[1].model_copy(update={"instruction": "go elsewhere"})
    assert task_set_digest(edited) != task_set_digest(base)
    assert task_set_digest(base[::-1]) != task_set_digest(base)
