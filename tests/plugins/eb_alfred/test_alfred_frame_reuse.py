"""A step that changes nothing in view is served from the last frame: same pixels and boxes as a draw.

Two rendered envs play the same actions -- the expert's plan with failing actions and repeated finds mixed
in -- one reusing frames (the default), one drawing every frame; every observation must be identical, and
the reusing env must have skipped the draws of the steps that changed nothing. Then the planner: an unchanged
image is not PNG-encoded again.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import eb_alfred
from eb_core.config import validate_config
from eb_core.env import Observation
from eb_core.planner import VLMPlanner, encode_png

from eb_alfred.env import AlfredEnv


def _task_that(verb: str):
    """The first base task whose expert plan has an action starting with ``verb``."""
    for t in AlfredEnv.load_tasks():
        if t.subset != "base":
            continue
        sym = AlfredEnv(render=False)
        sym.reset(t, 0)
        names = sym.action_space().actions
        if any(names[a].startswith(verb) for a in sym.expert_plan() or []):
            return t
    raise AssertionError(f"no base task opens with {verb!r}")


def _missing_find(env: AlfredEnv) -> int:
    """An action that fails and changes nothing: find a type the scene does not have."""
    present = {o.type for o in env.world.objects.values()}
    names = env.action_space().actions
    return next(i for i, a in enumerate(names) if a.startswith("find a ") and a[len("find a "):] not in present)


def _same(a: Observation, b: Observation) -> None:
    assert a.images.keys() == b.images.keys()
    for k in a.images:
        assert np.array_equal(a.images[k], b.images[k]), k
    assert [o.model_dump() for o in a.objects] == [o.model_dump() for o in b.objects]


@pytest.mark.parametrize(("verb", "multi_view"), [("open the", False), ("turn on", True)])
def test_reused_frames_equal_drawn_ones(verb: str, multi_view: bool) -> None:
    task = _task_that(verb)
    reusing = AlfredEnv(render=True, resolution=160, multi_view=multi_view)
    drawing = AlfredEnv(render=True, resolution=160, multi_view=multi_view)
    try:
        first = reusing.reset(task, 0)
        assert ("overhead" in first.images) == multi_view
        _same(first, drawing.reset(task, 0))
        drawing._renderer.reuse_frames = False
        plan = reusing.expert_plan()
        fail = _missing_find(reusing)
        actions: list[int] = [fail]
        for a in plan:
            actions += [a, fail, a]  # a state change, then two steps that change nothing (or a repeat)
        changed = 0
        for a in actions:
            drawn_before = reusing._renderer.frames_drawn
            ra, rb = reusing.step(a), drawing.step(a)
            assert (ra.action_success, ra.feedback) == (rb.action_success, rb.feedback)
            _same(ra.observation, rb.observation)
            if a == fail:
                assert reusing._renderer.frames_drawn == drawn_before, "a failed action drew a new frame"
            changed += reusing._renderer.frames_drawn - drawn_before
            if ra.done:
                break
        assert reusing._renderer.frames_reused >= len(plan)  # every inserted failure at least
        assert changed >= 2  # the plan's steps that changed the view were drawn, not reused
        assert drawing._renderer.frames_reused == 0
        # a reused frame is a copy: editing one observation's image cannot change the next one
        obs = reusing.step(fail).observation
        obs.images["first_person"][:] = 0
        assert reusing.step(fail).observation.images["first_person"].any()
    finally:
        reusing.close()
        drawing.close()


def test_unchanged_image_is_not_encoded_again() -> None:
    conf = yaml.safe_load((Path(list(eb_alfred.__path__)[0]) / "conf" / "env" / "alfred.yaml").read_text())
    cfg = validate_config({"env": conf, "model": {"name": "m", "backend": "litellm", "model_id": "openai/m"},
                           "planner": {"name": "vlm"}, "ablation": {"name": "none"}})
    env = AlfredEnv(render=True, resolution=96)
    try:
        task = AlfredEnv.load_tasks()[0]
        obs = env.reset(task, 0)
        planner = VLMPlanner(cfg.planner, cfg.env, supports_json_schema=False, supports_images=True)
        planner.reset(task, env.prompt_parts(), env.action_space(), obs)
        planner.build_request(obs)
        first = planner.last_primary_png
        assert first == encode_png(obs.primary_image)
        same = env.step(_missing_find(env)).observation
        assert same.primary_image is not obs.primary_image
        planner.build_request(same)
        assert planner.last_primary_png is first  # the same pixels: the same bytes, not encoded again
        moved = env.step(env.expert_plan()[0]).observation
        planner.build_request(moved)
        assert planner.last_primary_png != first
        assert planner.last_primary_png == encode_png(moved.primary_image)
    finally:
        env.close()
