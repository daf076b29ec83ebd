"""User-facing errors: each carries one line that says what was wrong, what is allowed and how to fix it.

Every command module raises these and none imports the CLI, which only turns them into ``eb: error: ...``.
"""

from __future__ import annotations

__all__ = ["CliError", "ConfigError", "UserError"]


class UserError(Exception):
    """Bad input from the user; the message is one line for them (the CLI prints it and exits 2)."""


class CliError(UserError):
    """A command's arguments are wrong (unknown option, missing argument, not a run directory...)."""


class ConfigError(UserError, ValueError):
    """The config is invalid; the message is one line naming the key and what is allowed."""
