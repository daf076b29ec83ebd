"""The discrete action conventions of the paper."""

from __future__ import annotations

import numpy as np
import pytest

from eb_manipulation.actions import (
    ACTION_SPACE,
    angle_to_bin,
    bin_to_angle,
    bin_to_pos,
    euler_to_matrix,
    matrix_to_euler,
    pos_to_bin,
)


def test_position_bins_are_centres_of_100_bins() -> None:
    assert bin_to_pos(0, "x") == pytest.approx(-0.3 + 0.005)
    assert bin_to_pos(99, "y") == pytest.approx(0.5 - 0.005)
    assert bin_to_pos(50, "z") == pytest.approx(0.6 + 50.5 * 0.01)
    for axis in "xyz":
        for i in (0, 7, 42, 99):
            assert pos_to_bin(bin_to_pos(i, axis), axis) == i


def test_angle_bins_are_3_degrees_from_minus_180() -> None:
    assert bin_to_angle(0) == -180 and bin_to_angle(60) == 0 and bin_to_angle(120) == 180
    assert angle_to_bin(-90) == 30 and angle_to_bin(45) == 75


def test_top_down_orientation() -> None:
    R = euler_to_matrix(bin_to_angle(120), bin_to_angle(60), bin_to_angle(60))
    assert np.allclose(R[:, 2], [0, 0, -1])  # approach axis points down
    assert np.allclose(abs(R[:, 1] @ [0, 1, 0]), 1)  # fingers close along y
    R90 = euler_to_matrix(180, 0, 90)
    assert np.allclose(abs(R90[:, 1] @ [1, 0, 0]), 1)  # yaw 90: along x


def test_euler_round_trip() -> None:
    for r, p, y in [(10, 20, 30), (-170, 5, 100), (180, 0, -45)]:
        R = euler_to_matrix(r, p, y)
        assert np.allclose(euler_to_matrix(*matrix_to_euler(R)), R)


def test_space_bounds() -> None:
    assert ACTION_SPACE.parse_plan_item({"action": [100, 0, 50, 120, 0, 60, 1]}) == (100, 0, 50, 120, 0, 60, 1)
    with pytest.raises(ValueError):
        ACTION_SPACE.parse_plan_item({"action": [101, 0, 50, 120, 0, 60, 1]})
    with pytest.raises(ValueError):
        ACTION_SPACE.parse_plan_item({"action": [1, 0, 50, 120, 0, 60, 2]})
