"""The joint sampler's identities follow the camera (``RJMCMCFilter.warp``).

Until 5 December 2026 camera-motion compensation moved the per-object filters' tracks only
(``warp_tracks``): with ``sampler="rjmcmc"`` the chain's identities stayed where the previous
frame had them while the picture moved under them (user trial of the samplers).
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter.rjmcmc import RJMCMCConfig, RJMCMCFilter
from tests.particle_filter.test_rjmcmc import PARAMS

SHAPE = (96, 200)
BLOBS = [((50, 40), (200, 40, 30)), ((90, 46), (40, 200, 40)), ((130, 36), (30, 60, 220))]


def scene(blobs, shift=(0, 0)):
    """Blobs on a black background (only the foreground is binned), moved by `shift` (x, y)."""
    frame = np.zeros((*SHAPE, 3), np.uint8)
    mask = np.zeros(SHAPE, np.uint8)
    dx, dy = shift
    for (cx, cy), colour in blobs:
        cx, cy = cx + dx, cy + dy
        frame[cy - 9 : cy + 9, cx - 5 : cx + 5] = colour
        frame[cy - 9 : cy - 3, cx - 5 : cx + 5] = (200, 180, 160)  # a head: some texture
        mask[cy - 10 : cy + 10, cx - 6 : cx + 6] = 1
    return _core.hsv_bins(frame, mask), mask


def candidates(blobs, shift=(0, 0)):
    return np.array([[cx + shift[0], cy + shift[1], 10.0, 18.0] for (cx, cy), _ in blobs])


def moved(step):
    return [((cx + 2 * step, cy), col) for (cx, cy), col in BLOBS]


def translation(dx, dy):
    return np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]])


def test_a_translated_camera_tracks_as_a_still_one():
    """Frames 1-3 still; then the camera's view moves by (16, 8): the content of frame 4 is
    frame 4 of the still run shifted by it. Warped by that shift, the chain gives the still
    run's estimates shifted by it (the same draws, the same target up to round-off)."""
    cfg = RJMCMCConfig(**PARAMS)
    still, moving = RJMCMCFilter(cfg, rng=3), RJMCMCFilter(cfg, rng=3)
    for step in range(3):
        for f in (still, moving):
            f.step(*scene(moved(step)), candidates(moved(step)))
    shift = (16, 8)
    moving.warp(translation(*shift))
    a = still.step(*scene(moved(3)), candidates(moved(3)))
    b = moving.step(*scene(moved(3), shift), candidates(moved(3), shift))
    assert len(a) == 3
    assert [t.id for t in a] == [t.id for t in b]
    for s, m in zip(a, b, strict=True):
        np.testing.assert_allclose(m.box_cxcywh, s.box_cxcywh + [*shift, 0, 0], atol=1e-6)
        assert m.score == pytest.approx(s.score)


def test_without_the_warp_the_identities_are_left_behind():
    """The same shifted frame without the warp: the chain's predictions are 18 px off and the
    estimates are not the still run's shifted (what the tracker did before)."""
    cfg = RJMCMCConfig(**PARAMS)
    still, moving = RJMCMCFilter(cfg, rng=3), RJMCMCFilter(cfg, rng=3)
    for step in range(3):
        for f in (still, moving):
            f.step(*scene(moved(step)), candidates(moved(step)))
    a = still.step(*scene(moved(3)), candidates(moved(3)))
    b = moving.step(*scene(moved(3), (16, 8)), candidates(moved(3), (16, 8)))
    shifted = sorted(t.box_cxcywh[0] + 16 for t in a)
    assert [t.id for t in a] != [t.id for t in b] or not np.allclose(
        sorted(t.box_cxcywh[0] for t in b), shifted, atol=1e-6
    )


def test_warp_maps_the_kept_samples_and_scales_the_base_size():
    t = _core.RJMCMCTracker(**PARAMS)
    t.step(*scene(BLOBS), candidates(BLOBS), seed=0, step=0)
    before = t.tracks
    assert before
    z, theta = 1.25, 0.1
    lin = z * np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    affine = np.c_[lin, [5.0, -3.0]]
    t.warp(affine)
    after = t.tracks
    for p, q in zip(before, after, strict=True):
        assert q["id"] == p["id"] and q["existence"] == p["existence"]
        for c in (0, 3):  # current and previous centres
            expect = p["parents"][:, c : c + 2] @ lin.T + [5.0, -3.0]
            np.testing.assert_allclose(q["parents"][:, c : c + 2], expect)
        np.testing.assert_array_equal(q["parents"][:, [2, 5]], p["parents"][:, [2, 5]])  # scales
        assert q["w0"] == pytest.approx(z * p["w0"]) and q["h0"] == pytest.approx(z * p["h0"])


@pytest.mark.parametrize(
    ("affine", "message"),
    [
        (np.eye(3), r"affine must have shape \(2, 3\)"),
        (np.array([[1.0, 0, np.nan], [0, 1, 0]]), "affine has a non-finite value"),
        (np.array([[1.0, 1, 0], [1, 1, 0]]), "affine is singular"),
        (np.array([[1e200, 0, 0], [0, 1e200, 0]]), "out of the finite numbers"),
    ],
)
def test_warp_refuses_a_bad_affine_and_keeps_the_identities(affine, message):
    f = RJMCMCFilter(RJMCMCConfig(**PARAMS), rng=0)
    f.step(*scene(BLOBS), candidates(BLOBS))
    before = f._core.tracks
    with pytest.raises(ValueError, match=message):
        f.warp(affine)
    for p, q in zip(before, f._core.tracks, strict=True):
        np.testing.assert_array_equal(q["parents"], p["parents"])
        assert (q["w0"], q["h0"]) == (p["w0"], p["h0"])


def test_warp_before_the_first_frame_does_nothing():
    f = RJMCMCFilter(RJMCMCConfig(**PARAMS), rng=0)
    f.warp(translation(3, 4))
    assert f._core.tracks == []


def test_the_tracker_moves_the_joint_samplers_identities_with_the_camera(monkeypatch):
    """pftrack.Tracker(sampler="rjmcmc") on a moving-camera scene: each frame the camera moved,
    the chain's identities are warped by the measured motion (as warp_tracks moves the
    per-object filters' tracks); was never."""
    import pftrack
    from pftrack.synthetic import make_scene, move_camera

    calls = []
    warp = RJMCMCFilter.warp
    monkeypatch.setattr(RJMCMCFilter, "warp", lambda self, a: (calls.append(a), warp(self, a)))
    scene = move_camera(make_scene(n_frames=12, n_walkers=3, rng=0), period=20.0)
    tracker = pftrack.Tracker(sampler="rjmcmc", camera_motion="on", seed=0)
    for k, frame in enumerate(scene.frames, start=1):
        rows = scene.truth[scene.truth[:, 0] == k]
        dets = np.c_[rows[:, 2:4], rows[:, 2:4] + rows[:, 4:6], np.ones(len(rows))]
        tracker.update(dets, frame)
    assert len(calls) >= 10  # every frame after the chain's first (camera_motion="on")
    assert all(np.asarray(a).shape == (2, 3) for a in calls)
