"""``pftrack.recovery.baselines``' public functions check what they are given.

Were (developer trial, 5 December): lists failed with "list indices must be integers or
slices, not tuple", segment B before A with SciPy's or NumPy's own error (or a path), frames
outside the gap were extrapolated. The recovery's own calls use the unchecked private
versions (``_BASELINES``, ``_rts_batch``, ``_interpolate_sizes``), as ``_estimate_noise``.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from pftrack.recovery import baselines as bl
from pftrack.recovery.registry import recover_gaps

_T = np.arange(1.0, 21.0)
_A = np.column_stack([_T, 10 + 1.5 * _T + 0.1 * np.sin(_T), 50 + 0.05 * _T**2, 30 + 0 * _T,
                      80 + 0 * _T])  # fmt: skip
_B = _A.copy()
_B[:, 0] += 30
_B[:, 1] += 48
_B[:, 3:] += 4
NAMES = ("linear", "cubic", "bspline", "gsi", "rts")


@pytest.mark.parametrize("name", NAMES)
def test_lists_give_the_arrays_path(name):
    fn = bl.BASELINES[name]
    want = fn(_A, _B, np.arange(21, 31))
    np.testing.assert_array_equal(fn(_A.tolist(), _B.tolist()), want)  # every frame of the gap
    np.testing.assert_array_equal(bl._BASELINES[name](_A, _B, np.arange(21, 31)), want)
    some = np.array([21, 22], dtype=np.int64)  # gsi's path depends on the frames filled
    np.testing.assert_array_equal(
        fn(_A[:, :3].tolist(), _B[:, :3], [21, 22]), bl._BASELINES[name](_A, _B, some)
    )
    assert fn(_A, _B, []).shape == (0, 2)


@pytest.mark.parametrize("name", NAMES)
def test_segment_b_before_a_is_refused_in_one_line(name):
    fn = bl.BASELINES[name]
    with pytest.raises(
        ValueError,
        match=f"^{name}: segment_b starts at frame 1, expected after segment_a's end 50$",
    ):
        fn(_B, _A)
    with pytest.raises(ValueError, match=f"^{name}: frames must lie strictly between 20 and 31$"):
        fn(_A, _B, [20, 21])
    with pytest.raises(TypeError, match=f"^{name}: segment_a must hold real numbers"):
        fn([["a", 1, 2]], _B)
    with pytest.raises(ValueError, match=rf"^{name}: segment_b must have shape \(k, 3\) or"):
        fn(_A, _B[:, :2])


def test_interpolate_sizes_and_rts_batch_are_checked():
    np.testing.assert_array_equal(
        bl.interpolate_sizes(_A.tolist(), _B.tolist()),
        bl._interpolate_sizes(_A, _B, np.arange(21, 31)),
    )
    assert bl.interpolate_sizes(_A[:, :3], _B) is None
    with pytest.raises(ValueError, match="^interpolate_sizes: segment_b starts at frame 1"):
        bl.interpolate_sizes(_B, _A)
    got = bl.rts_batch([(_A.tolist(), _B.tolist()), (_A, _B)])
    np.testing.assert_array_equal(got[0], bl.rts(_A, _B))
    np.testing.assert_array_equal(got[1], bl._rts_batch([(_A, _B)])[0])
    assert bl.rts_batch([]) == []
    with pytest.raises(
        ValueError, match=r"^rts_batch: pairs\[1\]: segment_b starts at frame 1, expected after"
    ):
        bl.rts_batch([(_A, _B), (_B, _A)])
    with pytest.raises(ValueError, match=r"^rts_batch: pairs\[0\] is not a pair"):
        bl.rts_batch((_A, _B))  # one pair given for the sequence
    with pytest.raises(TypeError, match="^rts_batch: pairs must be a sequence of"):
        bl.rts_batch(iter([(_A, _B)]))


# (call, error, the whole one-line message)
OPTIONS = [
    (lambda: bl.cubic(_A, _B, window=0), ValueError,
     "cubic: window is 0, expected an integer in [1, 2147483647]"),
    (lambda: bl.bspline(_A, _B, spacing=2.0), TypeError,
     "bspline: spacing must be an integer in [1, 2147483647], got float 2.0"),
    (lambda: bl.gsi(_A, _B, tau=0), ValueError, "gsi: tau is 0, expected a finite number > 0"),
    (lambda: bl.rts(_A, _B, q="1"), TypeError, "rts: q must be a number, got str '1'"),
    (lambda: bl.rts(_A, _B, r=0.0), ValueError, "rts: r is 0, expected a finite number > 0"),
    (lambda: bl.rts_batch([(_A, _B)], history=0), ValueError,
     "rts_batch: history is 0, expected an integer in [1, 2147483647]"),
]  # fmt: skip


@pytest.mark.parametrize(("call", "error", "message"), OPTIONS)
def test_options_are_checked(call, error, message):
    with pytest.raises(error, match=f"^{re.escape(message)}$"):
        call()


def test_recover_gaps_gives_the_same_path_as_the_public_baseline():
    """The recovery's own (unchecked) calls and the public functions agree."""
    for name in NAMES:
        (got,) = recover_gaps([(_A, _B)], name)
        np.testing.assert_allclose(got[:, :2], bl.BASELINES[name](_A, _B), rtol=0, atol=0)
