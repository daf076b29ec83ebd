"""Probes of the instructions alone: near-duplicates, too few templates, and mechanical writing defects."""

from __future__ import annotations

import re
from collections import Counter
from typing import Any

from eb_core.audit.contract import ProbeResult
from eb_core.audit.setup import AuditSetup, _by_subset, _listed, _pct

__all__ = ["grammar_issues", "probe_grammar", "probe_templates", "probe_unique_instructions"]

UNIQUE_MIN = 0.95
TEMPLATES_MIN = 10


def probe_unique_instructions(setup: AuditSetup) -> ProbeResult:
    rows, failing, worst = [], [], (1.0, "")
    dup_note = []
    for subset, ts in _by_subset(setup.tasks).items():
        norm = [" ".join(t.instruction.lower().split()) for t in ts]
        counts = Counter(norm)
        unique = len(counts) / len(ts)
        first: dict[str, str] = {}
        dups = []
        for t, n in zip(ts, norm):
            if counts[n] > 1:
                if n in first:
                    dups.append(t.id)
                    dup_note.append(f"{t.id} = {first[n]}")
                else:
                    first[n] = t.id
        rows.append({"subset": subset, "tasks": len(ts), "unique": _pct(unique), "duplicates": len(dups)})
        if unique < worst[0]:
            worst = (unique, subset)
        failing += dups
    value = f"worst {_pct(worst[0])} unique ({worst[1]})" if worst[1] else "100 % unique in every subset"
    warning = None
    passed = worst[0] >= UNIQUE_MIN
    if failing:
        note = ", ".join(dup_note[:4]) + (" ..." if len(dup_note) > 4 else "")
        value += f"; duplicates: {note}"
        if passed:
            warning = f"{len(failing)} duplicate instructions (same words, ignoring case and spacing): {note}"
    return ProbeResult(name="instruction_unique", passed=passed, value=value,
                       threshold=">= 95 % unique per subset (duplicates named)", failing_tasks=_listed(failing),
                       warning=warning, rows=rows)


def probe_templates(setup: AuditSetup) -> ProbeResult:
    groups = _by_subset(setup.tasks)
    if not any("template" in t.metadata for t in setup.tasks):
        return ProbeResult(name="instruction_templates", passed=True, skipped=True,
                           value="n/a (tasks carry no metadata['template'])",
                           threshold=f">= {TEMPLATES_MIN} templates per subset")
    rows: list[dict[str, Any]] = []
    bad: list[str] = []
    failing: list[str] = []
    for subset, ts in groups.items():
        n = len({str(t.metadata.get("template")) for t in ts if "template" in t.metadata})
        rows.append({"subset": subset, "templates": n, "tasks": len(ts)})
        if n < TEMPLATES_MIN:
            bad.append(f"{subset} ({n})")
            failing += [t.id for t in ts]
    worst = min(rows, key=lambda r: r["templates"])
    value = f"fewest: {worst['templates']} ({worst['subset']})" + (f"; below: {', '.join(bad)}" if bad else "")
    return ProbeResult(name="instruction_templates", passed=not bad, value=value,
                       threshold=f">= {TEMPLATES_MIN} templates per subset", failing_tasks=_listed(failing), rows=rows)


_SILENT_H = ("hour", "honest", "honor", "honour", "heir")
_CONSONANT_U = ("use", "usu", "usa", "ute", "uti", "ura", "ure", "uri", "uro", "ufo", "uk", "ubiq", "uku", "uvu")
_LETTER_VOWEL_SOUND = set("AEFHILMNORSX")
_DOUBLED_OK = {"that", "had", "is", "bye", "no", "very", "so"}


def _vowel_sound(word: str) -> bool | None:
    """Whether ``word`` starts with a vowel sound (for a/an); None when unsure."""
    w = word.strip("\"'()[]{}.,;:!?")
    if not w:
        return None
    if w[0].isdigit():
        return w.startswith("8") or w in ("11", "18") or w.startswith(("11,", "18,"))
    if (len(w) == 1 or (w.isupper() and len(w) <= 4)) and w[0].isalpha():
        return w[0].upper() in _LETTER_VOWEL_SOUND
    lw = w.lower()
    if lw.startswith(_SILENT_H):
        return True
    if lw.startswith("herb"):
        return None
    if lw[0] not in "aeiou":
        return False
    if lw.startswith(("one", "once", "eu", "ewe")):
        return False
    if lw.startswith("uni"):  # unique, unit, uniform ... but uninteresting, unimportant, unidentified
        return lw.startswith(("unin", "unim", "unid"))
    if lw.startswith(_CONSONANT_U):
        return False
    return True


def grammar_issues(text: str) -> list[str]:
    """Mechanical writing defects: a/an before the wrong sound, doubled words, stray spaces, unbalanced
    brackets or quotes, an empty sentence."""
    issues: list[str] = []
    if text != text.strip():
        issues.append("leading or trailing whitespace")
    if "  " in text:
        issues.append("double space")
    if re.search(r"\s[,.;:!?](?!\w)", text):
        issues.append("space before punctuation")
    if re.search(r"[,;:]{2,}|\.\.(?!\.)|[,;:]\.", text):
        issues.append("doubled punctuation")
    words = re.findall(r"[A-Za-z0-9'\-]+|[^\sA-Za-z0-9]", text)
    for i, w in enumerate(words[:-1]):
        nxt = words[i + 1]
        lw = w.lower()
        if lw in ("a", "an") and re.match(r"[A-Za-z0-9]", nxt):
            vowel = _vowel_sound(nxt)
            if vowel is True and lw == "a":
                issues.append(f"'a {nxt}' (use 'an')")
            elif vowel is False and lw == "an":
                issues.append(f"'an {nxt}' (use 'a')")
    for m in re.finditer(r"\b([A-Za-z]+)\s+\1\b", text, re.I):
        if m.group(1).lower() not in _DOUBLED_OK:
            issues.append(f"doubled word '{m.group(0)}'")
    for open_, close in (("(", ")"), ("[", "]")):
        if text.count(open_) != text.count(close):
            issues.append(f"unbalanced '{open_}{close}'")
    if text.count('"') % 2:
        issues.append("unbalanced '\"'")
    if re.search(r"[.!?]\s+[a-z]", text):
        issues.append("sentence starts lowercase")
    return issues


def probe_grammar(setup: AuditSetup) -> ProbeResult:
    rows: list[dict[str, Any]] = []
    failing: list[str] = []
    kinds: Counter[str] = Counter()
    for t in setup.tasks:
        found = grammar_issues(t.instruction)
        if found:
            failing.append(t.id)
            kinds.update("a/an" if "(use '" in f else "doubled word" if f.startswith("doubled word") else f
                         for f in found)
            if len(rows) < 10:
                rows.append({"task": t.id, "issues": "; ".join(found), "instruction": t.instruction[:90]})
    value = (f"{len(failing)} instructions with issues (" + ", ".join(f"{k}: {v}" for k, v in kinds.most_common(4))
             + ")") if failing else f"no issues in {len(setup.tasks)} instructions"
    return ProbeResult(name="instruction_grammar", passed=not failing, value=value,
                       threshold="no a/an, doubled-word, spacing or bracket defects", failing_tasks=_listed(failing),
                       rows=rows)

