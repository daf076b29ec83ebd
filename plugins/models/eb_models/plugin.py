"""Entry point of the ``eb-models`` plugin: registers the model backends and ships ``conf/model`` presets.

Imports nothing heavy: the backend classes (and litellm) are imported only when a run selects them.
"""

from __future__ import annotations

from eb_core import ModelBackendSpec, hookimpl

LITELLM_INSTALL = "pip install 'litellm==1.110.2'"
LLAMACPP_INSTALL = "pip install 'eb-models[local]'  (or: pip install 'llama-cpp-python[server]==0.3.36')"


@hookimpl
def eb_register_model_backends() -> list[ModelBackendSpec]:
    return [
        ModelBackendSpec(
            name="litellm",
            entry_point="eb_models.litellm_backend:LiteLLMBackend",
            description="Any API model (OpenAI, Anthropic, Gemini, Azure, Bedrock) or OpenAI-compatible server "
            "(vLLM, lmdeploy, SGLang, Ollama) through litellm",
            install_hint=LITELLM_INSTALL,
        ),
        ModelBackendSpec(
            name="llamacpp",
            entry_point="eb_models.llamacpp_backend:LlamaCppBackend",
            description="A GGUF model run in this process by llama-cpp-python (text, or vision with its projector); "
            "grammar-constrained JSON",
            install_hint=LLAMACPP_INSTALL,
        ),
        ModelBackendSpec(
            name="oracle",
            entry_point="eb_models.baselines:OracleBackend",
            description="Offline: answers with the env's expert plan (exercises the whole pipeline)",
        ),
        ModelBackendSpec(
            name="random",
            entry_point="eb_models.baselines:RandomBackend",
            description="Offline: plans of 1-3 uniformly random valid actions, seeded per episode",
        ),
        ModelBackendSpec(
            name="replay",
            entry_point="eb_models.replay:ReplayBackend",
            description="Offline: replays the raw answers recorded in an earlier run directory",
        ),
        ModelBackendSpec(
            name="human",
            entry_point="eb_models.human:HumanBackend",
            description="A person plays in the terminal: sees the image path and prompt, types action ids",
        ),
    ]


@hookimpl
def eb_config_searchpath() -> list[str]:
    return ["pkg://eb_models.conf"]
