"""``Tracker(record=False)``: an online tracker for unbounded streams, whose memory stays flat."""

from __future__ import annotations

import pickle
import tracemalloc

import numpy as np
import pytest

import pftrack
import pftrack.tracking.tracker
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking.api import xywh_to_xyxy_dets


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=60, n_walkers=6, rng=3, fps=25.0)


def truth_dets(scene):
    by_frame = group_by_frame(scene.truth)
    empty = np.zeros((0, 10))
    return [
        xywh_to_xyxy_dets(by_frame.get(f, empty)[:, 2:7]) for f in range(1, len(scene.frames) + 1)
    ]


@pytest.mark.parametrize("given", [True, False], ids=["detections", "built-in"])
def test_update_returns_what_a_recording_tracker_returns(scene, given):
    dets = truth_dets(scene) if given else [None] * len(scene.frames)
    recording = pftrack.Tracker(25.0, seed=4)
    online = pftrack.Tracker(25.0, seed=4, record=False)
    n_tracked = 0
    for d, frame in zip(dets, scene.frames, strict=True):
        a, b = recording.update(d, frame), online.update(d, frame)
        np.testing.assert_array_equal(a, b)
        n_tracked += len(a)
    assert n_tracked > 100  # the scene's walkers were tracked, not an empty comparison
    assert len(recording.finalize())
    assert online.n_settled == 0


def test_finalize_and_settled_rows_refuse(scene):
    tracker = pftrack.Tracker(25.0, record=False)
    tracker.update(truth_dets(scene)[0], scene.frames[0])
    for call in (tracker.finalize, tracker.settled_rows):
        with pytest.raises(RuntimeError, match=r"record=False, which keeps no rows"):
            call()
    # the refusal changed nothing: the run goes on
    tracker.update(truth_dets(scene)[1], scene.frames[1])


def test_settled_rows_start_is_an_int_from_0(scene):
    """Was ``slice indices must be integers`` for 1.5, and every row for -1."""
    tracker = pftrack.Tracker(25.0, seed=4)
    for d, frame in zip(truth_dets(scene)[:20], scene.frames[:20], strict=True):
        tracker.update(d, frame)
    n = tracker.n_settled
    assert n > 2
    assert len(tracker.settled_rows()) == n
    assert len(tracker.settled_rows(np.int64(2))) == n - 2
    assert len(tracker.settled_rows(n)) == len(tracker.settled_rows(n + 5)) == 0
    for bad, error, message in (
        (1.5, TypeError, r" must be an int >= 0, got float 1\.5$"),
        (True, TypeError, r" must be an int >= 0, got bool True$"),
        ("2", TypeError, r" must be an int >= 0, got str '2'$"),
        (-1, ValueError, r" is -1, expected an int >= 0$"),
    ):
        with pytest.raises(error, match=rf"^Tracker\.settled_rows: start{message}"):
            tracker.settled_rows(bad)  # type: ignore[arg-type]


def test_record_is_a_flag():
    with pytest.raises(TypeError, match="record"):
        pftrack.Tracker(record="no")  # type: ignore[arg-type]


def test_a_checkpoint_keeps_the_option(scene):
    tracker = pftrack.Tracker(25.0, record=False)
    tracker.update(truth_dets(scene)[0], scene.frames[0])
    copy = pickle.loads(pickle.dumps(tracker))
    assert copy.record is False
    with pytest.raises(RuntimeError, match="record=False"):
        copy.finalize()


def _growth(record: bool) -> int:
    """Python-heap bytes the tracker gained from the end of its 2nd loop of a scene to its 4th.

    Both ends at the same place in the loop: as many live tracks (their filters' arrays).
    """
    scene = make_scene(n_frames=60, width=240, height=180, n_walkers=6, rng=3, fps=25.0)
    dets = truth_dets(scene)
    tracker = pftrack.Tracker(25.0, refine=False, record=record)
    tracemalloc.start()
    try:
        for k in range(240):
            tracker.update(dets[k % 60], scene.frames[k % 60])
            if k == 119:
                start = tracemalloc.get_traced_memory()[0]
        return tracemalloc.get_traced_memory()[0] - start
    finally:
        tracemalloc.stop()


@pytest.mark.slow
def test_memory_stays_flat_without_recording(monkeypatch):
    # The recording tracker's rows grow (22 KB here: its rows and the camera path); the online
    # one keeps nothing that grows. The tracker's window of recent speeds is bounded (5000
    # samples, about 200 KB when full): a window of 100 is full before frame 60, so what is
    # left is any growth without bound.
    monkeypatch.setattr(pftrack.tracking.tracker, "MAX_SPEED_SAMPLES", 100)
    kept = _growth(True)
    online = _growth(False)
    assert kept > 10_000, kept  # 22 KB when measured
    assert online < 3_000, (online, kept)  # 0.9 KB when measured: small objects come and go


def test_nothing_is_kept_without_recording(scene):
    # what the slow test measures, by the holders of a recording run's rows: the writer's rows
    # and the camera path the offline pass needs, and the detections' sizes its size rule
    # fits (size_ratio, on by default: were kept without recording, 33 KB in the slow test)
    tracker = pftrack.Tracker(25.0, refine=False, record=False)
    for d, frame in zip(truth_dets(scene), scene.frames, strict=True):
        tracker.update(d, frame)
    assert len(tracker._writer.rows) == 0
    assert tracker._stabiliser.to_first == []
    assert tracker._sizes == []
