"""Tracks sized unlike the scene's people are left out: LifecycleConfig.size_ratio.

With given detections the offline pass fits a Theil-Sen line of box height against foot row to
the run's detections and leaves out every track whose median height is below `size_ratio`, or
above ``1 / size_ratio``, times the line's (`pftrack.tracking.offline.drop_odd_sizes`;
docs/tracking.md, "Tracks sized unlike the scene's people").
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

import pftrack
from pftrack._typing import CameraMotion
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import LifecycleConfig, TrackerConfig, offline
from pftrack.tracking.offline import drop_odd_sizes


def _line(foot: np.ndarray) -> np.ndarray:
    """The scene's people: 0.4 px of height per foot row, 20 px at row 0."""
    return 0.4 * foot + 20.0


def _sizes(
    n: int = 200, cls: float | None = None, seed: int = 0, rows: tuple[float, float] = (60, 230)
) -> np.ndarray:
    """`n` detections on the line, feet within `rows`, heights within 5 %: ``foot, height[,
    class]``."""
    rng = np.random.default_rng(seed)
    foot = rng.uniform(*rows, n)
    h = _line(foot) * rng.uniform(0.95, 1.05, n)
    return np.column_stack([foot, h] if cls is None else [foot, h, np.full(n, cls)])


def _track(i: int, share: float, foot: float = 150.0, n: int = 20) -> np.ndarray:
    """`n` rows of track `i`, walking right at foot row `foot`, `share` times the line's height."""
    h = share * _line(np.array(foot))
    f = np.arange(1, n + 1, dtype=np.float64)
    return np.column_stack(
        [f, np.full(n, i), 10.0 + 2 * f, np.full(n, foot - h), np.full(n, h / 2.5),
         np.full(n, h), np.full(n, 0.9), -np.ones((n, 3))]
    )  # fmt: skip


def _ids(rows: np.ndarray) -> set[int]:
    return set(rows[:, 1].astype(int).tolist())


def test_tracks_far_smaller_or_larger_than_the_people_at_their_row_are_left_out() -> None:
    rows = np.vstack([_track(1, 1.0), _track(2, 0.6), _track(3, 1.6), _track(4, 0.85, 90.0)])
    kept = drop_odd_sizes(rows, _sizes(), 0.8)
    assert _ids(kept) == {1, 4}
    np.testing.assert_array_equal(kept, rows[np.isin(rows[:, 1], [1, 4])])  # rows as they were
    assert _ids(drop_odd_sizes(rows, _sizes(), 0.5)) == {1, 2, 3, 4}  # 0.5 and 2: all within


def test_each_class_is_judged_by_its_own_detections() -> None:
    # class 1 (say, a child-sized class) at half the people's line: its track is kept
    small = _sizes(cls=1.0)
    small[:, 1] *= 0.5
    sizes = np.vstack([_sizes(cls=0.0), small])
    rows = np.vstack([_track(1, 1.0), _track(2, 0.5)])
    assert _ids(drop_odd_sizes(rows, sizes, 0.8, classes={1: 0, 2: 1})) == {1, 2}
    assert _ids(drop_odd_sizes(rows, sizes, 0.8)) == {1}  # both taken for class 0
    # fewer than 30 detections of a class: its tracks are not judged
    few = np.vstack([_sizes(cls=0.0), small[:29]])
    rows = np.vstack([_track(1, 1.0), _track(2, 0.3)])
    assert _ids(drop_odd_sizes(rows, few, 0.8, classes={2: 1})) == {1, 2}


def test_boxes_cut_by_the_frames_bottom_are_not_judged() -> None:
    # a person walking out at the bottom of a 240-row frame: the box is cut, short for its row
    cut = _track(2, 0.5, foot=239.5)
    rows = np.vstack([_track(1, 1.0), cut])
    assert _ids(drop_odd_sizes(rows, _sizes(), 0.8, frame_height=240.0)) == {1, 2}
    # without the frame's height, and detections' feet down to row 300 (a taller frame)
    assert _ids(drop_odd_sizes(rows, _sizes(rows=(60, 300)), 0.8)) == {1}
    # detections cut by the bottom do not bend the line either
    sizes = np.vstack([_sizes(), np.column_stack([np.full(300, 239.5), np.full(300, 10.0)])])
    assert _ids(drop_odd_sizes(rows, sizes, 0.8, frame_height=240.0)) == {1, 2}


def test_rows_outside_the_fitted_rows_are_not_judged() -> None:
    """The line is not extrapolated: the detections' feet lie at rows 60-230, and a track whose
    feet are at row 20 (or 300) is kept whatever its height; the same track inside is left out."""
    for share in (0.5, 2.0):
        rows = np.vstack([_track(1, 1.0), _track(2, share, foot=20.0), _track(3, share, 300.0)])
        assert _ids(drop_odd_sizes(rows, _sizes(), 0.8)) == {1, 2, 3}
        rows = np.vstack([_track(1, 1.0), _track(2, share, foot=70.0), _track(3, share, 220.0)])
        assert _ids(drop_odd_sizes(rows, _sizes(), 0.8)) == {1}
    # the range is of the fitted rows' 5th-95th percentiles, not their extremes: one detection
    # at row 10 does not open the rows above 60 to judgement
    sizes = np.vstack([_sizes(), [[10.0, float(_line(np.array(10.0)))]]])
    rows = np.vstack([_track(1, 1.0), _track(2, 0.5, foot=20.0)])
    assert _ids(drop_odd_sizes(rows, sizes, 0.8)) == {1, 2}
    # a track with rows on both sides of the range's edge is judged by the rows inside it
    inside, outside = _track(2, 0.5, foot=100.0, n=5), _track(2, 1.0, foot=20.0, n=15)
    outside[:, 0] += 5
    rows = np.vstack([_track(1, 1.0), inside, outside])
    assert _ids(drop_odd_sizes(rows, _sizes(), 0.8)) == {1}


def test_size_rows_none_judges_every_row(monkeypatch: pytest.MonkeyPatch) -> None:
    """``SIZE_ROWS`` None (candidate B of experiments.size_check) turns limit 2 off: tracks
    whose feet lie outside the fitted rows are judged, on the line extrapolated."""
    rows = np.vstack([_track(1, 1.0), _track(2, 0.5, foot=20.0), _track(3, 2.0, 300.0)])
    assert _ids(drop_odd_sizes(rows, _sizes(), 0.8)) == {1, 2, 3}
    monkeypatch.setattr(offline, "SIZE_ROWS", None)
    assert _ids(drop_odd_sizes(rows, _sizes(), 0.8)) == {1}


@pytest.mark.parametrize("seed", range(5))
def test_medians_by_id_are_numpys_median_per_id(seed: int) -> None:
    """One sort for every track's median, equal to ``np.median`` of each id's values (odd and
    even counts, ties, ids in any order)."""
    rng = np.random.default_rng(seed)
    ids = rng.integers(1, 40, 500).astype(np.float64)
    values = np.round(rng.uniform(0.3, 2.0, 500), 2)  # ties within and across ids
    uid, q = offline._medians_by_id(ids, values)
    np.testing.assert_array_equal(uid, np.unique(ids))
    want = [np.median(values[ids == i]) for i in uid]
    np.testing.assert_array_equal(q, want)  # bit for bit: the same two middle values, / 2


def test_drop_odd_sizes_judges_two_thousand_tracks() -> None:
    """2000 tracks of 50 rows, half of them small for their row: each judged on its own rows
    (the medians of one sort, `_medians_by_id`)."""
    n, k = 2000, 50
    rows = np.vstack([_track(i, 1.0 if i % 2 else 0.6, n=k) for i in range(1, n + 1)])
    kept = drop_odd_sizes(rows, _sizes(), 0.8)
    assert _ids(kept) == set(range(1, n + 1, 2))


@pytest.mark.parametrize(
    ("ratio", "sizes", "error", "match"),
    [
        (0.0, np.zeros((40, 2)), ValueError, r"ratio is 0.0, expected a value in \(0, 1\)"),
        (1.0, np.zeros((40, 2)), ValueError, "ratio is 1.0"),
        (float("nan"), np.zeros((40, 2)), ValueError, "ratio is nan"),
        ("0.8", np.zeros((40, 2)), TypeError, "ratio"),
        (0.8, np.zeros((40, 5)), ValueError, r"sizes has shape \(40, 5\), expected \(K, 2\)"),
        (0.8, np.full((40, 2), np.nan), ValueError, "sizes has shape"),
    ],
)
def test_drop_odd_sizes_bad_arguments(
    ratio: object, sizes: np.ndarray, error: type[Exception], match: str
) -> None:
    with pytest.raises(error, match=match):
        drop_odd_sizes(_track(1, 1.0), sizes, ratio)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", [0.0, 1.0, 1.25, -0.5, float("nan")])
def test_size_ratio_is_checked(bad: float) -> None:
    with pytest.raises(ValueError, match=r"size_ratio is .*, expected a value in \(0, 1\)"):
        LifecycleConfig(size_ratio=bad)
    with pytest.raises(TypeError, match="size_ratio"):
        LifecycleConfig(size_ratio="0.8")  # type: ignore[arg-type]


def _people_and_false_box(k: int) -> np.ndarray:
    """Frame `k`'s detections ``x1, y1, x2, y2, score, class``: three people walking right at
    rows 100, 150 and 200, sized on the line, and a confident false box, a third of the height
    a person has at its row, standing still at row 180."""
    dets = []
    for j, foot in enumerate((100.0, 150.0, 200.0)):
        h = float(_line(np.array(foot)))
        x = 20.0 + 90 * j + 2 * k
        dets.append([x, foot - h, x + h / 2.5, foot, 0.95, 0.0])
    h = float(_line(np.array(180.0))) / 3
    dets.append([280.0, 180.0 - h, 280.0 + h / 2.5, 180.0, 0.95, 0.0])
    return np.array(dets)


@pytest.mark.parametrize(("ratio", "n_ids"), [(0.8, 3), (None, 4)])
def test_finalize_leaves_out_a_track_on_small_false_boxes(ratio: float | None, n_ids: int) -> None:
    """Three people walk at rows 100, 150 and 200, sized on the line; a confident false box,
    a third of the height a person has at its row, stands still at row 180. With
    `size_ratio` its track is left out of finalize(); `update` still reports it."""
    rng = np.random.default_rng(1)
    frame = rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)
    config = TrackerConfig(refine=pftrack.tracking.RefineConfig(enabled=False))
    config = dataclasses.replace(
        config, lifecycle=dataclasses.replace(config.lifecycle, size_ratio=ratio)
    )
    tracker = pftrack.Tracker.from_config(config, 0, prime_frames=0)
    online = set()
    for k in range(40):
        dets = _people_and_false_box(k)
        online |= {int(r[4]) for r in tracker.update(dets, frame)}
    assert len(online) == 4
    assert len(_ids(tracker.finalize())) == n_ids


@pytest.mark.parametrize(("spreads", "n_ids"), [(offline.SIZE_SPREADS, 5), (None, 3)])
def test_a_scene_whose_sizes_do_not_follow_the_row_is_not_judged(
    spreads: float | None, n_ids: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`make_scene`'s five people are 52-98 px tall whatever their row (the one of 98 px is 1.5
    times the line's height at its row): the line does not explain their heights (a robust
    spread of 0.11 of the log ratio, 2 of them wider than the band ``log 1.25``), so the guard
    keeps all five; without it (``SIZE_SPREADS`` None) two are left out."""
    monkeypatch.setattr(offline, "SIZE_SPREADS", spreads)
    scene = make_scene(n_frames=40, rng=1)
    by_frame = group_by_frame(scene.truth)
    ids = {}
    for ratio in (None, 0.8):
        config = TrackerConfig(lifecycle=LifecycleConfig(size_ratio=ratio))
        tracker = pftrack.Tracker.from_config(config, 0, prime_frames=0)
        for f, frame in enumerate(scene.frames, 1):
            r = by_frame.get(f, np.zeros((0, 10)))
            tracker.update(
                np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6], np.ones(len(r))]), frame
            )
        ids[ratio] = len(_ids(tracker.finalize()))
    assert (ids[None], ids[0.8]) == (5, n_ids)


def _zooming(n: int = 400, drift: float = 0.6, noise: float = 0.05) -> np.ndarray:
    """`n` detections ``foot, height, class, frame`` over frames 0-199 of a camera zooming
    steadily: people on the line times ``exp(drift (frame / 199 - 1 / 2))``, heights within
    `noise`."""
    rng = np.random.default_rng(3)
    frame = np.sort(rng.integers(0, 200, n)).astype(np.float64)
    foot = rng.uniform(60, 230, n)
    zoom = np.exp(drift * (frame / 199 - 0.5))
    h = _line(foot) * zoom * rng.uniform(1 - noise, 1 + noise, n)
    return np.column_stack([foot, h, np.zeros(n), frame])


@pytest.mark.parametrize(("spreads", "kept"), [(offline.SIZE_SPREADS, {1, 2}), (None, {2})])
def test_a_drifting_zoom_is_not_judged(
    spreads: float | None, kept: set[int], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A camera zooming in over the run (the people's size for their row grows by
    ``exp(0.6)``): a person early in the run is 0.74 of the line fitted over the whole run.
    The guard sees the drift and keeps them; without it they are left out."""
    monkeypatch.setattr(offline, "SIZE_SPREADS", spreads)
    rows = np.vstack([_track(1, 0.74), _track(2, 1.0)])
    assert _ids(drop_odd_sizes(rows, _zooming(), 0.8)) == kept


def test_size_line_measures_the_spread_and_the_drift() -> None:
    rng = np.random.default_rng(4)
    foot = rng.uniform(60, 230, 2000)
    r = rng.normal(0.0, 0.1, 2000)
    slope, intercept, spread, drift = offline.size_line(foot, _line(foot) * np.exp(r))
    assert slope == pytest.approx(0.4, rel=0.05) and intercept == pytest.approx(20, abs=3)
    assert spread == pytest.approx(0.1, rel=0.1) and drift == 0.0  # no frames: no drift
    frame = np.arange(2000.0)
    assert offline.size_line(foot, _line(foot) * np.exp(r), frame)[3] == pytest.approx(0, abs=0.03)
    # a steady drift of 0.3 over the run, heights within 1 %: the spread alone (0.11: twice it
    # fits the band log 1.25 = 0.223) would judge the class, the drift's half does not
    s = _zooming(2000, drift=0.3, noise=0.01)
    _, _, spread, drift = offline.size_line(s[:, 0], s[:, 1], s[:, 3])
    assert drift == pytest.approx(0.3, rel=0.1)
    assert 2 * spread <= -np.log(0.8) < 2 * spread + drift / 2
    rows = np.vstack([_track(1, 0.85, n=5), _track(2, 0.79, n=5)])
    rows[rows[:, 1] == 2, 0] += 190  # at the run's end, people are 1.16 of the line
    assert _ids(drop_odd_sizes(rows, s, 0.8)) == {1, 2}
    assert _ids(drop_odd_sizes(rows, s[:, :3], 0.8)) == {1}  # without frames: no drift seen


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (([1.0, 2.0], [1.0]), r"foot, height\[, frame\] have shapes \(2,\), \(1,\)"),
        (([1.0, 2.0], [1.0, 0.0]), "height has values not finite or not positive"),
        (([1.0, 2.0], [1.0, 2.0], [0.0, np.nan]), "frame has values not finite"),
        (([1.0, 1.0], [1.0, 2.0]), "distinct"),
    ],
)
def test_size_line_bad_arguments(args: tuple[list[float], ...], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        offline.size_line(*args)


def test_finalize_gives_drop_odd_sizes_each_boxs_frame(monkeypatch: pytest.MonkeyPatch) -> None:
    """The guard's drift needs the frames: `Tracker.update` records ``foot, height, class,
    frame`` of each given box."""
    seen = []

    def spy(rows: np.ndarray, sizes: np.ndarray, *args: object) -> np.ndarray:
        seen.append(sizes)
        return rows

    monkeypatch.setattr(pftrack.tracking.api, "drop_odd_sizes", spy)
    frame = np.random.default_rng(1).integers(0, 255, (240, 320, 3), dtype=np.uint8)
    config = TrackerConfig(lifecycle=LifecycleConfig(size_ratio=0.8))
    tracker = pftrack.Tracker.from_config(config, 0, prime_frames=0)
    for k in range(12):
        tracker.update(_people_and_false_box(k), frame)
    tracker.finalize()
    (sizes,) = seen
    assert sizes.shape == (48, 4)
    np.testing.assert_array_equal(sizes[:, 3], np.repeat(np.arange(12.0), 4))
    np.testing.assert_allclose(sizes[:4, :2], [[100, 60], [150, 80], [200, 100], [180, 92 / 3]])


def _panning_frames(n: int, step: float) -> list[np.ndarray]:
    """`n` 240x320 frames of a blurred noise texture, the camera panning `step` px a frame."""
    rng = np.random.default_rng(2)
    texture = cv2.GaussianBlur(rng.integers(0, 255, (240, 320 + 400), dtype=np.uint8), (0, 0), 2)
    scene = cv2.cvtColor(texture, cv2.COLOR_GRAY2BGR)
    return [
        np.ascontiguousarray(scene[:, round(k * step) : round(k * step) + 320]) for k in range(n)
    ]


@pytest.mark.parametrize(("camera_motion", "step", "n_ids"), [("auto", 4.0, 4), ("off", 4.0, 3),
                                                              ("auto", 0.0, 3)])  # fmt: skip
def test_the_rule_does_not_run_after_the_camera_was_found_moving(
    camera_motion: CameraMotion, step: float, n_ids: int
) -> None:
    """A height-for-row line is a still camera's: under a panning camera (found moving with
    ``camera_motion="auto"``) the false box of the test above is kept; with the camera's motion
    off, or a still camera, it is left out as before."""
    config = TrackerConfig(
        refine=pftrack.tracking.RefineConfig(enabled=False),
        camera_motion=camera_motion,
        lifecycle=LifecycleConfig(size_ratio=0.8),
    )
    tracker = pftrack.Tracker.from_config(config, 0, prime_frames=0)
    for k, frame in enumerate(_panning_frames(40, step)):
        tracker.update(_people_and_false_box(k), frame)
    assert tracker.tracker.camera.moving == (camera_motion == "auto" and step > 0)
    assert len(_ids(tracker.finalize())) == n_ids
