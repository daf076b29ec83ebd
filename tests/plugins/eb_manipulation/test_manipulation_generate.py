"""The task generator: the shipped file is its output, tasks are valid, varied and reproducible."""

from __future__ import annotations

import json
import re
from collections import Counter
from pathlib import Path

import pytest

from eb_manipulation.generate import SUBSET_FAMILIES, generate, make_task
from eb_manipulation.spec import SceneSpec
from eb_manipulation.tasks import DEFAULT_TASK_FILE, SUBSET_COUNTS, TaskFileError, load_task_file

DOC = json.loads(Path(DEFAULT_TASK_FILE).read_text())


def test_shipped_file_has_the_papers_subsets_and_families() -> None:
    assert DOC["version"] == "v2" and DOC["verified"] is True and DOC["count"] == 228
    tasks = DOC["tasks"]
    assert Counter(t["subset"] for t in tasks) == SUBSET_COUNTS
    per = Counter((t["subset"], t["metadata"]["family"]) for t in tasks)
    for subset, families in SUBSET_FAMILIES.items():
        for family in families:
            assert per[(subset, family)] == 12
    assert not any(t["metadata"]["family"] == "wipe" for t in tasks if t["subset"] == "visual")
    spatial_variants = {t["metadata"]["variant"] for t in tasks if t["subset"] == "spatial"}
    assert all(v.endswith("_relative") for v in spatial_variants)
    for t in tasks:
        SceneSpec.model_validate(t["metadata"])
        assert t["metadata"]["oracle_steps"] <= 15


def test_instructions_are_unique_and_templates_varied() -> None:
    for subset in SUBSET_COUNTS:
        tasks = [t for t in DOC["tasks"] if t["subset"] == subset]
        instructions = [t["instruction"] for t in tasks]
        assert len(set(instructions)) >= 0.95 * len(instructions), subset
        templates = {t["metadata"]["template"] for t in tasks}
        assert len(templates) >= 10, (subset, len(templates))
        for text in instructions:
            assert not re.search(r"\b(\w+) \1\b", text), text  # no doubled words
            assert not re.search(r"\ba [aeiou]", text), text  # "an" before a vowel
            assert text[0].isupper() and text.endswith(".") and "  " not in text


def test_layouts_and_plan_lengths_spread() -> None:
    """Distractor counts, placements and the expert's plan length vary within every family."""
    for family in ("pick", "stack", "sorter", "wipe"):
        tasks = [t for t in DOC["tasks"] if t["metadata"]["family"] == family]
        counts = Counter(len(t["metadata"]["objects"]) for t in tasks)
        lengths = Counter(t["metadata"]["oracle_steps"] for t in tasks)
        assert len(counts) >= 3, (family, counts)
        assert len(lengths) >= 2, (family, lengths)
        xs = [o["x"] for t in tasks for o in t["metadata"]["objects"]]
        assert max(xs) - min(xs) > 0.25
    stack_modes = Counter(t["metadata"]["template"].rsplit("/", 1)[1] for t in DOC["tasks"]
                          if t["metadata"]["family"] == "stack")
    assert set(stack_modes) == {"scratch2", "scratch3", "partial3", "blocked2"}


def test_old_task_files_are_refused_with_one_line(tmp_path: Path) -> None:
    old = tmp_path / "manipulation_v1.json"
    old.write_text(json.dumps({"format": 1, "tasks": []}))
    with pytest.raises(TaskFileError) as err:
        load_task_file(old)
    assert "format 1" in str(err.value) and "reads 2" in str(err.value) and "\n" not in str(err.value)


def test_shipped_tasks_are_reproducible_from_their_seed() -> None:
    """Every shipped task is exactly what make_task gives for its recorded attempt (checked on a sample)."""
    for t in DOC["tasks"][::7]:
        subset, family, k = t["subset"], t["metadata"]["family"], int(t["id"].rsplit("_", 1)[1])
        again = make_task(DOC["seed"], subset, family, k, t["metadata"]["attempt"])
        meta = {key: v for key, v in t["metadata"].items() if key not in ("oracle_steps", "attempt")}
        again_meta = {key: v for key, v in again["metadata"].items() if key not in ("oracle_steps", "attempt")}
        assert again["instruction"] == t["instruction"] and again_meta == meta


def test_generate_writes_a_verified_file(tmp_path: Path) -> None:
    out = generate(out=tmp_path / "t.json", seed=3, per_family=1, subsets="visual", quiet=True)
    doc = json.loads(out.read_text())
    assert doc["count"] == 3 and doc["seed"] == 3 and doc["verified"]
    assert {t["metadata"]["family"] for t in doc["tasks"]} == {"pick", "stack", "sorter"}
    from eb_manipulation.env import ManipulationEnv

    assert [t.id for t in ManipulationEnv.load_tasks(task_file=str(out))] == [t["id"] for t in doc["tasks"]]
