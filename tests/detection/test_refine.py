"""Box refinement (pftrack._core.refine_boxes) against its NumPy reference."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.detection import refine_boxes
from tests.reference.refine import refine_boxes_reference


def _scene(rng: np.random.Generator, rows: int = 90, cols: int = 120) -> np.ndarray:
    """A mask of a few filled rectangles with noise, as a background model gives."""
    mask = np.zeros((rows, cols), np.uint8)
    for _ in range(5):
        x, y = rng.integers(0, cols - 5), rng.integers(0, rows - 5)
        w, h = rng.integers(3, 30), rng.integers(3, 40)
        mask[y : y + h, x : x + w] = 255
    mask[rng.random((rows, cols)) < 0.03] = 255
    mask[rng.random((rows, cols)) < 0.05] = 0
    return mask


@pytest.mark.parametrize("seed", range(20))
def test_matches_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mask = _scene(rng)
    k = 30
    boxes = np.column_stack(
        [rng.uniform(-20, 130, k), rng.uniform(-20, 100, k), rng.uniform(0, 60, (k, 2))]
    )
    for fraction, min_cover in [(0.05, 0.1), (0.0, 0.01), (0.5, 0.3), (0.99, 1.0)]:
        got = refine_boxes(boxes, mask, fraction, min_cover)
        want = refine_boxes_reference(boxes, mask, fraction, min_cover)
        np.testing.assert_array_equal(got, want)
        got_bool = refine_boxes(boxes, mask > 0, fraction, min_cover)
        np.testing.assert_array_equal(got_bool, want)


def test_a_flipped_or_broadcast_mask_is_refined_as_its_copy() -> None:
    # was: ValueError "refine_boxes: mask must be packed along rows" for mask[::-1] (a
    # negative row stride) and np.broadcast_to (a zero one), whose pixels are packed
    rng = np.random.default_rng(3)
    mask = _scene(rng)
    boxes = np.column_stack(
        [rng.uniform(0, 100, 20), rng.uniform(0, 70, 20), rng.uniform(5, 40, (20, 2))]
    )
    flipped = mask[::-1]
    np.testing.assert_array_equal(
        refine_boxes(boxes, flipped, 0.05, 0.1),
        refine_boxes_reference(boxes, np.ascontiguousarray(flipped), 0.05, 0.1),
    )
    row = np.broadcast_to(mask[40], mask.shape)
    np.testing.assert_array_equal(
        refine_boxes(boxes, row, 0.05, 0.1),
        refine_boxes_reference(boxes, np.ascontiguousarray(row), 0.05, 0.1),
    )


def _shaded(rng: np.random.Generator, rows: int = 90, cols: int = 120) -> np.ndarray:
    """The same with shadow pixels (127): patches of shadow, some of them below an object."""
    mask = _scene(rng, rows, cols)
    for _ in range(6):
        x, y = rng.integers(0, cols - 5), rng.integers(0, rows - 5)
        w, h = rng.integers(3, 30), rng.integers(3, 30)
        patch = mask[y : y + h, x : x + w]
        patch[(patch == 0) & (rng.random(patch.shape) < 0.8)] = 127
    return mask


@pytest.mark.parametrize("seed", range(20))
def test_legs_match_reference(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    mask = _shaded(rng)
    k = 30
    boxes = np.column_stack(
        [rng.uniform(-20, 130, k), rng.uniform(-20, 100, k), rng.uniform(0, 60, (k, 2))]
    )
    for fraction, min_cover, fill in [(0.05, 0.1, 0.5), (0.0, 0.01, 0.0), (0.5, 0.3, 1.0)]:
        got = refine_boxes(boxes, mask, fraction, min_cover, fill)
        want = refine_boxes_reference(boxes, mask, fraction, min_cover, fill)
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("seed", range(10))
def test_min_height_matches_reference(seed: int) -> None:
    rng = np.random.default_rng(200 + seed)
    mask = _shaded(rng)
    k = 30
    boxes = np.column_stack(
        [rng.uniform(-20, 130, k), rng.uniform(-20, 100, k), rng.uniform(0, 60, (k, 2))]
    )
    kept = 0
    for fill in (None, 0.5):
        plain = refine_boxes(boxes, mask, 0.05, 0.1, fill)
        for min_height in (0.0, 0.3, 0.6, 1.0):
            got = refine_boxes(boxes, mask, 0.05, 0.1, fill, min_height)
            want = refine_boxes_reference(boxes, mask, 0.05, 0.1, fill, min_height)
            np.testing.assert_array_equal(got, want)
            # columns are refined whatever the height; rows are either refined or the box's own
            np.testing.assert_array_equal(got[:, [0, 2]], plain[:, [0, 2]])
            own = (got[:, [1, 3]] == boxes[:, [1, 3]]).all(axis=1)
            refined = (got[:, [1, 3]] == plain[:, [1, 3]]).all(axis=1)
            assert (own | refined).all()
            kept += int((own & ~refined).sum())
    assert kept > 0  # the test does reach boxes whose height is kept


def test_min_height_keeps_the_height_of_a_fragment() -> None:
    mask = np.zeros((60, 60), np.uint8)
    mask[5:25, 20:30] = 255  # a torso whose legs are the colour of the ground
    box = np.array([[15.0, 4.0, 20.0, 50.0]])  # the detector's box: 50 rows
    # refined to 20 of 50 rows: under 0.6 of the height, so the top and height stay the box's
    np.testing.assert_array_equal(refine_boxes(box, mask, 0.05, min_height=0.6), [[20, 4, 10, 50]])
    np.testing.assert_array_equal(refine_boxes(box, mask, 0.05, min_height=0.3), [[20, 5, 10, 20]])
    np.testing.assert_array_equal(refine_boxes(box, mask, 0.05), [[20, 5, 10, 20]])
    with pytest.raises(ValueError, match="min_height"):
        refine_boxes(box, mask, 0.05, min_height=1.5)
    with pytest.raises(ValueError, match="min_height"):
        refine_boxes(box, mask, 0.05, min_height=float("nan"))


def test_legs_taken_for_shadow_come_back_a_cast_shadow_does_not() -> None:
    mask = np.zeros((60, 60), np.uint8)
    mask[5:30, 20:30] = 255  # torso: foreground
    mask[30:50, 21:29] = 127  # legs, taken for shadow
    mask[50:54, 30:58] = 127  # the shadow cast beside the feet
    box = np.array([[15.0, 2.0, 45.0, 55.0]])
    np.testing.assert_array_equal(refine_boxes(box, mask, 0.05, leg_fill=0.5), [[20, 5, 10, 45]])
    # without legs every non-zero pixel is foreground: the shadow widens the box
    np.testing.assert_array_equal(refine_boxes(box, mask, 0.05), [[20, 5, 38, 49]])
    np.testing.assert_array_equal(
        refine_boxes(box, np.where(mask == 255, 255, 0).astype(np.uint8), 0.05), [[20, 5, 10, 25]]
    )
    with pytest.raises(ValueError, match="leg_fill"):
        refine_boxes(box, mask, 0.05, leg_fill=1.5)


def test_strided_mask_and_boxes_untouched() -> None:
    rng = np.random.default_rng(1)
    big = _scene(rng, 90, 240)
    view = big[:, ::2]  # columns not packed: copied once
    boxes = np.array([[10.5, 3.2, 30.0, 40.7], [50.0, 20.0, 2.5, 9.0]])
    before = boxes.copy()
    got = refine_boxes(boxes, view, 0.05)
    np.testing.assert_array_equal(got, refine_boxes_reference(boxes, view, 0.05))
    np.testing.assert_array_equal(boxes, before)


def test_shrinks_to_foreground() -> None:
    mask = np.zeros((50, 50), np.uint8)
    mask[10:40, 20:30] = 255
    out = refine_boxes(np.array([[12.0, 5.0, 30.0, 40.0], [0.0, 0.0, 5.0, 5.0]]), mask)
    np.testing.assert_array_equal(out, [[20, 10, 10, 30], [0, 0, 5, 5]])
    assert refine_boxes(np.zeros((0, 4)), mask).shape == (0, 4)


def test_bad_input() -> None:
    mask = np.zeros((20, 20), np.uint8)
    box = np.array([[1.0, 1.0, 5.0, 5.0]])
    with pytest.raises(ValueError, match=r"expected \(K, 4\)"):
        refine_boxes(np.ones((2, 3)), mask)
    with pytest.raises(ValueError, match="NaN or inf"):
        refine_boxes([[np.nan, 1, 5, 5]], mask)
    with pytest.raises(TypeError, match="mask dtype"):  # a wrong dtype (was ValueError)
        refine_boxes(box, mask.astype(np.float32))
    with pytest.raises(ValueError, match=r"\(H, W\)"):
        refine_boxes(box, np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="fraction"):
        refine_boxes(box, mask, 1.0)
    with pytest.raises(ValueError, match="min_cover"):
        refine_boxes(box, mask, 0.1, -0.5)


def test_no_foreground_with_min_cover_0_is_unchanged() -> None:
    box = np.array([[2.0, 2.0, 10.0, 10.0]])
    np.testing.assert_array_equal(refine_boxes(box, np.zeros((20, 20), np.uint8), 0.05, 0.0), box)


def test_core_refuses_non_finite_boxes() -> None:
    from pftrack import _core

    with pytest.raises(ValueError, match="boxes has a non-finite value"):
        _core.refine_boxes(np.array([[1.0, np.inf, 5, 5]]), np.zeros((9, 9), np.uint8), 0.1, 0.1)
