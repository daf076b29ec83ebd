"""The invariant: the closed-loop oracle (``model=oracle model.plan_length=1``) plays right by definition, so its
runs carry no error label at all, in every world; and with no description it gets no perception score."""

import json
import random

import pytest

WORLDS = ("alfred", "habitat", "navigation", "manipulation")
PER_WORLD = 4  # one task of each of a few subsets, picked by a fixed seed


def _sample(cls):
    tasks = cls.load_tasks()
    by_subset = {}
    for t in tasks:
        by_subset.setdefault(t.subset, []).append(t.id)
    rng = random.Random(26)
    subsets = sorted(by_subset)
    return [rng.choice(by_subset[s]) for s in rng.sample(subsets, min(PER_WORLD, len(subsets)))]


@pytest.mark.parametrize("world", WORLDS)
def test_the_closed_loop_oracle_gets_no_error_label(world, tmp_path, monkeypatch):
    monkeypatch.delenv("EB_DISABLE_PLUGIN_AUTOLOAD", raising=False)
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    from eb_core.cli import compose
    from eb_core.config import validate_config
    from eb_core.plugins import Registry
    from eb_core.runner import run

    registry = Registry.create()
    if world not in registry.envs or "oracle" not in registry.all("model backend"):
        pytest.skip(f"eb-{world} or the oracle backend is not installed")
    tasks = _sample(registry.get("env", world).load())
    cfg = compose([f"env={world}", "model=oracle", "model.plan_length=1", f"tasks=[{','.join(tasks)}]",
                   "runner.quiet=true", "runner.workers=1"])
    summary = run(validate_config(cfg), tmp_path)
    recs = [json.loads(x) for x in (tmp_path / "episodes.jsonl").read_text().splitlines()]
    assert len(recs) == len(tasks) and all(r["status"] == "ok" for r in recs)
    for r in recs:
        assert r["error_counts"] == {}, (r["task_id"], r["error_counts"])
        assert r["perception_score"] is None
    ea = summary["overall"]["error_analysis"]
    assert ea["labels"] == 0 and ea["perception_score"] is None
    assert summary["overall"]["invalid_action_ratio"] == 0.0
