"""pftrack.boxes: IoU against a loop over pairs, and the two box layouts."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack.boxes import (
    cxcywh_to_xywh,
    intersection_xywh,
    iou_xywh,
    iou_xywh_rows,
    xywh_to_cxcywh,
)


def _iou_loop(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.zeros((len(a), len(b)))
    for i, (ax, ay, aw, ah) in enumerate(a):
        for j, (bx, by, bw, bh) in enumerate(b):
            iw = max(0.0, min(ax + aw, bx + bw) - max(ax, bx))
            ih = max(0.0, min(ay + ah, by + bh) - max(ay, by))
            union = aw * ah + bw * bh - iw * ih
            out[i, j] = iw * ih / union if union > 0 else 0.0
    return out


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6), m=st.integers(0, 6))
def test_iou_matches_loop(seed, n, m):
    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (m, 2)), rng.uniform(0, 30, (m, 2))])
    got = iou_xywh(a, b)
    assert got.shape == (n, m) and got.dtype == np.float64
    np.testing.assert_allclose(got, _iou_loop(a, b), atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6), m=st.integers(0, 6))
def test_intersection_matches_loop(seed, n, m):
    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (m, 2)), rng.uniform(0, 30, (m, 2))])
    want = np.zeros((n, m))
    for i, (ax, ay, aw, ah) in enumerate(a):
        for j, (bx, by, bw, bh) in enumerate(b):
            iw = max(0.0, min(ax + aw, bx + bw) - max(ax, bx))
            ih = max(0.0, min(ay + ah, by + bh) - max(ay, by))
            want[i, j] = iw * ih
    got = intersection_xywh(a, b)
    assert got.shape == (n, m) and got.dtype == np.float64
    np.testing.assert_allclose(got, want, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6))
def test_iou_rows_is_the_diagonal_bit_for_bit(seed, n):
    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    got = iou_xywh_rows(a, b)
    assert got.shape == (n,) and got.dtype == np.float64
    np.testing.assert_array_equal(got, np.diagonal(iou_xywh(a, b)))
    np.testing.assert_allclose(got, np.diagonal(_iou_loop(a, b)), atol=1e-12)
    with pytest.raises(ValueError, match="as many"):
        iou_xywh_rows(a, np.zeros((n + 1, 4)))


def test_iou_special_cases():
    box = np.array([[10.0, 20, 4, 6]])
    np.testing.assert_array_equal(iou_xywh(box, box), [[1.0]])
    np.testing.assert_array_equal(iou_xywh(box, box + [4, 0, 0, 0]), [[0.0]])  # touching edges
    np.testing.assert_array_equal(
        iou_xywh(np.zeros((1, 4)), np.zeros((1, 4))), [[0.0]]
    )  # empty union
    np.testing.assert_allclose(iou_xywh(box, [[12.0, 20, 4, 6]]), [[12 / 36]])
    assert iou_xywh([1, 2, 3, 4], np.zeros((0, 4))).shape == (1, 0)


def test_layout_conversions():
    xywh = np.array([[10.0, 20, 4, 6], [0, 0, 1, 1]])
    c = xywh_to_cxcywh(xywh)
    np.testing.assert_array_equal(c, [[12, 23, 4, 6], [0.5, 0.5, 1, 1]])
    np.testing.assert_array_equal(cxcywh_to_xywh(c), xywh)
    np.testing.assert_array_equal(xywh_to_cxcywh([2, 2, 2, 2]), [3, 3, 2, 2])  # any leading shape
    assert cxcywh_to_xywh(np.zeros((3, 5, 4))).shape == (3, 5, 4)
