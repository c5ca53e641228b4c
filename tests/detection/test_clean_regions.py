"""The mask's cleaning at some regions only (pftrack._core.clean_mask with regions), against the
NumPy reference's and OpenCV's whole-mask opening then closing, bit for bit, inside the regions."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.detection.base import BlobConfig, BlobExtractor
from tests.reference.detection import close_mask_reference, open_mask_reference


def _mask(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    """Shadow and foreground blocks (127, 255) with speckle, or any grey levels."""
    if rng.random() < 0.3:
        return rng.integers(0, 256, (rows, cols), dtype=np.uint8)
    m = np.zeros((rows, cols), np.uint8)
    for _ in range(int(rng.integers(0, 10))):
        x, y = int(rng.integers(-5, cols)), int(rng.integers(-5, rows))
        w, h = int(rng.integers(1, 30)), int(rng.integers(1, 40))
        m[max(y, 0) : y + h, max(x, 0) : x + w] = rng.choice([127, 255])
    m[rng.random((rows, cols)) < rng.choice([0.0, 0.02, 0.2])] = 255
    m[rng.random((rows, cols)) < 0.01] = 127
    return m


def _element(rng: np.random.Generator, shape: int) -> np.ndarray:
    size = (int(rng.integers(1, 10)), int(rng.integers(1, 10)))  # even sides: anchor off centre
    return np.asarray(cv2.getStructuringElement(shape, size), np.uint8)


def _only(whole: np.ndarray, regions: np.ndarray) -> np.ndarray:
    """`whole` inside the regions (clipped to the image), 0 elsewhere."""
    out = np.zeros_like(whole)
    for x0, y0, x1, y1 in np.maximum(regions, 0):  # clipped: a negative end is an empty range
        out[y0:y1, x0:x1] = whole[y0:y1, x0:x1]
    return out


@settings(max_examples=300, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rows=st.integers(1, 90),
    cols=st.integers(1, 90),
    n_regions=st.integers(0, 5),
)
def test_regions_hold_the_whole_cleanings_bytes(
    seed: int, rows: int, cols: int, n_regions: int
) -> None:
    rng = np.random.default_rng(seed)
    mask = _mask(rng, rows, cols)
    k_open = _element(rng, cv2.MORPH_RECT)
    k_close = _element(rng, rng.choice([cv2.MORPH_ELLIPSE, cv2.MORPH_CROSS, cv2.MORPH_RECT]))
    corner = np.column_stack(
        [rng.integers(-8, cols + 2, n_regions), rng.integers(-8, rows + 2, n_regions)]
    )
    regions = np.column_stack([corner, corner + rng.integers(0, 40, (n_regions, 2))])
    opened = cv2.morphologyEx(mask, cv2.MORPH_OPEN, k_open)
    whole = cv2.morphologyEx(opened, cv2.MORPH_CLOSE, k_close)
    np.testing.assert_array_equal(
        whole, close_mask_reference(open_mask_reference(mask, k_open), k_close)
    )
    got, partial = _core.clean_mask(mask, k_open, k_close, regions)
    np.testing.assert_array_equal(got, _only(whole, regions) if partial else whole)
    everything, partial_all = _core.clean_mask(mask, k_open, k_close)
    assert not partial_all
    np.testing.assert_array_equal(everything, whole)


def test_a_small_box_far_from_the_edges_is_cleaned_alone() -> None:
    """The detector's elements at 480x360: a box in the middle is cleaned on its crop (partial),
    its bytes the whole cleaning's, and a blob outside it is left out (0)."""
    rng = np.random.default_rng(5)
    mask = _mask(rng, 360, 480)
    mask[10:60, 10:60] = 255  # outside the region
    k_open, k_close = BlobExtractor(BlobConfig())._elements(360)
    regions = np.array([[200, 150, 232, 225], [0, 300, 20, 360]])  # one at the image's corner
    got, partial = _core.clean_mask(mask, k_open, k_close, regions)
    whole = _core.close_mask(_core.open_mask(mask, k_open), k_close)
    assert partial
    np.testing.assert_array_equal(got, _only(whole, regions))
    assert not got[10:60, 10:60].any() and whole[10:60, 10:60].all()


def test_regions_covering_the_frame_clean_the_whole() -> None:
    rng = np.random.default_rng(6)
    mask = _mask(rng, 60, 80)
    k = np.ones((3, 3), np.uint8)
    got, partial = _core.clean_mask(mask, k, k, np.array([[0, 0, 80, 60], [5, 5, 70, 50]]))
    assert not partial
    np.testing.assert_array_equal(got, _core.close_mask(_core.open_mask(mask, k), k))


def test_blob_extractor_cleans_the_regions_once_and_keeps_the_raw_mask() -> None:
    rng = np.random.default_rng(7)
    raw = _mask(rng, 120, 160)
    ex = BlobExtractor(BlobConfig())
    whole = ex.clean(raw)
    assert ex.partial_raw is None
    regions = np.array([[40, 30, 60, 80]])
    ex.only_regions(regions)
    part = ex.clean(raw)
    assert ex.partial_raw is raw
    np.testing.assert_array_equal(part, _only(whole, regions))
    np.testing.assert_array_equal(ex.clean(raw), whole)  # said for one call
    assert ex.partial_raw is None
    ex.only_regions(regions)
    ex.only_regions(None)
    np.testing.assert_array_equal(ex.clean(raw), whole)


def test_clean_mask_refuses_bad_input() -> None:
    mask = np.zeros((5, 5), np.uint8)
    k = np.ones((3, 3), np.uint8)
    with pytest.raises(ValueError, match="regions must be a \\(K, 4\\)"):
        _core.clean_mask(mask, k, k, np.zeros((2, 3), np.int64))
    with pytest.raises(ValueError, match="not one run"):
        _core.clean_mask(mask, np.array([[1, 0, 1]], np.uint8), k)
    with pytest.raises(ValueError, match="no set pixel"):
        _core.clean_mask(mask, k, np.zeros((3, 3), np.uint8))
    with pytest.raises(TypeError, match="mask dtype"):
        _core.clean_mask(mask.astype(np.float32), k, k)
    with pytest.raises(ValueError, match="non-empty"):
        _core.clean_mask(np.zeros((0, 5), np.uint8), k, k)
