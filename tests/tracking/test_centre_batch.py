"""The centre filters' core calls against the Python loops they replaced, float for float.

``predict_tracks`` and ``follow_tracks_motion`` (pftrack.tracking.track) step every track's
centre filter in one core call (``_core.centre_predict_tracks``, ``_core.centre_follow_tracks``);
until stop 65 they were the loops below, on plain Python floats. Random states, and the tracker
itself on the bench's scene and on PETS09, give the same bits either way.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from pftrack import _core
from pftrack.tracking import tracker as tracker_module
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.track import FLAT_RHO, follow_tracks_motion, predict_tracks
from pftrack.tracking.tracker import MultiObjectTracker
from tests.conftest import dataset

# ---- the reference: the Python loops of stop 64 (pftrack/tracking/track.py, 2d74cac3) -------


def _cv_update_floats(px, py, vx, vy, p00, p01, p11, zx, zy, r2):  # type: ignore[no-untyped-def]
    s = p00 + r2
    k0, k1 = p00 / s, p01 / s
    ex, ey = zx - px, zy - py
    return (
        px + k0 * ex, py + k0 * ey, vx + k1 * ex, vy + k1 * ey,
        (1 - k0) * p00, (1 - k0) * p01, p11 - k1 * p01,
    )  # fmt: skip


def predict_reference(
    tracks: Sequence[Any], summary: np.ndarray, gains: Sequence[float], colour_noise: float
) -> np.ndarray:
    """The centre filters' half of predict_tracks as it was (the colour filters stepped)."""
    rows = []
    for t, (zx, zy, rho, rho_max), gain in zip(tracks, summary.tolist(), gains, strict=True):
        m = t.motion
        w, h = t.size.tolist()
        (px, py), (vx, vy) = m.p.tolist(), m.v.tolist()
        p00, p01, p11 = m.cov
        q = (m.accel * gain if gain != 1.0 else m.accel) * h
        q = q * q
        px, py = px + vx, py + vy
        p00, p01, p11 = p00 + 2.0 * p01 + p11 + q / 3.0, p01 + p11 + q / 2, p11 + q
        t.flat = not rho_max - rho > FLAT_RHO
        if not t.flat:
            r = colour_noise * h
            px, py, vx, vy, p00, p01, p11 = _cv_update_floats(
                px, py, vx, vy, p00, p01, p11, zx, zy, r * r
            )
        m.cov = (p00, p01, p11)
        t.measured = None
        t.rho = rho
        t.age += 1
        rows.append((px, py, vx, vy, px - w / 2, py - h / 2, w, h))
    out = np.array(rows).reshape(-1, 8)
    for t, p, v, box in zip(tracks, out[:, 0:2], out[:, 2:4], out[:, 4:8], strict=True):
        t.motion.p, t.motion.v, t.box = p, v, box
    return out


def follow_reference(tracks: Sequence[Any], boxes: np.ndarray, noise: float, smooth: bool) -> None:
    """follow_tracks_motion as it was."""
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    rows = []
    for t, (bx, by, bw, bh) in zip(tracks, b.tolist(), strict=True):
        m = t.motion
        w, h = t.size.tolist()
        (px, py), (vx, vy) = m.p.tolist(), m.v.tolist()
        sigma = noise * h
        px, py, vx, vy, p00, p01, p11 = _cv_update_floats(
            px, py, vx, vy, *m.cov, bx + bw / 2, by + bh / 2, sigma * sigma
        )
        m.cov = (p00, p01, p11)
        w, h = 0.7 * w + 0.3 * bw, 0.7 * h + 0.3 * bh
        box = (px - w / 2, py - h / 2, w, h) if smooth else (bx, by, bw, bh)
        rows.append((px, py, vx, vy, w, h, *box, bx, by, bw, bh))
    out = np.array(rows)
    for t, row in zip(tracks, out, strict=True):
        t.motion.p, t.motion.v, t.size, t.box, t.measured = (
            row[0:2], row[2:4], row[4:6], row[6:10], row[10:14],
        )  # fmt: skip


# ---- random states ---------------------------------------------------------------------------

FIELDS = ("flat", "measured", "rho", "age", "box", "size")


def _random_tracks(rng: np.random.Generator, k: int) -> list[SimpleNamespace]:
    tracks = []
    for _ in range(k):
        h = float(rng.uniform(5, 300))
        motion = SimpleNamespace(
            p=rng.uniform(-50, 800, 2),
            v=rng.normal(0, 3, 2),
            cov=(float(rng.uniform(0, 50)), float(rng.normal(0, 5)), float(rng.uniform(0, 50))),
            accel=float(rng.uniform(0.001, 0.2)),
        )
        tracks.append(
            SimpleNamespace(
                motion=motion, size=np.array([h * rng.uniform(0.2, 1), h]),
                box=rng.normal(size=4), flat=False, measured=rng.normal(size=4),
                rho=0.5, age=int(rng.integers(1, 100)),
            )
        )  # fmt: skip
    return tracks


def _copy(tracks: list[SimpleNamespace]) -> list[SimpleNamespace]:
    return [
        SimpleNamespace(**{**vars(t), "motion": SimpleNamespace(**vars(t.motion))}) for t in tracks
    ]


def _bits(x: Any) -> Any:
    """A value as its exact bits (floats and arrays by bytes and dtype; -0.0 is not 0.0)."""
    if isinstance(x, np.ndarray):
        return (x.dtype.str, x.shape, x.tobytes())
    if isinstance(x, float):
        return ("float", np.float64(x).tobytes())
    if isinstance(x, tuple):
        return tuple(_bits(v) for v in x)
    return (type(x).__name__, x)


def _state(t: Any) -> dict[str, Any]:
    m = t.motion
    own = {name: _bits(getattr(t, name)) for name in FIELDS}
    return {**own, "p": _bits(m.p), "v": _bits(m.v), "cov": _bits(m.cov)}


def _summary(rng: np.random.Generator, tracks: list[SimpleNamespace]) -> np.ndarray:
    k = len(tracks)
    rho = rng.uniform(0, 1, k)
    rho_max = rho + rng.choice([0.0, 1e-10, 1e-9, 2e-9, 0.1], k)  # flat, and not
    rho_max[rng.uniform(size=k) < 0.1] = np.nan  # no evidence either
    centres = np.array([t.motion.p for t in tracks]).reshape(-1, 2) + rng.normal(0, 4, (k, 2))
    return np.column_stack([centres, rho, rho_max])


@pytest.mark.parametrize("seed", range(12))
def test_predict_is_the_python_loops_floats(seed: int) -> None:
    rng = np.random.default_rng(seed)
    k = int(rng.integers(0, 25))
    tracks = _random_tracks(rng, k)
    ref = _copy(tracks)
    summary = _summary(rng, tracks)
    gains = [1.0 if rng.uniform() < 0.5 else float(rng.uniform(0.5, 3)) for _ in range(k)]
    noise = float(rng.uniform(0.01, 1))
    want = predict_reference(ref, summary, gains, noise)
    got = _core.centre_predict_tracks(tracks, summary, gains, noise, FLAT_RHO)
    assert _bits(got) == _bits(want)
    for t, r in zip(tracks, ref, strict=True):
        assert _state(t) == _state(r)
        # each array a view of the returned rows, as the rows' slices were
        assert t.motion.p.base is got and t.box.base is got


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("smooth", [False, True])
def test_follow_is_the_python_loops_floats(seed: int, smooth: bool) -> None:
    rng = np.random.default_rng(100 + seed)
    k = int(rng.integers(1, 25))
    tracks = _random_tracks(rng, k)
    ref = _copy(tracks)
    centres = np.array([t.motion.p for t in tracks]) + rng.normal(0, 5, (k, 2))
    sizes = np.array([t.size for t in tracks]) * rng.uniform(0.7, 1.4, (k, 1))
    boxes = np.column_stack([centres - sizes / 2, sizes])
    noise = float(rng.uniform(0.01, 1))
    follow_reference(ref, boxes, noise, smooth)
    got = _core.centre_follow_tracks(tracks, boxes, noise, smooth)
    assert got.shape == (k, 14)
    for t, r in zip(tracks, ref, strict=True):
        assert _state(t) == _state(r)


def test_a_bad_track_changes_no_track() -> None:
    """One line naming the track; the tracks before it keep their state (read before written)."""
    rng = np.random.default_rng(7)
    tracks = _random_tracks(rng, 3)
    before = [_state(t) for t in tracks]
    summary = _summary(rng, tracks)
    summary[:, 3] = summary[:, 2] + 1  # every track measured
    bad = [
        ("size", np.array([1.0, 2.0, 3.0]), ValueError, r"tracks\[2\]\.size must have shape"),
        ("size", [1.0, 2.0], TypeError, r"tracks\[2\]\.size is list, expected a \(2,\) float64"),
        ("cov", (1.0, 2.0), TypeError, r"tracks\[2\]\.motion\.cov must be a tuple of 3 floats"),
        ("p", np.array([np.nan, 1.0]), ValueError, r"tracks\[2\]: its new centre, velocity"),
    ]
    for name, value, error, match in bad:
        owner = tracks[2] if name == "size" else tracks[2].motion
        kept = getattr(owner, name)
        setattr(owner, name, value)
        with pytest.raises(error, match=match):
            _core.centre_predict_tracks(tracks, summary, [1.0] * 3, 0.2, FLAT_RHO)
        with pytest.raises(error, match=match):
            _core.centre_follow_tracks(tracks, summary, 0.2, False)
        setattr(owner, name, kept)
        assert [_state(t) for t in tracks] == before
    with pytest.raises(ValueError, match="gains has 2 values for 3 tracks"):
        _core.centre_predict_tracks(tracks, summary, [1.0] * 2, 0.2, FLAT_RHO)
    with pytest.raises(ValueError, match=r"summary must have shape \(3, 4\), one row per track"):
        _core.centre_predict_tracks(tracks, summary[:2], [1.0] * 3, 0.2, FLAT_RHO)
    with pytest.raises(TypeError, match="tracks is tuple, expected a list of LiveTrack"):
        _core.centre_follow_tracks(tuple(tracks), summary, 0.2, False)
    tracks[1].motion.cov = (0.0, 0.0, 1.0)
    with pytest.raises(ValueError, match=r"tracks\[1\]: the centre's innovation variance"):
        _core.centre_follow_tracks(tracks, summary, 0.0, False)


# ---- the tracker, with the calls and with the loops ------------------------------------------


def _reference_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    """The tracker's predict_tracks and follow_tracks_motion with the Python loops inside."""

    def predict(tracks, binned, colour_noise, accel_gain=1.0):  # type: ignore[no-untyped-def]
        from pftrack.particle_filter.filter import step_filters_summary

        if not tracks:
            return np.empty((0, 8))
        summary = step_filters_summary([t.filter for t in tracks], binned)
        return predict_reference(tracks, summary, accel_gain, colour_noise)

    def follow(tracks, boxes, config, smooth):  # type: ignore[no-untyped-def]
        if tracks:
            follow_reference(tracks, boxes, config.motion.detection_noise, smooth)

    monkeypatch.setattr(tracker_module, "predict_tracks", predict)
    monkeypatch.setattr(tracker_module, "follow_tracks_motion", follow)


def _run(frames: list[np.ndarray], dets: list[np.ndarray] | None) -> list[Any]:
    """Each frame's reported tracks and every live track's centre state, as bits."""
    tracker = MultiObjectTracker(TrackerConfig(), rng=0)
    seen = []
    for k, frame in enumerate(frames):
        out = tracker.update(frame, None if dets is None else dets[k])
        reported = [(t.id, _bits(t.box_xywh), _bits(t.score), t.age) for t in out]
        seen.append((reported, [(t.id, _state(t)) for t in tracker.tracks]))
    return seen


def _both(monkeypatch: pytest.MonkeyPatch, frames: list[np.ndarray], dets: Any) -> None:
    got = _run(frames, dets)
    with monkeypatch.context() as m:
        _reference_calls(m)
        want = _run(frames, dets)
    assert sum(len(r) for r, _ in got) > 0
    assert got == want


def test_the_tracker_on_the_bench_scene_is_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    from experiments import python_share

    frames, dets = python_share.scene_dets()
    xywh = [np.column_stack([d[:, :2], d[:, 2:4] - d[:, :2], d[:, 4]]) for d in dets]
    _both(monkeypatch, frames[:40], xywh[:40])


def test_the_tracker_on_pets09_is_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    """PETS09's first 60 frames with the built-in detector: the same tracks and states."""
    import cv2

    folder = dataset("pets09-s2l1")
    videos = sorted(folder.glob("*.avi")) + sorted(folder.glob("*.mp4"))
    if not videos:
        pytest.skip(f"no video in {folder}")
    cap = cv2.VideoCapture(str(videos[0]))
    frames = []
    while len(frames) < 60:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame)
    cap.release()
    _both(monkeypatch, frames, None)


def test_predict_and_follow_take_any_sequence() -> None:
    """A tuple of tracks and a tuple of gains, as the public functions take them."""
    from pftrack.particle_filter import hsv_bins
    from pftrack.tracking.track import LiveTrack

    cfg = TrackerConfig()
    frame = np.random.default_rng(3).integers(0, 255, (60, 80, 3), dtype=np.uint8)
    image = hsv_bins(frame)
    ref = np.full(image.n_bins, 1.0 / image.n_bins)
    tracks = tuple(
        LiveTrack(i + 1, np.array([10.0 + 20 * i, 10.0, 8.0, 20.0]), ref, cfg, i, 0.9)
        for i in range(2)
    )
    rows = predict_tracks(tracks, image, cfg.motion.colour_noise, (1.0, 2.0))
    assert rows.shape == (2, 8)
    assert [t.age for t in tracks] == [2, 2]
    follow_tracks_motion(tracks, np.array([[10.0, 11.0, 8.0, 20.0]] * 2), cfg, True)
    assert all(t.measured is not None for t in tracks)
