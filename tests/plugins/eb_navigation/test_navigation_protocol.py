"""The original's navigation protocol through the core planner: same first prompt for every task but the
instruction, 1-2 then 5-6 actions, what the overhead image is, visual in-context examples, chat window 5."""

from __future__ import annotations

import io
import itertools
import re
from pathlib import Path

import pytest
import yaml
from PIL import Image

from eb_core.config import EnvConfig, PlannerConfig
from eb_core.env import VisualExample
from eb_core.model import ImagePart, TextPart
from eb_core.planner import VLMPlanner
from eb_navigation.env import NavigationEnv
from eb_navigation.geometry import ACTION_NAMES
from eb_navigation.prompts import EXAMPLES

YAML = Path(__import__("eb_navigation").__file__).parent / "conf" / "env" / "navigation.yaml"


def env_config(**over) -> EnvConfig:
    raw = yaml.safe_load(YAML.read_text())
    raw.update(over)
    return EnvConfig.model_validate(raw)


@pytest.fixture(scope="module")
def sample_tasks():
    tasks = {t.id: t for t in NavigationEnv.load_tasks()}
    # two rooms, every subset, and the visual task whose target differs from base's
    return [tasks[f"{s}_{n:03d}"] for n in (0, 1) for s in
            ("base", "common_sense", "complex_instruction", "visual_appearance", "long_horizon")]


def first_request(env: NavigationEnv, task, planner_cfg: PlannerConfig, cfg: EnvConfig):
    obs = env.reset(task, 0)
    planner = VLMPlanner(planner_cfg, cfg, supports_json_schema=False)
    planner.reset(task, env.prompt_parts(), env.action_space(), obs)
    return planner, planner.build_request(obs), obs


def _texts(req) -> str:
    return "\n".join(p.text for m in req.messages for p in m.content if isinstance(p, TextPart))


@pytest.mark.parametrize("mode", ["images", "language_only", "multi_view"])
def test_first_prompts_differ_only_in_the_instruction(sample_tasks, mode: str) -> None:
    cfg = env_config(multi_view=mode == "multi_view", resolution=64)
    planner_cfg = PlannerConfig(language_only=mode == "language_only")
    env = NavigationEnv(resolution=64, multi_view=mode == "multi_view", render=mode != "language_only")
    prompts = {}
    try:
        for task in sample_tasks:
            _, req, obs = first_request(env, task, planner_cfg, cfg)
            assert obs.extra_prompt is None
            n_images = sum(isinstance(p, ImagePart) for m in req.messages for p in m.content)
            assert n_images == {"images": 1, "language_only": 0, "multi_view": 2}[mode]
            text = _texts(req)
            assert text.count(task.instruction) == 1
            prompts[task.id] = text.replace(task.instruction, "<INSTRUCTION>")
    finally:
        env.close()
    for (a, pa), (b, pb) in itertools.combinations(prompts.items(), 2):
        assert pa == pb, f"first prompts of {a} and {b} differ beyond the instruction"
    if mode == "language_only":  # no scene text: the blind baseline sees the instruction only
        assert "In view:" not in next(iter(prompts.values()))


def test_first_call_asks_for_1_2_actions_later_calls_5_6(sample_tasks) -> None:
    env = NavigationEnv(render=False)
    try:
        planner, req, _ = first_request(env, sample_tasks[0], PlannerConfig(language_only=True), env_config())
        assert "about 1-2 actions" in _texts(req) and "5-6" not in _texts(req)
        result = env.step(0)
        planner.record_action(1, ACTION_NAMES[0], "0", result.action_success, result.feedback)
        later = _texts(planner.build_request(result.observation))
        assert "about 5-6 actions" in later and "1-2" not in later
    finally:
        env.close()


def test_multi_view_says_which_image_is_the_overhead_view_and_which_mark_is_the_agent(sample_tasks) -> None:
    env = NavigationEnv(resolution=64, multi_view=True)
    try:
        _, req, _ = first_request(env, sample_tasks[0], PlannerConfig(), env_config(multi_view=True))
    finally:
        env.close()
    text = _texts(req)
    assert "Image 1: your own first-person view" in text
    assert re.search(r"Image 2: the whole room seen from above; you are the round blue marker", text)


def test_chat_history_window_is_the_originals_five() -> None:
    assert env_config().chat_history_window == 5


def test_text_examples_are_multi_round_episodes_with_valid_action_ids() -> None:
    assert len(EXAMPLES) == 3
    for ex in EXAMPLES:
        assert ex.startswith("Instruction: ") and ex.count("Plan: ") >= 3 and ex.count("Feedback: ") >= 3
        for ids in re.findall(r"\[(\d)\] ([A-Za-z ]+?)(?:,|\n|$)", ex):
            assert ACTION_NAMES[int(ids[0])].startswith(ids[1].strip()), ids


def test_visual_examples_are_our_rendered_episodes() -> None:
    env = NavigationEnv(render=False)
    parts = env.prompt_parts()
    env.close()
    assert len(parts.visual_examples) >= 2
    for ex in parts.visual_examples:
        assert isinstance(ex, VisualExample) and ex.text.count("<image>") == len(ex.images) >= 2
        assert "episode ended" in ex.text
        for png in ex.images:
            img = Image.open(io.BytesIO(png))
            assert img.format == "PNG" and 256 <= img.width <= 500 and img.height == img.width
            assert len(png) < 120_000  # keeps the wheel light
            assert max(img.convert("L").getextrema()) - min(img.convert("L").getextrema()) > 100  # a real render


def test_visual_icl_request_carries_the_example_images(sample_tasks) -> None:
    env = NavigationEnv(resolution=64)
    try:
        _, req, _ = first_request(env, sample_tasks[0], PlannerConfig(visual_icl=True), env_config(resolution=64))
    finally:
        env.close()
    parts = req.messages[-1].content
    example_images = [p for p in parts if isinstance(p, ImagePart) and p.name.startswith("example-")]
    n = sum(len(ex.images) for ex in env.prompt_parts().visual_examples)
    assert len(example_images) == n and isinstance(parts[-1], ImagePart)  # the current view comes last


def test_the_rules_give_the_body_width_the_world_collides_with() -> None:
    """A calibration player lost hard tasks to gaps that looked passable and to furniture beside it: the rules say
    how wide the body is (the collision disc of geometry.AGENT_RADIUS, so the two cannot drift apart) and that a
    sideways move can bump into what no image showed; blind play gets the width but not the camera sentence."""
    from eb_navigation.geometry import AGENT_RADIUS
    from eb_navigation.prompts import ACTION_RULES, ACTION_RULES_LANGUAGE_ONLY

    width = f"about {2 * AGENT_RADIUS:g} metres across"
    assert width in ACTION_RULES and width in ACTION_RULES_LANGUAGE_ONLY
    assert "a sideways or backward move can bump into something" in ACTION_RULES
    assert "no image" not in ACTION_RULES_LANGUAGE_ONLY
    # session 10: a player walked into a low table just ahead that the level camera did not show; the rules say how
    # much floor the level view leaves out (from the camera's own height and field of view) and to tilt down
    import math

    from eb_navigation.geometry import EYE_HEIGHT, FIRST_PERSON_FOVY

    hidden = EYE_HEIGHT / math.tan(math.radians(FIRST_PERSON_FOVY / 2))
    assert f"the floor within about {hidden:.1f} metres in front of you is out of the picture" in ACTION_RULES
    assert "tilt the camera down" in ACTION_RULES and "picture" not in ACTION_RULES_LANGUAGE_ONLY
    env = NavigationEnv(render=False)
    try:
        env.reset(NavigationEnv.load_tasks()[0], 0)
        assert width in env.prompt_parts().action_rules
    finally:
        env.close()
