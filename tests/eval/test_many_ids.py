"""Scoring files with thousands of ids: memory grows with the rows, not ids x ids."""

from __future__ import annotations

import tracemalloc

import numpy as np

from pftrack.eval.hota import ALPHAS, evaluate_hota


def many_ids(n_ids: int, per_frame: int) -> tuple[np.ndarray, np.ndarray]:
    """`n_ids` objects of one frame each, `per_frame` a frame side by side; the result shifted."""
    k = np.arange(n_ids)
    gt = np.zeros((n_ids, 10))
    gt[:, 0] = k // per_frame + 1
    gt[:, 1] = k + 1
    gt[:, 2] = 50.0 * (k % per_frame)
    gt[:, 3:6] = (20.0, 30.0, 60.0)
    gt[:, 6:] = (1, -1, -1, -1)
    res = gt.copy()
    res[:, 2] += 3.0
    res[:, 1] += 100_000
    return gt, res


def peak_mib(fn, *args):
    """Peak memory traced while `fn(*args)` runs, in MiB, and its result."""
    tracemalloc.start()
    try:
        out = fn(*args)
        return tracemalloc.get_traced_memory()[1] / 2**20, out
    finally:
        tracemalloc.stop()


def test_hota_of_many_ids_holds_no_ids_by_ids_matrix():
    # 2000 ids a side: a (gt ids, result ids) float64 matrix is 31 MiB, and the alignment took
    # a few of them (peak 94 MiB); the pairs that overlap are 2000
    gt, res = many_ids(2000, 100)
    peak, h = peak_mib(evaluate_hota, gt, res)
    assert peak < 15, f"{peak:.0f} MiB"
    matched = ALPHAS < 0.81  # IoU 27/33 = 0.82: matched up to alpha 0.8
    assert np.all(h.ass_a[matched] == 1.0)  # each object its own result id
    assert np.all(h.tp[matched] == 2000) and np.all(h.tp[~matched] == 0)
