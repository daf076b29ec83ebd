"""Typed run records: StepRecord and the run manifest, one reader for every consumer, old runs still load."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import fixture_plugin
import pytest
from eb_core_testutil import make_config

from eb_core.episode import EpisodeDriver, EpisodeOptions, run_episode
from eb_core.planner import VLMPlanner
from eb_core.records import FORMAT_VERSION, RunManifest, StepRecord, iter_steps, read_manifest, read_run, read_steps
from eb_core.runner import run

REAL_PLAY = Path("/work/shared/real-play/navigation")


@pytest.fixture
def old_run(tmp_path) -> Path:
    """A copy of a run made before format version 1 (a real model on Navigation)."""
    if not REAL_PLAY.is_dir():
        pytest.skip("the recorded real-play run is not on this machine")
    dst = tmp_path / "old"
    shutil.copytree(REAL_PLAY, dst)
    return dst


def test_an_old_run_loads_through_the_reader(old_run):
    run_log = read_run(old_run)
    assert run_log.manifest is None and run_log.format_version == 0
    assert len(run_log.episodes) == len((old_run / "episodes.jsonl").read_text().splitlines())
    n = 0
    for rec, steps in iter_steps(run_log):
        raw = (old_run / "episodes" / rec.task_id / "steps.jsonl").read_text().splitlines()
        assert len(steps) == len(raw) == rec.planner_steps
        for step, line in zip(steps, raw):
            assert isinstance(step, StepRecord)
            assert json.loads(step.to_json_line()) == json.loads(line)  # typed, and nothing lost
        n += len(steps)
    assert n > 0


def test_every_consumer_reads_an_old_run(old_run, tmp_path):
    from eb_core.errors import label_run
    from eb_core.export import export_run
    from eb_core.html import write_html

    assert write_html(old_run).exists()
    labels = label_run(old_run)
    assert len(labels) == len(read_run(old_run).episodes)
    export_run(old_run, tmp_path / "export")
    assert any((tmp_path / "export").iterdir())


def test_every_run_writes_a_manifest(tmp_path):
    run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    manifest = read_manifest(tmp_path)
    assert manifest is not None and manifest.format_version == FORMAT_VERSION == read_run(tmp_path).format_version
    assert manifest.env == "corridor" and manifest.n_tasks == 10 and len(manifest.task_set_digest) == 64
    assert manifest.versions["plugin:fixture_plugin"] and manifest.versions["python"]
    # a second invocation keeps the time of the first
    first = manifest.created
    run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    assert read_manifest(tmp_path).created == first


def test_a_manifest_of_a_newer_format_is_refused_in_one_line(tmp_path):
    m = RunManifest(format_version=FORMAT_VERSION + 1, env="x", model="y", n_tasks=1, task_set_digest="a",
                    selected_digest="b", config_digest="c")
    (tmp_path / "manifest.json").write_text(m.model_dump_json())
    with pytest.raises(ValueError, match=r"format_version 2; this EmbodiedBench reads up to 1\. Fix: upgrade"):
        read_manifest(tmp_path)


def test_the_driver_keeps_the_steps_it_wrote(tmp_path):
    cfg = make_config()
    task = fixture_plugin.CorridorEnv.load_tasks()[6]
    backend = fixture_plugin.ScriptedBackend(oracle=True)
    driver = EpisodeDriver(env=fixture_plugin.CorridorEnv(), task=task, seed=3, backend=backend, env_config=cfg.env,
                           planner=VLMPlanner(cfg.planner, cfg.env), options=EpisodeOptions(step_dir=tmp_path))
    request = driver.next_request()
    while request is not None:
        driver.submit(backend.complete(request))
        request = driver.next_request()
    assert driver.record.success and driver.record.planner_steps >= 1 and driver.steps[0].actions
    assert driver.steps == read_steps(tmp_path)


def test_options_object_and_keywords_give_the_same_episode(tmp_path):
    cfg = make_config()
    task = fixture_plugin.CorridorEnv.load_tasks()[5]

    def play(**kw):
        return run_episode(env=fixture_plugin.CorridorEnv(), task=task, seed=9, env_config=cfg.env,
                           backend=fixture_plugin.ScriptedBackend(oracle=True),
                           planner=VLMPlanner(cfg.planner, cfg.env), **kw)

    a = play(options=EpisodeOptions(step_dir=tmp_path / "a", repeat=1))
    b = play(step_dir=tmp_path / "b", repeat=1)
    assert a.model_dump(exclude={"wall_time_s"}) == b.model_dump(exclude={"wall_time_s"}) and a.repeat == 1
    with pytest.raises(TypeError, match="unknown episode option.*step_dri.*allowed: step_dir"):
        play(step_dri=tmp_path)


@pytest.mark.parametrize("workers", [1, 2])
def test_the_runner_labels_errors_without_reading_steps_back(tmp_path, monkeypatch, workers):
    """Labels come from the steps the driver kept in memory: reading a steps.jsonl during the run fails it."""
    import eb_core.errors
    import eb_core.records

    def forbidden(*_a, **_k):
        raise AssertionError("a steps.jsonl was read back during the run")

    monkeypatch.setattr(eb_core.records, "read_steps", forbidden)
    monkeypatch.setattr(eb_core.errors, "load_steps", forbidden)
    run(make_config(limit=4, runner__workers=workers), tmp_path, plugins=[fixture_plugin])
    monkeypatch.undo()
    recs = read_run(tmp_path).episodes
    assert len(recs) == 4 and all(r.status == "ok" and r.error_counts is not None for r in recs)
