"""Reference of pftrack.recovery.calibrate's artificial gaps: one attempt at a time.

What ``_artificial_gaps`` did before it matched the places of several attempts in a few array
operations: for each attempt, its draws, their places and end-point distances, and the nearest
one, in NumPy calls on ``MATCH_DRAWS`` values; one ``Generator.integers`` call per attempt, as
its draws were made before stop 67 drew a batch of attempts in one call.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pftrack._typing import F64
from pftrack.recovery.calibrate import (
    CONTEXT,
    MATCH_DRAWS,
    MAX_CONTEXT,
    SPAN_DECIMALS,
    RegionBlocks,
    _flat,
)


def artificial_gaps(
    runs: Sequence[F64],
    targets: Sequence[tuple[int, float] | tuple[int, float, int, int]],
    n: int,
    rng: np.random.Generator,
    regions: RegionBlocks | None = None,
    marks: list[bool] | None = None,
) -> list[tuple[F64, F64, F64, int]]:
    """``_artificial_gaps(runs, targets, n, rng, None, regions, marks)``, one attempt at a time."""
    sizes, offset, xy = _flat(runs)
    out: list[tuple[F64, F64, F64, int]] = []
    used: set[tuple[int, int, int]] = set()
    places: dict[int, tuple[NDArray[np.int64], NDArray[np.int64], int]] = {}
    order = rng.permutation(len(targets)) if len(targets) else np.zeros(0, dtype=np.int64)
    for attempt in range(4 * n):
        if len(out) >= n or not len(order):
            break
        t = targets[int(order[attempt % len(order)])]
        L, dist = int(t[0]), float(t[1])
        n_a, n_b = (int(t[2]), int(t[3])) if len(t) == 4 else (-1, -1)
        ctx_a = CONTEXT if n_a < 0 else min(max(n_a, CONTEXT), MAX_CONTEXT)
        ctx_b = CONTEXT if n_b < 0 else min(max(n_b, CONTEXT), MAX_CONTEXT)
        by_region = False
        if regions is not None:  # the stretches of this length with room for the contexts
            ok = (
                (regions.length == L)
                & (regions.start >= ctx_a)
                & (regions.start + L + ctx_b <= sizes[regions.run])
            )
            by_region = bool(ok.any())
        if by_region:
            assert regions is not None
            ks = rng.integers(int(ok.sum()), size=MATCH_DRAWS)
            idx, starts = regions.run[ok][ks], regions.start[ok][ks]
        else:
            span = L + ctx_a + ctx_b
            if span not in places:
                slots_of = np.maximum(sizes - span + 1, 0)
                cum_of = np.cumsum(slots_of)
                places[span] = (slots_of, cum_of, int(cum_of[-1]) if len(cum_of) else 0)
            slots, cum, total = places[span]
            if total == 0:
                continue
            ks = rng.integers(total, size=MATCH_DRAWS)
            idx = np.searchsorted(cum, ks, side="right")
            starts = ctx_a + ks - (cum[idx] - slots[idx])
        j = 0
        if dist >= 0:
            at = offset[idx] + starts
            d = np.round(np.hypot(*(xy[at + L] - xy[at - 1]).T), SPAN_DECIMALS)
            j = int(np.argmin(np.abs(np.log1p(d) - np.log1p(dist))))
        i, st = int(idx[j]), int(starts[j])
        if (i, st, L) in used:
            continue
        used.add((i, st, L))
        r = runs[i]
        lo = 0 if n_a < 0 else max(0, st - n_a)
        hi = len(r) if n_b < 0 else st + L + n_b
        out.append((r[lo:st], r[st + L : hi], r[st : st + L], i))
        if marks is not None:
            marks.append(by_region)
    if regions is not None and len(out) < n:
        # the regions' stretches ran out (each is used once): the rest at random places
        for seg_a, seg_b, lost, k in artificial_gaps(runs, targets, 4 * (n - len(out)), rng):
            st = int(np.searchsorted(runs[k][:, 0], lost[0, 0]))
            if len(out) >= n or (k, st, len(lost)) in used:
                continue
            used.add((k, st, len(lost)))
            out.append((seg_a, seg_b, lost, k))
            if marks is not None:
                marks.append(False)
    return out
