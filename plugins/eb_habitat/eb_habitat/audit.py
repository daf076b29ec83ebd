"""EB-Habitat's own shortcut probes for ``eb audit`` (behind :meth:`HabitatEnv.audit_probes`).

* ``word_matching_spatial``: a text-only agent that maps the words of a spatial_relationship instruction straight
  onto action names (the first object named -> ``pick up the <object>``, the receptacle words after it ->
  ``place it on the <receptacle>``, "left"/"right" next to "drawer", "counter" or "chair" -> that side) and,
  generously, knows where every object lies. If it solves many spatial tasks, the relation in the instruction
  is decorative: it can be resolved without the image.
* ``conditional_first_branch``: a text-only agent that always follows the first branch of a conditional
  complex_instruction ("If ..., move the A ...; otherwise the B") must not do much better than chance.

Both run on the symbolic world only (no MuJoCo) and take well under a second for 300 tasks.
"""

from __future__ import annotations

import re
from collections import defaultdict
from dataclasses import dataclass
from typing import Any

from eb_core.audit.contract import AuditProbe, ProbeResult
from eb_core.env import Task
from eb_habitat.catalog import COLORS, OBJECT_TYPES, receptacle
from eb_habitat.goals import Predicate
from eb_habitat.oracle import OracleError, expert_plan
from eb_habitat.tasks import spec_of

__all__ = [
    "WORD_MATCH_LIMIT",
    "FIRST_BRANCH_LIMIT",
    "WordGuess",
    "conditional_first_branch",
    "probes",
    "word_guess",
    "word_matching_score",
    "word_matching_spatial",
]

WORD_MATCH_LIMIT = 0.20
"""Largest share of spatial_relationship tasks the word-matching agent may solve."""
FIRST_BRANCH_LIMIT = 0.65
"""Largest share of conditional tasks that the first-named branch may solve (chance is one half)."""

_TOKEN = re.compile(r"[a-z']+")

#: Head nouns a matcher would map to receptacles, with the receptacles each may mean.
_HEADS: dict[str, tuple[str, ...]] = {
    "counter": ("left_counter", "right_counter"),
    "drawer": ("left_drawer", "right_drawer"),
    "chair": ("left_chair", "right_chair"),
    "table": ("dining_table", "coffee_table", "brown_table"),
    "sink": ("sink",), "basin": ("sink",),
    "fridge": ("fridge",), "refrigerator": ("fridge",),
    "cabinet": ("cabinet",), "cupboard": ("cabinet",),
    "sofa": ("sofa",), "couch": ("sofa",),
    "tv": ("tv_stand",), "television": ("tv_stand",),
    "desk": ("desk",),
}
#: Words before a head noun that pick one of its receptacles.
_MODIFIERS = {"left": "left_", "right": "right_", "dining": "dining_", "coffee": "coffee_", "brown": "brown_"}


@dataclass(frozen=True)
class WordGuess:
    """What the matcher makes of an instruction: the object type, an optional colour, candidate targets."""

    type_key: str
    color: str | None
    targets: tuple[str, ...]


def _tokens(text: str) -> list[str]:
    return _TOKEN.findall(text.lower().replace("-", " "))


def _object_mentions(toks: list[str]) -> list[tuple[int, str, int]]:
    """(position, type key, length in tokens) of every object-type name in the token list."""
    out = []
    for t in OBJECT_TYPES:
        for name in (t.name, *t.aliases):
            words = _tokens(name)
            for i in range(len(toks) - len(words) + 1):
                if toks[i:i + len(words)] == words or toks[i:i + len(words)] == words[:-1] + [words[-1] + "s"]:
                    out.append((i, t.key, len(words)))
    out.sort(key=lambda m: (m[0], -m[2]))
    return out


def _receptacle_mentions(toks: list[str], start: int) -> list[tuple[int, tuple[str, ...]]]:
    """(position, candidate receptacle keys) of every receptacle word at or after ``start``, side words applied."""
    out = []
    for i in range(start, len(toks)):
        cands = _HEADS.get(toks[i])
        if cands is None:
            continue
        if toks[i] == "tv" and i + 1 < len(toks) and toks[i + 1] == "stand":
            cands = ("tv_stand",)
        if len(cands) > 1:
            window = toks[max(0, i - 2):i] + toks[i + 1:i + 6]
            for word in window:
                prefix = _MODIFIERS.get(word)
                chosen = tuple(c for c in cands if prefix is not None and c.startswith(prefix))
                if chosen:
                    cands = chosen
                    break
        if i > 0 and toks[i - 1] in ("from", "off"):
            continue
        if i > 1 and toks[i - 2] in ("from", "off") and toks[i - 1] == "the":
            continue
        out.append((i, cands))
    return out


def word_guess(instruction: str) -> WordGuess | None:
    """The matcher's reading of ``instruction``, or None when it names no object type or no receptacle."""
    toks = _tokens(instruction)
    objs = _object_mentions(toks)
    if not objs:
        return None
    pos, type_key, length = objs[0]
    color = None
    t = next(o for o in OBJECT_TYPES if o.key == type_key)
    if pos > 0:
        for c in t.colors:
            words = _tokens(c)
            if toks[max(0, pos - len(words)):pos] == words:
                color = c
    mentions = _receptacle_mentions(toks, pos + length)
    if not mentions:
        return None
    return WordGuess(type_key, color, mentions[0][1])


def word_matching_score(task: Task) -> float:
    """Expected success of the matcher on ``task`` (its picks among equal candidates count as a fair draw),
    given perfect knowledge of where objects lie."""
    guess = word_guess(task.instruction)
    if guess is None:
        return 0.0
    spec = spec_of(task)
    goal = spec.goal_predicates()
    start = spec.world()
    instances = [it for it in start.items.values()
                 if it.type == guess.type_key and (guess.color is None or it.color == guess.color)]
    if not instances:
        return 0.0
    wins = 0
    for target in guess.targets:
        name = "inside" if receptacle(target).kind == "container" else "on"
        for it in instances:
            world = start.copy()
            try:
                for action in expert_plan(world, [Predicate(name, (it.name, target))]):
                    world.step(action)
            except OracleError:
                continue
            wins += all(p.holds(world) for p in goal)
    return wins / (len(guess.targets) * len(instances))


def _result(name: str, share: float, limit: float, n: int, failing: list[str],
            rows: list[dict[str, Any]]) -> ProbeResult:
    passed = share <= limit
    # The solved tasks are named only when the share is too high: then they are what to rewrite.
    return ProbeResult(name=name, passed=passed, value=f"{100 * share:.1f} % of {n} tasks",
                       threshold=f"<= {100 * limit:.0f} %", failing_tasks=[] if passed else failing[:40], rows=rows)


def word_matching_spatial(tasks: list[Task], env_params: dict[str, Any] | None = None) -> ProbeResult:
    """Run the word-matching agent over the spatial_relationship tasks."""
    spatial = [t for t in tasks if t.subset == "spatial_relationship"]
    by_template: dict[str, list[float]] = defaultdict(list)
    total, solved = 0.0, []
    for t in spatial:
        s = word_matching_score(t)
        total += s
        by_template[str(t.metadata.get("template", "?"))].append(s)
        if s >= 0.5:
            solved.append(t.id)
    rows = [{"template": k, "tasks": len(v), "expected_solved": round(sum(v), 2)}
            for k, v in sorted(by_template.items())]
    share = total / len(spatial) if spatial else 0.0
    return _result("word_matching_spatial", share, WORD_MATCH_LIMIT, len(spatial), solved, rows)


def _first_branch_type(instruction: str) -> str | None:
    """The object type of the first "move the X" branch: the first object named after the condition's comma or
    full stop (the condition itself may name an object, as in "If there is a mug on ...")."""
    return _first_branch(instruction)[0]


def _first_branch(instruction: str) -> tuple[str | None, str | None]:
    """The object type of the first branch and the colour word right before it, if any (the hard set's branches
    name two colours of one type: "If it is red, bring the blue mug ...; otherwise the white mug")."""
    toks = _tokens(instruction.split(",", 1)[1] if "," in instruction else instruction)
    mentions = _object_mentions(toks)
    if not mentions:
        return None, None
    if len(mentions) > 1 and mentions[0][1] in COLORS and mentions[1][0] == mentions[0][0] + 1:
        return mentions[1][1], mentions[0][1]  # "the orange ball": the colour, not the fruit
    pos = mentions[0][0]
    for color in sorted(COLORS, key=lambda c: -len(c.split())):  # "light green" before "green"
        words = _tokens(color)
        if pos >= len(words) and toks[pos - len(words):pos] == words:
            return mentions[0][1], color
    return mentions[0][1], None


def conditional_first_branch(tasks: list[Task], env_params: dict[str, Any] | None = None) -> ProbeResult:
    """Share of conditional complex_instruction tasks solved by always taking the first branch."""
    cond = [t for t in tasks if t.subset == "complex_instruction" and "if" in str(t.metadata.get("template", ""))]
    wins, solved = 0, []
    for t in cond:
        spec = spec_of(t)
        placed = [p for p in spec.goal_predicates() if p.name in ("on", "inside")]
        template = str(t.metadata.get("template", ""))
        if ".if_count." in template:
            # both branches move the same object, one "there" (the landmark's place), the other to the receptacle
            # the instruction names; the named one comes first in the ``.named_first.`` templates
            named = any(receptacle(p.args[1]).name.lower() in t.instruction.lower() for p in placed)
            if placed and named == (".named_first." in template):
                wins += 1
                solved.append(t.id)
            continue
        first, color = _first_branch(t.instruction)
        types = {spec.instances().get(p.args[0], p.args[0].lstrip("?")) for p in placed}
        colors = {o.color for o in spec.objects for p in placed if o.name == p.args[0]}
        if first is not None and types == {first} and (color is None or colors == {color}):
            wins += 1
            solved.append(t.id)
    share = wins / len(cond) if cond else 0.0
    res = _result("conditional_first_branch", share, FIRST_BRANCH_LIMIT, len(cond), solved, [])
    if not cond:
        res.warning = "no conditional complex_instruction tasks in this task set"
    return res


def probes() -> list[AuditProbe]:
    return [
        AuditProbe("word_matching_spatial",
                   "A text-only agent that maps instruction words to action names (no image) must not solve "
                   "spatial_relationship tasks: their relations must need the picture.", word_matching_spatial),
        AuditProbe("conditional_first_branch",
                   "Always following the first branch of a conditional instruction must not beat chance by much.",
                   conditional_first_branch),
    ]
