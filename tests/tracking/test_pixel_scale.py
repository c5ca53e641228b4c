"""Pixel settings that grow with the frame (TrackerConfig.pixel_diagonal).

The particle filter's centre noise and the offline linker's gate are given in pixels; on frames
larger than 640x480 they grow with the diagonal, so that footage of one scene at a higher
resolution is tracked with the same settings relative to the image. On frames smaller than
480x360 the filter's noise shrinks with the diagonal (TrackerConfig.noise_scale); the gate does
not.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import pftrack
from pftrack.tracking import MultiObjectTracker, TrackerConfig


@pytest.mark.parametrize(
    ("width", "height", "scale"),
    [(480, 360, 1.0), (640, 480, 1.0), (320, 240, 1.0), (1280, 960, 2.0), (1920, 1440, 3.0)],
)
def test_pixel_scale_is_the_diagonal_over_800_above_640x480(width, height, scale):
    assert TrackerConfig().pixel_scale(width, height) == pytest.approx(scale)
    assert TrackerConfig(pixel_diagonal=None).pixel_scale(width, height) == 1.0
    assert TrackerConfig(pixel_diagonal=400).pixel_scale(width, height) == pytest.approx(
        max(1.0, np.hypot(width, height) / 400)
    )


@pytest.mark.parametrize(
    ("width", "height", "scale"),
    [(240, 180, 0.5), (360, 270, 0.75), (480, 360, 1.0), (640, 480, 1.0), (1280, 960, 2.0)],
)
def test_noise_scale_shrinks_below_480x360_and_grows_above_640x480(width, height, scale):
    config = TrackerConfig()
    assert config.noise_scale(width, height) == pytest.approx(scale)
    assert config.pixel_scale(width, height) == pytest.approx(max(1.0, scale))
    assert TrackerConfig(pixel_diagonal=None).noise_scale(width, height) == 1.0


def test_noise_scale_with_a_small_pixel_diagonal_is_the_diagonal_over_it():
    config = TrackerConfig(pixel_diagonal=400)  # 320x240: settings hold at 400 px and below
    assert config.noise_scale(320, 240) == pytest.approx(1.0)
    assert config.noise_scale(160, 120) == pytest.approx(0.5)
    assert config.noise_scale(480, 360) == pytest.approx(1.5)  # grows above it, as before


def test_scaled_pixels_changes_only_the_particle_noise():
    config = TrackerConfig()
    assert config.scaled_pixels(1.0) is config
    big = config.scaled_pixels(2.5)
    assert big.filter.model.sigma_xy == 2.5 * config.filter.model.sigma_xy
    same = dataclasses.replace(big, filter=config.filter)
    assert same == config


@pytest.mark.parametrize("value", [0, -1.0, np.nan, np.inf, True, "800"])
def test_bad_pixel_diagonal_is_refused(value):
    with pytest.raises(ValueError, match="pixel_diagonal"):
        TrackerConfig(pixel_diagonal=value)


@pytest.mark.parametrize(
    ("height", "width", "sigma"), [(180, 240, 1.5), (480, 640, 3.0), (960, 1280, 6.0)]
)
def test_the_tracks_filters_get_the_scaled_noise(height, width, sigma):
    tracker = MultiObjectTracker(rng=0)
    assert tracker.pixel_scale == 1.0
    frame = np.zeros((height, width, 3), np.uint8)
    k = width / 640
    box = np.array([[100.0, 100.0, 40.0, 100.0, 1.0]]) * [k, k, k, k, 1]
    tracker.update(frame, box)
    assert tracker.pixel_scale == pytest.approx(max(1.0, width / 640))
    assert tracker.noise_scale == pytest.approx(sigma / 3.0)
    assert [t.filter.config.model.sigma_xy for t in tracker.tracks] == [pytest.approx(sigma)]
    assert tracker.config == TrackerConfig()  # the user's settings are left as given


def jump_run(factor: float, pixel_diagonal: float | None) -> set[int]:
    """Ids of one person walking right, unseen for 20 frames, seen again 40 px (x factor) off.

    On black frames of 640x480 times `factor`, 25 frames/s: the track ends during the gap and a
    new one starts after it; the offline linker joins the two when the jump is inside its gate
    (50 px on 640x480).
    """
    h, w = round(480 * factor), round(640 * factor)
    frame = np.zeros((h, w, 3), np.uint8)
    config = TrackerConfig(pixel_diagonal=pixel_diagonal)
    tracker = pftrack.Tracker.from_config(config, seed=0, frame_rate=25.0)
    for f in range(60):
        if 20 <= f < 40:
            dets = np.zeros((0, 5))
        else:
            x = 100 + 2 * f + (40 if f >= 40 else 0)
            dets = np.array([[x, 150, x + 40, 250, 1.0]])
        tracker.update(dets * [factor, factor, factor, factor, 1], frame)
    rows = tracker.finalize()
    assert len(rows) > 0
    return set(rows[:, 1].astype(int))


@pytest.mark.filterwarnings("ignore:frame 1 is blank")  # black frames: boxes only
def test_the_linker_gate_grows_with_the_frame():
    assert len(jump_run(1.0, 800.0)) == 1  # 40 px of 640x480: inside the 50 px gate
    assert len(jump_run(2.0, 800.0)) == 1  # 80 px of 1280x960: inside its 100 px gate
    assert len(jump_run(2.0, None)) == 2  # the same footage with the gate in frame pixels
