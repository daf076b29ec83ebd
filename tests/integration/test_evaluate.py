"""``eb_core.evaluate.evaluate``: a policy callable scored exactly as ``eb run`` scores a model."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from eb_core.evaluate import evaluate


def _answer(actions):
    return json.dumps({"visual_state_description": "", "reasoning_and_reflection": "", "language_plan": "",
                       "executable_plan": [{"action_id": int(a), "action_name": ""} for a in actions]})


def _expert_step(obs, info):
    assert set(obs) == {"prompt", "images"} and isinstance(obs["prompt"], str)
    return _answer((info["expert_plan"] or [])[:1])


def _episodes(run_dir):
    rows = [json.loads(line) for line in (run_dir / "episodes.jsonl").read_text().splitlines() if line.strip()]
    return {r["task_id"]: (r["success"], round(r["progress"], 6), r["env_steps"], r["planner_steps"], r["end_reason"]) for r in rows}


@pytest.mark.parametrize("world", ["navigation", "habitat"])
def test_expert_policy_scores_like_the_closed_loop_oracle(tmp_path, world):
    overrides = ["env.params.render=false"] if world == "navigation" else []
    ours = evaluate(_expert_step, world, limit=6, expert=True, overrides=overrides, run_dir=tmp_path / "ours")
    p = subprocess.run([sys.executable, "-m", "eb_core", "run", f"env={world}", "model=oracle", "model.plan_length=1",
                        "limit=6", "runner.quiet=true", f"hydra.run.dir={tmp_path / 'cli'}", *overrides],
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert _episodes(tmp_path / "ours") == _episodes(tmp_path / "cli")
    for key in ("success_rate", "subgoal_success", "avg_env_steps", "success_rate_ci"):
        assert ours["overall"][key] == cli["overall"][key], key
    assert ours["overall"]["success_rate"] == 1.0


def test_text_policy_and_failures_are_scored(tmp_path):
    calls = []

    def stubborn(prompt):  # always the same (invalid for most states) plan: a weak policy
        calls.append(prompt)
        return _answer([0, 0, 0])

    s = evaluate(stubborn, "navigation", limit=3, policy_input="text", overrides=["env.params.render=false"])
    assert calls and all(isinstance(c, str) and "action" in c.lower() for c in calls)
    assert s["overall"]["episodes"] == 3 and s["overall"]["success_rate"] < 1.0


def test_bad_policies_fail_with_one_line():
    with pytest.raises(ValueError, match="policy_input must be"):
        evaluate(lambda o: "", "navigation", policy_input="pixels")
    with pytest.raises(TypeError, match="must be a callable"):
        evaluate("oracle", "navigation")  # type: ignore[arg-type]
