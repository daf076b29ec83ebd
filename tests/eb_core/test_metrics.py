"""Summary metrics: the paper-compatible subgoal rate and the intervals in every block."""

import pytest

from eb_core.metrics import compute_summary, errors, paper_progress, steps, subgoal_success, success_rate, usage
from eb_core.records import EpisodeRecord

FNS = {"success_rate": success_rate, "subgoal_success": subgoal_success, "steps": steps, "errors": errors,
       "usage": usage}


def rec(task, subset="a", success=False, progress=0.0, end="max_steps", repeat=0, status="ok"):
    return EpisodeRecord(task_id=task, subset=subset, instruction="i", status=status, success=success,
                         progress=1.0 if success else progress, end_reason=end, repeat=repeat)


@pytest.mark.parametrize(("end", "expected"), [("empty_plan", 0.0), ("invalid_cap", 0.0), ("max_steps", 0.5),
                                               ("done", 0.5)])
def test_the_original_zeroes_progress_on_empty_plan_and_invalid_cap(end, expected):
    assert paper_progress(rec("t", progress=0.5, end=end)) == expected
    assert paper_progress(rec("t", success=True, end="success")) == 1.0


def test_summary_blocks_have_both_subgoal_rates_and_intervals():
    eps = [rec("t1", progress=0.5, end="empty_plan"), rec("t2", progress=0.5), rec("t3", success=True, end="success"),
           rec("t4", subset="b", progress=0.25, end="invalid_cap"), rec("t5", subset="b", status="error")]
    s = compute_summary(eps, FNS, ["a", "b"])
    a, b, o = s["subsets"]["a"], s["subsets"]["b"], s["overall"]
    assert a["subgoal_success"] == pytest.approx(2 / 3) and a["subgoal_success_paper"] == pytest.approx(0.5)
    assert b["subgoal_success"] == 0.25 and b["subgoal_success_paper"] == 0.0
    assert o["episodes"] == 4 and o["success_rate_ci"]["tasks"] == 4  # the error episode is not measured
    for block in (a, b, o):
        for key in ("success_rate", "subgoal_success", "subgoal_success_paper"):
            ci = block[f"{key}_ci"]
            assert ci["ci_low"] <= block[key] <= ci["ci_high"]
    assert a["success_rate_ci"]["ci_method"] == "wilson" and a["subgoal_success_ci"]["ci_method"] == "cluster-bootstrap"


def test_repeats_are_grouped_by_task():
    eps = [rec(f"t{i}", success=(i + r) % 2 == 0, repeat=r) for i in range(6) for r in range(3)]
    ci = compute_summary(eps, FNS)["overall"]["success_rate_ci"]
    assert ci["tasks"] == 6 and ci["repeats"] == 3 and ci["ci_method"] == "cluster-bootstrap"
    assert ci["repeat_sd"] == pytest.approx(0.0)  # each repeat solves exactly half the tasks
