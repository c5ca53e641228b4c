"""A file of several video streams: OpenCV reads the first, and that is said once.

A user's recording with two cameras in one Matroska file (or a phone's MP4 with a second,
smaller stream) was tracked on the first stream without a word, the other never read.
"""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io import video
from pftrack.io.video import FrameSource

av = pytest.importorskip("av")


def write_streams(
    path: Path, sizes: list[tuple[int, int]], audio: bool = False, **options: str
) -> Path:
    """20 frames in each of one H.264 stream per (width, height) of `sizes`, in that order.

    With `audio`, an AAC stream of silence before them (a stream with samples: MP4 leaves out
    a track without); `options` are the muxer's (``movflags="faststart"``: MP4's header first).
    """
    out = av.open(str(path), "w", options=options)
    sound = out.add_stream("aac", rate=8000) if audio else None
    streams = []
    for w, h in sizes:
        stream = out.add_stream("libx264", rate=10)
        stream.width, stream.height, stream.pix_fmt = w, h, "yuv420p"
        streams.append(stream)
    for i in range(20):
        if sound is not None:
            silence = av.AudioFrame.from_ndarray(np.zeros((2, 800), np.float32), "fltp", "stereo")
            silence.sample_rate, silence.pts = 8000, 800 * i
            for packet in sound.encode(silence):
                out.mux(packet)
        for k, stream in enumerate(streams):
            image = np.full((stream.height, stream.width, 3), (60 * k + 5 * i) % 256, np.uint8)
            for packet in stream.encode(av.VideoFrame.from_ndarray(image, format="bgr24")):
                out.mux(packet)
    for stream in [*streams, *([sound] if sound is not None else [])]:
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


def pyav_count(path: Path) -> int:
    """The video streams PyAV finds in `path` (cover art left out), as the warning lists them."""
    with av.open(str(path)) as container:
        return sum(
            1
            for s in container.streams.video
            if not s.disposition & av.stream.Disposition.attached_pic
        )


@pytest.mark.parametrize("suffix", [".mp4", ".mov", ".avi"])
@pytest.mark.parametrize("audio", [False, True])
@pytest.mark.parametrize("sizes", [[(160, 120)], [(160, 120), (96, 64)]])
def test_the_header_count_is_pyavs(
    tmp_path: Path, suffix: str, audio: bool, sizes: list[tuple[int, int]]
) -> None:
    # MP4, MOV and AVI headers are read without PyAV (importing it cost 0.05-0.1 s a run)
    path = write_streams(tmp_path / f"v{suffix}", sizes, audio=audio)
    assert video._header_video_count(path) == pyav_count(path) == len(sizes)
    if suffix == ".mp4":  # the header (moov) first, as a web video's
        path = write_streams(tmp_path / "fast.mp4", sizes, audio=audio, movflags="faststart")
        assert video._header_video_count(path) == pyav_count(path) == len(sizes)


def test_64_bit_and_to_the_end_box_sizes_are_stepped_over(tmp_path: Path) -> None:
    path = write_streams(tmp_path / "two.mp4", [(160, 120), (96, 64)], audio=True)
    data = bytearray(path.read_bytes())
    moov = data.rindex(b"moov") - 4
    data[moov : moov + 4] = bytes(4)  # size 0: up to the file's end (moov is last)
    after_ftyp = int.from_bytes(data[:4], "big")
    # a 64-bit size (1, then the size after the type) for a free box before mdat and moov
    data[after_ftyp:after_ftyp] = (1).to_bytes(4, "big") + b"free" + (24).to_bytes(8, "big")
    data[after_ftyp + 16 : after_ftyp + 16] = bytes(8)
    path.write_bytes(data)
    assert video._header_video_count(path) == pyav_count(path) == 2


def test_other_containers_are_left_to_pyav(tmp_path: Path) -> None:
    path = write_streams(tmp_path / "two.mkv", [(160, 120), (96, 64)])
    assert video._header_video_count(path) is None
    assert video._several_video_streams(path) == video._video_streams(path)


def add_chapter_track(path: Path) -> Path:
    """`path` (an MP4 of two video tracks, its moov last) with its second track made the first's
    chapter images (a ``tref`` ``chap`` box in the first ``trak``): FFmpeg takes it as cover art.
    """
    data = bytearray(path.read_bytes())
    moov = data.rindex(b"moov") - 4
    assert int.from_bytes(data[moov : moov + 4], "big") == len(data) - moov  # moov is last
    trak = data.index(b"trak", moov) - 4
    tkhd = data.index(b"tkhd", trak) - 4
    after = tkhd + int.from_bytes(data[tkhd : tkhd + 4], "big")
    tref = (20).to_bytes(4, "big") + b"tref" + (12).to_bytes(4, "big") + b"chap"
    data[after:after] = tref + (2).to_bytes(4, "big")  # track 2
    for box in (moov, trak):
        data[box : box + 4] = (int.from_bytes(data[box : box + 4], "big") + 20).to_bytes(4, "big")
    path.write_bytes(data)
    return path


def test_chapter_images_are_no_video_stream(tmp_path: Path) -> None:
    path = add_chapter_track(write_streams(tmp_path / "chap.mp4", [(160, 120), (96, 64)]))
    assert video._header_video_count(path) == pyav_count(path) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        FrameSource(path)


def header_end(path: Path) -> int:
    """The byte after the header of `path`: an AVI's hdrl list, an MP4's moov box (its last)."""
    data = path.read_bytes()
    if path.suffix == ".avi":
        return 20 + int.from_bytes(data[16:20], "little")
    return len(data)


@pytest.mark.parametrize("suffix", [".mp4", ".avi"])
def test_a_truncated_header_says_nothing(tmp_path: Path, suffix: str) -> None:
    path = write_streams(tmp_path / f"two{suffix}", [(160, 120), (96, 64)], audio=True)
    data, cut = path.read_bytes(), tmp_path / f"cut{suffix}"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for n in [*range(0, 64), *range(64, header_end(path), 13)]:
            cut.write_bytes(data[:n])
            assert video._several_video_streams(cut) == [], n


def test_garbage_headers_say_nothing(tmp_path: Path) -> None:
    path = tmp_path / "bad.mp4"

    def box(kind: bytes, body: bytes = b"", size: int | None = None) -> bytes:
        return (8 + len(body) if size is None else size).to_bytes(4, "big") + kind + body

    def chunk(kind: bytes, body: bytes = b"", size: int | None = None) -> bytes:
        return kind + (len(body) if size is None else size).to_bytes(4, "little") + body

    cases = {
        "a box shorter than its header": box(b"ftyp", size=4),
        "a 64-bit size past the end": box(b"ftyp", (2**64 - 1).to_bytes(8, "big"), size=1),
        "a 64-bit size below 16": box(b"ftyp", (8).to_bytes(8, "big"), size=1),
        "size 0 (to the end) and no moov": box(b"ftyp", bytes(100), size=0),
        "a trak past its moov": box(b"moov", box(b"trak", size=256)),
        "an hdlr too short": box(b"moov", box(b"trak", box(b"mdia", box(b"hdlr", b"\0" * 4)))),
        "a tkhd too short": box(b"moov", box(b"trak", box(b"tkhd", b"\1" * 8))),
        "an AVI of no hdrl": b"RIFF\0\0\0\0AVI " + chunk(b"LIST", b"movi", size=2**32 - 1),
        "an AVI strl past its hdrl": b"RIFF\0\0\0\0AVI "
        + chunk(b"LIST", b"hdrl" + chunk(b"LIST", b"strl", size=255)),
        "an AVI chunk id not text": b"RIFF\0\0\0\0AVI "
        + chunk(b"LIST", b"hdrl" + chunk(b"\1\2\3\4")),
        "an AVI strh too short": b"RIFF\0\0\0\0AVI "
        + chunk(b"LIST", b"hdrl" + chunk(b"LIST", b"strl" + chunk(b"strh", b"vi"))),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for what, data in cases.items():
            path.write_bytes(data)
            assert video._several_video_streams(path) == [], what


def test_damaged_headers_raise_nothing(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    for suffix in (".mp4", ".avi"):
        path = write_streams(tmp_path / f"two{suffix}", [(160, 120), (96, 64)], audio=True)
        data = path.read_bytes()
        start = 0 if suffix == ".avi" else data.rindex(b"moov") - 4
        end = header_end(path)
        bad = tmp_path / f"bad{suffix}"
        for _ in range(150):
            damaged = bytearray(data)
            for at in rng.integers(start, end, 3):
                damaged[at] = int(rng.integers(256))
            bad.write_bytes(damaged)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # several streams may still be said, rightly
                assert isinstance(video._several_video_streams(bad), list)


def test_track_reads_an_mp4_and_an_avi_without_pyav(tmp_path: Path) -> None:
    # importing PyAV cost 0.05-0.1 s of every pftrack track run (--render imports it anyway)
    sources = [
        write_streams(tmp_path / f"one{s}", [(160, 120)], audio=True) for s in (".mp4", ".avi")
    ]
    code = (
        "import sys\n"
        "from pftrack.cli import main\n"
        "for source in sys.argv[1:]:\n"
        "    argv = ['-q', 'track', source, '--out', source + '.txt', '--particles', '30']\n"
        "    assert main(argv) == 0\n"
        "print(sorted(m for m in sys.modules if m == 'av' or m.startswith('av.')))\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    run = subprocess.run(
        [sys.executable, "-c", code, *map(str, sources)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[-1] == "[]"  # after each run's summary
    assert all(Path(f"{s}.txt").is_file() for s in sources)
