"""Plugin discovery and the component registry.

``get_plugin_manager()`` builds a fresh :class:`pluggy.PluginManager` (no import-time global):
the core's built-in plugin first, then every distribution advertising the ``eb.plugins`` entry-point
group. :class:`Registry` merges the specs the registration hooks return and answers lookups with
errors that list what exists.
"""

from __future__ import annotations

import importlib
import importlib.metadata as md
import os
from collections.abc import Iterable
from typing import Any, TypeVar

import pluggy

from eb_core import hookspecs
from eb_core.specs import AugmenterSpec, ComponentSpec, EnvSpec, MetricSpec, ModelBackendSpec, PlannerSpec

__all__ = ["ENTRY_POINT_GROUP", "PluginError", "Registry", "get_plugin_manager", "plugin_versions"]

ENTRY_POINT_GROUP = "eb.plugins"
#: Comma-separated importable modules registered as plugins without installing them (development, tests).
PLUGINS_ENV_VAR = "EB_PLUGINS"
#: Set to 1 to load no installed plugins (only built-ins and EB_PLUGINS), like PYTEST_DISABLE_PLUGIN_AUTOLOAD.
AUTOLOAD_OFF_ENV_VAR = "EB_DISABLE_PLUGIN_AUTOLOAD"

S = TypeVar("S", bound=ComponentSpec)

#: Hook name -> (component kind shown to users, spec type).
KINDS: dict[str, tuple[str, type[ComponentSpec]]] = {
    "eb_register_envs": ("env", EnvSpec),
    "eb_register_model_backends": ("model backend", ModelBackendSpec),
    "eb_register_planners": ("planner", PlannerSpec),
    "eb_register_augmenters": ("augmenter", AugmenterSpec),
    "eb_register_metrics": ("metric", MetricSpec),
}


class PluginError(RuntimeError):
    """A plugin could not be loaded, registered twice, or a component name is unknown."""


def get_plugin_manager(*, load_entrypoints: bool = True, plugins: Iterable[Any] = ()) -> pluggy.PluginManager:
    """Return a new plugin manager with the built-ins, installed plugins and ``plugins`` registered.

    ``plugins`` lets tests register fixture plugins directly.
    """
    pm = pluggy.PluginManager(hookspecs.PROJECT)
    pm.add_hookspecs(hookspecs)
    from eb_core import builtin_plugin

    pm.register(builtin_plugin, name="eb_core")
    if load_entrypoints and not os.environ.get(AUTOLOAD_OFF_ENV_VAR):
        for ep in md.entry_points(group=ENTRY_POINT_GROUP):
            if pm.get_plugin(ep.name) is not None or pm.is_blocked(ep.name):
                continue
            try:
                plugin = ep.load()
            except Exception as exc:  # a broken plugin must be loud, never skipped
                dist = getattr(ep, "dist", None)
                where = f" (distribution {dist.name} {dist.version})" if dist else ""
                raise PluginError(
                    f"plugin {ep.name!r}{where} failed to import {ep.value!r}: {type(exc).__name__}: {exc}. "
                    f"Fix the plugin or uninstall it."
                ) from exc
            pm.register(plugin, name=ep.name)
            if dist := getattr(ep, "dist", None):
                _DIST_OF[ep.name] = (dist.name, dist.version)
    extra = [m.strip() for m in os.environ.get(PLUGINS_ENV_VAR, "").split(",") if m.strip()]
    for module_name in extra:
        if pm.get_plugin(module_name) is not None:
            continue
        try:
            pm.register(importlib.import_module(module_name), name=module_name)
        except ImportError as exc:
            raise PluginError(f"{PLUGINS_ENV_VAR} names {module_name!r}, which cannot be imported: {exc}") from exc
    for i, plugin in enumerate(plugins):
        name = getattr(plugin, "__name__", None) or f"local-{i}"
        if pm.get_plugin(name) is None:
            pm.register(plugin, name=name)
    try:
        pm.check_pending()
    except pluggy.PluginValidationError as exc:
        raise PluginError(f"a plugin implements an unknown hook: {exc}") from exc
    return pm


_DIST_OF: dict[str, tuple[str, str]] = {}


def plugin_versions(pm: pluggy.PluginManager) -> dict[str, str]:
    """``{plugin name: "distribution version"}`` for every registered plugin (recorded in run dirs)."""
    out: dict[str, str] = {}
    for name, plugin in pm.list_name_plugin():
        if name in _DIST_OF:
            dist, version = _DIST_OF[name]
            out[name] = f"{dist} {version}"
        elif name == "eb_core":
            out[name] = f"embodiedbench {_version('embodiedbench')}"
        else:
            out[name] = f"{getattr(plugin, '__name__', type(plugin).__name__)} (registered directly)"
    return dict(sorted(out.items()))


def _version(dist: str) -> str:
    try:
        return md.version(dist)
    except md.PackageNotFoundError:
        return "unknown"


class Registry:
    """All specs registered by the plugins of one plugin manager."""

    def __init__(self, pm: pluggy.PluginManager) -> None:
        self.pm = pm
        self._specs: dict[str, dict[str, ComponentSpec]] = {}
        for hook_name, (kind, spec_type) in KINDS.items():
            merged: dict[str, ComponentSpec] = {}
            hook = getattr(pm.hook, hook_name)
            for impl in hook.get_hookimpls():
                plugin_name = pm.get_name(impl.plugin) or repr(impl.plugin)
                result = impl.function()
                if result is None:
                    continue
                if not isinstance(result, (list, tuple)):
                    raise PluginError(f"plugin {plugin_name!r}: {hook_name}() must return a list of "
                                      f"{spec_type.__name__}")
                for spec in result:
                    if not isinstance(spec, spec_type):
                        raise PluginError(
                            f"plugin {plugin_name!r}: {hook_name}() returned {type(spec).__name__}, "
                            f"expected {spec_type.__name__}"
                        )
                    spec = spec.model_copy(update={"plugin": plugin_name})
                    if spec.name in merged:
                        raise PluginError(
                            f"{kind} {spec.name!r} is registered twice: by plugin {merged[spec.name].plugin!r} "
                            f"and by plugin {plugin_name!r}. Uninstall one of them."
                        )
                    merged[spec.name] = spec
            self._specs[kind] = dict(sorted(merged.items()))

    @classmethod
    def create(cls, **kwargs: Any) -> Registry:
        return cls(get_plugin_manager(**kwargs))

    def all(self, kind: str) -> dict[str, ComponentSpec]:
        return dict(self._specs[kind])

    def get(self, kind: str, name: str) -> ComponentSpec:
        specs = self._specs[kind]
        if name not in specs:
            available = ", ".join(specs) or "none"
            raise PluginError(
                f"unknown {kind} {name!r}; available: {available}. Is the plugin that provides it installed? "
                f"(`eb list` shows what is installed)"
            )
        return specs[name]

    def _typed(self, kind: str, spec_type: type[S]) -> dict[str, S]:
        return {k: v for k, v in self._specs[kind].items() if isinstance(v, spec_type)}

    def env(self, name: str) -> EnvSpec:
        """The env ``name`` (:meth:`get` with its type); :class:`PluginError` lists the installed ones."""
        spec = self.get("env", name)
        assert isinstance(spec, EnvSpec)
        return spec

    @property
    def envs(self) -> dict[str, EnvSpec]:
        return self._typed("env", EnvSpec)

    @property
    def model_backends(self) -> dict[str, ModelBackendSpec]:
        return self._typed("model backend", ModelBackendSpec)

    @property
    def planners(self) -> dict[str, PlannerSpec]:
        return self._typed("planner", PlannerSpec)

    @property
    def augmenters(self) -> dict[str, AugmenterSpec]:
        return self._typed("augmenter", AugmenterSpec)

    @property
    def metrics(self) -> dict[str, MetricSpec]:
        return self._typed("metric", MetricSpec)

    def config_searchpath(self) -> list[str]:
        paths: list[str] = []
        for result in self.pm.hook.eb_config_searchpath():
            for p in result or []:
                if p not in paths:
                    paths.append(p)
        return paths
