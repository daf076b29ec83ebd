"""The error taxonomy: one :class:`Category` per label, the world ``failure`` reasons and the label record."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["CATEGORIES", "DRIFT_WINDOW", "FAILURE_LABELS", "INVALID_LABELS", "Category", "invalid_count",
           "make_label"]


@dataclass(frozen=True)
class Category:
    """One error label: its key, a short title, the paper's group (perception, reasoning, planning) and sub-type."""

    key: str
    title: str
    group: str
    paper: str


#: The taxonomy, in report order.
CATEGORIES: dict[str, Category] = {c.key: c for c in (
    Category("format_error", "format error", "planning", "invalid action (unusable output)"),
    Category("invalid_action", "invalid action", "planning", "invalid action"),
    Category("hallucinated_object", "hallucinated object", "perception", "hallucination"),
    Category("misperceived_object", "misperceived object", "perception", "wrong recognition"),
    Category("affordance_error", "affordance error", "planning", "inaccurate action"),
    Category("precondition_error", "precondition error", "reasoning", "inaccurate understanding of the state"),
    Category("not_in_scene", "object not in the scene", "reasoning", "inaccurate understanding of the state"),
    Category("wrong_target", "wrong target", "perception", "wrong recognition"),
    Category("collision", "collision", "planning", "collision"),
    Category("grasp_failure", "grasp failure", "planning", "inaccurate action"),
    Category("failed_action", "failed action (unclassified)", "planning", "inaccurate action"),
    Category("repetition", "repetition / loop", "reasoning", "reflection error"),
    Category("premature_stop", "premature stop / give-up", "reasoning", "wrong termination"),
    Category("missing_step", "missing step", "planning", "missing steps"),
    Category("wrong_order", "wrong order", "planning", "missing steps (order)"),
    Category("extra_step", "extra step", "planning", "inaccurate action (unneeded)"),
    Category("navigation_drift", "navigation drift", "reasoning", "spatial reasoning"),
)}

#: Allowed values of a world's ``StepResult.info["failure"]`` and the label each gives.
FAILURE_LABELS: dict[str, str] = {
    "affordance": "affordance_error",
    "precondition": "precondition_error",
    "wrong_target": "wrong_target",
    # acting on a thing the scene lacks is a wrong belief about the state, not a percept: the original's action
    # lists offer every type in every room ("find a Knife" in a kitchen without one). A description that claims
    # to see it is judged by the perception check and labelled hallucinated_object there.
    "absent": "not_in_scene",
    "collision": "collision",
    "grasp": "grasp_failure",
}

#: What "invalid action" counts everywhere (summary.json, eb report, the viewer): an action the world refuses
#: outright, as the original's "Last action is invalid": a plan item naming no action of the list
#: (``invalid_action``), an action the object cannot do (``affordance_error``) or one refused without a known
#: reason (``failed_action``). Collisions and unmet preconditions are valid actions that failed in this state:
#: they keep their own labels and are not counted here.
INVALID_LABELS: tuple[str, ...] = ("invalid_action", "affordance_error", "failed_action")


def invalid_count(counts: dict[str, int] | dict[str, float] | None) -> int:
    """Invalid actions of an episode from its label counts (:data:`INVALID_LABELS`)."""
    return int(sum((counts or {}).get(k, 0) for k in INVALID_LABELS))


#: Navigation drift: the distance to the goal grew over this many consecutive actions.
DRIFT_WINDOW = 3


def make_label(category: str, detail: str, env_step: int | None = None, **evidence: Any) -> dict[str, Any]:
    """One label record: ``category``, a readable ``detail``, the ``env_step`` it is about (actions) and the
    ``evidence`` that made it fire (words matched, objects in view, the failing state)."""
    out: dict[str, Any] = {"category": category, "detail": detail}
    if env_step is not None:
        out["env_step"] = env_step
    if evidence:
        out["evidence"] = {k: v for k, v in evidence.items() if v is not None}
    return out
