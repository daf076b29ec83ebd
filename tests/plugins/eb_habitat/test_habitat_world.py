"""The symbolic world: the 70 skills, their preconditions and the feedback that says why an action failed."""

from __future__ import annotations

import pytest

from eb_habitat.catalog import OBJECT_TYPES, RECEPTACLES
from eb_habitat.skills import SKILL_NAMES, SKILLS, skill_id
from eb_habitat.world import World


def test_seventy_skills_in_five_kinds() -> None:
    assert len(SKILLS) == 70 and len(set(SKILL_NAMES)) == 70
    kinds = [s.kind for s in SKILLS]
    assert {k: kinds.count(k) for k in set(kinds)} == {"navigate": 15, "pick": 32, "place": 15, "open": 4, "close": 4}
    assert len(RECEPTACLES) >= 12 and len(OBJECT_TYPES) >= 25
    # ids are part of the benchmark: a few fixed points
    assert SKILL_NAMES[0] == "navigate to the left counter"
    assert SKILL_NAMES[skill_id("open", "fridge")] == "open the fridge"
    assert SKILL_NAMES[69] == "close the kitchen cabinet"


def _world() -> World:
    return World(
        [
            {"name": "apple_1", "type": "apple", "color": "red", "at": "fridge", "slot": 0},
            {"name": "mug_1", "type": "mug", "color": "blue", "at": "sofa", "slot": 1},
            {"name": "mug_2", "type": "mug", "color": "red", "at": "sofa", "slot": 0},
            {"name": "ball_1", "type": "ball", "color": "red", "at": "left_chair", "slot": 0},
        ]
    )


def act(w: World, kind: str, arg: str):
    return w.step(skill_id(kind, arg))


def test_pick_needs_to_be_at_the_receptacle_with_hand_empty() -> None:
    w = _world()
    out = act(w, "pick", "mug")
    assert not out.success and "not next to any receptacle" in out.feedback
    act(w, "navigate", "desk")
    out = act(w, "pick", "mug")
    assert not out.success and "no mug on the desk" in out.feedback
    act(w, "navigate", "sofa")
    out = act(w, "pick", "mug")
    assert out.success and "red mug" in out.feedback and w.held == "mug_2"  # leftmost instance
    out = act(w, "pick", "mug")
    assert not out.success and "already holds the red mug" in out.feedback


def test_closed_container_hides_and_blocks() -> None:
    w = _world()
    act(w, "navigate", "fridge")
    assert "closed, so you cannot see" in w.describe()
    assert w.visible_items() == []
    out = act(w, "pick", "apple")
    assert not out.success and "the fridge is closed" in out.feedback
    out = act(w, "close", "fridge")
    assert not out.success and "already closed" in out.feedback
    assert act(w, "open", "fridge").success
    assert "open" in w.describe() and "a red apple" in w.describe()
    assert not act(w, "open", "fridge").success
    assert act(w, "pick", "apple").success
    assert act(w, "close", "fridge").success
    out = act(w, "place", "fridge")
    assert not out.success and "it is closed" in out.feedback


def test_open_and_place_need_to_be_there() -> None:
    w = _world()
    out = act(w, "open", "left_drawer")
    assert not out.success and "out of reach" in out.feedback
    out = act(w, "place", "sofa")
    assert not out.success and "hand is empty" in out.feedback
    act(w, "navigate", "left_chair")
    assert act(w, "pick", "ball").success
    out = act(w, "place", "sofa")
    assert not out.success and "at the left chair" in out.feedback and "Navigate to the sofa" in out.feedback
    act(w, "navigate", "sofa")
    out = act(w, "place", "sofa")
    assert out.success and w.items["ball_1"].loc == "sofa" and w.items["ball_1"].slot == 2
    # the sofa holds 3: a fourth thing does not fit
    act(w, "navigate", "left_chair")
    w2 = w.copy()
    w2.items["apple_1"].loc, w2.items["apple_1"].slot = "left_chair", 0
    act(w2, "pick", "apple")
    act(w2, "navigate", "sofa")
    out = act(w2, "place", "sofa")
    assert not out.success and "no free space" in out.feedback


def test_navigate_twice_is_harmless() -> None:
    w = _world()
    assert act(w, "navigate", "sofa").success
    out = act(w, "navigate", "sofa")
    assert out.success and "already" in out.feedback


def test_describe_lists_left_to_right_and_hand() -> None:
    w = _world()
    act(w, "navigate", "sofa")
    assert "On the sofa (from left to right): a red mug, a blue mug." in w.describe()
    assert w.describe().endswith("Your hand is empty.")


@pytest.mark.parametrize("action", range(70))
def test_every_skill_runs_from_the_start(action: int) -> None:
    out = _world().step(action)
    assert isinstance(out.feedback, str) and out.feedback
