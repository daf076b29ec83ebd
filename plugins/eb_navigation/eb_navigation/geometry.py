"""The agent's moves on the floor, collisions, success and the oracle planner (pure Python + numpy).

The agent is a disc of radius :data:`AGENT_RADIUS` whose centre lives on a lattice of
:data:`STEP` metres (moves are exactly one step along a heading that is a multiple of 90 degrees, so
positions never leave the lattice). Collisions are read from the scene kit's occupancy grid of the room.
The environment and the oracle use the same :class:`FreeSpace`, so the oracle's plans never collide and its
collision feedback matches the env's exactly.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace

import numpy as np

__all__ = [
    "ACTION_NAMES",
    "AGENT_RADIUS",
    "EYE_HEIGHT",
    "FIRST_PERSON_FOVY",
    "HEADING_VECTORS",
    "STEP",
    "SUCCESS_DISTANCE",
    "TILT_MAX",
    "TILT_MIN",
    "TILT_STEP",
    "GRID_RESOLUTION",
    "AgentState",
    "FreeSpace",
]

STEP = 0.25
"""Metres per move."""
AGENT_RADIUS = 0.2
"""Radius of the agent's footprint (collisions with furniture and walls)."""
EYE_HEIGHT = 1.5
"""Camera height above the floor: a person's eye height."""
FIRST_PERSON_FOVY = 100.0
"""Field of view of the square first-person image in degrees, vertical = horizontal (the original benchmark's
camera has a 100 degree field of view)."""
SUCCESS_DISTANCE = 1.0
"""The task is solved when the agent's centre is this close (horizontally) to the target's centre."""
GRID_RESOLUTION = 0.05
"""Cell size of the scene kit's occupancy grid the collision checks read (metres)."""
TILT_STEP = 30
TILT_MIN = -60
TILT_MAX = 30
"""Camera tilt range in degrees (negative looks down)."""

#: Action ids 0..7 (our wording; the paper's order).
ACTION_NAMES: tuple[str, ...] = (
    "Move forward by 0.25 meters",
    "Move backward by 0.25 meters",
    "Move sideways to the right by 0.25 meters",
    "Move sideways to the left by 0.25 meters",
    "Turn right by 90 degrees",
    "Turn left by 90 degrees",
    "Tilt the camera up by 30 degrees",
    "Tilt the camera down by 30 degrees",
)

#: Unit lattice steps per heading: 0 = +x (east), 1 = +y (north), 2 = -x, 3 = -y.
HEADING_VECTORS = ((1, 0), (0, 1), (-1, 0), (0, -1))


@dataclass(frozen=True)
class AgentState:
    """Where the agent is: lattice point ``(i, j)`` (metres = ``STEP * (i, j)`` in the room's frame, whose origin
    is the room's centre), heading, camera tilt."""

    i: int
    j: int
    heading: int
    """Quarter turns counter-clockwise from +x."""
    tilt: int = 0
    """Degrees, positive looks up."""

    @property
    def x(self) -> float:
        return self.i * STEP

    @property
    def y(self) -> float:
        return self.j * STEP

    @property
    def yaw_deg(self) -> int:
        return self.heading % 4 * 90

    @classmethod
    def from_pose(cls, x: float, y: float, yaw_deg: float, tilt: int = 0) -> "AgentState":
        i, j = round(x / STEP), round(y / STEP)
        if abs(i * STEP - x) > 1e-6 or abs(j * STEP - y) > 1e-6:
            raise ValueError(f"start position ({x}, {y}) is not on the {STEP} m grid")
        if yaw_deg % 90:
            raise ValueError(f"start yaw {yaw_deg} is not a multiple of 90 degrees")
        return cls(i, j, int(yaw_deg // 90) % 4, int(tilt))


def _move_delta(heading: int, action: int) -> tuple[int, int]:
    offset = {0: 0, 1: 2, 2: -1, 3: 1}[action]  # forward, backward, right, left
    return HEADING_VECTORS[(heading + offset) % 4]


class FreeSpace:
    """Which lattice points the agent may stand on and which moves between them are clear.

    Built from the scene kit's occupancy grid (:meth:`eb_scenekit.rooms.RoomLayout.free_space`: True where a
    disc of the agent's radius fits on the floor). A lattice point ``(i, j)`` sits at ``(i * STEP, j * STEP)``
    in the room's frame (the room is centred on the origin); a move is clear when every grid cell under the
    straight segment between its two lattice points (sampled every ``resolution`` metres) is free.
    """

    def __init__(self, grid: np.ndarray, size: tuple[float, float], resolution: float) -> None:
        self.grid = np.asarray(grid, dtype=bool)
        self.size = (float(size[0]), float(size[1]))
        self.resolution = float(resolution)
        hx, hy = self.size[0] / 2, self.size[1] / 2
        self.i0, self.j0 = math.ceil(-hx / STEP - 1e-9), math.ceil(-hy / STEP - 1e-9)
        i1, j1 = math.floor(hx / STEP + 1e-9), math.floor(hy / STEP + 1e-9)
        self.ni, self.nj = i1 - self.i0 + 1, j1 - self.j0 + 1
        ii, jj = np.meshgrid(np.arange(self.ni) + self.i0, np.arange(self.nj) + self.j0, indexing="ij")
        x, y = ii * STEP, jj * STEP
        self._point = self._free_at(x, y)
        n = max(2, int(math.ceil(STEP / self.resolution)) + 1)
        east = np.ones_like(self._point)
        north = np.ones_like(self._point)
        for t in np.linspace(0.0, STEP, n):
            east &= self._free_at(x + t, y)
            north &= self._free_at(x, y + t)
        east[-1, :] = False
        north[:, -1] = False
        self._east, self._north = east, north

    @classmethod
    def from_layout(cls, layout, resolution: float = GRID_RESOLUTION, radius: float = AGENT_RADIUS) -> "FreeSpace":
        """The free space of a scene kit :class:`~eb_scenekit.rooms.RoomLayout` (every object it holds now)."""
        return cls(layout.free_space(resolution, radius), layout.size, resolution)

    def _free_at(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        gi = np.floor((x + self.size[0] / 2) / self.resolution + 1e-9).astype(int)
        gj = np.floor((y + self.size[1] / 2) / self.resolution + 1e-9).astype(int)
        inside = (gi >= 0) & (gi < self.grid.shape[0]) & (gj >= 0) & (gj < self.grid.shape[1])
        out = np.zeros(np.shape(x), dtype=bool)
        out[inside] = self.grid[gi[inside], gj[inside]]
        return out

    def _inside(self, a: int, b: int) -> bool:
        return 0 <= a < self.ni and 0 <= b < self.nj

    def is_free(self, i: int, j: int) -> bool:
        a, b = i - self.i0, j - self.j0
        return self._inside(a, b) and bool(self._point[a, b])

    def free_cells(self) -> list[tuple[int, int]]:
        """Every free lattice point ``(i, j)``."""
        aa, bb = np.nonzero(self._point)
        return [(int(a) + self.i0, int(b) + self.j0) for a, b in zip(aa, bb)]

    def can_move(self, i: int, j: int, di: int, dj: int) -> bool:
        """Whether one step from ``(i, j)`` by ``(di, dj)`` (a unit lattice step) is clear."""
        a, b = i - self.i0, j - self.j0
        if di < 0 or dj < 0:
            a, b = a + di, b + dj
        if not self._inside(a, b):
            return False
        return bool(self._east[a, b] if di else self._north[a, b])

    def apply(self, s: AgentState, action: int) -> tuple[AgentState, bool, str]:
        """The state after ``action``, whether it succeeded and, if not, why (our wording)."""
        if action in (0, 1, 2, 3):
            di, dj = _move_delta(s.heading, action)
            if not self.can_move(s.i, s.j, di, dj):
                return s, False, "blocked"
            return replace(s, i=s.i + di, j=s.j + dj), True, ""
        if action == 4:
            return replace(s, heading=(s.heading - 1) % 4), True, ""
        if action == 5:
            return replace(s, heading=(s.heading + 1) % 4), True, ""
        if action == 6:
            if s.tilt + TILT_STEP > TILT_MAX:
                return s, False, "tilt_max"
            return replace(s, tilt=s.tilt + TILT_STEP), True, ""
        if action == 7:
            if s.tilt - TILT_STEP < TILT_MIN:
                return s, False, "tilt_min"
            return replace(s, tilt=s.tilt - TILT_STEP), True, ""
        raise ValueError(f"action id {action} is out of range 0..7")

    def free_ahead(self, s: AgentState, limit: int = 40) -> int:
        """How many forward moves are possible in a row from ``s``."""
        di, dj = HEADING_VECTORS[s.heading % 4]
        n, i, j = 0, s.i, s.j
        while n < limit and self.can_move(i, j, di, dj):
            i, j, n = i + di, j + dj, n + 1
        return n

    # -- the oracle ------------------------------------------------------------------------------------

    def goal_cells(self, target_xy: tuple[float, float], distance: float = SUCCESS_DISTANCE) -> np.ndarray:
        """Boolean array over lattice points (offset by ``i0, j0``): free and within ``distance`` of the target."""
        ii, jj = np.meshgrid(np.arange(self.ni) + self.i0, np.arange(self.nj) + self.j0, indexing="ij")
        d2 = (ii * STEP - target_xy[0]) ** 2 + (jj * STEP - target_xy[1]) ** 2
        return (d2 <= distance * distance + 1e-9) & self._point

    def shortest_plan(self, s: AgentState, target_xy: tuple[float, float],
                      distance: float = SUCCESS_DISTANCE) -> list[int] | None:
        """Fewest actions (ids 0..5) from ``s`` to any free point within ``distance`` of the target.

        Breadth-first search over ``(i, j, heading)``; camera tilt does not matter for success. Returns
        ``[]`` when already there and None when no free point within reach is connected to the start.
        """
        goal = self.goal_cells(target_xy, distance)
        if not goal.any():
            return None
        if self._inside(s.i - self.i0, s.j - self.j0) and goal[s.i - self.i0, s.j - self.j0]:
            return []
        start = (s.i, s.j, s.heading % 4)
        parent: dict[tuple[int, int, int], tuple[tuple[int, int, int], int] | None] = {start: None}
        queue = deque([start])
        order = (0, 3, 2, 5, 4, 1)  # prefer walking forward, then side steps, then turning
        while queue:
            cur = queue.popleft()
            i, j, h = cur
            for a in order:
                if a <= 3:
                    di, dj = _move_delta(h, a)
                    if not self.can_move(i, j, di, dj):
                        continue
                    nxt = (i + di, j + dj, h)
                else:
                    nxt = (i, j, (h - 1) % 4 if a == 4 else (h + 1) % 4)
                if nxt in parent:
                    continue
                parent[nxt] = (cur, a)
                if a <= 3 and goal[nxt[0] - self.i0, nxt[1] - self.j0]:
                    plan = []
                    link = parent[nxt]
                    while link is not None:
                        node, act = link
                        plan.append(act)
                        link = parent[node]
                    return plan[::-1]
                queue.append(nxt)
        return None


def distance_to(s: AgentState, target_xy: tuple[float, float]) -> float:
    return math.hypot(s.x - target_xy[0], s.y - target_xy[1])


def bearing_to(s: AgentState, point_xy: tuple[float, float]) -> float:
    """Angle in degrees from the agent's heading to the point, positive to the left, in (-180, 180]."""
    ang = math.degrees(math.atan2(point_xy[1] - s.y, point_xy[0] - s.x)) - s.yaw_deg
    ang = (ang + 180.0) % 360.0 - 180.0
    return 180.0 if ang == -180.0 else ang
