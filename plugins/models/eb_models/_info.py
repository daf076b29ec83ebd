"""``<run_dir>/model_info.json``: what a backend settled on (structured-output mode and why, output limit...).

Written by the backend at its first episode until the runner records :meth:`info` itself.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

__all__ = ["MODEL_INFO_FILE", "write_model_info"]

MODEL_INFO_FILE = "model_info.json"


def write_model_info(run_dir: str | None, info: dict[str, Any]) -> None:
    """Write ``info`` atomically (workers may race; they write the same content)."""
    if not run_dir:
        return
    path = Path(run_dir) / MODEL_INFO_FILE
    tmp = path.with_name(f".{MODEL_INFO_FILE}.{os.getpid()}.tmp")
    try:
        tmp.write_text(json.dumps(info, indent=2, sort_keys=True) + "\n", encoding="utf-8")
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only run directory must not fail the episode
