"""The padded cost matrices :func:`pftrack.tracking.association.associate` keeps between frames."""

from __future__ import annotations

import numpy as np

from pftrack.tracking import association


def test_the_kept_padding_matrices_stay_small_in_a_long_run_of_crowds() -> None:
    # was: every (tracks, detections) shape kept, up to 256 of them: a service tracking crowds
    # of 150-180 people held 213 MB of them after 60 frames, 32 MB for each 1000 + 1000 shape
    association._PADDING.clear()
    try:
        for n in range(150, 180):
            for extra in (0, 7):
                padded = association._padding(n, n + extra, 3.0)
                assert padded.shape == (2 * n + extra, 2 * n + extra)
        for n in range(1, 30):  # the small matrices of ordinary scenes are still kept
            association._padding(n, n + 1, 3.0)
        kept = sum(p.nbytes for p in association._PADDING.values())
        assert kept <= 16 * 2**20
        assert kept <= association._PADDING_KEPT * association._PADDING_LARGEST
        assert association._padding(5, 6, 3.0) is association._padding(5, 6, 3.0)
    finally:
        association._PADDING.clear()


def test_a_padding_matrix_too_large_to_keep_is_the_same_matrix() -> None:
    nt, nd, tau = 120, 90, 2.5
    padded = association._padding(nt, nd, tau)
    assert not padded.flags.writeable
    want = np.full((nt + nd, nd + nt), association.FORBIDDEN)
    want[np.arange(nt), nd + np.arange(nt)] = tau
    want[nt + np.arange(nd), np.arange(nd)] = tau
    want[nt:, nd:] = 0.0
    np.testing.assert_array_equal(padded, want)
