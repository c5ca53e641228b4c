"""Frames and settings a user may pass by mistake: a clear error, or the frame used as it is.

A frame with no pixel, a non-frame given to ``prime``, a frame of another size mid-run, a
frame rate or seed of the wrong kind: one-line ``ValueError``/``TypeError`` naming the problem.
A BGR view that is not packed (``frame[..., ::-1]``, Fortran order, a crop) tracks exactly as
its packed copy.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import pftrack
from pftrack._check import bgr_frame
from pftrack.detection import make_detector
from pftrack.synthetic import make_scene
from pftrack.tracking import MultiObjectTracker, load_detections
from pftrack.tracking.camera import estimate_motion
from tests.conftest import dataset


@pytest.fixture(scope="module")
def frames() -> list[np.ndarray]:
    return make_scene(n_frames=8, n_walkers=2, rng=4).frames


@pytest.mark.parametrize("shape", [(0, 0, 3), (0, 5, 3), (5, 0, 3)])
def test_a_frame_without_pixels_is_refused(shape):
    empty = np.zeros(shape, np.uint8)
    with pytest.raises(ValueError, match="expected at least 1x1"):
        pftrack.Tracker().update(np.array([[1.0, 1.0, 5.0, 5.0, 0.9]]), empty)
    with pytest.raises(ValueError, match="expected at least 1x1"):
        pftrack.Tracker().update(None, empty)
    with pytest.raises(ValueError, match="expected at least 1x1"):
        MultiObjectTracker(rng=0).update(empty)


@pytest.mark.parametrize("shape", [(1, 500, 3), (500, 1, 3), (1, 1, 3), (2, 5000, 3)])
@pytest.mark.parametrize("camera_motion", ["auto", "on"])
def test_a_thin_frame_tracks(shape, camera_motion):
    """Every frame of at least 1x1 pixels (``bgr_frame``'s one check) is tracked.

    Was: ``cv2.error ... inv_scale_x > 0`` from the camera-motion estimate, whose scaled frame
    rounded to 0 pixels on a side.
    """
    rng = np.random.default_rng(0)
    h, w = shape[:2]
    tracker = pftrack.Tracker(camera_motion=camera_motion)
    with warnings.catch_warnings():  # "on" with the built-in detector: said, not asked about
        warnings.filterwarnings("ignore", "the camera counts as moving", UserWarning)
        for _ in range(5):
            tracker.update(None, rng.integers(0, 255, shape, dtype=np.uint8))
    out = tracker.update(np.array([[0.0, 0.0, w, h, 0.95]]), rng.integers(0, 255, shape, np.uint8))
    assert out.shape[1] == 8


def test_a_thin_image_folder_tracks_on_the_command_line(tmp_path, capsys):
    import cv2

    from pftrack.cli import main

    rng = np.random.default_rng(0)
    (tmp_path / "thin").mkdir()
    for k in range(1, 11):
        image = rng.integers(0, 255, (1, 500, 3), np.uint8)
        cv2.imwrite(str(tmp_path / "thin" / f"{k}.png"), image)
    out = tmp_path / "t.txt"
    assert main(["-q", "track", str(tmp_path / "thin"), "--out", str(out)]) == 0
    assert "10 frames" in capsys.readouterr().out and out.exists()


@pytest.mark.parametrize(
    ("bad", "error", "message"),
    [
        (None, TypeError, r"^prime frame is NoneType, expected a \(H, W, 3\) uint8 BGR array$"),
        (np.zeros((4, 4, 3)), TypeError, "^prime frame dtype is float64, expected uint8"),
        (np.zeros((4, 4), np.uint8), ValueError, r"^prime frame must have shape \(H, W, 3\)"),
    ],
)
def test_prime_refuses_what_is_not_a_frame(bad, error, message):
    with pytest.raises(error, match=message):
        pftrack.Tracker().prime([bad])


@pytest.mark.parametrize(
    ("frames", "got"),
    [
        (None, "got NoneType"),
        (3, "got int"),
        (np.zeros((6, 8, 3), np.uint8), r"got one \(6, 8, 3\) frame: prime\(\[frame\]\)"),
        (np.zeros((6, 8), np.uint8), r"got one \(6, 8\) frame: prime\(\[frame\]\)"),
    ],
    ids=["None", "int", "frame", "grey frame"],
)
def test_multi_object_tracker_prime_refuses_what_is_not_frames_as_tracker_prime(frames, got):
    """Were: 'NoneType' object is not iterable, and one frame's rows taken for frames (``frame
    must have shape (H, W, 3) (BGR), got (8, 3)``), where Tracker.prime names both."""
    with pytest.raises(
        TypeError, match=rf"^MultiObjectTracker\.prime takes an iterable of frames \(.*\), {got}$"
    ):
        MultiObjectTracker(rng=0).prime(frames)


@pytest.mark.parametrize("shape", [(6, 8, 3), (6, 8)])
def test_prime_refuses_one_frame_for_an_iterable_of_frames(frames, shape):
    """Was ``prime frame must have shape (H, W, 3) (BGR), got (8, 3): a grey frame?``: one
    frame, iterated, gives its rows."""
    one = np.zeros(shape, np.uint8)
    with pytest.raises(
        TypeError,
        match=rf"^prime takes an iterable of frames \(a list, or a \(K, H, W, 3\) array\), "
        rf"got one {re.escape(str(shape))} frame: prime\(\[frame\]\)$",
    ):
        pftrack.Tracker().prime(one)
    stacked, listed = pftrack.Tracker(seed=1), pftrack.Tracker(seed=1)
    stacked.prime(np.stack(frames[:4]))  # a (K, H, W, 3) array still primes
    listed.prime(frames[:4])
    dets = np.array([[40.0, 40.0, 70.0, 120.0, 0.9]])
    for f in frames:
        np.testing.assert_array_equal(stacked.update(dets, f), listed.update(dets, f))


GREY = np.zeros((6, 8), np.uint8)
GREY_1 = np.zeros((6, 8, 1), np.uint8)
BGRA = np.zeros((6, 8, 4), np.uint8)
TO_BGR = {
    id(GREY): "cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)",
    id(GREY_1): "cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)",
    id(BGRA): "cv2.cvtColor(frame, cv2.COLOR_BGRA2BGR)",
}
ENTRY_POINTS = {
    "Tracker.update": lambda f: pftrack.Tracker().update(np.zeros((0, 5)), f),
    "Tracker.update(None)": lambda f: pftrack.Tracker().update(None, f),
    "Tracker.prime": lambda f: pftrack.Tracker().prime([f]),
    "MultiObjectTracker.update": lambda f: MultiObjectTracker(rng=0).update(f),
    "hsv_bins": lambda f: pftrack.hsv_bins(f),
    "PaperDetector.detect": lambda f: make_detector("paper").detect(f),
    "MOG2Detector.prime": lambda f: make_detector("mog2").prime([f]),
    "estimate_motion": lambda f: estimate_motion(f, f),
}


@pytest.mark.parametrize("frame", [GREY, GREY_1, BGRA], ids=["grey", "grey1", "bgra"])
@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_a_grey_or_bgra_frame_is_a_value_error_naming_the_conversion(entry, frame):
    # was: TypeError "frame must be a (H, W, 3) uint8 BGR array" from Tracker.update and
    # prime, ValueError "frame must have shape (H, W, 3)" from hsv_bins
    with pytest.raises(ValueError, match=r"must have shape \(H, W, 3\) \(BGR\), got \(6, 8") as e:
        ENTRY_POINTS[entry](frame)
    assert str(e.value).endswith(f"? {TO_BGR[id(frame)]} makes it BGR")


@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_a_frame_of_the_wrong_dtype_is_a_type_error(entry):
    with pytest.raises(TypeError, match="frame dtype is float32, expected uint8"):
        ENTRY_POINTS[entry](np.zeros((6, 8, 3), np.float32))


@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_a_frame_given_as_a_list_is_named_as_one(entry):
    """Was ``frame dtype is int64``: the dtype NumPy gives ``frame.tolist()``, not the user's
    (the detectors' own check already said ``frame is list, expected a numpy.ndarray``)."""
    expected = r"frame is list, expected a (NumPy uint8 array \(H, W, 3\)|numpy\.ndarray)"
    with pytest.raises(TypeError, match=expected):
        ENTRY_POINTS[entry](np.zeros((6, 8, 3), np.uint8).tolist())


class _ArrayLikeFrame:
    """Not a NumPy array, but NumPy makes one of it: a uint8 (H, W, 3) frame, as a PIL image."""

    def __init__(self, a: np.ndarray) -> None:
        self._a = a

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return self._a


@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_a_frame_that_is_not_a_numpy_array_is_refused_whatever_its_dtype(entry):
    """Was taken when NumPy made a uint8 array of it (a PIL image: RGB, read as BGR), while a
    list was refused."""
    frame = _ArrayLikeFrame(np.zeros((6, 8, 3), np.uint8))
    expected = r"frame is _ArrayLikeFrame, expected a (NumPy uint8 array \(H, W, 3\)|numpy\.nd)"
    with pytest.raises(TypeError, match=expected):
        ENTRY_POINTS[entry](frame)


def test_a_pil_image_is_refused_with_the_conversion_to_bgr():
    image = pytest.importorskip("PIL.Image")
    pil = image.fromarray(np.zeros((6, 8, 3), np.uint8))
    for call in (
        lambda: pftrack.Tracker().update(np.zeros((0, 6)), pil),
        lambda: pftrack.Tracker().prime([pil]),
    ):
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value).endswith(
            "frame is Image, expected a NumPy uint8 array (H, W, 3) (BGR, as cv2 reads it); "
            "a PIL image is RGB: np.asarray(img)[..., ::-1] gives BGR"
        )


@pytest.mark.parametrize("threads", [True, False])
def test_track_frames_refuses_pil_images_unprimed(frames, threads):
    """``track_frames`` of PIL images without priming: refused as ``update`` refuses them.

    Was (threads on): the detection thread made arrays of them, and the RGB images were
    tracked as BGR without a word.
    """
    image = pytest.importorskip("PIL.Image")
    pil = [image.fromarray(np.ascontiguousarray(f[..., ::-1])) for f in frames]
    with pytest.raises(TypeError, match="a PIL image is RGB"):
        pftrack.track_frames(pil, prime_frames=0, threads=threads, show_progress=False)


def test_unpacked_views_track_as_their_packed_copies(frames):
    rgb = [np.ascontiguousarray(f[..., ::-1]) for f in frames]  # a user's RGB frames
    views = [f[..., ::-1] for f in rgb]  # the usual RGB -> BGR view
    fortran = [np.asfortranarray(f) for f in frames]
    assert not views[0].flags.c_contiguous and not fortran[0].flags.c_contiguous
    dets = np.array([[40.0, 40.0, 70.0, 120.0, 0.9]])

    def run(seq):
        t = pftrack.Tracker()
        out = [t.update(dets, f) for f in seq]
        with pytest.warns(UserWarning, match="dets=None runs the built-in"):  # on purpose
            out += [t.update(None, f) for f in seq]
        return out, t.finalize()

    base = run(frames)
    for seq in (views, fortran):
        got = run(seq)
        assert all(np.array_equal(a, b) for a, b in zip(got[0], base[0], strict=True))
        assert np.array_equal(got[1], base[1])


def test_a_packed_frame_is_not_copied(frames):
    assert bgr_frame(frames[0]) is frames[0]


def test_multi_object_tracker_says_when_the_arguments_look_swapped(frames):
    # update(dets, frame), BoxMOT's and Tracker.update's order: was "frame dtype is float64,
    # expected uint8" about the user's uint8 frame
    tracker = MultiObjectTracker(rng=0)
    with pytest.raises(TypeError) as e:
        tracker.update(np.array([[10.0, 10, 20, 40, 0.9]]), frames[0])  # type: ignore[arg-type]
    assert str(e.value) == (
        "MultiObjectTracker.update(frame, detections): detections is a (360, 480, 3) uint8 "
        "array, an image; were the arguments swapped? (Tracker.update takes (dets, frame), "
        "BoxMOT's order)"
    )
    assert tracker.frame_index == 0
    tracker.update(frames[0], np.array([[10.0, 10, 20, 40, 0.9]]))  # the run goes on


def test_a_new_size_mid_run_names_the_sizes(frames):
    tracker = MultiObjectTracker(rng=0)
    tracker.update(frames[0])
    with pytest.raises(ValueError, match=r"frame is 100x50, the run's earlier frames 480x360"):
        tracker.update(np.zeros((50, 100, 3), np.uint8))
    assert "reset" not in str(pytest.raises(ValueError, tracker.update, frames[0][:50]).value)


@pytest.mark.parametrize("rate", ["25", True, None, [25.0]])
def test_frame_rate_of_the_wrong_kind(rate):
    with pytest.raises(TypeError, match="frame_rate must be a number"):
        pftrack.Tracker(frame_rate=rate)


@pytest.mark.parametrize("seed", [True, 2.5, "0"])
def test_seed_of_the_wrong_kind(seed):
    # was ValueError, where Tracker.from_config said TypeError
    with pytest.raises(TypeError, match=f"^seed must be an int >= 0, got {type(seed).__name__}"):
        pftrack.Tracker(seed=seed)


def test_negative_seed():
    with pytest.raises(ValueError, match=r"^seed is -1, expected an int >= 0"):
        pftrack.Tracker(seed=-1)


@pytest.mark.parametrize(
    ("rng", "error"), [(2.5, TypeError), ("0", TypeError), (True, TypeError), (-1, ValueError)]
)
def test_track_frames_names_its_rng(rng, error):
    """A defect trial: track_frames(rng=2.5) raised NumPy's "SeedSequence expects int or
    sequence of ints for entropy not 2.5", rng=-1 named MultiObjectTracker's rng."""
    frames = make_scene(n_frames=2, width=96, height=64, rng=0).frames
    with pytest.raises(error, match=r"^track_frames: rng must be a numpy\.random\.Generator"):
        pftrack.track_frames(frames, rng=rng)


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ({"threads": "no"}, "threads must be True or False, got str 'no'"),
        ({"threads": None}, "threads must be True or False, got NoneType None"),
        ({"show_progress": "no"}, "show_progress must be True or False, got str 'no'"),
        ({"show_progress": 1}, "show_progress must be True or False, got int 1"),
    ],
)
def test_track_frames_flags_of_the_wrong_kind_are_refused(option, message):
    """A defect trial: threads="no" ran the threads and show_progress="no" showed the bar (any
    value was taken for its truth), before any frame is read."""
    with pytest.raises(TypeError, match=f"^track_frames: {re.escape(message)}$"):
        pftrack.track_frames(_NOT_READ, **option)


def test_track_frames_refuses_an_on_frame_that_cannot_be_called_before_any_frame():
    """A defect trial: track_frames(on_frame="log.txt") tracked the first frame, then failed
    with "'str' object is not callable", naming nothing."""
    with pytest.raises(
        TypeError,
        match=r"^track_frames: on_frame is str, expected a callable "
        r"on_frame\(index, frame, tracks, rows\) or None$",
    ):
        pftrack.track_frames(_NOT_READ, on_frame="log.txt")  # type: ignore[arg-type]


class _NotRead(list):  # type: ignore[type-arg]
    """A sequence of frames whose frames the checks above must not reach."""

    def __getitem__(self, k):  # type: ignore[no-untyped-def]
        raise AssertionError("a frame was read before the options were checked")

    def __iter__(self):  # type: ignore[no-untyped-def]
        raise AssertionError("a frame was read before the options were checked")

    def __len__(self) -> int:
        return 3


_NOT_READ = _NotRead()


@pytest.mark.parametrize("name", ["max_coast", "prime"])
@pytest.mark.parametrize("value", ["1", [1], True])
def test_seconds_of_the_wrong_kind(name, value):
    # was NumPy's "ufunc 'isfinite' not supported" or "'>=' not supported"
    kind = type(value).__name__
    with pytest.raises(TypeError, match=f"^{name} must be a number, got {kind}"):
        pftrack.Tracker(**{name: value})


@pytest.mark.parametrize("name", ["refine", "smooth", "link", "crossings"])
@pytest.mark.parametrize("value", ["no", "False", 0, 1, None])
def test_a_flag_that_is_not_a_bool_is_refused(name, value):
    """Was: ``Tracker(refine="no")`` accepted, and refinement on (a truthy string)."""
    kind = type(value).__name__
    with pytest.raises(TypeError, match=f"^{name} must be True or False, got {kind}"):
        pftrack.Tracker(**{name: value})


def test_flags_take_python_and_numpy_bools(tmp_path):
    from pftrack.tracking.run import track_path

    assert not pftrack.Tracker(refine=np.False_).config.refine.enabled
    assert pftrack.Tracker(crossings=True).config.crossings.enabled
    with pytest.raises(TypeError, match="^smooth must be True or False, got str 'no'"):
        track_path(tmp_path / "none.avi", smooth="no")  # before the source is opened


def test_zero_size_detections_are_left_out_with_a_warning(tmp_path):
    det = tmp_path / "det.txt"
    det.write_text(
        "1,-1,10,10,0,40,0.9,-1,-1,-1\n1,-1,20,20,10,30,0.8,-1,-1,-1\n2,-1,5,5,8,0,0.7\n"
    )
    with pytest.warns(UserWarning, match=r"2 detection\(s\) with zero width or height left out"):
        dets = load_detections(det)
    assert list(dets) == [1]
    assert np.array_equal(dets[1], [[20.0, 20.0, 10.0, 30.0, 0.8]])


def test_rjmcmc_refuses_the_dynamics_on_particle_means(capsys):
    """--dynamics ar2-mean was silently ignored with --sampler rjmcmc: the same bytes."""
    with pytest.raises(ValueError, match=r"needs a per-object sampler"):
        pftrack.Tracker(sampler="rjmcmc", dynamics="ar2-mean")
    from pftrack.cli import main

    argv = ["track", "v.avi", "--out", "t.txt", "--sampler", "rjmcmc", "--dynamics", "ar2-mean"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("pftrack track: error: ") and "needs a per-object sampler" in err
    assert pftrack.Tracker(sampler="mh", dynamics="ar2-mean").config.filter.model.use_means


def test_finalize_writes_no_row_wholly_outside_the_frame(tmp_path):
    """TUD-Campus at --max-side 320 wrote a track's boxes below the frame's bottom edge."""
    from pftrack.cli import main
    from pftrack.io.mot import read_mot

    folder = dataset("tud-campus")
    out = tmp_path / "t.txt"
    argv = ["-q", "track", str(folder / "video.mp4"), "--out", str(out), "--max-side", "320"]
    assert main(argv) == 0
    rows = read_mot(out)
    x, y, bw, bh = rows[:, 2], rows[:, 3], rows[:, 4], rows[:, 5]
    assert len(rows) and not ((x >= 640) | (y >= 480) | (x + bw <= 0) | (y + bh <= 0)).any()


def test_a_non_finite_detection_score_is_named_by_file_and_line_before_tracking(
    tmp_path: Path,
) -> None:
    """Regression: NaN in det.txt's score column passed the reader and stopped the tracker
    after tracking had started ("dets row 6 contains NaN or inf")."""
    p = tmp_path / "det.txt"
    p.write_text("1,-1,10,10,20,40,0.9,-1,-1,-1\n2,-1,12,10,20,40,nan,-1,-1,-1\n")
    with pytest.raises(ValueError, match=r"det.txt:2: detection file line .*column 7 \(conf\)"):
        load_detections(p)


@pytest.mark.parametrize("frame", [GREY, BGRA], ids=["grey", "bgra"])
def test_video_writer_names_the_conversion_too(tmp_path, frame):
    writer = pftrack.VideoWriter(tmp_path / "v.avi", 10.0)
    shape = r"frame must have shape \(H, W, 3\) \(BGR\), got \(6, 8(, 4)?\)"
    with pytest.raises(ValueError, match=r"^VideoWriter\.write: " + shape) as e:
        writer.write(frame)
    assert str(e.value).endswith(f"? {TO_BGR[id(frame)]} makes it BGR")


@pytest.mark.parametrize("external", [False, True])
def test_track_frames_of_unpacked_views_track_as_their_packed_copies(frames, external):
    """``track_frames`` of in-memory views (``frame[..., ::-1]``, Fortran order): as packed.

    Was: RuntimeError "DetectAhead: the tracker asked about a frame the detection thread did
    not detect": the thread detected the view, ``update`` the packed copy it made of it.
    """
    views = [np.ascontiguousarray(f[..., ::-1])[..., ::-1] for f in frames]
    fortran = [np.asfortranarray(f) for f in frames]
    assert not views[0].flags.c_contiguous and not fortran[0].flags.c_contiguous
    dets = {k: np.array([[40.0, 40.0, 30.0, 80.0, 0.9]]) for k in range(1, len(frames) + 1)}
    kwargs = {"detections": dets} if external else {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # short scene: no track may be said
        base = pftrack.track_frames(frames, show_progress=False, **kwargs).rows
        for seq in (views, fortran):
            got = pftrack.track_frames(seq, show_progress=False, **kwargs).rows
            np.testing.assert_array_equal(got, base)
