"""The generator is deterministic, reproduces the shipped files and writes only valid tasks."""

from __future__ import annotations

from pathlib import Path

from eb_habitat.generate import generate
from eb_habitat.tasks import SUBSETS, TASK_DIR, load_task_file, load_tasks


def test_regenerating_with_seed_0_gives_the_shipped_files(tmp_path: Path) -> None:
    paths = generate(out=str(tmp_path), seed=0)
    assert [Path(p).name for p in paths] == [f"{s}.json" for s in SUBSETS]
    for p in paths:
        assert Path(p).read_bytes() == (TASK_DIR / Path(p).name).read_bytes(), f"{p} differs from the shipped file"


def test_other_seed_single_file(tmp_path: Path) -> None:
    out = tmp_path / "few.json"
    generate(out=str(out), seed=7, per_subset=5, subset="long_horizon")
    tasks = load_task_file(out)
    assert [t.subset for t in tasks] == ["long_horizon"] * 5
    shipped = {t.instruction for t in load_tasks()}
    assert any(t.instruction not in shipped for t in tasks)


def test_templates_cover_the_paper_subsets() -> None:
    tasks = load_tasks()
    templates = {t.metadata["template"] for t in tasks}
    for needed in ("complex.if_open", "complex.if_present", "complex.irrelevant_context", "visual.color_variant",
                   "visual.looks", "spatial.next_to_object", "long.multi_object", "long.swap"):
        assert needed in templates
    long = [t for t in tasks if t.subset == "long_horizon"]
    assert all(len(t.metadata["goal"]) >= 2 for t in long)
    assert all(t.metadata["oracle_steps"] <= 20 for t in long)
