"""Box overlaps of ``pftrack.boxes``, one pair of boxes at a time."""

from __future__ import annotations

import numpy as np


def intersection_xywh(a, b):
    """(n, m) areas of the intersections of the ``left, top, width, height`` boxes of `a` and
    `b`."""
    out = np.zeros((len(a), len(b)))
    for i, (ax, ay, aw, ah) in enumerate(a):
        for j, (bx, by, bw, bh) in enumerate(b):
            iw = max(0.0, min(ax + aw, bx + bw) - max(ax, bx))
            ih = max(0.0, min(ay + ah, by + bh) - max(ay, by))
            out[i, j] = iw * ih
    return out


def iou_xywh(a, b):
    """(n, m) intersections over unions of the boxes of `a` and `b` (0 where the union is 0)."""
    inter = intersection_xywh(a, b)
    out = np.zeros_like(inter)
    for i, (_, _, aw, ah) in enumerate(a):
        for j, (_, _, bw, bh) in enumerate(b):
            union = aw * ah + bw * bh - inter[i, j]
            out[i, j] = inter[i, j] / union if union > 0 else 0.0
    return out
