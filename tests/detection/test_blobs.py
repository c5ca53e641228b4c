"""The blob pass in C++ (pftrack._core.blob_boxes and the size model's kernels) against
tests/reference/blobs.py (OpenCV's outer contours and the former Python pass), bit for bit."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import cv2
import numpy as np
import pytest

from pftrack import _core
from pftrack.detection import make_detector
from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.detection.size_model import PersonSizeModel, theil_sen
from tests.conftest import dataset
from tests.reference import blobs as ref

LINES = np.array([[0.3, 5.0], [0.1, 3.0]])  # h = 0.3 y + 5, w = 0.1 y + 3 in the foot row
DEFAULTS = (0.0015, 0.25, 0.25, 6.0, 0.2)  # min/max area, min/max aspect, min fill
SIZE = (1.6, 1.5, 1.2)  # split_ratio, split_max_height, merge_slack


def _scene(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    """Blobs of every kind: filled and hollow boxes (with blobs in their holes), groups side
    by side, stacked fragments, blobs on the frame's edges, diagonal contacts and speckle."""
    m = np.zeros((rows, cols), np.uint8)
    for _ in range(int(rng.integers(3, 12))):
        x, y = int(rng.integers(-5, cols)), int(rng.integers(-5, rows))
        w, h = int(rng.integers(2, 40)), int(rng.integers(2, 60))
        x0, y0 = max(x, 0), max(y, 0)
        m[y0 : y + h, x0 : x + w] = 255
        if rng.random() < 0.4 and w > 8 and h > 8:  # a ring, maybe with a blob in its hole
            t = int(rng.integers(1, 3))
            m[y0 + t : y + h - t, x0 + t : x + w - t] = 0
            if rng.random() < 0.7:
                m[y + t + 2 : y + h - t - 2, x + t + 2 : x + w - t - 2] = 255
    m[rng.random((rows, cols)) < rng.choice([0.0, 0.01, 0.05])] = 255
    k = int(rng.integers(0, 3))
    if k:
        m = cv2.morphologyEx(m, cv2.MORPH_CLOSE, np.ones((k + 1, k + 1), np.uint8))
    return np.ascontiguousarray(m)


def _both(
    mask: np.ndarray,
    limits: tuple[float, ...],
    person_aspect: float,
    lines: object,
    valley: float = 1.0,
) -> None:
    want = ref.blob_boxes(mask, *limits, person_aspect, lines, *SIZE, valley)  # type: ignore[arg-type]
    got = _core.blob_boxes(mask, *limits, person_aspect, lines, *SIZE, valley)
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_array_equal(got[1], want[1])


@pytest.mark.parametrize("seed", range(60))
def test_equals_reference_on_random_masks(seed: int) -> None:
    rng = np.random.default_rng(seed)
    rows, cols = int(rng.integers(1, 90)), int(rng.integers(1, 120))
    mask = _scene(rng, rows, cols)
    small = (0.0005, 0.5, 0.1, 10.0, 0.1)  # let most blobs through: the later steps run too
    for limits in (DEFAULTS, small, (0.0, 1.0, 1e-3, 1e3, 0.0)):
        for person_aspect, lines in ((2.8, None), (0.0, None), (2.8, LINES), (0.0, LINES * 0.5)):
            for valley in (1.0, 0.9, 0.5, 0.0):
                _both(mask, limits, person_aspect, lines, valley)


def test_a_group_is_cut_only_at_a_valley_of_its_column_profile() -> None:
    """One wide person (a full-height torso over legs) is not cut; two people with a gap
    between their bodies are, however wide the rule expects people to be."""
    wide = np.zeros((100, 120), np.uint8)
    wide[10:60, 20:70] = 255  # torso and arms (a coat, a bag), 50 px wide
    wide[60:90, 33:57] = 255  # legs, together
    pair = np.zeros((100, 120), np.uint8)
    pair[10:90, 20:42] = 255  # two people, 22 px each, touching at the hands only
    pair[10:90, 46:68] = 255
    pair[40:45, 42:46] = 255
    args = (0.0, 1.0, 0.1, 10.0, 0.0, 2.8, None, *SIZE)  # person_aspect: both are "groups"
    assert len(_core.blob_boxes(wide, *args, 1.0)[0]) == 2  # the rule alone cut the person
    assert len(_core.blob_boxes(wide, *args, 0.9)[0]) == 1
    people = _core.blob_boxes(pair, *args, 0.9)[0]
    assert len(people) == 2 and people[0].tolist() == [20, 10, 22, 80]
    for valley in (1.0, 0.9, 0.0):  # the reference agrees
        _both(wide, args[:5], 2.8, None, valley)
        _both(pair, args[:5], 2.8, None, valley)


def test_only_outer_regions_in_contour_order() -> None:
    mask = np.zeros((40, 60), np.uint8)
    mask[5:35, 5:35] = 255
    mask[10:30, 10:30] = 0  # a ring ...
    mask[15:25, 15:25] = 255  # ... with a blob in its hole: not reported
    mask[0:10, 40:60] = 255  # on the frame's edges
    mask[20:30, 45:50] = 255
    mask[30:32, 50:52] = 255  # touches the blob above only diagonally: the same region
    got, _ = _core.blob_boxes(mask, 0.0, 1.0, 1e-3, 1e3, 0.0, 0.0, None, *SIZE)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    want = np.array([cv2.boundingRect(c) for c in contours], np.float64)
    np.testing.assert_array_equal(got, want)
    assert got.tolist() == [[45, 20, 7, 12], [5, 5, 30, 30], [40, 0, 20, 10]]  # reverse raster


@pytest.mark.parametrize("cols", [8, 31, 32, 33, 64, 71, 100])
def test_lone_pixels_after_empty_stretches_of_every_length(cols: int) -> None:
    # the run scan skips empty bytes 32 a step, then 8, then one by one (stop 71): a pixel after
    # an empty stretch of every length 0 .. cols - 1 in its row, and a pixel at both ends of
    # another row, are each a region of their own, as OpenCV's outer contours find them
    mask = np.zeros((2 * cols + 2, cols), np.uint8)
    for x in range(cols):
        mask[2 * x, x] = 255
    mask[2 * cols, 0] = mask[2 * cols, cols - 1] = 1
    got, _ = _core.blob_boxes(mask, 0.0, 1.0, 1e-3, 1e3, 0.0, 0.0, None, *SIZE)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    want = np.array([cv2.boundingRect(c) for c in contours], np.float64)
    np.testing.assert_array_equal(got, want)
    assert len(got) == cols + (2 if cols > 1 else 1)


@pytest.mark.parametrize("allowed", [True, False], ids=["avx2", "portable"])
@pytest.mark.parametrize("cols", [8, 33, 63, 64, 65, 127, 128, 129, 200, 480])
def test_run_scan_skips_alike_with_and_without_avx2(cols: int, allowed: bool) -> None:
    # the run scan's skip of empty bytes 64 a step with AVX2 (stop 74, det73's diff), then 32,
    # 8 and one by one, or without it (`_set_avx2(False)`): a pixel after an empty stretch of
    # every length 0 .. cols - 1 (every offset in a 64-byte step), a row with pixels at both
    # ends, and sparse random masks, each against OpenCV's outer contours
    rng = np.random.default_rng(cols)
    lone = np.zeros((2 * cols + 2, cols), np.uint8)
    for x in range(cols):
        lone[2 * x, x] = 255
    lone[2 * cols, 0] = lone[2 * cols, cols - 1] = 1
    sparse = [(rng.random((40, cols)) < p).astype(np.uint8) * 255 for p in (0.002, 0.02, 0.2)]
    before = _core._set_avx2(allowed)
    try:
        for mask in (lone, *sparse):
            got, _ = _core.blob_boxes(mask, 0.0, 1.0, 1e-3, 1e3, 0.0, 0.0, None, *SIZE)
            contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
            want = np.array([cv2.boundingRect(c) for c in contours], np.float64).reshape(-1, 4)
            np.testing.assert_array_equal(got, want)
    finally:
        _core._set_avx2(before)
    assert len(_core.blob_boxes(lone, 0.0, 1.0, 1e-3, 1e3, 0.0, 0.0, None, *SIZE)[0]) == cols + 2


@pytest.mark.dataset
def test_equals_reference_on_pets_masks() -> None:
    video = dataset("pets09-s2l1") / "video.avi"
    cap = cv2.VideoCapture(str(video))
    frames = [cap.read()[1] for _ in range(200)]
    cap.release()
    det = make_detector("paper")
    det.prime(bootstrap_frames(frames, 10, "spread"))
    for frame in frames[::4]:
        mask, _ = det.foreground(frame)
        for person_aspect, lines in ((2.8, None), (0.0, LINES)):
            _both(mask, DEFAULTS, person_aspect, lines)


@pytest.mark.parametrize("seed", range(10))
def test_size_kernels_equal_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    k = int(rng.integers(0, 12))
    boxes = np.column_stack(
        [rng.integers(0, 200, (k, 2)), rng.integers(2, 40, k), rng.integers(5, 80, k)]
    ).astype(np.float64)
    lines = np.array([[rng.uniform(-0.2, 0.5), rng.uniform(-5, 20)], [0.1, rng.uniform(1, 9)]])
    np.testing.assert_array_equal(
        _core.split_count(boxes, lines, 1.6, 1.5), ref.split_count(boxes, lines, 1.6, 1.5)
    )
    assert _core.merge_fragments(boxes, lines, 1.2) == ref.merge_fragments(boxes, lines, 1.2)
    for n in (2, 3, 30, 31, 200):  # even and odd counts of slopes and residuals, with ties
        x = rng.integers(0, 50, n).astype(np.float64)
        y = 0.4 * x + rng.normal(0, 3, n).round(1)
        if np.ptp(x) > 0:
            assert theil_sen(x, y) == ref.theil_sen(x, y)


def _fragments(n: int, rng: np.random.Generator) -> np.ndarray:
    """`n` fragments of about n / 4 people (many merges), integer pixels (equal unions: ties)."""
    people = max(n // 4, 1)
    px, foot = rng.uniform(0, 400, people), rng.uniform(60, 300, people)
    k = rng.integers(0, people, n)
    h, w = 0.3 * foot[k] + 5, 0.1 * foot[k] + 3
    top = foot[k] - h + rng.uniform(0, 0.8, n) * h
    x = px[k] + rng.uniform(0, 0.3, n) * w
    return np.column_stack([x, top, w * rng.uniform(0.5, 0.9, n), h * rng.uniform(0.1, 0.3, n)])


@pytest.mark.parametrize("seed", range(8))
def test_merge_fragments_of_many_boxes_equals_the_full_scan(seed: int) -> None:
    """merge_fragments keeps each box's best partner instead of scanning every pair after each
    merge (O(n^3): 0.8 s for 1000 fragments of a frame, 11 ms for 300); the groups, their order
    and the ties (the first pair) are the full scan's (the reference)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(20, 70))
    boxes = _fragments(n, rng)
    if seed % 2:
        boxes = boxes.round()  # ties between unions of equal area
    got = _core.merge_fragments(boxes, LINES, 1.2)
    assert got == ref.merge_fragments(boxes, LINES, 1.2)
    assert len(got) < n - n // 4  # many merges: the updates after a merge are exercised
    same = np.tile(boxes[:1], (6, 1))  # every union the same: ties all the way
    assert _core.merge_fragments(same, LINES, 1.2) == ref.merge_fragments(same, LINES, 1.2)


@pytest.mark.parametrize("seed", range(12))
def test_size_fit_equals_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.choice([1, 2, 3, 30, 31, 200]))
    y = rng.uniform(50, 350, n).round(0)
    if seed % 4 == 0:
        y[:] = 200.0 + rng.uniform(0, 0.9)  # every foot on one row: a constant size
    h = 0.3 * y + rng.normal(0, 4, n).round(1)
    w = 0.1 * y + rng.normal(0, 2, n).round(1)
    h[::7] *= 1.9  # a one-sided block of outliers (groups)
    samples = np.column_stack([y, h, w])
    if n == 1 or np.ptp(y) >= 1.0 or seed % 4 == 0:
        np.testing.assert_array_equal(_core.size_fit(samples), ref.size_fit(samples))
    model = PersonSizeModel()
    model.observe(np.column_stack([np.arange(n) * 1000.0, y - h, w, h]))  # all isolated
    if model.fitted:  # the samples held (foot rows recomputed as top + h)
        held = model._samples[: model.n_samples]
        np.testing.assert_array_equal(model.coefficients, ref.size_fit(held))


def test_model_methods_and_extractor_use_the_kernels() -> None:
    model = PersonSizeModel()
    model._coef = LINES.copy()  # a fitted model without feeding it samples
    boxes = np.array([[10.0, 100.0, 30.0, 35.0], [50.0, 60.0, 8.0, 20.0], [50.0, 80.0, 9.0, 18.0]])
    np.testing.assert_array_equal(model.split_count(boxes), ref.split_count(boxes, LINES))
    assert model.merge_fragments(boxes) == ref.merge_fragments(boxes, LINES)
    lines = model.coefficients
    assert lines is not None and not lines.flags.writeable
    np.testing.assert_array_equal(lines, LINES)


def test_bool_mask_is_the_same_foreground() -> None:
    mask = np.zeros((60, 80), np.uint8)
    mask[5:40, 10:22] = 255
    mask[20:55, 50:58] = 255
    args = (*DEFAULTS, 2.8, None, *SIZE)
    want = _core.blob_boxes(mask, *args)
    assert len(want[0]) == 2
    for got, w in zip(_core.blob_boxes(mask > 0, *args), want, strict=True):
        np.testing.assert_array_equal(got, w)


def test_bad_input() -> None:
    mask = np.zeros((20, 30), np.uint8)
    args = (*DEFAULTS, 2.8, None, *SIZE)
    with pytest.raises(TypeError, match="blob_boxes: mask dtype is float64"):
        _core.blob_boxes(mask.astype(np.float64), *args)
    with pytest.raises(ValueError, match=r"mask must be a \(H, W\) array"):
        _core.blob_boxes(np.zeros((4, 4, 3), np.uint8), *args)
    with pytest.raises(ValueError, match="packed along rows"):
        _core.blob_boxes(np.asfortranarray(np.zeros((4, 5), np.uint8)), *args)
    with pytest.raises(ValueError, match="min_area, max_area"):
        _core.blob_boxes(mask, 0.3, 0.2, 0.25, 6.0, 0.2, 2.8, None, *SIZE)
    with pytest.raises(ValueError, match="min_fill is nan"):
        _core.blob_boxes(mask, 0.0015, 0.25, 0.25, 6.0, float("nan"), 2.8, None, *SIZE)
    with pytest.raises(ValueError, match="person_aspect is -1"):
        _core.blob_boxes(mask, *DEFAULTS, -1.0, None, *SIZE)
    with pytest.raises(ValueError, match=r"coefficients must have shape \(2, 2\)"):
        _core.blob_boxes(mask, *DEFAULTS, 2.8, np.zeros((2, 3)), *SIZE)
    with pytest.raises(ValueError, match="merge_slack is 0"):
        _core.blob_boxes(mask, *DEFAULTS, 2.8, LINES, 1.6, 1.5, 0.0)
    with pytest.raises(ValueError, match="split_count: boxes cols is 3"):
        _core.split_count(np.zeros((2, 3)), LINES, 1.6, 1.5)
    with pytest.raises(ValueError, match="merge_fragments: boxes has a non-finite value"):
        _core.merge_fragments(np.full((1, 4), np.nan), LINES, 1.2)
    with pytest.raises(ValueError, match="theil_sen: x has no two distinct values"):
        theil_sen(np.ones(5), np.arange(5.0))
    with pytest.raises(ValueError, match="theil_sen: y size is 4"):
        theil_sen(np.arange(5.0), np.arange(4.0))
    with pytest.raises(ValueError, match="size_fit: samples cols is 2"):
        _core.size_fit(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="size_fit: samples is empty"):
        _core.size_fit(np.zeros((0, 3)))
    with pytest.raises(ValueError, match="PersonSizeModel.split_count: the model is not fitted"):
        PersonSizeModel().split_count(np.zeros((1, 4)))


def test_threads_give_serial_result() -> None:
    rng = np.random.default_rng(7)
    masks = [_scene(rng, 240, 320) for _ in range(16)]

    def run(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return _core.blob_boxes(m, *DEFAULTS, 2.8, LINES, *SIZE)

    serial = [run(m) for m in masks]
    with ThreadPoolExecutor(4) as pool:
        threaded = list(pool.map(run, masks))
    for (a, fa), (b, fb) in zip(serial, threaded, strict=True):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(fa, fb)
