"""Validation of a backend's keyword arguments (the ``model`` config node minus ``name`` and ``backend``).

Each backend declares a pydantic model with ``extra="forbid"``; a typo fails with one line that names the
key and the keys the backend accepts.
"""

from __future__ import annotations

from typing import Any, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from eb_core.config import ConfigError
from eb_core.model import ModelFatalError

__all__ = ["BackendSettings", "ModelConfigError", "validate_settings"]


class ModelConfigError(ConfigError, ModelFatalError):
    """A model preset (or a ``model.*`` override) is invalid. One line, naming the key."""


class BackendSettings(BaseModel):
    """Keys every backend accepts."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    max_cost_usd: float | None = Field(default=None, ge=0)
    """Budget cap for the run, enforced by the runner from the per-call ``Usage.cost_usd``."""


S = TypeVar("S", bound=BackendSettings)

_HINTS = {
    "api_key": "API keys are never config values: put the key in an environment variable and name it in "
    "model.api_key_env",
}


def validate_settings(cls: type[S], backend: str, kwargs: dict[str, Any]) -> S:
    """Validate ``kwargs`` for ``backend`` or raise :class:`ModelConfigError` with one clear line."""
    for key, value in kwargs.items():
        if value == "???":  # Hydra's mandatory-value marker, left unset
            raise ModelConfigError(f"model backend {backend!r} needs a value for 'model.{key}': add model.{key}=... "
                                   f"to the command")
    try:
        return cls.model_validate(kwargs)
    except ValidationError as exc:
        err = exc.errors()[0]
        key = ".".join(str(p) for p in err["loc"])
        allowed = ", ".join(sorted(cls.model_fields))
        if err["type"] == "extra_forbidden":
            hint = _HINTS.get(key)
            extra = f" ({hint})" if hint else ""
            raise ModelConfigError(
                f"unknown key 'model.{key}' for model backend {backend!r}{extra}; allowed keys: {allowed}"
            ) from None
        if err["type"] == "missing":
            raise ModelConfigError(
                f"model backend {backend!r} needs the key 'model.{key}'; allowed keys: {allowed}"
            ) from None
        shown = repr(err.get("input"))
        if len(shown) > 80:
            shown = shown[:77] + "..."
        raise ModelConfigError(f"invalid value for 'model.{key}' (backend {backend!r}): {err['msg']} (got {shown})") from None
