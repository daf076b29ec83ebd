"""EmbodiedBench model backends (the ``eb-models`` plugin).

Backends, registered by :mod:`eb_models.plugin` and imported only when a run selects them:

* ``litellm`` (:class:`eb_models.litellm_backend.LiteLLMBackend`): API models and OpenAI-compatible servers.
* ``oracle``, ``random`` (:mod:`eb_models.baselines`), ``replay`` (:mod:`eb_models.replay`) and ``human``
  (:mod:`eb_models.human`): offline, no network.

Presets (one per model of the paper's Table 4, plus the offline ones) are Hydra options in
``eb_models/conf/model/*.yaml``. :mod:`eb_models.stub_server` is a scriptable OpenAI-compatible server for
tests and dry runs. This module imports nothing heavy.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
