"""Ghosts: foreground blobs that are uncovered background, found by their edges.

When someone present while the background was learnt walks away (or a stopped person leaves),
the background still holds their picture and the uncovered floor differs from it: a blob with
nobody in it, a "ghost". A real object has its silhouette's edges in the *current* frame; a
ghost has them in the *background* (where the object's picture is) and not in the frame. The
test compares the gradient magnitude of the frame and of the background along the blob's
boundary.

`edge_support` here is the OpenCV statement of the test; the detector runs the same computation
in C++ (``pftrack._core.BackgroundModel.edge_support``, on the model's own background, about 4
times faster), held equal to this function to 1e-5 by the tests.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._check import option

__all__ = ["GHOST_STATISTICS", "edge_support"]


GHOST_STATISTICS = ("ratio", "vote")


def _edge_magnitudes(bgr: NDArray[np.float32], band: NDArray[np.bool_]) -> NDArray[np.float32]:
    """The largest gradient magnitude over the channels, after a blur, at the `band` pixels.

    A step in colour at equal grey level is an edge too; fine texture (gravel, noise) is no
    silhouette, hence the blur. Only the band's pixels are reduced.
    """
    img = cv2.GaussianBlur(bgr, (5, 5), 1.5)
    gx = cv2.Sobel(img, cv2.CV_32F, 1, 0, ksize=3)[band]
    gy = cv2.Sobel(img, cv2.CV_32F, 0, 1, ksize=3)[band]
    return np.asarray(np.sqrt((gx * gx + gy * gy).max(axis=1)), np.float32)


def edge_support(
    frame: NDArray[np.uint8],
    background: NDArray[np.float32],
    mask: NDArray[np.uint8],
    boxes: NDArray[np.float64],
    statistic: str = "ratio",
) -> NDArray[np.float64]:
    """Share of each blob's boundary edges that the current frame holds.

    For each box, over the boundary of the mask inside it (its 3x3 dilation minus its
    erosion): ``E_frame / (E_frame + E_background)``, the summed gradient magnitudes (largest
    over the colour channels) of the frame and of the background (``"ratio"``), or the share of
    the boundary's pixels where the frame's magnitude is the larger (``"vote"``). About 1 for
    an object in front of a smooth background, about 0.5 when both are textured alike, near 0
    for a ghost (its edges are only in the background's picture of the object that left).
    A ghost that its owner has just walked out of keeps the owner's edge on one side of its
    boundary: a high-contrast silhouette that can outweigh the rest of the boundary in the
    sums, but is only its share of the pixels in the vote.

    Parameters
    ----------
    frame : (H, W, 3) uint8
        The BGR frame.
    background : (H, W, 3) float32
        The background model's BGR picture.
    mask : (H, W) uint8
        Cleaned foreground mask (0 / 255).
    boxes : (K, 4) float64
        Blob boxes ``left, top, w, h``.
    statistic : {"ratio", "vote"}
        Summed magnitudes, or a per-pixel vote.

    Returns
    -------
    (K,) ndarray of float64
        In [0, 1]; 0.5 for a box with no boundary edge at all.
    """
    option(statistic, "edge_support: statistic", GHOST_STATISTICS)
    if statistic not in GHOST_STATISTICS:
        raise ValueError(f"edge_support: statistic is {statistic!r}, expected 'ratio' or 'vote'")
    out = np.full(len(boxes), 0.5)
    rows, cols = mask.shape
    kernel = np.ones((3, 3), np.uint8)
    for k, (x, y, w, h) in enumerate(np.asarray(boxes, np.float64).reshape(-1, 4)):
        # a margin so that the boundary on the box's sides is seen
        x0, y0 = max(int(x) - 4, 0), max(int(y) - 4, 0)
        x1, y1 = min(int(x + w) + 4, cols), min(int(y + h) + 4, rows)
        if x1 - x0 < 3 or y1 - y0 < 3:
            continue
        m = mask[y0:y1, x0:x1]
        band = (cv2.dilate(m, kernel) > 0) & (cv2.erode(m, kernel) == 0)
        if not band.any():
            continue
        m_f = _edge_magnitudes(frame[y0:y1, x0:x1].astype(np.float32), band)
        m_b = _edge_magnitudes(np.asarray(background[y0:y1, x0:x1], np.float32), band)
        if statistic == "vote":
            out[k] = float(np.mean(m_f > m_b))
            continue
        e_f, e_b = float(m_f.sum()), float(m_b.sum())
        if e_f + e_b > 0:
            out[k] = e_f / (e_f + e_b)
    return out
