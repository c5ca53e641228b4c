"""The bins of a mask's pixels (`hsv_bins(frame, mask)`, the detector's kept foreground).

Since stop 71 a run of 8-pixel groups that each hold a masked pixel is binned whole by the AVX2
row pass (`HsvLut::bins_of_row`) and then masked; without AVX2 (or with `_core._set_avx2(False)`)
each masked pixel is binned one by one. Both are held to the NumPy reference.
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack import _core
from tests.reference.detection import hsv_bin_reference


@pytest.fixture(params=[True, False], ids=["avx2", "portable"])
def avx2(request: pytest.FixtureRequest):
    """Whether background.hpp's hand-written AVX2 passes may run: each test runs twice."""
    before = _core._set_avx2(request.param)
    yield request.param
    _core._set_avx2(before)


def masked_reference(frame: np.ndarray, mask: np.ndarray, **kw: float) -> np.ndarray:
    """hsv_bin_reference where the mask is not 0, -1 elsewhere."""
    return np.where(mask != 0, hsv_bin_reference(frame, **kw), -1).astype(np.int16)


@pytest.mark.parametrize("cols", [7, 8, 9, 16, 23, 24, 61, 480])
def test_masked_bins_of_runs_blobs_and_lone_pixels(cols, avx2):
    # runs of 8-pixel groups that end at the row's end or inside it, a group holding one lone
    # pixel, groups whose pixels are partly masked, an all-masked row, and the row's last
    # cols % 8 pixels (binned one by one either way)
    rng = np.random.default_rng(cols)
    frame = rng.integers(0, 256, size=(12, cols, 3), dtype=np.uint8)
    mask = np.zeros((12, cols), np.uint8)
    mask[0] = 255  # a whole row
    mask[1, ::3] = 1  # every third pixel: every group holds one
    mask[2, cols // 2 :] = 7  # a run to the row's end
    mask[3, 1 : max(cols - 5, 2)] = 255  # a run that starts and ends inside groups
    mask[4, cols - 1] = 255  # the last pixel alone
    mask[5, 0] = 1  # the first pixel alone
    mask[6:9] = rng.random((3, cols)) < 0.4  # blobs of noise
    for kw in ({}, {"n_h": 8, "n_s": 4, "n_v": 3, "s_min": 0.25, "v_min": 0.05}):
        got = _core.hsv_bins(frame, mask, **kw).bins
        np.testing.assert_array_equal(got, masked_reference(frame, mask, **kw))
        # the unmasked bins: the whole-row AVX2 pass, or the portable indices and look-ups
        want = hsv_bin_reference(frame, **kw)
        np.testing.assert_array_equal(_core.hsv_bins(frame, **kw).bins, want)


def test_masked_bins_of_a_strided_frame_and_mask(avx2):
    # a cropped frame (rows of another stride) and a mask view: the row pass reads only the
    # crop's bytes
    rng = np.random.default_rng(5)
    big = rng.integers(0, 256, size=(40, 100, 3), dtype=np.uint8)
    frame = big[5:35, 3:90]
    big_mask = (rng.random((40, 128)) < 0.5).astype(np.uint8) * 255
    big_mask[10:20, 20:70] = 255
    mask = big_mask[5:35, 3:90]
    got = _core.hsv_bins(frame, mask).bins
    np.testing.assert_array_equal(got, masked_reference(frame, mask))


def test_the_two_paths_give_the_same_bins_of_a_foreground():
    # a detector's kind of mask (a few dense blobs on a 360 x 480 frame), both paths the same
    rng = np.random.default_rng(71)
    frame = rng.integers(0, 256, size=(360, 480, 3), dtype=np.uint8)
    mask = np.zeros((360, 480), np.uint8)
    for y, x, h, w in ((40, 30, 90, 35), (200, 300, 120, 50), (10, 455, 60, 25)):
        mask[y : y + h, x : x + w] = 255
    before = _core._set_avx2(True)
    try:
        on = _core.hsv_bins(frame, mask).bins
        _core._set_avx2(False)
        off = _core.hsv_bins(frame, mask).bins
    finally:
        _core._set_avx2(before)
    np.testing.assert_array_equal(on, off)
    np.testing.assert_array_equal(on, masked_reference(frame, mask))
