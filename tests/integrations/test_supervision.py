"""pftrack.integrations.supervision against the real supervision (in the test extra)."""

from __future__ import annotations

import pickle
import subprocess
import sys

import numpy as np
import pytest
import supervision as sv

import pftrack
from pftrack.integrations.supervision import SupervisionTracker
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=30, rng=2)


def frame_detections(scene, n):
    r = group_by_frame(scene.truth).get(n, np.zeros((0, 10)))
    xyxy = np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6]])
    return sv.Detections(
        xyxy=xyxy,
        confidence=np.full(len(r), 0.95),
        class_id=np.zeros(len(r), int),
        data={"truth_id": r[:, 1].astype(int)},
    )


def test_update_with_detections_sets_tracker_id_like_the_tracker(scene):
    adapter = SupervisionTracker(frame_rate=10.0, seed=1)
    plain = pftrack.Tracker(frame_rate=10.0, seed=1)
    seen = 0
    for n, frame in enumerate(scene.frames, start=1):
        dets = frame_detections(scene, n)
        out = adapter.update_with_detections(dets, frame)
        ref = plain.update(np.column_stack([dets.xyxy, dets.confidence, dets.class_id]), frame)
        # in the input's order, as ByteTrack keeps it (a user trial: they were in track order,
        # which the docstring said ByteTrack gives)
        ref = ref[np.argsort(ref[:, 7], kind="stable")]
        assert isinstance(out, sv.Detections) and out.tracker_id is not None
        np.testing.assert_array_equal(out.tracker_id, ref[:, 4].astype(int))
        # the rows are the input detections the tracks were matched to, with all their fields
        rows = ref[:, 7].astype(int)
        assert (np.diff(rows) >= 0).all()
        np.testing.assert_array_equal(out.xyxy, dets.xyxy[rows])
        np.testing.assert_array_equal(out.data["truth_id"], dets.data["truth_id"][rows])
        seen += len(out)
    assert seen > 0.7 * len(scene.truth)
    np.testing.assert_array_equal(adapter.finalize(), plain.finalize())
    adapter.reset()
    assert adapter.tracker.frame_count == 0


def test_prime_is_the_plain_loops(scene):
    # the adapter had no prime(): its users could not reach the command's rows
    adapter = SupervisionTracker(frame_rate=10.0, seed=1)
    plain = pftrack.Tracker(frame_rate=10.0, seed=1)
    unprimed = SupervisionTracker(frame_rate=10.0, seed=1)
    adapter.prime(iter(scene.frames))
    plain.prime(iter(scene.frames))
    for n, frame in enumerate(scene.frames, start=1):
        dets = frame_detections(scene, n)
        adapter.update_with_detections(dets, frame)
        unprimed.update_with_detections(dets, frame)
        plain.update(np.column_stack([dets.xyxy, dets.confidence, dets.class_id]), frame)
    rows = adapter.finalize()
    np.testing.assert_array_equal(rows, plain.finalize())
    assert not np.array_equal(rows, unprimed.finalize())  # priming changed something
    with pytest.raises(ValueError, match="before the first update"):
        adapter.prime(iter(scene.frames))


def test_ids_follow_the_truth(scene):
    adapter = SupervisionTracker(frame_rate=10.0)
    pairs = set()
    for n, frame in enumerate(scene.frames, start=1):
        out = adapter.update_with_detections(frame_detections(scene, n), frame)
        pairs |= set(zip(out.tracker_id.tolist(), out.data["truth_id"].tolist(), strict=True))
    tracker_ids = [t for t, _ in pairs]
    assert len(tracker_ids) == len(set(tracker_ids))  # one truth per tracker id


def test_empty_and_bad_input(scene):
    adapter = SupervisionTracker()
    out = adapter.update_with_detections(sv.Detections.empty(), scene.frames[0])
    assert len(out) == 0
    with pytest.raises(TypeError, match="supervision.Detections"):
        adapter.update_with_detections(np.zeros((0, 5)), scene.frames[0])
    # a user trial: "Tracker.__init__() got an unexpected keyword argument 'bogus'"
    with pytest.raises(TypeError, match="^SupervisionTracker got an unknown option 'bogus'"):
        SupervisionTracker(bogus=1)  # type: ignore[call-arg]


@pytest.mark.parametrize("empty", [False, True])
def test_detections_given_to_the_plain_tracker_name_the_adapter(scene, empty):
    # a user trial: Tracker.update(sv.Detections, frame) said "dets must be a rectangular array
    # of numbers, got rows of different lengths", and empty Detections were taken silently as
    # a frame without detections
    dets = frame_detections(scene, 1)
    tracker = pftrack.Tracker()
    with pytest.raises(TypeError) as e:
        tracker.update(sv.Detections.empty() if empty else dets, scene.frames[0])
    assert str(e.value) == (
        "dets is a supervision Detections: use pftrack.integrations.supervision."
        "SupervisionTracker's update_with_detections(detections, frame), or give "
        "np.column_stack([d.xyxy, d.confidence, d.class_id])"
    )
    assert tracker.frame_count == 0


def test_boxes_without_area_and_inverted_boxes(scene):
    # a frame whose only box had no area raised "the boxes look like x, y, w, h": supervision's
    # boxes are always x1, y1, x2, y2, and a box without area is dropped (one warning)
    adapter = SupervisionTracker()
    flat = sv.Detections(xyxy=np.array([[320.0, 10, 320, 50]]), confidence=np.array([0.4]))
    with pytest.warns(UserWarning, match="^1 detection box without area"):
        assert len(adapter.update_with_detections(flat, scene.frames[0])) == 0
    inverted = sv.Detections(xyxy=np.array([[60.0, 10, 20, 90], [200, 40, 150, 120]]))
    message = (
        r"^detections row 0 \[60.0, 10.0, 20.0, 90.0\] has x2 < x1 or y2 < y1, as have 2 of the "
        r"2 boxes given \(x1, y1, x2, y2 expected\)$"  # no x, y, w, h hint
    )
    with pytest.raises(ValueError, match=message):
        adapter.update_with_detections(inverted, scene.frames[1])


@pytest.mark.parametrize(
    ("field", "value", "error", "message"),
    [
        ("confidence", np.array([0.9, np.nan]), ValueError,
         r"^detections.confidence\[1\] is nan, expected a finite number$"),
        ("xyxy", np.array([[10.0, 10, 40, 90], [50, np.inf, 80, 90]]), ValueError,
         r"^detections.xyxy\[1\] is \[50.0, inf, 80.0, 90.0\], expected finite numbers$"),
        ("class_id", np.array([0, 1.5]), ValueError,
         r"^detections.class_id\[1\] is 1.5, expected an integer in \[-2147483648, 2147483647\]$"),
        ("class_id", np.array(["person", "car"]), TypeError,
         r"^detections.class_id must hold real numbers, got dtype <U6$"),
    ],
)  # fmt: skip
def test_bad_fields_are_named_as_supervisions(scene, field, value, error, message):
    """A bad value is named by its Detections field (was: "detections row 1 contains NaN or
    inf: [..., nan, 0.0]", six columns with a class the user never gave, or "(column 6: x1,
    y1, x2, y2, conf, cls)", or "detections must hold real numbers" for class names)."""
    detections = sv.Detections(
        xyxy=np.array([[10.0, 10, 40, 90], [50, 10, 80, 90]]),
        confidence=np.array([0.9, 0.8]),
        class_id=np.array([0, 1]),
    )
    # set after it is made: supervision 0.31 refuses a non-finite xyxy itself when made
    setattr(detections, field, value)
    adapter = SupervisionTracker()
    with pytest.raises(error, match=message):
        adapter.update_with_detections(detections, scene.frames[0])
    assert adapter.tracker.frame_count == 0


def test_supervision_is_imported_lazily():
    code = (
        "import sys, pftrack.integrations.supervision as m, pftrack; pftrack.Tracker; "
        "print('supervision' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_the_adapters_options_are_the_trackers():
    """``SupervisionTracker(**options)`` is typed by TrackerOptions: the Tracker's own options."""
    import inspect

    from pftrack.integrations.supervision import TrackerOptions

    params = inspect.signature(pftrack.Tracker.__init__).parameters
    theirs = {n: str(p.annotation) for n, p in params.items() if p.kind is p.KEYWORD_ONLY}
    ours = {n: getattr(t, "__forward_arg__", t) for n, t in TrackerOptions.__annotations__.items()}
    assert ours == theirs


@pytest.mark.skipif(sys.version_info < (3, 11), reason="typing.Unpack is Python 3.11's")
def test_the_adapters_hints_resolve_at_run_time():
    """``typing.get_type_hints`` (pydantic, typer, docs tools) names no missing name."""
    import typing

    from pftrack._typing import RealLike

    hints = typing.get_type_hints(SupervisionTracker.__init__)
    assert hints["frame_rate"] == RealLike  # any real number, as Tracker's frame_rate
    hints = typing.get_type_hints(SupervisionTracker.update_with_detections, localns={"sv": sv})
    assert hints["return"] is sv.Detections


def test_the_adapters_warnings_name_the_callers_line(scene):
    """A user trial: clipping, negative and above-1 confidences were said at the adapter's own
    line, as if pftrack had called itself wrongly."""
    tracker = SupervisionTracker(frame_rate=7.0)
    boxes = np.array([[-10.0, 30, 40, 90], [60, 20, 90, 100]])
    detections = sv.Detections(xyxy=boxes, confidence=np.array([5.0, -1.0]))
    with pytest.warns(UserWarning) as caught:
        tracker.update_with_detections(detections, scene.frames[0])
    assert len(caught) >= 3
    assert {w.filename for w in caught} == {__file__}


def test_update_returns_every_detection_as_the_trackers_package_does(scene):
    """A user trial: supervision 0.28 deprecated sv.ByteTrack for the ``trackers`` package's
    ``ByteTrackTracker``, whose ``update(detections, frame=None)`` returns every detection,
    tracker_id -1 on the untracked ones; ``SupervisionTracker.update`` was an AttributeError."""
    a, b = SupervisionTracker(frame_rate=10.0), SupervisionTracker(frame_rate=10.0)
    untracked = 0
    for n, frame in enumerate(scene.frames, start=1):
        dets = frame_detections(scene, n)
        everything = a.update(dets, frame)
        tracked = b.update_with_detections(dets, frame)
        assert len(everything) >= len(dets)  # each once, a blob's once per track
        minus = everything[everything.tracker_id == -1]  # as given (truth ids: one row each)
        given = {t: tuple(x) for t, x in zip(dets.data["truth_id"], dets.xyxy, strict=True)}
        pairs = zip(minus.data["truth_id"], minus.xyxy, strict=True)
        assert all(given[t] == tuple(x) for t, x in pairs)
        kept = everything[everything.tracker_id != -1]
        np.testing.assert_array_equal(kept.tracker_id, tracked.tracker_id)
        np.testing.assert_array_equal(kept.xyxy, tracked.xyxy)
        np.testing.assert_array_equal(kept.data["truth_id"], tracked.data["truth_id"])
        # the input's order: the truth ids of the rows back, as given
        assert list(dict.fromkeys(everything.data["truth_id"])) == list(dets.data["truth_id"])
        untracked += int((everything.tracker_id == -1).sum())
    assert untracked > 0  # the first frames' tracks are not yet confirmed
    np.testing.assert_array_equal(a.finalize(), b.finalize())
    # its warnings name the caller's line too, and the frame is needed (pftrack follows colour)
    detections = sv.Detections(xyxy=np.array([[-10.0, 30, 40, 90]]), confidence=np.array([5.0]))
    with pytest.warns(UserWarning) as caught:
        SupervisionTracker().update(detections, scene.frames[0])
    assert caught and {w.filename for w in caught} == {__file__}
    with pytest.raises(TypeError, match="frame"):
        SupervisionTracker().update(detections)
    empty = SupervisionTracker().update(sv.Detections.empty(), scene.frames[0])
    assert len(empty) == 0 and empty.tracker_id is not None


def test_the_adapters_no_track_warning_names_the_callers_line(scene):
    """A trial find: ``finalize``'s "no track" warning named the adapter's own line
    (pftrack/integrations/supervision.py), as update's warnings once did."""
    tracker = SupervisionTracker()
    detections = sv.Detections(xyxy=np.array([[10.0, 30, 40, 90]]), confidence=np.array([0.1]))
    tracker.update_with_detections(detections, scene.frames[0])
    with pytest.warns(RuntimeWarning, match="^no track over 1 frame") as caught:
        tracker.finalize()
    assert [w.filename for w in caught] == [__file__]


# As tests/tracking/test_api_checkpoint.py's: in a child process, where protocols 0 and 1
# aborted the interpreter once the background model existed.
ADAPTER_AT_EVERY_PROTOCOL = """
import pickle
import numpy as np
import supervision as sv
from pftrack.integrations.supervision import SupervisionTracker
from pftrack.synthetic import make_scene

scene = make_scene(n_frames=20, rng=2)
truth = scene.truth

def dets(k):
    r = truth[truth[:, 0] == k + 1]
    xyxy = np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6]])
    return sv.Detections(xyxy=xyxy, confidence=np.full(len(r), 0.95),
                         class_id=np.zeros(len(r), int))

for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
    a = SupervisionTracker()
    a.prime(scene.frames[:5])
    for k in range(6):
        a.update_with_detections(dets(k), scene.frames[k])
    b = pickle.loads(pickle.dumps(a, protocol=protocol))
    for k in range(6, len(scene.frames)):
        out_a = a.update_with_detections(dets(k), scene.frames[k])
        out_b = b.update_with_detections(dets(k), scene.frames[k])
        assert out_a.xyxy.tobytes() == out_b.xyxy.tobytes(), (protocol, k)
        assert out_a.tracker_id.tolist() == out_b.tracker_id.tolist(), (protocol, k)
    rows = a.finalize()
    assert len(rows) and rows.tobytes() == b.finalize().tobytes(), protocol
    print(protocol, "resumed", flush=True)
"""


def test_a_checkpoint_at_every_pickle_protocol_resumes_byte_for_byte():
    run = subprocess.run(
        [sys.executable, "-c", ADAPTER_AT_EVERY_PROTOCOL], capture_output=True, text=True,
        timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split("\n")[:-1] == [
        f"{p} resumed" for p in range(pickle.HIGHEST_PROTOCOL + 1)
    ]


@pytest.mark.parametrize("dtype", [np.float32, np.int32, np.float64])
def test_tracks_sharing_a_detection_keep_the_inputs_order_and_dtype(dtype):
    """A user trial: on frames where two tracks shared a detection (a blob) the boxes came back
    float64 (float32 on every other frame), and in track order."""
    adapter = SupervisionTracker()
    rows = [[30, 10, 40, 40, 3, 0.9, 0, 1], [10, 10, 20, 40, 1, 0.9, 0, 0],
            [15, 10, 25, 40, 2, 0.9, 0, 0]]  # fmt: skip
    adapter.tracker.update = lambda dets, frame: np.array(rows, float)  # type: ignore[method-assign]
    dets = sv.Detections(
        xyxy=np.array([[10, 10, 25, 40], [30, 10, 40, 40]], dtype),
        confidence=np.array([0.9, 0.9], np.float32),
    )
    out = adapter.update_with_detections(dets, np.zeros((100, 100, 3), np.uint8))
    assert out.xyxy.dtype == dtype
    assert out.tracker_id.tolist() == [1, 2, 3]  # detection 0's two tracks, then detection 1's
    np.testing.assert_array_equal(out.xyxy, np.array([r[:4] for r in rows[1:] + rows[:1]], dtype))
