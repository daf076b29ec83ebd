"""Writing a run's ``manifest.json`` (:class:`eb_core.records.RunManifest`): format version, versions, digests.

``eb verify`` checks a run against it: the task set it was played on against the installed one, the config
against ``config.yaml``, and the versions it was made with against the installed ones.
"""

from __future__ import annotations

import hashlib
import json
import platform
from collections.abc import Sequence
from datetime import datetime, timezone
from importlib import metadata
from typing import Any

from eb_core.config import RunConfig
from eb_core.env import Task
from eb_core.records import FORMAT_VERSION, RunFiles, RunManifest, read_manifest
from eb_core.taskfile import task_set_digest

__all__ = ["KEY_LIBRARIES", "config_digest", "library_versions", "write_manifest"]

#: Libraries whose version can change a run's numbers (simulation, images, parsing).
KEY_LIBRARIES = ("numpy", "mujoco", "pydantic", "pillow", "gymnasium", "hydra-core", "litellm")


def library_versions() -> dict[str, str]:
    """Python and the installed versions of :data:`KEY_LIBRARIES` (those that are installed)."""
    out = {"python": platform.python_version()}
    for name in KEY_LIBRARIES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return out


def config_digest(cfg_dict: dict[str, Any]) -> str:
    """SHA-256 of a resolved config as canonical JSON (sorted keys)."""
    canon = json.dumps(cfg_dict, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(canon.encode("utf-8")).hexdigest()


def write_manifest(files: RunFiles, cfg: RunConfig, cfg_dict: dict[str, Any], all_tasks: Sequence[Task],
                   selected: Sequence[Task], plugins: dict[str, str]) -> RunManifest:
    """Write ``manifest.json`` for this invocation (keeping the time of the first one) and return it."""
    try:
        old = read_manifest(files.root)
    except ValueError:
        old = None
    created = old.created if old is not None and old.created else (
        datetime.now(timezone.utc).replace(microsecond=0).isoformat())
    manifest = RunManifest(
        format_version=FORMAT_VERSION, created=created, env=cfg.env.name, model=cfg.model.name,
        taskset=cfg.taskset, split=cfg.split, n_tasks=len(all_tasks), task_set_digest=task_set_digest(all_tasks),
        selected_digest=task_set_digest(selected), task_ids=[t.id for t in selected],
        config_digest=config_digest(json.loads(json.dumps(cfg_dict, default=str))),
        versions={**{f"plugin:{k}": v for k, v in plugins.items()}, **library_versions()})
    files.write_json("manifest.json", manifest.model_dump())
    return manifest
