"""What an old run's images showed, recomputed: its recorded actions replayed in the world.

A world is deterministic given the task and the episode's seed, so resetting it and stepping through the
actions ``steps.jsonl`` recorded reproduces every observation the model was sent. From each one the labeller
takes ``Observation.visible_objects`` (the world's segmentation-pixel count, edge objects included) instead of the
list stored at the time, and from each step the ``path_distance`` a world reports. A replay that disagrees with the
record (an action's success differs) stops there and keeps the stored lists for the rest of the episode. An
episode whose task has changed since the run (a regenerated task set: the id's instruction is no longer the
recorded one) is not replayed at all: the world would show another scene, and every label would be judged
against objects the model never saw. The run's manifest catches the same under unchanged wording: when the digest
of the tasks it ran (scenes included) is not the installed tasks', no episode of the run is replayed.
"""

from __future__ import annotations

import copy
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["replay_episode", "replay_run"]


def _in_view(obs: Any) -> list[dict[str, Any]]:
    if getattr(obs, "visible_objects", None) is not None:
        return list(obs.visible_objects)
    return [{"name": o.name, "type": o.type} for o in obs.objects if o.box is not None]


def _action(space: Any, a: dict[str, Any]) -> Any:
    raw = a.get("action")
    if isinstance(raw, str):
        try:
            raw = json.loads(raw)
        except ValueError:
            pass
    if getattr(space, "kind", None) == "discrete" and not isinstance(raw, int):
        return space.actions.index(a["action_name"])
    return raw


def replay_episode(env: Any, task: Any, seed: int, steps: Sequence[dict[str, Any]]) -> tuple[list[dict[str, Any]],
                                                                                               bool]:
    """``steps`` with ``visible_objects`` (and actions' ``path_distance``) recomputed; and whether the whole
    episode replayed as recorded."""
    out = [copy.deepcopy(s if isinstance(s, dict) else s.as_dict()) for s in steps]  # StepRecord or dict
    obs = env.reset(task, seed)
    if out and getattr(obs, "scene_objects", None) is not None:
        out[0]["scene_objects"] = list(obs.scene_objects)
    for s in out:
        s["visible_objects"] = _in_view(obs)
        for a in s.get("actions") or []:
            result = env.step(_action(env.action_space(), a))
            if bool(result.action_success) != bool(a.get("success")):
                return out, False
            for key in ("path_distance", "distance_to_goal"):
                if key in result.info and key not in a:
                    a[key] = result.info[key]
            obs = result.observation
    return out, True


def _config(root: Path) -> dict[str, Any]:
    import yaml

    path = root / "config.yaml"
    data = yaml.safe_load(path.read_text(encoding="utf-8")) if path.exists() else None
    return data if isinstance(data, dict) else {}


def _stale_tasks(root: Path, by_id: dict[str, Any]) -> str | None:
    """Why the installed tasks are not the ones ``root`` ran, or None when they are (or the run has no manifest to
    tell). The manifest's ``selected_digest`` covers every selected task's scene, not only its instruction, so a
    task set regenerated with the same wording (a new draw of the same template) is caught too."""
    from eb_core.taskfile import task_set_digest

    path = root / "manifest.json"
    try:
        manifest = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    ids, want = manifest.get("task_ids"), manifest.get("selected_digest")
    if not isinstance(ids, list) or not isinstance(want, str):
        return None
    missing = [i for i in ids if i not in by_id]
    if missing:
        return f"{len(missing)} task id(s) no longer exist, e.g. {missing[0]}"
    if task_set_digest(by_id[i] for i in ids) != want:
        return "the selected tasks' digest differs from the manifest's"
    return None


def replay_run(run_dir: str | Path, records: Sequence[Any], steps: dict[tuple[str, int], list[dict[str, Any]]]
               ) -> dict[tuple[str, int], list[dict[str, Any]]]:
    """Every measured episode of ``run_dir`` replayed (see the module docstring); episodes that cannot be replayed
    keep their stored lists, and one line on stderr says why."""
    from eb_core.plugins import PluginError, Registry

    root = Path(run_dir)
    cfg = _config(root)
    env_cfg = cfg.get("env") or {}
    try:
        env_cls = Registry.create().get("env", str(env_cfg.get("name"))).load()
    except (PluginError, ImportError) as exc:  # a world that is not installed: label from the stored lists
        print(f"eb: cannot replay {root}: {str(exc).splitlines()[0]}; labels use the stored visible_objects",
              file=sys.stderr)
        return steps
    env_params = dict(env_cfg.get("params") or {})
    params = dict(env_params)  # the task loaders also take the task set; the Env's constructor does not
    taskset = cfg.get("taskset") or "classic"
    if taskset != "classic":
        params["taskset"] = taskset
    split = cfg.get("split") or "test"
    tasks = (env_cls.load_tasks(**params) if split == "test"
             else env_cls.split_tasks(split, 0, cfg.get("limit"), **params))
    by_id = {t.id: t for t in tasks}
    stale = _stale_tasks(root, by_id)
    if stale is not None:  # the scenes changed under the same ids: replaying would show the model's words other rooms
        print(f"eb: the tasks of {root} are not the installed ones any more ({stale}); labels use the stored "
              "visible_objects", file=sys.stderr)
        return steps
    env = env_cls(resolution=int(env_cfg.get("resolution") or 500), multi_view=bool(env_cfg.get("multi_view")),
                  **env_params)
    out = dict(steps)
    diverged, changed = [], []
    try:
        for r in records:
            if r.status != "ok" or r.task_id not in by_id or not steps.get(r.key):
                continue
            if r.instruction and by_id[r.task_id].instruction != r.instruction:
                changed.append(r.task_id)  # the task set was regenerated since the run: another scene
                continue
            out[r.key], whole = replay_episode(env, by_id[r.task_id], r.seed, steps[r.key])
            if not whole:
                diverged.append(r.task_id)
    finally:
        env.close()
    if changed:
        print(f"eb: the task set has changed since {root} was run ({', '.join(changed)}: another instruction); "
              "their labels use the stored visible_objects", file=sys.stderr)
    if diverged:
        print(f"eb: replay of {root} differs from the record in {', '.join(diverged)}; their later steps keep the "
              "stored visible_objects", file=sys.stderr)
    return out
