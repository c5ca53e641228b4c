"""box_weights' integral-histogram path against the direct path and tests/reference.py.

The uniform-kernel counts of a group of overlapping boxes come from one integral histogram of
the group's union; they are exact integers, so every path must give bit-identical weights.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.particle_filter import hsv_bins
from tests.reference import kernels as ref

METHODS = ("auto", "direct", "integral")


def _image(rng: np.random.Generator, rows: int, cols: int, background: float):
    """A blocky random frame (runs of equal bins, as in real frames) with a random mask."""
    coarse = rng.integers(0, 256, (rows // 4 + 1, cols // 4 + 1, 3), dtype=np.uint8)
    frame = np.repeat(np.repeat(coarse, 4, axis=0), 4, axis=1)[:rows, :cols].copy()
    noisy = rng.random((rows, cols)) < 0.3
    frame[noisy] = rng.integers(0, 256, (int(noisy.sum()), 3), dtype=np.uint8)
    mask = (rng.random((rows, cols)) >= background).astype(np.uint8) if background > 0 else None
    return hsv_bins(frame, mask)


def _cloud(rng: np.random.Generator, centre, size, spread: float, n: int) -> np.ndarray:
    boxes = np.empty((n, 4))
    boxes[:, :2] = np.asarray(centre) + rng.normal(0.0, spread, (n, 2))
    boxes[:, 2:] = np.asarray(size) * rng.uniform(0.8, 1.25, (n, 1))
    return boxes


def _weights_all_paths(image, boxes, r, lam=30.0):
    """box_weights and box_histograms: every method bit-identical, and equal to the reference."""
    want_hists = ref.box_histograms(image.bins, image.n_bins, boxes)
    hists = {m: _core.box_histograms(image, boxes, "uniform", m) for m in METHODS}
    got = {m: _core.box_weights(image, boxes, r, lam, "uniform", m) for m in METHODS}
    want = ref.bhattacharyya_weights(want_hists, r, lam)
    for m in METHODS:
        np.testing.assert_array_equal(hists[m], hists["direct"], err_msg=m)
        np.testing.assert_allclose(hists[m], want_hists, rtol=1e-12, atol=1e-15, err_msg=m)
        np.testing.assert_array_equal(got[m], got["direct"], err_msg=m)
        np.testing.assert_allclose(got[m], want, rtol=1e-9, atol=1e-300, err_msg=m)
    return got["direct"]


def _reference_histogram(image, rng):
    return rng.random(image.n_bins) + 0.05


@pytest.mark.parametrize("background", [0.0, 0.3, 0.9])
def test_interleaved_clouds_with_edge_boxes(rng, background):
    image = _image(rng, 90, 120, background)
    r = _reference_histogram(image, rng)
    clouds = [
        _cloud(rng, (20, 30), (14, 30), 4.0, 60),  # near the top-left corner: clipped boxes
        _cloud(rng, (100, 70), (20, 20), 6.0, 60),  # partly beyond the right and bottom edges
        _cloud(rng, (60, 45), (3, 2), 2.0, 40),  # tiny boxes
        _cloud(rng, (-40, 200), (10, 10), 3.0, 10),  # wholly outside: empty, rho 0
    ]
    boxes = np.vstack(clouds)
    extra = np.array([[60.0, 45.0, 0.0, 0.0], [60.0, 45.0, 0.4, 0.4], [10.0, 10.0, 200.0, 200.0]])
    boxes = np.vstack([boxes, extra])
    _weights_all_paths(image, boxes, r)  # objects one after the other
    _weights_all_paths(image, boxes[rng.permutation(len(boxes))], r)  # interleaved


def test_each_path_is_taken_and_agrees(rng):
    """A dense cloud (integral under auto) and a few scattered boxes (direct under auto)."""
    image = _image(rng, 120, 160, 0.2)
    r = _reference_histogram(image, rng)
    dense = _cloud(rng, (80, 60), (20, 40), 3.0, 300)
    scattered = np.array([[10.0, 10.0, 8, 8], [150.0, 20.0, 8, 8], [20.0, 110.0, 8, 8]])
    for boxes in (dense, scattered, np.vstack([scattered, dense])):
        _weights_all_paths(image, boxes, r)


def test_boxes_on_few_corners_one_pixel_bands_and_repeats(rng):
    """The table is built at the boxes' corner rows and columns only (stop 70): boxes sharing
    their edges (few corners, bands of many pixels between them), corners one pixel apart
    (one-pixel bands), repeated boxes and one-pixel boxes all count as the reference does."""
    image = _image(rng, 100, 140, 0.3)
    r = _reference_histogram(image, rng)
    xs = rng.choice([3, 10, 11, 40, 41, 42, 90, 139], size=(120, 2))
    ys = rng.choice([0, 5, 6, 50, 70, 99], size=(120, 2))
    x0, x1 = xs.min(axis=1), xs.max(axis=1) + 1  # pixel ranges [x0, x1), never empty
    y0, y1 = ys.min(axis=1), ys.max(axis=1) + 1
    boxes = np.column_stack([(x0 + x1) / 2, (y0 + y1) / 2, x1 - x0, y1 - y0]).astype(float)
    boxes = np.vstack([boxes, boxes[:10], [[40.5, 50.5, 1.0, 1.0]]])
    _weights_all_paths(image, boxes, r)
    _weights_all_paths(image, boxes[rng.permutation(len(boxes))], r)


def test_boxes_too_large_for_uint16_counts_fall_back(rng):
    image = _image(rng, 300, 300, 0.1)
    r = _reference_histogram(image, rng)
    big = _cloud(rng, (150, 150), (270, 270), 3.0, 6)  # > 65535 pixels each
    small = _cloud(rng, (150, 150), (30, 30), 3.0, 30)
    _weights_all_paths(image, np.vstack([big, small]), r)


def test_regions_larger_than_the_table_cap(rng):
    image = _image(rng, 400, 400, 0.0)
    r = _reference_histogram(image, rng)
    boxes = np.column_stack([rng.uniform(0, 400, (300, 2)), rng.uniform(40, 120, (300, 2))])
    _weights_all_paths(image, boxes, r)


def test_all_boxes_empty_or_background(rng):
    image = _image(rng, 40, 50, 1.0)  # every pixel background
    r = _reference_histogram(image, rng)
    boxes = _cloud(rng, (25, 20), (10, 10), 2.0, 50)
    for m in METHODS:
        np.testing.assert_allclose(_core.box_weights(image, boxes, r, 20.0, "uniform", m), 1 / 50)


def test_epanechnikov_ignores_the_method(rng):
    image = _image(rng, 60, 80, 0.3)
    r = _reference_histogram(image, rng)
    boxes = _cloud(rng, (40, 30), (16, 24), 3.0, 50)
    want = ref.bhattacharyya_weights(
        ref.box_histograms(image.bins, image.n_bins, boxes, "epanechnikov"), r, 20.0
    )
    for m in METHODS:
        got = _core.box_weights(image, boxes, r, 20.0, "epanechnikov", m)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-300)
        hists = _core.box_histograms(image, boxes, "epanechnikov", m)
        np.testing.assert_array_equal(hists, _core.box_histograms(image, boxes, "epanechnikov"))


def test_bad_method_and_bad_boxes(rng):
    image = _image(rng, 30, 30, 0.0)
    r = np.ones(image.n_bins)
    with pytest.raises(ValueError, match="method"):
        _core.box_weights(image, np.ones((2, 4)), r, 20.0, "uniform", "fast")
    with pytest.raises(ValueError, match="method"):
        _core.box_histograms(image, np.ones((2, 4)), "uniform", "fast")
    for m in METHODS:
        with pytest.raises(ValueError, match=r"boxes\[2\]"):
            _core.box_weights(
                image, np.array([[5.0, 5, 4, 4]] * 2 + [[np.nan, 5, 4, 4]]), r, 20.0, "uniform", m
            )
        with pytest.raises(ValueError, match=r"boxes\[0\]"):
            _core.box_weights(image, np.array([[5.0, 5, -4, 4]]), r, 20.0, "uniform", m)


def test_threads_give_the_serial_result(rng):
    image = _image(rng, 120, 160, 0.2)
    r = _reference_histogram(image, rng)
    clouds = [_cloud(rng, (40 + 20 * k, 60), (20, 40), 4.0, 200) for k in range(4)]
    serial = [_core.box_weights(image, b, r, 20.0, "uniform", "integral") for b in clouds]
    with ThreadPoolExecutor(4) as pool:
        threaded = list(
            pool.map(
                lambda b: _core.box_weights(image, b, r, 20.0, "uniform", "integral"), clouds * 3
            )
        )
    for k, w in enumerate(threaded):
        np.testing.assert_array_equal(w, serial[k % 4])


cloud_spec = st.tuples(
    st.floats(-30, 90), st.floats(-30, 70),  # centre
    st.integers(0, 50), st.integers(0, 50),  # size
    st.floats(0, 12),  # spread
    st.integers(1, 40),  # boxes
)  # fmt: skip


@settings(max_examples=40, deadline=None)
@given(
    st.lists(cloud_spec, min_size=1, max_size=4),
    st.sampled_from([0.0, 0.5, 0.95]),
    st.booleans(),
    st.integers(0, 2**32 - 1),
)
def test_random_clouds_property(specs, background, shuffle, seed):
    rng = np.random.default_rng(seed)
    image = _image(rng, 64, 80, background)
    r = _reference_histogram(image, rng)
    boxes = np.vstack([_cloud(rng, (cx, cy), (w, h), s, n) for cx, cy, w, h, s, n in specs])
    if shuffle:
        boxes = boxes[rng.permutation(len(boxes))]
    _weights_all_paths(image, boxes, r)


@pytest.mark.parametrize("step", [2, 3])
@pytest.mark.parametrize("background", [0.0, 0.5])
def test_lattice_clouds_every_path_bit_identical(rng, step, background):
    """On a lattice too the table's counts are read in compact form (coefficient_of_compact):
    every method gives the direct path's weights bit for bit, and the reference's."""
    image = _image(rng, 120, 160, background)
    r = _reference_histogram(image, rng)
    boxes = np.vstack(
        [
            _cloud(rng, (50, 60), (30, 60), 5.0, 50),
            _cloud(rng, (120, 40), (40, 40), 8.0, 50),
            _cloud(rng, (150, 110), (24, 30), 4.0, 20),  # clipped at the corner
        ]
    )
    boxes = boxes[rng.permutation(len(boxes))]
    want = ref.bhattacharyya_weights(
        ref.box_histograms(image.bins, image.n_bins, boxes, "uniform", step), r, 30.0
    )
    got = {m: _core.box_weights(image, boxes, r, 30.0, "uniform", m, step) for m in METHODS}
    for m in METHODS:
        np.testing.assert_array_equal(got[m], got["direct"], err_msg=m)
        np.testing.assert_allclose(got[m], want, rtol=1e-9, atol=1e-300, err_msg=m)
