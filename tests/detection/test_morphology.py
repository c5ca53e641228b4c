"""The mask's closing and opening in C++ (pftrack._core.close_mask, open_mask, clean_mask)
against the NumPy reference (tests/reference/detection.py) and cv2.morphologyEx, bit for bit."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.detection.base import BlobConfig, BlobExtractor
from tests.reference.detection import close_mask_reference, open_mask_reference


def _opencv(mask: np.ndarray, element: np.ndarray, op: int = cv2.MORPH_CLOSE) -> np.ndarray:
    return np.asarray(cv2.morphologyEx(mask, op, element), np.uint8)


def _mask(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    """Shadow and foreground blocks (127, 255) with speckle, or any grey levels."""
    if rng.random() < 0.3:  # min / max of grey levels, not a binary operation
        return rng.integers(0, 256, (rows, cols), dtype=np.uint8)
    m = np.zeros((rows, cols), np.uint8)
    for _ in range(int(rng.integers(0, 10))):
        x, y = int(rng.integers(-5, cols)), int(rng.integers(-5, rows))
        w, h = int(rng.integers(1, 30)), int(rng.integers(1, 40))
        m[max(y, 0) : y + h, max(x, 0) : x + w] = rng.choice([127, 255])
    m[rng.random((rows, cols)) < rng.choice([0.0, 0.02, 0.2])] = 255
    m[rng.random((rows, cols)) < 0.01] = 127
    return m


def _assert_close_and_open(mask: np.ndarray, el: np.ndarray) -> None:
    """The core's closing and opening of `mask` by `el` equal the NumPy reference's and OpenCV's."""
    got = _core.close_mask(mask, el)
    np.testing.assert_array_equal(got, close_mask_reference(mask, el))
    np.testing.assert_array_equal(got, _opencv(mask, el))
    opened = _core.open_mask(mask, el)
    np.testing.assert_array_equal(opened, open_mask_reference(mask, el))
    np.testing.assert_array_equal(opened, _opencv(mask, el, cv2.MORPH_OPEN))


@pytest.mark.parametrize(
    "shape, size",
    [
        (cv2.MORPH_ELLIPSE, (5, 5)),
        (cv2.MORPH_ELLIPSE, (9, 9)),
        (cv2.MORPH_ELLIPSE, (11, 11)),
        (cv2.MORPH_ELLIPSE, (6, 6)),  # even: the anchor is at (3, 3)
        (cv2.MORPH_ELLIPSE, (7, 3)),
        (cv2.MORPH_ELLIPSE, (21, 21)),
        (cv2.MORPH_RECT, (1, 1)),
        (cv2.MORPH_RECT, (4, 2)),
        (cv2.MORPH_CROSS, (5, 5)),
    ],
)
def test_close_mask_equals_reference_and_opencv(shape: int, size: tuple[int, int]) -> None:
    rng = np.random.default_rng(size[0] * 100 + size[1] + shape)
    el = np.asarray(cv2.getStructuringElement(shape, size), np.uint8)
    for rows, cols in [(1, 1), (2, 7), (13, 1), (40, 57), (64, 96), (360, 480)]:
        mask = _mask(rng, rows, cols)
        _assert_close_and_open(mask, el)


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rows=st.integers(1, 40),
    cols=st.integers(1, 40),
    kh=st.integers(1, 12),
    kw=st.integers(1, 12),
)
def test_close_mask_any_element_of_runs(seed: int, rows: int, cols: int, kh: int, kw: int) -> None:
    """One run per row anywhere (off centre, asymmetric, empty rows): the reference's values."""
    rng = np.random.default_rng(seed)
    el = np.zeros((kh, kw), np.uint8)
    for y in range(kh):
        if rng.random() < 0.8:
            lo = int(rng.integers(0, kw))
            el[y, lo : int(rng.integers(lo, kw)) + 1] = 1
    if not el.any():
        el[int(rng.integers(0, kh)), int(rng.integers(0, kw))] = 1
    mask = _mask(rng, rows, cols)
    _assert_close_and_open(mask, el)


@pytest.mark.parametrize(
    "element",
    [
        np.asarray(cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (11, 11)), np.uint8),
        np.asarray(cv2.getStructuringElement(cv2.MORPH_RECT, (3, 6)), np.uint8),
        np.array([[0, 0, 1, 1], [1, 1, 1, 0], [0, 0, 0, 1]], np.uint8),  # runs off the anchor
    ],
)
def test_close_mask_with_empty_rows(element: np.ndarray) -> None:
    """A foreground mask's all-0 rows, which neither the closing nor the opening reduces: the
    full values."""
    rng = np.random.default_rng(int(element.sum()))
    for rows, cols in [(3, 9), (60, 80), (200, 333)]:
        for _ in range(4):
            mask = np.zeros((rows, cols), np.uint8)
            for _ in range(int(rng.integers(1, 5))):  # a few blobs, empty rows between them
                y, x = int(rng.integers(0, rows)), int(rng.integers(0, cols))
                h, w = int(rng.integers(1, 12)), int(rng.integers(1, 40))
                mask[y : y + h, x : x + w] = rng.choice([127, 255])
            mask[rng.integers(0, rows), rng.integers(0, cols)] = 255  # a lone pixel
            assert (mask.max(axis=1) == 0).any() or rows < 10
            _assert_close_and_open(mask, element)


def test_clean_is_opening_then_this_closing_on_a_strided_view() -> None:
    rng = np.random.default_rng(3)
    view = _mask(rng, 80, 120)[:, 10:100]  # rows strided
    ex = BlobExtractor(BlobConfig())
    k_open, k_close = ex._elements(80)
    opened = cv2.morphologyEx(np.ascontiguousarray(view), cv2.MORPH_OPEN, k_open)
    want = close_mask_reference(opened, k_close)
    np.testing.assert_array_equal(_core.close_mask(view, k_close), _opencv(view, k_close))
    np.testing.assert_array_equal(_core.open_mask(view, k_open), opened)
    np.testing.assert_array_equal(ex.clean(view), want)


@pytest.mark.parametrize("fn", [_core.close_mask, _core.open_mask])
def test_close_and_open_mask_refuse_bad_input(fn) -> None:
    mask = np.zeros((5, 5), np.uint8)
    with pytest.raises(ValueError, match="not one run"):
        fn(mask, np.array([[1, 0, 1]], np.uint8))
    with pytest.raises(ValueError, match="no set pixel"):
        fn(mask, np.zeros((3, 3), np.uint8))
    with pytest.raises(ValueError, match="shape"):
        fn(mask, np.ones(3, np.uint8))
    with pytest.raises(TypeError, match="mask dtype"):  # a wrong dtype (was ValueError)
        fn(mask.astype(np.float32), np.ones((3, 3), np.uint8))
    with pytest.raises(ValueError, match="non-empty"):
        fn(np.zeros((0, 5), np.uint8), np.ones((3, 3), np.uint8))


# --- the packed path (stop 71): masks of 0 and at most two levels, 255 the upper, as bit planes


@pytest.fixture(params=[True, False], ids=["avx2", "portable"])
def simd_packing(request: pytest.FixtureRequest):
    """Whether the packed path takes its AVX2 pack, passes and unpack or the portable loops
    (bytes 8 at a time in 64-bit words) other CPUs run: `_core._set_avx2` turns AVX2 off. Each
    test runs twice; both are held to OpenCV."""
    before = _core._set_avx2(request.param)
    yield request.param
    _core._set_avx2(before)


def _elements_in_use() -> list[tuple[np.ndarray, np.ndarray]]:
    """Every (opening, closing) element pair `BlobExtractor` makes, over frame heights 1-2200."""
    cfg = BlobConfig()
    sizes = sorted({cfg.kernel_sizes(rows) for rows in range(1, 2200)})
    assert len(sizes) >= 20 and (3, 5) in sizes and (7, 11) in sizes
    return [
        (
            np.asarray(cv2.getStructuringElement(cv2.MORPH_RECT, (o, o)), np.uint8),
            np.asarray(cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (c, c)), np.uint8),
        )
        for o, c in sizes
    ]


def _levels_mask(rng: np.random.Generator, rows: int, cols: int, levels: list[int]) -> np.ndarray:
    """Blocks and speckle of `levels` (non-zero), 0 elsewhere, touching every border."""
    m = np.zeros((rows, cols), np.uint8)
    for _ in range(int(rng.integers(0, 8))):
        x, y = int(rng.integers(-8, cols)), int(rng.integers(-8, rows))
        w, h = int(rng.integers(1, 70)), int(rng.integers(1, 20))
        m[max(y, 0) : y + h, max(x, 0) : x + w] = rng.choice(levels)
    speckle = rng.random((rows, cols)) < rng.choice([0.0, 0.05, 0.5, 0.95])
    m[speckle] = rng.choice(levels, int(speckle.sum()))
    return m


def _assert_clean_equals_opencv(mask: np.ndarray, k_open: np.ndarray, k_close: np.ndarray) -> None:
    opened = _opencv(mask, k_open, cv2.MORPH_OPEN)
    want = _opencv(opened, k_close)
    np.testing.assert_array_equal(_core.clean_mask(mask, k_open, k_close), want)
    np.testing.assert_array_equal(_core.open_mask(mask, k_open), opened)
    np.testing.assert_array_equal(_core.close_mask(mask, k_close), _opencv(mask, k_close))


_LEVELS = [[255], [127, 255], [1], [77], [200, 255]]


def test_packed_clean_every_width_and_element_in_use(simd_packing: bool) -> None:
    """Widths 1-600 (every tail of a 64-bit word and of the 16-byte packing), every element pair
    the detector uses, 0/255, 0/127/255, 0/1, 0/m masks: OpenCV's values."""
    rng = np.random.default_rng(600)
    pairs = _elements_in_use()
    for cols in range(1, 601):
        k_open, k_close = pairs[cols % len(pairs)]
        rows = int(rng.integers(1, 14))
        levels = _LEVELS[cols % len(_LEVELS)]
        _assert_clean_equals_opencv(_levels_mask(rng, rows, cols, levels), k_open, k_close)


@pytest.mark.parametrize("levels", _LEVELS + [[127]])
def test_packed_clean_frames_of_every_element_pair(levels: list[int], simd_packing: bool) -> None:
    """Each element pair in use on frame-sized masks (rows and columns past its reach), with
    foreground on the borders: OpenCV's values."""
    rng = np.random.default_rng(sum(levels))
    for k_open, k_close in _elements_in_use():
        rows = int(rng.integers(k_close.shape[0], 3 * k_close.shape[0] + 40))
        cols = int(rng.integers(k_close.shape[1], 400))
        mask = _levels_mask(rng, rows, cols, levels)
        mask[0, :] = mask[-1, :] = levels[-1]  # the borders: outside pixels never win
        mask[:, 0] = levels[0]
        _assert_clean_equals_opencv(mask, k_open, k_close)


def test_packed_clean_of_a_bool_mask_and_a_strided_view(simd_packing: bool) -> None:
    rng = np.random.default_rng(5)
    k_open, k_close = _elements_in_use()[3]
    mask = _levels_mask(rng, 50, 130, [255])
    got = _core.clean_mask(mask != 0, k_open, k_close)
    want = _opencv(_opencv((mask != 0).astype(np.uint8), k_open, cv2.MORPH_OPEN), k_close)
    np.testing.assert_array_equal(got, want)
    assert set(np.unique(got)) <= {0, 1}
    view = _levels_mask(rng, 60, 200, [127, 255])[:, 7:150]
    _assert_clean_equals_opencv(view, k_open, k_close)


@settings(max_examples=150, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rows=st.integers(1, 30),
    cols=st.integers(1, 200),
    kh=st.integers(1, 12),
    kw=st.integers(1, 40),
    simd=st.booleans(),
)
def test_packed_clean_any_elements_of_runs(
    seed: int, rows: int, cols: int, kh: int, kw: int, simd: bool
) -> None:
    """Off-centre, asymmetric, wide (doubling) runs and one-row elements, on two-level masks."""
    rng = np.random.default_rng(seed)
    els = []
    for _ in range(2):
        el = np.zeros((kh, kw), np.uint8)
        for y in range(kh):
            if rng.random() < 0.8:
                lo = int(rng.integers(0, kw))
                el[y, lo : int(rng.integers(lo, kw)) + 1] = 1
        if not el.any():
            el[int(rng.integers(0, kh)), int(rng.integers(0, kw))] = 1
        els.append(el)
    mask = _levels_mask(rng, rows, cols, _LEVELS[seed % len(_LEVELS)])
    before = _core._set_avx2(simd)
    try:
        _assert_clean_equals_opencv(mask, els[0], els[1])
    finally:
        _core._set_avx2(before)


def test_three_levels_take_the_byte_path_with_the_same_values(simd_packing: bool) -> None:
    """0, 127, 200, 255 (two levels under 255), and 0/50/100 (no 255): not two planes."""
    rng = np.random.default_rng(9)
    k_open, k_close = _elements_in_use()[1]
    for levels in ([127, 200, 255], [50, 100], [1, 2, 3, 255]):
        for cols in (5, 64, 65, 333):
            mask = _levels_mask(rng, 40, cols, levels)
            mask[0, 0], mask[-1, -1] = levels[0], levels[1]  # at least two levels present
            _assert_clean_equals_opencv(mask, k_open, k_close)


def test_clean_mask_refuses_bad_input() -> None:
    mask = np.zeros((5, 5), np.uint8)
    ok = np.ones((3, 3), np.uint8)
    with pytest.raises(ValueError, match="not one run"):
        _core.clean_mask(mask, ok, np.array([[1, 0, 1]], np.uint8))
    with pytest.raises(ValueError, match="no set pixel"):
        _core.clean_mask(mask, np.zeros((3, 3), np.uint8), ok)
    with pytest.raises(TypeError, match="mask dtype"):
        _core.clean_mask(mask.astype(np.float32), ok, ok)
    with pytest.raises(ValueError, match="non-empty"):
        _core.clean_mask(np.zeros((0, 5), np.uint8), ok, ok)


# --- the packed path by blocks of rows (stop 72): rows far from every non-zero row are left out


def _banded_mask(
    rng: np.random.Generator, rows: int, cols: int, bands: list[tuple[int, int]], levels: list[int]
) -> np.ndarray:
    """0 but for `bands` of rows [first, last], each full of blocks, speckle and whole rows of
    `levels` (whole rows: an erosion at a band's edge keeps them only if its rows above and
    below are read)."""
    m = np.zeros((rows, cols), np.uint8)
    for first, last in bands:
        part = _levels_mask(rng, last - first + 1, cols, levels)
        part[0, :] = levels[-1]
        part[-1, :] = levels[0]
        m[first : last + 1] = part
    return m


def test_packed_clean_by_blocks_at_every_gap_near_the_margin(simd_packing: bool) -> None:
    """Two bands of rows whose gap is every count from 0 to 2 margin + 3 empty rows (margin: the
    passes' summed vertical reach; at 2 margin + 1 the bands are cleaned as two images), bands at
    the top and bottom edges and inside, for the first 8 element pairs in use: OpenCV's values
    (and the NumPy reference's at every fourth gap)."""
    rng = np.random.default_rng(72)
    for k_open, k_close in _elements_in_use()[:8]:
        margin = 2 * (k_open.shape[0] // 2) + 2 * (k_close.shape[0] // 2)
        for gap in range(2 * margin + 4):
            for top in (0, 1, margin, margin + 3):
                h1, h2 = int(rng.integers(1, 9)), int(rng.integers(1, 9))
                first2 = top + h1 + gap
                rows = first2 + h2 + int(rng.choice([0, 1, margin, margin + 5]))
                cols = int(rng.integers(1, 140))
                bands = [(top, top + h1 - 1), (first2, first2 + h2 - 1)]
                levels = _LEVELS[(gap + top) % len(_LEVELS)]
                mask = _banded_mask(rng, rows, cols, bands, levels)
                _assert_clean_equals_opencv(mask, k_open, k_close)
                if gap % 4 == 0:  # the NumPy reference too (slower)
                    want = close_mask_reference(open_mask_reference(mask, k_open), k_close)
                    np.testing.assert_array_equal(_core.clean_mask(mask, k_open, k_close), want)


def test_packed_clean_by_blocks_of_an_empty_and_a_full_mask(simd_packing: bool) -> None:
    k_open, k_close = _elements_in_use()[1]
    for rows, cols in ((1, 1), (7, 33), (360, 480)):
        _assert_clean_equals_opencv(np.zeros((rows, cols), np.uint8), k_open, k_close)
        _assert_clean_equals_opencv(np.full((rows, cols), 255, np.uint8), k_open, k_close)


def test_packed_clean_by_blocks_with_other_levels_in_each_band(simd_packing: bool) -> None:
    """Bands far apart with their own levels (0/100 and 0/200: three values in the mask, not in
    a band), and a band with three levels after a packed one (the whole mask by the byte path
    after the first band was written): OpenCV's values."""
    rng = np.random.default_rng(3)
    k_open, k_close = _elements_in_use()[1]
    a = _banded_mask(rng, 120, 97, [(5, 30), (70, 100)], [100])
    a[70:101][a[70:101] != 0] = 200
    _assert_clean_equals_opencv(a, k_open, k_close)
    b = _banded_mask(rng, 120, 97, [(5, 30), (70, 100)], [127, 255])
    b[80, 10:40] = 60  # a third level in the second band only
    _assert_clean_equals_opencv(b, k_open, k_close)
