"""Straightforward reference of the neighbour search of the ``-nb`` methods (tests only)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def windows(
    runs: list[F64], segment_a: F64, segment_b: F64, exclude: int, cap: int
) -> list[tuple[F64, F64, F64]]:
    """The runs (but run `exclude`) seen on every frame from the gap's last point before to its
    first point after, nearest first to that last point (ties: run order), at most `cap`, each
    cut into as many points before and after as the gap has and the points between: one run at
    a time."""
    fa, fb = float(segment_a[-1, 0]), float(segment_b[0, 0])
    found = []
    for k, r in enumerate(runs):
        if k == exclude or r[0, 0] > fa or r[-1, 0] < fb:
            continue
        i = int(fa - r[0, 0])
        if r[i, 0] != fa:
            continue
        d = float(np.hypot(r[i, 1] - segment_a[-1, 1], r[i, 2] - segment_a[-1, 2]))
        found.append((d, k, i))
    n_gap = int(fb - fa) - 1
    out = []
    for _, k, i in sorted(found)[:cap]:
        r = runs[k]
        lo = max(0, i + 1 - len(segment_a))
        hi = i + 1 + n_gap + len(segment_b)
        out.append((r[lo : i + 1], r[i + 1 + n_gap : hi], r[i + 1 : i + 1 + n_gap]))
    return out
