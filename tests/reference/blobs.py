"""Reference of the blob pass (pftrack._core.blob_boxes, split_count, merge_fragments, theil_sen,
size_fit, extend_legs).

The detectors' blob pass as it was written in Python before it moved to C++: OpenCV's outer
contours (``cv2.findContours`` with ``RETR_EXTERNAL``), NumPy filters, the person-size model's
fragment merging and group splitting, one blob at a time. The C++ pass must give the same boxes
and fills, bit for bit and in the same order.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def theil_sen(x: F64, y: F64) -> tuple[float, float]:
    """Median of the pairwise slopes; intercept ``median(y - slope x)``."""
    i, j = np.triu_indices(len(x), k=1)
    dx = x[j] - x[i]
    ok = dx != 0
    slope = float(np.median((y[j] - y[i])[ok] / dx[ok]))
    return slope, float(np.median(y - slope * x))


def robust_line(x: F64, y: F64) -> tuple[float, float]:
    """Theil-Sen line refitted once on the points within 3 robust sigmas of the first."""
    slope, intercept = theil_sen(x, y)
    r = y - (slope * x + intercept)
    sigma = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    keep = np.abs(r) <= 3.0 * max(sigma, 1.0)
    if keep.sum() >= 3 and np.ptp(x[keep]) > 0:
        slope, intercept = theil_sen(x[keep], y[keep])
    return slope, intercept


def size_fit(samples: F64) -> F64:
    """The size model's (2, 2) lines from samples (n, 3) foot y, h, w."""
    s = np.asarray(samples, np.float64)
    coef = np.zeros((2, 2))
    if np.ptp(s[:, 0]) < 1.0:  # every foot on one row: a constant size
        coef[:, 1] = np.median(s[:, 1:], axis=0)
    else:
        for j in (0, 1):
            coef[j] = robust_line(s[:, 0], s[:, 1 + j])
    return coef


def expected(coef: F64, foot_y: F64 | float) -> F64:
    """Expected ``(h, w)`` at foot row(s) `foot_y`, at least 1 px."""
    y = np.asarray(foot_y, np.float64)[..., None]
    return np.maximum(coef[:, 0] * y + coef[:, 1], 1.0)


def split_count(
    boxes: F64, coef: F64, split_ratio: float = 1.6, split_max_height: float = 1.5
) -> NDArray[np.int64]:
    """People side by side in each box (K, 4)."""
    b = np.asarray(boxes, np.float64).reshape(-1, 4)
    h_exp, w_exp = expected(coef, b[:, 1] + b[:, 3]).T
    wide = (b[:, 2] > split_ratio * w_exp) & (b[:, 3] <= split_max_height * h_exp)
    n = np.where(wide, np.round(b[:, 2] / w_exp), 1.0).astype(np.int64)
    return np.maximum(n, 1)


def merge_fragments(boxes: F64, coef: F64, merge_slack: float = 1.2) -> list[list[int]]:
    """Greedy groups of the boxes (K, 4) that are one person's fragments."""
    b = np.asarray(boxes, np.float64).reshape(-1, 4)
    groups = [[i] for i in range(len(b))]
    cur = [r.copy() for r in b]
    while len(cur) > 1:
        best: tuple[float, int, int, F64] | None = None
        for i in range(len(cur)):
            for j in range(i + 1, len(cur)):
                a, c = cur[i], cur[j]
                ov = min(a[0] + a[2], c[0] + c[2]) - max(a[0], c[0])
                if ov < 0.5 * min(a[2], c[2]):
                    continue
                x0, y0 = min(a[0], c[0]), min(a[1], c[1])
                x1, y1 = max(a[0] + a[2], c[0] + c[2]), max(a[1] + a[3], c[1] + c[3])
                h_exp, w_exp = expected(coef, y1)
                if y1 - y0 > merge_slack * h_exp or x1 - x0 > merge_slack * w_exp:
                    continue
                area = (x1 - x0) * (y1 - y0)
                if best is None or area < best[0]:
                    best = (area, i, j, np.array([x0, y0, x1 - x0, y1 - y0]))
        if best is None:
            break
        _, i, j, u = best
        cur[i] = u
        groups[i] = groups[i] + groups[j]
        del cur[j], groups[j]
    return groups


def _merge(
    mask: NDArray[np.uint8], rects: F64, fill: F64, groups: list[list[int]]
) -> tuple[F64, F64]:
    if len(groups) == len(rects):
        return rects, fill
    out_r = np.zeros((len(groups), 4))
    out_f = np.zeros(len(groups))
    for k, g in enumerate(groups):
        x0, y0 = rects[g, 0].min(), rects[g, 1].min()
        x1, y1 = (rects[g, 0] + rects[g, 2]).max(), (rects[g, 1] + rects[g, 3]).max()
        out_r[k] = (x0, y0, x1 - x0, y1 - y0)
        roi = mask[int(y0) : int(y1), int(x0) : int(x1)]
        out_f[k] = cv2.countNonZero(roi) / max(roi.size, 1) if len(g) > 1 else fill[g[0]]
    return out_r, out_f


def _split(
    mask: NDArray[np.uint8],
    rects: F64,
    fill: F64,
    counts: NDArray[np.int64],
    min_area: float,
    valley: float = 1.0,
) -> tuple[F64, F64]:
    min_pixels = min_area * mask.shape[0] * mask.shape[1]
    out_r: list[F64] = []
    out_f: list[float] = []
    for r, f, n in zip(rects, fill, counts, strict=True):
        x, y, w, h = (int(v) for v in r)
        if n < 2:
            out_r.append(r)
            out_f.append(float(f))
            continue
        n = int(n)
        roi = mask[y : y + h, x : x + w] > 0
        profile = roi.sum(axis=0).astype(np.float64)
        cuts = [0]
        half = max(1, w // (4 * n))
        for k in range(1, n):
            c = round(k * w / n)
            lo, hi = max(cuts[-1] + 1, c - half), min(w - 1, c + half + 1)
            cuts.append(lo + int(np.argmin(profile[lo:hi])) if hi > lo else c)
        cuts.append(w)
        if valley < 1.0:  # a cut only at a valley: at most `valley` of both sides' peaks
            kept = [0]
            for k in range(1, len(cuts) - 1):
                if not kept[-1] < cuts[k] < cuts[k + 1]:
                    continue  # no column on one side (a narrow box cut into many): no valley
                left = profile[kept[-1] : cuts[k]].max()
                right = profile[cuts[k] : cuts[k + 1]].max()
                if profile[cuts[k]] <= valley * min(left, right):
                    kept.append(cuts[k])
            cuts = [*kept, w]
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            part = roi[:, a:b]
            rows = np.flatnonzero(part.any(axis=1))
            cols = np.flatnonzero(part.any(axis=0))
            if len(rows) == 0 or part.sum() < min_pixels:
                continue
            pw, ph = cols[-1] - cols[0] + 1, rows[-1] - rows[0] + 1
            out_r.append(np.array([x + a + cols[0], y + rows[0], pw, ph], np.float64))
            out_f.append(float(part.sum()) / (pw * ph))
    return np.array(out_r, np.float64).reshape(-1, 4), np.array(out_f, np.float64)


def blob_boxes(
    mask: NDArray[np.uint8],
    min_area: float = 0.0015,
    max_area: float = 0.25,
    min_aspect: float = 0.25,
    max_aspect: float = 6.0,
    min_fill: float = 0.2,
    person_aspect: float = 2.8,
    size_lines: F64 | None = None,
    split_ratio: float = 1.6,
    split_max_height: float = 1.5,
    merge_slack: float = 1.2,
    split_valley: float = 1.0,
) -> tuple[F64, F64]:
    """Boxes (K, 4) and fills (K,) of the blobs of a cleaned 0/255 mask, unsorted."""
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return np.zeros((0, 4)), np.zeros(0)
    rects = np.array([cv2.boundingRect(c) for c in contours], dtype=np.float64)
    frame_area = float(mask.shape[0] * mask.shape[1])
    w, h = rects[:, 2], rects[:, 3]
    aspect = h / w
    keep = (w * h >= min_area * frame_area) & (aspect >= min_aspect) & (aspect <= max_aspect)
    area = np.zeros(len(rects))
    for i in np.flatnonzero(keep):
        x, y, bw, bh = rects[i].astype(int)
        area[i] = cv2.countNonZero(mask[y : y + bh, x : x + bw])
    fill = area / (w * h)
    keep &= (area >= min_area * frame_area) & (area <= max_area * frame_area) & (fill >= min_fill)
    rects, fill = rects[keep], fill[keep]
    if size_lines is not None and len(rects):
        rects, fill = _merge(mask, rects, fill, merge_fragments(rects, size_lines, merge_slack))
        counts = split_count(rects, size_lines, split_ratio, split_max_height)
        rects, fill = _split(mask, rects, fill, counts, min_area, split_valley)
    elif person_aspect > 0 and len(rects):
        objects = rects[:, 2] * person_aspect / rects[:, 3]
        n = np.round(objects).astype(np.int64)
        n[objects < 1.5] = 1
        rects, fill = _split(mask, rects, fill, n, min_area, split_valley)
    return rects, fill


def extend_legs(
    mask: NDArray[np.uint8], boxes: F64, coef: F64, min_height: float, row_fill: float
) -> F64:
    """Short boxes grown down through the rows below them that `mask` fills, to the foot row.

    The expected height of a person whose head is at row ``y``: ``h = a + b (y + h)``, so
    ``(a + b y) / (1 - b)``. Each row's count of non-zero pixels in the box's columns is read
    from a cumulative sum; the box takes every row down to the first that fills less than
    `row_fill` of them (or none), stopping at the expected foot row.
    """
    out = np.array(boxes, np.float64).reshape(-1, 4)
    b, a = float(coef[0, 0]), float(coef[0, 1])
    if 1.0 - b == 0.0:
        return out
    rows, cols = mask.shape
    counts = np.concatenate(
        [np.zeros((rows, 1), np.int64), np.cumsum(mask != 0, axis=1, dtype=np.int64)], axis=1
    )
    for k, (x, y, w, h) in enumerate(out):
        h_exp = (a + b * y) / (1.0 - b)
        if not (h_exp > 0.0 and h < min_height * h_exp):
            continue
        x0, x1 = (int(np.rint(np.clip(v, 0, cols))) for v in (x, x + w))
        if x1 <= x0:
            continue
        start = int(np.rint(np.clip(y + h, 0, rows)))
        last = int(min(rows, np.floor(y + h_exp)))  # rows r with r + 1 <= y + h_exp: r < last
        if last <= start:
            continue
        n = counts[start:last, x1] - counts[start:last, x0]
        bad = (n == 0) | (n < row_fill * (x1 - x0))
        grow = int(np.argmax(bad)) if bad.any() else len(n)
        if grow:
            out[k, 3] = float(start + grow) - y
    return out
