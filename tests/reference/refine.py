"""NumPy reference of box refinement (pftrack._core.refine_boxes): one box at a time."""

from __future__ import annotations

import numpy as np


def refine_boxes_reference(
    boxes_xywh: np.ndarray,
    mask: np.ndarray,
    fraction: float = 0.05,
    min_cover: float = 0.1,
    leg_fill: float | None = None,
    min_height: float = 0.0,
) -> np.ndarray:
    """Shrink each (left, top, w, h) box to the rows and columns of its foreground.

    With `leg_fill`: foreground is 255 only, and the refined box then grows down through rows
    whose foreground-or-shadow share between its columns is at least `leg_fill`. A refined
    height under `min_height` times the clipped box's keeps the box's own top and height.
    """
    out = np.array(boxes_xywh, dtype=np.float64, copy=True).reshape(-1, 4)
    rows, cols = mask.shape
    for k, (x, y, w, h) in enumerate(out):
        x0, x1 = int(max(0, np.floor(x))), int(min(cols, np.ceil(x + w)))
        y0, y1 = int(max(0, np.floor(y))), int(min(rows, np.ceil(y + h)))
        if x1 - x0 < 3 or y1 - y0 < 3:
            continue
        changed = mask[y0:y1, x0:x1] > 0
        patch = mask[y0:y1, x0:x1] > (127 if leg_fill is not None else 0)
        if patch.mean() < min_cover:
            continue
        col, row = patch.mean(axis=0), patch.mean(axis=1)
        cs = np.flatnonzero(col > fraction * col.max())
        rs = np.flatnonzero(row > fraction * row.max())
        last = rs[-1]
        if leg_fill is not None:
            legs = changed[:, cs[0] : cs[-1] + 1].mean(axis=1)
            while last + 1 < len(legs) and legs[last + 1] >= leg_fill:
                last += 1
        out[k, 0], out[k, 2] = x0 + cs[0], cs[-1] + 1 - cs[0]
        if last + 1 - rs[0] >= min_height * (y1 - y0):
            out[k, 1], out[k, 3] = y0 + rs[0], last + 1 - rs[0]
    return out
