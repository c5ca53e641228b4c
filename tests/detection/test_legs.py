"""Lost legs: shadow pixels kept in the mask (127), short boxes extended within the size model."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import cv2
import numpy as np
import pytest

from pftrack import _core
from pftrack.detection import PaperConfig, PaperDetector, make_detector
from pftrack.detection.base import BlobConfig
from pftrack.detection.paper import foreground_only
from pftrack.detection.size_model import PersonSizeModel
from tests.reference import blobs as ref

GROUND = np.array([100.0, 112.0, 118.0])  # BGR of a flat, greyish path


def lines(h_slope: float, h_intercept: float) -> np.ndarray:
    return np.array([[h_slope, h_intercept], [0.3, 0.0]])


def test_extend_legs_grows_to_the_foot_row_and_stops_at_an_empty_row() -> None:
    mask = np.zeros((100, 60), np.uint8)
    mask[20:40, 10:20] = 255  # a torso
    mask[40:95, 11:19] = 127  # shadow-like legs, 8 of the box's 10 columns, down to row 94
    coef = lines(0.5, 0.0)  # h = 0.5 foot: a head at row 20 has h_e = 20, foot row 40 ...
    box = np.array([[10.0, 20.0, 10.0, 20.0]])
    np.testing.assert_array_equal(_core.extend_legs(mask, box, coef, 0.9, 0.3), box)  # full
    coef = lines(0.5, 20.0)  # ... now h_e = (20 + 10) / 0.5 = 60: foot row 80
    out = _core.extend_legs(mask, box, coef, 0.9, 0.3)
    np.testing.assert_array_equal(out, [[10, 20, 10, 60]])  # never past the foot row
    assert out[0, 3] < 75  # the legs' 75 rows are not all taken
    np.testing.assert_array_equal(_core.extend_legs(mask, box, coef, 0.9, 0.9), box)  # 8 < 9
    mask[60] = 0  # a row with nothing: the extension stops above it
    np.testing.assert_array_equal(_core.extend_legs(mask, box, coef, 0.9, 0.3), [[10, 20, 10, 40]])
    np.testing.assert_array_equal(_core.extend_legs(mask, box, coef, 0.0, 0.3), box)  # off
    np.testing.assert_array_equal(_core.extend_legs(mask, box, lines(1.0, 20.0), 0.9, 0.3), box)


def test_extend_legs_camera_below_head_height() -> None:
    # h_slope > 1 (TUD-Campus): h = 1.5 foot - 150, so the foot row of a head at row `top` is
    # (top - 150) / (1 - 1.5) = 300 - 2 top, above the horizon (row 100)
    mask = np.full((300, 30), 127, np.uint8)
    box = np.array([[5.0, 20.0, 10.0, 30.0], [5.0, 130.0, 10.0, 5.0]])
    out = _core.extend_legs(mask, box, lines(1.5, -150.0), 0.9, 0.3)
    np.testing.assert_array_equal(out[0], [5, 20, 10, 240])  # foot row 260
    np.testing.assert_array_equal(out[1], box[1])  # head below the horizon: no such person


def random_case(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rows, cols = (int(v) for v in rng.integers(1, 60, 2))
    mask = rng.choice(np.array([0, 127, 255], np.uint8), (rows, cols), p=[0.3, 0.4, 0.3])
    k = int(rng.integers(0, 8))
    xy = rng.uniform(-10, max(rows, cols) + 5, (k, 2))
    wh = rng.uniform(0.5, 40, (k, 2))
    boxes = np.column_stack([xy[:, 0], xy[:, 1], wh[:, 0], wh[:, 1]])
    boxes[::2] = np.round(boxes[::2])  # integer boxes, as blobs give, and fractional ones
    coef = np.array([[rng.uniform(-0.5, 2.0), rng.uniform(-60, 60)], [0.3, 1.0]])
    return mask, boxes, coef


@pytest.mark.parametrize("seed", range(40))
def test_extend_legs_matches_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mask, boxes, coef = random_case(rng)
    min_height, row_fill = rng.uniform(0, 2), rng.uniform(0, 1)
    got = _core.extend_legs(mask, boxes, coef, min_height, row_fill)
    np.testing.assert_array_equal(got, ref.extend_legs(mask, boxes, coef, min_height, row_fill))
    assert np.all(got[:, 3] >= boxes[:, 3]) and np.all(got[:, :3] == boxes[:, :3])
    wide = np.zeros((mask.shape[0], mask.shape[1] + 7), np.uint8)
    wide[:, : mask.shape[1]] = mask  # a strided view, and a bool mask, give the same boxes
    np.testing.assert_array_equal(
        _core.extend_legs(wide[:, : mask.shape[1]], boxes, coef, min_height, row_fill), got
    )
    np.testing.assert_array_equal(
        _core.extend_legs(mask > 0, boxes, coef, min_height, row_fill), got
    )


def test_extend_legs_from_threads_equals_serial() -> None:
    cases = [random_case(np.random.default_rng(s)) for s in range(20)]

    def work(_: int) -> list[np.ndarray]:
        return [_core.extend_legs(m, b, c, 1.2, 0.3) for m, b, c in cases]

    serial = work(0)
    with ThreadPoolExecutor(4) as pool:  # as tests/detection/test_blobs.py's thread test
        out = list(pool.map(work, range(4)))
    assert len(out) == 4
    for res in out:
        for a, b in zip(res, serial, strict=True):
            np.testing.assert_array_equal(a, b)


def test_extend_legs_bad_input() -> None:
    mask = np.zeros((10, 10), np.uint8)
    box, coef = np.array([[1.0, 1.0, 3.0, 3.0]]), lines(0.5, 1.0)
    with pytest.raises(ValueError, match="min_height"):
        _core.extend_legs(mask, box, coef, -1.0, 0.3)
    with pytest.raises(ValueError, match="row_fill"):
        _core.extend_legs(mask, box, coef, 0.9, 1.5)
    with pytest.raises(ValueError, match="boxes cols"):
        _core.extend_legs(mask, box[:, :3], coef, 0.9, 0.3)
    with pytest.raises(ValueError, match="coefficients"):
        _core.extend_legs(mask, box, coef[:1], 0.9, 0.3)
    with pytest.raises(TypeError, match="mask dtype"):  # a wrong dtype (was ValueError)
        _core.extend_legs(mask.astype(np.float32), box, coef, 0.9, 0.3)
    with pytest.raises(ValueError, match="not fitted"):
        PersonSizeModel().extend_legs(mask, box, 0.9, 0.3)
    with pytest.raises(ValueError, match="leg_height is -1"):
        PaperConfig(leg_height=-1.0)
    with pytest.raises(ValueError, match="leg_fill is 2"):
        PaperConfig(leg_fill=2.0)


def walker(frame: np.ndarray, x: int, foot: int, h: int, trousers: np.ndarray) -> None:
    """A person of height h, feet on row `foot`: red shirt over the top 55 %, then trousers."""
    w, top = max(6, round(0.35 * h)), foot - h
    waist = top + round(0.55 * h)
    frame[top:waist, x : x + w] = (40, 40, 200)
    frame[waist:foot, x : x + w] = trousers


def dark_legs_scene(n_frames: int = 60) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
    """Three people with blue trousers from frame 1 and, from frame 25, one whose trousers are
    the path's colour at 0.65 of its brightness (what the shadow test calls a shadow); all walk
    right in their own columns. Returns the background, the frames and the dark-legged person's
    true boxes (frame index, left, top, w, h) for frames 25 on."""
    rows, cols = 140, 320
    rng = np.random.default_rng(7)
    bg = np.empty((rows, cols, 3))
    bg[:] = GROUND
    frames, truth = [], []
    for f in range(n_frames):
        img = bg.copy()
        for x0, foot in ((10, 70), (110, 100), (210, 130)):  # h = 0.6 (foot - 20)
            walker(img, x0 + 2 * f, foot, round(0.6 * (foot - 20)), np.array([150.0, 60, 30]))
        if f >= 25:
            foot, h, x = 115, 57, 60 + 2 * f  # a 57 px person between the first two
            walker(img, x, foot, h, 0.65 * GROUND)
            truth.append((f, x, foot - h, max(6, round(0.35 * h)), h))
        img += rng.normal(0, 1.5, img.shape)
        frames.append(np.clip(img, 0, 255).astype(np.uint8))
    return bg.astype(np.uint8), frames, np.array(truth, np.float64)


def run(leg_height: float) -> tuple[PaperDetector, list[np.ndarray], np.ndarray]:
    bg, frames, truth = dark_legs_scene()
    det = make_detector("paper", leg_height=leg_height, leg_fill=0.3)
    det.prime([bg] * 3)
    return det, [det.detect(f).boxes for f in frames], truth


def dark_person_box(boxes: np.ndarray, x: float) -> np.ndarray:
    near = boxes[np.abs(boxes[:, 0] - x) <= 3]
    assert len(near) == 1
    return near[0]


def test_dark_legs_are_lost_without_the_extension_and_found_with_it() -> None:
    det_off, off, truth = run(0.0)
    det_on, on, _ = run(0.9)
    assert det_on.model.threshold >= 25  # the legs differ from the path by 35-41 grey levels ...
    assert det_on.size_model.fitted  # (fitted from the blue-trousered people first)
    bottoms_off, bottoms_on = [], []
    for f, x, top, _w, h in truth:
        b_off, b_on = dark_person_box(off[int(f)], x), dark_person_box(on[int(f)], x)
        assert abs(b_on[1] - top) <= 2 and abs(b_off[1] - top) <= 2
        bottoms_off.append(b_off[1] + b_off[3] - (top + h))
        bottoms_on.append(b_on[1] + b_on[3] - (top + h))
    # ... but are called shadow: without the extension the box ends at the waist (26 px short)
    assert np.median(bottoms_off) < -20
    # with it, the box reaches the feet (the model's foot row bounds it: never far below)
    assert abs(np.median(bottoms_on)) <= 4 and max(bottoms_on) <= 6
    for a, b in zip(off[:25], on[:25], strict=True):  # the others' boxes do not change
        np.testing.assert_array_equal(a, b)


def test_foreground_is_the_cleaned_255_mask_whatever_the_shadows() -> None:
    bg, frames, _ = dark_legs_scene(30)
    model = _core.BackgroundModel()
    det = PaperDetector(PaperConfig(blobs=BlobConfig(learn_size=False)))
    model.set_background(bg.astype(np.float32))
    det.prime([bg])
    k = np.ones((3, 3), np.uint8)
    for f in frames[25:]:  # the dark-legged person is in view
        _, raw = model.apply(f)
        assert (raw == 127).any() and set(np.unique(raw)) <= {0, 127, 255}
        fg = cv2.morphologyEx((raw == 255).astype(np.uint8) * 255, cv2.MORPH_OPEN, k)
        fg = cv2.morphologyEx(
            fg, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
        )
        mask, _ = det.foreground(f)
        np.testing.assert_array_equal(mask, fg)  # no 127 reaches the public mask
        np.testing.assert_array_equal(foreground_only(raw), (raw == 255).astype(np.uint8) * 255)


def test_boxes_do_not_grow_into_a_ghost() -> None:
    rows, cols = 140, 320
    ground = np.empty((rows, cols, 3), np.uint8)
    ground[:] = GROUND
    primed = ground.copy()
    primed[80:130, 100:125] = (150, 60, 30)  # someone who stood there while it was primed
    frame = ground.copy()
    frame[30:60, 100:120] = (40, 40, 200)  # a torso, its legs shadow-like down to row 80
    frame[60:80, 100:120] = np.round(0.65 * GROUND).astype(np.uint8)
    boxes = {}
    for leg_height in (0.0, 0.8):
        det = make_detector("paper", leg_height=leg_height, leg_fill=0.2)
        det.prime([primed] * 3)
        size = det.size_model
        for foot in np.linspace(50, 130, 40):  # h = 0.5 foot + 20: a head at row 30, foot row 100
            h = 0.5 * foot + 20
            size.observe(np.array([[10.0, foot - h, 20.0, h]]))  # 20 px wide
        np.testing.assert_allclose(size.coefficients[0], [0.5, 20.0], atol=1e-9)
        d = det.detect(frame)
        assert len(d) == 1 and det._ghost is not None and det._ghost[80:130, 100:125].all()
        boxes[leg_height] = d.boxes[0]
    np.testing.assert_array_equal(boxes[0.0], [100, 30, 20, 30])  # the torso alone
    # through the shadow, but not into the ghost below it (which the foot row 100 would allow)
    np.testing.assert_array_equal(boxes[0.8], [100, 30, 20, 50])
