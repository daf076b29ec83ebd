"""`eb export`: Parquet shards that pyarrow reads back with one row per planner step, a dataset card, and the
chat (SFT) form; heavy libraries are imported only by these commands."""

import json
import subprocess
import sys

import pyarrow.parquet as pq
import pytest

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.cli import main
from eb_core.export import export_run
from eb_core.runner import run

LEFT = json.dumps({"visual_state_description": "the goal <b>", "executable_plan": [{"action_id": 0}]})


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    root = tmp_path_factory.mktemp("run")
    run(make_config(model={"name": "lefty", "backend": "scripted", "answers": [LEFT, "no json"]}, limit=4),
        root, plugins=[fixture_plugin])
    return root


def _planner_steps(run_dir):
    return sum(json.loads(x)["planner_steps"] for x in (run_dir / "episodes.jsonl").read_text().splitlines())


def test_parquet_round_trips_with_one_row_per_planner_step(mixed, tmp_path):
    out = tmp_path / "ds"
    res = export_run(mixed, out, images="embed", shard_rows=5)
    expected = _planner_steps(mixed)
    table = pq.read_table(out / "data")
    assert res["rows"] == expected == table.num_rows and len(res["files"]) == -(-expected // 5)
    rows = table.to_pylist()
    first = rows[0]
    assert first["task_id"] == "near-0" and first["planner_step"] == 1 and first["subset"] == "near"
    assert first["instruction"] == "walk to cell 2" and "action id 0: step left" in first["prompt"]
    assert first["images"][0]["bytes"][:8] == b"\x89PNG\r\n\x1a\n"
    assert first["actions"] == ["step left"] and first["action_success"] == [False]
    assert "failed_action" in first["error_labels"] and first["visual_state_description"] == "the goal <b>"
    assert any(r["output_error"] for r in rows) and any("format_error" in r["error_labels"] for r in rows)
    features = json.loads(pq.read_schema(out / res["files"][0]).metadata[b"huggingface"])["info"]["features"]
    assert features["images"] == {"feature": {"_type": "Image"}, "_type": "Sequence"}  # datasets decodes them
    assert set(features) == set(table.schema.names)
    card = (out / "README.md").read_text()
    assert "configs:" in card and "data/*.parquet" in card and f"{expected} rows" in card
    assert "lefty" in card and "0.0 [0.0," in card and "embodiedbench" in card and "```yaml" in card


def test_paths_mode_copies_the_images_beside_the_data(mixed, tmp_path):
    out = tmp_path / "ds"
    export_run(mixed, out, images="paths")
    rows = pq.read_table(out / "data").to_pylist()
    img = rows[0]["images"][0]
    assert img["bytes"] is None and (out / img["path"]).read_bytes()[:4] == b"\x89PNG"
    features = json.loads(pq.read_schema(next((out / "data").glob("*.parquet"))).metadata[b"huggingface"])
    assert features["info"]["features"]["images"]["feature"]["path"] == {"dtype": "string", "_type": "Value"}


def test_chat_form_has_one_sample_per_planner_call(mixed, tmp_path):
    out = tmp_path / "chat"
    assert main(["export", str(mixed), "--out", str(out), "--format", "chat"]) == 0
    lines = [json.loads(x) for x in (out / "chat.jsonl").read_text().splitlines()]
    assert len(lines) == _planner_steps(mixed)
    s = lines[0]
    assert [m["role"] for m in s["messages"]] == ["user", "assistant"]
    assert s["messages"][0]["content"].startswith("<image>\n") and s["messages"][1]["content"] == LEFT
    assert (out / s["images"][0]).exists()
    out2 = tmp_path / "succ"
    assert main(["export", str(mixed), "--out", str(out2), "--format", "chat", "--only-success"]) == 0
    assert (out2 / "chat.jsonl").read_text() == ""  # lefty never succeeds


def test_bad_export_input_fails_in_one_line(mixed, tmp_path, capsys):
    assert main(["export", str(mixed), "--out", str(tmp_path / "x"), "--images", "inline"]) == 2
    assert "use embed" in capsys.readouterr().err
    assert main(["export", str(tmp_path), "--out", str(tmp_path / "x")]) == 2
    assert "is not a run directory" in capsys.readouterr().err
    assert main(["export", str(mixed)]) == 2
    assert "usage: eb export" in capsys.readouterr().err


def test_pyarrow_and_matplotlib_are_imported_only_by_their_commands():
    code = ("import sys, eb_core.cli, eb_core.report, eb_core.html, eb_core.export, eb_core.errors, eb_core.metrics;"
            "print(sorted(m for m in ('pyarrow', 'matplotlib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


@pytest.fixture(scope="module")
def noisy_train_run(tmp_path_factory):
    """``eb run env=navigation model=oracle model.noise=0.3 runner.expert_labels=true split=train limit=3``:
    a noisy expert on generated training tasks, with images (small), played with the installed plugins."""
    pytest.importorskip("eb_navigation")
    import os

    root = tmp_path_factory.mktemp("noisy") / "run"
    env = {k: v for k, v in os.environ.items() if k not in ("EB_PLUGINS", "EB_DISABLE_PLUGIN_AUTOLOAD")}
    r = subprocess.run([sys.executable, "-m", "eb_core", "run", "env=navigation", "model=oracle", "model.noise=0.3",
                        "model.plan_length=1", "runner.expert_labels=true", "split=train", "limit=3",
                        "env.resolution=64", "--quiet", f"hydra.run.dir={root}"],
                       capture_output=True, text=True, timeout=600, env=env)
    assert r.returncode == 0, r.stderr
    return root


def test_chat_export_of_a_noisy_expert_run_labels_every_call_with_the_expert_and_shows_recoveries(
        noisy_train_run, tmp_path):
    from eb_navigation.env import NavigationEnv

    out = tmp_path / "sft"
    assert main(["export", str(noisy_train_run), "--out", str(out), "--format", "chat", "--label", "expert"]) == 0
    lines = [json.loads(x) for x in (out / "chat.jsonl").read_text().splitlines()]
    steps = [json.loads(x) for d in sorted((noisy_train_run / "episodes").iterdir())
             for x in (d / "steps.jsonl").read_text().splitlines()]
    assert len(lines) == len(steps) and all(s["task_id"].startswith("train_") for s in lines)
    for s in lines:
        assert s["images"] and all((out / p).read_bytes()[:4] == b"\x89PNG" for p in s["images"])
        user, answer = s["messages"][0]["content"], json.loads(s["messages"][1]["content"])
        assert user.startswith("<image>\n") and "Move forward by 0.25 meters" in user
        # the label is the expert's action, as a one-action answer the benchmark's parser reads
        assert answer["executable_plan"] == [{"action_id": s["expert_action"], "action_name": s["expert_action_name"]}]
    # ...and the expert's action is the world's: replay each episode's first state and ask its expert
    records = {r["task_id"]: r for r in map(json.loads, (noisy_train_run / "episodes.jsonl").read_text().splitlines())}
    world = NavigationEnv(resolution=64, render=False)
    for i, task in enumerate(NavigationEnv.split_tasks("train", 0, 3)):
        world.reset(task, records[task.id]["seed"])
        first = next(s for s in lines if s["task_id"] == task.id and s["planner_step"] == 1)
        assert world.expert_plan()[0] == first["expert_action"]
    world.close()
    # the noise put the agent off the expert's path, and later calls show the way back
    off = [s for s in lines if s["off_expert"]]
    rec = [s for s in lines if s["recovery"]]
    assert off and rec and not lines[0]["recovery"]
    assert all(json.loads(s["model_answer"])["executable_plan"][0]["action_id"] != s["expert_action"] for s in off)
    assert any(s["episode_success"] for s in rec)  # recovered episodes
    # the model's own answers stay the default label, the expert's action rides along
    plain = tmp_path / "plain"
    assert main(["export", str(noisy_train_run), "--out", str(plain), "--format", "chat"]) == 0
    first = json.loads((plain / "chat.jsonl").read_text().splitlines()[0])
    assert first["messages"][1]["content"] == steps[0]["raw_output"]
    assert first["expert_action"] == lines[0]["expert_action"]


def test_expert_labels_need_a_run_that_recorded_them(mixed, tmp_path, capsys):
    assert main(["export", str(mixed), "--out", str(tmp_path / "x"), "--format", "chat", "--label", "expert"]) == 2
    err = capsys.readouterr().err
    assert "has no expert labels" in err and "runner.expert_labels=true" in err and err.count("\n") == 1
    assert main(["export", str(mixed), "--out", str(tmp_path / "x"), "--format", "chat", "--label", "gold"]) == 2
    assert "use model" in capsys.readouterr().err


def test_card_split_is_the_runs_and_an_export_is_never_overwritten_silently(mixed, tmp_path, capsys):
    from eb_core.cli import main

    out = tmp_path / "ds"
    export_run(mixed, out, images="paths")
    card = (out / "README.md").read_text()
    assert "  - split: test" in card and "split: train" not in card  # benchmark tasks are test data
    assert all(p.name.startswith("test-") for p in (out / "data").glob("*.parquet"))
    before = (out / "README.md").read_bytes()
    assert main(["export", str(mixed), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "exists (an earlier export)" in err and "--overwrite" in err and err.count("\n") == 1
    assert (out / "README.md").read_bytes() == before
    assert main(["export", str(mixed), "--out", str(out), "--format", "chat", "--overwrite"]) == 0
    assert (out / "chat.jsonl").exists() and not list((out / "data").glob("*.parquet"))
