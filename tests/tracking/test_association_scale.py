"""Many boxes in one frame (stop 70): the sparse association steps against their dense versions.

``first_of_twins``, ``MultiObjectTracker._beside`` and ``associate`` now work from the pairs of
boxes that overlap (``_core.overlap_pairs``) and an assignment that never makes the padded
matrix (``_core.padded_assignment``). Each is held here to the dense code it replaced
(tests/reference/association.py, as it was on main at stop 69), on random boxes with ties,
zero areas and identical boxes: the same results, exactly.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.boxes import _iou_matrix, _overlap_pairs
from pftrack.tracking import AssociationConfig, association
from pftrack.tracking.association import FORBIDDEN, _padding, associate
from pftrack.tracking.tracker import MultiObjectTracker
from tests.reference import association as dense


def _random_boxes(rng: np.random.Generator, n: int, grid: bool) -> np.ndarray:
    """`n` boxes ``left, top, w, h``: on a coarse grid (ties, touching edges, copies, zero
    areas) or spread floats; a few copies of earlier boxes either way."""
    if grid:
        xy = rng.integers(0, 12, (n, 2)) / 2.0
        wh = rng.integers(0, 7, (n, 2)) / 2.0  # 0: zero width or height
    else:
        xy = rng.uniform(0, 40, (n, 2))
        wh = rng.uniform(0, 12, (n, 2)) * (rng.random((n, 2)) > 0.05)
    b = np.c_[xy, wh]
    if n > 1:
        copies = rng.random(n) < 0.2
        b[copies] = b[rng.integers(0, n, copies.sum())]
    return b


# --- overlap_pairs -------------------------------------------------------------------------------


def _strict_overlaps(a: np.ndarray, b: np.ndarray) -> set[tuple[int, int]]:
    """NumPy reference: pairs whose interiors meet, edges as pftrack.boxes computes them."""
    ax0, ay0 = a[:, None, 0], a[:, None, 1]
    bx0, by0 = b[None, :, 0], b[None, :, 1]
    ax1, ay1 = ax0 + a[:, None, 2], ay0 + a[:, None, 3]
    bx1, by1 = bx0 + b[None, :, 2], by0 + b[None, :, 3]
    meet = (np.minimum(ax1, bx1) > np.maximum(ax0, bx0)) & (
        np.minimum(ay1, by1) > np.maximum(ay0, by0)
    )
    return set(zip(*(x.tolist() for x in np.nonzero(meet)), strict=True))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.integers(0, 40), st.booleans())
def test_overlap_pairs_are_the_pairs_whose_interiors_meet(
    seed: int, n: int, m: int, grid: bool
) -> None:
    rng = np.random.default_rng(seed)
    a, b = _random_boxes(rng, n, grid), _random_boxes(rng, m, grid)
    i, j = _overlap_pairs(a, b)
    got = list(zip(i.tolist(), j.tolist(), strict=True))
    assert got == sorted(set(got))  # increasing (i, j), each pair once
    assert set(got) == _strict_overlaps(a, b)
    # every pair of a positive IoU is among them
    iou = _iou_matrix(a, b)
    assert set(zip(*(x.tolist() for x in np.nonzero(iou > 0)), strict=True)) <= set(got)


def test_overlap_pairs_at_large_coordinates_and_tiny_sizes() -> None:
    # a width lost to rounding at 1e9 px is an empty span: it meets nothing, as in NumPy
    a = np.array(
        [[1e9 - 1, 0.0, 1e-9, 5.0], [0.0, 0.0, 1e-300, 1e-300], [-9e8, -9e8, 9.9e8, 9.9e8]]
    )
    b = np.array([[1e9 - 1, 0.0, 1.0, 5.0], [0.0, 0.0, 1e-300, 1e-300]])
    i, j = _overlap_pairs(a, b)
    assert set(zip(i.tolist(), j.tolist(), strict=True)) == _strict_overlaps(a, b)


@pytest.mark.parametrize(
    ("a", "b", "match"),
    [
        (np.zeros((2, 3)), np.zeros((1, 4)), "a cols is 3"),
        (np.zeros((2, 4)), np.full((1, 4), np.nan), "b"),
        (np.array([[0.0, 0.0, -1.0, 1.0]]), np.zeros((1, 4)), "w, h >= 0"),
    ],
)
def test_overlap_pairs_refuses_bad_boxes(a: np.ndarray, b: np.ndarray, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        _core.overlap_pairs(a, b)


# --- the three steps against their dense versions -----------------------------------------------


@settings(max_examples=200, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(0, 40),
    st.booleans(),
    st.sampled_from([0.3, 0.5, 1e-9, 1.0]),
)
def test_first_of_twins_is_the_dense_rule(seed: int, n: int, grid: bool, overlap: float) -> None:
    rng = np.random.default_rng(seed)
    boxes = _random_boxes(rng, n, grid)
    labels = rng.integers(0, 2, n).astype(np.int64)
    candidates = rng.permutation(n)[: rng.integers(0, n + 1)].tolist()
    explained = rng.random(n) < 0.2
    before = explained.copy()
    want = dense.first_of_twins(boxes, labels, candidates, explained, overlap)
    got = association.first_of_twins(boxes, labels, candidates, explained, overlap)
    assert got == want
    np.testing.assert_array_equal(explained, before)  # not changed


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 30), st.integers(0, 20), st.booleans())
def test_beside_is_the_dense_rule(seed: int, n: int, nt: int, grid: bool) -> None:
    rng = np.random.default_rng(seed)
    boxes = _random_boxes(rng, n, grid)
    labels = rng.integers(0, 2, n).astype(np.int64)
    tracks = [
        SimpleNamespace(box=b, cls=int(c))
        for b, c in zip(_random_boxes(rng, nt, grid), rng.integers(0, 2, nt), strict=True)
    ]
    unmatched = sorted(rng.permutation(n)[: rng.integers(0, n + 1)].tolist())
    cfg = SimpleNamespace(lifecycle=SimpleNamespace(birth_overlap=0.3))
    me = SimpleNamespace(tracks=tracks)
    got = MultiObjectTracker._beside(me, boxes, labels, unmatched, cfg)  # type: ignore[arg-type]
    assert got == dense.beside(tracks, boxes, labels, unmatched, 0.3)


@settings(max_examples=200, deadline=None)
@given(
    st.integers(0, 2**32 - 1), st.integers(0, 25), st.integers(0, 25), st.booleans(),
    st.sampled_from([1.5, 0.2, 3.0, 6e5, math.inf]), st.booleans(),
)  # fmt: skip
def test_associate_is_the_dense_assignment(
    seed: int, nt: int, nd: int, grid: bool, tau: float, classes: bool
) -> None:
    rng = np.random.default_rng(seed)
    tracks, boxes = _random_boxes(rng, nt, grid), _random_boxes(rng, nd, grid)
    bins = 6
    # colours on a few levels: equal costs (ties) between copies of a box
    references = rng.integers(0, 3, (nt, bins)).astype(np.float64) + 1e-3
    references /= references.sum(axis=1, keepdims=True)
    hists = rng.integers(0, 3, (nd, bins)).astype(np.float64)
    sums = hists.sum(axis=1, keepdims=True)
    hists = np.divide(hists, sums, out=np.zeros_like(hists), where=sums > 0)
    heights = np.maximum(tracks[:, 3], 1.0) if nt else np.zeros(0)
    coasted = rng.integers(0, 10, nt)
    config = AssociationConfig(unmatched_cost=tau)
    allowed = rng.random((nt, nd)) < 0.7 if classes else None
    args = (tracks, heights, coasted, references, boxes, hists, config, allowed)
    assert associate(*args) == dense.associate(*args)


@settings(max_examples=200, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(0, 12),
    st.integers(0, 12),
    st.sampled_from([0.5, 1.0, 1e6]),
)
def test_padded_assignment_is_linear_sum_assignment_of_the_padded_matrix(
    seed: int, nt: int, nd: int, tau: float
) -> None:
    rng = np.random.default_rng(seed)
    cost = rng.integers(0, 4, (nt, nd)) / 2.0  # many ties
    cost[rng.random((nt, nd)) < 0.3] = FORBIDDEN
    padded = _padding(nt, nd, tau).copy()
    padded[:nt, :nd] = cost
    want = _core.linear_sum_assignment(padded)
    got = _core.padded_assignment(cost, tau, FORBIDDEN)
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_array_equal(got[1], want[1])


def test_padded_assignment_refuses_what_it_cannot_take() -> None:
    with pytest.raises(ValueError, match="cost"):
        _core.padded_assignment(np.array([[np.nan]]), 1.0, FORBIDDEN)
    with pytest.raises(ValueError, match="tau and forbidden must be finite"):
        _core.padded_assignment(np.zeros((1, 1)), math.inf, FORBIDDEN)


def test_a_crowd_of_boxes_is_associated_as_the_dense_code_does() -> None:
    # 600 tracks and 900 detections of a 1920 x 1080 frame, some of them twins: the sizes at
    # which the dense code still answers in a test's time
    rng = np.random.default_rng(7)

    def spread(n: int) -> np.ndarray:
        h = rng.uniform(40, 200, n)
        w = h * rng.uniform(0.3, 0.6, n)
        return np.c_[rng.uniform(0, 1900, n), rng.uniform(0, 1000, n), w, h]

    tracks, boxes = spread(600), spread(900)
    boxes[::7] = tracks[: len(boxes[::7])] + rng.normal(0, 3, (len(boxes[::7]), 4)) * [1, 1, 0, 0]
    references = rng.dirichlet(np.ones(110), 600)
    hists = rng.dirichlet(np.ones(110), 900)
    args = (tracks, tracks[:, 3], rng.integers(0, 5, 600), references, boxes, hists,
            AssociationConfig(), None)  # fmt: skip
    got = associate(*args)
    assert got == dense.associate(*args)
    assert len(got.matches) > 50  # the crowd is associated, not left alone
    labels = np.zeros(900, np.int64)
    candidates = got.unmatched_detections
    explained = np.zeros(900, np.bool_)
    explained[[d for _, d in got.matches]] = True
    assert association.first_of_twins(boxes, labels, candidates, explained, 0.3) == (
        dense.first_of_twins(boxes, labels, candidates, explained, 0.3)
    )
