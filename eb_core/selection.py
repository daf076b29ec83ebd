"""The rule that a run directory holds one task selection (``subset=``, ``tasks=``, ``sample=``, ``limit=``):
the selection is part of a run's identity, recorded in ``fingerprint.json``. (Which tasks a selection picks:
:func:`eb_core.components.select_tasks`.)"""

from __future__ import annotations

from typing import Any

from eb_core.config import RunConfig

__all__ = ["SELECTION_KEYS", "selection_conflict", "selection_of"]

#: The keys that choose a run's tasks; a run directory holds one selection (``limit`` may only grow).
SELECTION_KEYS = ("subset", "tasks", "sample", "limit")


def selection_of(cfg: RunConfig) -> dict[str, Any]:
    out: dict[str, Any] = {"subset": cfg.subset, "tasks": cfg.tasks, "limit": cfg.limit}
    if cfg.sample is not None:  # recorded only when used, so runs from before sample= keep their selection
        out["sample"] = cfg.sample
    return out


def selection_conflict(old: dict[str, Any] | None, new: dict[str, Any], root: Any) -> str | None:
    """Why the run directory ``root``, which holds selection ``old``, cannot take selection ``new`` (one line),
    or None. A different selection is a different run; a larger ``limit`` extends the run, as the first N tasks
    of a selection are the first ones of any larger N."""
    if old is None:
        return None
    for key in SELECTION_KEYS:
        a, b = old.get(key), new.get(key)
        if a == b:
            continue
        if key == "limit" and (b is None or (a is not None and b > a)):
            continue
        return (f"{root} holds a run with {key}={_show(a)}, this one has {key}={_show(b)}: a different "
                f"selection is a different run. Add experiment=NAME (e.g. experiment={key}{_slug(b)}) to "
                f"keep both, or delete that directory")
    return None


def _show(value: Any) -> str:
    return "null" if value is None else (",".join(map(str, value)) if isinstance(value, list) else str(value))


def _slug(value: Any) -> str:
    return "".join(ch for ch in _show(value) if ch.isalnum() or ch in "_-")[:24] or "all"
