"""ManipulationEnv against the core's conformance suite (rendered and simulation-only), and its own rules."""

from __future__ import annotations

import io
import json
import re

import numpy as np
import pytest
from PIL import Image
from pydantic import ValidationError

from eb_core.env import VectorActionSpace
from eb_core.testing import EnvConformanceSuite
from eb_manipulation.env import ManipulationEnv
from eb_manipulation.plugin import SUBSETS


class TestManipulationConformanceRendered(EnvConformanceSuite):
    env_class = "eb_manipulation.env:ManipulationEnv"
    env_params = {"resolution": 160}
    expect_subsets = SUBSETS
    sample_size = 2
    max_env_steps = 15


class TestManipulationConformanceSimulation(EnvConformanceSuite):
    env_class = "eb_manipulation.env:ManipulationEnv"
    env_params = {"render": False}
    expect_subsets = SUBSETS
    sample_size = 6
    max_env_steps = 15


@pytest.fixture(scope="module")
def tasks():
    return {t.id: t for t in ManipulationEnv.load_tasks()}


@pytest.fixture(scope="module")
def env():
    e = ManipulationEnv(resolution=200, multi_view=True)
    yield e
    e.close()


def test_unknown_param_is_rejected() -> None:
    with pytest.raises(ValidationError, match="rendr"):
        ManipulationEnv(rendr=False)


def test_action_space_is_the_papers_vector() -> None:
    space = ManipulationEnv(render=False).action_space()
    assert space == VectorActionSpace(names=("x", "y", "z", "roll", "pitch", "yaw", "gripper"), low=(0,) * 7,
                                      high=(100, 100, 100, 120, 120, 120, 1))


def test_observation_front_wrist_boxes_and_object_list(env: ManipulationEnv, tasks) -> None:
    obs = env.reset(tasks["base_sorter_00"], 0)
    assert obs.primary == "front" and set(obs.images) == {"front", "wrist"}
    for img in obs.images.values():
        assert img.shape == (200, 200, 3) and img.dtype == np.uint8 and img.std() > 10
    # object k is labelled str(k), numbered by ascending y (left to right in the front image), as the original
    labels = [o.label for o in obs.objects]
    assert labels == [str(i + 1) for i in range(len(obs.objects))]
    ys = [o.position[1] for o in obs.objects]
    assert ys == sorted(ys)
    listing = json.loads(obs.extra_prompt)
    assert list(listing) == [o.name for o in obs.objects]
    for o in obs.objects:
        assert listing[o.name] == [int(v) for v in o.position]
        assert o.box is not None, f"{o.name} ({o.type}) has no box"
    assert any(o.type.endswith("hole of the shape sorter") for o in obs.objects)
    assert any(o.is_target for o in obs.objects)
    # language-only models get the index + coordinate list and nothing else: no colour, no shape, no kind
    words = set(re.findall(r"[a-z]+", (obs.extra_prompt + obs.text).lower()))
    assert words == {"object"}, words
    # people still get a full description
    assert "hole of the shape sorter" in env.describe() and "The gripper is open" in env.describe()


def test_object_list_is_read_again_after_every_action(tasks) -> None:
    """Carrying an object from left to right changes the numbering, and the feedback uses the new numbers."""
    e = ManipulationEnv(render=False)
    try:
        task = next(t for t in e.load_tasks() if t.metadata["family"] == "pick"
                    and t.metadata["oracle_steps"] == 4)
        obs = e.reset(task, 0)
        before = json.loads(obs.extra_prompt)
        plan = e.expert_plan()
        results = [e.step(a) for a in plan[:-1]]  # the object is held above the container
        after = json.loads(results[-1].observation.extra_prompt)
        assert after != before and set(after) == set(before)
        held = results[-1].info["held"]
        ys = [v[1] for v in after.values()]
        assert ys == sorted(ys)
        assert held in results[1].feedback or held in after
    finally:
        e.close()


def test_boxes_and_axes_are_drawn_on_the_front_image(tasks) -> None:
    plain = ManipulationEnv(resolution=200, detection_boxes="none", draw_axes=False)
    boxed = ManipulationEnv(resolution=200)
    try:
        a = plain.reset(tasks["base_pick_00"], 0).images["front"].astype(int)
        obs = boxed.reset(tasks["base_pick_00"], 0)
        b = obs.images["front"].astype(int)
    finally:
        plain.close()
        boxed.close()
    changed = np.abs(a - b).sum(axis=2) > 60
    assert changed.mean() > 0.005
    x0, y0, x1, y1 = obs.objects[0].box
    # the box outline of object 1 is drawn
    assert changed[max(y0 - 1, 0), x0:x1].mean() > 0.5 or changed[y0:y1, max(x0 - 1, 0)].mean() > 0.5
    # the red axes: strongly red pixels appear
    red = (b[..., 0] > 200) & (b[..., 1] < 60) & (b[..., 2] < 60)
    assert red.sum() > 30


def test_invalid_vector_fails_without_moving(env: ManipulationEnv, tasks) -> None:
    env.reset(tasks["base_stack_00"], 0)
    r = env.step((10, 10, 10, 200, 60, 60, 1))
    assert not r.action_success and "roll=200" in r.feedback and "did not move" in r.feedback
    r = env.step((1, 2, 3))
    assert not r.action_success


def test_pose_inside_the_table_fails_with_reason(env: ManipulationEnv, tasks) -> None:
    env.reset(tasks["base_stack_00"], 0)
    r = env.step((40, 50, 5, 120, 60, 60, 1))  # 10 cm below the table top
    assert not r.action_success and "table" in r.feedback


def test_unreachable_pose_fails_with_reason(env: ManipulationEnv, tasks) -> None:
    env.reset(tasks["base_stack_00"], 0)
    r = env.step((99, 50, 20, 120, 60, 60, 1))  # 1 m in front of the robot
    assert not r.action_success and "cannot reach" in r.feedback


def _stroke_axis(example: str) -> str:
    """The axis of a wiping example's stroke, read from its last two actions."""
    plan = json.loads(example.split("Answer:\n", 1)[1])["executable_plan"]
    a, b = plan[-2]["action"], plan[-1]["action"]
    return "y" if abs(a[1] - b[1]) > abs(a[0] - b[0]) else "x"


def test_prompt_parts_follow_the_original_protocol(tasks) -> None:
    """Text before the image, the colour list, the original's example counts and sets by condition."""
    counts = {"pick": 2, "stack": 4, "sorter": 4, "wipe": 8}
    plain = ManipulationEnv(render=False)
    multi = ManipulationEnv(render=False, multi_view=True)
    try:
        for family, n in counts.items():
            plain.reset(tasks[f"base_{family}_00"], 0)
            parts = plain.prompt_parts()
            assert parts.text_before_images and not parts.view_descriptions
            assert len(parts.examples) == n and len(parts.examples_language_only) == n
            assert all('"visual_state_description"' in ex for ex in parts.examples)
            assert not any("visual_state_description" in ex for ex in parts.examples_language_only)
            assert "[x, y, z, roll, pitch, yaw, gripper]" in parts.action_rules
            assert "red, maroon, lime, green, blue, navy" in parts.action_rules and "ascending y" in parts.action_rules
            multi.reset(tasks[f"base_{family}_00"], 0)
            other = multi.prompt_parts()
            assert "wrist" in other.view_descriptions
            assert sorted(other.examples) == sorted(parts.examples)
            if family == "wipe":  # baseline: strokes grouped by axis; other conditions: alternating
                assert [_stroke_axis(ex) for ex in parts.examples] == ["y"] * 4 + ["x"] * 4
                assert [_stroke_axis(ex) for ex in other.examples] == ["y", "x"] * 4
            assert len(parts.visual_examples) == 2
            for vex in parts.visual_examples:
                img = Image.open(io.BytesIO(vex.images[0]))
                assert img.size[0] >= 300 and np.asarray(img.convert("RGB")).std() > 10
                assert vex.text in other.examples[:2]
    finally:
        plain.close()
        multi.close()


def test_same_task_same_first_image(tasks) -> None:
    e = ManipulationEnv(resolution=128)
    try:
        a = e.reset(tasks["visual_pick_03"], 0).images["front"]
        b = e.reset(tasks["visual_pick_03"], 5).images["front"]
    finally:
        e.close()
    assert np.array_equal(a, b)
