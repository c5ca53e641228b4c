"""Writing video files that play everywhere: H.264 MP4 through PyAV, OpenCV as the fallback.

Browsers play H.264 in MP4 with 4:2:0 chroma and even frame sizes; OpenCV's ``mp4v`` (MPEG-4
part 2) they do not. PyAV's wheels ship FFmpeg with libx264, so :class:`VideoWriter` encodes
with it when ``av`` is importable, with the ``moov`` index first (``faststart``: playback starts
before the download ends). Without PyAV it falls back to OpenCV's ``avc1`` encoder if the OpenCV
build has one, else ``mp4v``.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
from fractions import Fraction
from pathlib import Path
from types import TracebackType
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._check import bgr_frame, integer, option, path_arg, real
from pftrack._typing import PathLike, RealLike
from pftrack.io.atomic import atomic_path
from pftrack.io.opencv_io import opencv_name

__all__ = [
    "MAX_CRF",
    "MAX_H264_SIDE",
    "VIDEO_SUFFIXES",
    "RENDER_MARK",
    "X264_PRESETS",
    "VideoWriter",
    "check_frame_size",
    "is_render",
    "pyav_available",
]

VIDEO_SUFFIXES = (".mp4", ".avi")
#: Largest side of an H.264 frame that x264 encodes (pixels).
MAX_H264_SIDE = 16384
#: Largest x264 constant rate factor of 8-bit video (:class:`VideoWriter`'s `crf`, from 0).
MAX_CRF = 51
#: x264's frame threads of an ``.mp4`` (:class:`VideoWriter`): a fixed count, so that the file's
#: bytes do not depend on the machine's cores; for frames of at least `_X264_THREADS_FROM` rows.
_X264_THREADS = 2
_X264_THREADS_FROM = 360
#: x264's presets, fastest first (:class:`VideoWriter`'s `preset`).
X264_PRESETS = (
    "ultrafast", "superfast", "veryfast", "faster", "fast", "medium", "slow", "slower",
    "veryslow",
)  # fmt: skip


#: What every video :class:`VideoWriter` writes carries, so that a later run can tell it from a
#: user's video (:func:`is_render`): an MP4's ``comment`` tag; an AVI's header padding (the
#: ``JUNK`` chunk before ``movi``, which players skip), where FFmpeg's muxer leaves one.
RENDER_MARK = "pftrack render"
_AVI_HEAD = 1 << 16  # bytes of an AVI read for its header (FFmpeg's: about 6 KiB)


def _avi_padding(head: bytes) -> int | None:
    """Where the payload of the ``JUNK`` chunk just before an AVI's ``movi`` list begins."""
    movi = head.find(b"movi")
    junk = head.rfind(b"JUNK", 0, movi) if movi > 0 else -1
    if junk < 0:
        return None
    size = int.from_bytes(head[junk + 4 : junk + 8], "little")
    return junk + 8 if size >= len(RENDER_MARK) and junk + 8 + size <= movi else None


def _mark_avi(path: Path) -> None:
    """Write :data:`RENDER_MARK` into the AVI `path`'s header padding, if it has room for it."""
    with open(path, "r+b") as f:
        head = f.read(_AVI_HEAD)
        at = _avi_padding(head)
        if at is not None and not head[at : at + len(RENDER_MARK)].strip(b"\0"):
            f.seek(at)
            f.write(RENDER_MARK.encode())


def is_render(path: PathLike) -> bool:
    """Whether the video at `path` was written by pftrack (:class:`VideoWriter`, stop 67 on).

    The output checks replace an existing video only then (``--render``, ``pftrack render
    --out``): any other video there is the user's.
    """
    try:
        with open(path, "rb") as f:
            head = f.read(_AVI_HEAD)
        if head[:4] == b"RIFF" and head[8:12] == b"AVI ":
            at = _avi_padding(head)
            return at is not None and head[at : at + len(RENDER_MARK)] == RENDER_MARK.encode()
        if head[4:8] != b"ftyp" or not pyav_available():
            return False
        import av

        with av.open(os.fspath(path)) as container:
            return bool(container.metadata.get("comment") == RENDER_MARK)
    except Exception:  # unreadable, or not a video PyAV opens: not ours
        return False


def pyav_available() -> bool:
    """Whether PyAV (``import av``) can be used for H.264 output."""
    return importlib.util.find_spec("av") is not None


def check_frame_size(what: str, suffix: str, width: int, height: int) -> None:
    """Refuse frames of `width` x `height` that the encoder of a `suffix` video cannot take.

    An ``.mp4`` is H.264 (x264 through PyAV): up to :data:`MAX_H264_SIDE` pixels a side, the
    odd sides made even first. For a command to call before any work, naming the output as
    `what` (``"--render v.mp4"``); :class:`VideoWriter` calls it at its first frame.

    Raises
    ------
    ValueError
        Such a size (was PyAV's "Generic error in an external library: avcodec_open2", a
        traceback of ``pftrack track`` with exit status 1, for 20000x64 frames).
    """
    w, h = width + width % 2, height + height % 2
    if suffix == ".mp4" and max(w, h) > MAX_H264_SIDE:
        raise ValueError(
            f"{what}: H.264 takes frames up to {MAX_H264_SIDE} pixels a side (x264), not "
            f"{w}x{h}; write an .avi (Motion-JPEG) instead"
        )


class VideoWriter:
    """Write BGR uint8 frames to a video file, atomically.

    The file appears at `path` only when :meth:`close` succeeds; :meth:`abort` (or an exception
    inside a ``with`` block) leaves any earlier file at `path` untouched.

    Parameters
    ----------
    path : str or os.PathLike
        ``.mp4`` (H.264, yuv420p) or ``.avi`` (Motion-JPEG, through OpenCV).
    fps : float
        Frame rate written into the container.
    backend : {"pyav", "opencv"}, optional
        Default: PyAV for ``.mp4`` when installed, else OpenCV.
    crf : int
        x264 constant rate factor, 0 to :data:`MAX_CRF` (lower: better and larger; 23 is
        x264's default).
    preset : str
        x264 preset (:data:`X264_PRESETS`): how much encoding time buys a smaller file at the
        same quality. The default ``"ultrafast"`` keeps an annotated run fast: 795 PETS09-S2L1
        frames (480x360) cost 0.39 s of encoding CPU and 5.9 MB against 0.87 s and 2.6 MB with
        ``"veryfast"``, and ``pftrack track --render`` takes 2.4 s instead of 2.8 s on two
        cores. Pass ``"veryfast"`` or slower for a file to keep or share.

    Attributes
    ----------
    backend : str
        The encoder in use.
    codec : str
        ``"h264"``, ``"mp4v"`` or ``"mjpeg"``.
    n_frames : int
        Frames written so far.
    ended : {None, "closed", "aborted"}
        None while frames are taken; then whether the file was finished or removed.

    Notes
    -----
    H.264 with 4:2:0 chroma needs even width and height: odd frames get one replicated row or
    column at the bottom or right. All frames must have the size of the first. x264 takes up
    to :data:`MAX_H264_SIDE` pixels a side: a larger first frame is a ValueError.
    """

    def __init__(
        self,
        path: PathLike,
        fps: RealLike,
        *,
        backend: str | None = None,
        crf: int = 23,
        preset: str = "ultrafast",
    ) -> None:
        self.path = Path(path_arg(path, "VideoWriter: path"))
        suffix = self.path.suffix.lower()
        if suffix not in VIDEO_SUFFIXES:
            raise ValueError(
                f"video {self.path}: unsupported extension {suffix or '(none)'!r}, expected one "
                f"of {', '.join(VIDEO_SUFFIXES)}"
            )
        # any real number (a Fraction: PyAV's rates); text or None a TypeError naming it (was
        # NumPy's "ufunc 'isfinite' not supported", for a Fraction too)
        fps = real(fps, "fps", finite=False)  # named as passed (was "video frame rate")
        if not (np.isfinite(fps) and fps > 0):
            raise ValueError(f"fps is {fps}, expected a finite value > 0")
        option(preset, "preset", X264_PRESETS)
        if preset not in X264_PRESETS:
            raise ValueError(f"preset is {preset!r}, expected one of {', '.join(X264_PRESETS)}")
        if backend is None:
            backend = "pyav" if suffix == ".mp4" and pyav_available() else "opencv"
        option(backend, "backend", ("pyav", "opencv"))
        if backend not in ("pyav", "opencv"):
            raise ValueError(f"backend is {backend!r}, expected 'pyav' or 'opencv'")
        if backend == "pyav" and suffix != ".mp4":
            raise ValueError(f"backend 'pyav' writes .mp4, not {suffix}")
        self.backend = backend
        self.fps = float(fps)
        self.crf = integer(crf, "crf", 0, MAX_CRF)  # was int(crf): 2.5 as 2, -1 and 100 kept
        self.preset = preset
        self.codec = "h264" if backend == "pyav" else ("mjpeg" if suffix == ".avi" else "")
        self.n_frames = 0
        self._size: tuple[int, int] | None = None  # (height, width) of the input frames
        self._container: Any = None
        self._stream: Any = None
        self._cv: Any = None
        self._ended: str | None = None  # "closed" or "aborted": no frame is taken after it
        self._stack = contextlib.ExitStack()
        self._tmp: Path = self._stack.enter_context(atomic_path(self.path))

    def _open(self, height: int, width: int) -> None:
        self._size = (height, width)
        h, w = height + height % 2, width + width % 2
        if self.backend == "pyav":
            check_frame_size(f"video {self.path}", ".mp4", width, height)
            import av

            rate = Fraction(self.fps).limit_denominator(1001)
            self._container = av.open(
                str(self._tmp), mode="w", format="mp4", options={"movflags": "+faststart"}
            )
            self._container.metadata["comment"] = RENDER_MARK  # is_render's
            stream = self._container.add_stream("libx264", rate=rate)
            stream.width, stream.height, stream.pix_fmt = w, h, "yuv420p"
            stream.options = {"crf": str(self.crf), "preset": self.preset}
            # two x264 frame threads, fixed (never FFmpeg's count of the machine's cores): the
            # encode leaves the calling thread, which draws the next frame meanwhile (the render
            # worker was the crowd's critical path), for the CPU and the pictures of one thread
            # (the 1280x720 crowd and PETS09: every frame decodes equal); x264's settings string
            # says "threads=2", so the bytes are the same from run to run and machine to machine.
            # Only from 360 rows: frame threads bound the vertical motion vectors to about a
            # quarter of the height (x264's mv_range_thread), which binds on small frames (a
            # 101x75 scene: 13 of 40 frames differ, 40.7 dB). Sliced threads change the
            # pictures (37.9 dB median on the crowd) and FFmpeg's default count costs CPU
            # (795 PETS09 frames: 2.2 s against 1.45 s on one thread): docs/results.md, rend74
            stream.thread_count = _X264_THREADS if h >= _X264_THREADS_FROM else 1
            stream.thread_type = "FRAME"
            self._stream = stream
            return
        candidates = ("MJPG",) if self.path.suffix.lower() == ".avi" else ("avc1", "mp4v")
        # OpenCV's FFmpeg MJPG writer corrupts the heap on frames 2 or 6 pixels wide (the
        # process aborts, "double free or corruption", unless the height is a multiple of
        # 16): OpenCV's own MJPEG writer takes frames narrower than 8, wider ones as ever
        for fourcc in candidates:
            api = cv2.CAP_OPENCV_MJPEG if fourcc == "MJPG" and w < 8 else cv2.CAP_ANY
            with contextlib.suppress(cv2.error), opencv_name(self._tmp) as name:  # any name
                code = cv2.VideoWriter.fourcc(*fourcc)
                writer = cv2.VideoWriter(name, api, code, self.fps, (w, h))
                if writer.isOpened():
                    self._cv = writer
                    self.codec = {"MJPG": "mjpeg", "avc1": "h264"}.get(fourcc, fourcc)
                    return
                writer.release()
        raise ValueError(f"OpenCV cannot write video {self.path} (no encoder for {candidates})")

    def write(self, frame: NDArray[np.uint8]) -> None:
        """Append one BGR uint8 frame (H, W, 3).

        Raises
        ------
        TypeError
            `frame` is not a NumPy uint8 array (a float or 16-bit frame is not cast: it would
            come out black or wrapped modulo 256).
        ValueError
            `frame` is not (H, W, 3) with pixels, or not of the first frame's size; or the
            writer is closed or aborted.
        """
        self._refuse_if_ended("write")
        frame = bgr_frame(frame, "VideoWriter.write: frame")  # was "frame is list ...": no name
        if self._size is None:
            self._open(int(frame.shape[0]), int(frame.shape[1]))
        h, w = self._size if self._size is not None else (0, 0)
        if frame.shape[:2] != (h, w):
            raise ValueError(
                f"VideoWriter.write: frame {self.n_frames + 1} is {frame.shape[1]}x"
                f"{frame.shape[0]}, the video {w}x{h}"
            )
        image: NDArray[Any] = frame
        if h % 2 or w % 2:
            image = cv2.copyMakeBorder(frame, 0, h % 2, 0, w % 2, cv2.BORDER_REPLICATE)
        image = np.ascontiguousarray(image, dtype=np.uint8)
        if self._stream is not None:
            import av

            # to 4:2:0 by OpenCV (BT.601 limited range, as PyAV's swscale conversion of bgr24
            # gives it): write() takes 2.06 instead of 2.32 ms a 480x360 frame
            yuv = np.asarray(cv2.cvtColor(image, cv2.COLOR_BGR2YUV_I420), dtype=np.uint8)
            if h % 4 == 0:
                # the planes wrapped, not copied (a fresh array each frame, which the frame
                # keeps): the same bytes encoded, 0.3 ms of CPU less a 1280x720 frame. PyAV 18
                # reads a wrong height from an array of other heights (6 rows as 4)
                picture = av.VideoFrame.from_numpy_buffer(yuv, format="yuv420p")
            else:
                picture = av.VideoFrame.from_ndarray(yuv, format="yuv420p")
            for packet in self._stream.encode(picture):
                self._container.mux(packet)
        else:
            self._cv.write(image)
        self.n_frames += 1

    def close(self) -> Path:
        """Finish the file and move it to `path`; return `path`.

        Closing a closed writer again returns `path` and does nothing more.

        Raises
        ------
        OSError
            No frame was written.
        ValueError
            The writer was aborted (nothing is at `path`).
        """
        if self._ended == "closed":
            return self.path
        self._refuse_if_ended("close")
        try:
            self._finish()
        except BaseException as exc:
            self._ended = "aborted"  # the partial file is removed: nothing more to take
            self._stack.__exit__(type(exc), exc, exc.__traceback__)
            raise
        self._ended = "aborted"  # until the file is in place (none without a frame: OSError)
        self._stack.close()
        self._ended = "closed"
        return self.path

    @property
    def ended(self) -> str | None:
        """None while the writer takes frames; ``"closed"`` or ``"aborted"`` after."""
        return self._ended

    def _refuse_if_ended(self, what: str) -> None:
        """A ValueError naming `what` once the writer is closed or aborted.

        Was: ``write`` after ``close`` an AttributeError ('NoneType' object has no attribute
        'write'), or, after a ``close`` that found no frame, a new file left under its hidden
        temporary name; ``close`` after ``abort`` returned a path where nothing was.
        """
        if self._ended is not None:
            then = "" if self._ended == "closed" else " (nothing was written)"
            raise ValueError(
                f"VideoWriter.{what}: video {self.path} is {self._ended} already{then}; "
                "open a new VideoWriter for more frames"
            )

    def _finish(self) -> None:
        if self._stream is not None:
            for packet in self._stream.encode(None):
                self._container.mux(packet)
            self._stream = None
        if self._container is not None:
            self._container.close()
            self._container = None
        if self._cv is not None:
            self._cv.release()
            self._cv = None
            if self.codec == "mjpeg" and self._tmp.is_file():  # not a device written through
                _mark_avi(self._tmp)

    def abort(self) -> None:
        """Stop and delete the partial file; an earlier file at `path` stays as it was."""
        with contextlib.suppress(Exception):
            self._stream = None
            if self._container is not None:
                self._container.close()
            if self._cv is not None:
                self._cv.release()
        self._container = self._cv = None
        if self._ended != "closed":  # a finished file stays
            self._ended = "aborted"
        error = RuntimeError("video aborted")
        self._stack.__exit__(RuntimeError, error, None)

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()
