"""Box refinement: shrink loose detection boxes to the extent of their foreground.

Static cameras give a background model; a detector's boxes (public detections) are often looser
than the object, and the extent of the foreground inside each box is a tighter box. All boxes
are refined in one C++ call (``tests/reference/refine.py`` is its NumPy reference).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._typing import F64

__all__ = ["refine_boxes"]


def refine_boxes(
    boxes_xywh: ArrayLike,
    mask: NDArray[np.uint8] | NDArray[np.bool_],
    fraction: float = 0.1,
    min_cover: float = 0.1,
    leg_fill: float | None = None,
    min_height: float = 0.0,
) -> F64:
    """Shrink boxes to the extent of their foreground.

    Parameters
    ----------
    boxes_xywh : (K, 4) array_like
        Boxes (left, top, width, height).
    mask : (H, W) ndarray of uint8 or bool
        Foreground mask (non-zero = foreground); with `leg_fill`, a mask with shadows (255
        foreground, 127 shadow, 0 background, OpenCV MOG2's convention).
    fraction : float
        Rows and columns whose foreground share is above ``fraction`` times the densest row or
        column's are kept; the new box spans the first to the last kept one. In [0, 1).
    min_cover : float
        Boxes whose foreground covers less than this share are returned unchanged (the
        background model has not seen the object move, or it is not there). In [0, 1].
    leg_fill : float, optional
        In [0, 1]: only 255 is foreground for the steps above, and a refined box then grows
        down, row by row, while the row's share of foreground or shadow pixels between the
        refined box's first and last column is at least `leg_fill`, no further than the
        original box. Legs the shadow test took for shadow (dark trousers on a grey path) come
        back; a shadow cast beside the feet, outside those columns, does not extend the box.
        None: no growing, every non-zero pixel is foreground.
    min_height : float
        In [0, 1]: a box refined to less than this share of its height (inside the image)
        keeps its own top and height, and only its columns are refined. A detector's box is
        rarely much taller than its object; a refined box that lost most of the height is a
        fragment of the object (legs the colour of the ground, a standing person the
        background model has absorbed, a ghost). 0: no such test.

    Returns
    -------
    (K, 4) ndarray
        Refined boxes. A box is first cut to whole pixels inside the image
        (``floor(left) .. ceil(left + width)``); one under 3 pixels a side there is unchanged.

    Raises
    ------
    TypeError
        `mask` not uint8 or bool (the dtype of a mask is checked as ``hsv_bins`` checks it;
        was ValueError until 5 December).
    ValueError
        `boxes_xywh` not (K, 4) or not finite, `mask` not 2-D, or `fraction`, `min_cover`,
        `leg_fill` or `min_height` out of range.
    """
    b = np.ascontiguousarray(boxes_xywh, dtype=np.float64)
    if b.size == 0:
        return np.zeros((0, 4))
    if b.ndim != 2 or b.shape[1] != 4:
        raise ValueError(f"boxes_xywh has shape {b.shape}, expected (K, 4) left, top, w, h")
    if not np.isfinite(b).all():
        raise ValueError("boxes_xywh contains NaN or inf")
    m = np.asarray(mask)
    if m.ndim == 2 and (m.strides[1] != 1 or m.strides[0] <= 0):
        # the core reads rows of packed pixels at a positive stride: a flipped (mask[::-1]) or
        # broadcast mask is copied once (was: refused as "must be packed along rows")
        m = np.ascontiguousarray(m)
    fill = None if leg_fill is None else float(leg_fill)
    out: F64 = _core.refine_boxes(b, m, float(fraction), float(min_cover), fill, float(min_height))
    return out
