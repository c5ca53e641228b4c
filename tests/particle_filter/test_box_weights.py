"""The public ``box_weights`` (the filters' fused histogram + Bhattacharyya weighting).

Was: only ``_core.box_weights``, which docs/kernels.md presented as the fastest path; called
directly, a raw frame or ``lam="3"`` gave pybind11's multi-line list of signatures.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pftrack
from pftrack import _core
from pftrack.particle_filter import (
    bhattacharyya_weights,
    box_histograms,
    box_weights,
    hsv_bins,
)
from tests.reference import kernels as ref


def _frame() -> np.ndarray:
    frame = np.random.default_rng(3).integers(0, 256, (80, 100, 3)).astype(np.uint8)
    frame[10:40, 20:40] = (30, 40, 200)
    return frame


_IMAGE = hsv_bins(_frame())
_REF = ref.box_histograms(_IMAGE.bins, _IMAGE.n_bins, np.array([[30.0, 25.0, 30.0, 40.0]]))[0]

boxes = st.lists(
    st.tuples(st.floats(-20, 120), st.floats(-20, 100), st.floats(0, 60), st.floats(0, 60)),
    min_size=1, max_size=8,
)  # fmt: skip


@settings(max_examples=60, deadline=None)
@given(boxes, st.sampled_from(["uniform", "epanechnikov"]), st.booleans(),
       st.floats(0.01, 50))  # fmt: skip
def test_box_weights_match_the_numpy_reference(box_list, kernel, masked, lam):
    mask = None
    if masked:
        mask = np.zeros((80, 100), np.uint8)
        mask[10:60, 15:70] = 1
    image = hsv_bins(_frame(), mask)
    r = _REF + 1e-3
    want = ref.bhattacharyya_weights(
        ref.box_histograms(image.bins, image.n_bins, np.array(box_list), kernel), r, lam
    )
    got = box_weights(image, box_list, r, lam, kernel)  # a list of tuples: array_like
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-300)
    two_calls = bhattacharyya_weights(box_histograms(image, box_list, kernel), r, lam)
    np.testing.assert_allclose(got, two_calls, rtol=1e-9, atol=1e-300)


def test_box_weights_is_the_cores_and_top_level():
    boxes = np.array([[30.0, 25, 20, 30], [60, 50, 20, 30], [-100, -100, 10, 10]])
    np.testing.assert_array_equal(
        box_weights(_IMAGE, boxes, _REF), _core.box_weights(_IMAGE, boxes, _REF, 20.0)
    )
    assert pftrack.box_weights is box_weights
    assert "box_weights" in pftrack.__all__
    # one box (4,) is one row, as box_histograms takes it; a float32 array is converted
    assert box_weights(_IMAGE, boxes[0].astype(np.float32), _REF).tolist() == [1.0]


_BOX = [[30.0, 25, 20, 30]]

# (call, error, the whole one-line message)
BAD = [
    # was pybind11's list of signatures, over several lines
    (lambda: box_weights(_frame(), _BOX, _REF), TypeError,
     "box_weights: image must be a BinnedImage from hsv_bins(frame), got ndarray (a frame? bin "
     "it first)"),
    (lambda: box_weights(_IMAGE, _BOX, _REF, lam="3"), TypeError,
     "box_weights: lam must be a real number, got str '3'"),
    (lambda: box_weights(_IMAGE, _BOX, _REF, kernel=None), TypeError,
     "box_weights: kernel must be 'uniform' or 'epanechnikov', got NoneType None"),
    (lambda: box_weights(_IMAGE, [["a", 1, 2, 3]], _REF), TypeError,
     "box_weights: boxes must hold real numbers, got dtype <U21"),
    # was accepted by the core (lam 0: every particle the same weight), as by FilterConfig
    (lambda: box_weights(_IMAGE, _BOX, _REF, lam=0), ValueError,
     "box_weights: lam is 0, expected a finite number > 0"),
    (lambda: box_weights(_IMAGE, [], _REF), ValueError,
     "box_weights: boxes has no rows: weights that sum to 1 need a particle"),
    (lambda: box_weights(_IMAGE, [[1.0, 2, 3]], _REF), ValueError,
     "box_weights: boxes cols is 3, expected 4 (cx, cy, w, h)"),
    (lambda: box_weights(_IMAGE, _BOX, _REF[:-1]), ValueError,
     "box_weights: ref size is 109, expected 110"),
    (lambda: box_weights(_IMAGE, _BOX, np.vstack([_REF, _REF])), ValueError,
     "box_weights: ref must have shape (B,), one histogram, got (2, 110)"),
    (lambda: box_weights(_IMAGE, _BOX, np.zeros(110)), ValueError,
     "box_weights: ref sums to 0 (an empty reference histogram: no bin counted)"),
    (lambda: box_weights(_IMAGE, [[1.0, 2, -3, 4]], _REF), ValueError,
     "box_weights: boxes[0] is (1, 2, -3, 4), expected finite (cx, cy, w, h) with w, h >= 0, "
     "each value within ±1e+09 px"),
    (lambda: box_weights(_IMAGE, _BOX, _REF, kernel="gauss"), ValueError,
     "box_weights: kernel is 'gauss', expected 'uniform' or 'epanechnikov'"),
]  # fmt: skip


@pytest.mark.parametrize(("call", "error", "message"), BAD)
def test_box_weights_refuses_in_one_line(call, error, message):
    with pytest.raises(error, match=f"^{re.escape(message)}$"):
        call()
