"""Number tags that hide nothing: the "clear" box layout of the harder task sets.

The classic overlay (:func:`eb_manipulation.render.draw_boxes`) puts every tag above its box's top-left corner, where
it can cover a neighbour: a hole outline behind it on the sorter's lid, or a shape left lying there. In the clear
layout each tag goes where it covers the smallest share of any listed object's visible pixels (MuJoCo's
segmentation, the same pass that gives the boxes), never onto another tag and preferably outside the other boxes;
a tag that does not touch its own box is tied to it by a thin leader line. The classic images keep the old layout
(the paper's protocol), so their pixels do not change.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from eb_manipulation.render import BOX_COLOURS, BOX_EDGE, _font

__all__ = ["TagPlacement", "draw_clear_boxes", "place_tags"]

Box = tuple[int, int, int, int]
TagPlacement = tuple[str, Box, tuple[int, int, int, int] | None]
"""(label, tag rectangle (x0, y0, x1, y1) inclusive, leader line (x0, y0, x1, y1) or None)."""

#: How much a tag pixel inside another object's box costs, against covering an object's whole visible area (1.0):
#: a tag sitting in another box reads as that box's number.
IN_OTHER_BOX = 0.002
#: Cost of a tag that lies as close to another box as to its own (or, with a leader line, within
#: :data:`NEAR` pixels of another box): it could be read as that box's tag.
NEAR_OTHER = 0.3
NEAR = 5
#: Cost per pixel of leader line (a tag near its box is easier to match to it).
LEADER = 0.0015
#: Offsets (pixels) of the tag positions further out, tied to the box by a leader line.
OFFSETS = (8, 16, 26, 38)
#: An object counts with at least this many visible pixels when its covered share is computed (a sliver of a few
#: pixels would otherwise make every tag near it look expensive).
MIN_PIXELS = 40


def _integral(a: np.ndarray) -> np.ndarray:
    out = np.zeros((a.shape[0] + 1, a.shape[1] + 1), dtype=np.float64)
    out[1:, 1:] = a.cumsum(0).cumsum(1)
    return out


def _rect_sum(ii: np.ndarray, x0: int, y0: int, x1: int, y1: int) -> float:
    """Sum over the inclusive rectangle (clipped to the image)."""
    h, w = ii.shape[0] - 1, ii.shape[1] - 1
    x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w - 1), min(y1, h - 1)
    if x1 < x0 or y1 < y0:
        return 0.0
    return float(ii[y1 + 1, x1 + 1] - ii[y0, x1 + 1] - ii[y1 + 1, x0] + ii[y0, x0])


def _overlap(a: Box, b: Box) -> int:
    """Pixels in both inclusive rectangles."""
    return max(0, min(a[2], b[2]) - max(a[0], b[0]) + 1) * max(0, min(a[3], b[3]) - max(a[1], b[1]) + 1)


def _gap(a: Box, b: Box) -> int:
    """Pixels between two inclusive rectangles along the axis where they are furthest apart (0: touching)."""
    return max(0, max(b[0] - a[2], a[0] - b[2], b[1] - a[3], a[1] - b[3]) - 1)


def _candidates(box: Box, tw: int, th: int) -> list[tuple[int, int, bool]]:
    """Top-left corners of the tag around ``box``, the classic spot first: (x, y, needs a leader line)."""
    x0, y0, x1, y1 = box
    above, below = y0 - th - 1, y1 + 2
    left, right = x0 - tw - 2, x1 + 2
    out = [(x0 - 1, above, False), (x1 + 1 - tw, above, False), (x0 - 1, below, False), (x1 + 1 - tw, below, False),
           (left, y0 - 1, False), (right, y0 - 1, False), (left, y1 + 1 - th, False), (right, y1 + 1 - th, False)]
    cx, cy = (x0 + x1 - tw) // 2, (y0 + y1 - th) // 2
    for d in OFFSETS:
        out += [(x0 - 1, above - d, True), (x1 + 1 - tw, above - d, True), (cx, above - d, True),
                (x0 - 1, below + d, True), (x1 + 1 - tw, below + d, True), (cx, below + d, True),
                (left - d, y0 - 1, True), (left - d, cy, True), (left - d, y1 + 1 - th, True),
                (right + d, y0 - 1, True), (right + d, cy, True), (right + d, y1 + 1 - th, True),
                (left - d, above - d, True), (right + d, above - d, True),
                (left - d, below + d, True), (right + d, below + d, True)]
    return out


def _leader(box: Box, tag: Box) -> tuple[int, int, int, int]:
    """A line from the tag's edge to the nearest point of the box outline."""
    bx0, by0, bx1, by1 = box
    tx0, ty0, tx1, ty1 = tag
    tcx, tcy = (tx0 + tx1) // 2, (ty0 + ty1) // 2
    px, py = min(max(tcx, bx0 - 1), bx1 + 1), min(max(tcy, by0 - 1), by1 + 1)
    qx, qy = min(max(px, tx0), tx1), min(max(py, ty0), ty1)
    return qx, qy, px, py


def _line_cost(cost_map: np.ndarray, line: tuple[int, int, int, int]) -> float:
    x0, y0, x1, y1 = line
    n = max(abs(x1 - x0), abs(y1 - y0)) + 1
    xs = np.clip(np.rint(np.linspace(x0, x1, n)).astype(int), 0, cost_map.shape[1] - 1)
    ys = np.clip(np.rint(np.linspace(y0, y1, n)).astype(int), 0, cost_map.shape[0] - 1)
    return float(cost_map[ys, xs].sum())


def place_tags(boxes: list[tuple[str, Box]], pixels: np.ndarray, tag_size: dict[str, tuple[int, int]],
               extra_pixels: np.ndarray | None = None) -> list[TagPlacement]:
    """Where each box's tag goes.

    Args:
        boxes: (label, box) per tagged object, in drawing order.
        pixels: (H, W) int array: per pixel the index into ``boxes`` of the object seen there, -1 for none.
        tag_size: (width, height) of each label's tag.
        extra_pixels: (H, W) int array of further objects to keep clear (-1 for none), e.g. untagged ones.

    A tag's cost is the share of each object's visible pixels it covers (summed), a small cost per pixel inside
    another object's box and per pixel of leader line; it never overlaps a placed tag or leaves the image. The
    most constrained tags (highest best cost when alone) are placed first.
    """
    h, w = pixels.shape
    ids = [pixels] + ([extra_pixels] if extra_pixels is not None else [])
    share = np.zeros((h, w), dtype=np.float64)
    for arr in ids:
        flat = arr.ravel()
        counts = np.bincount(flat[flat >= 0], minlength=int(flat.max(initial=-1)) + 1)
        weight = 1.0 / np.maximum(counts, MIN_PIXELS)
        share += np.where(arr >= 0, weight[np.maximum(arr, 0)] if len(weight) else 0.0, 0.0)
    share_ii = _integral(share)
    grown = [(x0 - 2, y0 - 2, x1 + 2, y1 + 2) for _, (x0, y0, x1, y1) in boxes]

    def cost(i: int, cand: tuple[int, int, bool], taken: list[Box]) -> tuple[float, Box, tuple | None] | None:
        label, box = boxes[i]
        tw, th = tag_size[label]
        x, y, lead = cand
        rect = (x, y, x + tw - 1, y + th - 1)
        if x < 0 or y < 0 or rect[2] >= w or rect[3] >= h:
            return None
        for t in taken:
            if not (rect[2] + 2 < t[0] or t[2] + 2 < rect[0] or rect[3] + 2 < t[1] or t[3] + 2 < rect[1]):
                return None
        c = _rect_sum(share_ii, *rect)
        c += IN_OTHER_BOX * sum(_overlap(rect, g) for j, g in enumerate(grown) if j != i)
        own = 0 if lead else _gap(rect, box)
        if any(_gap(rect, other) <= own + NEAR for j, (_, other) in enumerate(boxes) if j != i):
            c += NEAR_OTHER
        line = _leader(box, rect) if lead else None
        if line is not None:
            c += _line_cost(share, line) + LEADER * max(abs(line[2] - line[0]), abs(line[3] - line[1]))
        return round(c, 6), rect, line  # the integral image's float noise must not break ties

    cands = [_candidates(box, *tag_size[label]) for label, box in boxes]
    alone = []
    for i in range(len(boxes)):
        best = [r[0] for r in (cost(i, c, []) for c in cands[i]) if r is not None]
        alone.append(min(best) if best else 0.0)
    order = sorted(range(len(boxes)), key=lambda i: -alone[i])
    placed: dict[int, TagPlacement] = {}
    taken: list[Box] = []
    for i in order:
        label, box = boxes[i]
        options = [r for r in (cost(i, c, taken) for c in cands[i]) if r is not None]
        if not options:  # nowhere free: the classic spot, clipped into the image
            tw, th = tag_size[label]
            x, y = min(max(box[0] - 1, 0), w - tw), min(max(box[1] - th - 1, 0), h - th)
            options = [(0.0, (x, y, x + tw - 1, y + th - 1), None)]
        _, rect, line = min(options, key=lambda r: r[0])  # min keeps the first of equal costs: the classic spot
        placed[i] = (label, rect, line)
        taken.append(rect)
    return [placed[i] for i in range(len(boxes))]


def draw_clear_boxes(img: Image.Image, boxes: list[tuple[str, Box]], pixels: np.ndarray,
                     extra_pixels: np.ndarray | None = None) -> list[TagPlacement]:
    """Detection boxes with tags placed by :func:`place_tags`; returns the placements (tag rectangles, leaders).

    Same box and tag style as :func:`eb_manipulation.render.draw_boxes` (white with a thin dark edge)."""
    draw = ImageDraw.Draw(img)
    size = img.size[0]
    width = max(1, size // 250)
    font = _font(max(10, size // 34))
    pad = 2
    tag_size, offsets = {}, {}
    for label, _ in boxes:
        tb = draw.textbbox((0, 0), label, font=font)
        tag_size[label] = (tb[2] - tb[0] + 2 * pad + 1, tb[3] - tb[1] + 2 * pad + 1)
        offsets[label] = (pad - tb[0], pad - tb[1])
    placements = place_tags(boxes, pixels, tag_size, extra_pixels)
    colour = BOX_COLOURS[0]
    for _, (x0, y0, x1, y1) in boxes:
        draw.rectangle([x0 - 1 - width, y0 - 1 - width, x1 + 1 + width, y1 + 1 + width], outline=BOX_EDGE, width=1)
        draw.rectangle([x0 - 1, y0 - 1, x1 + 1, y1 + 1], outline=colour, width=width)
    for _, _, line in placements:
        if line is not None:
            draw.line(line, fill=BOX_EDGE, width=3)
            draw.line(line, fill=colour, width=1)
    for label, (x0, y0, x1, y1), _ in placements:
        draw.rectangle([x0, y0, x1, y1], fill=colour, outline=BOX_EDGE)
        ox, oy = offsets[label]
        draw.text((x0 + ox, y0 + oy), label, fill=(0, 0, 0), font=font)
    return placements
