"""The one config path: Hydra composition, override checks, group options, validation and the run directory.

Every entry point composes through here (``eb run`` and the other commands, the Gymnasium env, the benchmarks
and the tests), with Hydra's Compose API, so a config means the same thing wherever it is built. Sweeps
(``a=x,y``) are expanded with Hydra's own override parser and sweeper.
"""

from __future__ import annotations

import difflib
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from eb_core.exceptions import CliError

if TYPE_CHECKING:
    from eb_core.config import RunConfig

__all__ = ["GROUPS", "ComposedRun", "check_overrides", "compose", "compose_run", "expand_sweep", "group_options",
           "hydra_context", "list_options", "refuse_secrets", "run_segment", "sweep_keys", "validate"]

#: The config groups whose options ship in the core and in plugins.
GROUPS = ("env", "model", "planner", "ablation")

_SECRET_LEAVES = {"api_key", "apikey", "key", "secret", "password", "token", "access_key", "secret_key",
                  "auth_token", "access_token", "bearer"}


# -- run directory path segments (OmegaConf resolvers used by conf/config.yaml) --------------------------


def run_segment(value: Any) -> str:
    """A config value as ONE directory name: ``Qwen/Qwen2.5-VL`` -> ``Qwen--Qwen2.5-VL`` (a slash in a model
    name must not add a level, so ``runs/*/*/*/default`` finds every run)."""
    text = str(value).replace("/", "--").replace("\\", "--").strip()
    return text.lstrip(".") or "_"


def env_segment(env_name: Any, taskset: Any = "classic") -> str:
    """The env's directory: its name, and ``-<taskset>`` for task sets other than the classic one."""
    seg = run_segment(env_name)
    return seg if str(taskset) in ("classic", "None", "") else f"{seg}-{run_segment(taskset)}"


def _register_resolvers() -> None:
    from omegaconf import OmegaConf

    if not OmegaConf.has_resolver("eb_seg"):
        OmegaConf.register_new_resolver("eb_seg", run_segment)
    if not OmegaConf.has_resolver("eb_env_seg"):
        OmegaConf.register_new_resolver("eb_env_seg", env_segment)


# -- Hydra --------------------------------------------------------------------------------------------------


@contextmanager
def hydra_context() -> Iterator[None]:
    """Hydra initialised on the primary config (``eb_conf``) with every installed plugin's options."""
    from hydra import initialize_config_module
    from hydra.core.global_hydra import GlobalHydra

    from hydra_plugins.eb_searchpath import ensure_registered

    ensure_registered()
    _register_resolvers()
    if GlobalHydra.instance().is_initialized():  # nested use (a command inside a test's context)
        yield
        return
    with initialize_config_module(config_module="eb_conf", version_base=None):
        yield


def group_options(group: str) -> list[str]:
    """The options of a config group (``env``, ``model``...); call inside :func:`hydra_context`."""
    from hydra.core.global_hydra import GlobalHydra

    return sorted(GlobalHydra.instance().config_loader().get_group_options(group))


def list_options(group: str) -> dict[str, dict[str, Any]]:
    """Every option of ``group`` with its raw YAML (not composed); ``{}`` for an option that cannot be read."""
    from hydra.core.global_hydra import GlobalHydra
    from omegaconf import OmegaConf

    out: dict[str, dict[str, Any]] = {}
    with hydra_context():
        loader: Any = GlobalHydra.instance().config_loader()  # the repository is on the implementation
        repo = loader.repository
        for name in group_options(group):
            try:
                result = repo.load_config(config_path=f"{group}/{name}")
                node: Any = OmegaConf.to_container(result.config, resolve=False) if result is not None else {}
            except Exception:  # a broken option is listed, not hidden
                node = {}
            out[name] = node if isinstance(node, dict) else {}
    return out


def _parse(overrides: list[str]) -> list[Any]:
    from hydra.core.override_parser.overrides_parser import OverridesParser

    try:
        return OverridesParser.create().parse_overrides(overrides)
    except Exception as exc:
        raise CliError(f"cannot parse overrides {' '.join(overrides)!r}: {str(exc).splitlines()[0]}. "
                       f"Write key=value, e.g. env=navigation limit=5") from None


def refuse_secrets(overrides: list[str]) -> None:
    """API keys on the command line would be saved with the run: refuse them before composing."""
    for ov in overrides:
        key = ov.split("=", 1)[0].lower().lstrip("+~")
        leaf = key.rsplit(".", 1)[-1]
        if leaf in _SECRET_LEAVES or leaf.endswith(("_api_key", "_secret", "_password", "_access_token")):
            raise CliError(f"refusing '{key}=...': keys and secrets never go on the command line or in config "
                           f"files (they would be saved with the run). Export the key in an environment variable "
                           f"and name it with model.api_key_env=VAR_NAME")


def check_overrides(overrides: list[str]) -> list[str]:
    """Check group options (sweeps expanded) and return one override list to compose with (a sweep's first
    value). Call inside :func:`hydra_context`."""
    first: list[str] = []
    for ov in _parse(overrides):
        key = ov.get_key_element()
        if ov.is_sweep_override():
            values = [str(v) for v in ov.sweep_string_iterator()]
        else:
            values = [ov.get_value_element_as_str()]
        if key in GROUPS:
            options = group_options(key)
            for v in values:
                if v not in options:
                    raise CliError(_unknown_option_message(key, v, options))
        first.append(f"{key}={values[0]}" if ov.is_sweep_override() else ov.input_line)
    return first


def expand_sweep(overrides: list[str]) -> list[list[str]]:
    """The jobs of a sweep (``a=x,y b=1,2`` -> four override lists), with Hydra's own sweeper."""
    from hydra._internal.core_plugins.basic_sweeper import BasicSweeper

    batches = BasicSweeper.split_arguments(_parse(overrides), max_batch_size=None)
    return [list(job) for batch in batches for job in batch]


def _unknown_option_message(group: str, value: str, options: list[str]) -> str:
    close = difflib.get_close_matches(value, options, n=1)
    hint = f" Did you mean {close[0]!r}?" if close else ""
    if group == "env":
        registered = _registered_env(value)
        if registered is not None:
            return (f"env {value!r} is installed (plugin {registered}) but its config env/{value}.yaml is missing: "
                    f"the plugin must ship conf/env/{value}.yaml and return its conf folder from "
                    f"eb_config_searchpath. Reinstall the plugin (pip install -e plugins/...) or report it to its "
                    f"author")
    plugin = {"env": " Is its plugin installed? (pip install a plugin, e.g. plugins/eb_navigation, then `eb list`)",
              "model": " For any other model use model=openai-compatible model.name=... model.api_base=...",
              }.get(group, "")
    return f"unknown {group} {value!r}; available: {', '.join(options) or 'none'}.{hint}{plugin}"


def _registered_env(name: str) -> str | None:
    """The plugin that registers env ``name``, if any (its YAML may still be missing)."""
    from eb_core.plugins import PluginError, Registry

    try:
        spec = Registry.create().envs.get(name)
    except PluginError:
        return None
    return spec.plugin if spec is not None else None


def _hydra_error_line(exc: Exception) -> str:
    text = str(exc)
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    m = re.search(r"Key '([^']+)' is not in struct", text) or re.search(r"Could not override '([^']+)'", text)
    if m:
        key = m.group(1)
        full = re.search(r"full_key: (\S+)", text)
        full_key = full.group(1) if full else key
        return (f"unknown config key '{full_key}'. Check the spelling; `eb run --cfg job` prints every key "
                f"(add a new key with +{full_key}=VALUE only if a plugin reads it)")
    return (lines[0] if lines else type(exc).__name__) + " (see `eb run --cfg job`)"


def _compose_node(overrides: list[str], *, hydra_config: bool) -> Any:
    from hydra import compose as hydra_compose

    with hydra_context():
        checked = check_overrides(overrides)
        try:
            return hydra_compose(config_name="config", overrides=checked, return_hydra_config=hydra_config)
        except CliError:
            raise
        except Exception as exc:
            raise CliError(_hydra_error_line(exc)) from None


def _to_dict(cfg: Any) -> dict[str, Any]:
    from omegaconf import OmegaConf

    if "hydra" in cfg:
        cfg = OmegaConf.masked_copy(cfg, [k for k in cfg if k != "hydra"])
    try:
        out = OmegaConf.to_container(cfg, resolve=True)
    except Exception as exc:  # an interpolation that cannot be resolved
        raise CliError(_hydra_error_line(exc)) from None
    assert isinstance(out, dict)
    out.pop("hydra", None)
    return {str(k): v for k, v in out.items()}


def compose(overrides: list[str]) -> dict[str, Any]:
    """Compose the config for ``overrides`` and return it as a resolved plain dict (run dir excluded)."""
    return _to_dict(_compose_node(overrides, hydra_config=False))


def validate(cfg_dict: dict[str, Any]) -> RunConfig:
    """A composed config as a :class:`~eb_core.config.RunConfig`; :class:`ConfigError` names the bad key."""
    from eb_core.config import validate_config

    return validate_config(cfg_dict)


@dataclass(frozen=True)
class ComposedRun:
    """One job of ``eb run``: composed once, validated once."""

    overrides: list[str]
    """The overrides of this job (a sweep's values filled in)."""
    node: Any
    """The composed OmegaConf node, ``hydra`` included (``--cfg`` prints it)."""
    cfg_dict: dict[str, Any]
    """The resolved config without ``hydra`` (what runs; saved as ``config.yaml``)."""
    config: RunConfig
    run_dir: Path


def compose_run(overrides: list[str], *, multirun: bool = False) -> ComposedRun:
    """Compose, validate and place one run. ``multirun``: the directory comes from ``hydra.sweep``."""
    from omegaconf import OmegaConf

    node = _compose_node(overrides, hydra_config=True)
    cfg_dict = _to_dict(node)
    config = validate(cfg_dict)
    try:
        h = node.hydra
        if multirun:
            run_dir = os.path.join(str(h.sweep.dir), str(h.sweep.subdir))
        else:
            run_dir = str(h.run.dir)
    except Exception as exc:
        raise CliError(f"cannot resolve the run directory: {_hydra_error_line(exc)}") from None
    OmegaConf.set_readonly(node, True)
    return ComposedRun(list(overrides), node, cfg_dict, config, Path(run_dir))


def sweep_keys(overrides: list[str]) -> list[str]:
    """The keys of ``overrides`` that hold several values (``ablation=none,no_feedback``)."""
    return [ov.get_key_element() for ov in _parse(overrides) if ov.is_sweep_override()]
