"""Procedural rooms: deterministic, furnished, inside the walls, no overlapping furniture."""

from __future__ import annotations

import pytest

from eb_navigation.catalogue import CATALOGUE, TARGET_TYPES
from eb_navigation.geometry import FreeSpace
from eb_navigation.layout import KINDS, generate_layout
from eb_navigation.mjcf import layout_to_mjcf


@pytest.mark.parametrize("kind", KINDS)
def test_rooms_are_deterministic_and_sane(kind: str) -> None:
    for seed in range(6):
        a, b = generate_layout(kind, seed), generate_layout(kind, seed)
        assert a == b
        assert len(a.objects) >= 5
        ids = [o.id for o in a.objects]
        assert len(ids) == len(set(ids))
        solid = [o for o in a.objects if o.obstacle]
        for o in a.objects:
            x0, y0, x1, y1 = o.footprint
            assert -1e-6 <= x0 and x1 <= a.width + 1e-6 and -1e-6 <= y0 and y1 <= a.depth + 1e-6, o
        for i, p in enumerate(solid):
            for q in solid[i + 1:]:
                px0, py0, px1, py1 = p.footprint
                qx0, qy0, qx1, qy1 = q.footprint
                assert not (px0 < qx1 - 1e-6 and qx0 < px1 - 1e-6 and py0 < qy1 - 1e-6 and qy0 < py1 - 1e-6), (p, q)
        assert any(o.type in TARGET_TYPES for o in a.objects)
        assert FreeSpace(a).free_cells().sum() > 40, "the agent needs room to walk"


def test_different_seeds_differ() -> None:
    rooms = {generate_layout("kitchen", s) for s in range(10)}
    assert len(rooms) == 10


def test_every_catalogue_type_builds_and_compiles() -> None:
    from eb_navigation._gl import mujoco
    from eb_navigation.layout import Layout, Placed

    objs = tuple(Placed(f"{t}_1", t, CATALOGUE[t].colours[0], 1.0 + 2.5 * (k % 6), 1.5 + 2.5 * (k // 6))
                 for k, t in enumerate(CATALOGUE))
    lay = Layout("living_room", 0, 16.0, 16.0, (0.9, 0.9, 0.9), ("tiles", (1, 1, 1), (0.5, 0.5, 0.5)), objs)
    model = mujoco.MjModel.from_xml_string(layout_to_mjcf(lay, 64))
    assert model.nbody >= len(objs) + 2


def test_unknown_kind_is_named() -> None:
    with pytest.raises(ValueError, match="unknown room kind 'garage'"):
        generate_layout("garage", 0)
