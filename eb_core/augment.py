"""Observation augmenters: composable transforms applied before the planner sees an observation.

Subclass :class:`Augmenter` and override :meth:`transform` (the Gymnasium ``ObservationWrapper`` idea).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from PIL import Image, ImageDraw

from eb_core.env import Observation

__all__ = ["Augmenter", "DetectionBoxes"]


class Augmenter:
    """Base class. Constructed with the augmenter's config keys (everything but ``name``)."""

    def transform(self, obs: Observation) -> Observation:  # pragma: no cover - abstract
        raise NotImplementedError

    def __call__(self, obs: Observation) -> Observation:
        return self.transform(obs)


class DetectionBoxes(Augmenter):
    """Draw ground-truth 2-D boxes from ``obs.objects`` on the primary image (the paper's detection-box ablation).

    ``mode="all"`` draws every object with a box; ``mode="target"`` only the task's target(s).
    """

    def __init__(self, mode: Literal["all", "target"] = "all", color: tuple[int, int, int] = (255, 32, 32),
                 width: int = 2, labels: bool = True) -> None:
        if mode not in ("all", "target"):
            raise ValueError(f"detection_boxes mode must be 'all' or 'target', got {mode!r}")
        self.mode, self.color, self.width, self.labels = mode, tuple(color), int(width), labels

    def transform(self, obs: Observation) -> Observation:
        key, img = obs.primary, obs.primary_image
        if key is None or img is None:
            return obs
        pil = Image.fromarray(np.ascontiguousarray(img))
        draw = ImageDraw.Draw(pil)
        for obj in obs.objects:
            if obj.box is None or (self.mode == "target" and not obj.is_target):
                continue
            draw.rectangle(obj.box, outline=self.color, width=self.width)
            if self.labels:
                text = obj.label or obj.name
                x0, y0 = obj.box[0], max(0, obj.box[1] - 11)
                draw.rectangle((x0, y0, x0 + 6 * len(text) + 2, y0 + 10), fill=self.color)
                draw.text((x0 + 1, y0 - 1), text, fill=(255, 255, 255))
        images = dict(obs.images)
        images[key] = np.asarray(pil)
        return obs.model_copy(update={"images": images})
