"""Lower frame rates and sparse detections: empty frames, the speed rule, whole runs."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import pftrack
from pftrack.eval import evaluate_mot
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import TrackerConfig
from pftrack.tracking.api import xywh_to_xyxy_dets
from pftrack.tracking.config import LifecycleConfig, MotionConfig
from pftrack.tracking.track import LiveTrack
from pftrack.tracking.tracker import MIN_SPEED_SAMPLES, MultiObjectTracker


def jittered_dets(truth, n_frames, rng=0, size=(480, 360)):
    """Per-frame (N, 5) x1, y1, x2, y2, conf from truth rows, centres moved by 3 % of a height.

    Boxes are kept inside the `size` frame, as a detector's are.
    """
    g = np.random.default_rng(rng)
    by_frame = group_by_frame(truth)
    out = []
    for f in range(1, n_frames + 1):
        r = by_frame.get(f, np.zeros((0, 10)))
        boxes = r[:, 2:6].copy()
        boxes[:, :2] += g.normal(0.0, 0.03, (len(r), 2)) * boxes[:, 3:4]
        xyxy = xywh_to_xyxy_dets(np.column_stack([boxes, np.ones(len(r))]))
        xyxy[:, [0, 2]] = np.clip(xyxy[:, [0, 2]], 0, size[0])
        xyxy[:, [1, 3]] = np.clip(xyxy[:, [1, 3]], 0, size[1])
        keep = (xyxy[:, 2] - xyxy[:, 0] > 2) & (xyxy[:, 3] - xyxy[:, 1] > 2)
        out.append(xyxy[keep])
    return out


def track(frames, dets):
    tracker = pftrack.Tracker(seed=0)
    for d, f in zip(dets, frames, strict=True):
        tracker.update(d, f)
    return tracker.finalize()


def every_other(truth, stride):
    """Truth rows of frames 1, 1 + stride, ... renumbered 1, 2, ..."""
    r = truth[(truth[:, 0].astype(int) - 1) % stride == 0].copy()
    r[:, 0] = (r[:, 0].astype(int) - 1) // stride + 1
    return r


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=80, rng=1)


# -- whole runs -------------------------------------------------------------------------------
def test_a_detector_run_every_other_frame_gives_tracks(scene):
    """Empty (0, 5) arrays on even frames (the README's loop) no longer end every new track."""
    dets = jittered_dets(scene.truth, len(scene.frames))
    sparse = [d if f % 2 == 1 else np.zeros((0, 5)) for f, d in enumerate(dets, start=1)]
    every = evaluate_mot(scene.truth, track(scene.frames, dets))
    rows = track(scene.frames, sparse)
    assert len(rows)
    odd = evaluate_mot(scene.truth, rows)
    assert odd.mota > every.mota - 0.05, (odd.mota, every.mota)
    assert odd.num_switches <= every.num_switches + 2


def test_half_rate_tracks_close_to_full_rate(scene):
    full = evaluate_mot(scene.truth, track(scene.frames, jittered_dets(scene.truth, 80)))
    truth = every_other(scene.truth, 2)
    half = evaluate_mot(truth, track(scene.frames[::2], jittered_dets(truth, 40)))
    assert half.mota > full.mota - 0.05, (half.mota, full.mota)
    assert half.idf1 > full.idf1 - 0.05, (half.idf1, full.idf1)


# -- frames without detections do not count against tentative tracks -------------------------
def live(config=None):
    cfg = config or TrackerConfig()
    box = np.array([10.0, 10.0, 20.0, 50.0])
    hist = np.full(cfg.binning.n_bins, 1.0 / cfg.binning.n_bins)
    return LiveTrack(1, box, hist, cfg, 0, 1.0)


def test_a_frame_without_detections_is_not_a_miss():
    rules = LifecycleConfig()  # min_hits 4, tentative_coast 0, max_coast 10
    t = live()
    t.coast(detected=False)
    assert t.missed == 0 and t.time_since_update == 1
    assert t.alive(rules)
    t.coast(detected=True)
    assert t.missed == 1
    assert not t.alive(rules)  # a frame with detections it did not get


def test_a_tentative_track_still_ends_after_max_coast_empty_frames():
    rules = LifecycleConfig(max_coast=3)
    t = live()
    for _ in range(3):
        t.coast(detected=False)
    assert t.alive(rules)
    t.coast(detected=False)
    assert not t.alive(rules)


def test_a_match_clears_the_misses():
    rules = LifecycleConfig(tentative_coast=1)
    t = live()
    t.coast()
    assert t.missed == 1 and t.alive(rules)
    t.matched(1.0, 0)
    assert t.missed == 0 and t.time_since_update == 0


def test_confirmed_tracks_count_frames_as_before():
    rules = LifecycleConfig(max_coast=2)
    t = live()
    t.hits = rules.min_hits
    for _ in range(2):
        t.coast(detected=False)
    assert t.alive(rules)
    t.coast(detected=False)
    assert not t.alive(rules)


# -- the speed rule ---------------------------------------------------------------------------
def test_speed_is_distance_over_height_and_frames():
    t = live()
    h = 50.0
    assert t.speed(1, np.array([0.0, 0.0]), h, span=4) is None
    assert t.speed(3, np.array([10.0, 0.0]), h, span=4) is None  # 2 frames: too few
    v = t.speed(5, np.array([30.0, 40.0]), h, span=4)
    assert v == pytest.approx(50.0 / h / 4)
    # the trail starts at the sample's first point now
    assert t.trail[0][0] == 1


def test_motion_gain_rule():
    cfg = TrackerConfig(motion=MotionConfig(speed_reference=0.05))
    tr = MultiObjectTracker(cfg, rng=0)
    assert tr.motion_gain() == 1.0
    for _ in range(MIN_SPEED_SAMPLES - 1):
        tr._speeds.add(0.1)
    assert tr.motion_gain() == 1.0  # too few samples
    tr._speeds.add(0.1)
    assert tr.motion_gain() == pytest.approx(2.0**1.5)
    slow = MultiObjectTracker(cfg, rng=0)
    for _ in range(MIN_SPEED_SAMPLES):
        slow._speeds.add(0.02)
    assert slow.motion_gain() == 1.0  # slower than the reference: as given
    none = dataclasses.replace(cfg, motion=MotionConfig(speed_reference=None))
    off = MultiObjectTracker(none, rng=0)
    for _ in range(MIN_SPEED_SAMPLES):
        off._speeds.add(0.1)
    assert off.motion_gain() == 1.0  # None: the levels as given


def test_rolling_median_is_numpys_median_of_the_last_values():
    from pftrack.tracking.tracker import RollingMedian

    rng = np.random.default_rng(0)
    values = np.round(rng.gamma(2.0, 0.03, 400), 3)  # ties too
    for size in (1, 2, 7, 50, 1000):
        m = RollingMedian(size)
        assert m.median() is None and len(m) == 0
        for k, v in enumerate(values):
            m.add(v)
            window = values[max(0, k + 1 - size) : k + 1]
            assert len(m) == len(window)
            assert m.median() == float(np.median(window))  # the same float


def test_speed_reference_is_checked():
    with pytest.raises(ValueError, match="speed_reference"):
        MotionConfig(speed_reference=0.0)
    with pytest.raises(ValueError, match="speed_span"):
        MotionConfig(speed_span=0)
