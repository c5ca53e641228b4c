"""Heavily compressed footage, told by its 8x8 blocks: `pftrack.detection.blocking`."""

from __future__ import annotations

import itertools
import warnings

import cv2
import numpy as np
import pytest

import pftrack
from pftrack.detection.blocking import BLOCK_FRAMES, BLOCKY, blockiness
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from tests.conftest import dataset

SAID = "the frames are heavily compressed"


def resaved(frame: np.ndarray, quality: int) -> np.ndarray:
    """`frame` through a JPEG of `quality` (0-100), as a camera or a re-encoder leaves it."""
    ok, data = cv2.imencode(".jpg", frame, [cv2.IMWRITE_JPEG_QUALITY, quality])
    assert ok
    return cv2.imdecode(data, cv2.IMREAD_COLOR)


@pytest.fixture(scope="module")
def frames() -> list[np.ndarray]:
    return list(make_scene(n_frames=BLOCK_FRAMES, width=192, height=144, n_walkers=3, rng=0).frames)


def test_blocks_of_a_low_jpeg_quality_are_told(frames: list[np.ndarray]) -> None:
    assert all(blockiness(f) < 1.5 for f in frames)  # 0.95-1.45 for the synthetic scenes
    assert all(blockiness(resaved(f, 10)) > BLOCKY for f in frames)
    assert blockiness(resaved(frames[0], 5)) > blockiness(resaved(frames[0], 20))


def test_flat_or_small_frames_have_no_blocks_to_tell() -> None:
    flat = np.full((64, 96, 3), 90, np.uint8)
    drawn = flat.copy()
    drawn[16:48, 24:56] = 200  # a flat box whose edges fall on the 8x8 grid
    tiny = np.random.default_rng(0).integers(0, 256, (12, 96, 3), dtype=np.uint8)
    assert blockiness(flat) == blockiness(drawn) == blockiness(tiny) == 1.0
    assert blockiness(cv2.cvtColor(flat, cv2.COLOR_BGR2GRAY)) == 1.0


def test_frames_enlarged_by_repeating_pixels_are_no_blocks(frames: list[np.ndarray]) -> None:
    """2x and 4x by repeating pixels (a test's doubled scene, a digital zoom): a step on every
    second line, none between, read 2.5 against every other step; the middles are on them."""
    for k in (2, 4):
        enlarged = [np.repeat(np.repeat(f, k, axis=0), k, axis=1) for f in frames]
        assert np.median([blockiness(f) for f in enlarged]) < 1.5


def _said(frames: list[np.ndarray], dets: np.ndarray | None) -> list[str]:
    tracker = pftrack.Tracker(particles=30)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for frame in frames:
            tracker.update(dets, frame)
    return [str(w.message) for w in caught if SAID in str(w.message)]


def test_the_tracker_says_it_once_for_the_built_in_detector(frames: list[np.ndarray]) -> None:
    blocky = [resaved(f, 10) for f in frames]
    (message,) = _said(blocky * 2, None)  # once, at the run's 8th frame
    assert "times as strong as the steps inside them" in message
    assert _said(blocky[:-1], None) == []  # fewer than BLOCK_FRAMES frames: not decided
    assert _said(frames, None) == []
    # given detections' tracks changed as much at JPEG quality 40 as at 5: not said
    assert _said(blocky, np.array([[10.0, 10.0, 30.0, 60.0, 0.9]])) == []


def test_the_shared_sequences_are_not_said_and_their_quality_10_copies_are() -> None:
    for path in (
        dataset("pets09-s2l1") / "video.avi",
        dataset("tud-campus") / "video.mp4",
    ):
        first = list(itertools.islice(FrameSource(path), BLOCK_FRAMES))
        assert np.median([blockiness(f) for f in first]) < BLOCKY
        assert np.median([blockiness(resaved(f, 10)) for f in first]) > BLOCKY
        assert np.median([blockiness(resaved(f, 20)) for f in first]) < BLOCKY
