"""Goal predicates and the sticky subgoal progress."""

from __future__ import annotations

import pytest

from eb_habitat.goals import GoalTracker, PredicateError, default_subgoals, parse_predicate
from eb_habitat.skills import skill_id
from eb_habitat.world import World


@pytest.mark.parametrize(
    "text, reason",
    [
        ("on ?apple sofa", "not a predicate"),
        ("(under ?apple sofa)", "unknown predicate"),
        ("(on ?apple)", "takes 2"),
        ("(on ?durian sofa)", "unknown object type"),
        ("(on ?apple bathtub)", "unknown receptacle"),
        ("(on ?apple fridge)", "use (inside"),
        ("(inside ?apple sofa)", "use (on"),
        ("(open sofa)", "cannot be opened"),
        ("(holding apple_7)", "not in the scene"),
    ],
)
def test_bad_predicates_say_why(text: str, reason: str) -> None:
    with pytest.raises(PredicateError, match=reason.replace("(", r"\(")):
        parse_predicate(text, {"apple_1": "apple"})


def test_progress_is_sticky_and_success_needs_all() -> None:
    w = World([{"name": "apple_1", "type": "apple", "color": "red", "at": "sofa", "slot": 0},
               {"name": "cup_1", "type": "cup", "color": "red", "at": "desk", "slot": 0}])
    goal = [parse_predicate("(on ?apple desk)"), parse_predicate("(closed fridge)")]
    tracker = GoalTracker(goal, default_subgoals(goal))
    assert [str(p) for s in tracker.subgoals for p in s] == ["(holding ?apple)", "(on ?apple desk)", "(closed fridge)"]
    tracker.update(w)
    assert tracker.progress(w) == pytest.approx(1 / 3)  # the fridge is closed already
    for kind, arg in [("navigate", "sofa"), ("pick", "apple")]:
        w.step(skill_id(kind, arg))
        tracker.update(w)
    assert tracker.progress(w) == pytest.approx(2 / 3)
    w.step(skill_id("place", "sofa"))  # put it back: holding stays counted
    tracker.update(w)
    assert tracker.progress(w) == pytest.approx(2 / 3) and not tracker.success(w)
    for kind, arg in [("pick", "apple"), ("navigate", "desk"), ("place", "desk")]:
        w.step(skill_id(kind, arg))
        tracker.update(w)
    assert tracker.success(w) and tracker.progress(w) == 1.0
