"""``eb export RUN... --format matrix``: a task x run table of success and progress, read back with pyarrow."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pyarrow.parquet as pq


def _run(tmp_path, name, *args):
    d = tmp_path / name
    p = subprocess.run([sys.executable, "-m", "eb_core", "run", "env=navigation", "env.params.render=false",
                        "runner.quiet=true", f"hydra.run.dir={d}", *args], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    return d


def test_matrix_of_three_runs(tmp_path):
    oracle = _run(tmp_path, "oracle", "model=oracle", "limit=4")
    rnd = _run(tmp_path, "random", "model=random", "limit=4", "runner.repeats=2")
    other = _run(tmp_path, "other", "model=random", "subset=long_horizon", "limit=2")
    out = tmp_path / "m"
    p = subprocess.run([sys.executable, "-m", "eb_core", "export", str(oracle), str(rnd), str(other),
                        "--format", "matrix", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    table = pq.read_table(out / "matrix.parquet").to_pylist()
    runs = json.loads((out / "runs.json").read_text())
    labels = [r["label"] for r in runs]
    assert labels == ["oracle/none/default", "random/none/default", "random/none/default#2"]
    by_id = {r["task_id"]: r for r in table}
    assert len(by_id) == 6 and {r["world"] for r in table} == {"navigation"} and {r["taskset"] for r in table} == {"classic"}
    oracle_eps = [json.loads(x) for x in (oracle / "episodes.jsonl").read_text().splitlines()]
    for e in oracle_eps:
        assert by_id[e["task_id"]]["oracle/none/default:success"] == (1.0 if e["success"] else 0.0)
    rnd_eps = [json.loads(x) for x in (rnd / "episodes.jsonl").read_text().splitlines()]
    tid = rnd_eps[0]["task_id"]
    mine = [e for e in rnd_eps if e["task_id"] == tid]
    assert len(mine) == 2
    assert by_id[tid]["random/none/default:progress"] == sum(e["progress"] for e in mine) / 2
    long_ids = [t for t in by_id if t.startswith("long_horizon")]
    assert all(by_id[t]["oracle/none/default:success"] is None for t in long_ids)  # not played: empty
    with (out / "matrix.csv").open() as fh:
        assert len(list(csv.DictReader(fh))) == 6
    again = subprocess.run([sys.executable, "-m", "eb_core", "export", str(oracle), "--format=matrix", "--out",
                            str(out)], capture_output=True, text=True, timeout=300)
    assert again.returncode == 2 and "exists" in again.stderr and again.stderr.count("\n") == 1
