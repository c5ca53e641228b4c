"""Box refinement: shrink loose detection boxes to the extent of their foreground.

Static cameras give a background model; a detector's boxes (public detections) are often looser
than the object, and the extent of the foreground inside each box is a tighter box.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._typing import F64

__all__ = ["refine_boxes"]


def refine_boxes(
    boxes_xywh: ArrayLike, mask: NDArray[np.uint8], fraction: float = 0.1, min_cover: float = 0.1
) -> F64:
    """Shrink boxes to the extent of their foreground.

    Parameters
    ----------
    boxes_xywh : (K, 4) array_like
        Boxes (left, top, width, height).
    mask : (H, W) ndarray of uint8
        Foreground mask (non-zero = foreground).
    fraction : float
        Rows and columns whose foreground share is above ``fraction`` times the densest row or
        column's are kept; the new box spans the first to the last kept one.
    min_cover : float
        Boxes whose foreground covers less than this share are returned unchanged (the
        background model has not seen the object move, or it is not there).

    Returns
    -------
    (K, 4) ndarray
        Refined boxes.
    """
    out = np.array(boxes_xywh, dtype=np.float64, copy=True).reshape(-1, 4)
    rows, cols = mask.shape
    for k, (x, y, w, h) in enumerate(out):
        x0, x1 = int(max(0, np.floor(x))), int(min(cols, np.ceil(x + w)))
        y0, y1 = int(max(0, np.floor(y))), int(min(rows, np.ceil(y + h)))
        if x1 - x0 < 3 or y1 - y0 < 3:
            continue
        patch = mask[y0:y1, x0:x1] > 0
        if patch.mean() < min_cover:
            continue
        col, row = patch.mean(axis=0), patch.mean(axis=1)
        cs = np.flatnonzero(col > fraction * col.max())
        rs = np.flatnonzero(row > fraction * row.max())
        out[k] = (x0 + cs[0], y0 + rs[0], cs[-1] + 1 - cs[0], rs[-1] + 1 - rs[0])
    return out
