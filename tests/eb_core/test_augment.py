import numpy as np
import pytest

from eb_core.augment import DetectionBoxes
from eb_core.env import ObjectInfo, Observation


def _obs():
    img = np.zeros((60, 60, 3), np.uint8)
    return Observation(images={"rgb": img, "other": img.copy()}, primary="rgb", objects=[
        ObjectInfo(name="mug", box=(10, 20, 30, 40), is_target=True),
        ObjectInfo(name="plate", box=(35, 35, 55, 55)),
        ObjectInfo(name="hidden"),  # no box: not visible
    ])


def test_all_boxes_are_drawn_on_the_primary_image_only():
    obs = _obs()
    out = DetectionBoxes(mode="all", labels=False)(obs)
    img = out.images["rgb"]
    assert tuple(img[30, 10]) == (255, 32, 32) and tuple(img[45, 55]) == (255, 32, 32)
    assert img[25:35, 15:25].sum() == 0  # box interiors untouched
    assert out.images["other"].sum() == 0 and obs.images["rgb"].sum() == 0  # the input is not modified


def test_target_mode_draws_only_the_target():
    out = DetectionBoxes(mode="target", labels=False)(_obs())
    assert tuple(out.images["rgb"][30, 10]) == (255, 32, 32)
    assert out.images["rgb"][35:56, 35:56].sum() == 0


def test_labels_are_drawn_and_bad_mode_is_refused():
    out = DetectionBoxes(mode="all", labels=True)(_obs())
    assert out.images["rgb"][9:20, 10:30].sum() > 0
    with pytest.raises(ValueError, match="'all' or 'target'"):
        DetectionBoxes(mode="some")
