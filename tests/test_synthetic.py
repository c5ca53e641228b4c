from __future__ import annotations

import time
from functools import partial

import numpy as np
import pytest

from pftrack.boxes import iou_xywh
from pftrack.io.mot import read_mot
from pftrack.io.video import FrameSource
from pftrack.synthetic import BUSY_SCENES, make_busy_scene, make_scene


@pytest.fixture(scope="module")
def scene():
    return make_scene()


def test_deterministic(scene):
    again = make_scene()
    assert len(again.frames) == len(scene.frames) == 120
    assert all(np.array_equal(a, b) for a, b in zip(scene.frames, again.frames, strict=True))
    np.testing.assert_array_equal(scene.truth, again.truth)
    other = make_scene(rng=1)
    assert not np.array_equal(other.frames[0], scene.frames[0])


def test_frames_and_truth_layout(scene):
    assert scene.frames[0].shape == (360, 480, 3) and scene.frames[0].dtype == np.uint8
    t = scene.truth
    assert t.shape[1] == 10 and len(t) > 0
    assert t[:, 0].min() == 1 and t[:, 0].max() <= 120
    assert set(np.unique(t[:, 1]).astype(int)) == set(range(1, 6))
    left, top, w, h = t[:, 2], t[:, 3], t[:, 4], t[:, 5]
    assert (left >= 0).all() and (top >= 0).all() and (w > 0).all() and (h > 0).all()
    assert (left + w <= 480).all() and (top + h <= 360).all()
    # ids unique within a frame
    assert len(np.unique(t[:, :2], axis=0)) == len(t)
    # someone is there from frame 1, somebody enters later and somebody leaves before the end
    assert (t[:, 0] == 1).any()
    firsts = [t[t[:, 1] == i, 0].min() for i in range(1, 6)]
    lasts = [t[t[:, 1] == i, 0].max() for i in range(1, 6)]
    assert max(firsts) > 1 and min(lasts) < 120
    # fully visible walkers have people-like sizes
    full = t[(left > 0) & (left + w < 480)]
    assert 20 <= full[:, 4].min() and full[:, 4].max() <= 40
    assert 50 <= full[:, 5].min() and full[:, 5].max() <= 100


def test_walkers_are_drawn_where_truth_says(scene):
    for row in scene.truth[::17]:
        f, _, x, y, w, h = (int(v) for v in row[:6])
        frame = scene.frames[f - 1].astype(np.int16)
        diff = np.abs(frame - scene.background.astype(np.int16)).sum(axis=2)
        assert (diff[y : y + h, x : x + w] > 60).mean() > 0.2


def test_crossing_exists(scene):
    t = scene.truth
    crossed = False
    for f in np.unique(t[:, 0]):
        rows = t[t[:, 0] == f]
        iou = iou_xywh(rows[:, 2:6], rows[:, 2:6])
        np.fill_diagonal(iou, 0)
        crossed |= bool((iou > 0).any())
    assert crossed


def test_occluder_occludes_someone(scene):
    ox, oy, ow, oh = scene.occluder
    t = scene.truth
    behind = (t[:, 2] < ox) & (t[:, 2] + t[:, 4] > ox + ow)
    assert behind.any()
    f, _, x, y, w, h = (int(v) for v in t[np.flatnonzero(behind)[0], :6])
    # the post's pixels are the background's there, up to sensor noise
    post = scene.frames[f - 1][y : y + h, ox : ox + ow].astype(np.int16)
    assert np.abs(post - scene.background[y : y + h, ox : ox + ow]).max() < 40
    assert make_scene(n_frames=5, occluder=False).occluder is None


def test_fast():
    t = time.perf_counter()
    make_scene(rng=5)
    assert time.perf_counter() - t < 2.0  # < 1 s on a free core; slack for a busy CI


def test_writers(tmp_path):
    s = make_scene(n_frames=6, rng=2)
    v = s.write_video(tmp_path / "scene.avi")
    src = FrameSource(v)
    assert (src.width, src.height) == (480, 360) and len(list(src)) == 6
    folder = s.write_images(tmp_path / "img1")
    assert sorted(p.name for p in folder.iterdir()) == [f"{k:06d}.png" for k in range(1, 7)]
    np.testing.assert_array_equal(next(iter(FrameSource(folder))), s.frames[0])
    s.write_truth(tmp_path / "gt.txt")
    np.testing.assert_allclose(read_mot(tmp_path / "gt.txt"), s.truth, atol=1e-9)


@pytest.mark.parametrize("suffix", [".avi", ".mp4"])
def test_an_odd_sized_scene_is_written_whole(tmp_path, suffix):
    """321x241: one copied column and row (were: OpenCV cropped to 320x240 without a word, so
    the video no longer held the truth's last column and row)."""
    s = make_scene(n_frames=3, width=321, height=241, rng=0)
    src = FrameSource(s.write_video(tmp_path / f"odd{suffix}"))
    frames = list(src)
    assert (src.width, src.height) == (322, 242) and len(frames) == 3
    err = np.abs(frames[0][:241, :321].astype(int) - s.frames[0].astype(int)).mean()
    assert err < 8  # the scene itself, lossy compressed, not shifted or scaled
    last, copy = frames[0][:, 320].astype(int), frames[0][:, 321].astype(int)
    np.testing.assert_allclose(copy, last, atol=40)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n_frames": 0}, "n_frames"),
        ({"width": 10}, "width"),
        ({"n_walkers": 0}, "n_walkers"),
        ({"noise": -1.0}, "noise"),
    ],
)
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        make_scene(**kwargs)


@pytest.mark.parametrize("make", [make_scene, partial(make_busy_scene, BUSY_SCENES[0])])
def test_a_scene_too_large_to_hold_is_refused_before_any_frame(make):
    """A defect trial: make_scene(n_frames=10**12) ran until killed (every frame is held)."""
    with pytest.raises(
        ValueError, match=r"^make_(busy_)?scene: 1000000000000 frames of 480x360 .* GiB"
    ):
        make(n_frames=10**12)


@pytest.mark.parametrize("kwargs", [{"n_frames": 2.5}, {"width": 480.0}, {"height": True}])
def test_a_size_that_is_not_an_integer_is_a_type_error(kwargs):
    with pytest.raises(
        TypeError, match=f"^make_scene: {next(iter(kwargs))} is .*expected an integer"
    ):
        make_scene(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"n_walkers": True}, "^make_scene: n_walkers is True, expected an integer in 1..40$"),
        ({"n_walkers": 2.0}, "^make_scene: n_walkers is 2.0, expected an integer in 1..40$"),
        ({"occluder": "no"}, "^make_scene: occluder must be True or False, got str 'no'$"),
        ({"occluder": None}, "^make_scene: occluder must be True or False, got NoneType"),
        ({"noise": None}, "^make_scene: noise must be a number, got NoneType None$"),
        ({"noise": "3"}, "^make_scene: noise must be a number, got str '3'$"),
        ({"noise": True}, "^make_scene: noise must be a number, got bool True$"),
    ],
)
def test_a_count_flag_or_noise_of_the_wrong_type_is_a_type_error(kwargs, message):
    """A defect trial: n_walkers=True made one walker, occluder="no" drew the post (any value
    was taken for its truth), noise=True was noise 1, and noise=None or "3" failed in NumPy
    ("ufunc 'isfinite' not supported"), naming nothing."""
    with pytest.raises(TypeError, match=message):
        make_scene(n_frames=2, **kwargs)


def test_busy_scene_noise_of_the_wrong_type_is_named():
    with pytest.raises(TypeError, match="^make_busy_scene: noise must be a number, got NoneType"):
        make_busy_scene("present", n_frames=2, noise=None)


@pytest.mark.parametrize("make", [make_scene, lambda **kw: make_busy_scene("present", **kw)])
@pytest.mark.parametrize(("rng", "error"), [(2.5, TypeError), (True, TypeError), (-1, ValueError)])
def test_bad_rng_is_named(make, rng, error):
    """A defect trial: make_scene(rng=2.5) and rng=-1 raised NumPy's messages without the
    argument's name ("expected non-negative integer"); rng=True was taken as the seed 1."""
    with pytest.raises(error, match=r"^make_(busy_)?scene: rng must be a numpy\.random\.Generator"):
        make(n_frames=2, rng=rng)


def test_warp_rows_moves_clips_and_drops():
    from pftrack.synthetic import warp_rows

    rows = np.array(
        [
            [1, 1, 10, 20, 30, 40, 1, -1, -1, -1],  # inside
            [1, 2, 90, 20, 20, 20, 1, -1, -1, -1],  # 3/4 outside after the shift: dropped
            [2, 1, 60, 50, 20, 20, 1, -1, -1, -1],  # half outside after the zoom: clipped
        ],
        dtype=np.float64,
    )
    shift = np.array([[[1.0, 0.0, 5.0], [0.0, 1.0, -2.0]]])
    zoom = np.array([[[2.0, 0.0, -40.0], [0.0, 2.0, -40.0]]])  # about (40, 40)
    out = warp_rows(rows, np.concatenate([shift, zoom]), (100, 100))
    np.testing.assert_allclose(out[0], [1, 1, 15, 18, 30, 40, 1, -1, -1, -1])
    # centre (70, 60) -> (100, 80), size 40: x from 80 to 120 is clipped to 80..100
    np.testing.assert_allclose(out[1, 2:6], [80, 60, 20, 40])
    assert len(out) == 2
    same = warp_rows(rows, np.tile(np.eye(2, 3), (2, 1, 1)), (100, 200))
    np.testing.assert_array_equal(same, rows)


def test_move_camera_keeps_the_scene_and_moves_its_view():
    from pftrack.synthetic import move_camera

    still = make_scene(n_frames=6, n_walkers=2, rng=1)
    moved = move_camera(still)
    assert len(moved.frames) == 6 and moved.frames[0].shape == still.frames[0].shape
    assert moved.occluder is None and moved.walkers == still.walkers
    assert not np.array_equal(moved.frames[0], still.frames[0])
    assert set(moved.truth[:, 0]) <= set(still.truth[:, 0])
