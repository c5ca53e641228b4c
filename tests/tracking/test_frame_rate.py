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
from pftrack.tracking.tracker import (
    MAX_SPEED_SAMPLES,
    MIN_SPEED_SAMPLES,
    MultiObjectTracker,
    RollingMedian,
)


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


def _add_speeds(tr, value, n, cls=0):
    speeds = tr._speeds.setdefault(cls, RollingMedian(MAX_SPEED_SAMPLES))
    for _ in range(n):
        speeds.add(value)


def test_motion_gain_rule():
    cfg = TrackerConfig(motion=MotionConfig(speed_reference=0.05))
    tr = MultiObjectTracker(cfg, rng=0)
    assert tr.motion_gain() == 1.0
    _add_speeds(tr, 0.1, MIN_SPEED_SAMPLES - 1)
    assert tr.motion_gain() == 1.0  # too few samples
    _add_speeds(tr, 0.1, 1)
    assert tr.motion_gain() == pytest.approx(2.0**1.5)
    assert tr.motion_gain(2) == 1.0  # another class: its own samples (none)
    _add_speeds(tr, 0.4, MIN_SPEED_SAMPLES, cls=2)
    assert tr.motion_gain(2) == pytest.approx(8.0**1.5)
    assert tr.motion_gain() == pytest.approx(2.0**1.5)  # class 0's as it was
    assert tr.motion_gains == pytest.approx({0: 2.0**1.5, 2: 8.0**1.5})
    slow = MultiObjectTracker(cfg, rng=0)
    _add_speeds(slow, 0.02, MIN_SPEED_SAMPLES)
    assert slow.motion_gain() == 1.0  # slower than the reference: as given
    none = dataclasses.replace(cfg, motion=MotionConfig(speed_reference=None))
    off = MultiObjectTracker(none, rng=0)
    _add_speeds(off, 0.1, MIN_SPEED_SAMPLES)
    assert off.motion_gain() == 1.0  # None: the levels as given


def _people_and_cars(speed=14.0, n_frames=40):
    """Frames of `make_scene`'s walkers with fast cars (class 2) along the top, and the
    detections of both, ``x1, y1, x2, y2, conf, cls`` per frame."""
    scene = make_scene(n_frames, n_walkers=3, rng=0, occluder=False)
    people = group_by_frame(scene.truth)
    out = []
    for f, frame in enumerate(scene.frames, start=1):
        dets = [[x, y, x + w, y + h, 0.95, 0.0] for x, y, w, h in people[f][:, 2:6].tolist()]
        for k in range(0, f, 5):  # a car every 5 frames, 70x30, `speed` pixels a frame
            x = -70 + speed * (f - k)
            if 0 <= x <= 480 - 70:
                frame[20:50, int(x) : int(x) + 70] = (40 + 30 * (k % 5), 60, 200)
                dets.append([int(x), 20.0, int(x) + 70, 50.0, 0.95, 2.0])
        out.append((frame, np.array(dets)))
    return out


def test_fast_cars_leave_the_peoples_motion_noise_alone():
    """Each class's speed gives its own gain: cars at 0.47 heights a frame raise their own
    acceleration levels, not the walkers' (was: one median over every class, so the cars'
    samples raised the people's noise too)."""
    tracker = pftrack.Tracker(frame_rate=10.0, seed=0)
    for frame, dets in _people_and_cars():
        tracker.update(dets, frame)
    mot = tracker._tracker
    assert mot.motion_gain() == 1.0  # the walkers' (class 0's)
    assert mot.speed_of(2) > 0.3 > 0.065 > mot.speed_of(0)
    assert mot.motion_gain(2) > 10.0
    assert mot.speed == mot.speed_of(0)
    people = [t for t in mot.tracks if t.cls == 0]
    assert people
    # the gains the walkers' centre filters predict with: the levels as given
    assert [mot._gains.get(t.cls, 1.0) for t in people] == [1.0] * len(people)


def test_rolling_median_is_numpys_median_of_the_last_values():
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


def test_finalize_smooths_each_class_with_its_own_gain():
    """The offline smoother's levels grow with each class's own speed: the walkers' rows are
    smoothed as in a run whose gain is 1, the cars' with their own (was: both with the gain
    of every class's median)."""
    tracker = pftrack.Tracker(frame_rate=10.0, seed=0)
    for frame, dets in _people_and_cars():
        tracker.update(dets, frame)
    rows = tracker.finalize()
    gain = tracker._tracker.motion_gain(2)
    writer, smoother = tracker._writer, tracker._writer_args[2]
    fast = dataclasses.replace(
        smoother, accel=smoother.accel * gain, size_accel=smoother.size_accel * gain
    )
    as_given = writer.result(drop=tracker._tracker.never_confirmed(), relink_coast=7)
    own = writer.result(drop=tracker._tracker.never_confirmed(), relink_coast=7,
                        smoothers={2: fast})  # fmt: skip
    car = np.isin(own[:, 1], [i for i, c in writer.classes.items() if c == 2])
    np.testing.assert_array_equal(rows, own)
    np.testing.assert_array_equal(own[~car], as_given[~car])  # the walkers: gain 1
    assert not np.array_equal(own[car], as_given[car])
