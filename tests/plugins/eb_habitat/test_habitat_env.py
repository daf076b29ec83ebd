"""HabitatEnv against the core's conformance suite, and its own behaviour."""

from __future__ import annotations

import pytest

from eb_core.testing import EnvConformanceSuite
from eb_habitat.env import HabitatEnv
from eb_habitat.plugin import SUBSETS


class TestHabitatConformanceSymbolic(EnvConformanceSuite):
    env_class = "eb_habitat.env:HabitatEnv"
    env_params = {"render": False}
    expect_subsets = SUBSETS
    sample_size = 12


def test_unknown_param_names_itself() -> None:
    with pytest.raises(ValueError, match="unknown param 'rendr'"):
        HabitatEnv(rendr=False)


def test_step_result_fields() -> None:
    env = HabitatEnv(render=False)
    task = HabitatEnv.load_tasks()[0]
    obs = env.reset(task, 0)
    assert obs.primary is None and "middle of the apartment" in obs.text
    plan = env.expert_plan()
    r = env.step(plan[0])
    assert r.action_success and r.info["agent_at"] and 0.0 <= r.progress < 1.0
    assert r.observation.objects and any(o.is_target for o in r.observation.objects)
    with pytest.raises(ValueError):
        env.step(70)
    env.close()
    env.close()


def test_the_decoration_in_the_images_is_part_of_the_scene_for_the_error_labels() -> None:
    """Every apartment draws a TV, lamps, a plant and paintings; a description naming them ("a ball in front of
    the TV", said by a strong model at the TV stand) speaks of the scene and is no hallucination."""
    from eb_core.errors import label_episode
    from eb_habitat.catalog import DECOR
    from eb_habitat.render import LAYOUTS

    assert {d[0] for layout in LAYOUTS for d in layout.decor} == set(DECOR)
    env = HabitatEnv(render=False)
    obs = env.reset(HabitatEnv.load_tasks()[0], 0)
    env.close()
    step = {"planner_step": 1, "parsed": {"visual_state_description": "At the TV stand: a small yellow ball in "
                                                                      "front of the TV foot."},
            "visible_objects": [{"name": "ball_5", "type": "ball", "colour": "yellow"}], "actions": []}

    def categories(scene_objects: list[str]) -> list[str]:
        lab = label_episode([dict(step, scene_objects=scene_objects)], vocabulary=["Television"])
        return [label["category"] for s in lab["steps"] for label in s["labels"]
                if label["category"] in ("hallucinated_object", "misperceived_object")]  # the plan is not judged here

    assert categories(list(obs.scene_objects or [])) == []
    # the same words against the scene without its decoration: the TV would count as imagined
    assert categories([t for t in obs.scene_objects or [] if t not in DECOR]) == ["hallucinated_object"]
