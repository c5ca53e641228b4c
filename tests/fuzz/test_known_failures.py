"""Minimal failing inputs the fuzz suite found in code it does not own (recovery/, offline.py).

Each is what the call should do; all were fixed by bounded, checked input in recovery and the
offline pass (``check_rows``), and stay here as regression tests.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from pftrack.eval import evaluate_mot
from pftrack.recovery import fill_gaps, link_tracklets
from pftrack.tracking import BoxSmoother, smooth_tracks

ROWS = np.array([[1, 1, 0, 0, 10, 10, 1, -1, -1, -1], [5, 1, 4, 4, 10, 10, 1, -1, -1, -1.0]])


def _with(col: int, value: float, row: int = 0) -> Any:
    r = ROWS.copy()
    r[row, col] = value
    return r


CASES = {
    "smooth_tracks NaN frame": (lambda: smooth_tracks(_with(0, np.nan)), "frame"),
    "smooth_tracks (N, 2) rows": (lambda: smooth_tracks(np.ones((4, 2))), "column"),
    "smooth_tracks 5 columns": (lambda: smooth_tracks(ROWS[:, :5]), "column"),
    "smooth_tracks id 2.5": (lambda: smooth_tracks(_with(1, 2.5)), "id"),
    "smooth_tracks id 1e19": (lambda: smooth_tracks(_with(1, 1e19)), "id"),
    "link_tracklets 5 columns": (lambda: link_tracklets(ROWS[:, :5]), "column"),
    "link_tracklets id 2.5": (lambda: link_tracklets(_with(1, 2.5)), "id"),
    "link_tracklets NaN box": (lambda: link_tracklets(_with(2, np.nan)), "NaN"),
    "fill_gaps NaN frame": (lambda: fill_gaps(_with(0, np.nan), "linear"), "frame"),
    "BoxSmoother(size_noise=1e308)": (
        lambda: BoxSmoother(size_noise=1e308).smooth(
            np.array([1, 2, 3]), np.full((3, 4), 10.0), np.ones(3, bool)
        ),
        "size_noise",
    ),
    "BoxSmoother(accel=5e-324)": (lambda: BoxSmoother(accel=5e-324), "accel"),
    # found by the long fuzz run on the sanitized build: 1e308 frames and ids reached an int cast
    "evaluate_mot frame 1e308": (lambda: evaluate_mot(ROWS[:0], _with(0, 1e308)), "beyond"),
    "evaluate_mot id 1e308": (lambda: evaluate_mot(ROWS, _with(1, 1e308)), "frame or id"),
    "evaluate_mot complex rows": (
        lambda: evaluate_mot(ROWS, ROWS.astype(complex)),
        "must hold real numbers",
    ),
    "BoxSmoother.smooth NaN frame": (
        lambda: BoxSmoother().smooth(np.array([np.nan]), np.full((1, 4), 10.0), np.ones(1, bool)),
        "frames",
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_refused_with_a_message(name: str) -> None:
    fn, word = CASES[name]
    with pytest.raises((ValueError, TypeError), match=word):
        fn()
