"""A tiny, deterministic MJCF writer: elements with ordered attributes and fixed float formatting.

We write the XML ourselves (instead of ElementTree or MjSpec) so that the same inputs give the same string byte
for byte on every machine, which is what makes scenes and renders reproducible from a seed.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from xml.sax.saxutils import quoteattr

Vec = tuple[float, ...]


def fmt(x: float) -> str:
    """Format a number with at most 4 decimals and no trailing zeros (``-0`` becomes ``0``)."""
    s = f"{float(x):.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def fmt_attr(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return fmt(value)
    if isinstance(value, str):
        return value
    if isinstance(value, Iterable):
        return " ".join(fmt_attr(v) for v in value)
    raise TypeError(f"cannot write {value!r} as an MJCF attribute")


_NEEDS_ESCAPE = re.compile(r'[&<>"\n\r\t]')


def quote(value: str) -> str:
    """``quoteattr`` with a fast path for the usual case (numbers and names: nothing to escape); same output."""
    return f'"{value}"' if _NEEDS_ESCAPE.search(value) is None else quoteattr(value)


class El:
    """One MJCF element with attributes in insertion order and child elements."""

    __slots__ = ("tag", "attrs", "children")

    def __init__(self, tag: str, attrs: dict[str, object] | None = None) -> None:
        self.tag = tag
        self.attrs: dict[str, object] = {k: v for k, v in (attrs or {}).items() if v is not None}
        self.children: list[El] = []

    def add(self, tag: str, **attrs: object) -> El:
        """Append a child element (``class_`` is written as ``class``) and return it."""
        fixed = {("class" if k == "class_" else k): v for k, v in attrs.items()}
        child = El(tag, fixed)
        self.children.append(child)
        return child

    def append(self, child: El) -> El:
        self.children.append(child)
        return child

    def write(self, out: list[str], indent: int = 0) -> None:
        pad = "  " * indent
        attrs = "".join(f" {k}={quote(fmt_attr(v))}" for k, v in self.attrs.items())
        if not self.children:
            out.append(f"{pad}<{self.tag}{attrs}/>")
            return
        out.append(f"{pad}<{self.tag}{attrs}>")
        for child in self.children:
            child.write(out, indent + 1)
        out.append(f"{pad}</{self.tag}>")

    def to_string(self, indent: int = 0) -> str:
        out: list[str] = []
        self.write(out, indent)
        return "\n".join(out)
