"""Automatic error analysis: every planner step and executed action labelled from the run's records.

The taxonomy (:mod:`.taxonomy`), the perception check (:mod:`.perception`, words in :mod:`.lexicon`), the rules
over actions (:mod:`.actions`), the episode and run labeller (:mod:`.labeller`) and the replay that recomputes
what an old run's images showed (:mod:`.replay`). Each rule's exact condition is in docs/error_analysis.md.
"""

from eb_core.errors.labeller import (
                                     label_episode,
                                     label_run,
                                     load_steps,
                                     run_vocabulary,
                                     scene_terms,
)
from eb_core.errors.perception import has_description, perception_check
from eb_core.errors.taxonomy import (
                                     CATEGORIES,
                                     DRIFT_WINDOW,
                                     FAILURE_LABELS,
                                     INVALID_LABELS,
                                     Category,
                                     invalid_count,
                                     make_label,
)

__all__ = ["CATEGORIES", "DRIFT_WINDOW", "FAILURE_LABELS", "INVALID_LABELS", "Category", "has_description",
           "invalid_count", "label_episode", "label_run", "load_steps", "make_label", "perception_check", "run_vocabulary", "scene_terms"]
