"""median_frames (the background's start) against a NumPy sort and numpy.median."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack import _core
from tests.reference.detection import median_frames_reference


@pytest.mark.parametrize("m", [1, 2, 3, 4, 7, 30])
def test_median_frames_matches_reference_and_numpy(m: int) -> None:
    rng = np.random.default_rng(m)
    frames = [rng.integers(0, 256, (9, 13, 3), dtype=np.uint8) for _ in range(m)]
    frames[0][0, 0] = 255  # the extremes of the range
    frames[-1][0, 1] = 0
    got = _core.median_frames(frames)
    assert got.dtype == np.float32 and got.shape == (9, 13, 3)
    np.testing.assert_array_equal(got, median_frames_reference(frames))
    np.testing.assert_array_equal(got, np.median(np.stack(frames), axis=0).astype(np.float32))


@pytest.mark.parametrize("threads", [2, 3, 8, 64])
def test_median_frames_threads_give_the_same_values(threads: int) -> None:
    """Bands of rows on threads (more threads than rows too): the one-thread values."""
    rng = np.random.default_rng(threads)
    for rows in (1, 5, 37):
        frames = [rng.integers(0, 256, (rows, 23, 3), dtype=np.uint8) for _ in range(9)]
        frames[3] = np.repeat(frames[3], 2, axis=0)[::2]  # a view with strided rows among them
        np.testing.assert_array_equal(
            _core.median_frames(frames, threads), _core.median_frames(frames)
        )
    with pytest.raises(ValueError, match="threads is 0"):
        _core.median_frames(frames, 0)


def test_median_frames_of_views_and_ties() -> None:
    rng = np.random.default_rng(5)
    big = rng.integers(0, 256, (4, 12, 20, 3), dtype=np.uint8)
    views = [f[2:10, 3:17] for f in big]  # strided rows
    np.testing.assert_array_equal(
        _core.median_frames(views), median_frames_reference([v.copy() for v in views])
    )
    same = [np.full((2, 3, 3), 7, np.uint8)] * 5
    np.testing.assert_array_equal(_core.median_frames(same), np.full((2, 3, 3), 7.0, np.float32))


def test_median_frames_checks_its_arguments() -> None:
    f = np.zeros((4, 5, 3), np.uint8)
    with pytest.raises(ValueError, match="frames is empty"):
        _core.median_frames([])
    with pytest.raises(ValueError, match=r"frames\[1\] shape is \(4, 6, 3\), expected \(4, 5, 3\)"):
        _core.median_frames([f, np.zeros((4, 6, 3), np.uint8)])
    # a wrong dtype or type: TypeError, as the Python layer's (were ValueError)
    with pytest.raises(TypeError, match=r"frames\[0\] dtype is float64"):
        _core.median_frames([f.astype(np.float64)])
    with pytest.raises(TypeError, match=r"frames\[0\] is list"):
        _core.median_frames([[1, 2, 3]])


@pytest.mark.parametrize("m", [2, 4, 6, 30, 64])
def test_median_frames_of_an_even_count_with_many_ties(m: int) -> None:
    """The upper middle value (found from the lower one in one pass): the lower one again
    when it repeats past the middle, else the least value above it."""
    rng = np.random.default_rng(m)
    frames = [(rng.integers(0, 4, (11, 17, 3)) * 85).astype(np.uint8) for _ in range(m)]
    frames[0][0, :2] = [[255, 255, 255], [0, 0, 0]]
    got = _core.median_frames(frames)
    np.testing.assert_array_equal(got, np.median(np.stack(frames), axis=0).astype(np.float32))
    assert 0 < np.mean(got % 85 == 0) < 1  # both: middle values equal, and apart
