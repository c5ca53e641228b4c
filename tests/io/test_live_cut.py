"""An MPEG-TS cut from a live stream, without a key frame at its start: said, not silent.

FFmpeg cannot decode the frames before the stream's first key frame and leaves them out: the
first frame read is the stream's eighth, say, and every frame number is 7 off against
detections or ground truth counted from the stream's start. It was read without a word. The
first frame's time stamp (after the stream's start) and the stream's first packet (no key
frame) tell it, and one warning names how many frames appear to be missing; a stamp after the
start with a key frame first is a decoder's delay (PETS09's AVI), not said.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from pftrack.cli import main
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from tests.conftest import dataset
from tests.io.encode import encode

av = pytest.importorskip("av")

GOP = 10  # frames from one key frame to the next


def _stream(path: Path, bframes: int = 0, form: str | None = "mpegts") -> Path:
    """40 frames of a walk, H.264 with a key frame every GOP frames."""
    scene = make_scene(n_frames=40, width=160, height=120, rng=0)
    options = {"g": str(GOP), "bf": str(bframes)}
    return encode(path, scene.frames, 25, options=options, container=form)


def _cut(source: Path, path: Path, skip: int) -> Path:
    """`source`'s packets from its `skip`-th on (its time stamps kept), as a live recording
    started between two key frames saves them."""
    with av.open(str(source)) as inp, av.open(str(path), "w", format="mpegts") as out:
        into = out.add_stream_from_template(inp.streams.video[0])
        for i, packet in enumerate(p for p in inp.demux(video=0) if p.size):
            if i >= skip:
                packet.stream = into
                out.mux(packet)
    return path


def _said(source: Path) -> tuple[list[str], int]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frames = FrameSource(source)
        n = sum(1 for _ in frames)
        n += sum(1 for _ in frames)  # a second pass says nothing more
    return [str(w.message) for w in caught], n // 2


@pytest.mark.parametrize(("skip", "bframes", "missing"), [(3, 0, 7), (7, 0, 3), (13, 0, 7)])
def test_the_frames_ffmpeg_leaves_out_are_counted_once(
    tmp_path: Path, skip: int, bframes: int, missing: int
) -> None:
    cut = _cut(_stream(tmp_path / "whole.ts", bframes), tmp_path / "cut.ts", skip)
    said, n = _said(cut)
    assert n == 40 - skip - missing  # what FFmpeg decodes
    (message,) = said
    assert "\n" not in message and message.startswith(f"{cut}: the video stream begins without")
    assert f"{missing} frames before it appear to be missing" in message
    assert f"frame 1 here is the stream's frame {missing + 1};" in message


def test_b_frames_left_out_after_the_key_frame_are_counted(tmp_path: Path) -> None:
    """With B-frames, packets in decoding order are not frames in showing order: the stamps
    count the time line from the stream's first stamp to its first frame that decodes, 6
    frames here (5 packets before the key frame, and a B-frame whose packet went with the
    cut), not the packets before the key frame."""
    cut = _cut(_stream(tmp_path / "whole.ts", bframes=2), tmp_path / "cut.ts", 5)
    said, n = _said(cut)
    (message,) = said
    assert n == 40 - 5 - 5 and "6 frames before it appear to be missing" in message


@pytest.mark.parametrize(("name", "bframes", "form"), [
    ("whole.ts", 0, "mpegts"), ("whole.ts", 2, "mpegts"), ("whole.mp4", 2, None),
    ("whole.mkv", 0, None),
])  # fmt: skip
def test_a_stream_that_begins_with_a_key_frame_is_not_said(
    tmp_path: Path, name: str, bframes: int, form: str | None
) -> None:
    said, n = _said(_stream(tmp_path / name, bframes, form))
    assert (said, n) == ([], 40)


@pytest.mark.parametrize("suffix", [".avi", ".mp4"])
def test_the_synthetic_videos_are_not_said(tmp_path: Path, suffix: str) -> None:
    scene = make_scene(n_frames=20, width=96, height=64, rng=0)
    scene.write_video(tmp_path / f"walk{suffix}")
    assert _said(tmp_path / f"walk{suffix}") == ([], 20)


@pytest.mark.parametrize(("name", "video", "n"), [
    ("pets09-s2l1", "video.avi", 795), ("tud-campus", "video.mp4", 71),
])  # fmt: skip
def test_the_shared_sequences_are_not_said(name: str, video: str, n: int) -> None:
    """PETS09's first frame is stamped 200 ms (2 frames at its header's 10 fps) after the
    start, its first packet a key frame: a decoder's delay, its 795 frames all there."""
    assert _said(dataset(name) / video) == ([], n)


def test_the_command_says_it_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cut = _cut(_stream(tmp_path / "whole.ts"), tmp_path / "cut.ts", 3)
    assert main(["track", str(cut), "--out", str(tmp_path / "t.txt"), "--particles", "30"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len([e for e in err if "appear to be missing" in e]) == 1, err
    assert err[0].startswith("pftrack track: warning: ") and "7 frames" in err[0], err
