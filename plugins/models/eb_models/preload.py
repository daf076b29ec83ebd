"""Importing this module warms litellm up the safe way, for process pools that pre-import modules.

The runner's workers are fresh interpreters; each pays litellm's import (3-10 s of CPU) and its
first-call set-up (~0.5 s) before its first episode. A pool that forks workers from a warmed parent
(``multiprocessing`` forkserver with ``set_forkserver_preload(["eb_models.preload"])``) pays it once.
Measured with ``benchmarks/concurrency.py``: see plugins/models/README.md.

It sets ``LITELLM_LOCAL_MODEL_COST_MAP=True`` before the import and makes one offline call
(``mock_response``): no network is touched.
"""

from __future__ import annotations

from eb_models.litellm_backend import _import_litellm

_litellm = _import_litellm()
_litellm.completion(model="openai/warm-up", messages=[{"role": "user", "content": "warm up"}], mock_response="ok",
                    api_key="no-key")
