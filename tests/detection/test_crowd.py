"""Merged people read from their head tops (`pftrack.detection.crowd`, `crowd_split`)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from pftrack.detection import PaperConfig
from pftrack.detection.crowd import split_crowds
from pftrack.detection.size_model import PersonSizeModel

# a ground plane: h = 0.25 foot + 20, w = 0.4 h (as lines in the foot row)
LINES = np.array([[0.25, 20.0], [0.1, 8.0]])


def fitted() -> PersonSizeModel:
    """A person-size model fitted from 40 isolated people on the plane of `LINES`."""
    model = PersonSizeModel()
    foot = np.linspace(150.0, 330.0, 40)
    h = LINES[0, 0] * foot + LINES[0, 1]
    w = LINES[1, 0] * foot + LINES[1, 1]
    model.observe(np.column_stack([np.arange(40) * 1000.0, foot - h, w, h]))  # all isolated
    assert model.coefficients is not None
    np.testing.assert_allclose(model.coefficients, LINES, atol=1e-6)
    return model


def person(mask: np.ndarray, left: int, foot: int, w: int, h: int) -> np.ndarray:
    """Draw a walker (head, torso, two legs) into `mask`; return its box left, top, w, h."""
    top = foot - h
    head = max(6, h // 7)
    cx = left + w // 2
    cv2.ellipse(mask, (cx, top + head // 2), (max(3, w // 5), head // 2), 0, 0, 360, 255, -1)
    mask[top + head : top + int(0.55 * h), left : left + w] = 255
    leg = max(3, w // 3)
    mask[top + int(0.55 * h) : foot, cx - leg - 1 : cx - 1] = 255
    mask[top + int(0.55 * h) : foot, cx + 1 : cx + 1 + leg] = 255
    return np.array([left, top, w, h], np.float64)


def iou(a: np.ndarray, b: np.ndarray) -> float:
    lo = np.maximum(a[:2], b[:2])
    hi = np.minimum(a[:2] + a[2:], b[:2] + b[2:])
    inter = float(np.prod(np.clip(hi - lo, 0, None)))
    return inter / (a[2] * a[3] + b[2] * b[3] - inter)


def union(boxes: list[np.ndarray]) -> np.ndarray:
    lo = np.min([b[:2] for b in boxes], axis=0)
    hi = np.max([b[:2] + b[2:] for b in boxes], axis=0)
    return np.array([[*lo, *(hi - lo)]])


def sizes(foot: float) -> tuple[int, int]:
    h = LINES[0, 0] * foot + LINES[0, 1]
    return int(round(LINES[1, 0] * foot + LINES[1, 1])), int(round(h))


def test_two_people_touching_in_one_blob_become_two_boxes() -> None:
    mask = np.zeros((360, 480), np.uint8)
    w1, h1 = sizes(240.0)
    w2, h2 = sizes(225.0)  # a little farther, its torso against the first one's
    truth = [person(mask, 200, 240, w1, h1), person(mask, 200 + w1, 225, w2, h2)]
    blob = union(truth)
    assert max(iou(blob[0], t) for t in truth) < 0.6  # one box is neither person
    boxes, scores = split_crowds(mask, blob, np.array([0.7]), fitted())
    assert boxes.shape == (2, 4) and scores.shape == (2,)
    for t in truth:
        assert max(iou(b, t) for b in boxes) > 0.75
    assert np.all((scores > 0.25) & (scores <= 1.0))


def test_one_wide_person_stays_one_box() -> None:
    """One head, however wide the body: no second person (a broad coat, a bag)."""
    mask = np.zeros((360, 480), np.uint8)
    w, h = sizes(240.0)
    box = person(mask, 200, 240, 2 * w, h)[None]
    boxes, scores = split_crowds(mask, box, np.array([0.8]), fitted())
    np.testing.assert_array_equal(boxes, box)
    np.testing.assert_array_equal(scores, [0.8])


def test_nothing_changes_before_the_model_is_fitted_or_under_a_steep_line() -> None:
    mask = np.zeros((360, 480), np.uint8)
    w1, h1 = sizes(240.0)
    w2, h2 = sizes(225.0)
    blob = union([person(mask, 200, 240, w1, h1), person(mask, 200 + w1, 225, w2, h2)])
    boxes, _ = split_crowds(mask, blob, np.array([0.7]), PersonSizeModel())
    np.testing.assert_array_equal(boxes, blob)
    steep = fitted()
    steep._coef = np.array([[1.33, -300.0], [0.1, 8.0]])  # a camera at head height (TUD)
    boxes, _ = split_crowds(mask, blob, np.array([0.7]), steep)
    np.testing.assert_array_equal(boxes, blob)


def test_bad_input_is_one_line_naming_it() -> None:
    model = fitted()
    mask = np.zeros((40, 40), np.uint8)
    box, score = np.array([[1.0, 1.0, 5.0, 5.0]]), np.array([0.5])
    with pytest.raises(TypeError, match="split_crowds: mask is an array of shape"):
        split_crowds(mask.astype(np.float32), box, score, model)
    with pytest.raises(TypeError, match="split_crowds: mask is a list"):
        split_crowds([[0]], box, score, model)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"split_crowds: boxes is .*finite \(K, 4\)"):
        split_crowds(mask, np.array([[1.0, np.nan, 5.0, 5.0]]), score, model)
    with pytest.raises(ValueError, match=r"split_crowds: scores is .*expected \(1,\) floats"):
        split_crowds(mask, box, np.array([0.5, 0.5]), model)
    with pytest.raises(TypeError, match="PaperConfig: crowd_split must be True or False"):
        PaperConfig(crowd_split="yes")  # type: ignore[arg-type]
