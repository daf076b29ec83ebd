"""The shared timing helpers of the worlds' step benchmarks."""

from __future__ import annotations

import pytest

from eb_scenekit import SceneBuilder, set_object_pose
from eb_scenekit.bench import median_seconds, median_step_vs_render


def test_median_seconds_times_each_call() -> None:
    calls: list[int] = []
    assert median_seconds(calls.append, [1, 2, 3]) >= 0.0
    assert calls == [1, 2, 3]
    with pytest.raises(ValueError):
        median_seconds(calls.append, [])


def test_step_vs_render_follows_a_scene_that_is_rebuilt() -> None:
    def build():  # type: ignore[no-untyped-def]
        b = SceneBuilder(offscreen=(64, 64))
        b.add_studio()
        b.add_object("Apple", "apple", (0.0, 0.0))
        b.add_camera("cam", (1.0, 0.0, 0.5), lookat=(0.0, 0.0, 0.05))
        return b.build()

    scenes = [build()]
    steps = 0
    prepared = 0

    def before() -> None:
        nonlocal prepared
        prepared += 1
        if prepared == 3:
            scenes.append(build())  # a reset: a new model half-way through

    def step() -> None:
        nonlocal steps
        steps += 1
        model, data = scenes[-1]
        set_object_pose(model, data, "apple", (0.0, 0.01 * steps, 0.0))

    out = median_step_vs_render(step, lambda: scenes[-1], "cam", 4, resolution=48, before=before)
    assert set(out) == {"n", "step_s", "raw_render_s", "ratio"}
    assert out["n"] == steps == prepared == 4
    assert out["step_s"] > 0 and out["raw_render_s"] > 0
    assert out["ratio"] == pytest.approx(out["step_s"] / out["raw_render_s"])
