"""Kernels that split stacked rows into runs by an int32 ``lengths`` array refuse lengths that
do not split them: a negative length, or lengths whose int32 sum wraps to the row count.

Both passed a check of ``lengths.sum() == rows`` (summed in int32): a negative length made a
run start before the previous one and read past the end of ``z`` (results changed from one
call to the next), and ``{2**31 - 1, 2**31 - 1, 8}`` summed to 6, then sized scratch for a run
of 2**31 points (std::bad_alloc, or the process killed for memory) or read past the rows.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from pftrack import _core

BIG = 2**31 - 1
H = np.hstack([np.eye(2), np.zeros((2, 2))])
SEG_A = np.array([[0.0, 0, 0], [1, 1, 1]])
SEG_B = np.array([[5.0, 5, 5], [6, 6, 6]])


def _lengths(*values: int) -> np.ndarray:
    return np.array(values, np.int32)


def _noise(lengths: np.ndarray) -> Any:
    return _core.noise_loglik_grid(np.arange(6.0), lengths, np.ones(1), np.ones(1))


def _state(lengths: np.ndarray) -> Any:
    return _core.state_loglik_batch(np.arange(6.0), lengths, np.eye(2), np.eye(2), np.ones(1), 1e6)


def _gdt(a_len: np.ndarray, b_len: np.ndarray) -> Any:
    return _core.gdt_recover_batch(
        SEG_A, a_len, SEG_B, b_len, np.eye(4), np.eye(4), H, np.eye(2), 1.0, "first_point", 1,
        True,
    )  # fmt: skip


@pytest.mark.parametrize("fn", [_noise, _state])
def test_a_negative_length_is_refused(fn):
    with pytest.raises(ValueError, match=r"lengths\[0\] is -4, expected >= 0"):
        fn(_lengths(-4, 10))


@pytest.mark.parametrize("fn", [_noise, _state])
def test_lengths_whose_int32_sum_wraps_are_refused(fn):
    with pytest.raises(ValueError, match=r"sum\(lengths\) is 4294967302, expected 6"):
        fn(_lengths(BIG, BIG, 8))


def test_gdt_recover_batch_checks_its_segment_lengths():
    with pytest.raises(ValueError, match=r"sum\(a_len\) is 4294967298, expected 2"):
        _gdt(_lengths(BIG, BIG, 4), _lengths(1, 1, 0))
    with pytest.raises(ValueError, match=r"b_len\[1\] is -1, expected >= 0"):
        _gdt(_lengths(1, 1), _lengths(3, -1))


def test_lengths_that_split_the_rows_still_work():
    # the same values as before the check changed: runs of 6, and of 2 + 4 (the first skipped)
    np.testing.assert_array_equal(_noise(_lengths(6)), _noise(_lengths(0, 6)))
    assert np.isfinite(_state(_lengths(2, 4))).all()
    assert _gdt(_lengths(1, 1), _lengths(1, 1)).shape == (8, 2)  # 4 frames inside each gap
