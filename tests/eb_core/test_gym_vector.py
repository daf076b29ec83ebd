"""The vector env (eb_core.gym.vector): N environments over W worker processes, batched observations,
autoreset, an environment that crashes, a worker process killed with SIGKILL mid-run, a worker that hangs, and
the same groups in Ray actors (skipped without Ray)."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

import eb_core.gym as ebgym  # noqa: E402
import fixture_plugin  # noqa: E402
from eb_core.plugins import Registry, get_plugin_manager  # noqa: E402

WAIT, RIGHT, EXPLODE = 2, 1, 3
RAW = dict(obs_mode="raw", expert_labels=False)


@pytest.fixture(autouse=True)
def corridor():
    """The fixture world's id (the workers see it through EB_PLUGINS, set by the core conftest)."""
    ebgym.register_worlds(Registry(get_plugin_manager(plugins=[fixture_plugin])))


def _check_batch(vec, obs, n):
    assert obs["image"].shape == (n, 64, 64, 3) and obs["image"].dtype == np.uint8
    assert len(obs["text"]) == n and all(isinstance(t, str) and "walk to cell" in t for t in obs["text"])
    assert vec.observation_space.contains(obs)


def test_8_environments_over_2_processes_with_one_crashing():
    vec = ebgym.make_vector_env("corridor", 8, workers=2, **RAW)  # forkserver workers
    try:
        pids = vec.worker_pids
        assert len(set(pids)) == 2 and os.getpid() not in pids  # 4 environments in each of 2 processes
        assert [vec.worker_of(i) for i in range(8)] == [0] * 4 + [1] * 4
        obs, info = vec.reset(seed=list(range(8)))
        _check_batch(vec, obs, 8)
        assert list(info["task_id"]) == [f"{s}-{i}" for s in ("near", "far") for i in range(5)][:8]
        # the same seed gives the same task and pixels in either process
        same, _ = vec.reset(seed=[5] * 8)
        assert all(np.array_equal(same["image"][0], same["image"][i]) for i in range(8))
        obs, info = vec.reset(seed=list(range(8)))
        for t in range(4):
            actions = np.full(8, WAIT)
            if t == 1:
                actions[5] = EXPLODE  # the world of env 5 raises
            obs, rew, term, trunc, info = vec.step(actions)
            _check_batch(vec, obs, 8)
            if t == 1:
                assert trunc[5] and "the corridor exploded" in info["error"][5]
                assert not trunc[[0, 1, 2, 3, 4, 6, 7]].any() and not info["_error"][[0, 1, 2, 3, 4, 6, 7]].any()
                assert info["steps"][4] == 2 and info["steps"][6] == 2  # its neighbours in the process go on
            if t == 2:  # NextStep autoreset: env 5 starts a new episode with a rebuilt world
                assert list(np.flatnonzero(info["_instruction"])) == [5] and not trunc[5] and "error" not in info
            if t == 3:
                assert info["steps"][5] == 1 and info["steps"][0] == 4
        assert vec.worker_pids == pids and vec.restarts == 0  # an env crash never restarts its process
    finally:
        vec.close()
    assert vec.closed


def test_a_worker_killed_with_sigkill_loses_only_its_environments_episodes():
    vec = ebgym.make_vector_env("corridor", 8, workers=2, **RAW)
    try:
        vec.reset(seed=list(range(8)))
        for _ in range(2):
            vec.step(np.full(8, WAIT))
        victim = vec.worker_pids[1]
        os.kill(victim, signal.SIGKILL)  # mid-run, between two steps
        obs, rew, term, trunc, info = vec.step(np.full(8, WAIT))
        _check_batch(vec, obs, 8)
        assert trunc[4:].all() and not trunc[:4].any()
        assert all("died (signal 9)" in info["error"][i] for i in range(4, 8))
        assert not info["_error"][:4].any() and list(info["steps"][:4]) == [3] * 4  # the other process went on
        assert vec.restarts == 1 and vec.worker_pids[1] != victim and vec.worker_pids[0] != victim
        obs, rew, term, trunc, info = vec.step(np.full(8, WAIT))  # the new process resets envs 4..7
        assert list(np.flatnonzero(info["_instruction"])) == [4, 5, 6, 7] and "error" not in info and not trunc.any()
        obs, rew, term, trunc, info = vec.step(np.full(8, RIGHT))
        assert list(info["steps"]) == [5] * 4 + [1] * 4 and "error" not in info
    finally:
        vec.close()


def test_a_worker_that_stops_answering_is_replaced_and_same_step_autoreset():
    over = ("+env.params.sleep_s=30",)  # every step of the world hangs 30 s
    vec = ebgym.make_vector_env("corridor", 2, workers=2, context="fork", step_timeout_s=1.5, overrides=over, **RAW)
    try:
        vec.reset(seed=[0, 1])
        hung = vec.worker_pids
        obs, rew, term, trunc, info = vec.step(np.full(2, WAIT))
        assert trunc.all() and all("no answer within" in e for e in info["error"])
        assert vec.restarts == 2 and not set(vec.worker_pids) & set(hung)
    finally:
        vec.close()
    vec = ebgym.make_vector_env("corridor", 2, workers=1, context="fork", autoreset_mode="SameStep", **RAW)
    try:
        obs, info = vec.reset(seed=[0, 5])  # near-0: start 0, goal 2; far-0: start 0, goal 5
        for _ in range(2):
            obs, rew, term, trunc, info = vec.step(np.full(2, RIGHT))
        assert term[0] and not term[1] and info["_final_obs"][0] and not info["_final_obs"][1]
        assert info["_instruction"][0] and not info["_instruction"][1]  # env 0 is already reset, in the same step
        assert not np.array_equal(obs["image"][0], info["final_obs"][0]["image"])
        assert info["final_info"]["task_success"][0]
    finally:
        vec.close()


def test_bad_arguments_fail_with_one_clear_line():
    with pytest.raises(ValueError, match="executor must be 'local' or 'ray'"):
        ebgym.make_vector_env("corridor", 2, executor="slurm", **RAW)
    with pytest.raises(ValueError, match="workers must be an integer >= 1"):
        ebgym.make_vector_env("corridor", 2, workers=0, **RAW)
    with pytest.raises(ValueError, match="unknown world 'nowhere'"):
        ebgym.make_vector_env("nowhere", 2)
    with pytest.raises(ValueError, match="unknown config key 'env.params.sleepy'"):  # in this process, at once
        ebgym.make_vector_env("corridor", 2, overrides=("env.params.sleepy=1",), **RAW)


def test_groups_in_ray_actors_step_batched_and_survive_a_killed_actor():
    ray = pytest.importorskip("ray", reason='Ray is an optional extra: pip install "embodiedbench[ray]"')
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        vec = ebgym.make_vector_env("corridor", 4, workers=2, executor="ray", **RAW)
        try:
            pids = vec.worker_pids
            assert len(set(pids)) == 2 and os.getpid() not in pids
            obs, info = vec.reset(seed=[0, 1, 2, 3])
            _check_batch(vec, obs, 4)
            obs, rew, term, trunc, info = vec.step(np.array([WAIT, EXPLODE, WAIT, WAIT]))
            assert trunc[1] and "exploded" in info["error"][1] and not trunc[[0, 2, 3]].any()
            os.kill(pids[0], signal.SIGKILL)  # the actor holding envs 0 and 1
            obs, rew, term, trunc, info = vec.step(np.full(4, WAIT))
            _check_batch(vec, obs, 4)
            assert trunc[:2].all() and "Ray actor" in info["error"][0] and not trunc[2:].any()
            assert vec.restarts == 1 and vec.worker_pids[0] != pids[0]
            obs, rew, term, trunc, info = vec.step(np.full(4, WAIT))
            assert list(np.flatnonzero(info["_instruction"])) == [0, 1] and "error" not in info
            assert list(info["steps"][2:]) == [3, 3]
        finally:
            vec.close()
    finally:
        if started:
            ray.shutdown()


def test_prompt_mode_batches_texts_and_images_and_takes_answer_texts():
    vec = ebgym.make_vector_env("corridor", 3, workers=2, context="fork", obs_mode="prompt", expert_labels=False)
    try:
        obs, info = vec.reset(seed=[0, 1, 2])
        assert isinstance(obs["prompt"], tuple) and len(obs["prompt"]) == 3
        assert all(p.count(ebgym.IMAGE_PLACEHOLDER) == len(imgs) >= 1 for p, imgs in zip(obs["prompt"], obs["images"]))
        assert all("walk to cell" in p for p in obs["prompt"])
        right = '{"executable_plan": [{"action_id": 1, "action_name": "step right"}]}'
        obs, rew, term, trunc, info = vec.step((right, "not an answer", right))
        assert list(info["format_ok"]) == [True, False, True] and list(info["executed_actions"][0]) == [1]
        assert all(img.shape == (64, 64, 3) for imgs in obs["images"] for img in imgs)
    finally:
        vec.close()


def test_reset_seeds_follow_gymnasium_and_refuse_a_wrong_count():
    # one rule for the in-process vector env and the service's client (eb_core.serve.client)
    from eb_core.gym.vector import reset_seeds

    assert reset_seeds(None, 3) == [None, None, None]
    assert reset_seeds(np.int64(5), 3) == [5, 6, 7]
    assert reset_seeds([4, None, np.int32(9)], 3) == [4, None, 9]
    with pytest.raises(ValueError, match="needs 3 seeds \\(one per environment\\), got 2"):
        reset_seeds([1, 2], 3)
