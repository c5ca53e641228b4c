"""A flat colour likelihood is no measurement: the centre filter keeps its own prediction.

On a frame of one colour (the black frames of the public-detection runs without video) every
particle matches the reference equally, and the colour filter's estimate is only its own
motion prediction plus particle noise; taken as a measurement it moved the centre filter at
random (docs/tracking.md, identity with public detections).
"""

from __future__ import annotations

import copy

import numpy as np

from pftrack.particle_filter import box_histograms, hsv_bins
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.track import LiveTrack, colour_evidence, predict_tracks


def _track(frame: np.ndarray, box: list[float], seed: int, cfg: TrackerConfig) -> LiveTrack:
    image = hsv_bins(frame)
    b = np.array(box)
    hist = box_histograms(image, [[*(b[:2] + b[2:] / 2), *b[2:]]])[0] + 1e-3
    t = LiveTrack(seed, b, hist, cfg, seed, 0.9)
    t.motion.v = np.array([2.0, -1.0])  # moving: the prediction is not the starting point
    return t


def _textured(rng: np.random.Generator) -> np.ndarray:
    frame = rng.integers(60, 120, (120, 160, 3), dtype=np.uint8)
    frame[40:80, 30:50] = (20, 20, 220)
    return frame


def test_colour_evidence_is_the_spread_of_the_matches() -> None:
    assert not colour_evidence(1.0, 1.0)
    assert not colour_evidence(0.0, 0.0)  # no counted pixel in any box
    assert colour_evidence(0.6, 0.9)


def test_a_black_frame_leaves_the_centre_filter_to_its_prediction() -> None:
    cfg = TrackerConfig()
    black = np.zeros((120, 160, 3), np.uint8)
    for seed in range(5):
        t = _track(black, [30.0, 40.0, 20.0, 40.0], seed, cfg)
        want = copy.deepcopy(t.motion)
        for _ in range(3):
            want.predict(t.size[1])
            t.predict(hsv_bins(black), cfg.motion.colour_noise)
            np.testing.assert_array_equal(t.motion.p, want.p)
            np.testing.assert_array_equal(t.motion.v, want.v)
            assert t.motion.cov == want.cov


def test_a_coloured_frame_still_measures_the_centre() -> None:
    cfg = TrackerConfig()
    frame = _textured(np.random.default_rng(0))
    t = _track(frame, [30.0, 40.0, 20.0, 40.0], 1, cfg)
    want = copy.deepcopy(t.motion)
    want.predict(t.size[1])
    t.predict(hsv_bins(frame), cfg.motion.colour_noise)
    assert not np.array_equal(t.motion.p, want.p)
    assert t.motion.cov[0] < want.cov[0]  # a measurement shrinks the position variance


def test_predict_tracks_equals_predict_each_with_flat_and_coloured_tracks() -> None:
    cfg = TrackerConfig()
    frame = _textured(np.random.default_rng(1))
    frame[:, 100:] = 0  # the right part is black: a track there sees a flat likelihood
    boxes = [[30.0, 40.0, 20.0, 40.0], [120.0, 30.0, 15.0, 30.0], [110.0, 70.0, 20.0, 40.0]]

    def make() -> list[LiveTrack]:
        return [_track(frame, b, k, cfg) for k, b in enumerate(boxes)]

    batched, single = make(), make()
    flat = copy.deepcopy(batched[1].motion)
    image = hsv_bins(frame)
    predict_tracks(batched, image, cfg.motion.colour_noise)
    for s in single:
        s.predict(image, cfg.motion.colour_noise)
    for b, s in zip(batched, single, strict=True):
        np.testing.assert_array_equal(b.motion.p, s.motion.p)
        np.testing.assert_array_equal(b.motion.v, s.motion.v)
        assert b.motion.cov == s.motion.cov
        np.testing.assert_array_equal(b.box, s.box)
    flat.predict(batched[1].size[1])
    np.testing.assert_array_equal(batched[1].motion.p, flat.p)
