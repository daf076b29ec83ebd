"""Response matrices: ``eb export RUN... --format matrix --out DIR``.

One row per task (``world``, ``taskset``, ``subset``, ``task_id``), two columns per run: ``<run>:success`` (the
share of the task's episodes that succeeded: 0/1 with one repeat) and ``<run>:progress`` (mean final progress).
A task a run did not play is empty. This is what item-response-theory fits and benchmark-agreement studies read.
Written as ``matrix.csv`` and ``matrix.parquet`` (pyarrow, the ``[report]`` extra), with ``runs.json`` naming the
run directory, model, ablation, task set and episode count behind every column label.
"""

from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["run_label", "write_matrix"]


def _config(run_dir: Path) -> dict[str, Any]:
    import yaml

    path = run_dir / "config.yaml"
    if not path.is_file():
        return {}
    data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    return data if isinstance(data, dict) else {}


def run_label(run_dir: Path, cfg: dict[str, Any]) -> str:
    """``model/ablation/experiment`` of a run (its directory path when the config says nothing)."""
    model = (cfg.get("model") or {}).get("name")
    ablation = (cfg.get("ablation") or {}).get("name")
    if model is None:
        return str(run_dir)
    return f"{model}/{ablation or 'none'}/{cfg.get('experiment', 'default')}"


def write_matrix(run_dirs: Sequence[str | Path], out: str | Path, *, overwrite: bool = False) -> list[Path]:
    """Write the task x run matrix of ``run_dirs`` into the folder ``out``; return the files written."""
    from eb_core.records import RunFiles

    out = Path(out)
    targets = [out / "matrix.csv", out / "matrix.parquet", out / "runs.json"]
    existing = [t for t in targets if t.exists()]
    if existing and not overwrite:
        raise FileExistsError(f"{existing[0]} exists; choose another --out or pass --overwrite")
    rows: dict[tuple[str, str, str, str], dict[str, Any]] = {}
    runs: list[dict[str, Any]] = []
    labels: list[str] = []
    for rd in map(Path, run_dirs):
        cfg = _config(rd)
        eps = [e for e in RunFiles(rd).load_episodes() if e.status == "ok"]
        if not eps:
            raise ValueError(f"{rd}: no finished episodes (is it a run directory?)")
        label = run_label(rd, cfg)
        base, k = label, 2
        while label in labels:  # two runs with the same model/ablation/experiment: keep both, numbered
            label, k = f"{base}#{k}", k + 1
        labels.append(label)
        world = (cfg.get("env") or {}).get("name", "?")
        taskset = cfg.get("taskset", "classic")
        by_task: dict[str, list[Any]] = {}
        subset_of: dict[str, str] = {}
        for e in eps:
            by_task.setdefault(e.task_id, []).append(e)
            subset_of[e.task_id] = e.subset
        for tid, group in by_task.items():
            key = (world, taskset, subset_of[tid], tid)
            row = rows.setdefault(key, {"world": world, "taskset": taskset, "subset": subset_of[tid], "task_id": tid})
            row[f"{label}:success"] = sum(1.0 for e in group if e.success) / len(group)
            row[f"{label}:progress"] = sum(e.progress for e in group) / len(group)
        runs.append({"label": label, "run_dir": str(rd), "world": world, "taskset": taskset,
                     "model": (cfg.get("model") or {}).get("name"), "ablation": (cfg.get("ablation") or {}).get("name"),
                     "episodes": len(eps), "tasks": len(by_task)})
    columns = ["world", "taskset", "subset", "task_id"] + [f"{lab}:{m}" for lab in labels for m in ("success", "progress")]
    ordered = [rows[k] for k in sorted(rows)]
    out.mkdir(parents=True, exist_ok=True)
    with (out / "matrix.csv").open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=columns, restval="")
        w.writeheader()
        w.writerows(ordered)
    written = [out / "matrix.csv"]
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        pa = None
    if pa is not None:
        table = pa.table({c: [r.get(c) for r in ordered] for c in columns})
        pq.write_table(table, out / "matrix.parquet")
        written.append(out / "matrix.parquet")
    (out / "runs.json").write_text(json.dumps(runs, indent=1) + "\n", encoding="utf-8")
    written.append(out / "runs.json")
    return written


def cmd_matrix(args: list[str]) -> int:
    """``eb export RUN [RUN...] --format matrix --out DIR [--overwrite]``."""
    import sys

    from eb_core._export_flags import FlagError, parse_flags

    usage = "usage: eb export RUN [RUN...] --format matrix --out DIR [--overwrite]"
    try:
        runs, opts = parse_flags(args, fmt="matrix")
    except FlagError as exc:
        print(f"eb export: {exc}; {usage}", file=sys.stderr)
        return 2
    out, overwrite = opts["--out"], bool(opts["--overwrite"])
    if not runs or not out:
        print(f"eb export: {usage}", file=sys.stderr)
        return 2
    missing = [r for r in runs if not (Path(r) / "episodes.jsonl").is_file()]
    if missing:
        print(f"eb export: {missing[0]} is not a run directory (no episodes.jsonl)", file=sys.stderr)
        return 2
    try:
        files = write_matrix(runs, str(out), overwrite=overwrite)
    except (FileExistsError, ValueError) as exc:
        print(f"eb export: {exc}", file=sys.stderr)
        return 2
    print(f"{len(runs)} run(s) -> {', '.join(str(f) for f in files)}")
    return 0
