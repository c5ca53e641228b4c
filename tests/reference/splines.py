"""A NumPy reference of the ``bspline`` baseline: Cox-de Boor basis, weighted normal equations.

No SciPy: the basis comes from the recursion, the fit from ``X^T W X c = X^T W y``.
"""

from __future__ import annotations

import numpy as np


def basis(knots, k, x):
    """B-spline basis of degree `k` at `x`, ``(len(x), len(knots) - k - 1)`` (Cox-de Boor);
    the right end of the knot vector belongs to the last non-empty interval."""
    t = np.asarray(knots, float)
    x = np.asarray(x, float)
    B = np.zeros((len(x), len(t) - 1))
    for i in range(len(t) - 1):
        B[:, i] = (t[i] <= x) & (x < t[i + 1])
    B[x == t[-1], np.flatnonzero(t[:-1] < t[1:])[-1]] = 1.0
    for d in range(1, k + 1):
        nxt = np.zeros((len(x), len(t) - 1 - d))
        for i in range(len(t) - 1 - d):
            if t[i + d] > t[i]:
                nxt[:, i] += (x - t[i]) / (t[i + d] - t[i]) * B[:, i]
            if t[i + d + 1] > t[i + 1]:
                nxt[:, i] += (t[i + d + 1] - x) / (t[i + d + 1] - t[i + 1]) * B[:, i + 1]
        B = nxt
    return B[:, : len(t) - k - 1]


def weighted_bspline(a, b, frames, window=12, spacing=4):
    """The documented fit: cubic, `window` points a side, interior knots every `spacing` frames
    from each end of the gap outwards (none within spacing / 2 of the window's ends), each
    residual multiplied by ``1 / (1 + d / 5)`` (d: frames to the gap), so that its square
    weighs ``1 / (1 + d / 5)²``."""
    pts = np.vstack([a[-window:, :3], b[:window, :3]])
    t, xy = pts[:, 0], pts[:, 1:3]
    f0, f1 = a[-1, 0], b[0, 0]
    left, right = [], []
    while f0 - spacing * (len(left) + 1) > t[0] + spacing / 2:
        left.insert(0, f0 - spacing * (len(left) + 1))
    while f1 + spacing * (len(right) + 1) < t[-1] - spacing / 2:
        right.append(f1 + spacing * (len(right) + 1))
    knots = [t[0]] * 4 + left + right + [t[-1]] * 4
    w2 = (1.0 / (1.0 + np.where(t <= f0, f0 - t, t - f1) / 5.0)) ** 2
    X = basis(knots, 3, t)
    c = np.linalg.solve(X.T @ (w2[:, None] * X), X.T @ (w2[:, None] * xy))
    return basis(knots, 3, frames) @ c
