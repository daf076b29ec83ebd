"""The paper's discrete 7-D action ``[x, y, z, roll, pitch, yaw, gripper]`` and its conversions.

Positions use 100 bins per axis over the workspace box x in [-0.3, 0.7], y in [-0.5, 0.5], z in [0.6, 1.6]
(metres, world frame; the table top is at z = 0.752). Bin ``i`` means the bin centre
``min + (i + 0.5) * range / 100``; index 100 (allowed by the action space) is the far edge clamped to the
last bin. Angles use 120 bins of 3 degrees: ``angle = i * 3 - 180``. Gripper: 1 open, 0 closed.

Orientation is extrinsic roll-pitch-yaw about the world x, y, z axes (``R = Rz(yaw) Ry(pitch) Rx(roll)``)
of the gripper frame, whose z axis points out of the fingers and whose y axis is the direction the
fingers close along. ``roll = 180 deg, pitch = 0, yaw = 0`` (bins 120 or 0, 60, 60) points the gripper
straight down with the fingers closing along the world y axis; yaw turns it about the vertical.
"""

from __future__ import annotations

import math

import numpy as np

from eb_core.env import VectorActionSpace

__all__ = [
    "ACTION_SPACE",
    "ANGLE_BINS",
    "POS_BINS",
    "WORKSPACE",
    "angle_to_bin",
    "bin_to_angle",
    "bin_to_pos",
    "euler_to_matrix",
    "matrix_to_euler",
    "pos_to_bin",
]

WORKSPACE: dict[str, tuple[float, float]] = {"x": (-0.3, 0.7), "y": (-0.5, 0.5), "z": (0.6, 1.6)}
POS_BINS = 100
ANGLE_BINS = 120
ANGLE_STEP = 360.0 / ANGLE_BINS

ACTION_SPACE = VectorActionSpace(
    names=("x", "y", "z", "roll", "pitch", "yaw", "gripper"),
    low=(0,) * 7,
    high=(100, 100, 100, 120, 120, 120, 1),
)


def bin_to_pos(index: int, axis: str) -> float:
    """Centre of position bin ``index`` on ``axis`` (``"x"``, ``"y"`` or ``"z"``), in metres."""
    lo, hi = WORKSPACE[axis]
    i = min(max(int(index), 0), POS_BINS - 1)
    return lo + (i + 0.5) * (hi - lo) / POS_BINS


def pos_to_bin(value: float, axis: str) -> int:
    """The bin that contains ``value`` (clamped to 0..99)."""
    lo, hi = WORKSPACE[axis]
    i = int(math.floor((value - lo) / (hi - lo) * POS_BINS + 1e-9))
    return min(max(i, 0), POS_BINS - 1)


def bin_to_angle(index: int) -> float:
    """Angle in degrees of rotation bin ``index``."""
    return int(index) * ANGLE_STEP - 180.0


def angle_to_bin(degrees: float) -> int:
    """The nearest rotation bin for an angle in degrees (wrapped into [-180, 180])."""
    a = (degrees + 180.0) % 360.0 - 180.0
    return min(max(int(round((a + 180.0) / ANGLE_STEP)), 0), ANGLE_BINS)


def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def euler_to_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rotation matrix for extrinsic x-y-z angles in degrees."""
    return _rz(math.radians(yaw)) @ _ry(math.radians(pitch)) @ _rx(math.radians(roll))


def matrix_to_euler(R: np.ndarray) -> tuple[float, float, float]:
    """Inverse of :func:`euler_to_matrix` (degrees; pitch in [-90, 90])."""
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    if abs(R[2, 0]) < 0.999999:
        roll = math.atan2(R[2, 1], R[2, 2])
        yaw = math.atan2(R[1, 0], R[0, 0])
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = math.atan2(-R[0, 1], R[1, 1])
    return math.degrees(roll), math.degrees(pitch), math.degrees(yaw)
