"""The working resolution (TrackerConfig.max_side): frames scaled down, boxes scaled back.

A frame upscaled twice by pixel repetition and scaled back by ``INTER_AREA`` is the original
frame exactly, and halving or doubling a box is exact in floating point: so a tracker at
``max_side`` on the doubled frames must give, byte for byte, twice the boxes of a tracker on
the original frames.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import pftrack
from pftrack.cli import main
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import TrackerConfig, track_frames
from pftrack.tracking.api import working_size, xywh_to_xyxy_dets


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=30, rng=3)


def doubled(frame: np.ndarray) -> np.ndarray:
    return np.repeat(np.repeat(frame, 2, axis=0), 2, axis=1)


def truth_dets(scene) -> list[np.ndarray]:
    by_frame = group_by_frame(scene.truth)
    return [
        xywh_to_xyxy_dets(
            np.column_stack([r[:, 2:6], np.ones(len(r))])
            if len(r := by_frame.get(f, np.zeros((0, 10))))
            else np.zeros((0, 5))
        )
        for f in range(1, len(scene.frames) + 1)
    ]


@pytest.mark.parametrize(
    ("shape", "side", "size"),
    [
        ((360, 480, 3), 640, None),
        ((480, 640, 3), 640, None),
        ((720, 1280, 3), 640, (640, 360)),
        ((1080, 1920, 3), 640, (640, 360)),
        ((1280, 720, 3), 640, (360, 640)),
        ((370, 1224, 3), 640, (640, 193)),
        ((720, 1280, 3), None, None),
    ],
)
def test_working_size(shape, side, size):
    assert working_size(shape, side) == size


def test_working_frame_is_inter_area(scene):
    tracker = pftrack.Tracker(max_side=480)
    f = scene.frames[0]
    assert tracker.working_frame(f) is f  # 480x360: tracked as it is
    assert np.array_equal(tracker.working_frame(doubled(f)), f)


@pytest.mark.parametrize(
    ("frame", "error", "words"),
    [
        ([[[0, 0, 0]]], TypeError, "working_frame: frame is list"),
        (np.zeros((4, 4), np.uint8), ValueError, "working_frame: frame must have shape"),
        (np.zeros((4, 4, 3)), TypeError, "working_frame: frame dtype is float64"),
    ],
)
def test_working_frame_names_a_bad_frame(frame, error, words):
    """Was an AttributeError ('list' object has no attribute 'shape') for a list."""
    with pytest.raises(error, match=words):
        pftrack.Tracker(max_side=480).working_frame(frame)


@pytest.mark.parametrize("given", [True, False], ids=["detections", "builtin"])
def test_doubled_frames_give_doubled_boxes_byte_for_byte(scene, given):
    dets = truth_dets(scene) if given else [None] * len(scene.frames)
    small = pftrack.Tracker(seed=5)
    large = pftrack.Tracker(seed=5, max_side=480)
    small.prime(scene.frames[:10])
    large.prime([doubled(f) for f in scene.frames[:10]])
    n_out = 0
    for f, d in zip(scene.frames, dets, strict=True):
        a = small.update(d, f)
        b = large.update(None if d is None else d * [2, 2, 2, 2, 1], doubled(f))
        expect = a.copy()
        expect[:, :4] *= 2
        assert np.array_equal(b, expect)
        n_out += len(a)
        ra, rb = small.last_reports, large.last_reports
        assert [t.id for t in ra] == [t.id for t in rb]
        for s, t in zip(ra, rb, strict=True):
            assert np.array_equal(2 * s.box_xywh, t.box_xywh)
            assert (s.detection_box is None) == (t.detection_box is None)
    assert n_out > 0
    rows_a, rows_b = small.finalize(), large.finalize()
    assert len(rows_a) > 0
    expect = rows_a.copy()
    expect[:, 2:6] *= 2
    assert np.array_equal(rows_b, expect)


def test_the_run_scales_on_the_detection_thread_with_the_loops_rows(scene):
    frames = [doubled(f) for f in scene.frames]
    config = TrackerConfig(max_side=480)
    threaded = track_frames(frames, config=config, rng=2)
    single = track_frames(frames, config=config, rng=2, threads=False)
    reference = track_frames(scene.frames, rng=2)
    assert np.array_equal(threaded.rows, single.rows)
    expect = reference.rows.copy()
    expect[:, 2:6] *= 2
    assert np.array_equal(threaded.rows, expect)


def test_a_frame_of_another_size_is_refused(scene):
    tracker = pftrack.Tracker(max_side=480)
    tracker.update(None, doubled(scene.frames[0]))
    with pytest.raises(ValueError, match="earlier frames 960x720"):
        tracker.update(None, scene.frames[1])
    tracker.reset()
    tracker.update(None, scene.frames[1])  # a new run may have another size


@pytest.mark.parametrize("side", [10, -1, True, False, 640.0, 0.0, "640", "0"])
def test_bad_max_side_is_refused(side):
    with pytest.raises(ValueError, match=r"max_side is .*, expected None \(or 0: off\) or an int"):
        TrackerConfig(max_side=side)
    with pytest.raises(ValueError, match="max_side"):
        pftrack.Tracker(max_side=side)


@pytest.mark.parametrize("zero", [0, np.int64(0)])
def test_max_side_0_is_off_as_on_the_command_line(zero, scene):
    """Was: ``Tracker(max_side=0)`` raised 'max_side is 0, expected None or an int in [64,
    100000]' while ``--max-side 0`` (the CLI's default) means the frame's own size."""
    config = TrackerConfig(max_side=zero)
    assert config.max_side is None  # stored as None: equal to the default, the same hash
    assert config == TrackerConfig() == TrackerConfig(max_side=None)
    assert hash(config) == hash(TrackerConfig())
    tracker = pftrack.Tracker(max_side=zero)
    assert tracker.config == pftrack.Tracker().config
    assert tracker.working_frame(doubled(scene.frames[0])).shape == (720, 960, 3)  # not scaled


def test_cli_max_side(scene, tmp_path, capsys):
    folder = tmp_path / "seq"
    folder.mkdir()
    for n, f in enumerate(scene.frames[:12], start=1):
        cv2.imwrite(str(folder / f"{n:06d}.png"), doubled(f))
    out = tmp_path / "t.txt"
    with pytest.raises(SystemExit) as refused:
        main(["-q", "track", str(folder), "--max-side", "20", "--out", str(out)])
    assert refused.value.code == 2
    assert "--max-side" in capsys.readouterr().err
    assert not out.exists()
    assert main(["-q", "track", str(folder), "--max-side", "480", "--out", str(out)]) == 0
    half = tmp_path / "h.txt"
    small = tmp_path / "small"
    small.mkdir()
    for n, f in enumerate(scene.frames[:12], start=1):
        cv2.imwrite(str(small / f"{n:06d}.png"), f)
    assert main(["-q", "track", str(small), "--out", str(half)]) == 0
    a = np.loadtxt(half, delimiter=",", ndmin=2)
    b = np.loadtxt(out, delimiter=",", ndmin=2)
    assert len(a) > 0
    a[:, 2:6] *= 2
    np.testing.assert_allclose(b, a, atol=0.02)  # written with 2 decimals


def test_cli_default_is_the_config_default():
    from pftrack.cli._options import DEFAULT_MAX_SIDE, MAX_SIDE_RANGE
    from pftrack.tracking.config import MAX_SIDE, MIN_SIDE

    assert (DEFAULT_MAX_SIDE or None) == TrackerConfig().max_side
    assert pftrack.Tracker().config.max_side == TrackerConfig().max_side
    assert MAX_SIDE_RANGE == (MIN_SIDE, MAX_SIDE)


def test_max_side_help_states_the_range_its_error_enforces(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Was: the help named no minimum; ``--max-side 32`` was refused for one (64)."""
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "PX from 64 to 100000, or 0 to track at the frame's own size" in text
    with pytest.raises(SystemExit) as exit_:
        main(["track", "v.avi", "--out", "t.txt", "--max-side", "32"])
    assert exit_.value.code == 2
    assert "expected 0 (full size) or an integer in [64, 100000], got 32" in capsys.readouterr().err


@pytest.mark.parametrize("threads", [True, False])
def test_the_bootstrap_holds_its_frames_at_the_working_size(scene, tmp_path, monkeypatch, threads):
    """A 3840x2160 clip with ``--max-side 960`` peaked at 1.1-1.4 GB resident: the spread
    bootstrap's 30 frames were held at their own size (25 MB each) until the median of their
    working frames was taken. Now each is scaled as it is read: the frames the run primes with
    are at the working size, and its rows are those of the same frames in memory."""
    path = scene.write_video(tmp_path / "walk.avi")
    frames = list(pftrack.FrameSource(path))
    held: list[tuple[int, ...]] = []
    real = pftrack.Tracker.prime

    def prime(self, primer, **options):
        held.extend(np.shape(f) for f in primer)
        return real(self, primer, **options)

    monkeypatch.setattr(pftrack.Tracker, "prime", prime)
    config = TrackerConfig(max_side=100)
    run = track_frames(path, config=config, show_progress=False, threads=threads)
    size = working_size(frames[0].shape, 100)
    assert size is not None and held
    assert set(held) == {(size[1], size[0], 3)}
    held.clear()
    in_memory = track_frames(frames, config=config, show_progress=False, threads=threads)
    assert set(held) == {frames[0].shape}  # frames given are primed as given
    np.testing.assert_array_equal(run.rows, in_memory.rows)


def test_prime_with_the_frames_shape_takes_working_frames(scene):
    frames = [doubled(f) for f in scene.frames]
    whole = pftrack.Tracker(max_side=100)
    whole.prime(frames[:10])
    work = pftrack.Tracker(max_side=100)
    work.prime([work.working_frame(f) for f in frames[:10]], shape=frames[0].shape)
    for f in frames[:5]:
        np.testing.assert_array_equal(whole.update(None, f), work.update(None, f))
    with pytest.raises(ValueError, match=r"frame is \d+x\d+, the frames given to prime"):
        work2 = pftrack.Tracker(max_side=100)
        work2.prime([work2.working_frame(frames[0])], shape=frames[0].shape)
        work2.update(None, scene.frames[0])
    with pytest.raises(ValueError, match="expected 100x75, the working size"):
        pftrack.Tracker(max_side=100).prime([frames[0]], shape=frames[0].shape)
    with pytest.raises(TypeError, match="shape is"):
        pftrack.Tracker(max_side=100).prime([frames[0]], shape=[1, 2, 3])  # type: ignore[arg-type]
