"""The generator is deterministic, reproduces the shipped files and writes only valid, well-worded tasks."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest

from eb_habitat.catalog import FRIDGE_END, KITCHEN_SIDE_CHAIR
from eb_habitat.generate import PLURAL, fix_articles, generate
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


@pytest.mark.parametrize("subset", SUBSETS)
def test_each_subset_has_ten_templates_and_unique_instructions(subset: str) -> None:
    tasks = [t for t in load_tasks() if t.subset == subset]
    assert len(tasks) == 50
    templates = Counter(t.metadata["template"] for t in tasks)
    assert len(templates) >= 10, templates
    assert len({t.instruction for t in tasks}) >= 0.95 * len(tasks)


def test_templates_cover_the_paper_subsets() -> None:
    tasks = load_tasks()
    families = {t.metadata["template"].rsplit(".", 1)[0] for t in tasks}
    for needed in ("complex.if_open", "complex.if_present", "complex.context", "visual.color_variant",
                   "visual.looks", "spatial.beside", "spatial.with_landmark", "long.multi_object", "long.swap"):
        assert needed in families
    long = [t for t in tasks if t.subset == "long_horizon"]
    assert all(len(t.metadata["goal"]) >= 2 for t in long)
    assert all(t.metadata["oracle_steps"] <= 20 for t in long)


_VOWEL_SOUND_EXCEPTIONS = ("one", "uni", "use", "usu", "uten", "util", "eu")


def _grammar_problems(text: str) -> list[str]:
    problems = []
    for art, word in re.findall(r"\b([Aa]n?) ([A-Za-z']+)", text):
        vowel = word[0].lower() in "aeiou" and not word.lower().startswith(_VOWEL_SOUND_EXCEPTIONS)
        if art.lower() == "a" and vowel or art.lower() == "an" and not vowel:
            problems.append(f"'{art} {word}'")
    for plural in PLURAL:
        verbs = "is|has|needs|lies|belongs|goes|was|sits|stands"
        if re.search(rf"\ba {plural}\b|\b{plural} ({verbs})\b|\b{plural} and (put|bring|leave) it\b", text):
            problems.append(f"singular use of '{plural}'")
    if re.search(r"\b(the|a|an) (the|a|an)\b|  |\bin where\b|\bon the place\b", text):
        problems.append("doubled article, double space or a place used as a preposition's object")
    if not text[0].isupper() or text[-1] not in ".?!":
        problems.append("sentence case / final punctuation")
    return problems


def test_every_shipped_instruction_is_well_formed() -> None:
    bad = {t.id: _grammar_problems(t.instruction) for t in load_tasks()}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, bad


def test_grammar_check_catches_bad_articles_and_agreement() -> None:
    assert _grammar_problems("Find a orange and bring it to the sofa.")
    assert _grammar_problems("Carry an banana over to the desk.")
    assert _grammar_problems("Bring an utensil for flipping pancakes to the sofa.")
    assert _grammar_problems("The scissors is on the desk; move it.")
    assert _grammar_problems("The bowl goes where the scissors goes now.")
    assert _grammar_problems("Put the mug in where food stays cold.")
    assert fix_articles("Find a orange, an pear and a apple.") == "Find an orange, a pear and an apple."
    assert fix_articles("Bring a utensil and a one-euro coin.") == "Bring a utensil and a one-euro coin."


def test_layout_relations_follow_the_apartment() -> None:
    """spatial.layout tasks name a side that depends on the apartment, so the same words mean different places."""
    answers = Counter()
    for t in load_tasks():
        if not t.metadata["template"].startswith("spatial.layout"):
            continue
        apt, goal = t.metadata["apartment"], t.metadata["goal"][0]
        nearer = "nearer" in t.instruction
        if "chair" in t.instruction:
            assert (KITCHEN_SIDE_CHAIR[apt] in goal) == nearer, t.id
        else:
            assert (f" {FRIDGE_END[apt]}_" in goal) == nearer, t.id
        answers[goal.split()[-1].rstrip(")")] += 1
    assert len(answers) >= 2, answers


def test_eb_tasks_generate_writes_a_training_split_that_eb_run_plays(tmp_path):
    """`eb tasks generate env=habitat split=train n=N out=DIR`, then `eb run ... env.params.task_dir=DIR`; an
    unknown split is one line."""
    import json
    import subprocess
    import sys

    out = tmp_path / "train"
    r = subprocess.run([sys.executable, "-m", "eb_core", "tasks", "generate", "env=habitat", "split=train", "n=6",
                        f"out={out}"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    ids = [t["id"] for f in sorted(out.glob("*.json")) for t in json.loads(f.read_text())["tasks"]]
    assert len(ids) == 6
    run = subprocess.run([sys.executable, "-m", "eb_core", "run", "env=habitat", "model=oracle", "--quiet",
                          f"env.params.task_dir={out}", "env.params.render=false", f"hydra.run.dir={tmp_path / 'run'}"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "success rate: 100.0% (6 of 6 episodes succeeded)" in run.stdout
    bad = subprocess.run([sys.executable, "-m", "eb_core", "tasks", "generate", "env=habitat", "split=dev", "n=2",
                          f"out={tmp_path / 'x'}"], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "split" in bad.stderr


def test_eb_run_plays_a_generated_split_directly_and_keeps_it_apart_from_test_runs(tmp_path):
    import json
    import subprocess
    import sys

    base = [sys.executable, "-m", "eb_core", "run", "env=habitat", "model=oracle", "--quiet", "env.params.render=false",
            f"hydra.run.dir={tmp_path / 'run'}"]
    r = subprocess.run(base + ["split=val", "limit=4"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    ids = [json.loads(x)["task_id"] for x in (tmp_path / "run" / "episodes.jsonl").read_text().splitlines()]
    assert len(ids) == 4 and all(i.startswith("val-") for i in ids)
    missing = subprocess.run(base[:-1] + [f"hydra.run.dir={tmp_path / 'other'}", "split=val"], capture_output=True,
                             text=True, timeout=300)
    assert missing.returncode == 2 and "limit=N" in missing.stderr
    mixed = subprocess.run(base + ["limit=4"], capture_output=True, text=True, timeout=300)  # the test split, same dir
    assert mixed.returncode == 2 and "split" in mixed.stderr
