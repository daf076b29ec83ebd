"""The perception check: what a visual-state description claims, judged against what the image showed.

A careful reader's rules (docs/error_analysis.md, "Perception check"):

* a mention is a phrase naming an object: a term of the scene or the world, a synonym (:data:`~.lexicon.SYNONYMS`),
  a world's own name for an object in view (its ``aliases``), or the head noun of a term ("table" for the dining
  table); manipulation's "object k" names the object with that index;
* a mention in a clause that denies, remembers or guesses ("no TV is visible", "the table is no longer in view",
  "probably a TV stand", "I need to find the lamp") is not a claim about the image and is not judged;
* a mention of an object in view is *correct*, unless its colour words belong to no colour family of that object
  (or, for "object k", its shape differs): then it is *wrong*;
* a mention of an object of the scene that is not in this view is not judged (remembered, or at the very edge);
* a mention of a world's object type that is nowhere in the scene is *wrong*: a hallucination. (A wrong colour
  or shape for an object in view is a *misperception* of a real object, labelled apart.)

The step's score is correct / judged mentions; ``None`` when nothing could be judged and 0 when the description
names nothing at all while objects are in view.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from eb_core.errors.lexicon import (
    COLOURS,
    GENERIC,
    LOOKALIKES,
    PARTS,
    SHAPES,
    SYNONYMS,
    colour_families,
    norm,
    singular,
    term_of,
    words,
)

__all__ = ["ABSENT", "has_description", "perception_check"]

#: The ``why`` of a wrong mention naming an object type that is nowhere in the scene (a hallucination); every
#: other ``why`` is a wrong colour or shape for an object in view (a misperception).
ABSENT = "nowhere in the scene"

#: A clause with one of these words makes no claim about what the image shows now.
_NOT_A_CLAIM = re.compile(
    r"\b(no|not|never|nor|without|cannot|can't|isn't|aren't|don't|doesn't|won't|none|nothing|neither|"
    r"anymore|invisible|hidden|behind me|earlier|previously|before|remember\w*|recall\w*|was|were|had|"
    r"gone|out of view|off[- ]screen|outside|probably|possibly|maybe|might|perhaps|likely|presumably|"
    r"expect\w*|should|would|could|may|seems?|looks? like|need|needs|want|wants|search\w*|look for|"
    r"looking for|find|locate|reach|unsure|unclear|if)\b")

_OBJECT_K = re.compile(r"\bobject\s*(?:#|no\.?\s*)?(\d+)\b", re.IGNORECASE)


@dataclass
class _Mention:
    words: str
    terms: set[str]
    colours: list[str]
    shape: str | None = None
    ref: str | None = None  # "object k"
    start: int = 0
    compared: bool = False  # "plate-like": what another thing looks like, not a claim


@dataclass
class _Seen:
    terms: set[str] = field(default_factory=set)
    by_term: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    by_name: dict[str, dict[str, Any]] = field(default_factory=dict)


def has_description(description: Any) -> bool:
    """Whether a run wrote a description at all: not empty and not a baseline's parenthesised placeholder such as
    ``(oracle)`` or ``(random baseline: the image is ignored)``."""
    text = str(description or "").strip()
    return bool(text) and not (text.startswith("(") and text.endswith(")") and text.count("(") == 1)


#: Colour families a person may confuse under a room's light (white walls look grey; walnut looks black).
_NEAR = [{"white", "grey"}, {"grey", "black"}, {"brown", "orange"}, {"brown", "red"}, {"brown", "black"},
         {"brown", "yellow"}, {"orange", "yellow"}, {"orange", "red"}, {"red", "pink"}, {"pink", "purple"},
         {"purple", "blue"}, {"blue", "green"}, {"green", "yellow"}, {"white", "yellow"}, {"brown", "grey"}]


def _compatible(said: set[str], has: set[str]) -> bool:
    return bool(said & has) or any({a, b} in _NEAR for a in said for b in has)


def _colours_of(obj: dict[str, Any]) -> set[str]:
    """The colour families of an object in view: those its pixels show (``colours``) when the world counted them,
    else its declared colour, else colour words in its type ("red cube")."""
    if obj.get("colours"):
        return {c for c in obj["colours"] if isinstance(c, str)}
    if obj.get("pixels") is not None and obj.get("colours") is not None:
        return set()  # counted, but too few pixels of any one colour: not judged
    fams = colour_families(obj.get("colour") or obj.get("color"))
    if not fams:  # colour words inside the type ("red cube") or the name
        for w in words(f"{obj.get('type') or ''}"):
            if w in COLOURS:
                fams |= colour_families(w)
    return fams


def _seen(visible: Sequence[dict[str, Any]]) -> _Seen:
    out = _Seen()
    for obj in visible:
        t = term_of(obj.get("type") or obj.get("name") or "")
        if not t:
            continue
        out.terms.add(t)
        out.by_term.setdefault(t, []).append(obj)
        out.by_name[str(obj.get("name") or "").lower()] = obj
    return out


def _phrases(known: set[str], visible: Sequence[dict[str, Any]]) -> dict[tuple[str, ...], set[str]]:
    """Phrase (singular words) -> the terms it may name."""
    table: dict[tuple[str, ...], set[str]] = {}

    def add(phrase: str, terms: Iterable[str]) -> None:
        key = tuple(norm(phrase).split())
        if key and not (len(key) == 1 and key[0] in GENERIC):
            table.setdefault(key, set()).update(terms)

    for t in known:
        add(t, [t])
        head = t.split()[-1]
        if len(t.split()) > 1 and head not in GENERIC:
            add(head, [t])
        if " " in t:
            add(t.replace(" ", ""), [t])  # "armchair", "countertop"
    for obj in visible:
        t = term_of(obj.get("type") or obj.get("name") or "")
        for alias in obj.get("aliases") or ():
            alias_words = [w for w in norm(alias).split() if w not in COLOURS and w not in ("a", "an", "the")]
            if not alias_words or len(alias_words) > 4:
                continue  # a whole sentence is no name
            add(" ".join(alias_words), [t])
            if len(alias_words) > 1 and alias_words[-1] not in GENERIC:
                add(alias_words[-1], [t])
    for phrase, targets in SYNONYMS.items():
        add(phrase, targets)
    return table


#: Words after which a colour word no longer describes the next object named ("a blue item, bread": the item is
#: blue, not the bread); "and"/"or" only when no colour comes just before ("red and white mug" is one mug).
_COLOUR_STOPS = frozenset(["and", "or", "with", "of", "beside", "near", "next", "behind", "on", "in", "at", "from",
                           "holding", "between", "than", "plus"]) | (GENERIC - {"light"})

#: Words that make a name a comparison, not a claim: "almost plate-like", "shaped like a cup", "resembling a kettle".
_LIKE_AFTER = frozenset(["like", "shaped", "looking", "style", "ish"])
_LIKE_BEFORE = frozenset(["like", "resembling", "resembles", "resemble", "resembled"])


def _colour_start(raw: list[str], lo: int, i: int) -> int:
    """Where the colour words of a name at ``i`` may start: not before ``lo`` nor before a stop word."""
    start = max(lo, i - 3)
    for j in range(i - 1, start - 1, -1):
        w = raw[j]
        if w in _COLOUR_STOPS and not (w in ("and", "or") and j > 0 and raw[j - 1] in COLOURS):
            return j + 1
    return start


def _compared(raw: list[str], i: int, n: int) -> bool:
    """Whether the name ``raw[i:i + n]`` only says what another thing looks like ("a plate-like bowl")."""
    after = raw[i + n:i + n + 2]
    before = [w for w in raw[max(0, i - 2):i] if w not in ("a", "an", "the")]
    # "plate-like", "plate-shaped" compare; in "a bowl shaped like a plate" the bowl is the thing named
    return ((bool(after) and after[0] in _LIKE_AFTER and after[1:] != ["like"])
            or bool(before and before[-1] in _LIKE_BEFORE))


def _clause_mentions(clause: str, table: dict[tuple[str, ...], set[str]], longest: int) -> list[_Mention]:
    # a comma ends a list item: a colour word before it belongs to that item ("a blue item, bread")
    pieces = [words(p) for p in re.split(r"[,:]", clause)]
    raw = [w for p in pieces for w in p]
    piece_start = [sum(len(p) for p in pieces[:k]) for k, p in enumerate(pieces) for _ in p]
    sing = [singular(w) for w in raw]
    out: list[_Mention] = []
    i = 0
    last_end = 0
    def starts_phrase(j: int) -> bool:
        return any(tuple(sing[j:j + n]) in table for n in range(1, min(longest, len(sing) - j) + 1))

    while i < len(sing):
        for n in range(min(longest, len(sing) - i), 0, -1):
            key = tuple(sing[i:i + n])
            if n == 1 and raw[i] in COLOURS and i + 1 < len(sing) and starts_phrase(i + 1):
                continue  # "an orange bowl": the colour of the bowl, not an orange
            if key in table:
                lo = _colour_start(raw, max(last_end, piece_start[i]), i)
                cols = [w for w in raw[lo:i] if w in COLOURS or w in ("light", "dark")]
                m = _Mention(" ".join(raw[i:i + n]), set(table[key]), cols, start=i)
                m.compared = _compared(raw, i, n)
                out.append(m)
                i += n
                last_end = i
                break
        else:
            i += 1
    return out


def _object_refs(clause: str, table: dict[tuple[str, ...], set[str]], longest: int) -> list[_Mention]:
    """Manipulation's "object k is a silver cube": the colour and shape words said of each object index."""
    out = []
    parts = _OBJECT_K.split(clause)
    for k in range(1, len(parts) - 1, 2):
        said = re.split(r"\bobject\b", parts[k + 1], flags=re.IGNORECASE)[0]
        # only what is said *of* the object ("is a silver cube"), not what stands next to it ("beside the star")
        said = re.split(r"[,;]|\b(?:and|next|near|on|at|to|beside|behind|left|right|above|below|under|in|into|"
                        r"with|of|from|than|which|that|while)\b", said, flags=re.IGNORECASE)[0]
        cols = [w for w in words(said) if w in COLOURS or w in ("light", "dark")]
        named = {SHAPES[p] for p in SHAPES if re.search(rf"\b{p}s?\b", said.lower())}
        shape = next(iter(named)) if len(named) == 1 else None
        out.append(_Mention(f"object {parts[k]}", set(), cols, shape=shape, ref=f"object {parts[k]}"))
    return out


def _said_families(cols: list[str]) -> set[str]:
    fams: set[str] = set()
    i = 0
    while i < len(cols):
        if cols[i] in ("light", "dark") and i + 1 < len(cols):
            fams |= colour_families(f"{cols[i]} {cols[i + 1]}") | colour_families(cols[i + 1])
            i += 2
            continue
        fams |= colour_families(cols[i])
        i += 1
    return fams


#: Objects smaller than this (segmentation pixels) may hide a second instance of their type: when a description
#: gives more colours for a type than instances are in view, their colours are not judged.
SMALL_OBJECT_PIXELS = 400

#: Fewest segmentation pixels an object needs for its colour to be judged (a speck's colours are noise).
MIN_COLOUR_PIXELS = 50


def _judge_colour(m: _Mention, objs: list[dict[str, Any]]) -> str | None:
    """Why the colour said is wrong for every object it may name, or None (right, or not judged)."""
    said = _said_families(m.colours)
    if any((o.get("pixels") is not None and o["pixels"] < MIN_COLOUR_PIXELS) for o in objs):
        return None
    known = [_colours_of(o) for o in objs]
    if not said or not any(known):
        return None
    if any(not k or _compatible(said, k) for k in known):
        return None
    truth = sorted({c for k in known for c in k})
    return f"said {' '.join(m.colours)}; in view it shows {', '.join(truth)}"


def _same_kind(terms: set[str], pool: set[str]) -> set[str]:
    """Terms of ``pool`` a mention may mean: the same term, or one with the same head noun ("dining table" and
    the table in view: a person may call a table by another table's name, which is no hallucination)."""
    heads = {t.split()[-1] for t in terms if t}
    return {t for t in pool if t in terms or (t and t.split()[-1] in heads)}


def _fits_a_lookalike(m: _Mention, seen: _Seen) -> bool:
    """The colour said fits an object in view of a type drawn like the one named (:data:`~.lexicon.LOOKALIKES`)."""
    alike = {a for t in m.terms for a in LOOKALIKES.get(t, frozenset())} & seen.terms
    return any(_judge_colour(m, [o]) is None for a in sorted(alike) for o in seen.by_term[a])


def _judge(m: _Mention, seen: _Seen, scene: set[str], world: set[str]) -> tuple[str, str | None, list[str]]:
    """(verdict, why, terms): verdict ``correct``, ``wrong`` or ``unjudged``."""
    if m.ref is not None:
        obj = seen.by_name.get(m.ref)
        if obj is None:
            return "unjudged", None, []
        t = term_of(obj.get("type") or "")
        why = _judge_colour(m, [obj])
        if why is None and m.shape and t in SHAPES.values() and m.shape != t:
            why = f"said a {m.shape}; {m.ref} is a {obj.get('type')}"
        return ("wrong" if why else "correct"), why, [t] if t else []
    in_view = sorted(_same_kind(m.terms, seen.terms))
    if in_view:
        why = _judge_colour(m, [o for t in in_view for o in seen.by_term[t]])
        if why and _fits_a_lookalike(m, seen):
            return "unjudged", None, []  # the colour fits a thing drawn like it: which one was meant is unclear
        return ("wrong" if why else "correct"), why, in_view
    if _same_kind(m.terms, scene) or not m.terms & world:
        return "unjudged", None, sorted(m.terms & scene)  # remembered or at the edge; or a thing this world lacks
    if any(PARTS.get(t, frozenset()) & seen.terms for t in m.terms):
        return "unjudged", None, []  # a part of a thing in view (the pillows of the bed)
    if any(LOOKALIKES.get(t, frozenset()) & seen.terms for t in m.terms):
        return "unjudged", None, []  # a thing the render draws like one in view (a red watering can: a kettle)
    return "wrong", ABSENT, sorted(m.terms & world)


@dataclass
class _Verdicts:
    """The judged mentions of one description."""

    correct: set[str] = field(default_factory=set)
    wrong: set[str] = field(default_factory=set)
    unjudged: set[str] = field(default_factory=set)
    evidence: list[dict[str, Any]] = field(default_factory=list)
    any_mention: bool = False

    def add(self, m: _Mention, verdict: str, why: str | None, terms: list[str]) -> None:
        label = m.ref or (terms[0] if len(terms) == 1 else m.words)
        if verdict == "unjudged":
            self.unjudged.add(label)
            return
        (self.correct if verdict == "correct" else self.wrong).add(label)
        self.evidence.append({"words": (" ".join(m.colours + [m.words])).strip(), "verdict": verdict,
                              "objects": terms, "label": label, **({"why": why} if why else {})})

    def result(self, seen: _Seen) -> dict[str, Any] | None:
        mentioned = self.correct | self.wrong
        if not mentioned and not self.any_mention and not seen.terms:
            return None
        judged = len(self.evidence)  # every judged mention counts, a repeated one too
        precision = sum(e["verdict"] == "correct" for e in self.evidence) / judged if judged else None
        recall = len({t for t in self.correct if t in seen.terms}) / len(seen.terms) if seen.terms else None
        if judged:
            score: float | None = precision
        elif not self.any_mention and seen.terms:
            score = 0.0  # names nothing while objects are in view: a complete miss
        else:
            score = None
        absent = {e["label"] for e in self.evidence if e["verdict"] == "wrong" and e.get("why") == ABSENT}
        evidence = [{k: v for k, v in e.items() if k != "label"} for e in self.evidence]
        return {"mentioned": sorted(mentioned), "visible": sorted(seen.terms), "correct": sorted(self.correct),
                "wrong": sorted(self.wrong), "hallucinated": sorted(self.wrong & absent),
                "misperceived": sorted(self.wrong - absent), "unjudged": sorted(self.unjudged), "evidence": evidence,
                "precision": precision, "recall": recall, "score": score, "f1": score}


def _colour_sets(clauses: list[str], table: dict[tuple[str, ...], set[str]], longest: int
                 ) -> dict[frozenset[str], set[tuple[str, ...]]]:
    """The distinct colour phrases said of each kind of object across the description."""
    out: dict[frozenset[str], set[tuple[str, ...]]] = {}
    for clause in clauses:
        for m in _clause_mentions(clause, table, longest):
            if m.colours:
                out.setdefault(frozenset(m.terms), set()).add(tuple(m.colours))
    return out


def _hidden_instance(m: _Mention, said: set[tuple[str, ...]] | tuple[()], seen: _Seen) -> bool:
    """More colours said for a type than instances in view, all of them small: another may hide ("a red book,
    a blue book" with one small book segmented), so which colour is whose cannot be told."""
    same = [o for t in _same_kind(m.terms, seen.terms) for o in seen.by_term[t]]
    return (m.ref is None and bool(m.colours) and len(said) > len(same)
            and all((o.get("pixels") or 0) < SMALL_OBJECT_PIXELS for o in same))


def perception_check(description: str | None, visible: Sequence[dict[str, Any]],
                     vocabulary: Iterable[str] = (), scene: Iterable[str] = ()) -> dict[str, Any] | None:
    """Judge a visual-state description against the objects in view (see the module docstring).

    ``visible``: the step's ``visible_objects`` (``name``, ``type``, optional ``colour``, ``colours``,
    ``aliases``, ``pixels``); ``vocabulary``: the object terms this world has (a mention of one that is nowhere in
    the scene is wrong; a mention of anything else is recognised through the synonyms but never judged absent);
    ``scene``: the terms of this episode's scene (in view at any step, or said by the world to be there).
    Returns None when there is no description; else ``mentioned``, ``visible``, ``correct``, ``wrong`` (split
    into ``hallucinated``: nowhere in the scene, and ``misperceived``: in view with a wrong colour or shape),
    ``unjudged`` (term lists), ``evidence`` (one entry per judged mention: its words, verdict and why),
    ``precision``, ``recall``, ``score`` and ``f1`` (= ``score``, the name older readers use).
    """
    if not has_description(description):
        return None
    # "a trash can/pot", "white/light grey": a person hedging between two names; the first one is the claim
    text = re.sub(r"([A-Za-z-]+)/[A-Za-z-]+", r"\1", str(description))
    # coordinates ("object 6 [58, 45, 17] black block") are no words, and their commas split no list
    text = re.sub(r"\[[^\[\]]*\]", " ", text)
    seen = _seen(visible)
    scene_terms = {term_of(t) for t in scene} | seen.terms
    known = {t for t in {term_of(v) for v in vocabulary} | scene_terms if t}
    table = _phrases(known, visible)
    longest = max((len(k) for k in table), default=1)
    clauses = [c for c in re.split(r"[.;!?\n]+|,\s*(?:but|while|whereas)\b", text) if c.strip()]
    colour_sets = _colour_sets(clauses, table, longest)
    out = _Verdicts()
    for clause in clauses:
        ms = _object_refs(clause, table, longest) + [m for m in _clause_mentions(clause, table, longest)
                                                    if not _OBJECT_K.search(clause)]
        out.any_mention |= bool(ms)
        claim = not _NOT_A_CLAIM.search(clause.lower())
        for m in ms:
            if _hidden_instance(m, colour_sets.get(frozenset(m.terms), ()), seen):
                m.colours = []
            if not claim or m.compared:
                out.unjudged.add(m.words)
                continue
            out.add(m, *_judge(m, seen, scene_terms, known))
    return out.result(seen)
