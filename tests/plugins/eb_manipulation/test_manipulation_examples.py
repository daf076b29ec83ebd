"""In-context examples: hard scenes get examples that show what the hard set asks (a shape turned to its hole's
outline, a flush tower, a stroke the way the arrow points); classic scenes keep the paper's examples."""

from __future__ import annotations

import json
import re

import pytest
from eb_manipulation.env import ManipulationEnv
from eb_manipulation.prompts import EXAMPLE_COUNTS, EXAMPLES_FILE, HARD_EXAMPLES_FILE, uses_hard_examples
from eb_manipulation.tasks import load_task_file, scene_of

FAMILIES = ("pick", "stack", "sorter", "wipe")


@pytest.fixture(scope="module")
def hard_doc():
    return json.loads(HARD_EXAMPLES_FILE.read_text())


def _answer(example: str) -> tuple[str, dict]:
    """(instruction, answer JSON) of one example text."""
    head, answer = example.split("\nAnswer:\n", 1)
    return head.split("\n", 1)[0].removeprefix("Instruction: "), json.loads(answer)


def _carries(plan: list[list[int]]) -> list[tuple[int, int, list[int], list[int]]]:
    """Per object carried: (yaw bin when the gripper closed, yaw bin when it opened, closing action, opening
    action), read from the gripper values of an executable plan."""
    out, was_open, grab = [], True, None
    for a in plan:
        if was_open and a[6] == 0:
            grab = a
        elif not was_open and a[6] == 1 and grab is not None:
            out.append((grab[5], a[5], grab, a))
            grab = None
        was_open = bool(a[6])
    return out


def _stroke_axis(example: str) -> str:
    plan = [step["action"] for step in _answer(example)[1]["executable_plan"]]
    a, b = plan[-2], plan[-1]
    return "y" if abs(b[1] - a[1]) > abs(b[0] - a[0]) else "x"


def test_hard_scenes_get_the_hard_examples_and_classic_scenes_the_papers():
    classic_doc = json.loads(EXAMPLES_FILE.read_text())["examples"]
    hard_doc = json.loads(HARD_EXAMPLES_FILE.read_text())["examples"]
    hard = {t.id: t for t in load_task_file(taskset="hard")}
    classic = {t.id: t for t in load_task_file(taskset="classic")}
    env, multi = ManipulationEnv(render=False), ManipulationEnv(render=False, multi_view=True)
    try:
        for family in FAMILIES:
            task = hard[f"base_{family}_00"]
            assert uses_hard_examples(scene_of(task))
            env.reset(task, 0)
            parts = env.prompt_parts()
            assert list(parts.examples) == hard_doc[family]["baseline"]
            assert list(parts.examples_language_only) == hard_doc[family]["language_only"]
            assert len(parts.examples) == EXAMPLE_COUNTS[family] and len(parts.visual_examples) == 2
            assert not any("visual_state_description" in ex for ex in parts.examples_language_only)
            multi.reset(task, 0)
            other = multi.prompt_parts()
            assert list(other.examples) == hard_doc[family]["ablation"]
            assert [v.text for v in other.visual_examples] == list(other.examples[:2])
            if family == "wipe":  # the same structure as the paper's sets: grouped by axis, then alternating
                assert [_stroke_axis(ex) for ex in parts.examples] == ["y"] * 4 + ["x"] * 4
                assert [_stroke_axis(ex) for ex in other.examples] == ["y", "x"] * 4
            task = classic[f"base_{family}_00"]
            assert not uses_hard_examples(scene_of(task))
            env.reset(task, 0)
            assert list(env.prompt_parts().examples) == classic_doc[family]["baseline"]
    finally:
        env.close()
        multi.close()


def test_hard_sorter_examples_turn_each_shape_to_its_outline(hard_doc):
    """Each sorter example sorts two shapes; each is released turned against its grasp, and the reasoning and the
    language plan say by how much and which way (a larger yaw: counter-clockwise seen from above)."""
    for example in hard_doc["examples"]["sorter"]["baseline"]:
        _, answer = _answer(example)
        plan = [s["action"] for s in answer["executable_plan"]]
        carries = _carries(plan)
        assert len(carries) == 2, example[:200]
        reason = answer["reasoning_and_reflection"]
        assert "outline" in reason and "larger yaw turns the gripper" in reason
        for grab, drop, _, _ in carries:
            delta = drop - grab
            assert delta != 0
            way = "counter-clockwise" if delta > 0 else "clockwise"
            said = f"turn the gripper {abs(delta) * 3} degrees {way} to yaw {drop}"
            assert said in reason, (said, reason)
            assert f"turning it {abs(delta) * 3} degrees {way} (yaw {grab} to {drop})" in answer["language_plan"]


def test_hard_stack_examples_line_each_cube_up(hard_doc):
    for example in hard_doc["examples"]["stack"]["baseline"]:
        instruction, answer = _answer(example)
        assert "flush" in instruction or "line up" in instruction
        reason = answer["reasoning_and_reflection"]
        assert "flush" in reason
        carries = _carries([s["action"] for s in answer["executable_plan"]])
        assert carries
        for grab, drop, _, _ in carries:
            delta = drop - grab
            way = "counter-clockwise" if delta > 0 else "clockwise"
            assert f"with yaw {drop}, turned {abs(delta) * 3} degrees {way}" in reason, reason


_WAYS = {"to the right": (1, +1), "to the left": (1, -1), "toward the camera": (0, +1), "away from the camera": (0, -1)}


def test_hard_wipe_examples_stroke_the_way_the_arrow_points(hard_doc):
    """The reasoning reads the target area's arrow, the visual description shows it, and the plan's pressed stroke
    runs that way (x grows toward the camera, y to the right)."""
    for example in hard_doc["examples"]["wipe"]["baseline"]:
        instruction, answer = _answer(example)
        assert "arrow" in instruction
        reason = answer["reasoning_and_reflection"]
        m = re.search(r"The arrow printed on (object \d+) points (.+?) in the image", reason)
        assert m, reason
        area, way = m.group(1), m.group(2)
        assert f"{area} is " in answer["visual_state_description"]
        described = answer["visual_state_description"].split(f"{area} is ", 1)[1].split(";")[0]
        assert f"with its arrow pointing {way}" in described
        plan = [s["action"] for s in answer["executable_plan"]]
        axis, sign = _WAYS[way]
        assert (plan[-1][axis] - plan[-2][axis]) * sign > 0


def test_hard_examples_are_held_out(hard_doc):
    """No example is a shipped task: their instructions and object lists appear in neither task set."""
    shipped = {t.instruction for t in load_task_file(taskset="hard")} | {
        t.instruction for t in load_task_file(taskset="classic")}
    for family in FAMILIES:
        for example in hard_doc["examples"][family]["baseline"]:
            assert _answer(example)[0] not in shipped
    assert hard_doc["seed"] != json.loads(EXAMPLES_FILE.read_text())["seed"]
