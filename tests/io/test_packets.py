"""Chosen frames of an intra-only (MJPEG) file decoded from their packets alone (io/packets.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.io import packets, video
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from tests.io.decode import capture_frames


@pytest.fixture(scope="module")
def scene_avi(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The synthetic scene's MJPEG AVI (the videos of ``pftrack demo --video``)."""
    path = tmp_path_factory.mktemp("packets") / "walk.avi"
    return make_scene(n_frames=48, n_walkers=4, rng=2).write_video(path)


def _no_grabs(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make OpenCV's pass of grabs fail: the frames must come from the packets alone."""

    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("OpenCV's pass of grabs ran")

    monkeypatch.setattr(FrameSource, "_read_at", refuse)


def test_pyav_frames_are_opencvs_bit_for_bit(tmp_path: Path, scene_avi: Path) -> None:
    want = capture_frames(scene_avi)
    picked = [0, 1, 7, 30, 47]
    got = packets.intra_frames_at(str(scene_avi), picked, len(want))
    assert got is not None and len(got) == len(picked)
    for a, k in zip(got, picked, strict=True):
        np.testing.assert_array_equal(a, want[k])
    # MPEG-4 part 2 predicts frames from others: not read this way
    mp4 = make_scene(n_frames=20, n_walkers=2, rng=2).write_video(tmp_path / "walk.mp4")
    assert packets.intra_frames_at(str(mp4), [0, 5], 20) is None


def test_a_count_other_than_the_packets_is_refused(scene_avi: Path) -> None:
    assert packets.intra_frames_at(str(scene_avi), [0, 5], 49) is None
    assert packets.intra_frames_at(str(scene_avi), [0, 5], 47) is None
    assert packets.intra_frames_at(str(scene_avi / "missing.avi"), [0], 48) is None


def test_stopped_ends_before_the_next_frame(scene_avi: Path) -> None:
    calls: list[int] = []

    def stopped() -> bool:
        calls.append(1)
        return len(calls) > 2

    got = packets.intra_frames_at(str(scene_avi), [0, 10, 20, 30], 48, stopped)
    assert got is not None and len(got) == 2


def test_spread_bootstrap_of_an_mjpeg_file_decodes_only_its_frames(
    scene_avi: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    want = capture_frames(scene_avi)
    spread = np.linspace(0, len(want) - 1, 30).round().astype(int).tolist()
    monkeypatch.setattr(video, "PACKET_PASS_MIN_PIXELS", 0)
    _no_grabs(monkeypatch)
    for split in (False, True):
        got = bootstrap_frames(FrameSource(scene_avi), 30, "spread", split=split)
        assert len(got) == 30
        for a, k in zip(got, spread, strict=True):
            np.testing.assert_array_equal(a, want[k])
    # not from frame 0, and resized as every read is
    src = FrameSource(scene_avi, scale=0.5)
    got = src.frames_at([3, 40], prepare=lambda f: f[:1])
    for a, k in zip(got, [3, 40], strict=True):
        np.testing.assert_array_equal(a, src._resize(want[k])[:1])


def test_few_pixels_left_undecoded_keep_the_opencv_pass(
    scene_avi: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 48 frames of 320x240 (18 left of 30 chosen: 1.4e6 pixels) do not pay for importing PyAV
    called: list[object] = []
    monkeypatch.setattr(video, "intra_frames_at", lambda *a: called.append(a))
    assert len(bootstrap_frames(FrameSource(scene_avi), 30, "spread")) == 30
    assert called == []


def test_a_first_frame_unlike_opencvs_falls_back_to_its_pass(
    scene_avi: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Another build of PyAV's or OpenCV's FFmpeg could convert otherwise: OpenCV's pixels win."""
    want = capture_frames(scene_avi)
    read = packets.intra_frames_at

    def off_by_one(*args: Any) -> list[np.ndarray] | None:
        frames = read(*args)
        return None if frames is None else [f ^ 1 for f in frames]

    monkeypatch.setattr(video, "PACKET_PASS_MIN_PIXELS", 0)
    monkeypatch.setattr(video, "intra_frames_at", off_by_one)
    got = FrameSource(scene_avi).frames_at([5, 20])
    np.testing.assert_array_equal(got[0], want[5])
    np.testing.assert_array_equal(got[1], want[20])
