"""How much of an object the agent sees: its pixels in a small segmentation render of the first-person view.

Used by the task generator (is the target clearly in view at a start?) and by the audit probe that re-checks a
task file. Renders at :data:`VIS_SIZE` x :data:`VIS_SIZE`; keeps the compiled scenes of the last two rooms.
"""

from __future__ import annotations

from typing import Any

from eb_navigation.geometry import AgentState
from eb_navigation.room import NavRoom

__all__ = ["VIS_SIZE", "Visibility"]

VIS_SIZE = 128
"""Side of the segmentation image (pixels)."""


class Visibility:
    """Counts an object's pixels in the first-person view (low-resolution segmentation; two rooms kept)."""

    def __init__(self) -> None:
        self._scenes: list[tuple[NavRoom, Any]] = []

    def pixels(self, room: NavRoom, state: AgentState, obj_id: str) -> int:
        scene = next((sc for r, sc in self._scenes if r is room), None)
        if scene is None:
            from eb_navigation.scene import RoomScene

            scene = RoomScene(room, VIS_SIZE, VIS_SIZE)
            self._scenes.append((room, scene))
            if len(self._scenes) > 2:
                self._scenes.pop(0)[1].close()
        scene.set_agent(state)
        return int((scene.object_map() == room.index[obj_id]).sum())

    def close(self) -> None:
        for _, scene in self._scenes:
            scene.close()
        self._scenes.clear()
