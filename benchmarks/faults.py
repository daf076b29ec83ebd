"""Fault figures, one command: what survives a kill, an interrupt, a hostile model server, garbage, a full disk.

Each row runs a real fault against the real `eb` command or the real runner and prints its goal and the
measured figure. The world is the core's corridor fixture (tests/eb_core/fixture_plugin.py: real images,
cheap steps), so the figures measure the harness, not a simulator.

    python benchmarks/faults.py            # the full table (about 3-5 minutes on 2 cores)
    python benchmarks/faults.py --quick    # a short version (what tests/benchmarks/test_faults.py runs)

Exit status 0 when every row meets its goal, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import resource
import shutil
import signal
import string
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "tests" / "eb_core"
PLAN_RIGHT = json.dumps({
    "visual_state_description": "a corridor",
    "reasoning_and_reflection": "the goal is to the right",
    "language_plan": "walk right",
    "executable_plan": [{"action_id": 1, "action_name": "step right"}] * 5,
})


@dataclass
class Row:
    fault: str
    goal: str
    measured: str
    ok: bool


def _env() -> dict[str, str]:
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", PYTHONPATH=str(FIXTURES), EB_DISABLE_PLUGIN_AUTOLOAD="1")
    env.pop("PYTHONSTARTUP", None)
    return env


def _cmd(run_dir: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "eb_core.cli", "run", "env=corridor", "model=scripted-oracle",
            "runner.quiet=true", f"hydra.run.dir={run_dir}", *extra]


def _records(run_dir: Path) -> list[tuple[str, int]]:
    path = run_dir / "episodes.jsonl"
    if not path.exists():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            rec = json.loads(line)
        except ValueError:
            continue  # a torn last line is the runner's to drop; it is not a finished episode
        out.append((rec["task_id"], rec.get("repeat", 0)))
    return out


def _last_line(text: str) -> str:
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    return lines[-1] if lines else ""


# -- rows --------------------------------------------------------------------------------------------------------

def kill9(n_kills: int, rng: random.Random, tmp: Path) -> Row:
    """kill -9 of `eb run` (2 workers) at random moments; after each kill the same command resumes."""
    run_dir = tmp / "kill9"
    extra = ("+env.params.sleep_s=0.04", "runner.workers=2", "runner.repeats=3")
    total = 30
    lost = doubled = 0
    kills = 0
    seen: list[tuple[str, int]] = []
    for _ in range(n_kills):
        proc = subprocess.Popen(_cmd(run_dir, *extra), env=_env(), stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.3, 2.5))
        if proc.poll() is None:
            proc.send_signal(signal.SIGKILL)
            kills += 1
        proc.wait()
        now = _records(run_dir)
        lost += len(set(seen) - set(now))
        doubled += len(now) - len(set(now))
        seen = now
        if len(set(now)) >= total:
            break
    done = subprocess.run(_cmd(run_dir, *extra), env=_env(), capture_output=True, text=True, timeout=300)
    final = _records(run_dir)
    lost += len(set(seen) - set(final))
    doubled += len(final) - len(set(final))
    complete = done.returncode == 0 and len(set(final)) == total
    return Row(f"kill -9 of eb run at {kills} random moments (workers=2)", "0 lost, 0 doubled, resume completes",
               f"{lost} lost, {doubled} doubled, {len(set(final))}/{total} after resume"
               + ("" if done.returncode == 0 else f" (resume exit {done.returncode})"),
               lost == 0 and doubled == 0 and complete)


def sigint(rng: random.Random, tmp: Path) -> Row:
    """Ctrl-C at a random moment: how long until the process is gone, and the resume completes."""
    run_dir = tmp / "sigint"
    extra = ("+env.params.sleep_s=0.04", "runner.workers=2", "runner.repeats=2")
    proc = subprocess.Popen(_cmd(run_dir, *extra), env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.time() + 60
    while time.time() < deadline and not _records(run_dir):  # interrupt a run that is under way
        time.sleep(0.05)
    time.sleep(rng.uniform(0.0, 1.5))
    t0 = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=60)
        stop_s = time.perf_counter() - t0
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        stop_s = float("inf")
    before = _records(run_dir)
    done = subprocess.run(_cmd(run_dir, *extra), env=_env(), capture_output=True, text=True, timeout=300)
    after = _records(run_dir)
    ok = stop_s <= 10 and done.returncode == 0 and len(set(after)) == 20 == len(after) and set(before) <= set(after)
    return Row("SIGINT at a random moment", "stops within 10 s, resume completes, 0 doubled",
               f"stopped in {stop_s:.1f} s with {len(before)} finished; resume {len(set(after))}/20, "
               f"{len(after) - len(set(after))} doubled", ok)


def hostile_server(tmp: Path) -> Row:
    """The real litellm backend against a real HTTP server that misbehaves in every way we know."""
    sys.path.insert(0, str(FIXTURES))
    import fixture_plugin  # noqa: E402

    import eb_models.plugin
    from eb_core.config import validate_config
    from eb_core.runner import run
    from eb_models.stub_server import StubOpenAIServer, StubReply

    good = StubReply(content=PLAN_RIGHT)
    faults = {
        "429 + Retry-After": StubReply(status=429, headers={"Retry-After": "0.2"}),
        "500": StubReply(status=500),
        "timeout": StubReply(content=PLAN_RIGHT, delay_s=2.5),
        "truncated body": StubReply(body='{"id": "x", "choices": [{"message": {"content": "{\\"exec'),
        "1 MB answer": StubReply(content="x" * 1_000_000),
        "garbage": StubReply(content="I would rather not say."),
        "wrong JSON types": StubReply(content=json.dumps({"executable_plan": "five steps right",
                                                          "language_plan": 7})),
        "refused mid-run (503)": StubReply(status=503, headers={"Retry-After": "0.1"}),
    }
    cfg = validate_config({
        "env": {"name": "corridor", "max_steps": 10, "max_invalid_actions": 4, "resolution": 64, "params": {}},
        "model": {"name": "hostile", "backend": "litellm", "model_id": "openai/hostile", "api_base": "",
                  "input_cost_per_token": 0.0, "output_cost_per_token": 0.0, "timeout_s": 1.0, "max_retries": 3,
                  "retry_max_seconds": 20},
        "planner": {"name": "vlm"},
        "ablation": {"name": "none"},
        "runner": {"workers": 1, "quiet": True, "save_images": False},
    })
    saved = os.environ.get("EB_DISABLE_PLUGIN_AUTOLOAD")
    os.environ["EB_DISABLE_PLUGIN_AUTOLOAD"] = "1"  # only the fixture world and eb-models take part
    with StubOpenAIServer(default=good) as server:
        cfg.model.api_base = server.url  # type: ignore[attr-defined]
        queue = []
        for reply in faults.values():
            queue += [reply, good]
        server.push(*queue)
        t0 = time.perf_counter()
        try:
            summary = run(cfg, tmp / "hostile", plugins=[fixture_plugin, eb_models.plugin])
            error = None
        except Exception as exc:  # the row reports it; a crash is a failed goal
            summary, error = None, f"{type(exc).__name__}: {exc}"
        wall = time.perf_counter() - t0
        chat = [r for r in server.requests if r.path.endswith("/chat/completions")]
    if saved is None:
        os.environ.pop("EB_DISABLE_PLUGIN_AUTOLOAD", None)
    else:
        os.environ["EB_DISABLE_PLUGIN_AUTOLOAD"] = saved
    if summary is None:
        return Row("hostile model server (8 kinds of fault)", "run completes, faults counted, retries bounded",
                   f"crashed: {error}", False)
    recs = [json.loads(x) for x in (tmp / "hostile" / "episodes.jsonl").read_text().splitlines()]
    out_err = sum(r["output_errors"] for r in recs)
    errors = sum(r["status"] == "error" for r in recs)
    complete = summary["n_finished"] == 10
    bounded = len(chat) <= sum(r["model_calls"] for r in recs) * 4 + 2 and wall < 120
    return Row("hostile model server: " + ", ".join(faults),
               "run completes; every fault counted; retries bounded (<= 3 per call)",
               f"{summary['n_finished']}/10 episodes recorded ({errors} error episodes), {out_err} output errors "
               f"counted, {len(chat)} HTTP requests for {sum(r['model_calls'] for r in recs)} model calls, {wall:.0f} s",
               complete and bounded and out_err >= 3)


def fuzz(n: int) -> Row:
    """Garbage model outputs through the real parser, for a discrete and a vector action space."""
    from eb_core.env import DiscreteActionSpace, VectorActionSpace
    from eb_core.parsing import parse_planner_output

    spaces = (DiscreteActionSpace(actions=tuple(f"action {i}" for i in range(40))),
              VectorActionSpace(names=("x", "y", "z", "roll", "pitch", "yaw", "gripper"),
                                low=(0,) * 7, high=(100, 100, 100, 120, 120, 120, 1)))
    rng = random.Random(7)
    alphabet = string.printable + '{}[]":,' * 4

    def rand_json(depth: int = 0) -> Any:
        k = rng.randrange(7 if depth < 3 else 4)
        if k == 0:
            return rng.randrange(-5, 200)
        if k == 1:
            return "".join(rng.choice(alphabet) for _ in range(rng.randrange(12)))
        if k == 2:
            return None
        if k == 3:
            return rng.random() * 100
        if k == 4:
            return [rand_json(depth + 1) for _ in range(rng.randrange(5))]
        keys = ["executable_plan", "action_id", "action", "language_plan", "visual_state_description", "x"]
        return {rng.choice(keys): rand_json(depth + 1) for _ in range(rng.randrange(5))}

    crashes = 0
    worst = 0.0
    for i in range(n):
        if i % 3 == 0:
            text = "".join(rng.choice(alphabet) for _ in range(rng.randrange(400)))
        else:
            text = json.dumps({"executable_plan": rand_json(), "reasoning_and_reflection": rand_json()})
            if i % 3 == 2:
                text = "```json\n" + text[: rng.randrange(len(text) + 1)] + "\nsome prose"
        for space in spaces:
            t0 = time.perf_counter()
            try:
                parse_planner_output(text, space)
            except Exception:  # noqa: BLE001 - counting crashes is the point
                crashes += 1
            worst = max(worst, time.perf_counter() - t0)
    return Row(f"{n:,} fuzzed model outputs x 2 action spaces through the parser", "0 crashes, worst < 50 ms",
               f"{crashes} crashes, worst {worst * 1000:.1f} ms", crashes == 0 and worst < 0.05)


def concurrent_runs(tmp: Path) -> Row:
    run_dir = tmp / "twice"
    extra = ("+env.params.sleep_s=0.3",)
    first = subprocess.Popen(_cmd(run_dir, *extra), env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while time.time() < deadline and not _records(run_dir):  # the first run is under way
        time.sleep(0.05)
    t0 = time.perf_counter()
    second = subprocess.run(_cmd(run_dir, *extra), env=_env(), capture_output=True, text=True, timeout=60)
    refuse_s = time.perf_counter() - t0
    first.wait(timeout=120)
    recs = _records(run_dir)
    line = _last_line(second.stderr)
    ok = second.returncode != 0 and "pid" in line and len(recs) == len(set(recs)) == 10
    return Row("two eb run on one run directory at once", "the second refused at once (one line), 0 doubled",
               f"exit {second.returncode} after {refuse_s:.1f} s: {line[:90]!r}; {len(recs)} records, "
               f"{len(recs) - len(set(recs))} doubled", ok)


def malformed_task_file(tmp: Path) -> Row:
    bad = tmp / "bad_tasks.json"
    bad.write_text('{"version": 3, "tasks": [{"id": "x", "subset": 5}')
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-m", "eb_core.cli", "run", "env=navigation", "model=oracle",
                        f"env.params.task_file={bad}", f"hydra.run.dir={tmp / 'badtasks'}", "runner.quiet=true"],
                       env=env, capture_output=True, text=True, timeout=120)
    err = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    ok = r.returncode != 0 and len(err) == 1 and str(bad) in err[0] and "Traceback" not in r.stderr
    return Row("malformed task file", "one line naming the file, no traceback",
               f"exit {r.returncode}, {len(err)} line(s): {(err[0] if err else '')[:100]!r}", ok)


def _make_read_only(path: Path) -> Any:
    """Make ``path`` read-only for the next command; return the undo. Root ignores permission bits, so as
    root the directory is bind-mounted read-only onto itself (a read-only file system); else chmod."""
    if os.geteuid() == 0 and shutil.which("mount"):
        ok = subprocess.run(["mount", "--bind", str(path), str(path)], capture_output=True).returncode == 0 and \
            subprocess.run(["mount", "-o", "remount,bind,ro", str(path)], capture_output=True).returncode == 0
        if ok:
            return lambda: subprocess.run(["umount", str(path)], capture_output=True)
    modes = {p: p.stat().st_mode for p in [path, *path.rglob("*")]}
    for p, m in modes.items():
        p.chmod(m & ~0o222)
    return lambda: [p.chmod(m) for p, m in modes.items()]


def read_only_dir(tmp: Path) -> Row:
    run_dir = tmp / "ro"
    first = subprocess.run(_cmd(run_dir, "limit=4"), env=_env(), capture_output=True, text=True, timeout=120)
    before = (run_dir / "episodes.jsonl").read_bytes() if (run_dir / "episodes.jsonl").exists() else b""
    undo = _make_read_only(run_dir)
    try:
        r = subprocess.run(_cmd(run_dir), env=_env(), capture_output=True, text=True, timeout=120)
    finally:
        undo()
    after = (run_dir / "episodes.jsonl").read_bytes() if (run_dir / "episodes.jsonl").exists() else b""
    err = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    ok = first.returncode == 0 and r.returncode != 0 and len(err) == 1 and "Traceback" not in r.stderr \
        and after == before and len(before.splitlines()) == 4
    return Row("read-only run directory", "one clear line, nothing finished lost",
               f"exit {r.returncode}, {len(err)} line(s): {(err[0] if err else '')[:100]!r}; "
               f"{len(after.splitlines())}/4 finished kept", ok)


def full_disk(tmp: Path) -> Row:
    """A file-size limit (ulimit -f) stands in for a full disk: writes past it fail with EFBIG. Once at start
    (refused before anything is written) and once in the middle of a run (episodes.jsonl outgrows it)."""
    run_dir = tmp / "full"
    extra = ("runner.repeats=15", "runner.save_images=false")
    subprocess.run(_cmd(run_dir, "limit=3", *extra), env=_env(), capture_output=True, text=True, timeout=300)
    before = (run_dir / "episodes.jsonl").read_bytes()

    def limit(nbytes: int) -> Any:
        return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))

    lines = []
    codes = []
    for nbytes in (4_096, 32 * 1024):  # below the start-up probe; above it, hit while episodes are appended
        r = subprocess.run(_cmd(run_dir, *extra), env=_env(), capture_output=True, text=True, timeout=300,
                           preexec_fn=limit(nbytes))
        codes.append(r.returncode)
        lines.append([ln for ln in r.stderr.strip().splitlines() if ln.strip()])
    after = (run_dir / "episodes.jsonl").read_bytes()
    mid = _records(run_dir)
    kept = after.startswith(before) and len(mid) == len(set(mid)) > len(before.splitlines())
    resumed = subprocess.run(_cmd(run_dir, *extra), env=_env(), capture_output=True, text=True, timeout=300)
    final = _records(run_dir)
    one_line = all(c != 0 and len(ls) == 1 for c, ls in zip(codes, lines))
    ok = one_line and kept and resumed.returncode == 0 and len(final) == len(set(final)) == 150
    shown = " / ".join(repr((ls[0] if ls else "")[:70]) for ls in lines)
    return Row("full disk (ulimit -f), at start and mid-run", "one clear line, nothing finished lost, resume completes",
               f"exit {codes}, lines {[len(x) for x in lines]}: {shown}; {len(mid)} kept of which "
               f"{len(before.splitlines())} from before; after resume {len(set(final))}/150", ok)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer kills and fuzz inputs (about a minute)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    rng = random.Random(args.seed)
    rows: list[Row] = []
    with tempfile.TemporaryDirectory(prefix="eb_faults_") as d:
        tmp = Path(d)
        tmp.chmod(0o755)
        steps = [
            lambda: kill9(3 if args.quick else 10, rng, tmp),
            lambda: sigint(rng, tmp),
            lambda: hostile_server(tmp),
            lambda: fuzz(1_000 if args.quick else 10_000),
            lambda: concurrent_runs(tmp),
            lambda: malformed_task_file(tmp),
            lambda: read_only_dir(tmp),
            lambda: full_disk(tmp),
        ]
        for step in steps:
            row = step()
            rows.append(row)
            print(f"[{'ok' if row.ok else 'FAIL'}] {row.fault}: {row.measured}", flush=True)
        shutil.rmtree(tmp, ignore_errors=True)
    w = max(len(r.fault) for r in rows)
    print()
    print(f"| {'fault':<{w}} | goal | measured | met |")
    print(f"|{'-' * (w + 2)}|------|----------|-----|")
    for r in rows:
        print(f"| {r.fault:<{w}} | {r.goal} | {r.measured} | {'yes' if r.ok else 'NO'} |")
    passed = sum(r.ok for r in rows)
    print(f"\nfaults: {passed} passed, {len(rows) - passed} failed")
    return 0 if passed == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
