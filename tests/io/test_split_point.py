"""Where a split pass's second half starts: after a key frame, from the packets (io/video.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import av
import numpy as np
import pytest

from pftrack.io.video import SEEK_BACK, FrameSource, _key_frames, _split_point
from pftrack.synthetic import make_scene
from tests.io.decode import capture_frames
from tests.io.encode import encode


@pytest.fixture(scope="module")
def h264(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """60 frames of H.264, a key frame every 20 and B-frames between (PETS09's kind of file)."""
    path = tmp_path_factory.mktemp("split") / "walk.mp4"
    scene = make_scene(n_frames=60, n_walkers=4, rng=5)
    try:
        return encode(path, scene.frames, options={"bf": "2", "g": "20"})
    except (av.FFmpegError, ValueError) as error:  # an av build without x264
        pytest.skip(f"no H.264 encoder: {error}")


def _decoded_key_frames(path: Path) -> list[int]:
    """The positions of the key frames among the decoded frames, in display order (PyAV)."""
    with av.open(str(path)) as container:
        return [i for i, frame in enumerate(container.decode(video=0)) if frame.key_frame]


def test_key_frames_from_the_packets_are_the_decoded_ones(tmp_path: Path, h264: Path) -> None:
    assert _key_frames(str(h264), 60) == _decoded_key_frames(h264) == [0, 20, 40]
    mp4 = make_scene(n_frames=30, n_walkers=2, rng=2).write_video(tmp_path / "walk.mp4")
    keys = _key_frames(str(mp4), 30)  # MPEG-4 part 2, as the synthetic MP4 videos
    assert keys is not None and keys == _decoded_key_frames(mp4) and len(keys) > 1


def test_a_count_other_than_the_packets_gives_none(h264: Path) -> None:
    assert _key_frames(str(h264), 59) is None
    assert _key_frames(str(h264), 61) is None
    assert _key_frames(str(h264.with_name("missing.mp4")), 60) is None


def test_the_point_balances_the_halves_from_where_the_seek_lands() -> None:
    # PETS09: 795 frames, key frames 0, 250, 500, 750; its middle chosen frame 411 had the
    # second half decode from 250 (545 frames), the first 413
    assert _split_point(795, 411, [0, 250, 500, 750]) == 500 + SEEK_BACK
    assert _split_point(795, 411, None) == _split_point(795, 411, []) == 411
    # every frame a key frame (MJPEG): the halves as even as can be
    point = _split_point(300, 150, list(range(300)))
    assert abs((point + 2) - (300 - (point - SEEK_BACK))) <= 1
    # one key frame: the second half decodes from 0 wherever it lands; the first stops soonest
    assert _split_point(100, 50, [0]) == SEEK_BACK


def test_a_split_pass_seeks_past_a_key_frame_and_gives_the_plain_frames(
    h264: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    want = capture_frames(h264)
    spread = np.linspace(0, len(want) - 1, 12).round().astype(int).tolist()
    seeks: list[int] = []
    seek = FrameSource._read_from_seek

    def spy(self: FrameSource, middle: int, *args: Any, **options: Any) -> object:
        seeks.append(middle)  # where the second half starts
        return seek(self, middle, *args, **options)

    monkeypatch.setattr(FrameSource, "_read_from_seek", spy)
    got = FrameSource(h264).frames_at(spread, split=True)
    # the middle chosen frame is 32 (its seek decodes from 0); from 36 it decodes from 20
    assert seeks == [20 + SEEK_BACK] != [spread[len(spread) // 2]]
    assert len(got) == len(spread)
    for a, k in zip(got, spread, strict=True):
        np.testing.assert_array_equal(a, want[k])
