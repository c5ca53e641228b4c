"""Recovery part of ``pftrack demo``: cut gaps into tracks, recover them, report the errors."""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import ArrayLike

from pftrack._typing import RecoveryMethod, RngLike
from pftrack.recovery.noise import _estimate_noise
from pftrack.recovery.registry import METHODS, recover_gaps

__all__ = ["demo_report"]


def demo_report(
    tracks_rows: ArrayLike,
    rng: RngLike = None,
    *,
    n_gaps: int = 20,
    gap_range: tuple[int, int] = (5, 25),
    methods: tuple[RecoveryMethod, ...] = METHODS,
) -> str:
    """Cut random gaps into tracks, recover them with every method and tabulate the errors.

    Parameters
    ----------
    tracks_rows : (M, 10) array_like
        MOTChallenge rows (true tracks or a tracker's output); box centres are the points.
    rng : numpy.random.Generator, int or None
        Chooses the gaps.
    n_gaps : int
        How many gaps to cut (at most one per track and place; fewer if tracks are short).
    gap_range : (int, int)
        Smallest and largest gap length in frames.
    methods : tuple of str
        Methods compared.

    Returns
    -------
    str
        A small table: mean Euclidean error (px) per method over the gaps and total time.
    """
    gen = np.random.default_rng(rng)
    rows = np.asarray(tracks_rows, dtype=np.float64)
    if rows.ndim != 2 or rows.shape[1] < 6:
        raise ValueError(f"demo_report: tracks_rows must have shape (M, 10), got {rows.shape}")
    lo, hi = gap_range
    tracks = []
    for tid in np.unique(rows[:, 1]):
        r = rows[rows[:, 1] == tid]
        r = r[np.argsort(r[:, 0])]
        if len(r) >= hi + 10 and np.all(np.diff(r[:, 0]) == 1):
            tracks.append(np.column_stack([r[:, 0], r[:, 2] + r[:, 4] / 2, r[:, 3] + r[:, 5] / 2]))
    if not tracks:
        return "recovery demo: no track long enough to cut a gap into"
    gaps = []
    truths = []
    for _ in range(n_gaps):
        tr = tracks[int(gen.integers(len(tracks)))]
        length = int(gen.integers(lo, min(hi, len(tr) - 10) + 1))
        start = int(gen.integers(5, len(tr) - length - 4))
        gaps.append((tr[:start], tr[start + length :]))
        truths.append(tr[start : start + length, 1:3])
    noise = _estimate_noise([g[0] for g in gaps] + [g[1] for g in gaps])
    lines = [
        f"recovery demo: {len(gaps)} gaps of {lo}-{hi} frames cut into {len(tracks)} tracks",
        f"{'method':<10}{'mean error (px)':>17}{'time (ms)':>11}",
    ]
    for m in methods:
        t0 = time.perf_counter()
        paths = recover_gaps(gaps, m, noise=noise)
        dt = 1e3 * (time.perf_counter() - t0)
        err = np.mean([np.hypot(*(p - t).T).mean() for p, t in zip(paths, truths, strict=True)])
        lines.append(f"{m:<10}{err:>17.3f}{dt:>11.2f}")
    return "\n".join(lines)
