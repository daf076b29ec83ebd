"""ManipulationEnv against the core's conformance suite (rendered and simulation-only), and its own rules."""

from __future__ import annotations

import numpy as np
import pytest
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
    # object k is labelled str(k), numbered by decreasing y, with discrete coordinates in the prompt
    labels = [o.label for o in obs.objects]
    assert labels == [str(i + 1) for i in range(len(obs.objects))]
    ys = [o.position[1] for o in obs.objects]
    assert ys == sorted(ys, reverse=True)
    for o in obs.objects:
        assert f'"{o.name}": [{", ".join(str(int(v)) for v in o.position)}]' in obs.extra_prompt
        assert o.box is not None, f"{o.name} ({o.type}) has no box"
    assert any(o.type.endswith("hole of the shape sorter") for o in obs.objects)
    assert any(o.is_target for o in obs.objects)
    # language-only description names colours and shapes with the same coordinates
    assert "object 1:" in obs.text and "The gripper is open" in obs.text


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


def test_prompt_parts_have_four_examples_of_the_episodes_family(env: ManipulationEnv, tasks) -> None:
    for family in ("pick", "stack", "sorter", "wipe"):
        env.reset(tasks[f"base_{family}_00"], 0)
        parts = env.prompt_parts()
        assert len(parts.examples) == 4
        assert all('"executable_plan"' in ex for ex in parts.examples)
        assert "[x, y, z, roll, pitch, yaw, gripper]" in parts.action_rules


def test_same_task_same_first_image(tasks) -> None:
    e = ManipulationEnv(resolution=128)
    try:
        a = e.reset(tasks["visual_pick_03"], 0).images["front"]
        b = e.reset(tasks["visual_pick_03"], 5).images["front"]
    finally:
        e.close()
    assert np.array_equal(a, b)
