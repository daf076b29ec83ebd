"""The core's own components, registered through the same hooks a third-party plugin uses."""

from __future__ import annotations

from eb_core.hookspecs import hookimpl
from eb_core.specs import AugmenterSpec, MetricSpec, ModelBackendSpec, PlannerSpec


@hookimpl
def eb_register_planners() -> list[PlannerSpec]:
    return [
        PlannerSpec(
            name="vlm",
            entry_point="eb_core.planner:VLMPlanner",
            description="The paper's unified agent: image + instruction + actions + examples + history -> JSON plan",
        )
    ]


@hookimpl
def eb_register_augmenters() -> list[AugmenterSpec]:
    return [
        AugmenterSpec(
            name="detection_boxes",
            entry_point="eb_core.augment:DetectionBoxes",
            description="Draw ground-truth boxes (and labels) of all objects or only the target on the main image",
        ),
    ]


@hookimpl
def eb_register_model_backends() -> list[ModelBackendSpec]:
    return [
        ModelBackendSpec(
            name="policy", entry_point="eb_core.evaluate:PolicyBackend",
            description="A policy callable given to eb_core.evaluate.evaluate() (evaluation during training)",
        ),
    ]


@hookimpl
def eb_register_metrics() -> list[MetricSpec]:
    return [
        MetricSpec(name="success_rate", entry_point="eb_core.metrics:success_rate",
                   description="Fraction of episodes whose task succeeded (the paper's main number)"),
        MetricSpec(name="subgoal_success", entry_point="eb_core.metrics:subgoal_success",
                   description="Mean final task progress (goal conditions met / total)"),
        MetricSpec(name="steps", entry_point="eb_core.metrics:steps",
                   description="Average planner steps and environment steps per episode"),
        MetricSpec(name="errors", entry_point="eb_core.metrics:errors",
                   description="Invalid-action ratio, output-error rate, empty plans, error episodes"),
        MetricSpec(name="usage", entry_point="eb_core.metrics:usage",
                   description="Tokens, model calls, cost and latency"),
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return []
