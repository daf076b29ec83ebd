"""Every hook EmbodiedBench calls, in one place.

Plugins implement hooks with ``@eb_core.hookimpl`` and are found through the ``eb.plugins`` entry-point
group. Registration hooks return lists of specs (cheap data, lazily imported factories); lifecycle hooks
receive one frozen event each and are for observers (loggers, dashboards): their return values are
ignored and they cannot change results. Hooks are always called with keyword arguments.
"""

from __future__ import annotations

import pluggy

from eb_core.events import EpisodeEndEvent, EpisodeStartEvent, RunEndEvent, RunStartEvent, StepEndEvent
from eb_core.specs import AugmenterSpec, EnvSpec, MetricSpec, ModelBackendSpec, PlannerSpec

PROJECT = "eb"

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


# -- registration ---------------------------------------------------------------------------------


@hookspec
def eb_register_envs() -> list[EnvSpec]:
    """Return the environments this plugin provides.

    Called once when the plugin manager is built. Names must be unique across plugins: a duplicate
    aborts start-up, naming both plugins.
    """


@hookspec
def eb_register_planners() -> list[PlannerSpec]:
    """Return the planners this plugin provides (the core registers ``vlm``, the paper's pipeline)."""


@hookspec
def eb_register_augmenters() -> list[AugmenterSpec]:
    """Return the observation augmenters this plugin provides (e.g. ``detection_boxes``)."""


@hookspec
def eb_register_metrics() -> list[MetricSpec]:
    """Return the metrics this plugin adds to ``summary.json`` (the core registers the paper's)."""


@hookspec
def eb_register_model_backends() -> list[ModelBackendSpec]:
    """Return the model backends this plugin provides (``litellm``, ``oracle``, ``random``...)."""


@hookspec
def eb_config_searchpath() -> list[str]:
    """Return Hydra search-path entries holding this plugin's config options.

    Typically ``["pkg://my_plugin.conf"]`` where ``my_plugin/conf/env/<name>.yaml`` (and ``model/``,
    ``ablation/``...) ship inside the package. They are appended after the core's own ``conf``.
    """


# -- lifecycle (observers) ------------------------------------------------------------------------


@hookspec
def eb_on_run_start(event: RunStartEvent) -> None:
    """Called in the main process before the first episode of a run (after resume bookkeeping)."""


@hookspec
def eb_on_episode_start(event: EpisodeStartEvent) -> None:
    """Called in the worker process before an episode's reset."""


@hookspec
def eb_on_step_end(event: StepEndEvent) -> None:
    """Called in the worker process after every environment step."""


@hookspec
def eb_on_episode_end(event: EpisodeEndEvent) -> None:
    """Called in the main process after an episode's record is safely written."""


@hookspec
def eb_on_run_end(event: RunEndEvent) -> None:
    """Called in the main process after ``summary.json`` is written."""
