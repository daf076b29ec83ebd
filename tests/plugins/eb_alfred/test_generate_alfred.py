"""The generator's wording over every shipped instruction: grammar, templates, uniqueness, buried requests,
referring phrases, long-horizon spread, and the version gate of the task files."""

from __future__ import annotations

import collections
import json
import re
from pathlib import Path

import pytest

from eb_alfred.audit import probes
from eb_alfred.catalog import TYPES
from eb_alfred.env import AlfredEnv
from eb_alfred.instructions import _ASIDE, _CLOSE, _CONTEXT, noun, plural
from eb_alfred.tasks import SUBSETS, TASK_DIR, TaskFileError, load_task_file

_VOWEL_SOUND_EXCEPTIONS = {"one", "once", "unit", "united", "useful", "usual", "european", "uniform"}
_SILENT_H = {"hour", "honest", "honour"}


def _records() -> dict[str, list[dict]]:
    return {s: json.loads((TASK_DIR / f"{s}.json").read_text())["tasks"] for s in SUBSETS}


def article_problems(text: str) -> list[str]:
    """'a' before a vowel sound, 'an' before a consonant sound, an article before a plural noun, 'two' or
    'pair of' before a singular noun."""
    out = []
    for art, word in re.findall(r"\b(a|an|A|An)\s+([A-Za-z][\w-]*)", text):
        w = word.lower().split("-")[0]
        vowel = (w[0] in "aeiou" and w not in _VOWEL_SOUND_EXCEPTIONS) or w in _SILENT_H
        if art.lower() == "a" and vowel:
            out.append(f"'a {word}'")
        if art.lower() == "an" and not vowel:
            out.append(f"'an {word}'")
    nouns = {noun(t) for t in TYPES}
    plurals = {plural(t) for t in TYPES} - nouns
    for p in plurals:
        for m in re.finditer(rf"\b(a|an)\s+((?:\w+\s+)?){re.escape(p)}\b", text, flags=re.I):
            out.append(f"article before plural: {m.group(0)!r}")
    for n in nouns:
        if n in plurals:
            continue
        for m in re.finditer(rf"\b(two|pair of|both)\s+((?:\w+\s+)?){re.escape(n)}\b(?!\s*(?:box|holder|bottle|"
                             rf"shaker|knife|table|lamp|can|brush|towel|machine|basin|paper|hanger|bar|chain|"
                             rf"clock|card|phone|control|sponge|stand|chair|top))", text, flags=re.I):
            out.append(f"singular after '{m.group(1)}': {m.group(0)!r}")
    for m in re.finditer(r"\b(shelfs|knifes|loafs|boxs|dishs|glasss)\b", text, flags=re.I):
        out.append(f"wrong plural {m.group(0)!r}")
    return out


def test_article_checker_catches_the_known_slips() -> None:
    assert article_problems("Find a orange.") and article_problems("Should a apple go there?")
    assert article_problems("Put an mug on the desk.") and article_problems("Put two mug on the desk.")
    assert article_problems("Put a tomatoes in the fridge.") and article_problems("on one of the shelfs")
    assert not article_problems("Put an apple and a mug in an hour, a one-off, a CD box? no: an egg.")
    assert article_problems("Put an CD there.")


def test_every_shipped_instruction_has_right_articles_and_agreement() -> None:
    bad = {t["id"]: article_problems(t["instruction"]) for recs in _records().values() for t in recs}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, list(bad.items())[:5]


def test_templates_and_unique_instructions_per_subset() -> None:
    for subset, recs in _records().items():
        templates = {t["template"] for t in recs}
        unique = len({t["instruction"] for t in recs}) / len(recs)
        assert len(templates) >= 10, (subset, len(templates))
        assert unique >= 0.95, (subset, unique)


def test_complex_instructions_bury_the_request_without_a_signpost() -> None:
    signposts = ("what i need", "could you please", "my request", "the task is", "here is", ":")
    positions = collections.Counter()
    for t in _records()["complex_instruction"]:
        text = t["instruction"]
        assert not any(re.search(rf"(^|\W){re.escape(s)}", text.lower()) for s in signposts), text
        sentences = re.split(r"(?<=[.?!])\s+", text)
        assert len(sentences) >= 4, text
        # the request is the one sentence that is not stock context, an aside or a closing remark
        asides = [re.compile(re.escape(a).replace(r"\{d\}", ".+") + "$") for a in _ASIDE]
        request = [i for i, sen in enumerate(sentences)
                   if sen not in _CONTEXT and sen not in _CLOSE and not any(a.match(sen) for a in asides)]
        assert len(request) == 1 and request[0] > 0, text
        assert "please" not in sentences[request[0]].lower(), text
        positions[request[0]] += 1
    assert len(positions) >= 2  # the request moves around


def test_long_horizon_spread() -> None:
    recs = _records()["long_horizon"]
    steps = collections.Counter(t["oracle_steps"] for t in recs)
    assert all(n > 15 for n in steps.elements())
    assert max(steps.values()) <= 0.4 * len(recs), steps
    assert len({t["task_type"] for t in recs}) >= 3


def test_every_shipped_task_names_its_instance() -> None:
    probe = next(p for p in probes() if p.name == "referring_phrase")
    result = probe.run(AlfredEnv.load_tasks(), {})
    assert result.passed, result.rows[:3]


def test_shape_words_used_are_drawn_by_the_scene_kit() -> None:
    from eb_alfred.render import KIT
    from eb_scenekit import get_type

    used = 0
    for t in _records()["visual_appearance"]:
        goal = t["goal"]["object"]
        xt = goal.get("type") or goal["instance"].split("_")[0]
        for shape in TYPES[xt].shapes:
            if re.search(rf"\b{shape} ({re.escape(noun(xt))}|{re.escape(plural(xt))})\b", t["instruction"]):
                assert shape in get_type(KIT[xt][0]).shapes, (t["id"], shape)
                used += 1
    assert used >= 5  # the subset does use shape words


def test_an_old_version_file_is_refused_with_one_line(tmp_path: Path) -> None:
    data = json.loads((TASK_DIR / "base.json").read_text())
    data["version"] = 1
    path = tmp_path / "base.json"
    path.write_text(json.dumps(data))
    with pytest.raises(TaskFileError) as err:
        load_task_file(path)
    msg = str(err.value)
    assert "\n" not in msg and "version 1" in msg and "regenerate" in msg and "eb tasks generate env=alfred" in msg
