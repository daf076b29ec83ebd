"""runner.executor=ray on a real 2-node Ray cluster (ray.cluster_utils.Cluster): placement, records, a lost node.

Skipped when Ray is not installed (``pip install "embodiedbench[ray]"``; requirements-test.txt installs it)."""

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.records import EpisodeRecord
from eb_core.runner import RunError, run

ray = pytest.importorskip("ray", reason='Ray is an optional extra: pip install "embodiedbench[ray]"')
from ray.cluster_utils import Cluster  # noqa: E402


class NodeLoggingScripted(fixture_plugin.ScriptedBackend):
    """The scripted oracle, taking ``delay_s`` per call and logging the Ray node of each call to ``log``."""

    def __init__(self, delay_s: float = 0.2, log: str | None = None, max_concurrency=None, rpm=None, model_id=None, **kw):
        super().__init__(**kw)
        self.delay_s, self.log = delay_s, log

    def complete(self, request):
        t0 = time.time()
        time.sleep(self.delay_s)
        node = ray.get_runtime_context().get_node_id() if ray.is_initialized() else "driver"
        if self.log:
            fd = os.open(self.log, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            os.write(fd, f"{node} {time.time()} {t0}\n".encode())
            os.close(fd)
        return super().complete(request)


@fixture_plugin.hookimpl
def eb_register_model_backends():
    from eb_core import ModelBackendSpec

    return [ModelBackendSpec(name="node-logging", entry_point=f"{__name__}:NodeLoggingScripted", description="test")]


PLUGINS = [fixture_plugin, sys.modules[__name__]]


def lines(run_dir):
    return [json.loads(x) for x in (Path(run_dir) / "episodes.jsonl").read_text().splitlines()]


def ray_config(log, delay_s=0.2, model=None, **over):
    return make_config(model={"name": "node-logging", "backend": "node-logging", "oracle": True, "delay_s": delay_s,
                              "log": str(log), **(model or {})},
                       runner__executor="ray", runner__workers=2, runner__concurrency=4, **over)


@pytest.fixture(scope="module")
def cluster():
    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 0})
    nodes = [c.add_node(num_cpus=1), c.add_node(num_cpus=1)]
    c.wait_for_nodes()
    ray.init(address=c.address, include_dashboard=False, log_to_driver=False)
    yield c, nodes
    ray.shutdown()
    c.shutdown()


def test_episodes_land_on_both_nodes_and_match_a_local_run(cluster, tmp_path):
    c, nodes = cluster
    log = tmp_path / "calls.log"
    summary = run(ray_config(log, runner__repeats=2), tmp_path / "ray", plugins=PLUGINS)
    local = run(make_config(runner__repeats=2), tmp_path / "local", plugins=[fixture_plugin])
    strip = lambda rs: sorted((r["task_id"], r["repeat"], r["seed"], r["success"], r["env_steps"]) for r in rs)
    assert strip(lines(tmp_path / "ray")) == strip(lines(tmp_path / "local"))
    assert summary["complete"] and summary["n_finished"] == 20
    used = {ln.split()[0] for ln in log.read_text().splitlines()}
    assert used == {n.node_id for n in nodes}  # both worker nodes played episodes (the head has no CPU)
    # the driver wrote the step files of every episode, as in a local run
    for r in lines(tmp_path / "ray"):
        name = r["task_id"] if r["repeat"] == 0 else f"{r['task_id']}_repeat{r['repeat']}"
        assert (tmp_path / "ray" / "episodes" / name / "steps.jsonl").read_text().strip()
    if "node" in EpisodeRecord.model_fields:
        assert {r["node"] for r in lines(tmp_path / "ray")} == used


def test_max_concurrency_holds_across_the_cluster_and_jobs_share_the_limiter(cluster, tmp_path):
    from eb_core.ray_executor import get_limiter

    log = tmp_path / "calls.log"
    model = {"max_concurrency": 1, "model_id": f"limited-{tmp_path.name}"}
    summary = run(ray_config(log, delay_s=0.15, model=model, limit=6), tmp_path / "run", plugins=PLUGINS)
    assert summary["complete"]
    calls = [(float(s), float(e), n) for n, e, s in (ln.split() for ln in log.read_text().splitlines())]
    assert len({n for _s, _e, n in calls}) == 2  # both nodes called the model...
    assert max(sum(1 for s, e, _ in calls if s <= t < e) for t, _e, _n in calls) == 1  # ...never two at once
    full = {"name": "node-logging", "backend": "node-logging", **model}
    a, b = get_limiter(full), get_limiter(full)  # a second job (another driver) gets the same limiter
    assert a._actor_id == b._actor_id and ray.get(a.limits.remote()) == (1, None)


def test_a_node_lost_mid_run_loses_no_episode_and_doubles_none(cluster, tmp_path):
    c, nodes = cluster
    log = tmp_path / "calls.log"
    victim = nodes[1]

    def remove_when_busy():
        deadline = time.time() + 120
        while time.time() < deadline:
            if log.exists() and sum(1 for ln in log.read_text().splitlines() if ln.startswith(victim.node_id)) >= 3:
                c.remove_node(victim, allow_graceful=False)
                return
            time.sleep(0.05)

    remover = threading.Thread(target=remove_when_busy)
    remover.start()
    summary = run(ray_config(log, delay_s=0.4, runner__repeats=3), tmp_path / "run", plugins=PLUGINS)
    remover.join()
    recs = lines(tmp_path / "run")
    keys = [(r["task_id"], r["repeat"]) for r in recs]
    assert len(keys) == 30 == len(set(keys))  # none lost, none doubled
    assert all(r["status"] == "ok" and r["success"] for r in recs) and summary["complete"]
    calls = [ln.split() for ln in log.read_text().splitlines()]
    removed_at = max(float(t) for n, t, _ in calls if n == victim.node_id)
    assert any(n == nodes[0].node_id and float(t) > removed_at for n, t, _ in calls)  # the survivor took over


def test_the_ray_executor_without_ray_is_one_line_naming_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # as if not installed
    with pytest.raises(RunError, match=r'pip install "embodiedbench\[ray\]"') as err:
        run(ray_config(tmp_path / "log"), tmp_path / "run", plugins=PLUGINS)
    assert "\n" not in str(err.value)


def test_plain_runs_and_eb_list_never_import_ray(tmp_path):
    code = ("import sys; from eb_core.cli import main\n"
            "try:\n    main(['list'])\nexcept SystemExit:\n    pass\n"
            "import fixture_plugin; from eb_core_testutil import make_config; from eb_core.runner import run\n"
            f"run(make_config(runner__workers=2, runner__concurrency=3), {str(tmp_path)!r}, plugins=[fixture_plugin])\n"
            "print('RAY IMPORTED' if 'ray' in sys.modules else 'NO RAY')\n")
    env = dict(os.environ, PYTHONPATH=str(Path(fixture_plugin.__file__).parent))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().endswith("NO RAY")
