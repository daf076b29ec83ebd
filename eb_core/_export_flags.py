"""The flags of ``eb export``'s extra formats (``--format matrix``, ``--format video``), parsed one way."""

from __future__ import annotations

from collections.abc import Sequence


class FlagError(ValueError):
    """A bad ``eb export`` argument (one line)."""


def parse_flags(args: Sequence[str], *, fmt: str, switches: Sequence[str] = ("--overwrite",),
                values: Sequence[str] = ("--out",)) -> tuple[list[str], dict[str, object]]:
    """``(run directories, {flag: value})``: ``--format`` is skipped, ``values`` take the next word or ``=value``,
    ``switches`` are booleans; any other ``-...`` is an error naming the format."""
    runs: list[str] = []
    opts: dict[str, object] = {s: False for s in switches}
    opts.update({v: None for v in values})
    it = iter(args)
    for a in it:
        key, eq, val = a.partition("=")
        if key == "--format":
            if not eq:
                next(it, "")
        elif key in values:
            opts[key] = val if eq else next(it, "")
        elif a in switches:
            opts[a] = True
        elif a.startswith("-"):
            raise FlagError(f"unknown option {a!r} for --format {fmt}")
        else:
            runs.append(a)
    return runs, opts
