"""A file of several video streams: OpenCV reads the first, and that is said once.

A user's recording with two cameras in one Matroska file (or a phone's MP4 with a second,
smaller stream) was tracked on the first stream without a word, the other never read.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io import video
from pftrack.io.video import FrameSource

av = pytest.importorskip("av")


def write_streams(path: Path, sizes: list[tuple[int, int]], audio: bool = False) -> Path:
    """20 frames in each of one H.264 stream per (width, height) of `sizes`, in that order."""
    out = av.open(str(path), "w")
    if audio:
        out.add_stream("aac", rate=8000)
    streams = []
    for w, h in sizes:
        stream = out.add_stream("libx264", rate=10)
        stream.width, stream.height, stream.pix_fmt = w, h, "yuv420p"
        streams.append(stream)
    for i in range(20):
        for k, stream in enumerate(streams):
            image = np.full((stream.height, stream.width, 3), (60 * k + 5 * i) % 256, np.uint8)
            for packet in stream.encode(av.VideoFrame.from_ndarray(image, format="bgr24")):
                out.mux(packet)
    for stream in streams:
        for packet in stream.encode():
            out.mux(packet)
    out.close()
    return path


@pytest.mark.parametrize("suffix", [".mkv", ".mp4"])
def test_a_second_video_stream_is_said(tmp_path: Path, suffix: str) -> None:
    path = write_streams(tmp_path / f"two{suffix}", [(160, 120), (96, 64)])
    with pytest.warns(UserWarning, match="2 video streams") as said:
        source = FrameSource(path)
    (message,) = [str(w.message) for w in said]
    assert str(path) in message
    assert "#0 (h264 160x120)" in message and "#1 (h264 96x64)" in message
    assert (source.width, source.height) == (160, 120)  # the first stream's frames, as said


def test_the_stream_read_is_the_first_video_stream_after_an_audio_one(tmp_path: Path) -> None:
    path = write_streams(tmp_path / "three.mkv", [(96, 64), (160, 120)], audio=True)
    with pytest.warns(UserWarning, match="2 video streams") as said:
        source = FrameSource(path)
    assert (source.width, source.height) == (96, 64)
    assert "the first, #1 (h264 96x64), is read" in str(said[0].message)


def test_one_video_stream_is_not_said(tmp_path: Path) -> None:
    path = write_streams(tmp_path / "one.mkv", [(160, 120)], audio=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        FrameSource(path)


def test_without_pyav_nothing_is_said(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = write_streams(tmp_path / "two.mkv", [(160, 120), (96, 64)])
    monkeypatch.setattr(video, "_import_av", lambda: None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        FrameSource(path)


@pytest.mark.filterwarnings("default")  # said on stderr, as a user sees it
def test_track_says_it_once(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_streams(tmp_path / "two.mkv", [(160, 120), (96, 64)])
    assert main(["track", str(path), "--out", str(tmp_path / "t.txt"), "--particles", "30"]) == 0
    said = [line for line in capsys.readouterr().err.splitlines() if "video streams" in line]
    assert len(said) == 1 and said[0].startswith("pftrack track: warning: ")


def test_a_stream_of_a_codec_ffmpeg_does_not_know_is_named(tmp_path: Path) -> None:
    # its second track's sample entry says "zzzz": PyAV gives it no codec context (was: an
    # AttributeError traceback out of FrameSource, pftrack track too)
    path = write_streams(tmp_path / "two.mp4", [(160, 120), (96, 64)])
    data = bytearray(path.read_bytes())
    second = data.index(b"avc1", data.index(b"avc1", data.rindex(b"moov")) + 4)
    data[second : second + 4] = b"zzzz"
    path.write_bytes(data)
    with pytest.warns(UserWarning, match="2 video streams") as said:
        FrameSource(path)
    assert "#0 (h264 160x120)" in str(said[0].message)
    assert "not #1 (a codec FFmpeg does not know)" in str(said[0].message)
