"""The paper's execution rules, played on the corridor fixture with scripted answers."""

import json

import pytest

from eb_core_testutil import make_config
from eb_core.episode import BudgetGuard, run_episode
from eb_core.model import ImagePart, ModelBudgetExceeded
from eb_core.planner import VLMPlanner
from fixture_plugin import CorridorEnv, ScriptedBackend


def plan(*ids):
    return json.dumps({"visual_state_description": "v", "reasoning_and_reflection": "r", "language_plan": "l",
                       "executable_plan": [{"action_id": i, "action_name": "x"} for i in ids]})


def play(answers=None, oracle=False, task_index=0, tmp_path=None, **over):
    cfg = make_config(**over)
    env = CorridorEnv(resolution=64, multi_view=cfg.env.multi_view)
    backend = ScriptedBackend(answers=answers, oracle=oracle)
    task = CorridorEnv.load_tasks()[task_index]  # near-0: start 0, goal 2
    planner = VLMPlanner(cfg.planner, cfg.env, supports_json_schema=False)
    rec = run_episode(env=env, task=task, seed=1, planner=planner, backend=backend, env_config=cfg.env,
                      step_dir=tmp_path)
    return rec, backend


def test_plan_runs_in_order_until_success():
    rec, backend = play([plan(1, 1, 1, 1)])
    assert rec.success and rec.env_steps == 2 and rec.planner_steps == 1 and rec.end_reason == "success"


def test_failed_action_stops_the_plan_and_replans_with_feedback():
    rec, backend = play([plan(0, 1, 1), plan(1, 1)])
    # step left at cell 0 fails -> the rest of the first plan is dropped
    assert rec.success and rec.env_steps == 3 and rec.planner_steps == 2 and rec.invalid_actions == 1
    second_prompt = backend.requests[1].messages[-1].text
    assert "bumped into the left wall" in second_prompt and "failed" in second_prompt


def test_no_feedback_ablation_hides_feedback_text():
    rec, backend = play([plan(0, 1, 1), plan(1, 1)], planner__feedback=False)
    second = backend.requests[1].messages[-1].text
    assert "bumped" not in second and "Step 1: action 0 (step left)" in second


def test_without_replanning_the_whole_plan_runs():
    rec, _ = play([plan(0, 1, 1)], env__replan_on_failure=False)
    assert rec.success and rec.env_steps == 3 and rec.planner_steps == 1


def test_empty_plan_ends_the_episode():
    rec, _ = play([plan()])
    assert rec.end_reason == "empty_plan" and rec.empty_plan and not rec.success and rec.planner_steps == 1


def test_empty_plan_is_an_output_error_where_it_does_not_end():
    rec, backend = play([plan(), plan(1, 1)], env__empty_plan_ends=False)
    assert rec.success and rec.output_errors == 1 and "plan was empty" in backend.requests[1].messages[-1].text


def test_out_of_range_id_truncates_and_is_reported():
    rec, backend = play([plan(1, 9, 1), plan(1)])
    assert rec.success and rec.env_steps == 2 and rec.planner_steps == 2
    assert "out of range" in backend.requests[1].messages[-1].text


def test_garbage_is_an_output_error_and_the_next_prompt_says_so():
    rec, backend = play(["no json here", plan(1, 1)])
    assert rec.success and rec.output_errors == 1 and rec.invalid_actions == 1
    assert "could not be used" in backend.requests[1].messages[-1].text
    # not the identical prompt again (the deviation from the original we document)
    assert backend.requests[0].messages[-1].text != backend.requests[1].messages[-1].text


def test_garbage_forever_ends_at_the_invalid_cap():
    rec, _ = play(["garbage"])
    assert rec.end_reason == "invalid_cap" and rec.planner_steps == 4 and rec.env_steps == 0


def test_garbage_forever_without_a_cap_still_ends_by_budget():
    rec, _ = play(["garbage"], env__max_invalid_actions=None)
    assert rec.end_reason == "max_steps" and rec.output_errors == 10 and rec.planner_steps == 10


def test_plans_are_cut_to_the_remaining_step_budget():
    rec, _ = play([plan(2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2)], env__max_steps=5)
    assert rec.env_steps == 5 and rec.end_reason == "max_steps"


def test_env_exception_gives_an_error_episode_not_a_crash():
    rec, _ = play([plan(3)])
    assert rec.status == "error" and "the corridor exploded" in rec.error and not rec.success


def test_language_only_sends_no_image_and_no_scene_text():
    rec, backend = play([plan(1, 1)], planner__language_only=True)
    parts = backend.requests[0].messages[-1].content
    assert not any(isinstance(p, ImagePart) for p in parts)
    assert "You are at cell 0" not in backend.requests[0].messages[-1].text
    assert "visual_state_description" not in backend.requests[0].messages[-1].text


def test_text_state_sends_no_image_and_the_text_state():
    rec, backend = play([plan(1, 1)], planner__text_state=True)
    parts = backend.requests[0].messages[-1].content
    assert not any(isinstance(p, ImagePart) for p in parts)
    assert "You are at cell 0" in backend.requests[0].messages[-1].text
    assert "visual_state_description" not in backend.requests[0].messages[-1].text


def test_image_is_sent_first_as_png():
    rec, backend = play([plan(1, 1)])
    first = backend.requests[0].messages[-1].content[0]
    assert isinstance(first, ImagePart) and first.png.startswith(b"\x89PNG") and first.data_url().startswith("data:image/png;base64,")


def test_multi_step_images_and_multi_view():
    rec, backend = play([plan(0), plan(1), plan(1, 1)], planner__multi_step_images=2, env__multi_view=True)
    names = [p.name for p in backend.requests[2].messages[-1].content if isinstance(p, ImagePart)]
    assert names == ["frame-0", "frame-1", "side"]


def test_chat_history_sends_earlier_turns():
    rec, backend = play([plan(0), plan(1), plan(1, 1)], planner__chat_history=True, planner__history_window=3)
    roles = [m.role for m in backend.requests[2].messages]
    assert roles == ["user", "assistant", "user"]


def test_n_shot_controls_examples():
    _, b0 = play([plan(1, 1)], planner__n_shot=0)
    _, b3 = play([plan(1, 1)], planner__n_shot=3)
    assert "## Examples" not in b0.requests[0].messages[-1].text
    assert "Example 3:" in b3.requests[0].messages[-1].text and "Example 4:" not in b3.requests[0].messages[-1].text


def test_json_schema_only_when_supported_or_forced():
    cfg = make_config(planner__json_schema="auto")
    p = VLMPlanner(cfg.planner, cfg.env, supports_json_schema=True)
    q = VLMPlanner(cfg.planner, cfg.env, supports_json_schema=False)
    assert p.use_schema and not q.use_schema


def test_step_records_hold_prompt_output_and_actions(tmp_path):
    rec, _ = play([plan(0, 1), plan(1, 1)], tmp_path=tmp_path)
    lines = [json.loads(x) for x in (tmp_path / "steps.jsonl").read_text().splitlines()]
    assert [ln["planner_step"] for ln in lines] == [1, 2]
    assert lines[0]["actions"][0]["feedback"] == "bumped into the left wall"
    assert (tmp_path / lines[0]["image"]).read_bytes().startswith(b"\x89PNG")


def test_multi_view_saves_every_view(tmp_path):
    play([plan(1, 1)], tmp_path=tmp_path, env__multi_view=True)
    first = json.loads((tmp_path / "steps.jsonl").read_text().splitlines()[0])
    assert first["image"] == "step001_top.png" and first["extra_images"] == ["step001_side.png"]
    assert (tmp_path / "step001_side.png").read_bytes().startswith(b"\x89PNG")


def test_budget_guard_raises_when_spent():
    g = BudgetGuard(0.05)
    g.add(0.03)
    with pytest.raises(ModelBudgetExceeded):
        g.add(0.03)
