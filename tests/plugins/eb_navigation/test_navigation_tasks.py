"""The shipped task file: its shape, the generator's guarantees, and one-line errors for bad files."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from eb_navigation.env import NavigationEnv, build_room
from eb_navigation.generate import GENERATOR_VERSION
from eb_navigation.instructions import colour_word, display_name
from eb_navigation.tasks import DEFAULT_TASK_FILE, SUBSETS, TASK_FILE_VERSION, TaskFileError, load_task_file


@pytest.fixture(scope="module")
def shipped():
    return load_task_file()


def test_shipped_file_is_versioned_and_records_its_generator(shipped) -> None:
    assert shipped.version == TASK_FILE_VERSION == 3 and DEFAULT_TASK_FILE.name == "navigation_v3.json"
    g = shipped.generator
    assert g["function"] == "eb_navigation.generate:generate" and g["generator_version"] == GENERATOR_VERSION
    assert g["max_oracle_steps"] == 15 and "scenekit_version" in g
    assert g["scenes"] == 60 and g["min_distance"] == 2.5 and g["max_distance"] == 3.5 and "seed" in g
    assert g["blind_cap"] == 2 and g["rule_cap"] == 6


def test_300_tasks_in_5_subsets_over_60_distinct_scenes(shipped) -> None:
    tasks = shipped.tasks
    assert len(tasks) == 300
    for s in SUBSETS:
        assert sum(t.subset == s for t in tasks) == 60
    scenes = {(t.scene.kind, t.scene.seed) for t in tasks}
    assert len(scenes) == 60
    # room by room, so a run in file order compiles each room once
    assert [t.subset for t in tasks[:10]] == list(SUBSETS) * 2
    assert all(t.scene == tasks[5 * (k // 5)].scene for k, t in enumerate(tasks))
    kinds = {k for k, _ in scenes}
    assert kinds == {"kitchen", "living_room", "bedroom", "bathroom"}
    for s in SUBSETS:
        assert len({t.target.type for t in tasks if t.subset == s}) >= 10, s


def test_start_distances_and_oracle_budget(shipped) -> None:
    for t in shipped.tasks:
        d = math.hypot(t.start.x - t.target.position[0], t.start.y - t.target.position[1])
        far = 4.5 if t.subset == "long_horizon" else 3.5
        assert 2.5 - 1e-6 <= d <= far + 1e-6, t.id
        assert t.oracle_steps <= (17 if t.subset == "long_horizon" else 15), t.id


def test_subsets_derive_from_base(shipped) -> None:
    by_id = {t.id: t for t in shipped.tasks}
    for n in range(60):
        base = by_id[f"base_{n:03d}"]
        for s in ("common_sense", "complex_instruction", "long_horizon"):
            other = by_id[f"{s}_{n:03d}"]
            assert other.scene == base.scene and other.target == base.target
        for s in ("common_sense", "complex_instruction"):
            assert by_id[f"{s}_{n:03d}"].start == base.start
        lh = by_id[f"long_horizon_{n:03d}"]  # another start, the target behind, a longer way
        assert lh.start != base.start and lh.oracle_steps >= base.oracle_steps + 2
        assert by_id[f"common_sense_{n:03d}"].instruction != base.instruction
        assert len(by_id[f"complex_instruction_{n:03d}"].instruction) > 2 * len(base.instruction)
        vis = by_id[f"visual_appearance_{n:03d}"]  # same room; same target unless it had no room for a twin
        assert vis.scene == base.scene
        assert vis.extra_objects and all(e.type == vis.target.type and e.colour != vis.target.colour
                                         for e in vis.extra_objects)
        assert colour_word(vis.target.colour) in vis.instruction
        # the plain name of the target appears in base but not in common_sense or visual_appearance
        name = display_name(base.target.type)
        assert name in base.instruction
        assert name not in by_id[f"common_sense_{n:03d}"].instruction
        assert display_name(vis.target.type) not in vis.instruction


def test_wording_is_varied_unique_and_grammatical(shipped) -> None:
    from eb_core.audit import grammar_issues

    for s in SUBSETS:
        ts = [t for t in shipped.tasks if t.subset == s]
        assert all(t.template.startswith(f"{s}.") for t in ts)
        assert len({t.template for t in ts}) >= 10, s
        assert len({t.instruction.lower() for t in ts}) >= 0.95 * len(ts), s
        for t in ts:
            assert not grammar_issues(t.instruction), (t.id, t.instruction)
    # complex requests carry no signpost that points at the request
    for t in shipped.tasks:
        if t.subset == "complex_instruction":
            low = t.instruction.lower()
            assert "what i need" not in low and "is simple" not in low and "only thing" not in low, t.id


def test_lookalikes_differ_clearly_in_colour(shipped) -> None:
    from eb_navigation.generate import MIN_COLOUR_DISTANCE
    from eb_navigation.room import colour_distance

    for t in shipped.tasks:
        if t.subset == "visual_appearance":
            colours = [t.target.colour] + [e.colour for e in t.extra_objects]
            for i, a in enumerate(colours):
                for b in colours[i + 1:]:
                    assert colour_distance(a, b) >= MIN_COLOUR_DISTANCE, (t.id, a, b)


def test_long_horizon_plans_are_longer_than_base(shipped) -> None:
    mean = {s: sum(t.oracle_steps for t in shipped.tasks if t.subset == s) / 60 for s in SUBSETS}
    assert mean["long_horizon"] >= mean["base"] + 2


def test_tasks_match_their_rebuilt_rooms(shipped) -> None:
    # (the oracle test resets every task, which checks all of them; here the first rooms, with and without extras)
    for t in shipped.tasks[:10]:
        room = build_room(t)  # raises if the room no longer matches the file
        assert {e.id for e in t.extra_objects} <= set(room.index)


def test_load_tasks_gives_core_tasks() -> None:
    tasks = NavigationEnv.load_tasks()
    assert len(tasks) == 300 and tasks[0].id == "base_000"
    assert {"scene", "start", "target", "extra_objects", "oracle_steps", "template"} <= set(tasks[0].metadata)


def _write(tmp_path: Path, doc) -> Path:
    p = tmp_path / "tasks.json"
    p.write_text(json.dumps(doc) if not isinstance(doc, str) else doc)
    return p


@pytest.fixture()
def raw() -> dict:
    return json.loads(DEFAULT_TASK_FILE.read_text())


@pytest.mark.parametrize(
    ("mutate", "expect"),
    [
        (lambda d: d["tasks"][3]["start"].pop("x"), r"task 'visual_appearance_000': field start.x: is missing"),
        (lambda d: d["tasks"][5]["start"].update(x=1.3), r"task 'base_001': field start.x: .*multiple of 0.25"),
        (lambda d: d["tasks"][7]["start"].update(yaw=45),
         r"task 'complex_instruction_001': field start.yaw: .*0, 90, 180 or 270"),
        (lambda d: d["tasks"][2].update(subset="spatial"), r"task 'complex_instruction_000': field subset:"),
        (lambda d: d["tasks"][1]["scene"].update(kind="garage"), r"task 'common_sense_000': field scene.kind:"),
        (lambda d: d["tasks"][0]["target"].update(type="spaceship"), r"field target.type: .*unknown object type"),
        (lambda d: d["tasks"][0]["target"].update(colour="plaid"), r"task 'base_000': field target: .*no colour 'plaid'"),
        (lambda d: d["tasks"][3]["extra_objects"][0].update(type="Spaceship"),
         r"task 'visual_appearance_000': field extra_objects.0.type: .*unknown object type"),
        (lambda d: d["tasks"][4].update(colour="red"), r"task 'long_horizon_000': field colour: is not a known field"),
        (lambda d: d["tasks"][4].pop("template"), r"task 'long_horizon_000': field template: is missing"),
        (lambda d: d.pop("version"), r"tasks.json: field version: is missing"),
    ],
)
def test_malformed_file_fails_with_one_clear_line(tmp_path: Path, raw: dict, mutate, expect: str) -> None:
    mutate(raw)
    path = _write(tmp_path, raw)
    with pytest.raises(TaskFileError, match=expect) as info:
        load_task_file(path)
    msg = str(info.value)
    assert "\n" not in msg and str(path) in msg


def test_not_json_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(TaskFileError, match="not valid JSON"):
        load_task_file(_write(tmp_path, "{oops"))
    with pytest.raises(TaskFileError, match="task file not found"):
        load_task_file(tmp_path / "nope.json")


def test_duplicate_ids_and_old_file_version(tmp_path: Path, raw: dict) -> None:
    raw["tasks"][1]["id"] = raw["tasks"][0]["id"]
    with pytest.raises(TaskFileError, match="task 'base_000': field id: duplicate task id"):
        load_task_file(_write(tmp_path, raw))
    raw["tasks"][1]["id"] = "common_sense_000"
    for old in (1, 2):  # 1: the plugin's own rooms; 2: starts that a blind walk could solve
        raw["version"] = old
        with pytest.raises(TaskFileError, match=f"field version: the file is version {old} .*regenerate"):
            load_task_file(_write(tmp_path, raw))


def test_a_moved_target_is_caught_at_reset(tmp_path: Path, raw: dict) -> None:
    raw["tasks"] = raw["tasks"][:1]
    raw["tasks"][0]["target"]["position"][0] += 0.5
    path = _write(tmp_path, raw)
    env = NavigationEnv(task_file=str(path), render=False)
    task = NavigationEnv.load_tasks(task_file=str(path))[0]
    with pytest.raises(TaskFileError, match="no longer matches"):
        env.reset(task, 0)
    env.close()
