"""The still camera's measurement in the core (stop 72): OpenCV's one-level Lucas-Kanade to the bit,
the closed-form similarity against NumPy's least squares, and a still path that decides and
applies exactly what OpenCV's refined fit did."""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import pytest

from pftrack import _core
from pftrack.synthetic import make_scene, warp_frame
from pftrack.tracking import CameraConfig
from pftrack.tracking import camera as camera_module
from pftrack.tracking.camera import CameraMotion, CameraStep, motion_magnitude

CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 30, 0.01)


def opencv_flow(
    prev: np.ndarray, cur: np.ndarray, pts: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``cv2.calcOpticalFlowPyrLK`` as camera.py called it for a still frame (maxLevel 0)."""
    p = np.ascontiguousarray(pts.reshape(-1, 1, 2), dtype=np.float32)
    nxt, status, _ = cv2.calcOpticalFlowPyrLK(
        prev, cur, p, np.empty_like(p), winSize=(11, 11), maxLevel=0, criteria=CRITERIA, flags=0
    )
    return nxt.reshape(-1, 2), status.reshape(-1) == 1


def assert_same_flow(prev: np.ndarray, cur: np.ndarray, pts: np.ndarray) -> int:
    """The core's flow equals OpenCV's: the same points followed, at the same float32 bits."""
    want, want_ok = opencv_flow(prev, cur, pts)
    got, got_ok = _core.still_flow(prev, cur, pts)
    assert got.dtype == np.float32 and got.shape == (len(pts), 2)
    np.testing.assert_array_equal(got_ok, want_ok)
    np.testing.assert_array_equal(got[got_ok].view(np.uint32), want[want_ok].view(np.uint32))
    return int(want_ok.sum())


@pytest.fixture(scope="module")
def cv_threads() -> Any:
    before = cv2.getNumThreads()
    cv2.setNumThreads(1)
    yield
    cv2.setNumThreads(before)


@pytest.mark.parametrize("seed", range(4))
def test_still_flow_equals_opencv_bit_for_bit_on_random_images(cv_threads: Any, seed: int) -> None:
    # blurred noise of every size from 1 to 120 pixels a side, moved by up to several pixels
    # (the flow then runs its 30 steps, leaves the image, or stops oscillating), points inside,
    # on the edges and up to 15 px outside (refused, or windows read reflected pixels)
    rng = np.random.default_rng(seed)
    followed = 0
    for trial in range(120):
        h, w = (int(v) for v in rng.integers(1, 121, 2))
        noise = rng.integers(0, 256, (h, w), dtype=np.uint8)
        prev = cv2.GaussianBlur(noise, (0, 0), rng.uniform(0.5, 3.0))
        shift = rng.normal(0.0, [0.3, 1.0, 3.0][trial % 3], 2)
        m = np.array([[1.0, 0.0, shift[0]], [0.0, 1.0, shift[1]]])
        cur = cv2.warpAffine(prev, m, (w, h), borderMode=cv2.BORDER_REFLECT)
        cur = np.clip(cur.astype(int) + rng.integers(-3, 4, cur.shape), 0, 255).astype(np.uint8)
        pts = np.column_stack([rng.uniform(-15, w + 15, 40), rng.uniform(-15, h + 15, 40)]).astype(
            np.float32
        )
        pts[:4] = [[0, 0], [w - 1, h - 1], [-11.0, 2.5], [w + 5.5, h - 0.25]]
        followed += assert_same_flow(prev, cur, pts)
    assert followed > 1000  # the comparison is not only of refused points


def test_still_flow_equals_opencv_on_a_scene_s_corners(cv_threads: Any) -> None:
    # the use in camera.py: the corners of a scaled grey frame, followed into the next one
    # moved by a fraction of a pixel (a still camera) and by a few pixels
    bg = make_scene(n_frames=1, rng=3, occluder=False).background
    grey = cv2.cvtColor(bg, cv2.COLOR_BGR2GRAY)
    grey = cv2.resize(grey, (240, 180), interpolation=cv2.INTER_AREA)
    pts = cv2.goodFeaturesToTrack(grey, 100, 0.01, 4.5)
    assert pts is not None and len(pts) >= 40
    rng = np.random.default_rng(1)
    for shift in (0.0, 0.05, 0.3, 0.8, 2.5, 6.0):
        m = np.array([[1.0, 0.0, shift], [0.0, 1.0, -0.5 * shift]])
        cur = cv2.warpAffine(grey, m, (240, 180), borderMode=cv2.BORDER_REFLECT)
        cur = np.clip(cur + rng.normal(0, 1.5, cur.shape), 0, 255).astype(np.uint8)
        assert assert_same_flow(grey, cur, pts) >= 30
        # the (N, 1, 2) layout of goodFeaturesToTrack and (N, 2) give the same
        a, _ = _core.still_flow(grey, cur, pts)
        b, _ = _core.still_flow(grey, cur, pts.reshape(-1, 2))
        np.testing.assert_array_equal(a, b)


def test_still_flow_reads_strided_rows(cv_threads: Any) -> None:
    rng = np.random.default_rng(2)
    big = cv2.GaussianBlur(rng.integers(0, 256, (90, 130), dtype=np.uint8), (0, 0), 1.5)
    prev, cur = big[5:85, 3:120], big[6:86, 4:121]  # views: rows strided, one pixel apart
    pts = rng.uniform(0, 80, (30, 2)).astype(np.float32)
    assert assert_same_flow(np.ascontiguousarray(prev), np.ascontiguousarray(cur), pts) > 0
    got = _core.still_flow(prev, cur, pts)
    want = _core.still_flow(np.ascontiguousarray(prev), np.ascontiguousarray(cur), pts)
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_array_equal(got[1], want[1])


def test_still_flow_refuses_bad_input_in_one_line() -> None:
    g = np.zeros((20, 30), np.uint8)
    pts = np.zeros((3, 2), np.float32)
    with pytest.raises(TypeError, match="prev dtype is float32, expected uint8"):
        _core.still_flow(g.astype(np.float32), g, pts)
    with pytest.raises(TypeError, match="next is list"):
        _core.still_flow(g, [[0]], pts)
    with pytest.raises(ValueError, match=r"prev must have shape \(H, W\)"):
        _core.still_flow(np.zeros((20, 30, 3), np.uint8), g, pts)
    with pytest.raises(ValueError, match="differ in size"):
        _core.still_flow(g, np.zeros((20, 31), np.uint8), pts)
    with pytest.raises(ValueError, match="prev is empty"):
        _core.still_flow(np.zeros((0, 30), np.uint8), np.zeros((0, 30), np.uint8), pts)
    with pytest.raises(ValueError, match="pts must have shape"):
        _core.still_flow(g, g, np.zeros((3, 3), np.float32))
    with pytest.raises(ValueError, match="packed along rows"):
        _core.still_flow(g[:, ::2], g[:, ::2], pts)
    with pytest.raises(ValueError, match=r"win_size is 2, expected in \[3, 255\]"):
        _core.still_flow(g, g, pts, win_size=2)
    with pytest.raises(ValueError, match="pts must be finite and within 1e8"):
        _core.still_flow(g, g, np.array([[1.0, np.nan]], np.float32))
    with pytest.raises(ValueError, match="pts must be finite and within 1e8"):
        _core.still_flow(g, g, np.array([[1e9, 2.0]]))
    nxt, ok = _core.still_flow(g, g, np.zeros((0, 2), np.float32))  # no points: nothing
    assert nxt.shape == (0, 2) and ok.shape == (0,)


def lstsq_similarity(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """The least-squares similarity [[a, -b, tx], [b, a, ty]] by NumPy's lstsq."""
    x, y = src[:, 0].astype(np.float64), src[:, 1].astype(np.float64)
    one, zero = np.ones_like(x), np.zeros_like(x)
    design = np.vstack([np.column_stack([x, -y, one, zero]), np.column_stack([y, x, zero, one])])
    target = np.concatenate([dst[:, 0], dst[:, 1]]).astype(np.float64)
    a, b, tx, ty = np.linalg.lstsq(design, target, rcond=None)[0]
    return np.array([[a, -b, tx], [b, a, ty]])


@pytest.mark.parametrize("seed", range(5))
def test_similarity_fit_is_numpy_s_least_squares(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 60))
    src = rng.uniform(0, 240, (n, 2)).astype(np.float32)
    th, z = rng.normal(0, 0.05), 1 + rng.normal(0, 0.02)
    lin = z * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    dst = (src @ lin.T + rng.normal(0, 3, 2) + rng.normal(0, 0.3, (n, 2))).astype(np.float32)
    got = _core.similarity_fit(src, dst)
    assert got is not None and got.dtype == np.float64 and got.shape == (2, 3)
    np.testing.assert_allclose(got, lstsq_similarity(src, dst), rtol=0, atol=1e-9)
    # the (N, 1, 2) layout gives the same
    np.testing.assert_array_equal(_core.similarity_fit(src[:, None], dst[:, None]), got)


def test_similarity_fit_of_points_without_spread_is_none() -> None:
    same = np.full((5, 2), 3.0, np.float32)
    assert _core.similarity_fit(same, same + 1) is None
    assert _core.similarity_fit(same[:1], same[:1]) is None
    with pytest.raises(ValueError, match="differ in length"):
        _core.similarity_fit(same, same[:4])
    with pytest.raises(ValueError, match="dst must be finite"):
        _core.similarity_fit(same, np.full((5, 2), np.inf, np.float32))


def _opencv_follow_still(
    self: Any, prev: np.ndarray, cur: np.ndarray, pts: np.ndarray, factor: float,
    size: tuple[int, int], below: float,
) -> tuple[np.ndarray, float, np.ndarray] | None:  # fmt: skip
    """The still path as it was before stop 72: OpenCV's flow at one level, its refined fit."""
    affine, kept = self.follow(prev, cur, pts, factor, 0)
    if affine is None:
        return None
    return affine, motion_magnitude(affine, size), kept


def _run(frames: list[np.ndarray], config: CameraConfig) -> list[CameraStep]:
    camera = CameraMotion("auto", config)
    return [camera.update(f) for f in frames]


def test_still_path_decides_and_applies_what_opencv_s_refined_fit_did(
    monkeypatch: pytest.MonkeyPatch, cv_threads: Any
) -> None:
    # a still camera (noise only); a frame that stirs, measured by the still path, then a pan
    # that moves: the transform applied when the camera starts moving covers the stirring
    # frame (twice); then steps at the lower threshold (the refined fit must be taken there)
    bg = make_scene(n_frames=1, rng=5, occluder=False).background
    rng = np.random.default_rng(4)
    diag = float(np.hypot(*bg.shape[:2]))
    # a lower threshold under half the upper one, so that a frame between them stirs and is
    # still measured by the still path
    config = CameraConfig(refresh_frames=12, still_threshold=0.0005)
    low = config.still_threshold * diag
    steps_px = [0.0] * 20 + [1.5 * low] + [4.0] * 5 + [0.0] * 15 + [1.2 * low] + [4.0] * 4
    steps_px += [0.0] * 15 + list(low * (1 + rng.normal(0, 0.02, 20)))
    frames, x = [], 0.0
    for s in steps_px:
        x += s
        view = np.array([[1.25, 0.0, -0.125 * bg.shape[1] + x], [0.0, 1.25, -0.125 * bg.shape[0]]])
        f = warp_frame(bg, view).astype(float) + rng.normal(0, 2.0, bg.shape)
        frames.append(np.clip(f, 0, 255).astype(np.uint8))
    got = _run(frames, config)
    monkeypatch.setattr(camera_module._Measure, "follow_still", _opencv_follow_still)
    want = _run(frames, config)
    assert [s.moving for s in got] == [s.moving for s in want]
    assert [s.background_ok for s in got] == [s.background_ok for s in want]
    assert any(s.moving for s in got) and any(s.apply is not None for s in got)
    for g, w in zip(got, want, strict=True):
        assert (g.apply is None) == (w.apply is None)
        if g.apply is not None:
            np.testing.assert_array_equal(g.apply, w.apply)  # to the bit
        assert (g.affine is None) == (w.affine is None)
        if g.affine is not None and w.affine is not None:
            np.testing.assert_allclose(g.affine, w.affine, rtol=0, atol=1e-4)
            assert abs(g.magnitude - w.magnitude) < 1e-4
            below = config.still_threshold * diag - camera_module.STILL_MARGIN
            if g.magnitude >= below:  # near or over the threshold: the refined fit itself
                np.testing.assert_array_equal(g.affine, w.affine)
                assert g.magnitude == w.magnitude
    assert sum(s.apply is not None for s in got) >= 2
    closed_form = [
        g for g, w in zip(got, want, strict=True)
        if g.affine is not None and w.affine is not None and not np.array_equal(g.affine, w.affine)
    ]  # fmt: skip
    assert len(closed_form) >= 10
