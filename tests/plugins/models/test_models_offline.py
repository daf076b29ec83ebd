"""The offline backends in the real episode loop: oracle, random, replay (identical results) and human."""

from __future__ import annotations

import io
import json
from pathlib import Path

import models_toyenv
import pytest
from models_toyenv import ButtonLine, VectorReach

import eb_models.plugin
from eb_core.config import EnvConfig, PlannerConfig, validate_config
from eb_core.episode import run_episode
from eb_core.model import EpisodeContext, ModelFatalError, ModelTransientError
from eb_core.parsing import parse_planner_output
from eb_core.planner import VLMPlanner
from eb_models._settings import ModelConfigError
from eb_models.baselines import OracleBackend, RandomBackend
from eb_models.human import HumanBackend
from eb_models.replay import ReplayBackend

ENV_CFG = EnvConfig(name="button-line", max_steps=12, max_invalid_actions=None, replan_on_failure=True,
                    empty_plan_ends=True, default_n_shot=0, resolution=64)
TIMING = ("wall_time_s", "model_latency_s")


def play(backend, task, step_dir: Path | None = None, run_dir: str = "", env_cls=ButtonLine):
    env = env_cls()
    planner = VLMPlanner(PlannerConfig(), ENV_CFG, supports_json_schema=backend.supports_json_schema)
    rec = run_episode(env=env, task=task, seed=5, planner=planner, backend=backend, env_config=ENV_CFG,
                      step_dir=step_dir, save_images=False, run_dir=run_dir)
    env.close()
    return rec


def context(env_cls=ButtonLine, seed: int = 0, i: int = 0) -> EpisodeContext:
    env = env_cls()
    task = env_cls.load_tasks()[i]
    env.reset(task, seed)
    return EpisodeContext(env=env, task=task, seed=seed)


# -- oracle and random ----------------------------------------------------------------------------------


def test_oracle_solves_every_task_through_the_pipeline():
    for task in ButtonLine.load_tasks():
        rec = play(OracleBackend(), task)
        assert rec.status == "ok" and rec.success and rec.planner_steps == 1 and rec.output_errors == 0


def test_oracle_answer_is_the_planner_format():
    backend = OracleBackend()
    backend.start_episode(context())
    from eb_core.model import Message, ModelRequest, TextPart

    text = backend.complete(ModelRequest(messages=(Message(role="user", content=(TextPart(text="go"),)),))).text
    answer = json.loads(text)
    assert set(answer) == {"visual_state_description", "reasoning_and_reflection", "language_plan", "executable_plan"}
    assert answer["executable_plan"] == [{"action_id": 1, "action_name": "step right"},
                                         {"action_id": 1, "action_name": "step right"},
                                         {"action_id": 2, "action_name": "press the button"}]


def test_random_is_seeded_valid_and_short():
    plans = []
    for _ in range(2):
        backend = RandomBackend()
        backend.start_episode(context(seed=3))
        plans.append([backend.sample() for _ in range(20)])
    assert plans[0] == plans[1]  # same seed and task: same plans
    assert all(1 <= len(p) <= 3 and all(a in (0, 1, 2) for a in p) for p in plans[0])
    other = RandomBackend()
    other.start_episode(context(seed=4))
    assert [other.sample() for _ in range(20)] != plans[0]
    vec = RandomBackend()
    vec.start_episode(context(VectorReach))
    for plan in (vec.sample() for _ in range(30)):
        assert all(len(a) == 3 and all(0 <= v <= 10 for v in a) for a in plan)
    text = vec.complete(__import__("eb_core").ModelRequest(messages=())).text
    assert parse_planner_output(text, VectorReach().action_space(), 20).error is None


def test_random_settings_are_validated():
    with pytest.raises(ModelConfigError, match="min_plan"):
        RandomBackend(min_plan=4, max_plan=2)
    with pytest.raises(ModelConfigError, match="'model.plan_len'.*allowed keys: max_cost_usd, max_plan, min_plan"):
        RandomBackend(plan_len=3)


def test_offline_backends_need_an_episode():
    from eb_core.model import ModelRequest

    for backend in (OracleBackend(), RandomBackend()):
        with pytest.raises(ModelFatalError, match="start_episode"):
            backend.complete(ModelRequest(messages=()))


# -- replay ---------------------------------------------------------------------------------------------


def _compare(a, b):
    da = {k: v for k, v in a.model_dump().items() if k not in TIMING}
    db = {k: v for k, v in b.model_dump().items() if k not in TIMING}
    assert da == db


def test_replay_reproduces_recorded_episodes(tmp_path):
    recorded = tmp_path / "recorded"
    for task in ButtonLine.load_tasks():
        original = play(RandomBackend(), task, step_dir=recorded / "episodes" / task.id)
        assert original.planner_steps >= 2  # several answers to replay, in order
        again = play(ReplayBackend(run_dir=str(recorded)), task, step_dir=tmp_path / "replayed" / task.id)
        _compare(original, again)
        steps_a = [json.loads(x) for x in (recorded / "episodes" / task.id / "steps.jsonl").read_text().splitlines()]
        steps_b = [json.loads(x) for x in (tmp_path / "replayed" / task.id / "steps.jsonl").read_text().splitlines()]
        assert [s["actions"] for s in steps_a] == [s["actions"] for s in steps_b]
        assert [s["prompt"] for s in steps_a] == [s["prompt"] for s in steps_b]


def test_replay_running_out_is_a_clear_error(tmp_path):
    task = ButtonLine.load_tasks()[0]
    steps = tmp_path / "episodes" / task.id / "steps.jsonl"
    steps.parent.mkdir(parents=True)
    # Recorded out of order on purpose: answers come back in planner_step order.
    rows = [{"planner_step": 2, "raw_output": "second"}, {"planner_step": 1, "raw_output": "first"}]
    steps.write_text("".join(json.dumps(r) + "\n" for r in rows))
    backend = ReplayBackend(run_dir=str(tmp_path))
    backend.start_episode(context())
    from eb_core.model import ModelRequest

    assert [backend.complete(ModelRequest(messages=())).text for _ in range(2)] == ["first", "second"]
    with pytest.raises(ModelTransientError, match="asked for answer 3 but .* holds only 2; this run diverged"):
        backend.complete(ModelRequest(messages=()))
    other = context(i=1)
    backend.start_episode(other)
    with pytest.raises(ModelTransientError, match="no recorded steps for task 'line-1'"):
        backend.complete(ModelRequest(messages=()))


def test_replay_checks_its_run_dir(tmp_path):
    with pytest.raises(ModelConfigError, match="has no episodes/ directory"):
        ReplayBackend(run_dir=str(tmp_path / "nowhere"))
    with pytest.raises(ModelConfigError, match="needs the key 'model.run_dir'"):
        ReplayBackend()
    (tmp_path / "episodes").mkdir()
    backend = ReplayBackend(run_dir=str(tmp_path))
    ctx = context()
    ctx.run_dir = str(tmp_path)
    with pytest.raises(ModelFatalError, match="the run being written"):
        backend.start_episode(ctx)


def test_runner_replay_gives_identical_episodes(tmp_path, monkeypatch):
    """Through the real runner: a random run, then its replay into a new directory."""
    from eb_core.runner import run

    monkeypatch.setenv("EB_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.delenv("EB_PLUGINS", raising=False)

    def config(model):
        return validate_config({
            "env": ENV_CFG.model_dump(), "model": model, "planner": {"name": "vlm"}, "ablation": {"name": "none"},
            "runner": {"workers": 1, "quiet": True, "save_images": False}, "seed": 11,
        })

    plugins = [models_toyenv, eb_models.plugin]
    first = run(config({"name": "random", "backend": "random"}), tmp_path / "a", plugins=plugins)
    second = run(config({"name": "replay", "backend": "replay", "run_dir": str(tmp_path / "a")}), tmp_path / "b",
                 plugins=plugins)
    load = lambda d: sorted((json.loads(x) for x in (d / "episodes.jsonl").read_text().splitlines()),  # noqa: E731
                            key=lambda r: r["task_id"])
    a, b = load(tmp_path / "a"), load(tmp_path / "b")
    assert len(a) == 3 and all(r["status"] == "ok" for r in a + b)
    strip = lambda r: {k: v for k, v in r.items() if k not in TIMING}  # noqa: E731
    assert [strip(r) for r in a] == [strip(r) for r in b]
    for key in ("success_rate", "avg_planner_steps", "avg_env_steps", "invalid_action_ratio"):
        assert first["overall"][key] == second["overall"][key]


def test_runner_replay_plays_each_repeat_from_its_own_recording(tmp_path, monkeypatch):
    """runner.repeats=2: each repeat has its own seed, so the random model answers differently; the replay
    must answer repeat k with repeat k's recorded outputs (not repeat 0's for every repeat)."""
    from eb_core.runner import run

    monkeypatch.setenv("EB_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.delenv("EB_PLUGINS", raising=False)

    def config(model):
        return validate_config({
            "env": ENV_CFG.model_dump(), "model": model, "planner": {"name": "vlm"}, "ablation": {"name": "none"},
            "runner": {"workers": 1, "quiet": True, "save_images": False, "repeats": 2}, "seed": 11,
        })

    plugins = [models_toyenv, eb_models.plugin]
    run(config({"name": "random", "backend": "random"}), tmp_path / "a", plugins=plugins)
    run(config({"name": "replay", "backend": "replay", "run_dir": str(tmp_path / "a")}), tmp_path / "b",
        plugins=plugins)

    def outputs(d: Path, task_id: str, repeat: int) -> list[str]:
        name = task_id if repeat == 0 else f"{task_id}_repeat{repeat}"
        rows = (d / "episodes" / name / "steps.jsonl").read_text().splitlines()
        return [json.loads(x)["raw_output"] for x in rows]

    load = lambda d: sorted((json.loads(x) for x in (d / "episodes.jsonl").read_text().splitlines()),  # noqa: E731
                            key=lambda r: (r["task_id"], r["repeat"]))
    a, b = load(tmp_path / "a"), load(tmp_path / "b")
    assert len(a) == 6 and {r["repeat"] for r in a} == {0, 1} and all(r["status"] == "ok" for r in a + b)
    ids = sorted({r["task_id"] for r in a})
    # the recording's repeats differ, so replaying repeat 0 for repeat 1 would show
    assert any(outputs(tmp_path / "a", t, 0) != outputs(tmp_path / "a", t, 1) for t in ids)
    for t in ids:
        for k in (0, 1):
            assert outputs(tmp_path / "b", t, k) == outputs(tmp_path / "a", t, k), (t, k)
    strip = lambda r: {k: v for k, v in r.items() if k not in TIMING}  # noqa: E731
    assert [strip(r) for r in a] == [strip(r) for r in b]


def test_replay_missing_repeat_is_a_clear_error(tmp_path):
    task = ButtonLine.load_tasks()[0]
    play(RandomBackend(), task, step_dir=tmp_path / "rec" / "episodes" / task.id)
    backend = ReplayBackend(run_dir=str(tmp_path / "rec"))
    ctx = context()
    ctx.repeat = 1
    backend.start_episode(ctx)
    from eb_core.model import Message, ModelRequest, TextPart

    with pytest.raises(ModelTransientError, match=r"repeat 1 .*_repeat1/steps.jsonl is missing.*fewer runner.repeats"):
        backend.complete(ModelRequest(messages=(Message(role="user", content=(TextPart(text="go"),)),)))


# -- human ----------------------------------------------------------------------------------------------


def test_human_plays_from_stdin(tmp_path):
    out = io.StringIO()
    backend = HumanBackend(stdin=io.StringIO("9\nleft\n1, 1 2\n"), stdout=out, image_dir=str(tmp_path))
    rec = play(backend, ButtonLine.load_tasks()[0])
    assert rec.success and rec.env_steps == 3
    printed = out.getvalue()
    assert "action id 2: press the button" in printed  # the prompt with the action list
    assert printed.count("Not a valid plan") == 2  # 9 is out of range, "left" is not an id
    [image_line] = [line for line in printed.splitlines() if line.startswith("[image] ")]
    image = Path(image_line.split(" ", 1)[1])
    assert image.is_file() and image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_human_end_of_input_is_an_empty_plan(tmp_path):
    rec = play(HumanBackend(stdin=io.StringIO(""), stdout=io.StringIO(), image_dir=str(tmp_path)),
               ButtonLine.load_tasks()[0])
    assert rec.empty_plan and rec.end_reason == "empty_plan" and not rec.success


def test_human_vector_actions(tmp_path):
    backend = HumanBackend(stdin=io.StringIO("3,4,99\n1 2 3; [3, 4, 5]\n"), stdout=io.StringIO(),
                           image_dir=str(tmp_path), show_prompt=False)
    backend.start_episode(context(VectorReach))
    from eb_core.model import ModelRequest

    answer = json.loads(backend.complete(ModelRequest(messages=())).text)
    assert answer["executable_plan"] == [{"action": [1, 2, 3]}, {"action": [3, 4, 5]}]


def _make_human(q):
    try:
        HumanBackend()
        q.put("constructed")
    except ModelConfigError as exc:
        q.put(str(exc))


def test_human_refuses_worker_processes():
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_make_human, args=(q,))
    p.start()
    p.join(20)
    assert "runner.workers=1" in q.get(timeout=5)
