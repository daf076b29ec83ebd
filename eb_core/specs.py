"""Typed specs returned by the ``eb_register_*`` hooks.

A spec is cheap data: a name, a description and an ``entry_point`` string ``"package.module:Attr"``
that is imported only when a run selects the component (so ``eb list`` never imports a simulator or
a model SDK).
"""

from __future__ import annotations

import importlib
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, field_validator

__all__ = [
    "AugmenterSpec",
    "ComponentSpec",
    "EnvSpec",
    "MetricSpec",
    "ModelBackendSpec",
    "PlannerSpec",
    "load_entry_point",
]


class MissingDependencyError(ImportError):
    """A selected component needs a package that is not installed."""


def load_entry_point(entry_point: str, install_hint: str | None = None) -> Any:
    """Import ``"package.module:Attr"`` and return the attribute.

    A missing module fails with the exact ``pip install`` line from ``install_hint`` when given.
    """
    module_name, _, attr = entry_point.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        hint = f" Fix: {install_hint}" if install_hint else ""
        raise MissingDependencyError(f"cannot import {entry_point!r}: no module named {exc.name!r}.{hint}") from exc
    obj: Any = module
    for part in attr.split(".") if attr else []:
        try:
            obj = getattr(obj, part)
        except AttributeError as exc:
            raise ImportError(f"entry point {entry_point!r}: {module_name} has no attribute {part!r}") from exc
    return obj


class ComponentSpec(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    """Name used in the config (``env=navigation``)."""
    entry_point: str
    """``"package.module:Attr"``, imported lazily."""
    description: str = ""
    install_hint: str | None = None
    """The ``pip install ...`` line that provides the entry point's optional dependencies."""
    plugin: str = ""
    """Filled in by the registry: the name of the plugin that registered the spec."""

    @field_validator("entry_point")
    @classmethod
    def _entry_point_form(cls, value: str) -> str:
        module, sep, attr = value.partition(":")
        if not module or not sep or not attr:
            raise ValueError(f"entry_point must look like 'package.module:Attr', got {value!r}")
        return value

    def load(self) -> Any:
        return load_entry_point(self.entry_point, self.install_hint)


class EnvSpec(ComponentSpec):
    """An environment: the ``Env`` subclass plus static facts for ``eb list``."""

    subsets: dict[str, int] = Field(default_factory=dict)
    """Subset name -> number of shipped tasks (shown by ``eb list`` without loading anything)."""
    display_name: str = ""
    """How the world is spelled in titles and Gymnasium ids (``ALFRED`` -> ``EB/ALFRED-v0``); default: the name
    with a capital letter."""
    visual_examples: bool = False
    """The world ships visual in-context examples (``ablation=visual_icl``)."""
    tasksets: tuple[str, ...] = ("classic",)
    """Shipped task sets (``taskset=``); ``classic`` is the paper's. Another set is passed to
    :meth:`eb_core.env.Env.load_tasks` (and ``split_tasks``) as the keyword ``taskset``."""
    task_generator: str | None = None
    """Optional ``"module:function"`` behind ``eb tasks generate env=<name> key=value...``."""
    audit_probes: str | None = None
    """Optional ``"module:function"`` returning the world's own ``eb audit`` probes
    (``list[eb_core.audit.contract.AuditProbe]``), imported only when an audit runs."""
    notes: str = ""
    """What a reader of this world's episodes should know (plain text), shown on the viewer's episode pages."""

    @field_validator("task_generator", "audit_probes")
    @classmethod
    def _function_form(cls, value: str | None) -> str | None:
        if value is not None:
            module, sep, attr = value.partition(":")
            if not module or not sep or not attr:
                raise ValueError(f"must look like 'package.module:function', got {value!r}")
        return value


class ModelBackendSpec(ComponentSpec):
    """A model backend class (``litellm``, ``oracle``...). Presets are Hydra options in ``conf/model``."""


class PlannerSpec(ComponentSpec):
    """A planner class that turns observations into plans."""


class AugmenterSpec(ComponentSpec):
    """An observation transform (draw boxes, resize...)."""


class MetricSpec(ComponentSpec):
    """A function ``(episodes: list[EpisodeRecord]) -> dict[str, float]`` used in ``summary.json``."""
