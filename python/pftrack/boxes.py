"""Axis-aligned boxes: overlap and the two layouts pftrack uses.

``xywh`` is ``(left, top, width, height)`` (MOTChallenge files, detections, reported tracks);
``cxcywh`` is ``(centre x, centre y, width, height)`` (particle filters, the colour kernels).
Tracking and scoring share :func:`iou_xywh`, so they never disagree about an overlap.

Every public function here checks its boxes: a ``(n, 4)`` array (or one ``(4,)`` box), finite
values, widths and heights ``>= 0`` and every value within ±:data:`~pftrack._check.MAX_COORD`
px (the bound of the other kernels), with a ValueError naming the function, the argument and
the first bad box. The tracker's per-frame calls, whose boxes it made and checked itself, use
the unchecked ``_iou_matrix``, ``_intersection_matrix``, ``_iou_rows``, ``_to_cxcywh`` and
``_to_xywh``, which compute the same floats.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import first_bad_box, real_array
from pftrack._typing import F64

__all__ = ["cxcywh_to_xywh", "intersection_xywh", "iou_xywh", "iou_xywh_rows", "xywh_to_cxcywh"]


def _box_rows(boxes: ArrayLike, fn: str, what: str) -> F64:
    """`boxes` as a checked (n, 4) float64 array: (n, 4), one box (4,), or empty (``[]``).

    Raises
    ------
    TypeError
        Not real numbers (text, complex numbers, booleans, None).
    ValueError
        Another shape (a (n, 6) array of ``xywh, conf, cls`` is not taken for boxes), or a
        value :func:`_check_values` refuses.
    """
    b = real_array(boxes, f"{fn}: {what}", booleans=False)
    if b.ndim == 1 and b.size == 0:
        return np.zeros((0, 4))  # [] is no box, as np.zeros((0, 4))
    if b.shape == (4,):
        b = b[None, :]
    if b.ndim != 2 or b.shape[1] != 4:
        raise ValueError(
            f"{fn}: {what} must have shape (n, 4) (left, top, width, height), or (4,) for one "
            f"box, got {b.shape}"
        )
    _check_values(b, fn, what)
    return b


def _check_values(b: F64, fn: str, what: str, edges: bool = True) -> None:
    """Refuse a non-finite value, a negative width or height, or a value beyond ±MAX_COORD px.

    `b` holds boxes on its last axis (4 values), any leading shape; the message names the first
    bad box by its index.
    """
    rows = b.reshape(-1, 4)
    finite = np.isfinite(rows).all(axis=1)
    if finite.all():
        found = first_bad_box(rows, edges=edges)
        if found is None:
            return
        r, _, problem = found
    else:
        r, problem = int(np.argmin(finite)), "a value is not finite"
    at = np.unravel_index(r, b.shape[:-1])
    where = f"[{', '.join(str(int(i)) for i in at)}]" if at else ""
    raise ValueError(f"{fn}: {what}{where} is {rows[r].tolist()}: {problem}")


def _layout(boxes: ArrayLike, fn: str, edges: bool = True) -> F64:
    """`boxes` for a layout conversion: any leading shape, 4 values on the last axis, checked.

    `edges`: whether their far edges are checked (False for centre-format boxes, whose far
    edge is not ``x + w``).
    """
    b = real_array(boxes, f"{fn}: boxes", booleans=False)
    if b.ndim == 0 or b.shape[-1] != 4:
        raise ValueError(f"{fn}: boxes must have 4 values on the last axis, got shape {b.shape}")
    _check_values(b, fn, "boxes", edges)
    return b


def intersection_xywh(a: ArrayLike, b: ArrayLike) -> F64:
    """Area of the intersection of every box of `a` with every box of `b`.

    Parameters
    ----------
    a : (n, 4) array_like of float
        Boxes ``left, top, width, height``; one box may be given as (4,).
    b : (m, 4) array_like of float
        Boxes ``left, top, width, height``; one box may be given as (4,).

    Returns
    -------
    (n, m) ndarray of float64
        Areas, 0 where two boxes do not meet.

    Raises
    ------
    TypeError
        Boxes that are not real numbers.
    ValueError
        Boxes not of shape (n, 4) or (4,), a value not finite or beyond ±1e9 px, a negative
        width or height.
    """
    fn = "intersection_xywh"
    return _intersection_matrix(_box_rows(a, fn, "a"), _box_rows(b, fn, "b"))


def _intersection_matrix(a: ArrayLike, b: ArrayLike) -> F64:
    """:func:`intersection_xywh` without its checks."""
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
        Boxes ``left, top, width, height``; one box may be given as (4,).
    b : (m, 4) array_like of float
        Boxes ``left, top, width, height``; one box may be given as (4,).

    Returns
    -------
    (n, m) ndarray of float64
        IoU in [0, 1]; 0 where the union is empty.

    Raises
    ------
    TypeError
        Boxes that are not real numbers.
    ValueError
        Boxes not of shape (n, 4) or (4,) (e.g. (n, 6) detections ``xywh, conf, cls``: pass
        ``dets[:, :4]``), a value not finite or beyond ±1e9 px, a negative width or height.
    """
    return _iou_matrix(_box_rows(a, "iou_xywh", "a"), _box_rows(b, "iou_xywh", "b"))


def _iou_matrix(a: ArrayLike, b: ArrayLike) -> F64:
    """:func:`iou_xywh` without its checks: the tracker's per-frame association."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    return _iou(a[:, None, :], b[None, :, :])


def _overlap_pairs(a: ArrayLike, b: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Pairs ``(i, j)`` of boxes ``a[i]``, ``b[j]`` whose intersection can have an area > 0.

    Every pair whose :func:`_iou_matrix` entry is > 0 is among them (their interiors meet in x
    and in y), in increasing ``(i, j)`` order; the caller computes their IoU with
    :func:`_iou_rows`, the same floats as the dense matrix's. Sort-and-sweep in the core
    (``_core.overlap_pairs``): time and memory grow with the boxes and the pairs that meet, not
    with ``len(a) * len(b)``. Unchecked, as :func:`_iou_matrix`.

    References
    ----------
    .. [1] Baraff, D. (1992). Dynamic simulation of non-penetrating rigid bodies (sweep and
       prune), PhD thesis, Cornell University.
    """
    i, j = _core.overlap_pairs(
        np.ascontiguousarray(a, dtype=np.float64).reshape(-1, 4),
        np.ascontiguousarray(b, dtype=np.float64).reshape(-1, 4),
    )
    return i.astype(np.intp, copy=False), j.astype(np.intp, copy=False)


def iou_xywh_rows(a: ArrayLike, b: ArrayLike) -> F64:
    """Intersection over union of ``a[k]`` with ``b[k]``, row by row.

    The diagonal of :func:`iou_xywh`, without computing the other pairs.

    Parameters
    ----------
    a, b : (n, 4) array_like of float
        Boxes ``left, top, width, height``; one box may be given as (4,).

    Returns
    -------
    (n,) ndarray of float64
        IoU in [0, 1]; 0 where the union is empty.

    Raises
    ------
    TypeError
        Boxes that are not real numbers.
    ValueError
        Boxes as :func:`iou_xywh` refuses them, or not as many in `a` as in `b`.
    """
    fn = "iou_xywh_rows"
    a = _box_rows(a, fn, "a")
    b = _box_rows(b, fn, "b")
    if len(a) != len(b):
        raise ValueError(f"{fn}: {len(a)} boxes against {len(b)}, expected as many")
    return _iou_rows(a, b)


def _iou_rows(a: ArrayLike, b: ArrayLike) -> F64:
    """:func:`iou_xywh_rows` without its checks (`a` and `b` of one length)."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    return _iou(a, b)


def xywh_to_cxcywh(boxes: ArrayLike) -> F64:
    """``(left, top, w, h)`` to ``(cx, cy, w, h)``; any leading shape, last axis 4.

    Raises
    ------
    TypeError
        Boxes that are not real numbers.
    ValueError
        Not 4 values on the last axis, a value not finite or beyond ±1e9 px, a negative width
        or height.
    """
    return _to_cxcywh(_layout(boxes, "xywh_to_cxcywh"))


def _to_cxcywh(boxes: ArrayLike) -> F64:
    """:func:`xywh_to_cxcywh` without its checks."""
    b = np.asarray(boxes, dtype=np.float64)
    return np.concatenate([b[..., :2] + b[..., 2:] / 2, b[..., 2:]], axis=-1)


def cxcywh_to_xywh(boxes: ArrayLike) -> F64:
    """``(cx, cy, w, h)`` to ``(left, top, w, h)``; any leading shape, last axis 4.

    Raises
    ------
    TypeError
        Boxes that are not real numbers.
    ValueError
        Not 4 values on the last axis, a value not finite or beyond ±1e9 px, a negative width
        or height.
    """
    return _to_xywh(_layout(boxes, "cxcywh_to_xywh", edges=False))


def _to_xywh(boxes: ArrayLike) -> F64:
    """:func:`cxcywh_to_xywh` without its checks."""
    b = np.asarray(boxes, dtype=np.float64)
    return np.concatenate([b[..., :2] - b[..., 2:] / 2, b[..., 2:]], axis=-1)
