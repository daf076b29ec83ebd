"""The worlds as Gymnasium environments (eb_core.gym): registration, check_env per world and mode, prompt
observations equal to what ``eb run`` sends, determinism across processes, reward terms, never-raising step,
the vector env with a crashing environment, generated splits."""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

import eb_core.gym as ebgym  # noqa: E402
import fixture_plugin  # noqa: E402
from eb_core.plugins import Registry, get_plugin_manager  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402

WORLDS = {"navigation": "EB/Navigation-v0", "alfred": "EB/ALFRED-v0", "habitat": "EB/Habitat-v0",
          "manipulation": "EB/Manipulation-v0"}
LOW_RES = ("env.resolution=64",)


@pytest.fixture
def installed(monkeypatch):
    """These tests use the installed world plugins (the core conftest restricts to the fixture plugin)."""
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    monkeypatch.delenv("EB_DISABLE_PLUGIN_AUTOLOAD", raising=False)


def _corridor_ids() -> dict[str, str]:
    return ebgym.register_worlds(Registry(get_plugin_manager(plugins=[fixture_plugin])))


def test_import_registers_one_id_per_installed_world():
    ids = ebgym.registered_ids()
    for world, gid in WORLDS.items():
        assert ids.get(gid) == world
        assert gid in gymnasium.registry
    assert ebgym.gym_id("gridworld") == "EB/Gridworld-v0"


def test_eb_list_and_eb_run_modules_do_not_import_gymnasium():
    code = ("import sys, eb_core.cli, eb_core.runner, eb_core.episode, eb_core.planner; "
            "print('gymnasium' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "False", out.stderr


def test_a_third_party_world_gets_an_id_and_passes_check_env():
    assert _corridor_ids() == {"EB/Corridor-v0": "corridor"}
    for mode in ("prompt", "raw"):
        env = gymnasium.make("eb_core.gym:EB/Corridor-v0", obs_mode=mode)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # check_env warnings are failures here
            check_env(env.unwrapped, skip_render_check=True)
        env.close()


@pytest.mark.parametrize("world", list(WORLDS))
@pytest.mark.parametrize("mode", ["prompt", "raw"])
def test_check_env_every_world_and_mode(installed, world, mode):
    env = gymnasium.make(f"eb_core.gym:{WORLDS[world]}", obs_mode=mode, overrides=LOW_RES, expert_labels=False)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            check_env(env.unwrapped, skip_render_check=True)
        obs, info = env.reset(seed=2)
        assert set(info) >= {"task_id", "subset", "instruction"}
        if mode == "prompt":
            assert obs["prompt"].count(ebgym.IMAGE_PLACEHOLDER) == len(obs["images"]) >= 1
            assert obs["images"][0].shape == (64, 64, 3) and obs["images"][0].std() > 5  # a real rendering
        else:
            assert obs["image"].shape == (64, 64, 3) and obs["image"].std() > 5
            assert info["instruction"] in obs["text"]
    finally:
        env.close()


def test_prompt_observation_is_exactly_what_eb_run_sends(installed):
    from eb_core.compose import compose
    from eb_core.compose import validate as _validate
    from eb_core.prompt_view import capture_prompt

    env = gymnasium.make("EB/Habitat-v0", obs_mode="prompt", overrides=("ablation=multi_step_images",)).unwrapped
    obs, info = env.reset(options={"task_id": "base-03"})
    cfg = _validate(compose(["env=habitat", "ablation=multi_step_images"]))
    expected = capture_prompt(cfg, Registry.create(), "base-03", 0)[0]
    text, images = ebgym.request_observation(expected)
    assert obs["prompt"] == text and len(obs["images"]) == len(images)
    assert all(np.array_equal(a, b) for a, b in zip(obs["images"], images))
    # the answer is executed as eb run does: a 2-action plan whose second item is invalid is cut there
    plan = {"executable_plan": [{"action_id": info["expert_action"], "action_name": "x"}, {"action_id": 999}]}
    _, _, term, trunc, step = env.step(json.dumps(plan))
    assert step["executed_actions"] == [info["expert_action"]] and step["format_ok"]
    assert "cut" in step["plan_error"] and not step["action_valid"] and step["reward_terms"]["invalid"] == 1
    env.close()


def test_think_answer_format_in_prompt_and_parser(installed):
    env = gymnasium.make("EB/Habitat-v0", obs_mode="prompt", overrides=("planner.answer_format=think",)).unwrapped
    obs, info = env.reset(seed=0)
    assert "<think>" in obs["prompt"] and "<answer>" in obs["prompt"]
    item = {"action_id": info["expert_action"], "action_name": "x"}
    bare = json.dumps({"executable_plan": [item]})
    _, _, _, _, step = env.step(bare)  # the JSON alone is not the asked format
    assert not step["format_ok"] and "<answer>" in step["format_error"]
    _, _, _, _, step = env.step(f"<think>the {{brace}} is a trap</think>\n<answer>{bare}</answer>")
    assert step["format_ok"] and step["executed_actions"] == [info["expert_action"]]
    env.close()


_DETERMINISM = """
import hashlib, json, sys, gymnasium, eb_core.gym
world, split, mode, seed = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
env = gymnasium.make(world, split=split, obs_mode=mode, overrides=("env.resolution=96",))
obs, info = env.reset(seed=seed)
img = obs["images"][0] if mode == "prompt" else obs["image"]
text = obs["prompt"] if mode == "prompt" else obs["text"]
print(json.dumps([info["task_id"], hashlib.sha256(img.tobytes()).hexdigest(), hashlib.sha256(text.encode()).hexdigest()]))
"""


@pytest.mark.parametrize("world,split,mode", [("EB/Navigation-v0", "test", "raw"),
                                              ("EB/Habitat-v0", "train", "prompt")])
def test_reset_is_deterministic_across_processes(installed, world, split, mode):
    procs = [subprocess.Popen([sys.executable, "-c", _DETERMINISM, world, split, mode, str(seed)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ})
             for seed in (11, 11, 12)]  # three processes at once
    outs = []
    for proc in procs:
        out, err = proc.communicate(timeout=240)
        assert proc.returncode == 0, err[-2000:]
        outs.append(json.loads(out.strip().splitlines()[-1]))
    assert outs[0] == outs[1]
    assert outs[0][0] != outs[2][0]  # another seed, another task


def test_step_never_raises_on_the_parser_fuzz_corpus():
    from test_parsing import _random_json

    _corridor_ids()
    env = gymnasium.make("EB/Corridor-v0", obs_mode="prompt").unwrapped
    rng = random.Random(1234)
    env.reset(seed=0)
    counts = {"format": 0, "ok": 0, "ended": 0}
    for i in range(400):
        if i % 2:
            text = "".join(rng.choice(string_printable() + "{}[]\"':,") for _ in range(rng.randrange(200)))
        else:
            text = json.dumps(_random_json(rng))
            if i % 4 == 0:
                text = text[: rng.randrange(len(text) + 1)]
        obs, reward, term, trunc, info = env.step(text)
        assert isinstance(reward, float) and "reward_terms" in info
        assert env.observation_space.contains(obs)
        counts["format" if not info["format_ok"] else "ok"] += 1
        if term or trunc:
            counts["ended"] += 1
            env.reset(seed=i)
    for odd in (None, b"\xff\xfe", 12, "", "\x00" * 5, "<answer>" * 1000):
        env.step(odd)
        env.reset(seed=0)
    assert counts["format"] > 100 and counts["ended"] > 10
    env.close()


def string_printable() -> str:
    import string

    return string.printable


def test_reward_terms_on_a_scripted_habitat_episode(installed):
    env = gymnasium.make("EB/Habitat-v0", obs_mode="raw", reward="shaped", overrides=("env.params.render=false",
                                                                                       "env.resolution=64"))
    obs, info = env.reset(options={"task_id": "base-00"})
    w = ebgym.reward_weights("shaped")
    total = {k: 0.0 for k in ebgym.TERMS}
    rewards = []
    # one invalid action first (picking with nothing in reach), then the expert to the end
    obs, r, term, trunc, step = env.step(env.unwrapped.env.action_space().actions.index(
        next(a for a in env.unwrapped.env.action_space().actions if a.startswith("pick up"))))
    assert step["reward_terms"]["invalid"] == 1 and not step["action_valid"] and r == pytest.approx(w["invalid"])
    while not (term or trunc):
        obs, r, term, trunc, step = env.step(step["expert_action"])
        rewards.append(r)
        for k, v in step["reward_terms"].items():
            total[k] += v
        assert r == pytest.approx(sum(w.get(k, 0) * v for k, v in step["reward_terms"].items()))
    assert term and not trunc and step["task_success"] and step["progress"] == 1.0
    assert total["success"] == 1 and total["progress"] == pytest.approx(1.0) and total["invalid"] == 0
    assert "expert_action" not in step  # the episode is over
    env.close()


def test_truncated_at_the_worlds_step_limit_and_success_preset(installed):
    env = gymnasium.make("EB/Navigation-v0", obs_mode="raw", reward="success",
                         overrides=("env.max_steps=3", "env.resolution=64"), expert_labels=False)
    env.reset(seed=4)
    ends = [env.step(4)[2:4] for _ in range(3)]  # turning on the spot never reaches the goal
    assert ends == [(False, False), (False, False), (False, True)]
    env.close()


def test_generated_splits_habitat_disjoint_from_test_over_10000_train_tasks(installed):
    from eb_habitat.env import HabitatEnv
    from eb_habitat.splits import scene_key

    shipped = HabitatEnv.load_tasks()
    test_scenes = {scene_key(t.metadata) for t in shipped}
    test_instr = {t.instruction for t in shipped}
    train = HabitatEnv.split_tasks("train", 0, 10_000)
    assert len({t.id for t in train}) == 10_000
    assert not any(scene_key(t.metadata) in test_scenes for t in train)
    assert not any(t.instruction in test_instr for t in train)
    assert {t.subset for t in train} == {t.subset for t in shipped}
    assert HabitatEnv.split_tasks("train", 4321, 2) == train[4321:4323]  # task i depends on (split, i) only
    val = HabitatEnv.split_tasks("val", 0, 50)
    assert [t.instruction for t in val] != [t.instruction for t in train[:50]]


def test_a_world_without_generated_splits_says_which_worlds_have_them(installed):
    with pytest.raises(ValueError, match="no generated 'train' split.*habitat"):  # the fixture world has none
        fixture_plugin.CorridorEnv.split_tasks("train", 0, 1)
    with pytest.raises(ValueError, match="unknown split 'dev'"):
        gymnasium.make("EB/Habitat-v0", split="dev")


def test_vector_env_of_8_with_a_crashing_environment():
    _corridor_ids()
    vec = ebgym.make_vector_env("corridor", 8, obs_mode="raw", expert_labels=False, context="fork")
    try:
        obs, info = vec.reset(seed=list(range(8)))
        assert obs["image"].shape[0] == 8 and len(obs["text"]) == 8
        assert all("walk to cell" in t for t in obs["text"])  # Text observations intact without shared memory
        crashed = False
        for t in range(6):
            actions = np.array([2] * 8)  # wait
            if t == 2:
                actions[3] = 3  # "explode": the world raises in env 3
            obs, rew, term, trunc, info = vec.step(actions)
            if t == 2:
                assert trunc[3] and "Error" in info["error"][3]
                assert not any(trunc[i] and info["_error"][i] for i in range(8) if i != 3)
                crashed = True
            assert len(obs["text"]) == 8 and all(isinstance(x, str) and x for x in obs["text"])
        assert crashed
        # after the autoreset the crashed environment plays again, rebuilt
        obs, rew, term, trunc, info = vec.step(np.array([2] * 8))
        assert "error" not in info or not info["_error"][3]
    finally:
        vec.close()


def test_a_written_val_split_is_what_eb_run_evaluates(installed, tmp_path):
    from eb_habitat.env import HabitatEnv
    from eb_habitat.splits import split_tasks, write_split

    write_split(str(tmp_path), "val", 12)
    loaded = HabitatEnv.load_tasks(task_dir=str(tmp_path))
    assert sorted(t.id for t in loaded) == sorted(t.id for t in split_tasks("val", 0, 12))
    env = gymnasium.make("EB/Habitat-v0", obs_mode="raw", overrides=(f"env.params.task_dir={tmp_path}",
                                                                   "env.params.render=false", "env.resolution=64"))
    _, info = env.reset(options={"task_id": loaded[0].id})
    assert info["instruction"] == loaded[0].instruction
    env.close()
