"""Keeping API keys out of messages: a wrapper whose repr hides the value, and a scrubber for error text."""

from __future__ import annotations

import os
import re
from collections.abc import Iterable

__all__ = ["Scrubber", "Secret", "scrub", "secret_values"]

#: Environment variables whose values are never allowed into a message, besides the backend's own key.
_SECRET_NAME = re.compile(r"(API_KEY|SECRET|TOKEN|PASSWORD|CREDENTIAL)", re.IGNORECASE)
_MIN_LEN = 8


class Secret:
    """Holds a secret string; ``repr``/``str`` never show it."""

    __slots__ = ("_value",)

    def __init__(self, value: str | None) -> None:
        self._value = value

    def get(self) -> str | None:
        return self._value

    def __repr__(self) -> str:
        return "Secret('***')" if self._value else "Secret(None)"

    __str__ = __repr__

    def __reduce__(self):  # never pickled into a child process or a file by accident
        raise TypeError("Secret values cannot be pickled")


def secret_values(extra: Iterable[str | None] = ()) -> list[str]:
    """The strings to scrub: ``extra`` plus the values of secret-looking environment variables."""
    values = {v for v in extra if v and len(v) >= _MIN_LEN}
    for name, value in os.environ.items():
        if _SECRET_NAME.search(name) and value and len(value) >= _MIN_LEN:
            values.add(value)
    return sorted(values, key=len, reverse=True)


def scrub(text: str, secrets: Iterable[str]) -> str:
    """``text`` with every secret (and a ``Bearer <anything>`` token) replaced by ``***``."""
    for s in secrets:
        if s:
            text = text.replace(s, "***")
    return re.sub(r"(?i)(bearer\s+)[A-Za-z0-9._\-]{8,}", r"\1***", text)


class Scrubber:
    """Callable that scrubs a fixed set of secrets from text; its repr shows how many, never which."""

    __slots__ = ("_secrets",)

    def __init__(self, secrets: Iterable[str]) -> None:
        self._secrets = tuple(secrets)

    def __call__(self, text: str) -> str:
        return scrub(text, self._secrets)

    def __repr__(self) -> str:
        return f"Scrubber({len(self._secrets)} secrets)"

    def __reduce__(self):
        raise TypeError("Scrubber objects cannot be pickled")
