"""Left-right mirrored versions of kit furniture, so a door can open away from its neighbours in the kitchen row.

The scene kit's fridge and cabinet are hinged on their left side (seen from the front), so their doors swing to
the left. Where such a piece stands right of the sink (``eb_habitat.catalog.KITCHEN_ROWS``), its open door would
cover the counter beside it; the renderer uses the mirrored type there. A mirrored type draws the kit's own
builder through a writer that flips every local y coordinate (and hinge axis), and is registered with the
apartment's ``SceneBuilder`` (``register_type``), never with the kit's catalogue.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from eb_scenekit.objects import ObjectType, get_type

__all__ = ["MIRRORED", "mirrored_type"]

MIRRORED = "Mirrored"
"""Suffix of a mirrored type's name (``FridgeMirrored``)."""


def _flip(v: tuple[float, float, float]) -> tuple[float, float, float]:
    return (v[0], -v[1], v[2])


class _MirrorY:
    """A :class:`eb_scenekit.Parts` writer seen in a mirror: local y -> -y."""

    def __init__(self, parts: Any) -> None:
        self._parts = parts

    @staticmethod
    def _kw(kw: dict[str, Any]) -> dict[str, Any]:
        if "xyaxes" in kw:
            raise ValueError("mirrored types do not support xyaxes frames")
        if kw.get("rot") is not None:
            roll, pitch, yaw = kw["rot"]
            kw = {**kw, "rot": (-roll, pitch, -yaw)}
        return kw

    def box(self, part: str, half: Any, pos: Any, *a: Any, **kw: Any) -> Any:
        return self._parts.box(part, half, _flip(pos), *a, **self._kw(kw))

    def cyl(self, part: str, r: float, hh: float, pos: Any, *a: Any, **kw: Any) -> Any:
        return self._parts.cyl(part, r, hh, _flip(pos), *a, **self._kw(kw))

    def sph(self, part: str, r: float, pos: Any, *a: Any, **kw: Any) -> Any:
        return self._parts.sph(part, r, _flip(pos), *a, **self._kw(kw))

    def ell(self, part: str, radii: Any, pos: Any, *a: Any, **kw: Any) -> Any:
        return self._parts.ell(part, radii, _flip(pos), *a, **self._kw(kw))

    def cap_ft(self, part: str, p0: Any, p1: Any, *a: Any, **kw: Any) -> Any:
        return self._parts.cap_ft(part, _flip(p0), _flip(p1), *a, **self._kw(kw))

    def cyl_ft(self, part: str, p0: Any, p1: Any, *a: Any, **kw: Any) -> Any:
        return self._parts.cyl_ft(part, _flip(p0), _flip(p1), *a, **self._kw(kw))

    def hinge(self, part: str, pos: Any, axis: Any, max_deg: float) -> _MirrorY:
        # An axis is a pseudo-vector: under a mirror it flips sign and then reflects.
        return _MirrorY(self._parts.hinge(part, _flip(pos), (-axis[0], axis[1], -axis[2]), max_deg))

    def __getattr__(self, name: str) -> Any:
        raise AttributeError(f"mirrored kit types cannot use Parts.{name}; add it to eb_habitat._mirror")


_CACHE: dict[str, ObjectType] = {}


def mirrored_type(kit_name: str) -> ObjectType:
    """The kit type ``kit_name`` mirrored left to right, named ``<kit_name>Mirrored`` (surfaces are symmetric
    in the kit's fridge and cabinet, so they are kept)."""
    if kit_name not in _CACHE:
        base = get_type(kit_name)
        for s in base.surfaces:
            if abs(s.center[1]) > 1e-9:
                raise ValueError(f"{kit_name}: surface {s.name!r} is off-centre; mirror its offset too")

        def build(p: Any, c: Any, _b: Any = base.builder) -> None:
            _b(_MirrorY(p), c)

        _CACHE[kit_name] = dataclasses.replace(base, name=kit_name + MIRRORED, builder=build)
    return _CACHE[kit_name]
