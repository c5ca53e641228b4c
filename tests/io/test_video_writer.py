"""Video output: H.264 MP4 that browsers play (PyAV), OpenCV as the fallback, atomically."""

from __future__ import annotations

import inspect
import os
import stat
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.io import video_writer
from pftrack.io.video_writer import VideoWriter
from tests.io.decode import decode


def _frames(n: int, h: int = 21, w: int = 33) -> list[np.ndarray]:
    """Smooth gradients that move: frame k is recognisable after lossy coding."""
    y, x = np.mgrid[0:h, 0:w]
    return [
        np.stack([(4 * x + 10 * k) % 256, (6 * y) % 256, np.full_like(x, 12 * k % 256)], -1)
        .astype(np.uint8)
        for k in range(n)
    ]  # fmt: skip


@pytest.fixture
def umask() -> Iterator[int]:
    old = os.umask(0o027)
    yield 0o027
    os.umask(old)


def test_mp4_is_h264_yuv420p_at_the_given_rate(tmp_path: Path) -> None:
    frames = _frames(23)
    with VideoWriter(tmp_path / "v.mp4", 7) as writer:
        for f in frames:
            writer.write(f)
    assert (writer.backend, writer.codec, writer.n_frames) == ("pyav", "h264", 23)
    stream, got = decode(tmp_path / "v.mp4")
    assert stream.codec == "h264"
    assert stream.pix_fmt == "yuv420p"
    assert stream.average_rate == 7
    assert len(got) == 23
    assert got[0].shape == (22, 34, 3)  # odd 33x21 padded to even: yuv420p needs it
    for a, b in zip(got, frames, strict=True):
        assert np.abs(a[:21, :33].astype(int) - b).mean() < 6
    data = (tmp_path / "v.mp4").read_bytes()
    assert 0 < data.find(b"moov") < data.find(b"mdat")  # faststart: the index comes first


def test_ntsc_rate_is_kept_exactly(tmp_path: Path) -> None:
    with VideoWriter(tmp_path / "v.mp4", 30000 / 1001) as writer:
        for f in _frames(5):
            writer.write(f)
    stream, got = decode(tmp_path / "v.mp4")
    assert stream.average_rate == Fraction(30000, 1001) and len(got) == 5


def test_opencv_fallback_when_pyav_is_missing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(video_writer, "pyav_available", lambda: False)
    with VideoWriter(tmp_path / "v.mp4", 7) as writer:
        for f in _frames(9):
            writer.write(f)
    assert writer.backend == "opencv"
    cap = cv2.VideoCapture(str(tmp_path / "v.mp4"))
    n = 0
    while cap.read()[0]:
        n += 1
    assert n == 9 and cap.get(cv2.CAP_PROP_FPS) == pytest.approx(7)
    cap.release()


def test_avi_is_mjpeg_through_opencv(tmp_path: Path) -> None:
    with VideoWriter(tmp_path / "v.avi", 10) as writer:
        for f in _frames(4):
            writer.write(f)
    assert (writer.backend, writer.codec) == ("opencv", "mjpeg")
    stream, got = decode(tmp_path / "v.avi")
    assert stream.codec == "mjpeg" and len(got) == 4


_NARROW_AVI = """
import sys
from pathlib import Path
import numpy as np
from pftrack.io.video_writer import VideoWriter
w, h = int(sys.argv[2]), int(sys.argv[3])
rng = np.random.default_rng(0)
with VideoWriter(Path(sys.argv[1]), 10) as writer:
    for _ in range(10):
        writer.write(rng.integers(0, 255, (h, w, 3), np.uint8))
print(writer.codec)
"""


@pytest.mark.parametrize(("w", "h"), [(1, 8), (2, 50), (5, 120), (6, 120)])
def test_a_narrow_avi_is_written(tmp_path: Path, w: int, h: int) -> None:
    """Frames 1, 2, 5 or 6 pixels wide (2 or 6 once made even) make a playable .avi.

    Was: OpenCV's FFmpeg MJPG writer corrupted the heap on them ("double free or corruption",
    the process aborted) unless the height was a multiple of 16: ``pftrack track`` of a folder
    of 1-pixel-wide images with ``--render v.avi`` died with exit status 134. Run in a process
    of its own: the failure kills it.
    """
    import subprocess
    import sys

    out = tmp_path / "v.avi"
    env = {**os.environ, "MALLOC_CHECK_": "3"}  # glibc: any heap damage aborts
    run = subprocess.run(
        [sys.executable, "-c", _NARROW_AVI, str(out), str(w), str(h)],
        capture_output=True, text=True, env=env, timeout=120, check=False,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-500:]
    assert run.stdout.strip() == "mjpeg"
    stream, got = decode(out)
    assert stream.codec == "mjpeg" and len(got) == 10
    assert got[0].shape == (h + h % 2, w + w % 2, 3)


def test_a_failure_keeps_the_old_file_and_leaves_nothing(tmp_path: Path) -> None:
    target = tmp_path / "v.mp4"
    target.write_bytes(b"old")
    frames = _frames(3)
    with (
        pytest.raises(ValueError, match=r"^VideoWriter.write: frame 2 is 33x10, the video 33x21$"),
        VideoWriter(target, 7) as writer,
    ):
        writer.write(frames[0])
        writer.write(frames[1][:10])  # another size
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.mp4"]


def test_a_closed_or_aborted_writer_is_one_clear_error(tmp_path: Path) -> None:
    """A frame after ``close``/``abort``, or ``close`` after ``abort``: a ValueError naming it.

    Was: ``write`` after ``close`` an AttributeError ('NoneType' object has no attribute
    'write'); after a ``close`` without frames (OSError) a frame made a hidden file that
    nothing removed; ``close`` after ``abort`` returned a path where no file was.
    """
    frame = _frames(1)[0]
    done = VideoWriter(tmp_path / "done.mp4", 7)
    assert done.ended is None
    done.write(frame)
    assert done.close() == tmp_path / "done.mp4" and done.ended == "closed"
    assert done.close() == tmp_path / "done.mp4"  # closing again does nothing more
    with pytest.raises(ValueError, match=r"^VideoWriter.write: video .*done.mp4 is closed already"):
        done.write(frame)
    done.abort()  # a finished file stays
    assert done.ended == "closed" and decode(tmp_path / "done.mp4")[1]
    empty = VideoWriter(tmp_path / "empty.mp4", 7)
    with pytest.raises(OSError, match="nothing was written"):
        empty.close()
    with pytest.raises(ValueError, match=r"empty.mp4 is aborted already \(nothing was written\)"):
        empty.write(frame)
    dropped = VideoWriter(tmp_path / "dropped.avi", 7)
    dropped.write(frame)
    dropped.abort()
    dropped.abort()  # twice: nothing more
    with pytest.raises(ValueError, match=r"^VideoWriter.close: video .*dropped.avi is aborted"):
        dropped.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["done.mp4"]


def test_output_keeps_the_umask(tmp_path: Path, umask: int) -> None:
    for name in ("v.mp4", "v.avi"):
        with VideoWriter(tmp_path / name, 7) as writer:
            writer.write(_frames(1)[0])
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o666 & ~umask


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"path": "v.mkv", "fps": 7}, "unsupported extension '.mkv'"),
        ({"path": "v.mp4", "fps": 0}, "fps is 0"),
        ({"path": "v.mp4", "fps": float("nan")}, "fps is nan"),
        ({"path": "v.avi", "fps": 7, "backend": "pyav"}, "writes .mp4"),
        ({"path": "v.mp4", "fps": 7, "backend": "gst"}, "backend is 'gst'"),
        ({"path": "v.mp4", "fps": 7, "preset": "quick"}, "preset is 'quick', expected one of"),
    ],
)
def test_bad_arguments_are_one_clear_error(
    tmp_path: Path, kwargs: dict[str, object], message: str
) -> None:
    kwargs = {**kwargs, "path": tmp_path / str(kwargs["path"])}
    with pytest.raises(ValueError, match=message):
        VideoWriter(**kwargs)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


def test_the_preset_trades_encoding_time_for_size(tmp_path: Path) -> None:
    frames = _frames(40, 120, 160)
    sizes = {}
    for preset in ("ultrafast", "medium"):
        with VideoWriter(tmp_path / f"{preset}.mp4", 10, preset=preset) as writer:
            for f in frames:
                writer.write(f)
        assert writer.preset == preset
        sizes[preset] = (tmp_path / f"{preset}.mp4").stat().st_size
        _, got = decode(tmp_path / f"{preset}.mp4")
        assert len(got) == 40 and np.abs(got[-1].astype(int) - frames[-1]).mean() < 6
    assert sizes["ultrafast"] > sizes["medium"]  # the same quality target, a larger file
    assert inspect.signature(VideoWriter).parameters["preset"].default == "ultrafast"


@pytest.mark.parametrize(("h", "w"), [(20, 32), (22, 34), (21, 33), (6, 10), (2, 2)])
def test_wrapped_planes_encode_the_bytes_of_copied_ones(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, h: int, w: int
) -> None:
    """``from_numpy_buffer`` (heights that are multiples of 4) writes ``from_ndarray``'s file."""
    import av

    def write(name: str) -> bytes:
        with VideoWriter(tmp_path / name, 7) as writer:
            for f in _frames(6, h, w):
                writer.write(f)
        return (tmp_path / name).read_bytes()

    wrapped = write("wrapped.mp4")
    monkeypatch.setattr(
        av.VideoFrame,
        "from_numpy_buffer",
        lambda array, format: av.VideoFrame.from_ndarray(array, format=format),
    )
    assert write("copied.mp4") == wrapped
    _, got = decode(tmp_path / "wrapped.mp4")
    assert len(got) == 6 and got[0].shape[:2] == (h + h % 2, w + w % 2)


@pytest.mark.parametrize(("w", "h"), [(16385, 8), (8, 16386), (20000, 64)])
def test_an_mp4_beyond_h264s_side_is_refused_in_one_line(tmp_path: Path, w: int, h: int) -> None:
    """x264 takes frames up to 16384 pixels a side. Was: PyAV's ExternalError ("Generic error in
    an external library: avcodec_open2(...)"), a traceback and exit status 1 for ``pftrack
    track panorama/ --render v.mp4`` of 20000x64 frames; the .avi (MJPG) takes them."""
    frame = np.zeros((h, w, 3), np.uint8)
    writer = VideoWriter(tmp_path / "v.mp4", 10)
    with pytest.raises(ValueError) as info:
        writer.write(frame)
    writer.abort()
    assert str(info.value) == (
        f"video {tmp_path / 'v.mp4'}: H.264 takes frames up to 16384 pixels a side (x264), not "
        f"{w + w % 2}x{h + h % 2}; write an .avi (Motion-JPEG) instead"
    )
    assert os.listdir(tmp_path) == []
    with VideoWriter(tmp_path / "v.avi", 10) as avi:  # the way out works
        avi.write(frame)
    frames = decode(tmp_path / "v.avi")[1]
    assert len(frames) == 1 and frames[0].shape == (h + h % 2, w + w % 2, 3)


@pytest.mark.parametrize(
    ("frame", "error", "message"),
    [
        (
            None,
            TypeError,
            r"^VideoWriter.write: frame is NoneType, expected a \(H, W, 3\) uint8 BGR array$",
        ),
        ([[[0, 0, 0]]], TypeError, r"^VideoWriter.write: frame is list, expected a NumPy"),
        (
            np.full((21, 33, 3), 0.8),
            TypeError,
            r"^VideoWriter.write: frame dtype is float64, expected uint8",
        ),
        (
            np.full((21, 33, 3), 4000, np.uint16),
            TypeError,
            r"^VideoWriter.write: frame dtype is uint16",
        ),
        (np.zeros((0, 0, 3), np.uint8), ValueError, r"^VideoWriter.write: frame is 0x0 pixels"),
    ],
    ids=["none", "list", "float", "uint16", "empty"],
)
@pytest.mark.parametrize("name", ["v.mp4", "v.avi"])
def test_a_frame_that_is_not_bgr_uint8_is_refused_not_cast(
    tmp_path: Path, name: str, frame: object, error: type[Exception], message: str
) -> None:
    """Was: a float frame of 0..1 written black and a 16-bit one wrapped modulo 256, without a
    word; None or a list an AttributeError ('list' object has no attribute 'ndim'); an empty
    frame OpenCV's assertion. Then each without the ``VideoWriter.write:`` its other errors
    have ("frame is list ...")."""
    with pytest.raises(error, match=message), VideoWriter(tmp_path / name, 7) as writer:
        writer.write(frame)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("crf", "error", "message"),
    [
        (-1, ValueError, r"^crf is -1, expected an integer in \[0, 51\]$"),
        (100, ValueError, r"^crf is 100, expected an integer in \[0, 51\]$"),
        (2.5, TypeError, r"^crf must be an integer in \[0, 51\], got float 2.5$"),
        ("x", TypeError, r"^crf must be an integer in \[0, 51\], got str 'x'$"),
        (True, TypeError, r"^crf must be an integer in \[0, 51\], got bool True$"),
        (float("inf"), TypeError, r"^crf must be an integer in \[0, 51\], got float inf$"),
    ],
)
def test_a_crf_outside_x264s_range_is_one_clear_error(
    tmp_path: Path, crf: object, error: type[Exception], message: str
) -> None:
    """Was: -1 and 100 written as given, 2.5 and True taken as 2 and 1, 'x' "invalid literal
    for int()", inf an OverflowError."""
    with pytest.raises(error, match=message):
        VideoWriter(tmp_path / "v.mp4", 7, crf=crf)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []
    with VideoWriter(tmp_path / "v.mp4", 7, crf=np.int64(51)) as writer:  # NumPy's ints too
        writer.write(_frames(1)[0])
    assert writer.crf == 51
