"""A seeded `eb run` of every world (oracle and random, limit=20) writes the same episodes.jsonl and summary.json
as the golden files in golden/, recorded from main before the CLI/config restructuring (issue #27).

Compared: every field of the golden records, except timings (``model_latency_s``, ``wall_time_s``), the host
(``node``), plugin versions and the automatic error labels (see ``SKIP``). Fields added since (a format version, the partial mark...) are not compared, so
a new field does not fail this test; a changed or missing one does. Navigation's golden files were re-recorded
when ``limit=`` became "the first N subset by subset" in every world (the same 20 tasks played by the old code
give these very records). Manipulation plays ~6 s per episode, so only its first tasks are replayed
(``tasks=``): an episode's seed depends on its task id alone, so its record is the same in any selection.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

GOLDEN = Path(__file__).parent / "golden"
#: Timings, the host and plugin versions vary; the automatic error labels (``error_counts``, ``perception_score``,
#: ``error_analysis``) and the summary's ``invalid_action_ratio`` (now: actions refused outright) are an analysis of
#: the records that issue 26 changed on purpose after these files were recorded; its own tests guard them.
SKIP = {"model_latency_s", "wall_time_s", "node", "plugins", "error_counts", "perception_score", "error_analysis",
        "invalid_action_ratio"}
FAST = ("navigation", "alfred", "habitat")


def _installed(world: str) -> bool:
    from eb_core.plugins import Registry

    return world in Registry.create().envs


def _eb_run(world: str, model: str, run_dir: Path, *extra: str) -> None:
    args = [sys.executable, "-m", "eb_core", "run", f"env={world}", f"model={model}", "seed=0",
            f"hydra.run.dir={run_dir}", "--quiet", *extra]
    if world != "manipulation":
        args.append("env.params.render=false")
    r = subprocess.run(args, capture_output=True, text=True, timeout=600,
                       env=dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl")))
    assert r.returncode == 0, r.stderr[-2000:]


def _like(new, golden, where: str = ""):
    """``new`` restricted to the shape of ``golden`` (dict keys of golden only, minus timings); a key golden has
    and ``new`` lacks fails with its path."""
    if isinstance(golden, dict):
        assert isinstance(new, dict), where
        missing = [k for k in golden if k not in new and k not in SKIP]
        assert not missing, f"{where}: fields gone: {missing}"
        return {k: _like(new[k], v, f"{where}.{k}") for k, v in golden.items() if k not in SKIP}
    if isinstance(golden, list):
        assert isinstance(new, list) and len(new) == len(golden), where
        return [_like(n, g, f"{where}[{i}]") for i, (n, g) in enumerate(zip(new, golden))]
    return new


def _strip(x):
    if isinstance(x, dict):
        return {k: _strip(v) for k, v in x.items() if k not in SKIP}
    if isinstance(x, list):
        return [_strip(v) for v in x]
    return x


def _episodes(run_dir: Path) -> list[dict]:
    eps = [json.loads(line) for line in (run_dir / "episodes.jsonl").read_text().splitlines()]
    return sorted(eps, key=lambda e: (e["task_id"], e["repeat"]))


@pytest.mark.parametrize("model", ["oracle", "random"])
@pytest.mark.parametrize("world", FAST)
def test_seeded_run_matches_the_golden_files(world, model, tmp_path):
    if not _installed(world):
        pytest.skip(f"the {world} plugin is not installed")
    golden = json.loads((GOLDEN / f"{world}-{model}.json").read_text())
    _eb_run(world, model, tmp_path, "limit=20")
    assert _like(_episodes(tmp_path), golden["episodes"], "episodes") == _strip(golden["episodes"])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert _like(summary, golden["summary"], "summary") == _strip(golden["summary"])
    assert summary["partial"] is True and summary["n_selected"] == 20  # limit=20 of a larger task set


@pytest.mark.parametrize("model", ["oracle", "random"])
def test_manipulation_episodes_match_the_golden_files(model, tmp_path):
    if not _installed("manipulation"):
        pytest.skip("the manipulation plugin is not installed")
    golden = json.loads((GOLDEN / f"manipulation-{model}.json").read_text())
    first = golden["episodes"][:2]
    _eb_run("manipulation", model, tmp_path, f"tasks=[{','.join(e['task_id'] for e in first)}]")
    assert _like(_episodes(tmp_path), first, "episodes") == _strip(first)
