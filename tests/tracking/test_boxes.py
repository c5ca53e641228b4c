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
from tests.reference import boxes as ref


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6), m=st.integers(0, 6))
def test_iou_matches_loop(seed, n, m):
    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (m, 2)), rng.uniform(0, 30, (m, 2))])
    got = iou_xywh(a, b)
    assert got.shape == (n, m) and got.dtype == np.float64
    np.testing.assert_allclose(got, ref.iou_xywh(a, b), atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6), m=st.integers(0, 6))
def test_intersection_matches_loop(seed, n, m):
    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (m, 2)), rng.uniform(0, 30, (m, 2))])
    got = intersection_xywh(a, b)
    assert got.shape == (n, m) and got.dtype == np.float64
    np.testing.assert_allclose(got, ref.intersection_xywh(a, b), atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6))
def test_iou_rows_is_the_diagonal_bit_for_bit(seed, n):
    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    got = iou_xywh_rows(a, b)
    assert got.shape == (n,) and got.dtype == np.float64
    np.testing.assert_array_equal(got, np.diagonal(iou_xywh(a, b)))
    np.testing.assert_allclose(got, np.diagonal(ref.iou_xywh(a, b)), atol=1e-12)
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


@pytest.mark.parametrize(
    ("call", "match"),
    [
        # (n, 6) detections xywh, conf, cls were read as other boxes: a 2x6 pair gave 3x3 IoU
        (lambda a: iou_xywh(a, a), r"iou_xywh: a must have shape \(n, 4\).*got \(2, 6\)"),
        (lambda a: intersection_xywh(a[:, :4], a), r"intersection_xywh: b .*got \(2, 6\)"),
        (lambda a: iou_xywh_rows(a, a), r"iou_xywh_rows: a .*got \(2, 6\)"),
        (lambda a: iou_xywh(np.ones((4, 3)), a[:, :4]), r"got \(4, 3\)"),  # was 3 boxes
        (lambda a: iou_xywh(np.ones(7), a[:, :4]), r"got \(7,\)"),  # was numpy's reshape error
        (lambda a: iou_xywh(np.ones((2, 2, 4)), a[:, :4]), r"got \(2, 2, 4\)"),
    ],
)
def test_iou_refuses_arrays_that_are_not_boxes(call, match):
    a = np.array([[0.0, 0, 10, 10, 0.9, 1], [5, 5, 10, 10, 0.8, 2]])
    with pytest.raises(ValueError, match=match):
        call(a)


def test_mot_iou_refuses_arrays_that_are_not_boxes():
    from pftrack.eval import mot_iou

    rows = np.array([[0.0, 0, 10, 10, 0.9, 1], [5, 5, 10, 10, 0.8, 2]])
    with pytest.raises(ValueError, match=r"mot_iou: a must have shape \(n, 4\).*got \(2, 6\)"):
        mot_iou(rows, rows)
    with pytest.raises(ValueError, match=r"mot_iou: b\[0\] .*negative box width or height"):
        mot_iou(rows[:, :4], [[0.0, 0, -1, 1]])
    np.testing.assert_allclose(mot_iou([0.0, 0, 10, 10], rows[:, :4]), [[1.0, 25 / 175]])


@pytest.mark.parametrize(
    ("box", "match"),
    [
        ([0.0, 0, -10, 10], r"a\[0\] is \[0.0, 0.0, -10.0, 10.0\]: negative box width or height"),
        ([0.0, np.nan, 10, 10], r"a\[0\] is \[0.0, nan, 10.0, 10.0\]: a value is not finite"),
        ([0.0, 0, np.inf, 10], r"a\[0\] is \[0.0, 0.0, inf, 10.0\]: a value is not finite"),
        # identical 1e200 boxes gave IoU 0 with overflow warnings
        ([0.0, 0, 1e200, 1e200], r"a\[0\] is \[.*\]: a box value is beyond ±1e\+09 px"),
        ([-2e9, 0, 1, 1], r"a\[0\] is \[-2000000000.0, .*\]: a box value is beyond ±1e\+09 px"),
    ],
)
def test_iou_refuses_values_that_are_not_a_box(box, match):
    for fn in (iou_xywh, intersection_xywh, iou_xywh_rows):
        with pytest.raises(ValueError, match=f"{fn.__name__}: {match}"):
            fn([box], [[0.0, 0, 10, 10]])


def test_iou_refuses_what_is_not_real_numbers():
    with pytest.raises(TypeError, match="iou_xywh: a must hold real numbers"):
        iou_xywh([["a", "b", "c", "d"]], [[0, 0, 1, 1]])
    with pytest.raises(TypeError, match="iou_xywh: b must hold real numbers, got dtype bool"):
        iou_xywh([[0, 0, 1, 1]], np.ones((1, 4), bool))


def test_iou_takes_the_boxes_its_docstring_names():
    box = [0.0, 0, 10, 10]
    np.testing.assert_array_equal(iou_xywh(box, [box, [5, 0, 10, 10]]), [[1.0, 50 / 150]])
    assert iou_xywh([], [box]).shape == (0, 1)  # [] is no box
    assert iou_xywh(np.zeros((0, 4)), np.zeros((0, 4))).shape == (0, 0)
    np.testing.assert_array_equal(iou_xywh_rows(box, box), [1.0])
    np.testing.assert_array_equal(iou_xywh([[0, 0, 1e9, 1e9]], [[0, 0, 1e9, 1e9]]), [[1.0]])


@pytest.mark.parametrize("fn", [xywh_to_cxcywh, cxcywh_to_xywh])
def test_conversions_refuse_what_is_not_boxes(fn):
    name = fn.__name__
    with pytest.raises(ValueError, match=rf"{name}: boxes must have 4 values .*got shape \(1, 3\)"):
        fn(np.array([[10.0, 20, 30]]))  # was garbage
    with pytest.raises(ValueError, match=r"got shape \(2, 5\)"):
        fn(np.ones((2, 5)))  # was a broadcast error
    with pytest.raises(ValueError, match=r"got shape \(\)"):
        fn(5.0)
    with pytest.raises(ValueError, match=rf"{name}: boxes is \[nan, 0.0, 1.0, 1.0\]: .*not finite"):
        fn([np.nan, 0, 1, 1])
    bad = np.zeros((2, 3, 4))
    bad[1, 2, 3] = -1
    with pytest.raises(ValueError, match=r"boxes\[1, 2\] is .*negative box width or height"):
        fn(bad)
    with pytest.raises(ValueError, match=r"beyond ±1e\+09 px"):
        fn([[1e300, 0, 1, 1]])
    with pytest.raises(TypeError, match=f"{name}: boxes must hold real numbers"):
        fn([["a", "b", "c", "d"]])


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 6), m=st.integers(0, 6))
def test_unchecked_helpers_give_the_same_floats(seed, n, m):
    # the tracker's per-frame calls skip the checks, with the public functions' arithmetic
    from pftrack import boxes as bx
    from pftrack.eval import mot_iou
    from pftrack.eval.rows import _mot_iou

    rng = np.random.default_rng(seed)
    a = np.column_stack([rng.uniform(0, 50, (n, 2)), rng.uniform(0, 30, (n, 2))])
    b = np.column_stack([rng.uniform(0, 50, (m, 2)), rng.uniform(0, 30, (m, 2))])
    np.testing.assert_array_equal(bx._iou_matrix(a, b), iou_xywh(a, b))
    np.testing.assert_array_equal(bx._intersection_matrix(a, b), intersection_xywh(a, b))
    np.testing.assert_array_equal(bx._iou_rows(a, a[::-1]), iou_xywh_rows(a, a[::-1]))
    np.testing.assert_array_equal(bx._to_cxcywh(a), xywh_to_cxcywh(a))
    np.testing.assert_array_equal(bx._to_xywh(a), cxcywh_to_xywh(a))
    np.testing.assert_array_equal(_mot_iou(a, b), mot_iou(a, b))
