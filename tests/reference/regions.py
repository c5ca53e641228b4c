"""Reference of pftrack.recovery.calibrate's square regions: one square at a time.

What ``_region_blocks`` did before its squares went to one C++ call (``_core.region_blocks``):
for each square, its band of x in the points sorted by x, its band of y, the distances rounded
to ``SPAN_DECIMALS`` and the stretches they make, in NumPy calls on the square's points.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pftrack._typing import F64
from pftrack.recovery.calibrate import REGION_SQUARES, REGION_WORK, SPAN_DECIMALS, RegionBlocks


def region_blocks(
    flat: tuple[NDArray[np.int64], NDArray[np.int64], F64],
    side: float,
    rng: np.random.Generator,
    squares: int = REGION_SQUARES,
    work: int = REGION_WORK,
) -> RegionBlocks:
    """``_region_blocks(flat, side, rng, squares)`` with a budget of `work`, square by square."""
    sizes, offset, xy = flat
    n = len(xy)
    none = np.zeros(0, dtype=np.int64)
    if n == 0 or not side > 0:
        return RegionBlocks(none, none, none)
    run_of = np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)
    pos = np.arange(n, dtype=np.int64) - np.repeat(offset, sizes)
    first = pos == 0
    last = pos == np.repeat(sizes, sizes) - 1
    by_x = np.argsort(xy[:, 0], kind="stable")
    xs = xy[by_x, 0]
    half = 0.5 * side
    centres = xy[rng.integers(n, size=squares)]
    reach = half + 10.0**-SPAN_DECIMALS
    lo = np.searchsorted(xs, centres[:, 0] - reach, side="left")
    hi = np.searchsorted(xs, centres[:, 0] + reach, side="right")
    within = np.cumsum(hi - lo) <= work
    kept = max(1, int(np.argmin(within)) if not within.all() else squares)
    starts: list[NDArray[np.int64]] = []
    ends: list[NDArray[np.int64]] = []
    for k in range(kept):
        inside = by_x[lo[k] : hi[k]]
        inside = inside[np.abs(xy[inside, 1] - centres[k, 1]) <= reach]
        near = np.round(np.abs(xy[inside] - centres[k]), SPAN_DECIMALS)
        inside = np.sort(inside[(near <= half).all(axis=1)])
        if len(inside) == 0:
            continue
        cut = np.flatnonzero((np.diff(inside) != 1) | first[inside[1:]])
        s = inside[np.r_[0, cut + 1]]
        e = inside[np.r_[cut, len(inside) - 1]]
        ok = ~first[s] & ~last[e]
        starts.append(s[ok])
        ends.append(e[ok])
    if not starts:
        return RegionBlocks(none, none, none)
    s_all, e_all = np.concatenate(starts), np.concatenate(ends)
    return RegionBlocks(run_of[s_all], pos[s_all], e_all - s_all + 1)
