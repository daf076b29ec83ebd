"""The 70 high-level skills of EB-Habitat, fixed for the benchmark.

Five kinds, parameterised by the catalogue: navigate to each of the 15 receptacles, pick up each of the 32
object types, place on/in each of the 15 receptacles, open and close each of the 4 articulated receptacles.
15 + 32 + 15 + 4 + 4 = 70. The id of a skill is its index in :data:`SKILLS`.
"""

from __future__ import annotations

from dataclasses import dataclass

from eb_habitat.catalog import OBJECT_TYPES, RECEPTACLES

__all__ = ["SKILLS", "SKILL_NAMES", "Skill", "skill_id"]


@dataclass(frozen=True)
class Skill:
    kind: str
    """``navigate``, ``pick``, ``place``, ``open`` or ``close``."""
    arg: str
    """A receptacle key (navigate, place, open, close) or an object type key (pick)."""
    name: str
    """The action name the model sees."""


def _build() -> tuple[Skill, ...]:
    skills: list[Skill] = []
    for r in RECEPTACLES:
        skills.append(Skill("navigate", r.key, f"navigate to the {r.name}"))
    for o in OBJECT_TYPES:
        skills.append(Skill("pick", o.key, f"pick up the {o.name}"))
    for r in RECEPTACLES:
        skills.append(Skill("place", r.key, f"place it {r.preposition} the {r.name}"))
    for r in RECEPTACLES:
        if r.articulated:
            skills.append(Skill("open", r.key, f"open the {r.name}"))
    for r in RECEPTACLES:
        if r.articulated:
            skills.append(Skill("close", r.key, f"close the {r.name}"))
    return tuple(skills)


SKILLS: tuple[Skill, ...] = _build()
SKILL_NAMES: tuple[str, ...] = tuple(s.name for s in SKILLS)
_IDS = {(s.kind, s.arg): i for i, s in enumerate(SKILLS)}

assert len(SKILLS) == 70, len(SKILLS)
assert len(set(SKILL_NAMES)) == 70


def skill_id(kind: str, arg: str) -> int:
    """The action id of skill ``kind`` with argument ``arg`` (``skill_id("pick", "mug")``)."""
    try:
        return _IDS[(kind, arg)]
    except KeyError:
        raise KeyError(f"no skill {kind}({arg})") from None
