"""An unprimed Tracker's background learns its first frames around the given boxes.

docs/tracking.md, "A loop without prime, third candidate": while the paper's model learns
(`PaperConfig.n_learn` frames, a run `prime` did not start), the pixels the frame's given
boxes cover are not learnt, so the people walking through those frames leave no ghost.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import pftrack
from pftrack.detection.paper import PaperDetector, cover_mask
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking.api import xywh_to_xyxy_dets


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=40, width=160, height=120, n_walkers=3, rng=4)


def _boxes(scene):
    by_frame = group_by_frame(scene.truth)
    return [by_frame.get(f, np.zeros((0, 10)))[:, 2:6] for f in range(1, len(scene.frames) + 1)]


def _background(tracker: pftrack.Tracker) -> np.ndarray:
    detector = tracker._tracker.detector
    assert isinstance(detector, PaperDetector)
    return detector.model.background


def test_the_unprimed_background_is_learnt_around_the_given_boxes(scene):
    boxes = _boxes(scene)
    tracker = pftrack.Tracker(seed=0)
    reference = PaperDetector()
    for k, (frame, b) in enumerate(zip(scene.frames, boxes, strict=True), start=1):
        tracker.update(xywh_to_xyxy_dets(np.column_stack([b, np.ones(len(b))])), frame)
        reference.foreground(frame, cover=b)
        np.testing.assert_array_equal(_background(tracker), reference.model.background)
        if k == 30:  # the learning phase's end: no ghost where the walkers were on frame 1
            covered = cover_mask(boxes[0], frame.shape[:2]) != 0
            still = np.ones_like(covered)
            for later in boxes[1:30]:
                still &= cover_mask(later, frame.shape[:2]) != 0
            moved = covered & ~still  # frame 1's people, later gone from there
            assert moved.sum() > 50
            plain = PaperDetector()
            for f in scene.frames[:30]:
                plain.foreground(f)
            empty = scene.background.astype(np.float32)
            err = np.abs(_background(tracker) - empty).max(axis=2)[moved]
            err_plain = np.abs(plain.model.background - empty).max(axis=2)[moved]
            assert err.mean() < 0.5 * err_plain.mean()


@pytest.mark.parametrize("how", ["primed", "refine=False", "dets=None"])
def test_primed_unrefined_and_own_detector_runs_are_as_before(scene, how, monkeypatch):
    boxes = _boxes(scene)
    dets = [xywh_to_xyxy_dets(np.column_stack([b, np.ones(len(b))])) for b in boxes]
    rows = []
    real = PaperDetector.foreground

    def no_cover(self, frame, shadows=False, bins=True, cover=None):
        return real(self, frame, shadows, bins)

    for cover in (True, False):
        if not cover:  # the rule off: foreground() never given a cover
            monkeypatch.setattr(PaperDetector, "foreground", no_cover)
        tracker = pftrack.Tracker(seed=0, refine=how != "refine=False")
        if how == "primed":
            tracker.prime(itertools.islice(iter(scene.frames), 30))
        for frame, d in zip(scene.frames, dets, strict=True):
            tracker.update(None if how == "dets=None" else d, frame)
        rows.append(tracker.finalize())
    np.testing.assert_array_equal(rows[0], rows[1])


def test_a_bad_cover_is_refused(scene):
    detector = PaperDetector()
    with pytest.raises(ValueError, match=r"^PaperDetector.foreground: cover has shape \(4,\)"):
        detector.foreground(scene.frames[0], cover=np.zeros(4))
    with pytest.raises(ValueError, match="^PaperDetector.foreground: cover contains NaN"):
        detector.foreground(scene.frames[0], cover=[[0, 0, np.nan, 3]])
