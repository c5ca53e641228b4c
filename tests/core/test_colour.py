"""hsv_bins, box_histograms and the Bhattacharyya kernels against tests/reference.py."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from pftrack import _core
from pftrack.particle_filter import (
    HsvBinning,
    bhattacharyya_coefficient,
    bhattacharyya_distance,
    bhattacharyya_weights,
    box_histograms,
    hsv_bins,
)
from tests.reference import kernels as ref

frames = hnp.arrays(
    np.uint8,
    st.tuples(st.integers(1, 24), st.integers(1, 24), st.just(3)),
    elements=st.integers(0, 255),
)


@settings(max_examples=60, deadline=None)
@given(frames, st.integers(1, 16), st.integers(1, 16), st.integers(1, 16),
       st.floats(0, 1), st.floats(0, 1))  # fmt: skip
def test_hsv_bins_matches_reference(frame, n_h, n_s, n_v, s_min, v_min):
    binning = HsvBinning(n_h, n_s, n_v, s_min, v_min)
    got = hsv_bins(frame, binning=binning)
    assert got.n_bins == n_h * n_s + n_v
    np.testing.assert_array_equal(got.bins, ref.hsv_bins(frame, None, n_h, n_s, n_v, s_min, v_min))


def test_hsv_bins_every_colour_cube_corner():
    # All 256^3 colours would be slow; a 1/5-stride lattice covers every hue sector and edge.
    v = np.arange(0, 256, 5, dtype=np.uint8)
    b, g, r = np.meshgrid(v, v, v, indexing="ij")
    frame = np.stack([b, g, r], axis=-1).reshape(-1, len(v), 3)
    np.testing.assert_array_equal(hsv_bins(frame).bins, ref.hsv_bins(frame))


def test_hsv_bins_mask_marks_background(textured_frame, rng):
    mask = (rng.random(textured_frame.shape[:2]) > 0.5).astype(np.uint8)
    got = hsv_bins(textured_frame, mask).bins
    np.testing.assert_array_equal(got, ref.hsv_bins(textured_frame, mask))
    assert np.all(got[mask == 0] == -1) and np.all(got[mask == 1] >= 0)
    np.testing.assert_array_equal(hsv_bins(textured_frame, mask.astype(bool)).bins, got)


def test_hsv_bins_sparse_mask(textured_frame):
    # masked pixels are binned one by one and empty runs of 8 mask bytes skipped: blobs, empty
    # rows, pixels at both row ends, a width that is no multiple of 8, a strided mask
    frame = textured_frame[:, :61]
    mask = np.zeros((frame.shape[0], 64), np.uint8)
    mask[3:9, 10:23] = 255
    mask[12, 0] = mask[12, 60] = mask[13, 59] = 1
    mask[20:, 7:9] = 255
    view = mask[:, :61]
    got = hsv_bins(frame, view).bins
    np.testing.assert_array_equal(got, ref.hsv_bins(frame, view))
    assert (got[view > 0] >= 0).all() and (got[view == 0] == -1).all()
    assert (hsv_bins(frame, np.zeros(frame.shape[:2], np.uint8)).bins == -1).all()


def test_hsv_bins_of_a_strided_view(textured_frame):
    view = textured_frame[5:50, 10:70]  # rows strided, pixels packed
    np.testing.assert_array_equal(hsv_bins(view).bins, ref.hsv_bins(view))
    flipped = textured_frame[:, ::-1]  # pixels not packed: copied once by the wrapper
    np.testing.assert_array_equal(hsv_bins(flipped).bins, ref.hsv_bins(flipped))


def test_hsv_bins_of_rows_flipped_or_broadcast(textured_frame):
    # pixels packed, rows at a negative or zero stride (np.flipud, np.broadcast_to): the core
    # takes rows at a positive stride only; the wrapper copies (was "frame pixels must be
    # packed", of pixels that are)
    upside_down = textured_frame[::-1]
    np.testing.assert_array_equal(hsv_bins(upside_down).bins, ref.hsv_bins(upside_down))
    one_row = np.broadcast_to(textured_frame[:1], textured_frame.shape)
    np.testing.assert_array_equal(hsv_bins(one_row).bins, ref.hsv_bins(one_row))
    lazy = hsv_bins(upside_down, lazy=True)
    np.testing.assert_array_equal(lazy.bins, ref.hsv_bins(upside_down))


def test_pure_colours_land_in_expected_bins():
    frame = np.array([[[0, 0, 255], [0, 255, 0], [255, 0, 0], [0, 0, 0], [255, 255, 255]]],
                     dtype=np.uint8)  # fmt: skip
    bins = hsv_bins(frame).bins[0]
    # red: hue 0 -> h bin 0, s = 1 -> s bin 9; green: 120 deg -> 3; blue: 240 deg -> 6
    assert bins.tolist() == [9, 39, 69, 100, 109]


def _frame():
    rng = np.random.default_rng(5)
    frame = rng.integers(0, 256, (72, 96, 3), dtype=np.uint8)
    frame[10:40, 20:40] = (30, 40, 200)
    return frame


boxes = st.lists(
    st.tuples(st.floats(-20, 120), st.floats(-20, 100), st.floats(0, 60), st.floats(0, 60)),
    min_size=1, max_size=8,
)  # fmt: skip


@settings(max_examples=60, deadline=None)
@given(boxes, st.sampled_from(["uniform", "epanechnikov"]), st.booleans())
def test_box_histograms_match_reference(box_list, kernel, masked):
    textured_frame = _frame()
    mask = None
    if masked:
        mask = np.zeros(textured_frame.shape[:2], np.uint8)
        mask[10:60, 15:70] = 1
    image = hsv_bins(textured_frame, mask)
    b = np.array(box_list)
    got = box_histograms(image, b, kernel)
    want = ref.box_histograms(image.bins, image.n_bins, b, kernel)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    sums = got.sum(axis=1)
    assert np.all(np.isclose(sums, 1.0) | (sums == 0.0))


@settings(max_examples=60, deadline=None)
@given(boxes, st.sampled_from(["uniform", "epanechnikov"]), st.booleans(), st.floats(0, 50))
def test_fused_box_weights_match_reference(box_list, kernel, masked, lam):
    textured_frame = _frame()
    mask = None
    if masked:
        mask = np.zeros(textured_frame.shape[:2], np.uint8)
        mask[10:60, 15:70] = 1
    image = hsv_bins(textured_frame, mask)
    b = np.array(box_list)
    r = ref.box_histograms(image.bins, image.n_bins, np.array([[30.0, 25.0, 30.0, 40.0]]))[0] + 1e-3
    hists = ref.box_histograms(image.bins, image.n_bins, b, kernel)
    want = ref.bhattacharyya_weights(hists, r, lam)
    got = _core.box_weights(image, b, r, lam, kernel)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-300)
    two_calls = _core.bhattacharyya_weights(box_histograms(image, b, kernel), r, lam)
    np.testing.assert_allclose(got, two_calls, rtol=1e-9, atol=1e-300)


def test_box_weights_bad_input():
    image = hsv_bins(_frame())
    r = np.ones(image.n_bins)
    with pytest.raises(ValueError, match="boxes rows"):
        _core.box_weights(image, np.zeros((0, 4)), r)
    with pytest.raises(ValueError, match="ref size"):
        _core.box_weights(image, np.ones((2, 4)), r[:-1])
    with pytest.raises(ValueError, match="lambda"):
        _core.box_weights(image, np.ones((2, 4)), r, -1.0)
    with pytest.raises(ValueError, match=r"boxes\[1\]"):
        _core.box_weights(image, np.array([[1.0, 1, 1, 1], [np.nan, 1, 1, 1]]), r)
    with pytest.raises(ValueError, match="kernel"):
        _core.box_weights(image, np.ones((2, 4)), r, 20.0, "gauss")


def test_bhattacharyya_rejects_bad_histogram_entries():
    r = np.ones(4)
    for bad in (-0.5, np.nan, np.inf):
        h = np.full((3, 4), 0.25)
        h[2, 1] = bad
        with pytest.raises(ValueError, match=r"hists\[2, 1\]"):
            _core.bhattacharyya_coefficient(h, r)


def test_empty_box_gives_zero_histogram_and_distance_one(textured_frame):
    image = hsv_bins(textured_frame)
    h = box_histograms(image, [[-500, -500, 20, 50], [40, 30, 0, 0]])
    assert np.all(h == 0)
    r = h[0] + 1.0
    np.testing.assert_array_equal(bhattacharyya_coefficient(h, r), [0.0, 0.0])
    np.testing.assert_array_equal(bhattacharyya_distance(h, r), [1.0, 1.0])


def test_box_fully_in_background_is_empty(textured_frame):
    mask = np.zeros(textured_frame.shape[:2], np.uint8)
    mask[:, :10] = 1
    image = hsv_bins(textured_frame, mask)
    assert np.all(box_histograms(image, [[50, 40, 20, 20]]) == 0)
    assert box_histograms(image, [[5, 40, 20, 20]]).sum() == pytest.approx(1.0)


def test_bhattacharyya_kernels_match_reference(rng):
    hists = rng.random((30, 110))
    hists /= hists.sum(axis=1, keepdims=True)
    r = rng.random(110) * 3  # unnormalised reference is normalised by the kernels
    np.testing.assert_allclose(
        bhattacharyya_coefficient(hists, r), ref.bhattacharyya_coefficient(hists, r), rtol=1e-12
    )
    np.testing.assert_allclose(
        bhattacharyya_distance(hists, r), ref.bhattacharyya_distance(hists, r), rtol=1e-10
    )
    for lam in (1.0, 20.0, 1e4):
        w = bhattacharyya_weights(hists, r, lam)
        np.testing.assert_allclose(
            w, ref.bhattacharyya_weights(hists, r, lam), rtol=1e-9, atol=1e-300
        )
        assert w.sum() == pytest.approx(1.0)


def test_histogram_rows_are_normalised_as_the_reference(rng):
    """``H*2`` gave other weights than ``H``, integer counts near-uniform ones: only `ref` was
    normalised. Each row of `hists` is now normalised too (by the public functions)."""
    hists = rng.random((4, 110))
    hists /= hists.sum(axis=1, keepdims=True)
    r = rng.random(110)
    want = bhattacharyya_weights(hists, r)
    counts = np.round(hists * rng.integers(50, 5000, size=(4, 1)))  # pixel counts, per box
    np.testing.assert_allclose(bhattacharyya_weights(hists * 2, r), want, rtol=1e-12)
    np.testing.assert_allclose(
        bhattacharyya_weights(counts, r),
        ref.bhattacharyya_weights(counts / counts.sum(axis=1, keepdims=True), r),
        rtol=1e-9,
    )
    np.testing.assert_allclose(
        bhattacharyya_coefficient(hists * 7, r), ref.bhattacharyya_coefficient(hists, r), rtol=1e-12
    )
    np.testing.assert_allclose(
        bhattacharyya_distance(counts.astype(np.int64), r * 3),
        ref.bhattacharyya_distance(counts / counts.sum(axis=1, keepdims=True), r),
        rtol=1e-9,
    )
    zero = bhattacharyya_distance(np.vstack([np.zeros(110), hists[0]]), r)
    assert zero[0] == 1.0  # a box with no pixel counted: rho 0
    with pytest.raises(ValueError, match=r"hists row 1 sum is not finite \(overflow"):
        bhattacharyya_weights(np.vstack([hists[0], np.full(110, 1e307)]), r)


@pytest.mark.parametrize(
    ("lam", "error", "match"),
    [
        ("20", TypeError, "lam must be a real number, got str '20'"),
        (None, TypeError, "lam must be a real number, got NoneType"),
        (True, TypeError, "lam must be a real number, got bool"),
        (1j, TypeError, "lam must be a real number, got complex"),
        (0, ValueError, "lam is 0, expected a finite number > 0"),
        (-1.0, ValueError, "lam is -1.0"),
        (float("nan"), ValueError, "lam is nan"),
        (float("inf"), ValueError, "lam is inf"),
    ],
)
def test_weights_lambda_is_checked(lam, error, match):
    h = np.full((2, 4), 0.25)
    with pytest.raises(error, match=f"bhattacharyya_weights: {match}"):
        bhattacharyya_weights(h, np.ones(4), lam=lam)
    assert bhattacharyya_weights(h, np.ones(4), lam=np.float32(3)).shape == (2,)


def test_weights_are_stable_for_huge_lambda(rng):
    hists = rng.random((5, 10))
    hists /= hists.sum(axis=1, keepdims=True)
    w = bhattacharyya_weights(hists, hists[2], lam=1e8)  # exp(-1e8 D^2) underflows naively
    assert np.all(np.isfinite(w)) and w[2] == pytest.approx(1.0)


def test_identical_histogram_has_coefficient_one(textured_frame):
    image = hsv_bins(textured_frame)
    h = box_histograms(image, [[30, 25, 20, 30]])
    assert bhattacharyya_coefficient(h, h[0])[0] == pytest.approx(1.0)
    assert bhattacharyya_distance(h, h[0])[0] == pytest.approx(0.0, abs=1e-7)


def test_binned_image_from_user_array():
    bins = np.array([[0, 1, -1], [2, 2, 2]], dtype=np.int16)
    image = _core.BinnedImage(bins, 3)
    np.testing.assert_array_equal(image.bins, bins)
    assert not image.bins.flags.writeable
    np.testing.assert_allclose(box_histograms(image, [[1, 1, 4, 4]])[0], [1 / 5, 1 / 5, 3 / 5])
