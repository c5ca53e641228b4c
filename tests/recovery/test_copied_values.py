"""``copied_values``: which values of a filled file are copies of given ones, against NumPy."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.recovery import fill_gaps
from pftrack.recovery.fill import copied_values


def _reference(rows: np.ndarray, filled: np.ndarray) -> np.ndarray:
    """The straightforward NumPy answer: every given (frame, id) row, and columns 7-10."""
    given = {(int(f), int(i)) for f, i in rows[:, :2]}
    mask = np.zeros(filled.shape, bool)
    mask[:, 6:] = True
    mask[[(int(f), int(i)) in given for f, i in filled[:, :2]]] = True
    return mask


@pytest.mark.parametrize("seed", range(4))
def test_copied_values_are_the_given_rows_and_the_marks(seed: int) -> None:
    """Was ``np.isin`` (which imports ``numpy.ma``); now a sorted search: the same mask."""
    rng = np.random.default_rng(seed)
    rows = []
    for tid in range(1, 8):
        start = int(rng.integers(1, 40))
        frames = np.arange(start, start + int(rng.integers(10, 60)))
        keep = rng.random(len(frames)) > 0.3
        keep[[0, -1]] = True
        for f in frames[keep]:
            rows.append([f, tid, *rng.uniform(0, 500, 2), 40, 80, 1, -1, -1, -1])
    given = np.array(rows, float)
    filled, _ = fill_gaps(given, "linear")
    assert len(filled) > len(given)  # holes were filled
    np.testing.assert_array_equal(copied_values(given, filled), _reference(given, filled))
    none = copied_values(given[:0], filled)  # nothing given: the marks alone
    np.testing.assert_array_equal(none, _reference(given[:0], filled))
    assert copied_values(given, filled[:0]).shape == (0, 10)
