"""Axis-aligned boxes: overlap and the two layouts pftrack uses.

``xywh`` is ``(left, top, width, height)`` (MOTChallenge files, detections, reported tracks);
``cxcywh`` is ``(centre x, centre y, width, height)`` (particle filters, the colour kernels).
Tracking and scoring share :func:`iou_xywh`, so they never disagree about an overlap.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pftrack._typing import F64

__all__ = ["cxcywh_to_xywh", "intersection_xywh", "iou_xywh", "iou_xywh_rows", "xywh_to_cxcywh"]


def intersection_xywh(a: ArrayLike, b: ArrayLike) -> F64:
    """Area of the intersection of every box of `a` with every box of `b`.

    Parameters
    ----------
    a : (n, 4) array_like of float
        Boxes ``left, top, width, height``.
    b : (m, 4) array_like of float
        Boxes ``left, top, width, height``.

    Returns
    -------
    (n, m) ndarray of float64
        Areas, 0 where two boxes do not meet.
    """
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    return _intersection(a[:, None, :], b[None, :, :])


def _intersection(a: F64, b: F64) -> F64:
    """Intersection areas of boxes ``left, top, width, height`` on the last axis, broadcast."""
    ax0, ay0 = a[..., 0], a[..., 1]
    ax1, ay1 = ax0 + a[..., 2], ay0 + a[..., 3]
    bx0, by0 = b[..., 0], b[..., 1]
    bx1, by1 = bx0 + b[..., 2], by0 + b[..., 3]
    # np.maximum(x, 0.0): what np.clip(x, 0.0, None) computes, without its Python wrapper
    iw = np.maximum(np.minimum(ax1, bx1) - np.maximum(ax0, bx0), 0.0)
    ih = np.maximum(np.minimum(ay1, by1) - np.maximum(ay0, by0), 0.0)
    return np.asarray(iw * ih, dtype=np.float64)


def _iou(a: F64, b: F64) -> F64:
    """IoU of boxes on the last axis, broadcast; 0 where the union is empty."""
    inter = _intersection(a, b)
    union = a[..., 2] * a[..., 3] + b[..., 2] * b[..., 3] - inter
    # inter / union where union > 0, else 0 (divided only there: nothing to warn about)
    out: F64 = np.divide(inter, union, out=np.zeros(inter.shape), where=union > 0)
    return out


def iou_xywh(a: ArrayLike, b: ArrayLike) -> F64:
    """Intersection over union of every box of `a` with every box of `b`.

    Parameters
    ----------
    a : (n, 4) array_like of float
        Boxes ``left, top, width, height``.
    b : (m, 4) array_like of float
        Boxes ``left, top, width, height``.

    Returns
    -------
    (n, m) ndarray of float64
        IoU in [0, 1]; 0 where the union is empty.
    """
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    return _iou(a[:, None, :], b[None, :, :])


def iou_xywh_rows(a: ArrayLike, b: ArrayLike) -> F64:
    """Intersection over union of ``a[k]`` with ``b[k]``, row by row.

    The diagonal of :func:`iou_xywh`, without computing the other pairs.

    Parameters
    ----------
    a, b : (n, 4) array_like of float
        Boxes ``left, top, width, height``.

    Returns
    -------
    (n,) ndarray of float64
        IoU in [0, 1]; 0 where the union is empty.
    """
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    if len(a) != len(b):
        raise ValueError(f"iou_xywh_rows: {len(a)} boxes against {len(b)}, expected as many")
    return _iou(a, b)


def xywh_to_cxcywh(boxes: ArrayLike) -> F64:
    """``(left, top, w, h)`` to ``(cx, cy, w, h)``; any leading shape, last axis 4."""
    b = np.asarray(boxes, dtype=np.float64)
    return np.concatenate([b[..., :2] + b[..., 2:] / 2, b[..., 2:]], axis=-1)


def cxcywh_to_xywh(boxes: ArrayLike) -> F64:
    """``(cx, cy, w, h)`` to ``(left, top, w, h)``; any leading shape, last axis 4."""
    b = np.asarray(boxes, dtype=np.float64)
    return np.concatenate([b[..., :2] - b[..., 2:] / 2, b[..., 2:]], axis=-1)
