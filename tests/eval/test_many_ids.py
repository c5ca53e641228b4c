"""Scoring long files: memory grows with the rows, not ids x ids; no per-frame NumPy calls."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from pftrack.eval import evaluate_mot
from pftrack.eval.hota import ALPHAS, evaluate_hota
from pftrack.eval.rows import check_unique_ids
from pftrack.io.mot import group_by_frame


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


def test_identity_of_many_ids_holds_no_ids_by_ids_matrix():
    gt, res = many_ids(2000, 100)
    peak, m = peak_mib(evaluate_mot, gt, res)  # one (ids, ids) matrix for IDF1: peak 62 MiB
    assert peak < 15, f"{peak:.0f} MiB"
    assert m.idtp == 2000 and m.idf1 == 1.0


def test_identity_by_groups_equals_one_assignment_over_all_ids():
    # id switches link ids into groups; the best pairing summed over groups is the best of all
    rng = np.random.default_rng(5)
    gt, res = many_ids(600, 20)
    k = np.arange(len(res))  # a switch to one of 40 ids, unique within a frame
    other = 200_000 + k % 20 + 20 * rng.integers(0, 2, len(res))
    res[:, 1] = np.where(rng.random(len(res)) < 0.3, other, res[:, 1])
    gt = np.vstack([gt, gt + [[30, 0] + [0] * 8]])  # each object again 30 frames later
    res = np.vstack([res, res + [[30, 0] + [0] * 8]])
    m = evaluate_mot(gt, res)
    g_ids = np.unique(gt[:, 1])
    r_ids = np.unique(res[:, 1])
    w = np.zeros((len(g_ids), len(r_ids)))
    for f in np.unique(gt[:, 0]):
        g, r = gt[gt[:, 0] == f], res[res[:, 0] == f]
        for gi in g:
            for ri in r:
                if ri[2] < gi[2] + gi[4] and gi[2] < ri[2] + ri[4]:  # same row: IoU 27/33
                    w[np.searchsorted(g_ids, gi[1]), np.searchsorted(r_ids, ri[1])] += 1
    a, b = linear_sum_assignment(-w)
    assert m.idtp == int(w[a, b].sum())
    assert 0 < m.idtp < len(gt)


def test_unique_ids_of_100000_frames_are_checked_at_once(monkeypatch: pytest.MonkeyPatch):
    # one np.unique per frame: 1.2 to 3.2 s here (four calls in each `pftrack eval`); at once:
    # 0.1 s. Counted, not timed (a loaded machine would make a time bound fail by chance)
    import pftrack.eval.rows as rows_module

    n = 100_000
    rows = np.zeros((3 * n, 10))
    rows[:, 0] = np.repeat(np.arange(1, n + 1), 3)
    rows[:, 1] = np.tile([1.0, 2.0, 3.0], n)
    frames = group_by_frame(rows)
    calls = []
    unique = np.unique

    def counted(*args, **kwargs):
        calls.append(1)
        return unique(*args, **kwargs)

    monkeypatch.setattr(rows_module.np, "unique", counted)
    check_unique_ids(frames, "result")
    assert len(calls) <= 1  # not one call a frame
    monkeypatch.undo()
    rows[[-1, -4, -7], 1] = (2.0, 1.0, 2.0)  # id 3 made 2 in frame 100 000, 1 in 99 999, ...
    # and 2 in 99 998: the first frame named
    with pytest.raises(ValueError, match="^result has id 2 more than once in frame 99998 "):
        check_unique_ids(group_by_frame(rows), "result")
