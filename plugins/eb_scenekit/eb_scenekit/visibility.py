"""Which objects an image shows: counted from segmentation pixels, partial objects at the image edge included.

A world renders an instance-segmentation map of the camera the model looks through (any resolution: the
threshold is a share of the image) and maps it to its own object ids; :func:`objects_in_view` returns each object
with enough pixels to be seen, how many, the share of the image, its pixel box and whether it is cut by the
image border. The error labeller (``eb_core.errors``) judges descriptions against this list.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["MIN_COLOUR_SHARE", "MIN_FRACTION", "MIN_PIXELS", "Seen", "colours_in_view", "objects_in_view"]

MIN_FRACTION = 0.001
"""Smallest share of the image an object must cover to count as in view (250 pixels of a 500 x 500 image, a
16 x 16 patch: large enough for a person to see)."""

MIN_PIXELS = 4
"""And never fewer than this many pixels of the segmentation map (low-resolution maps)."""


@dataclass(frozen=True)
class Seen:
    """One object in view."""

    pixels: int
    """Its pixels in the segmentation map."""
    fraction: float
    """Its share of the image (0..1)."""
    box: tuple[int, int, int, int]
    """``(x0, y0, x1, y1)`` inclusive, in the segmentation map's pixels."""
    edge: bool
    """Cut by the image border: only part of it is in view."""


def objects_in_view(object_map: np.ndarray, min_fraction: float = MIN_FRACTION, min_pixels: int = MIN_PIXELS,
                    names: Sequence[str] | None = None) -> dict[int | str, Seen]:
    """Objects an ``(h, w)`` map of object ids shows (negative ids: walls, floor, nothing).

    Every id with at least ``max(min_pixels, min_fraction * h * w)`` pixels counts, wherever it is: an object
    filling the left side of the image with its middle out of view is in view. With ``names``, ids are indices
    into it and the result is keyed by name.
    """
    ids = np.asarray(object_map)
    h, w = ids.shape[:2]
    flat = ids.ravel()
    keep = flat >= 0
    if not keep.any():
        return {}
    counts = np.bincount(flat[keep])
    need = max(int(min_pixels), int(np.ceil(min_fraction * h * w)))
    out: dict[int | str, Seen] = {}
    for k in np.nonzero(counts >= need)[0]:
        mask = ids == k
        rows = np.flatnonzero(mask.any(axis=1))
        cols = np.flatnonzero(mask.any(axis=0))
        box = (int(cols[0]), int(rows[0]), int(cols[-1]), int(rows[-1]))
        edge = box[0] == 0 or box[1] == 0 or box[2] == w - 1 or box[3] == h - 1
        key: int | str = names[int(k)] if names is not None else int(k)
        out[key] = Seen(pixels=int(counts[k]), fraction=float(counts[k]) / (h * w), box=box, edge=edge)
    return out


#: Share of an object's pixels a colour family must cover to count as one of its colours.
MIN_COLOUR_SHARE = 0.12


def _family_of_pixels(rgb: np.ndarray) -> np.ndarray:
    """Colour family name of every pixel of an ``(n, 3)`` uint8 array (HSV thresholds; brown for dark oranges)."""
    x = rgb.astype(np.float32) / 255.0
    mx, mn = x.max(axis=1), x.min(axis=1)
    v, c = mx, mx - mn
    s = np.where(mx > 0, c / np.maximum(mx, 1e-6), 0.0)
    r, g, b = x[:, 0], x[:, 1], x[:, 2]
    cz = np.maximum(c, 1e-6)
    h = np.where(mx == r, ((g - b) / cz) % 6, np.where(mx == g, (b - r) / cz + 2, (r - g) / cz + 4)) * 60.0
    out = np.full(len(x), "grey", dtype=object)
    chroma = (s >= 0.22) & (v >= 0.18)
    out[~chroma & (v >= 0.78)] = "white"
    out[~chroma & (v < 0.22)] = "black"
    hue = np.select([h < 15, h < 45, h < 70, h < 165, h < 255, h < 290, h < 340, h >= 340],
                    ["red", "orange", "yellow", "green", "blue", "purple", "pink", "red"], "grey")
    brown = (h >= 10) & (h < 50) & (v < 0.7)
    out[chroma] = np.where(brown[chroma], "brown", hue[chroma])
    return out


def colours_in_view(rgb: np.ndarray, object_map: np.ndarray, keys: Sequence[int],
                    min_share: float = MIN_COLOUR_SHARE) -> dict[int, list[str]]:
    """Colour families (red, orange, yellow, green, blue, purple, pink, brown, white, grey, black) that cover at
    least ``min_share`` of each object's pixels in ``rgb``; ``object_map`` may be smaller than the image (it is
    sampled at the matching pixels)."""
    ids = np.asarray(object_map)
    h, w = ids.shape[:2]
    ys = np.minimum((np.arange(h) + 0.5) * rgb.shape[0] / h, rgb.shape[0] - 1).astype(int)
    xs = np.minimum((np.arange(w) + 0.5) * rgb.shape[1] / w, rgb.shape[1] - 1).astype(int)
    small = rgb[ys][:, xs]
    out: dict[int, list[str]] = {}
    for k in keys:
        mask = ids == k
        if not mask.any():
            continue
        fams, counts = np.unique(_family_of_pixels(small[mask]), return_counts=True)
        share = counts / counts.sum()
        out[int(k)] = [str(f) for f, sh in sorted(zip(fams, share), key=lambda t: -t[1]) if sh >= min_share]
    return out
