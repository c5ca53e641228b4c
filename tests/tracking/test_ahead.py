"""The detector on a thread ahead of the tracker: same rows and same errors as in update()."""

from __future__ import annotations

import threading
import warnings
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

import pftrack
from pftrack.cli import main
from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene, move_camera
from pftrack.tracking import TrackerConfig, track_frames
from pftrack.tracking.ahead import DetectAhead
from pftrack.tracking.api import xywh_to_xyxy_dets
from pftrack.tracking.tracker import MultiObjectTracker


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=40, rng=3)


def as_file(scene):
    """The scene's truth as a detection file read by load_detections: {frame: (k, 5)}."""
    rows = group_by_frame(scene.truth)
    return {f: np.column_stack([r[:, 2:6], np.ones(len(r))]) for f, r in rows.items()}


def loop_rows(frames, config, seed, dets=None, bootstrap="spread"):
    """The tracker loop with the detector called inside update() (no thread)."""
    tracker = pftrack.Tracker.from_config(config, seed)
    primer = bootstrap_frames(frames, 30, bootstrap)
    if primer:
        tracker.prime(primer)
    empty = np.zeros((0, 5))
    for n, f in enumerate(frames, start=1):
        d = None if dets is None else xywh_to_xyxy_dets(dets.get(n, empty))
        tracker.update(d, f)
    return tracker.finalize()


def no_reader_thread():
    return not any(t.name == "pftrack-prefetch" for t in threading.enumerate())


@pytest.mark.parametrize("camera", ["auto", "on"])
def test_builtin_detector_ahead_gives_the_loops_rows(scene, camera):
    # "on": the background is never trusted, the tracker reads the detector's full-frame bins
    frames = move_camera(scene).frames if camera == "on" else scene.frames
    config = replace(TrackerConfig(), camera_motion=camera)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        run = track_frames(frames, config=config, rng=4)
        expected = loop_rows(frames, config, 4)
    # the built-in detector on a moving camera is said once a run, in both
    moving = [str(w.message) for w in said if "the camera counts as moving" in str(w.message)]
    assert len(moving) == (2 if camera == "on" else 0) and len(said) == len(moving), moving
    assert len(expected) > 0
    np.testing.assert_array_equal(run.rows, expected)


@pytest.mark.parametrize("detector", ["paper", "mog2"])
def test_foreground_ahead_gives_the_loops_rows(scene, detector):
    config = replace(TrackerConfig(), detector=detector)
    assert config.refine.enabled
    run = track_frames(scene.frames, detections=as_file(scene), config=config, rng=2)
    expected = loop_rows(scene.frames, config, 2, as_file(scene), bootstrap="first")
    assert len(expected) > 0
    np.testing.assert_array_equal(run.rows, expected)


def resized_at(frames, k):
    """`frames` with frame `k` (0-based) half the size: the detector refuses it."""
    out = list(frames)
    out[k] = np.ascontiguousarray(out[k][::2, ::2])
    return out


@pytest.mark.parametrize("external", [False, True])
def test_detector_error_is_the_loops_error(scene, external):
    frames = resized_at(scene.frames, 12)
    # no box on the small frame: its only error is the detector's
    dets = {f: v for f, v in as_file(scene).items() if f != 13} if external else None
    config = TrackerConfig()
    with pytest.raises(ValueError) as in_loop:
        loop_rows(frames, config, 0, dets, bootstrap="none")
    with pytest.raises(ValueError) as ahead:
        track_frames(frames, detections=dets, config=config, rng=0, prime_frames=0)
    # the tracker refuses the new size before its detector sees it, in the loop and ahead alike
    assert "frame is 240x180, the run's earlier frames 480x360" in str(in_loop.value)
    assert str(ahead.value) == str(in_loop.value)
    assert no_reader_thread()


def test_cli_reports_a_detector_error_in_one_line(scene, tmp_path, capsys, monkeypatch):
    # frames of another size are refused by the folder reader itself (naming the image), so
    # the detector is made to fail on the 16th frame it sees, on its thread
    from pftrack.detection.paper import PaperDetector

    folder = tmp_path / "images"
    folder.mkdir()
    for n, f in enumerate(scene.frames[:20], start=1):
        cv2.imwrite(str(folder / f"{n:06d}.png"), f)
    detect = PaperDetector.detect
    calls = []

    def failing(self, frame):
        calls.append(threading.current_thread().name)
        if len(calls) == 16:
            raise ValueError("PaperDetector.detect: the detector failed on this frame\n(two lines)")
        return detect(self, frame)

    monkeypatch.setattr(PaperDetector, "detect", failing)
    out = tmp_path / "t.txt"
    assert main(["track", str(folder), "--bootstrap", "none", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    said = "PaperDetector.detect: the detector failed on this frame (two lines)"
    assert err == f"pftrack track: error: {said}"
    assert threading.main_thread().name not in calls  # it ran on the detector's thread
    assert not out.exists()
    assert no_reader_thread()


def test_the_tracker_gets_its_detector_back(scene):
    mot = MultiObjectTracker(TrackerConfig(), rng=0)
    detector = mot.detector
    with DetectAhead(mot, scene.frames[:5], external=False) as frames:
        assert mot.detector is not detector
        for frame in frames:
            mot.update(frame, None)
    assert mot.detector is detector
    assert no_reader_thread()


def test_a_frame_the_thread_did_not_detect_is_refused(scene):
    mot = MultiObjectTracker(TrackerConfig(), rng=0)
    with DetectAhead(mot, scene.frames[:5], external=False) as frames:
        next(frames)
        with pytest.raises(RuntimeError, match="did not detect"):
            mot.update(scene.frames[1].copy(), None)
    assert no_reader_thread()


def test_folder_source_is_read_once_in_order(scene, tmp_path: Path):
    # a FrameSource behind the thread: the detector sees every frame once, in order
    folder = tmp_path / "seq"
    folder.mkdir()
    for n, f in enumerate(scene.frames, start=1):
        cv2.imwrite(str(folder / f"{n:06d}.png"), f)
    from pftrack.io.video import FrameSource

    run = track_frames(FrameSource(folder), rng=1)
    frames = list(FrameSource(folder))
    np.testing.assert_array_equal(run.rows, loop_rows(frames, TrackerConfig(), 1))


def test_without_threads_the_rows_are_the_same(scene):
    # threads=False (a batch worker): everything on the calling thread, the same rows
    config = TrackerConfig()
    on = track_frames(scene.frames, config=config, rng=0)
    before = {t.name for t in threading.enumerate()}
    off = track_frames(scene.frames, config=config, rng=0, threads=False)
    assert {t.name for t in threading.enumerate()} == before
    np.testing.assert_array_equal(on.rows, off.rows)
    dets = as_file(scene)
    on = track_frames(scene.frames, detections=dets, config=config, rng=0)
    off = track_frames(scene.frames, detections=dets, config=config, rng=0, threads=False)
    np.testing.assert_array_equal(on.rows, off.rows)


@pytest.mark.parametrize("read_depth", [None, 2])
def test_the_cameras_grey_is_made_ahead(scene, monkeypatch, read_depth):
    # each frame's grey for the camera-motion check is made on a thread (with read_depth the
    # reading one, which also prepares the frames) and handed over: update() makes none
    from pftrack.tracking import camera

    made, prepared, detected = [], [], []
    grey = camera._Measure.grey

    def recorded(self, frame):
        made.append(threading.get_ident())
        return grey(self, frame)

    def prepare(frame):
        prepared.append(threading.get_ident())
        return frame

    frames = move_camera(scene).frames[:12]
    config = replace(TrackerConfig(), camera_motion="on")
    alone = MultiObjectTracker(config, rng=0)
    expected = [(alone.update(f, None), alone.camera_step)[1] for f in frames]
    monkeypatch.setattr(camera._Measure, "grey", recorded)
    mot = MultiObjectTracker(config, rng=0)
    real = mot.detector
    detect = real.detect

    def detect_recorded(frame):
        detected.append(threading.get_ident())
        return detect(frame)

    monkeypatch.setattr(real, "detect", detect_recorded)
    steps = []
    with DetectAhead(mot, frames, external=False, prepare=prepare, read_depth=read_depth) as ahead:
        for frame in ahead:
            mot.update(frame, None)
            steps.append(mot.camera_step)
    main = threading.get_ident()
    assert len(made) == len(frames) and main not in made
    assert set(made) == set(prepared) and len(set(made)) == 1
    # the reading thread is not the detector's
    assert (set(made) == set(detected)) == (read_depth is None)
    assert any(s.apply is not None for s in expected)
    for got, want in zip(steps, expected, strict=True):
        assert got.moving == want.moving and got.magnitude == want.magnitude
        np.testing.assert_array_equal(got.apply, want.apply)
    assert no_reader_thread()
