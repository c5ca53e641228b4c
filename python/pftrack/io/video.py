"""Frames from a video file, an image folder, a MOTChallenge sequence, a camera or a stream.

Sources, as :class:`FrameSource` takes them:

- a video file OpenCV can decode (a text file is refused, though FFmpeg would decode it as
  ANSI art: :data:`TEXT_FOURCC`);
- a folder of images, read in the order of the numbers in their names (``2.jpg`` before
  ``10.jpg``; decimals by value, ``10.15.png`` before ``10.2.png``: :func:`_natural_order`),
  frames 1..N in that order; names that skip numbers (``1.png, 6.png``) are read, and
  detections refused with them (:attr:`FrameSource.gap`); 16-bit images of 10- to 14-bit data
  are read at their depth (:attr:`FrameSource.bits`);
- a MOTChallenge sequence folder: ``seqinfo.ini`` gives the frame rate and the image folder
  (``imDir``, default ``img1``); ``det/det.txt`` (or ``det.txt``) is its public detection
  file. Integer image names (``000001.jpg``, the MOTChallenge convention) are frame numbers
  there, image 1 frame 1, and a missing one is refused rather than shifting every later
  frame. When the image folder does not exist and the sequence folder holds exactly one video
  file (``SEQ/video.mp4``: the layout of ``pftrack batch`` and the shared data), that video is
  read, with the sequence's frame rate and detections;
- a camera index (``"0"``), or a stream URL (anything with ``://``: ``rtsp://``, ``http://``,
  ``udp://``, ...), or a named pipe: *live* sources, read once, of unknown length.

The frame rate comes from the caller (``fps=``), else ``seqinfo.ini`` (beside a video file, in a
sequence folder or one level above its image folder), else the container header, else 25.
"""

from __future__ import annotations

import bisect
import configparser
import contextlib
import errno
import hashlib
import itertools
import math
import operator
import os
import re
import stat
import threading
from collections.abc import Callable, Collection, Generator, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any, BinaryIO, Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack import _stats
from pftrack._check import brief, number, path_arg, real, shown
from pftrack._text import counted, listed
from pftrack._threads import wait_through_interrupts
from pftrack._typing import PathLike, RealLike
from pftrack._warn import warn_outside
from pftrack.io.opencv_io import opencv_name, read_image, read_image_depth, utf8_name
from pftrack.io.packets import INTRA_FOURCCS, PACKET_PASS_MIN_PIXELS, intra_frames_at

__all__ = [
    "VIDEO_SUFFIXES",
    "FrameSequence",
    "FrameSource",
    "SequenceInfo",
    "check_source",
    "find_sequence",
    "image_files",
    "info_scale",
    "is_live_source",
    "natural_key",
    "read_frames",
    "read_seqinfo",
    "sequence_video",
    "source_files",
    "video_files",
]

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".webp")
#: The image formats of :data:`IMAGE_SUFFIXES` that may hold 16-bit pixels (PNG, TIFF).
DEEP_SUFFIXES = (".png", ".tif", ".tiff")
#: Extensions taken as video files when a folder is looked into (those of ``pftrack batch``).
VIDEO_SUFFIXES = (".avi", ".mp4", ".mkv", ".mov", ".m4v", ".mpg", ".mpeg", ".webm", ".wmv")
#: Containers whose header holds the number of frames (AVI's frame total, MP4's sample table):
#: OpenCV's count of any other (Matroska, WebM, MPEG streams) is FFmpeg's estimate from the
#: duration and the frame rate, which a variable frame rate puts off either way (a Matroska file
#: of 60 frames gave 53 and 276).
COUNTED_SUFFIXES = (".avi", ".mp4", ".mov", ".m4v")
DEFAULT_FPS = 25.0
#: The frame rates ``seqinfo.ini``'s ``frameRate`` may give, as ``pftrack track --fps`` (frames per
#: second): 1e9 wrote an MP4 at 1e9 fps, 0.001 made 100 frames a 28-hour video.
FRAME_RATE_RANGE = (0.01, 1000.0)
#: Largest ``imWidth`` / ``imHeight`` a ``seqinfo.ini`` may give (px), as ``pftrack eval``'s
#: ``--image-size``.
MAX_IMAGE_SIDE = 100_000
#: The codec FFmpeg's ``tty`` demuxer reports: it opens text files (``.txt``, ``.nfo``, ``.asc``,
#: ...) as ANSI art, 640x400 frames of rendered characters. A text file is not a video.
TEXT_FOURCC = "ansi"
#: Largest camera index (OpenCV's ``VideoCapture(index)`` takes a C int).
MAX_CAMERA_INDEX = 2**31 - 1
REPLAY_FRAMES = 64
"""Frames of a live source kept for a second pass (the tracker reads ahead to prime)."""


def _bit_depth(top: int) -> int:
    """The bit depth of 16-bit image data whose largest value is `top`: 8, 10, 12, 14 or 16.

    The fewest bits that hold `top`, rounded up to an even number (cameras give 10, 12 or 14
    bits; rounding up leaves room for brighter pixels than the images'): 4000 is 12 bits, 4096
    14, 255 8 (8-bit data in a 16-bit file).
    """
    bits = max(8, int(top).bit_length())
    return min(16, bits + bits % 2)


#: The images of a folder whose largest value decides the depth its 16-bit images are read at.
DEPTH_SAMPLE = 9


def _depth_sample(n: int) -> list[int]:
    """The indices of the images of an `n`-image folder that decide its depth (:func:`_bit_depth`).

    The first, then up to :data:`DEPTH_SAMPLE` - 1 others evenly spaced up to the last: a
    bounded cost whatever the folder's length, the same images on every read. 20 images:
    ``[0, 2, 5, 7, 10, 12, 14, 17, 19]``; 3 images: all three.
    """
    if n <= DEPTH_SAMPLE:
        return list(range(n))
    return sorted(
        {(k * (n - 1) + (DEPTH_SAMPLE - 1) // 2) // (DEPTH_SAMPLE - 1) for k in range(DEPTH_SAMPLE)}
    )


#: Frames whose time stamps :func:`_stamped_rate` reads.
STAMPED_FRAMES = 25


def _stamped_rate(path: Path) -> float | None:
    """A video's frame rate from its first frames' time stamps, when its header has none.

    The median step between the time stamps of up to :data:`STAMPED_FRAMES` frames (grabbed:
    decoded, not converted). OpenCV reports a Matroska file's time base as its rate when the
    file says none (1000 "fps"), and 0 for a raw stream: a render of such a video played at
    25 fps whatever its real rate (a variable-rate file of about 9 fps: 2.8 times too fast).
    None when fewer than two frames have increasing stamps, or the rate is not in (0, 1000).
    """
    cap = _file_capture(str(path))
    stamps: list[float] = []
    try:
        while len(stamps) < STAMPED_FRAMES and cap.grab():
            stamps.append(float(cap.get(cv2.CAP_PROP_POS_MSEC)))
    finally:
        cap.release()
    steps = np.diff(stamps)
    steps = steps[np.isfinite(steps) & (steps > 0)]
    if len(steps) == 0:
        return None
    rate = 1000.0 / _stats.median(steps)
    return rate if 0 < rate < 1000 else None


#: A step between two frames' time stamps more than this share off the median step (and more
#: than :data:`UNEVEN_MS`) is uneven; :func:`_uneven_steps`.
UNEVEN_STEP = 0.25
#: Milliseconds a step may be off the median in any case (stamps in whole milliseconds: a
#: 29.97 fps video's steps are 33 and 34 ms).
UNEVEN_MS = 1.5
#: The share of uneven steps that makes a variable frame rate (one dropped frame in 40 does not).
UNEVEN_SHARE = 0.05
#: Frames whose time stamps are first looked at for a variable frame rate while a video is read
#: (:meth:`FrameSource._warn_uneven`), then twice as many, and so on: said a few seconds in, not
#: once the whole file was read (at 50, 100, 200, ... frames: a bounded cost, the same rule).
UNEVEN_FIRST_CHECK = 50


def _uneven_steps(stamps: Sequence[float]) -> tuple[float, float, float] | None:
    """The smallest, median and largest steps (ms) between `stamps` if they are clearly uneven.

    The steps between consecutive increasing stamps (a decoder's last frames, flushed, may say
    0: PETS09's) are uneven when more than :data:`UNEVEN_SHARE` of them are more than
    :data:`UNEVEN_STEP` of the median step off it (and more than :data:`UNEVEN_MS`): a
    variable-frame-rate video's (a phone's: 100 and 200 ms), not a constant rate in whole
    milliseconds nor one frame dropped now and then. None otherwise, and with fewer than 10
    steps.
    """
    steps = np.diff(np.asarray(stamps, dtype=np.float64))
    steps = steps[np.isfinite(steps) & (steps > 0)]
    if len(steps) < 10:
        return None
    median = _stats.median(steps)
    off = np.abs(steps - median) > max(UNEVEN_STEP * median, UNEVEN_MS)
    if np.count_nonzero(off) <= UNEVEN_SHARE * len(steps):
        return None
    return float(steps.min()), median, float(steps.max())


def _import_av() -> Any:
    """PyAV (``import av``), or None where it cannot be imported."""
    try:
        import av
    except ImportError:
        return None
    return av


def _video_streams(path: Path) -> list[str]:
    """The video streams of file `path` as ``#1 (h264 1920x1080)``, in the file's order.

    From its container's header, through PyAV (a pftrack dependency, with FFmpeg as OpenCV's;
    OpenCV itself says neither how many there are nor which it reads: it opens no file with
    ``CAP_PROP_VIDEO_STREAM`` set, and reads the first video stream). Cover art (an attached
    picture) is no stream of frames. A stream in a codec FFmpeg does not know (PyAV gives it no
    codec context) is ``#1 (a codec FFmpeg does not know)``. Empty where PyAV is missing or
    cannot open the file.
    """
    av = _import_av()
    if av is None:
        return []

    def said(stream: Any) -> str:
        codec = stream.codec_context
        if codec is None:  # was: an AttributeError out of FrameSource
            return f"#{stream.index} (a codec FFmpeg does not know)"
        return f"#{stream.index} ({codec.name} {codec.width}x{codec.height})"

    try:
        with av.open(str(path)) as container:
            return [
                said(s)
                for s in container.streams.video
                if not s.disposition & av.stream.Disposition.attached_pic
            ]
    except (av.FFmpegError, OSError, ValueError):
        return []


def _starts_without_key_frame(path: Path) -> bool:
    """Whether the first video stream of file `path` begins with a packet that is no key frame.

    As a recording cut from a live stream does (an MPEG-TS saved from a broadcast or a camera's
    feed, ``ffmpeg -c copy`` started between key frames): FFmpeg cannot decode the frames
    before the first key frame and leaves them out without a word. One packet read through
    PyAV; False where PyAV is missing or cannot read the file, and for an AVI, without PyAV:
    its stamps are its frames' places in the file (from its index, which counts every frame
    it holds), late by a decoder's delay with B-frames (PETS09's first, 200 ms), not a live
    stream's time line.
    """
    try:
        with path.open("rb") as fh:
            head = fh.read(12)
    except OSError:
        return False
    av = _import_av() if not (head[:4] == b"RIFF" and head[8:12] == b"AVI ") else None
    if av is None:
        return False
    try:
        with av.open(str(path)) as container:
            if not container.streams.video:
                return False
            for packet in container.demux(container.streams.video[0]):
                if packet.size:  # not the empty packet that ends a demux
                    return not packet.is_keyframe
    except (av.FFmpegError, OSError, ValueError):
        pass
    return False


#: Box types an ISO base media file (MP4, MOV, M4V, 3GP) may begin with: its header is read by
#: :func:`_header_video_count`, without PyAV.
ISO_FIRST_BOXES = (b"ftyp", b"styp", b"moov", b"mdat", b"free", b"skip", b"wide", b"pnot", b"uuid")
#: AVI stream types (``strh`` ``fccType``) FFmpeg reads as video: ``vids``, and DV (``iavs``,
#: ``ivas``: one video stream, its sound inside it).
AVI_VIDEO_TYPES = (b"vids", b"iavs", b"ivas")
#: Most boxes or chunks :func:`_header_video_count` walks in one list before it gives up (a
#: header holds a few dozen: a bounded cost whatever the file).
HEADER_ITEMS = 10_000


class _BadHeader(Exception):
    """A container header :func:`_header_video_count` cannot read: damaged or cut short."""


def _iso_boxes(fh: BinaryIO, start: int, end: int) -> Iterator[tuple[bytes, int, int]]:
    """The boxes of an ISO base media file between bytes `start` and `end`: (type, body, end).

    A box's size is its first 4 bytes (big-endian), else (1) the 8 after its type, else (0) up
    to `end`. Raises :class:`_BadHeader` at a box smaller than its header or past `end`.
    """
    pos = start
    for _ in range(HEADER_ITEMS):
        if pos + 8 > end:
            return
        fh.seek(pos)
        head = fh.read(16)
        size, kind, body = int.from_bytes(head[:4], "big"), head[4:8], pos + 8
        if size == 1:
            size, body = int.from_bytes(head[8:16], "big"), pos + 16
        elif size == 0:
            size = end - pos
        if len(head) < body - pos or size < body - pos or pos + size > end:
            raise _BadHeader(f"box {kind!r} at byte {pos}")
        yield kind, body, pos + size
        pos += size
    raise _BadHeader(f"more than {HEADER_ITEMS} boxes")


def _iso_field(fh: BinaryIO, body: int, end: int, size: int) -> bytes:
    """The first `size` bytes of the box whose body is bytes `body` to `end` of `fh`."""
    if end - body < size:
        raise _BadHeader(f"a box of {end - body} bytes at byte {body}, expected {size}")
    fh.seek(body)
    return fh.read(size)


def _iso_video_count(fh: BinaryIO, size: int) -> int:
    """The video tracks of an ISO base media file (MP4, MOV), from its ``moov`` box.

    Each ``trak`` whose ``mdia`` ``hdlr`` says ``vide``, less the tracks another names as its
    chapter images (``tref`` ``chap``: FFmpeg's cover art). The top-level boxes are stepped
    over by their sizes to ``moov`` (at the end of a file written in one pass), and in it only
    the few boxes needed are read (not its sample tables). Raises :class:`_BadHeader` without
    a ``moov``.
    """
    for kind, body, end in _iso_boxes(fh, 0, size):
        if kind != b"moov":
            continue
        video: list[int] = []  # the video tracks' IDs
        chapters: set[int] = set()
        for trak, trak_body, trak_end in _iso_boxes(fh, body, end):
            if trak != b"trak":
                continue
            track, handler = -1, b""
            for box, box_body, box_end in _iso_boxes(fh, trak_body, trak_end):
                if box == b"tkhd":  # version, flags, 2 times (4 or 8 bytes each), track ID
                    at = 20 if _iso_field(fh, box_body, box_end, 1) == b"\1" else 12
                    track = int.from_bytes(_iso_field(fh, box_body, box_end, at + 4)[at:], "big")
                elif box == b"tref":
                    for ref, ref_body, ref_end in _iso_boxes(fh, box_body, box_end):
                        if ref == b"chap":
                            ids = _iso_field(fh, ref_body, ref_end, (ref_end - ref_body) & ~3)
                            chapters.update(
                                int.from_bytes(ids[i : i + 4], "big") for i in range(0, len(ids), 4)
                            )
                elif box == b"mdia":  # hdlr: version, flags, pre_defined, handler_type
                    for sub, sub_body, sub_end in _iso_boxes(fh, box_body, box_end):
                        if sub == b"hdlr":
                            handler = _iso_field(fh, sub_body, sub_end, 12)[8:]
            if handler == b"vide":
                video.append(track)
        return sum(1 for track in video if track not in chapters)
    raise _BadHeader("no moov box")


def _iso_without_index(path: Path) -> bool:
    """Whether `path` is an ISO base media file (MP4, MOV) with media data but no ``moov`` box.

    The index of a file written in one pass comes last: a recording stopped before it was
    finished (a camera or OBS killed, ffmpeg without its trailer, a copy cut short) holds its
    frames in ``mdat`` and nothing that says where they are, which no player reads. Only the
    top-level boxes' headers are read; any other file, or one that cannot be read, is False.
    """
    kinds: set[bytes] = set()
    try:
        with path.open("rb") as fh:
            size, pos = fh.seek(0, os.SEEK_END), 0
            for _ in range(HEADER_ITEMS):
                if pos + 8 > size:
                    break
                fh.seek(pos)
                head = fh.read(16)
                box, kind = int.from_bytes(head[:4], "big"), head[4:8]
                if pos == 0 and kind not in ISO_FIRST_BOXES:
                    return False
                kinds.add(kind)
                if box == 1 and len(head) == 16:
                    box = int.from_bytes(head[8:16], "big")
                if box < 8:  # 0: up to the end of the file; less: damaged
                    break
                pos += box
    except OSError:
        return False
    return b"mdat" in kinds and b"moov" not in kinds


def _riff_chunks(fh: BinaryIO, start: int, end: int) -> Iterator[tuple[bytes, bytes, int, int]]:
    """The chunks of a RIFF file between bytes `start` and `end`: (id, first 4 bytes, body, end).

    The first 4 bytes of a ``LIST`` are its type (``hdrl``, ``strl``), of a ``strh`` its stream's
    (``vids``); empty for a chunk of fewer. Raises :class:`_BadHeader` at an id that is not text
    (:func:`_printable_id`) or a chunk past `end`.
    """
    pos = start
    for _ in range(HEADER_ITEMS):
        if pos + 8 > end:
            return
        fh.seek(pos)
        head = fh.read(12)
        chunk_id, length = head[:4], int.from_bytes(head[4:8], "little")
        if not _printable_id(chunk_id) or pos + 8 + length > end:
            raise _BadHeader(f"chunk {chunk_id!r} at byte {pos}")
        yield chunk_id, head[8:12] if length >= 4 else b"", pos + 8, pos + 8 + length
        pos += 8 + length + (length & 1)
    raise _BadHeader(f"more than {HEADER_ITEMS} chunks")


def _avi_video_count(fh: BinaryIO, size: int) -> int:
    """The video streams of an AVI file, from its ``hdrl`` list.

    The ``strl`` lists whose ``strh`` says video (:data:`AVI_VIDEO_TYPES`). The RIFF list is
    taken to end where the file does (as :func:`_avi_break` takes it: a file being recorded may
    say 0 bytes). Raises :class:`_BadHeader` without an ``hdrl``.
    """
    for chunk_id, kind, body, end in _riff_chunks(fh, 12, size):
        if chunk_id != b"LIST" or kind != b"hdrl":
            continue
        count = 0
        for strl_id, strl, strl_body, strl_end in _riff_chunks(fh, body + 4, end):
            if strl_id == b"LIST" and strl == b"strl":
                count += any(
                    inner == b"strh" and stream in AVI_VIDEO_TYPES
                    for inner, stream, _, _ in _riff_chunks(fh, strl_body + 4, strl_end)
                )
        return count
    raise _BadHeader("no hdrl list")


def _header_video_count(path: Path) -> int | None:
    """The video streams of an MP4, MOV or AVI file, read from its header without PyAV.

    Importing PyAV costs 0.05-0.1 s, 3-5 % of a whole ``pftrack track`` run on PETS09; this
    reads a few KB (:func:`_iso_video_count`, :func:`_avi_video_count`), as many as PyAV counts
    (cover art left out). The container is told by the file's first bytes, not its name.

    Returns
    -------
    int or None
        None for another container (Matroska, WebM, MPEG-TS, ...): PyAV tells.

    Raises
    ------
    _BadHeader
        A damaged or truncated header.
    OSError
        The file cannot be read.
    """
    with path.open("rb") as fh:
        size = os.fstat(fh.fileno()).st_size
        head = fh.read(12)
        if head[:4] == b"RIFF" and head[8:12] == b"AVI ":
            return _avi_video_count(fh, size)
        if head[4:8] in ISO_FIRST_BOXES:
            return _iso_video_count(fh, size)
    return None


def _several_video_streams(path: Path) -> list[str]:
    """The video streams of file `path` (:func:`_video_streams`) if it holds several, else [].

    An MP4, MOV or AVI file's header says how many without PyAV (:func:`_header_video_count`),
    which then lists them only when there are several; a damaged header says nothing, as
    PyAV's failure to open a file does.
    """
    try:
        count = _header_video_count(path)
    except (_BadHeader, OSError):
        return []
    if count is not None and count < 2:
        return []
    streams = _video_streams(path)
    return streams if len(streams) > 1 else []


def _file_capture(path: str) -> cv2.VideoCapture:
    """A ``cv2.VideoCapture`` of a stored video file whose decoder runs on the calling thread.

    OpenCV's FFmpeg backend otherwise adds decoding threads (one per CPU). Measured on PETS09
    (H.264) and TUD-Campus (MPEG-4), same pixels either way: a pass that only decodes (the
    spread bootstrap's) gains nothing from them and takes 15-20 % more CPU and wall time
    (PETS09: 0.29 against 0.38 s); in ``track_path(threads=False)`` they overlap decoding with
    tracking, 0.1-0.15 s less wall time for 0.2-0.3 s more CPU, which pays only on an idle
    core; ``pftrack track`` decodes on a thread of its own already (:mod:`pftrack.io.prefetch`)
    beside the detector's and the tracker's, and a ``pftrack batch`` worker has one core. Falls
    back to OpenCV's default backend choice if FFmpeg cannot open the file.
    """
    with opencv_name(path) as name:  # any file name (opencv_io); OpenCV keeps its own handle
        cap = cv2.VideoCapture(name, cv2.CAP_FFMPEG, [cv2.CAP_PROP_N_THREADS, 1])
        if cap.isOpened():
            return cap
        cap.release()
        return cv2.VideoCapture(name)


def _fourcc(cap: cv2.VideoCapture) -> str:
    """The four-character code of the codec `cap` decodes (``"FMP4"``, ``"H264"``, ``"ansi"``)."""
    code = int(cap.get(cv2.CAP_PROP_FOURCC)) & 0xFFFFFFFF
    return code.to_bytes(4, "little").decode("latin-1")


#: What :meth:`FrameSource.frames_at` makes of each frame it keeps (``prepare``).
_Prepare = Callable[[NDArray[np.uint8]], NDArray[np.uint8]]


def _as_read(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """`frame` itself: :meth:`FrameSource.frames_at` without a ``prepare``."""
    return frame


def _frame_digest(frame: NDArray[Any]) -> bytes:
    """A digest of `frame`'s shape, type and pixels: what :func:`_same_frames` compares.

    Kept instead of the frame itself, which at 4K is 25 MB (a split pass held four).
    """
    digest = hashlib.blake2b(repr((frame.shape, frame.dtype.str)).encode())
    digest.update(np.ascontiguousarray(frame).data)
    return digest.digest()


def _same_frames(a: list[tuple[bytes, float]], b: list[tuple[bytes, float]]) -> bool:
    """Whether two reads gave the same frames: the same pixels and the same time stamps.

    The frames by their :func:`_frame_digest`.
    """
    return len(a) == len(b) and all(
        ta == tb and fa == fb for (fa, ta), (fb, tb) in zip(a, b, strict=True)
    )


#: How far before the frame asked for OpenCV's FFmpeg reader starts a seek
#: (``CAP_PROP_POS_FRAMES``): it seeks to the key frame at or before that many frames earlier
#: and grabs forward, so a seek to a key frame plus this many frames decodes the fewest frames
#: twice (OpenCV's ``cap_ffmpeg_impl.hpp``; a wrong guess costs time only: the split pass
#: checks its halves' frames).
SEEK_BACK = 16


def _key_frames(path: str, n_frames: int) -> list[int] | None:
    """0-based indexes of the key frames of a video file, read from its packets, not decoded.

    OpenCV's raw mode (``CAP_PROP_FORMAT`` -1) hands out the packets, and
    ``CAP_PROP_LRF_HAS_KEY_FRAME`` says which hold a key frame: 0.012 s of CPU for PETS09's
    795 packets (key frames 0, 250, 500, 750). None when the reader has no raw mode, when
    there are not `n_frames` packets (not one a frame, so their positions are not the
    frames'), or when the first packet is not a key frame.
    """
    cap = _file_capture(path)
    keys: list[int] = []
    n = 0
    try:
        if not cap.set(cv2.CAP_PROP_FORMAT, -1):
            return None
        while n <= n_frames and cap.grab():
            if cap.get(cv2.CAP_PROP_LRF_HAS_KEY_FRAME):
                keys.append(n)
            n += 1
    except cv2.error:
        return None
    finally:
        cap.release()
    return keys if n == n_frames and keys[:1] == [0] else None


def _split_point(n_frames: int, middle: int, keys: Sequence[int] | None) -> int:
    """Where the second half of a split pass starts (:meth:`FrameSource.frames_at`).

    The first half reads frames 0 to the point and one more (to check that the halves agree);
    the second half seeks to the point, which decodes from the key frame at or before
    :data:`SEEK_BACK` frames earlier, and reads on to the end. Of `middle` (the middle chosen
    frame) and each key frame plus :data:`SEEK_BACK`, the point whose longer half decodes the
    fewest frames, then the fewest in all; `middle` without `keys`. PETS09 (795 frames, key
    frames 0, 250, 500, 750): 516, halves of 518 and 295 frames, against 413 and 545 from its
    middle chosen frame 411 (the second half decoding frames 250-410 twice).
    """
    if not keys:
        return middle

    def cost(point: int) -> tuple[int, int]:
        start = keys[max(bisect.bisect_right(keys, point - SEEK_BACK) - 1, 0)]
        first, second = point + 2, n_frames - start
        return max(first, second), first + second

    points = [middle] + [k + SEEK_BACK for k in keys if 2 <= k + SEEK_BACK <= n_frames - 2]
    return min(points, key=cost)


def natural_key(name: str) -> tuple[tuple[int, int | str], ...]:
    """Sort key that orders the digit runs of `name` as numbers: ``9.jpg < 10.jpg``.

    Image folders written by tools that do not zero-pad frame numbers (``1.jpg, 2.jpg, ...,
    10.jpg``) would otherwise be read as 1, 10, 11, ..., 2, silently scrambling the video.
    """
    return tuple(
        (0, int(part)) if part.isdigit() else (1, part.lower())
        for part in re.split(r"(\d+)", name)
        if part
    )


@dataclass(frozen=True)
class SequenceInfo:
    """The ``[Sequence]`` section of a MOTChallenge ``seqinfo.ini``.

    Attributes
    ----------
    folder : Path
        The sequence folder (the one holding ``seqinfo.ini``).
    name : str
        ``name`` (default: the folder's name).
    frame_rate : float or None
        ``frameRate``, frames per second.
    image_dir : str
        ``imDir`` (default ``img1``).
    width, height : int or None
        ``imWidth``, ``imHeight``: the image size the ground truth is given in.
    length : int or None
        ``seqLength``, frames.
    """

    folder: Path
    name: str
    frame_rate: float | None
    image_dir: str
    width: int | None
    height: int | None
    length: int | None

    @property
    def detections(self) -> Path | None:
        """``det/det.txt`` (or ``det.txt``) of the sequence, if it exists."""
        for path in (self.folder / "det" / "det.txt", self.folder / "det.txt"):
            if path.is_file():
                return path
        return None


def info_scale(
    frame_size: tuple[int, int], info_size: tuple[int | None, int | None], where: object
) -> float:
    """The factor from a sequence's ``seqinfo.ini`` pixels to its frames' pixels.

    MOTChallenge detection and ground-truth boxes are given in ``imWidth`` x ``imHeight``
    pixels; frames of another size (a re-encoded or downscaled video) take them scaled by
    the width's ratio, which must be the height's too: one factor cannot map boxes onto frames
    of another shape.

    Parameters
    ----------
    frame_size : (width, height)
        The frames' size.
    info_size : (imWidth, imHeight)
        ``seqinfo.ini``'s size (None where it is not given: the width alone decides).
    where : object
        The ``seqinfo.ini`` (or sequence) named in the error.

    Returns
    -------
    float
        ``width / imWidth`` (1.0 without an ``imWidth``).

    Raises
    ------
    ValueError
        The two ratios differ by more than 1 % (a 4:3 sequence stored as 16:9, for instance).
    """
    (w, h), (iw, ih) = frame_size, info_size
    if not iw:
        return 1.0
    sx = w / iw
    if ih and abs(sx * ih - h) > 0.01 * h:
        raise ValueError(
            f"{where}: the frames are {w}x{h} but seqinfo.ini says {iw}x{ih}, another shape "
            f"(x{sx:.4g} across, x{h / ih:.4g} down), so its boxes cannot be scaled onto the "
            "frames by one factor: give frames of seqinfo.ini's shape, or the boxes' scale "
            "yourself (pftrack track --det-scale)"
        )
    return float(sx)


def _ini_text(ini: Path) -> str:
    """The text of ``seqinfo.ini`` `ini`, in the encoding MOT files are read in.

    UTF-16 by its byte-order mark (Windows PowerShell 5's ``>`` and ``Out-File``; was refused
    as "expected a [Sequence] section", while the sequence's det.txt and gt.txt so written were
    read), else UTF-8 with a byte-order mark skipped (Notepad). A file that is not UTF-8 is
    read as Windows-1252 (Notepad's "ANSI", Latin-1 but for 0x80-0x9f), else as Latin-1, which
    takes any byte: ``imDir=café`` saved so names the folder ``café`` (was: undecodable bytes
    replaced, so the folder was "caf\ufffd", which "does not exist", beside ``café``).
    OSError as reading raises it.
    """
    from pftrack.io.mot import _encoding

    data = ini.read_bytes()
    encoding = _encoding(data[:4])
    for tried in (encoding, "cp1252", "latin-1"):
        try:
            return data.decode(tried)
        except UnicodeDecodeError:
            if encoding != "utf-8-sig":  # UTF-16 by its mark: no other reading
                return data.decode(encoding, errors="replace")
    raise AssertionError("latin-1 decodes every byte")  # pragma: no cover


def _duplicate(
    ini: Path, exc: configparser.DuplicateOptionError | configparser.DuplicateSectionError
) -> str:
    """The message of a key or section `ini` gives twice, with the lines it is on.

    configparser gives the line of the second one only (and the key in lower case): the file is
    read again to find the first and the key as written.
    """
    option = getattr(exc, "option", None)  # None: a section given twice
    section: str | None = None
    lines: list[int] = []
    written = option
    try:
        text = _ini_text(ini).splitlines()
    except OSError:
        text = []
    for at, line in enumerate(text[: exc.lineno], start=1):
        stripped = line.strip()
        if stripped.startswith("[") and "]" in stripped:
            section = stripped[1 : stripped.index("]")]
            if option is None and section == exc.section:
                lines.append(at)
        elif option is not None and section == exc.section:
            key = re.split(r"[=:]", stripped, maxsplit=1)[0].strip()
            if key.lower() == option:
                written = key if not lines else written  # as written the first time
                lines.append(at)
    where = f"lines {lines[0]} and {lines[-1]}" if len(lines) > 1 else f"line {exc.lineno}"
    what = f"section [{exc.section}]" if option is None else f"key {written} in [{exc.section}]"
    return f"{ini}: {what} is given twice ({where}); give it once"


#: The keys of ``seqinfo.ini``'s ``[Sequence]`` that :func:`read_seqinfo` reads.
SEQINFO_KEYS = ("name", "imDir", "frameRate", "seqLength", "imWidth", "imHeight")


def _key_names(keys: object) -> tuple[str, ...]:
    """:func:`read_seqinfo`'s `keys` as a tuple of str; TypeError naming what is not one.

    Was: a str taken for its letters (``keys has 'W', 'd', ...``), and Python's "'bool' object
    is not iterable" or "unhashable type: 'list'".
    """
    if isinstance(keys, str):
        raise TypeError(
            f"read_seqinfo: keys must be a collection of key names (keys=[{brief(keys)}] for one), "
            f"got {shown(keys)}"
        )
    if isinstance(keys, bytes) or not isinstance(keys, Iterable):
        raise TypeError(f"read_seqinfo: keys must be a collection of key names, got {shown(keys)}")
    names = tuple(keys)
    for k, name in enumerate(names):
        if not isinstance(name, str):
            raise TypeError(
                f"read_seqinfo: keys[{k}] must be a str (a key name), got {shown(name)}"
            )
    return names


def read_seqinfo(path: PathLike, *, keys: Collection[str] | None = None) -> SequenceInfo:
    """Read a MOTChallenge ``seqinfo.ini`` (or the one in folder `path`).

    A key left out takes its default (``name``: the folder's name, ``imDir``: ``img1``; the
    numbers: unknown); a key given with an empty value (``frameRate=``) is an error, as one
    of ``0`` is: it would otherwise fall back silently (the container's frame rate for an
    empty ``frameRate``).

    Parameters
    ----------
    path : path-like
        The file, or the folder holding it.
    keys : collection of str, optional
        The keys the caller uses (some of :data:`SEQINFO_KEYS`); the others are neither read
        nor checked, and take their default as if left out, so that a value the caller does
        not use (``frameRate=0`` for ``pftrack eval``, which needs only the image size and
        length) does not refuse the file. None: all of them.

    Raises
    ------
    ValueError
        No ``[Sequence]`` section, a key or section given twice, a key pftrack reads given
        empty, a field that is not a positive number (``imWidth``, ``imHeight``,
        ``seqLength``: an integer), or a ``frameRate`` outside :data:`FRAME_RATE_RANGE`;
        a name in `keys` that is not one of :data:`SEQINFO_KEYS`.
    TypeError
        `path` is not a str or os.PathLike (bytes are decoded); `keys` is not a collection of
        str (one name given as a str, whose letters were taken for names).
    """
    if keys is not None:
        keys = _key_names(keys)
    unknown = sorted(set(keys or ()) - set(SEQINFO_KEYS))
    if unknown:
        raise ValueError(
            f"read_seqinfo: keys has {', '.join(map(repr, unknown))}, expected some of "
            f"{', '.join(SEQINFO_KEYS)}"
        )
    ini = Path(path_arg(path, "read_seqinfo: path"))
    if ini.is_dir():
        ini = ini / "seqinfo.ini"
    parser = configparser.ConfigParser(interpolation=None)
    try:
        text = _ini_text(ini)
    except IsADirectoryError:  # was "cannot be read (Is a directory)", or passed over unsaid
        raise ValueError(
            f"{ini}: is a folder, expected the sequence's seqinfo.ini text file ([Sequence] with "
            "frameRate, imWidth, ...): rename or remove that folder"
        ) from None
    except OSError as exc:
        raise ValueError(f"{ini}: cannot be read ({exc.strerror})") from None
    try:
        parser.read_string(text, source=str(ini))
        sec = parser["Sequence"]
    except (configparser.DuplicateOptionError, configparser.DuplicateSectionError) as exc:
        raise ValueError(_duplicate(ini, exc)) from None
    except (configparser.Error, KeyError):
        raise ValueError(
            f"{ini}: expected a [Sequence] section (MOTChallenge seqinfo.ini)"
        ) from None

    def text_of(key: str) -> str | None:
        if keys is not None and key not in keys:
            return None  # not used by the caller: not checked either
        text = sec.get(key)
        if text is not None and not text.strip():
            raise ValueError(f"{ini}: {key} is empty; give a value or leave the key out")
        return text

    def number(key: str) -> float | None:
        text = text_of(key)
        if text is None:
            return None
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{ini}: {key} is {brief(text)}, expected a number > 0")
        return value

    def integer(key: str, limit: int) -> int | None:
        value = number(key)
        # not an integer was rounded: 0.4 to 0, an absent size; 1e300 was taken
        if value is not None and not (value.is_integer() and value <= limit):
            raise ValueError(
                f"{ini}: {key} is {sec[key].strip()!r}, expected an integer in 1..{limit}"
            )
        return None if value is None else int(value)

    frame_rate = number("frameRate")
    lo, hi = FRAME_RATE_RANGE
    if frame_rate is not None and not lo <= frame_rate <= hi:
        raise ValueError(
            f"{ini}: frameRate is {sec['frameRate'].strip()!r}, expected a frame rate in "
            f"[{lo:g}, {hi:g}] frames per second"
        )
    return SequenceInfo(
        folder=ini.parent,
        name=text_of("name") or ini.parent.name,
        frame_rate=frame_rate,
        image_dir=text_of("imDir") or "img1",
        width=integer("imWidth", MAX_IMAGE_SIDE),
        height=integer("imHeight", MAX_IMAGE_SIDE),
        length=integer("seqLength", 2**31 - 1),
    )


def _has_seqinfo(folder: Path) -> bool:
    """Whether `folder` holds anything named ``seqinfo.ini``.

    A file, or a folder or a broken link by that name, which :func:`read_seqinfo` then refuses
    naming it (was: passed over as if there were none, the sequence's frame rate and size
    unsaid and unused).
    """
    return os.path.lexists(folder / "seqinfo.ini")


def find_sequence(source: PathLike) -> SequenceInfo | None:
    """The MOTChallenge sequence `source` belongs to, from the ``seqinfo.ini`` nearest to it.

    Looks in `source` itself (a sequence folder), beside it (a video file, or an image folder
    inside the sequence folder), in that order. Without one, a folder laid out as a sequence's,
    ``SEQ/img1/`` (`source` is ``SEQ`` or ``SEQ/img1``), is that sequence all the same, with
    nothing known but its name and image folder (no frame rate, size or length), as ``pftrack
    batch`` takes it: its ``det/det.txt`` is its detections, and its images are frame numbers.
    None otherwise.
    """
    path = Path(source)
    if not path.is_dir():
        return read_seqinfo(path.parent) if _has_seqinfo(path.parent) else None
    for folder in (path, path.parent):
        if _has_seqinfo(folder):
            return read_seqinfo(folder)
    real = Path(os.path.realpath(path))
    if (path / "img1").is_dir():
        return SequenceInfo(path, real.name, None, "img1", None, None, None)
    if real.name == "img1":  # SEQ/img1, or "." inside it
        folder = path.parent if path.name == "img1" else real.parent
        return SequenceInfo(folder, real.parent.name, None, "img1", None, None, None)
    return None


#: The RIFF forms and lists whose chunks :func:`_avi_break` walks into: the file's RIFF lists
#: (``AVIX``: an OpenDML file's later ones), the frames' ``movi`` and their ``rec`` groups.
AVI_LISTS = (b"AVI ", b"AVIX", b"movi", b"rec ")


def _printable_id(chunk_id: bytes) -> bool:
    """Whether `chunk_id` can be a RIFF chunk's id: four printable ASCII characters."""
    return len(chunk_id) == 4 and all(0x20 <= c <= 0x7E for c in chunk_id)


def _avi_break(path: Path) -> tuple[int, int] | None:
    """Where the chunks of AVI file `path` break off inside it: (frames before it, its byte).

    FFmpeg's AVI demuxer reads on past damage in the middle of a file (bytes overwritten or
    cut out) from the next chunk it finds, and numbers the frames it reads by counting them:
    every frame after the damage takes the number of an earlier one, silently (a user trial:
    frames 35.. read as 32.., tracks and ground truth three frames apart). The chunks are
    walked from the start, 8 bytes read for each (no decoding: a bounded cost), counting the
    frames (``##dc``, ``##db`` of the first stream that has them) before a chunk that is not
    one (an id that is not four printable characters, or a size past the list holding it).

    Returns
    -------
    tuple of (int, int) or None
        The frames before the break and its offset in the file; None when the chunks do not
        break (a file that ends early, its last chunk cut, keeps its frames' numbers) or
        `path` is not a RIFF file.
    """
    try:
        with path.open("rb") as fh:
            size = os.fstat(fh.fileno()).st_size
            stream: bytes | None = None
            frames = 0
            if fh.read(4) != b"RIFF":
                return None
            # (start, declared end) of the lists still to walk: the file (whose chunks are
            # RIFF lists, ending where the file ends), then RIFF, movi and rec lists; a list
            # declared past the file's end is of a file that ends early, not broken
            todo = [(0, 1 << 63)]
            while todo:
                pos, end = todo.pop()
                while pos + 8 <= min(end, size):
                    fh.seek(pos)
                    head = fh.read(12)
                    chunk_id, length = head[:4], int.from_bytes(head[4:8], "little")
                    stop = pos + 8 + length + (length & 1)
                    if not _printable_id(chunk_id) or (stop > end and end <= size):
                        return frames, pos
                    if chunk_id in (b"RIFF", b"LIST") and head[8:12] in AVI_LISTS:
                        todo.append((stop, end))  # the rest of this list, after the inner one
                        pos, end = pos + 12, stop
                        continue
                    if chunk_id[2:] in (b"dc", b"db") and stream in (None, chunk_id[:2]):
                        stream = chunk_id[:2]
                        frames += 1
                    pos = stop
    except OSError:
        return None
    return None


#: Reads tried after a frame inside a video fails to decode, before the video counts as ended.
RESUME_TRIES = 16


def _stamp_index(cap: cv2.VideoCapture, rate: float) -> int:
    """The index of the frame `cap` read last, from its time stamp and the file's frame rate."""
    return round(float(cap.get(cv2.CAP_PROP_POS_MSEC)) * rate / 1000.0)


def _resume(
    cap: cv2.VideoCapture,
    rate: float,
    start: int,
    at: int,
    n_frames: int,
    read: Callable[[], tuple[bool, Any]],
) -> tuple[int, Any] | None:
    """The next frame that decodes after a failure at frame `at`, with its index.

    A damaged packet in the middle of a file (bytes overwritten) fails one read, and FFmpeg
    decodes on from the next frame: its time stamp (less the first frame's, `start`) says
    which one it is. `read`: ``cap.read`` (the frame comes back), or a pass of grabs' step
    (``lambda: (cap.grab(), None)``). None when none of :data:`RESUME_TRIES` reads decodes, or
    its stamp is not a later frame of the header's.
    """
    for _ in range(RESUME_TRIES):
        ok, frame = read()
        if ok:
            index = _stamp_index(cap, rate) - start
            return (index, frame) if at <= index < max(n_frames, at + 1) else None
    return None


class _DamagedInside(Exception):  # a signal between readers, never raised out of them
    """A pass of grabs stopped at a frame that fails to decode, with frames after it that do.

    :meth:`FrameSource._read_at` raises it; its callers read such a file as iterating reads
    it instead (:meth:`FrameSource._iter_stored`: the frame before stands in).
    """


def _frame_list(indexes: list[int]) -> str:
    """``frame 18`` or ``frames 18-20, 31`` (1-based) for 0-based `indexes`, in order."""
    runs: list[list[int]] = []
    for i in indexes:
        if runs and i == runs[-1][1] + 1:
            runs[-1][1] = i
        else:
            runs.append([i, i])
    text = ", ".join(f"{a + 1}" if a == b else f"{a + 1}-{b + 1}" for a, b in runs)
    return f"frame{'s' * (len(indexes) > 1)} {text}"


def video_files(folder: PathLike) -> list[Path]:
    """The video files (:data:`VIDEO_SUFFIXES`) directly in `folder`, in natural order."""
    folder = Path(path_arg(folder, "video_files: folder"))  # was: an AttributeError for a str
    return sorted(
        (p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in VIDEO_SUFFIXES),
        key=lambda p: natural_key(p.name),
    )


def _sequence_folders(folder: Path) -> list[Path]:
    """The MOTChallenge sequence folders directly in `folder` (``seqinfo.ini`` or ``img1/``).

    In natural order; unreadable entries are passed over.
    """
    found = []
    for p in folder.iterdir():
        with contextlib.suppress(OSError):
            if p.is_dir() and (_has_seqinfo(p) or (p / "img1").is_dir()):
                found.append(p)
    return sorted(found, key=lambda p: natural_key(p.name))


def _not_there(folder: Path) -> str:
    """How an image folder that is not there is not: ``does not exist``, ``is a file``."""
    return "is a file" if folder.exists() else "does not exist"


def sequence_video(folder: PathLike) -> Path | None:
    """The video a MOTChallenge sequence folder without its image folder is read from.

    That is the layout ``pftrack batch`` takes (``SEQ/seqinfo.ini``, ``SEQ/video.mp4``,
    ``SEQ/det.txt``, no ``SEQ/img1/``).

    Parameters
    ----------
    folder : str or os.PathLike
        A folder.

    Returns
    -------
    Path or None
        The one video file (:data:`VIDEO_SUFFIXES`) in `folder`, when `folder` holds a
        ``seqinfo.ini`` whose image folder (``imDir``) does not exist; None when `folder` is
        not such a sequence folder (no ``seqinfo.ini``, or its image folder exists).

    Raises
    ------
    ValueError
        `folder` is such a sequence folder but holds no video, or several.
    """
    path = Path(folder)
    if not _has_seqinfo(path):
        return None
    images = path / read_seqinfo(path).image_dir
    if images.is_dir():
        return None
    videos = video_files(path)
    if len(videos) == 1:
        return videos[0]
    found = (
        f"{len(videos)} videos ({', '.join(p.name for p in videos)}), not one"
        if videos
        else f"no video ({', '.join(VIDEO_SUFFIXES)})"
    )
    raise ValueError(
        f"{path / 'seqinfo.ini'}: image folder {images} {_not_there(images)} and {path} holds "
        f"{found} to read instead"
    )


def _same_folder(a: Path, b: Path) -> bool:
    """Whether `a` and `b` name the same existing folder (``SEQ/img1`` and ``SEQ/./img1/``)."""
    try:
        return a == b or a.samefile(b)
    except OSError:
        return False


#: A number in an image's name: digits, and a decimal fraction (``10.15``) where there is one.
_NUMBER = re.compile(r"\d+(?:\.\d+)?", re.ASCII)
#: The same with a sign: in names that are numbers alone (``-1``), a leading ``-`` is one.
_SIGNED = re.compile(r"-?\d+(?:\.\d+)?", re.ASCII)
#: A name that is an integer alone (``000001``, ``7``, ``-1``): a frame number.
_INTEGER = re.compile(r"-?\d+", re.ASCII)


def _numbered(stems: Sequence[str]) -> tuple[str, list[str], str] | None:
    """The numbers `stems` spell between a prefix and a suffix they all share, if they do.

    ``frame_1``, ``frame_6``: ``("frame_", ["1", "6"], "")``; ``10.1``, ``10.15``:
    ``("", ["10.1", "10.15"], "")``; ``-1``, ``0``: ``("", ["-1", "0"], "")``. The prefix ends
    in no digit, nor in digits and a point (``10.`` is part of the numbers ``10.1`` and
    ``10.15``), and the suffix starts in neither. A ``-`` is a sign only in names that are
    numbers alone (``frame-1`` is frame 1). Two names at least.

    Returns
    -------
    tuple of (str, list of str, str) or None
        The prefix, each stem's number as written, and the suffix. None when some stem is not
        the prefix, a number and the suffix, and when numbers with a decimal point follow a
        prefix ending in a letter or a digit (``cam1.2``, ``cam1.10``: camera 1's frames 2 and
        10, or the times 1.2 and 1.10 of camera ``cam``?).
    """
    if len(stems) < 2:
        return None
    prefix = re.sub(r"(?:\d+\.)?\d*\Z", "", os.path.commonprefix(list(stems)), flags=re.ASCII)
    prefix = "" if prefix == "-" else prefix
    suffix = os.path.commonprefix([s[::-1] for s in stems])[::-1]
    suffix = re.sub(r"\A\d*(?:\.\d+)?", "", suffix, flags=re.ASCII)
    number = _NUMBER if prefix else _SIGNED
    texts = [s[len(prefix) : len(s) - len(suffix)] for s in stems]
    if any(
        len(prefix) + len(suffix) > len(s) or not number.fullmatch(t)
        for s, t in zip(stems, texts, strict=True)
    ):
        return None
    if prefix[-1:].isalnum() and any("." in t for t in texts):
        return None
    return prefix, texts, suffix


def _decimal_key(name: str) -> tuple[tuple[int, Decimal | str], ...]:
    """:func:`natural_key` reading digits around a point as one number (``10.15 < 10.2``)."""
    return tuple(
        (0, Decimal(part)) if _NUMBER.fullmatch(part) else (1, part.lower())
        for part in re.split(r"(\d+(?:\.\d+)?)", name, flags=re.ASCII)
        if part
    )


def _read_two_ways(names: list[str]) -> tuple[str, str] | None:
    """Two of `names` (in :func:`natural_key` order) that :func:`_decimal_key` orders otherwise.

    None when both keys give one order (as when no name has digits around a point).
    """
    if not any(re.search(r"\d\.\d", n, re.ASCII) for n in names):
        return None
    as_decimals = sorted(names, key=lambda n: (_decimal_key(n), n))
    return next(((a, b) for a, b in zip(names, as_decimals, strict=True) if a != b), None)


def _natural_order(folder: Path, images: list[Path]) -> list[Path]:
    """`images` in the order of their names' numbers; two names of one number refused.

    Names that are numbers, integers or decimals, between a prefix and a suffix they all share
    (``10.1.png``, ``10.15.png``, ``10.2.png``; ``frame_9.png``, ``frame_10.png``; ``-1.png``,
    ``0.png``) are in the order of those numbers; other names in :func:`natural_key` order,
    unless reading the digits around a point as one decimal number orders them otherwise
    (``cam1.2.png``, ``cam1.10.png``): which is meant is not known, and that is refused. Two
    names of one number (``1.png``, ``01.png``; ``1.1.png``, ``1.10.png``) are refused too:
    their order would be the file system's, not the names', frames swapped silently.
    """
    numbered = _numbered([p.stem for p in images])
    keys: list[Any] = (
        [(Decimal(text),) for text in numbered[1]]
        if numbered is not None
        else [natural_key(p.name) for p in images]
    )
    keyed = sorted(zip(keys, (p.name for p in images), images, strict=True))
    for (k1, n1, _), (k2, n2, _) in itertools.pairwise(keyed):
        if k1 == k2:
            raise ValueError(
                f"images {n1} and {n2} in folder {folder} have the same number: which comes "
                "first is not known (rename one)"
            )
    pair = _read_two_ways([n for _, n, _ in keyed]) if numbered is None else None
    if pair is not None:
        raise ValueError(
            f"images {pair[0]} and {pair[1]} in folder {folder} come in one order if the "
            "digits around a point in their names are two numbers and in the other if they "
            "are one decimal number: which comes first is not known (rename them: zero-padded "
            "numbers, or names that are numbers alone)"
        )
    return [p for _, _, p in keyed]


def _frame_order(
    folder: Path, images: list[Path], sequence: SequenceInfo | None
) -> list[Path] | None:
    """A folder's images in frame order if their names are frame numbers.

    The names are frame numbers when every stem is an integer (``000001.jpg``, ``1.png``: the
    MOTChallenge convention; ``-1.png``, a negative one). A frame is its image's position, so in
    a MOTChallenge sequence's image folder a hole in the numbering would silently shift every
    later frame onto the wrong detections and ground truth (whose frames are those numbers):
    it is an error there. A folder that is not a sequence's (`sequence` None) may start at any
    number (``000000.png`` of a 0-based dump, a cut of a longer one) and skip numbers (camera
    time stamps, every fifth frame): frame 1 is its lowest, frame k its k-th image; detections
    are refused with such a folder (:attr:`FrameSource.gap`).

    Parameters
    ----------
    folder : Path
        The image folder (for the messages).
    images : list of Path
        Its images, in any order.
    sequence : SequenceInfo or None
        The MOTChallenge sequence `folder` is the image folder of: frame 1 is then image 1,
        no number is skipped, and there are ``seqLength`` images when ``seqinfo.ini`` says so.
        None: not checked.

    Returns
    -------
    list of Path or None
        The images by number; None when some name is not a number (their order is left to
        the caller).

    Raises
    ------
    ValueError
        Two images have one number, or, in a sequence, a number is missing (a hole, images
        that do not start at 1 or end before its ``seqLength``) or there are more images than
        its ``seqLength``.
    """
    if not all(_INTEGER.fullmatch(p.stem) for p in images):
        return None
    ordered = sorted(images, key=lambda p: (int(p.stem), p.name))
    numbers = [int(p.stem) for p in ordered]
    first, last = ordered[0].stem, ordered[-1].stem
    names = f"names {first}..{last} are frame numbers"

    def missing(number: int, width: int, why: str) -> ValueError:
        return ValueError(f"{folder}: image {str(number).zfill(width)} is missing ({why})")

    if sequence is not None and numbers[0] != 1:
        if numbers[0] > 1:
            raise missing(1, len(first), f"{names}; frame 1 of a MOTChallenge sequence is image 1")
        # numbered from 0 (a dump by a decoder's index): was said without a way out
        mend = (
            f": numbered from 0? rename each image to its number plus 1 ({ordered[0].name} to "
            f"{str(1).zfill(len(first))}{ordered[0].suffix}, ...) and add 1 to the frames of "
            "its det.txt and gt.txt, which number the frames by the names"
            if numbers[0] == 0
            else ""
        )
        raise ValueError(
            f"{folder}: image {first} is not a frame ({names}; a MOTChallenge sequence's "
            f"frames start at 1{mend})"
        )
    for k in range(1, len(numbers)):
        if numbers[k] == numbers[k - 1]:
            raise ValueError(
                f"{folder}: images {ordered[k - 1].name} and {ordered[k].name} are both "
                f"frame {numbers[k]} (names that are numbers are frame numbers)"
            )
        if sequence is not None and numbers[k] != numbers[k - 1] + 1:
            raise missing(
                numbers[k - 1] + 1,
                len(ordered[k - 1].stem),
                f"{names}; restore it: the sequence's detections and ground truth number its "
                "frames by them",
            )
    length = sequence.length if sequence is not None else None
    if length is not None and len(ordered) < length:
        raise missing(numbers[-1] + 1, len(last), f"{names}; seqinfo.ini says seqLength={length}")
    if length is not None and len(ordered) > length:
        raise ValueError(
            f"{folder}: {len(ordered)} images ({first}..{last}) but seqinfo.ini says "
            f"seqLength={length}"
        )
    return ordered


def _gap(folder: Path, images: list[Path]) -> str | None:
    """The first number that `images`' names skip, as :attr:`FrameSource.gap` says it.

    For names that are integers between a prefix and a suffix they share (``1.png``,
    ``6.png``; ``frame_1.png``, ``frame_6.png``: :func:`_numbered`), given in order; None when
    they skip none, or are not such names (decimal numbers are no frame numbers).
    """
    stems = [p.stem for p in images]
    numbered = _numbered(stems)
    if numbered is None or any("." in text for text in numbered[1]):
        return None
    prefix, texts, suffix = numbered
    for before, after in itertools.pairwise(texts):
        if int(after) != int(before) + 1:
            width = 0 if before.startswith("-") else len(before)
            name = f"{prefix}{str(int(before) + 1).zfill(width)}{suffix}"
            return f"{folder}: image {name} is missing (names {stems[0]}..{stems[-1]} skip numbers)"
    return None


def gap_note(source: FrameSource) -> str | None:
    """What a run without detections says of `source`'s numbering, or None.

    Said of an image folder whose names count frames one by one with holes (``0001.png ..
    0030.png`` without ``0011``: a camera's or a cut's dropped frames; most steps between
    consecutive names are 1): its rows number the frames by position, as :class:`FrameSource`
    does, and a ground truth numbered by the names does not line up with them past the hole.
    Names that step evenly by more (``1.png, 6.png, 11.png``; millisecond time stamps) number
    no frames and say nothing. With detections a folder with a gap is refused instead
    (:func:`pftrack.track_frames`).
    """
    if source.gap is None or source._images is None:
        return None
    numbered = _numbered([p.stem for p in source._images])
    if numbered is None:
        return None
    steps = np.diff([int(text) for text in numbered[1]])
    if np.count_nonzero(steps == 1) * 2 <= len(steps):  # most steps are not 1: no frame count
        return None
    return (
        f"{source.gap}: the rows number the frames 1..N in the names' order (row frame k is the "
        "k-th image), not by the names: a ground truth numbered by the names does not line up "
        "with them past the gap"
    )


def _image_folder(path: Path, sequence: SequenceInfo | None) -> Path:
    """The folder whose images a folder source `path` (of `sequence`, if any) reads.

    A sequence folder's ``imDir`` (ValueError if missing), else ``path/img1`` if it exists,
    else `path` itself.
    """
    if sequence is not None and sequence.folder == path:
        folder = path / sequence.image_dir
        if not folder.is_dir():
            raise ValueError(f"{path / 'seqinfo.ini'}: image folder {folder} {_not_there(folder)}")
        return folder
    if (path / "img1").is_dir():
        return path / "img1"
    return path


def _no_images(folder: Path, sequence: SequenceInfo | None = None) -> str:
    """The message for a folder source without images; one of videos says how to track them.

    An empty image folder of `sequence` beside the one video :func:`sequence_video` would read
    without it (``SEQ/img1/``, ``SEQ/seqinfo.ini`` and ``SEQ/video.mp4``) says so.
    """
    videos = video_files(folder)
    if not videos:
        none = f"no images ({', '.join(IMAGE_SUFFIXES)}) in folder {folder}"
        held = _sequence_folders(folder) if sequence is None else []
        if held:  # a benchmark's folder of sequences (was: "no images", no word of them)
            names = ", ".join(p.name for p in held[:3]) + (", ..." if len(held) > 3 else "")
            one = "a sequence" if len(held) == 1 else f"{len(held)} sequences"
            return (
                f"folder {folder} holds {one} ({names}) and no images: give "
                f"{'it' if len(held) == 1 else 'one of them'} ({held[0]})"
                + ("" if len(held) == 1 else f", or track them all with pftrack batch {folder}")
            )
        if sequence is None or not (sequence.folder / "seqinfo.ini").is_file():
            return none
        beside = video_files(sequence.folder)
        if len(beside) != 1:
            return none
        return (
            f"{none}; {sequence.folder} holds a video, {beside[0].name}, read as the sequence's "
            f"frames once the empty image folder is gone (or give {beside[0]})"
        )
    names = ", ".join(p.name for p in videos[:3]) + (", ..." if len(videos) > 3 else "")
    if len(videos) == 1:
        return f"folder {folder} holds a video ({names}) and no images: give it ({videos[0]})"
    return (
        f"folder {folder} holds {len(videos)} videos ({names}) and no images: give one of them "
        f"({videos[0]}), or track them all with pftrack batch {folder}"
    )


def _cut_jpeg(path: Path) -> bool:
    """Whether the JPEG file `path` ends before its end marker (``FF D9``): a truncated file.

    libjpeg decodes a truncated file without an error, the rest of the image grey, and says
    only "Premature end of JPEG file" on stderr, naming no file (a user trial). The marker is
    looked for in the last 64 bytes; a file with more after it (a phone's trailer, a motion
    photo's video) is walked segment by segment (:func:`_jpeg_ends`) before it is said to be
    cut.
    """
    try:
        with path.open("rb") as fh:
            fh.seek(0, os.SEEK_END)
            fh.seek(max(fh.tell() - 64, 0))
            if b"\xff\xd9" in fh.read():
                return False
            fh.seek(0)
            data = fh.read()
    except OSError:
        return False
    return _jpeg_ends(data) is False


#: What libjpeg prints on stderr of a file that ends before its end marker (:func:`_cut_jpeg`).
JPEG_CUT_NOTE = "Premature end of JPEG file"


def _jpeg_ends(data: bytes) -> bool | None:
    """Whether the JPEG stream in `data` reaches its end marker; None if it cannot be told.

    The segments are walked from the start (each marker's length), and each scan's
    entropy-coded data to the next marker that is neither a stuffed ``FF 00`` nor a restart.
    """
    if data[:2] != b"\xff\xd8":
        return None
    i, n = 2, len(data)
    while i + 1 < n:
        if data[i] != 0xFF:
            return None  # not a marker where one should be: damaged, not (only) cut
        marker = data[i + 1]
        if marker == 0xD9:
            return True
        if marker == 0xFF:  # fill byte
            i += 1
            continue
        if 0xD0 <= marker <= 0xD7 or marker == 0x01:  # restarts, TEM: no length
            i += 2
            continue
        if i + 4 > n:
            return False
        i += 2 + int.from_bytes(data[i + 2 : i + 4], "big")
        if marker == 0xDA:  # a scan: entropy-coded data up to the next real marker
            while True:
                j = data.find(b"\xff", i)
                if j < 0 or j + 1 >= n:
                    return False
                following = data[j + 1]
                if following == 0x00 or 0xD0 <= following <= 0xD7:
                    i = j + 2
                elif following == 0xFF:
                    i = j + 1
                else:
                    i = j
                    break
    return False


#: JPEG start-of-frame markers (``FF C0``-``FF CF`` but DHT C4, JPG C8, DAC CC): the image's size.
_JPEG_SOF = frozenset(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}


def _header_size(path: Path) -> tuple[int, int] | None:
    """(width, height) of an image file from its header, as stored; None if not told.

    PNG, JPEG, BMP, TIFF or WebP.
    A few bytes a file: PNG's IHDR (bytes 16-24), JPEG's start-of-frame segment, walked to
    marker by marker from the start, each segment skipped by its length (EXIF's thumbnail
    unread); BMP's info header (:func:`_bmp_size`), TIFF's first directory (:func:`_tiff_size`),
    WebP's first chunk (:func:`_webp_size`). Not told: another format, a file too short or
    damaged there (read as a frame, it is refused or stood in for then, as before). As stored:
    OpenCV turns a JPEG by its EXIF orientation as it reads it, so a size that is the other's
    turned is not told apart here.
    """
    try:
        with path.open("rb") as fh:
            head = fh.read(30)
            if head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":
                return _positive(
                    int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
                )
            if head[:2] == b"BM":
                return _bmp_size(head)
            if head[:4] in (b"II*\x00", b"MM\x00*"):
                return _tiff_size(fh, "little" if head[:2] == b"II" else "big")
            if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
                return _webp_size(head)
            if head[:2] != b"\xff\xd8":
                return None
            fh.seek(2)
            for _ in range(1000):  # segments before the frame's (a damaged file: not told)
                marker = fh.read(4)
                if len(marker) < 4 or marker[0] != 0xFF:
                    return None
                if marker[1] == 0xFF or 0xD0 <= marker[1] <= 0xD7 or marker[1] == 0x01:
                    fh.seek(-3 if marker[1] == 0xFF else -2, os.SEEK_CUR)  # fill, no length
                    continue
                length = int.from_bytes(marker[2:4], "big")
                if marker[1] in _JPEG_SOF:
                    frame = fh.read(5)  # precision, height, width
                    if len(frame) < 5:
                        return None
                    return _positive(
                        int.from_bytes(frame[3:5], "big"), int.from_bytes(frame[1:3], "big")
                    )
                if marker[1] in (0xD9, 0xDA) or length < 2:  # end or scan before a frame
                    return None
                fh.seek(length - 2, os.SEEK_CUR)
    except OSError:
        return None
    return None


def _positive(w: int, h: int) -> tuple[int, int] | None:
    """``(w, h)`` if both are above 0 (a header's size), else None (not told)."""
    return (w, h) if w > 0 and h > 0 else None


def _bmp_size(head: bytes) -> tuple[int, int] | None:
    """(width, height) from a BMP's first 30 bytes: its info header after the 14-byte file header.

    BITMAPCOREHEADER (12 bytes): unsigned 16-bit width and height at 18 and 20; the longer
    ones (BITMAPINFOHEADER, 40 bytes, and V4, V5): signed 32-bit at 18 and 22, little-endian, a
    negative height a top-down image (its rows stored first to last), of that height.
    """
    if len(head) < 26:
        return None
    info = int.from_bytes(head[14:18], "little")
    if info == 12:
        return _positive(
            int.from_bytes(head[18:20], "little"), int.from_bytes(head[20:22], "little")
        )
    if info < 40:
        return None
    w = int.from_bytes(head[18:22], "little", signed=True)
    h = int.from_bytes(head[22:26], "little", signed=True)
    return _positive(w, abs(h))


def _tiff_size(fh: BinaryIO, order: Literal["little", "big"]) -> tuple[int, int] | None:
    """(width, height) from a TIFF's first image directory, the page OpenCV reads.

    Tags 256 and 257 (ImageWidth, ImageLength), each a SHORT (type 3) or LONG (type 4) held in
    its entry, in the file's byte order (``II`` little, ``MM`` big).
    """
    fh.seek(4)
    offset = int.from_bytes(fh.read(4), order)
    fh.seek(offset)
    count = fh.read(2)
    if len(count) < 2:
        return None
    n = int.from_bytes(count, order)
    entries = fh.read(12 * n)
    size: dict[int, int] = {}
    for k in range(0, len(entries) - 11, 12):
        tag, kind = (
            int.from_bytes(entries[k : k + 2], order),
            int.from_bytes(entries[k + 2 : k + 4], order),
        )
        if tag in (256, 257) and kind in (3, 4):
            value = entries[k + 8 : k + (10 if kind == 3 else 12)]
            size[tag] = int.from_bytes(value, order)
    return _positive(size.get(256, 0), size.get(257, 0))


def _webp_size(head: bytes) -> tuple[int, int] | None:
    """(width, height) from a WebP's first 30 bytes: its first chunk, at byte 12.

    ``VP8 `` (lossy): the key frame's 14-bit width and height at 26 and 28, after its start
    code ``9D 01 2A``; ``VP8L`` (lossless): after the signature byte ``2F``, 14 bits of width
    - 1 and 14 of height - 1, little-endian; ``VP8X`` (extended): the canvas's 24-bit width - 1
    and height - 1 at 24 and 27.
    """
    if len(head) < 30:
        return None
    chunk = head[12:16]
    if chunk == b"VP8 " and head[23:26] == b"\x9d\x01\x2a":
        w = int.from_bytes(head[26:28], "little") & 0x3FFF
        return _positive(w, int.from_bytes(head[28:30], "little") & 0x3FFF)
    if chunk == b"VP8L" and head[20] == 0x2F:
        bits = int.from_bytes(head[21:25], "little")
        return (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1
    if chunk == b"VP8X":
        return int.from_bytes(head[24:27], "little") + 1, int.from_bytes(head[27:30], "little") + 1
    return None


def _odd_size(
    images: Sequence[Path], first: int
) -> tuple[Path, tuple[int, int], tuple[int, int]] | None:
    """The first image of a folder whose header's size is another than image `first`'s.

    :func:`_header_size` of each (PNG, JPEG, BMP, TIFF and WebP; another format, or one not
    told, is checked when read, :meth:`FrameSource._read_image`). A size that is the other
    turned (``480x640`` beside ``640x480``) is left to the read: an EXIF orientation may turn it
    back. Returns the image, its size and image `first`'s, or None.
    """
    size = _header_size(images[first])
    if size is None:
        return None
    turned = size[::-1]
    for path in images:
        other = _header_size(path)
        if other is not None and other != size and other != turned:
            return path, other, size
    return None


def _odd_depth(path: Path) -> str | None:
    """The depth of image `path` if it decodes only at a depth other than 8 or 16 bits.

    A 32-bit float TIFF (a processing pipeline's output) decodes at its own depth but not in
    OpenCV's 8-bit colour read; its values have no set range (0..1, 0..255, radiance).
    """
    image = read_image_depth(path, notes=[])  # the decoder's lines: said by the caller's read
    if image is None or image.dtype in (np.uint8, np.uint16):
        return None
    kind = {"f": "floats", "i": "signed integers", "u": "unsigned integers"}
    return f"{image.dtype.itemsize * 8}-bit {kind.get(image.dtype.kind, 'values')} ({image.dtype})"


class _Unreadable(ValueError):
    """An image of a folder that cannot be read (:func:`_unreadable`): `path` and `why`.

    Its reader stands the frame before in for it (:meth:`FrameSource._iter_stored`); raised out
    of a reader only when no image of the folder can be read, or by :func:`_open_depth`'s caller.
    """

    def __init__(self, path: Path, why: str) -> None:
        super().__init__(f"cannot read image {path}: {why}")
        self.path, self.why = path, why


def _unreadable(path: Path, notes: Sequence[str]) -> _Unreadable:
    """The error of image `path` of a folder that cannot be read, saying why.

    An empty file (a copy that failed), a folder or a broken link named like an image, a file
    that cannot be opened, an image of another depth than 8 or 16 bits (:func:`_odd_depth`), or
    what its decoder said (`notes`, :func:`read_image`'s); were all ``cannot read image P``.
    """
    try:
        info = path.stat()
    except OSError as exc:
        why = exc.strerror or str(exc)
        if path.is_symlink() and exc.errno == errno.ENOENT:
            why = f"a symbolic link to {os.readlink(path)}, which does not exist"
    else:
        if stat.S_ISDIR(info.st_mode):
            why = "it is a folder"
        elif info.st_size == 0:
            why = "it is empty (0 bytes)"
        elif (depth := _odd_depth(path)) is not None:  # was "damaged?", of an intact file
            why = (
                f"its pixels are {depth}, not 8- or 16-bit integers (whose range is known); "
                "convert the images to 8 or 16 bits (PNG or TIFF)"
            )
        elif notes:
            why = f"its decoder says {'; '.join(dict.fromkeys(notes))!r}"
        else:
            why = "not an image OpenCV can decode (damaged?)"
            try:
                path.open("rb").close()
            except OSError as exc:
                why = exc.strerror or str(exc)
    return _Unreadable(path, why)


def image_files(folder: PathLike) -> list[Path]:
    """The image files (:data:`IMAGE_SUFFIXES`) directly in `folder`, in no particular order.

    Hidden files (names starting with a point) are left out, as ``ls`` leaves them: macOS's
    ``._000001.jpg`` beside each image of a folder copied from its disks, a viewer's
    ``.thumb.jpg`` (were: frames, or an image that could not be read; a user trial).
    """
    folder = Path(path_arg(folder, "image_files: folder"))  # was: an AttributeError for a str
    return [p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.name[0] != "."]


def _frames_only(folder: Path, images: list[Path]) -> list[Path]:
    """A MOTChallenge sequence's images without those whose names are not frame numbers.

    In a sequence's image folder the names are frame numbers (``000001.jpg``): an image named
    otherwise beside them (a ``cover.jpg``) is no frame, and is left out with a warning (was:
    the numbers were no longer read as frames, the stray image became one more frame, and
    ``pftrack eval`` refused the rows of a frame beyond ``seqLength``; a user trial). Images
    none of whose names is a number are kept, in their names' order.
    """
    numbered = [p for p in images if _INTEGER.fullmatch(p.stem)]
    if not numbered or len(numbered) == len(images):
        return images
    others = sorted(p.name for p in images if not _INTEGER.fullmatch(p.stem))
    listed = ", ".join(others[:3]) + (", ..." if len(others) > 3 else "")
    warn_outside(
        f"{folder}: {len(others)} image{'s' * (len(others) > 1)} whose name is not a frame "
        f"number left out ({listed}): a MOTChallenge sequence's frames are its numbered images",
    )
    return numbered


def source_files(source: PathLike | int) -> list[Path]:
    """Every file :class:`FrameSource` reads for `source`: what no output of a run may replace.

    Parameters
    ----------
    source : str, int or os.PathLike
        As :class:`FrameSource` takes it.

    Returns
    -------
    list of Path
        `source` itself; every ``seqinfo.ini`` it looks for that exists (in a folder `source`
        and the folder above it; beside a file); for a folder, each image of the folder it
        reads frames from (``imDir`` of a sequence, ``img1/``, or the folder), or a sequence
        folder's one video. Nothing for a camera index or a stream URL. A ``seqinfo.ini`` that
        cannot be parsed is listed all the same (it is read: the run fails on it), and so is
        every image of a sequence folder's image folders it may name.
    """
    text = str(source)
    if _camera_index(source) is not None or "://" in text:
        return []
    path = Path(text)
    files = [path]
    if not path.is_dir():
        ini = path.parent / "seqinfo.ini"
        return files + ([ini] if ini.is_file() else [])
    files += [f / "seqinfo.ini" for f in (path, path.parent) if (f / "seqinfo.ini").is_file()]
    try:
        sequence = find_sequence(path)
    except ValueError:  # an unreadable seqinfo.ini: refused when read; guard every image folder
        folders = [path, path / "img1"]
    else:
        try:
            video = sequence_video(path) if sequence is not None else None
        except ValueError:  # no video, or several: refused when read
            video = None
        if video is not None:
            return [*files, video]
        try:
            folders = [_image_folder(path, sequence)]
        except ValueError:  # its image folder is missing: refused when read
            folders = []
    return files + [p for f in folders if f.is_dir() for p in image_files(f)]


def check_outside_frames(outputs: Mapping[str, PathLike | None], source: PathLike | int) -> None:
    """Refuse an image output in the folder whose images are `source`'s frames.

    The run itself reads its frames before writing it, but the next run on that folder would
    read it as one more frame (was: a ``--plot imgs/paths.png`` beside ``0001.jpg`` ..
    ``0020.jpg`` was frame 21 of every later run, silently; a user trial). An output that is
    already one of the images is an input of the run, refused by
    :func:`~pftrack.io.atomic.check_output`.

    Parameters
    ----------
    outputs : mapping of str to path or None
        Each output by the name error messages give it (e.g. ``"--plot"``); None: not written.
    source : str, int or os.PathLike
        As :class:`FrameSource` takes it: only an image or sequence folder has such a folder.

    Raises
    ------
    ValueError
        An output with an image's extension (:data:`IMAGE_SUFFIXES`) lies in that folder.
    """
    if not Path(str(source)).is_dir():
        return
    frames = [p for p in source_files(source) if p.suffix.lower() in IMAGE_SUFFIXES]
    if not frames:
        return
    folder = frames[0].parent
    for what, path in outputs.items():
        target = Path(path) if path is not None else None
        if target is None or target.suffix.lower() not in IMAGE_SUFFIXES:
            continue
        if target.name.startswith("."):  # hidden: no frame (image_files)
            continue
        if _same_folder(target.parent, folder):
            raise ValueError(
                f"{what} {target} is in {folder}, whose images are this run's frames: a later "
                "run on it would read it as one more frame; write elsewhere"
            )


def check_source(source: object) -> None:
    """Refuse what cannot name a frame source, before anything is opened.

    Raises
    ------
    TypeError
        `source` is not a path, a string or an integer (a bool is refused: ``True`` is not
        camera 1).
    ValueError
        A negative camera index (OpenCV's ``VideoCapture(-1)`` crashes the process when there is
        no camera), one beyond a C int (``"99999999999999999999"``), or an empty string (it
        would read the current folder).
    """
    what = "expected a video file, an image or sequence folder, a stream URL or a camera index"
    if isinstance(source, (bool, np.bool_)):
        raise TypeError(f"video source is {source}, a bool; {what} (an int >= 0)")
    if isinstance(source, (int, np.integer)) and source < 0:
        raise ValueError(f"camera index is {source}, expected an int >= 0")
    if isinstance(source, (int, np.integer)):
        camera: int | None = int(source)
    else:  # a name: "0", or Path("0"), when no file has it
        camera = _camera_index(str(source)) if isinstance(source, (str, os.PathLike)) else None
    if camera is not None and camera > MAX_CAMERA_INDEX:  # was OpenCV's overload error
        raise ValueError(
            f"camera index is {camera}, expected an int from 0 to {MAX_CAMERA_INDEX} (OpenCV's "
            "VideoCapture takes a C int)"
        )
    if isinstance(source, (int, np.integer)):
        return
    if not isinstance(source, (str, os.PathLike)):
        kind = type(source).__name__
        raise TypeError(f"video source must be a path, a URL or an int, got {kind}")
    if isinstance(source, str) and not source:
        raise ValueError(f"video source is {brief(source)} (empty); {what}")


def _camera_index(source: PathLike | int) -> int | None:
    """The camera index `source` names (``0``, ``"1"``), unless a file or folder has that name."""
    if isinstance(source, (int, np.integer)) and not isinstance(source, (bool, np.bool_)):
        return int(source)
    text = str(source)
    # ASCII digits only: str.isdigit() takes any Unicode digit ('\u00b2', which int() refuses)
    digits = text.isascii() and text.isdigit()
    return int(text) if digits and not Path(text).exists() else None


def is_live_source(source: PathLike | int) -> bool:
    """Whether `source` is a camera index, a stream URL (``scheme://``) or a named pipe.

    A digit string is a camera index unless a file or folder of that name exists.
    """
    text = str(source)
    if _camera_index(source) is not None or "://" in text:
        return True
    try:
        mode = Path(text).stat().st_mode
    except OSError:
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)


#: Largest side of a frame that `FrameSource(scale=...)` may make (OpenCV's image limit).
MAX_SCALED_SIDE = 32767

#: Guards a live source's capture between a reader inside its ``read()`` and ``close()``
#: from another thread; held only for that bookkeeping, never during a read (one for every
#: source: a FrameSource stays picklable).
_LIVE_CAPTURE = threading.Lock()


class FrameSource:
    """Iterate over BGR uint8 frames of a video, image folder, sequence, camera or stream.

    Parameters
    ----------
    source : str, int or os.PathLike
        A video file, an image folder, a MOTChallenge sequence folder (``seqinfo.ini`` and
        ``img1/``, or ``seqinfo.ini`` and one video file: see :func:`sequence_video`), a
        camera index (``0`` or ``"0"``), or a stream URL such as
        ``rtsp://host/path`` or ``http://host:8080/video`` (passed to OpenCV's FFmpeg
        backend untouched).
    scale : float
        Resize factor applied to every frame (1 keeps the size).
    fps : float, optional
        Frame rate; overrides ``seqinfo.ini`` and the container header.

    Attributes
    ----------
    fps : float
        Frames per second (see `fps_origin`).
    fps_origin : str
        Where `fps` came from: ``"given"``, ``"seqinfo.ini"``, ``"container"`` (a header
        rate below 1000), ``"time stamps"`` (without one: the median step between the first
        frames' time stamps, :func:`_stamped_rate`) or ``"default"``.
    n_frames : int
        Frames expected (0 when unknown, as for live sources).
    count_known : bool
        Whether `n_frames` is the number of frames, not an estimate: an image folder's, or
        the header count of a container that stores one (:data:`COUNTED_SUFFIXES`). Checks
        that refuse frame numbers past the last frame, or warn of a video that ended early,
        are made only then.
    live : bool
        A camera, stream or pipe: read once, frames as they arrive.
    sequence : SequenceInfo or None
        The MOTChallenge sequence `source` belongs to.
    path : Path or None
        The file or folder read: `source`, or a sequence folder's video (see
        :func:`sequence_video`); None for a camera or a stream URL.
    width, height : int
        Frame size after `scale`.
    gap : str or None
        For an image folder whose names are numbered with a gap (``1.png, 6.png, 11.png``,
        ``1690000000000.png, 1690000000033.png``, ``frame_1.png, frame_6.png``; outside a
        MOTChallenge sequence's image folder, where a gap is an error), what is missing:
        ``"imgs: image 2 is missing (names 1..11 skip numbers)"``. The frames are still
        numbered 1..N in the names' order; detections, whose frame numbers could count the
        images by name or by position, are refused with it (:func:`pftrack.track_frames`).
        None otherwise.
    rotation : int
        For a video file with rotation metadata (a phone's portrait video: a display matrix
        of 90, 180 or 270 degrees), the degrees its stored frames are turned by, clockwise, to
        be shown.
        OpenCV turns them as it reads them, as players and FFmpeg do: the frames, the tracks'
        boxes, ``--render``'s video and plot, and the detections a source takes are all in
        the frames as shown (360x480 for a 480x360 video turned 90 degrees). 0 otherwise.
    bits : int or None
        For an image folder whose first image is 16-bit with values of fewer bits (10- or
        12-bit camera data: :func:`_bit_depth` of the largest value of its first image, its
        last and up to seven evenly spaced between, :func:`_depth_sample`, 10, 12 or 14; 8 for
        8-bit data), the depth every 16-bit image of the folder is read at: each value divided
        by ``2 ** (bits - 8)`` (a value past it white), not by 256 as OpenCV reads them, which
        makes such images almost black. None: images read as OpenCV reads them (8-bit images,
        full-range 16-bit ones), a video, a camera or a stream.

    Raises
    ------
    FileNotFoundError
        If a path `source` does not exist.
    TypeError
        If `source` is not a path, a string or an int (a bool is refused).
    ValueError
        If it is empty or a negative camera index; if it cannot be opened or decoded, or holds
        no frame (an image folder none of whose images can be read: the count and the first's
        reason); if two images of a folder have one number, or another size than the first
        that can be read (a PNG, JPEG, BMP, TIFF or WebP when the folder is opened, from its
        header, :func:`_odd_size`; another when read), or are 16-bit where it is 8-bit (when
        read); or if a MOTChallenge sequence's image folder is named by number and one is
        missing (a hole in the numbering, numbers that do not start at 1 or a count other than
        ``seqLength``); if read (iterated, :meth:`frames_at`) after :meth:`stop`.

    Warns
    -----
    UserWarning
        Once, when a video read to its end had fewer frames than its header says, or a number
        other than its sequence's ``seqLength`` (counted as read: no pass of its own). At the
        first image read, when a folder's 16-bit images are read at :attr:`bits`; once, when
        an image it was not decided from is brighter than that depth holds (its brighter
        pixels clipped to white). When an ``.avi`` is opened whose chunks break off inside it
        (:func:`_avi_break`): the frames after the break may carry earlier frames' numbers.
        When a video file of several video streams is opened (:func:`_several_video_streams`): the
        first is read. Once, when a frame inside a video fails to decode (the frame before
        stands in): as it is read, before the stand-in is given (under ``-W error`` a loop stops
        there); at the end of a pass again only if more frames failed, naming them all. Once,
        when a video with a rate from the file has clearly uneven time stamps
        (:func:`_uneven_steps`), a variable frame rate read as one: as soon as its first
        :data:`UNEVEN_FIRST_CHECK` frames show it (then 100, 200, ...), else once it was read to
        its end. Once, when an image of a folder cannot be read (empty, cut short, not an
        image: the frame before stands in, a black frame for those before the first that can
        be read, counted by :attr:`lead_black`): as it is read, naming it and why; at the end of
        a pass again only if more could not be, with their count and first names.

    Notes
    -----
    A file or folder can be iterated any number of times. A live source can be iterated once,
    except that the first 64 frames are kept: a second iteration (the tracker primes its
    background model on the first frames, then tracks from frame 1) replays them and goes on
    reading, as long as the first one stopped within them. :meth:`stop` ends the reads under
    way and every later one.
    """

    def __init__(
        self, source: PathLike | int, *, scale: float = 1.0, fps: RealLike | None = None
    ) -> None:
        check_source(source)
        scale = number(scale, "scale", finite=False)  # text, bools, None: a TypeError naming it
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale is {scale}, expected a finite value > 0")
        if fps is not None:
            fps = real(fps, "fps", finite=False)  # a Fraction too (PyAV's stream rates)
            if not (np.isfinite(fps) and fps > 0):
                raise ValueError(f"fps is {fps}, expected a finite value > 0")
        self.scale = scale
        self.name = str(source)
        self.live = is_live_source(source)
        self.sequence: SequenceInfo | None = None
        self._images: list[Path] | None = None
        self.rotation = 0  # a video file's display rotation, applied as OpenCV reads it
        self._image_shape = (0, 0)  # (height, width) of a folder's first image
        # a folder's 16-bit images of fewer bits (from a few of its images): read at that depth
        self.bits: int | None = None
        self.gap: str | None = None  # an image folder's names skip a number
        self._depth_note: str | None = None  # the warning saying so, given at the first read
        self._eight_bit = False  # the folder's first image is 8-bit: a 16-bit one is refused
        self._depth_from = ""  # the images `bits` was decided from, for the clipping warning
        self._clipped = False  # a later 16-bit image went past `bits`: said once
        self._cut_said = False  # a JPEG without its end marker: said once
        self._decoder_said: set[str] = set()  # what image decoders printed: each said once
        self._warned_short = False  # a video's frames were not its header's or seqLength's
        self._warned_uneven = False  # a video's time stamps were looked at (_warn_uneven)
        self._warned_skip = False  # its stamps skipped frames a decoder dropped (_warn_skip)
        self._header_frames = 0  # the header's frame count, if it has one (set when opened)
        # the frames inside the video said not to decode (_warn_lost): said between frames
        # once, at the end of a pass again only for more
        self._said_lost: frozenset[int] = frozenset()
        self._warned_lead = False  # its first frames could not be decoded (_warn_lead)
        self._warned_cut = False  # its first frames were left out by FFmpeg (_warn_cut_start)
        #: how many of its first frames did not decode and are black stand-ins (0: none, or
        #: not read yet); known once its first frame is read (an image folder's: when opened,
        #: the images before the first that can be read)
        self.lead_black = 0
        # an image folder's images that cannot be read, by index (the frame before stands in:
        # _image_frame), and those said (_warn_unread): once, at the end of a pass only more
        self._bad: dict[int, _Unreadable] = {}
        self._said_bad: frozenset[int] = frozenset()
        self._folder: Path | None = None  # the folder of an image folder's images
        self._broken: tuple[int, int] | None = None  # an AVI's chunks break off (_avi_break)
        self._span_ms: float | None = None  # a file's duration by its container (not counted)
        self._cap: Any = None
        self._reading = False  # a thread is inside the live capture's read()
        self._replay: list[NDArray[np.uint8]] = []
        self._read_past_replay = False
        self.stopped = False
        text = str(source)
        camera = _camera_index(source)
        self._target: str | int = text if camera is None else camera
        self.path: Path | None = None
        header_fps = 0.0
        if isinstance(self._target, int) or "://" in text:
            first, header_fps, count = self._open_live()
        else:
            self.path = Path(text)
            if not self.path.exists():
                from pftrack.io.atomic import refuse_dash, refuse_loop

                refuse_dash(text, "video source", name="video, image folder or sequence folder")
                refuse_loop(text, "video source")
                raise FileNotFoundError(f"video source not found: {self.path}")
            self.sequence = find_sequence(self.path)
            if self.sequence is not None and self.path.is_dir():
                video = sequence_video(self.path) if self.sequence.folder == self.path else None
                self.path = video or self.path  # SEQ/video.mp4 read as SEQ/img1 would be
            if self.path.is_dir():
                first, count = self._open_folder(self.path)
            elif self.live:
                first, header_fps, count = self._open_live()
            else:
                first, header_fps, count, self.rotation = self._probe_file(self.path)
                if count > 0 and header_fps > 0:  # OpenCV's estimate is duration x rate
                    self._span_ms = 1000.0 * count / header_fps
                self._broken = _avi_break(self.path)
                streams = _several_video_streams(self.path)
                if streams:  # OpenCV reads the first, without a word
                    warn_outside(
                        f"{self.name}: holds {len(streams)} video streams; the first, "
                        f"{streams[0]}, is read (OpenCV reads no other), not "
                        f"{', '.join(streams[1:])}: to track another, copy it to a file of "
                        "its own first (ffmpeg -i FILE -map 0:v:1 -c copy OUT.mkv: the "
                        "second)",
                        UserWarning,
                    )
        if self._broken is not None:  # before any work: said once for each source opened
            frames, offset = self._broken
            warn_outside(
                f"{self.name}: damaged inside: its AVI chunks break off after frame {frames} "
                f"(byte {offset}), and FFmpeg reads on from the next chunk it finds, numbering "
                f"the frames it reads by counting them: the frames after frame {frames} may "
                "carry the numbers of earlier ones (tracks, detections and ground truth apart "
                "there)",
                UserWarning,
            )
        self.n_frames = max(count, 0)
        self.count_known = self.n_frames > 0 and (
            self.path is not None
            and (self.path.is_dir() or self.path.suffix.lower() in COUNTED_SUFFIXES)
        )
        self._header_frames = self.counted_frames  # kept when a count replaces it (_warn_skip)
        seq_fps = self.sequence.frame_rate if self.sequence is not None else None
        if fps is not None:
            self.fps, self.fps_origin = float(fps), "given"
        elif seq_fps is not None:
            self.fps, self.fps_origin = float(seq_fps), "seqinfo.ini"
        elif header_fps and np.isfinite(header_fps) and 0 < header_fps < 1000:
            self.fps, self.fps_origin = float(header_fps), "container"
        elif (
            self.path is not None
            and not self.path.is_dir()
            and not self.live
            and (stamped := _stamped_rate(self.path)) is not None
        ):
            # no rate in the header, or a time base given as one (Matroska's 1000 "fps")
            self.fps, self.fps_origin = stamped, "time stamps"
        else:
            self.fps, self.fps_origin = DEFAULT_FPS, "default"
            if header_fps and not (np.isfinite(header_fps) and 0 < header_fps < 1000):
                warn_outside(
                    f"{self.name}: the header's frame rate {header_fps:g} is taken for none "
                    f"(a time base, not a rate?), nor do its time stamps give one below 1000: "
                    f"{DEFAULT_FPS:g} fps assumed; give the video's rate (--fps)",
                    UserWarning,
                )
        h, w = first.shape[:2]
        size = self._scaled_size(first)
        if min(size) < 1 or max(size) > MAX_SCALED_SIDE:
            if self._cap is not None:
                self._cap.release()
            made = (  # a scale nobody gave is not named (was "scale 1 makes the ...")
                f"the frames of {self.name} are {w}x{h} pixels"
                if self.scale == 1.0
                else f"scale {self.scale:g} makes the {w}x{h} frames of {self.name} "
                f"{size[0]}x{size[1]} pixels"
            )
            raise ValueError(f"{made}; expected 1 to {MAX_SCALED_SIDE} pixels a side")
        first = self._resize(first)
        self.height, self.width = int(first.shape[0]), int(first.shape[1])
        if self.live:
            self._replay.append(first)

    def _open_folder(self, path: Path) -> tuple[NDArray[Any], int]:
        folder = _image_folder(path, self.sequence)
        images = image_files(folder)
        if not images:
            seq = self.sequence
            own = seq is not None and _same_folder(folder, seq.folder / seq.image_dir)
            raise ValueError(_no_images(folder, seq if own and not any(folder.iterdir()) else None))
        videos = video_files(folder)
        if videos:  # was passed over without a word
            names = ", ".join(p.name for p in videos[:3]) + (", ..." if len(videos) > 3 else "")
            warn_outside(
                f"{folder} holds {len(images)} images and {len(videos)} video"
                f"{'s' * (len(videos) != 1)} ({names}): the images are the frames; give a "
                "video's own path to track it",
            )
        seq = self.sequence
        own = seq is not None and _same_folder(folder, seq.folder / seq.image_dir)
        if own:
            images = _frames_only(folder, images)
        numbered = _frame_order(folder, images, seq if own else None)
        self._images = numbered or _natural_order(folder, images)
        self.gap = _gap(folder, self._images)
        self._folder = folder
        for k, path in enumerate(self._images):
            try:
                first = self._open_depth(folder, path)
            except _Unreadable as unread:  # a black frame stands in for it (_iter_stored)
                self._bad[k] = unread
                continue
            self._image_shape = (int(first.shape[0]), int(first.shape[1]))
            self.lead_black = k
            odd = _odd_size(self._images, k)  # before any work (was: when reached, minutes on)
            if odd is not None:
                image, (w, h), (w0, h0) = odd
                raise ValueError(
                    f"image {image} is {w}x{h} but {path.name} is {w0}x{h0}: "
                    "every image of a folder must have one size"
                )
            return first, len(self._images)
        if len(self._images) == 1:
            raise self._bad[0]
        raise ValueError(
            f"cannot read any of the {len(self._images)} images in folder {folder}: "
            f"{self._bad[0].path.name}: {self._bad[0].why}"
        )

    def _open_depth(self, folder: Path, path: Path) -> NDArray[Any]:
        """A folder's first image, 8-bit; sets :attr:`bits` when it is 16-bit of fewer bits.

        16-bit images whose values use only the low bits (10- or 12-bit camera data) become
        almost black as OpenCV reads them in colour (value / 256): they are read at the depth
        of the largest value of the images :func:`_depth_sample` picks (the first, the last and
        up to seven evenly spaced between), :func:`_bit_depth` of it, for the whole folder: a
        dark first image (a lens cap, a night start) does not decide it alone. 8-bit and
        full-range 16-bit images are read as OpenCV reads them, the same pixels as ever.
        """
        unsaid: list[str] = []  # the decoders' notes: said when the images are read as frames
        first = read_image_depth(path, notes=unsaid)
        if first is None:
            raise _unreadable(path, unsaid)
        if first.dtype == np.uint8:  # the pixels read_image gives
            self._eight_bit = True
            return first
        top = int(first.max()) if first.dtype == np.uint16 else 65535
        brightest = path
        images = self._images or [path]
        sample = _depth_sample(len(images))
        for k in sample[1:]:
            if _bit_depth(top) == 16:
                break
            other = read_image_depth(images[k], notes=unsaid)  # unreadable: refused when read
            if other is not None and other.dtype == np.uint16 and int(other.max()) > top:
                top, brightest = int(other.max()), images[k]
        bits = _bit_depth(top)
        if bits == 16:  # full range, or another depth: as OpenCV reads it (a float TIFF: refused)
            again = read_image(path, notes=unsaid)
            if again is None:
                raise _unreadable(path, unsaid)
            return again
        self.bits = bits
        self._depth_from = (
            "from the first's values"
            if len(sample) == 1
            else f"from the values of {len(sample)} of its {len(images)} images"
        )
        self._depth_note = (
            f"{folder}: its 16-bit images hold {bits}-bit values ({brightest.name} goes up to "
            f"{top} of 65535): read as {bits}-bit data, each value / {1 << (bits - 8)} to 8 "
            "bits (not / 256, which makes them almost black)"
        )
        return self._to_8_bits(first, path)

    def _to_8_bits(self, image: NDArray[Any], path: Path) -> NDArray[np.uint8]:
        """A 16-bit `image` of :attr:`bits` bits as 8 bits; brighter pixels white (said once)."""
        bits = self.bits or 16
        limit = (1 << bits) - 1
        top = int(image.max())
        if top > limit:
            image = np.minimum(image, limit)
            if not self._clipped:
                self._clipped = True
                warn_outside(
                    f"image {path} goes up to {top}, past the {bits} bits its folder's 16-bit "
                    f"images are read at ({self._depth_from}): its brighter pixels are clipped "
                    "to white",
                    UserWarning,
                )
        return np.asarray(np.right_shift(image, bits - 8), dtype=np.uint8)

    @staticmethod
    def _probe_file(path: Path) -> tuple[NDArray[Any], float, int, int]:
        """The first frame, the header's rate and count, and the rotation OpenCV applies."""
        cap = _file_capture(str(path))
        try:
            if cap.isOpened() and _fourcc(cap) == TEXT_FOURCC:
                raise ValueError(
                    f"not a video: {path} is a text file (FFmpeg decodes text as ANSI-art frames)"
                )
            ok, first = cap.read() if cap.isOpened() else (False, None)
            fps = float(cap.get(cv2.CAP_PROP_FPS)) if cap.isOpened() else 0.0
            for _ in range(RESUME_TRIES if cap.isOpened() and not ok else 0):
                # its first frames damaged (a key frame overwritten): FFmpeg decodes on from
                # the next key frame, black frames standing in before it (_iter_stored); was
                # "not a video OpenCV can read", of a file whose later frames all decode
                ok, first = cap.read()
                if ok:
                    if not fps > 0:  # no rate: which frame it is cannot be told
                        raise ValueError(
                            f"cannot decode the first frames of {path} (damaged?): later "
                            "frames decode, but without a frame rate in its header their "
                            "numbers are not known; re-encode the video from its first "
                            "frame that decodes"
                        )
                    break
            count = int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) if cap.isOpened() else 0
            # the display matrix OpenCV applies (CAP_PROP_ORIENTATION_AUTO is on by default)
            turn = int(cap.get(cv2.CAP_PROP_ORIENTATION_META)) if cap.isOpened() else 0
        finally:
            cap.release()
        if not ok or first is None:
            try:  # a file that cannot be opened says why (was: "not a video", of a video the
                path.open("rb").close()  # user may not read; a user trial)
            except OSError as exc:
                raise ValueError(f"cannot read {path}: {exc.strerror}") from None
            if _iso_without_index(path):  # was: "not a video OpenCV can read, or empty"
                raise ValueError(
                    f"cannot decode a frame from {path}: it holds video data but no index (its "
                    "moov box), which an MP4 or MOV file gets when it is finished: a recording "
                    "stopped before that (a camera or ffmpeg killed, a copy cut short)? No "
                    "player reads it as it is; a tool such as untrunc rebuilds the index from "
                    "an intact file of the same camera and settings"
                )
            raise ValueError(
                f"cannot decode a frame from {path}: not a video OpenCV can read, or empty"
            )
        return first, fps, count, turn % 360 if turn % 90 == 0 else 0

    def _open_live(self) -> tuple[NDArray[Any], float, int]:
        what = "camera" if isinstance(self._target, int) else "stream"
        if isinstance(self._target, int):
            cap = cv2.VideoCapture(self._target)
        elif "://" in self._target:  # a URL OpenCV's binding cannot take crashes it
            cap = cv2.VideoCapture(utf8_name(self._target, "stream URL"), cv2.CAP_FFMPEG)
        else:  # a named pipe, under any name (opencv_io)
            with opencv_name(self._target) as name:
                cap = cv2.VideoCapture(name, cv2.CAP_FFMPEG)
        ok, first = cap.read() if cap.isOpened() else (False, None)
        if not ok or first is None:
            cap.release()
            raise ValueError(f"cannot read a frame from {what} {self.name}")
        self._cap = cap
        return first, float(cap.get(cv2.CAP_PROP_FPS)), 0

    def _scaled_size(self, frame: NDArray[Any]) -> tuple[int, int]:
        """(width, height) of `frame` at :attr:`scale`."""
        return round(frame.shape[1] * self.scale), round(frame.shape[0] * self.scale)

    def _resize(self, frame: NDArray[Any]) -> NDArray[np.uint8]:
        if self.scale != 1.0:
            frame = cv2.resize(frame, self._scaled_size(frame), interpolation=cv2.INTER_LINEAR)
        return np.asarray(frame, dtype=np.uint8)  # OpenCV's colour reads are uint8: no copy

    def _read_image(self, path: Path) -> NDArray[np.uint8]:
        """One image of a folder, resized; ValueError if unreadable or not the first's size.

        At :attr:`bits` when the folder's images set it (the first read says so, once). A 16-bit
        PNG or TIFF in a folder whose first image is 8-bit is refused, naming it (was: read as
        OpenCV reads it, value / 256: 10- or 12-bit data almost black, without a word).
        """
        if self._depth_note is not None:
            note, self._depth_note = self._depth_note, None
            warn_outside(note)
        img: NDArray[Any] | None
        notes: list[str] = []  # what its decoder prints on stderr (libpng, libjpeg)
        if self._eight_bit and path.suffix.lower() in DEEP_SUFFIXES:
            img = read_image_depth(path, notes=notes)  # an 8-bit image: read_image's pixels
            if img is not None and img.dtype == np.uint16:
                first = self._images[self.lead_black].name if self._images else "the first image"
                raise ValueError(
                    f"image {path} is 16-bit but {first}, the folder's first, is 8-bit: a "
                    "folder's images must have one depth (its 16-bit images are read at the "
                    "depth their values show only when the first is 16-bit); convert them to one"
                )
            if img is not None and img.dtype != np.uint8:  # a float TIFF: refused below
                img = read_image(path, notes=notes)
        elif self.bits is None:
            img = read_image(path, notes=notes)
        else:
            img = read_image_depth(path, notes=notes)
            if img is not None and img.dtype == np.uint16:
                img = self._to_8_bits(img, path)
            elif img is not None and img.dtype != np.uint8:
                img = read_image(path, notes=notes)
        if img is None:
            raise _unreadable(path, notes)
        if not self._cut_said and path.suffix.lower() in (".jpg", ".jpeg") and _cut_jpeg(path):
            self._cut_said = True
            warn_outside(
                f"image {path} has no JPEG end marker (a truncated file?): what is missing is "
                "decoded as flat grey, and tracked as it is (said once a run)",
                UserWarning,
            )
        for note in notes:  # each once a run, naming the image (was: on stderr, no file named)
            if note in self._decoder_said or (self._cut_said and note == JPEG_CUT_NOTE):
                continue  # a cut JPEG: said above
            self._decoder_said.add(note)
            warn_outside(
                f"image {path}: its decoder says {note!r} (the image is read all the same; "
                "said once a run)",
                UserWarning,
            )
        if img.shape[:2] != self._image_shape:
            h0, w0 = self._image_shape
            first = self._images[self.lead_black].name if self._images else "the first image"
            raise ValueError(
                f"image {path} is {img.shape[1]}x{img.shape[0]} but {first} is {w0}x{h0}: "
                "every image of a folder must have one size"
            )
        return self._resize(img)

    @property
    def counted_frames(self) -> int:
        """`n_frames` when it is the number of frames (`count_known`), else 0 (unknown).

        What a check that refuses frames past the last one, or says a video ended early,
        holds to.
        """
        return self.n_frames if self.count_known else 0

    def frames_to(self, needed: int) -> int:
        """`counted_frames`, or the frames counted when a header says fewer than `needed`.

        A video's header count may be short of its frames (an AVI whose recorder stopped
        before its last header update, or whose header another tool wrote): a check that
        would refuse frame `needed` past the header's last frame, as not the video's, first
        counts the file's frames (:meth:`recount`). An image folder's count, 0 (not known) and
        a header count of `needed` or more are returned as they are.
        """
        header = self.counted_frames
        if not 0 < header < needed or self._images is not None or self.path is None:
            return header
        return self.recount()

    def recount(self) -> int:
        """The frames of a video file, counted (grabbed: decoded, not converted); `n_frames`.

        For a header count found wrong: too few (:meth:`frames_to`), or too many (frames
        asked for past the video's end, :func:`pftrack.detection.bootstrap.bootstrap_frames`).
        A count other than the header's becomes `n_frames`, with a warning naming both. An
        image folder's count, and a live source's 0, are returned as they are.
        """
        if self._images is not None or self.path is None or self.live:
            return self.n_frames
        cap = _file_capture(str(self.path))
        found = 0
        last_ms: float | None = None  # the last frame's time stamp
        rate = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
        timed = rate > 0  # as _iter_stored: the stamps give the frames' indexes, so far
        start = 0  # the first frame's stamp, in frames
        try:
            while True:
                if cap.grab():
                    if timed:
                        stamp = _stamp_index(cap, rate)
                        if found == 0:
                            start = stamp
                        elif stamp - start > found:  # frames a decoder dropped without
                            start = stamp - found  # failing (H.264): counted on, as read
                        elif stamp - start != found:
                            timed = False  # not a constant-rate file: no resuming
                    found += 1
                    last_ms = float(cap.get(cv2.CAP_PROP_POS_MSEC))
                    continue
                # a frame inside that fails to decode: reading goes on past it, with the
                # frame before standing in (_iter_stored), so the count does too (was: the
                # frames before it taken as the video's, a run cut there, "it holds 14")
                if not timed or found >= self.n_frames:
                    break
                resumed = _resume(
                    cap, rate, start, found, self.n_frames, lambda: (cap.grab(), None)
                )
                if resumed is None:
                    break
                found = resumed[0] + 1
                last_ms = float(cap.get(cv2.CAP_PROP_POS_MSEC))
        finally:
            cap.release()
        header = self.counted_frames
        if not header and found < self.n_frames and not self._warned_short:
            # fewer than the estimate: by its duration, a Matroska file cut short? (was: the
            # spread bootstrap's recount took the frames counted as the video's, unsaid)
            self._warn_frame_count(found, last_ms)
        if found != self.n_frames:
            self.n_frames, self.count_known = found, True
            if header:  # an estimate (Matroska's) is no header count to correct
                why = "the header is wrong" if found > header else "a truncated or damaged file"
                warn_outside(
                    f"{self.path}: its header says {counted(header, 'frame')} but it holds "
                    f"{found} (counted): {why}, the count is taken",
                    UserWarning,
                )
        return self.n_frames

    def __len__(self) -> int:
        return self.n_frames

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        self._refuse_stopped()  # here, at iter(), not at the first next()
        return self._iterate()

    def _iterate(self) -> Generator[NDArray[np.uint8], None, None]:
        frames = self._iter_live() if self.live else self._iter_stored()
        try:
            for frame in frames:
                if self.stopped:
                    return
                yield frame
        finally:
            frames.close()  # a video file's capture is released now, not when collected

    def frames_at(
        self,
        indices: Iterable[int],
        *,
        split: bool = False,
        prepare: Callable[[NDArray[np.uint8]], NDArray[np.uint8]] | None = None,
    ) -> list[NDArray[np.uint8]]:
        """The frames at 0-based `indices` (in increasing order, each once), read in one pass.

        The same pixels as iterating and keeping those frames: a folder reads only those
        images; a video file is decoded in order (seeking is not frame-exact in every
        container, and costs a decode from the previous key frame anyway), but the frames in
        between are only grabbed (``VideoCapture.grab``: decoded, not converted to BGR or
        copied to Python). An intra-only file (MJPEG) whose undecoded frames would cost more
        than importing PyAV decodes only the wanted frames, each from its own packet, with
        PyAV (:mod:`pftrack.io.packets`: the same pixels; a 1280x720 AVI's 30 of 300 frames in
        0.13-0.20 s of CPU, not 0.67-0.72 s). Indices past the last frame are left out.

        With `split`, a file's pass runs as two halves at once, the second on a thread of its
        own from a seek (for an idle second core: about half the time when seeking is cheap):
        to just past the key frame that makes the longer half shortest, when the file's packets
        say where its key frames are (:func:`_split_point`; the seek decodes from the key frame
        before it), else to the middle wanted frame. The second half is kept only if its
        first two frames are the first half's, pixel for pixel and time stamp for time stamp;
        otherwise the first half reads on, so the frames are those of the plain pass either way.

        With `prepare`, each frame is passed to it as it is read and its result kept instead
        (``Tracker.working_frame``: the frames are held at the working size, not their own).

        Raises
        ------
        ValueError
            For a live source (it can only be read in order, once), a negative index, or a
            source stopped (:meth:`stop`).
        """
        wanted = sorted({int(i) for i in indices})
        if wanted and wanted[0] < 0:
            raise ValueError(f"frame index is {wanted[0]}, expected >= 0")
        if self.live:
            raise ValueError(f"live source {self.name} cannot be read at chosen frames")
        self._refuse_stopped()
        if not wanted:
            return []
        keep = prepare if prepare is not None else _as_read
        if self._images is not None:
            out, lost = [], list[int]()
            for i in (i for i in wanted if i < len(self._images)):
                out.append(keep(self._image_frame(i, lost)))
            self._warn_unread(lost, at_end=True)
            return out
        try:
            return self._file_frames_at(wanted, split, keep)
        except _DamagedInside:
            # a frame inside the video failed to decode, which ends a pass of grabs: read as
            # iterating reads (the frame before stands in, the later frames keep their
            # numbers), not fewer frames (was: the spread bootstrap's frames all before it)
            return self._iterated_at(wanted, keep)

    def _iterated_at(self, wanted: list[int], keep: _Prepare) -> list[NDArray[np.uint8]]:
        """The frames at `wanted` (increasing) as iterating the file gives them, stand-ins too.

        The reader says the first failure as it reads on after it (:meth:`_warn_lost`, once a
        source, naming the user's line), and when the last of `wanted` is the last frame
        counted (the spread bootstrap's) the pass reads on to its end, which says any later
        ones: a stand-in among the chosen frames was not said (was: said only by a later pass
        over the whole file, after a run had tracked it).
        """
        kept, out = set(wanted), []
        to_end = wanted[-1] >= self.n_frames - 1  # at most a frame's grab more
        frames = self._iter_stored()
        try:
            for i, frame in enumerate(frames):
                if i in kept:
                    out.append(keep(frame))
                if i >= wanted[-1] and not to_end:
                    break
        finally:
            frames.close()
        return out

    def _file_frames_at(
        self, wanted: list[int], split: bool, keep: _Prepare
    ) -> list[NDArray[np.uint8]]:
        """:meth:`frames_at` of a video file, in one pass of grabs (two with `split`)."""
        cap = _file_capture(str(self.path))
        try:
            fast = self._intra_frames_at(cap, wanted)
            if fast is not None:
                return [keep(self._resize(frame)) for frame in fast]
            middle = wanted[len(wanted) // 2]
            if not split or len(wanted) < 4 or middle < 2:
                return self._read_at(cap, 0, wanted, prepare=keep)[0]
            # the halves' lengths from where the seek lands (the same frames from any point)
            middle = _split_point(self.n_frames, middle, _key_frames(str(self.path), self.n_frames))
            first = [i for i in wanted if i <= middle + 1]
            # an interrupt (Ctrl-C; SIGTERM, raised here by pftrack.cli._signals) stops the
            # second half at its next frame: the pool's join waited for it to read its whole
            # half (minutes of a long video), SIGTERM ignored meanwhile
            halt = threading.Event()
            with ThreadPoolExecutor(1, thread_name_prefix="pftrack-bootstrap") as pool:
                tail = pool.submit(self._read_from_seek, middle, wanted, halt, prepare=keep)
                try:
                    head, check, at = self._read_at(cap, 0, first, middle, prepare=keep)
                    second = tail.result()
                except BaseException:
                    halt.set()
                    # waited for through a second Ctrl-C: the pool's join, cut short, left its
                    # thread inside OpenCV as the process exited, which aborted it
                    done = threading.Event()
                    tail.add_done_callback(lambda _: done.set())
                    wait_through_interrupts(done)
                    raise
            if second is not None and len(check) == 2 and _same_frames(check, second[1]):
                return head[: sum(i < middle for i in first)] + second[0]
            rest, _, _ = self._read_at(cap, at, [i for i in wanted if i > middle + 1], prepare=keep)
            return head + rest
        finally:
            cap.release()

    def _intra_frames_at(
        self, cap: cv2.VideoCapture, wanted: list[int]
    ) -> list[NDArray[np.uint8]] | None:
        """The raw frames at `wanted` of an intra-only file (MJPEG), decoding only them; or None.

        :func:`pftrack.io.packets.intra_frames_at`, for a file whose frames are as its header
        counts them (no damage, no black stand-ins, no turn) and the pixels it leaves undecoded
        pay for importing PyAV. Its first frame must equal, pixel for pixel, the one a capture
        of its own reads; else None (the OpenCV pass reads). `cap` is only asked its codec and
        frame size, and left where it stands.
        """
        if (
            _fourcc(cap) not in INTRA_FOURCCS
            or not self.count_known
            or self.rotation
            or self.lead_black
            or self._broken is not None
            or self.path is None
            or wanted[-1] >= self.n_frames
        ):
            return None
        left = (self.n_frames - len(wanted)) * cap.get(cv2.CAP_PROP_FRAME_WIDTH)
        if left * cap.get(cv2.CAP_PROP_FRAME_HEIGHT) < PACKET_PASS_MIN_PIXELS:
            return None
        frames = intra_frames_at(str(self.path), sorted({0, *wanted}), self.n_frames, self._stop)
        if frames is None or len(frames) != len(wanted) + (wanted[0] != 0):
            return None
        check = _file_capture(str(self.path))
        try:
            ok, first = check.read()
        finally:
            check.release()
        if not ok or not np.array_equal(first, frames[0]):
            return None
        return frames if wanted[0] == 0 else frames[1:]

    def _stop(self) -> bool:
        """Whether :meth:`stop` was called (polled by a reader that takes a callable)."""
        return self.stopped

    def _read_at(
        self,
        cap: cv2.VideoCapture,
        start: int,
        keep: list[int],
        check: int | None = None,
        halt: threading.Event | None = None,
        *,
        prepare: _Prepare | None = None,
    ) -> tuple[list[NDArray[np.uint8]], list[tuple[bytes, float]], int]:
        """Read on from frame `start` (where `cap` stands) through the last of `keep`.

        Returns the frames at `keep`, resized (and passed through `prepare`); with `check`,
        the digests (:func:`_frame_digest`) of the raw frames `check` and `check + 1` with
        their time stamps (the pass then goes on to them); and the index of the frame `cap`
        stands at afterwards. Stops early, before its next frame, once
        :meth:`stop` is called or `halt` is set.
        """
        picked: list[NDArray[np.uint8]] = []
        seen: list[tuple[bytes, float]] = []
        stop = max(keep[-1] if keep else -1, -1 if check is None else check + 1) + 1
        wanted = set(keep)
        i = start
        while i < stop and not self.stopped and not (halt is not None and halt.is_set()):
            compare = check is not None and check <= i <= check + 1
            if i in wanted or compare:
                ok, frame = cap.read()
                if not ok:
                    break
                if i in wanted:
                    resized = self._resize(frame)
                    picked.append(resized if prepare is None else prepare(resized))
                if compare:
                    seen.append((_frame_digest(frame), float(cap.get(cv2.CAP_PROP_POS_MSEC))))
            elif not cap.grab():
                break
            i += 1
        else:
            return picked, seen, i
        if i < self.counted_frames and any(cap.grab() for _ in range(RESUME_TRIES)):
            raise _DamagedInside(i)  # frames decode after it: not the video's end
        return picked, seen, i

    def _read_from_seek(
        self,
        middle: int,
        wanted: list[int],
        halt: threading.Event | None = None,
        *,
        prepare: _Prepare | None = None,
    ) -> tuple[list[NDArray[np.uint8]], list[tuple[bytes, float]]] | None:
        """The second half of a split pass: frames from `middle` on, after a seek to it.

        None when the file cannot seek (or OpenCV fails on it): the first half reads on. Ends
        at its next frame once `halt` is set (the first half was interrupted).
        """
        cap = _file_capture(str(self.path))
        try:
            if not cap.set(cv2.CAP_PROP_POS_FRAMES, middle):
                return None
            keep = [i for i in wanted if i >= middle]
            picked, seen, _ = self._read_at(cap, middle, keep, middle, halt, prepare=prepare)
            return picked, seen
        except cv2.error:
            return None
        finally:
            cap.release()

    def stop(self) -> None:
        """End every read under way before its next frame (safe to call from a signal handler).

        For good: a run reads a source in up to three passes (its bootstrap frames, a live
        source's replay, the tracking pass), and one Ctrl-C ends them all. A read begun after
        it (an iteration, :meth:`frames_at`, a :class:`FrameSequence` item) is a ValueError
        naming the source (was: no frame, without a word); a new FrameSource reads it again.
        """
        self.stopped = True

    def _refuse_stopped(self) -> None:
        """Raise the ValueError of a read begun after :meth:`stop`."""
        if self.stopped:
            raise ValueError(
                f"{self.name}: stopped (FrameSource.stop() was called); "
                "a new FrameSource reads it again"
            )

    def _iter_images(self, images: list[Path]) -> Generator[NDArray[np.uint8], None, None]:
        """An image folder's frames: an image that cannot be read stands in by the frame before."""
        lost: list[int] = []
        last: NDArray[np.uint8] | None = None
        for i in range(len(images)):
            last = self._image_frame(i, lost, last)
            yield last
        self._warn_unread(lost, at_end=True)

    def _iter_stored(self) -> Generator[NDArray[np.uint8], None, None]:
        if self._images is not None:
            yield from self._iter_images(self._images)
            return
        cap = _file_capture(str(self.path))
        decoded = 0  # frames yielded, stand-ins included: the next frame's index
        rate = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
        timed = rate > 0  # the frames' time stamps give their indexes, so far
        start = 0  # the first frame's stamp, in frames (PETS09's is 2; 0 if it fails)
        lost: list[int] = []
        stamps: list[float] = []  # of the frames decoded, in ms (_uneven_steps)
        check = UNEVEN_FIRST_CHECK  # the stamps looked at for a variable rate at this many
        last: NDArray[np.uint8] | None = None
        skip: tuple[int, int] | None = None  # the frame whose stamp first left the count
        try:
            while True:
                ok, frame = cap.read()
                if ok:
                    stamps.append(float(cap.get(cv2.CAP_PROP_POS_MSEC)))
                    if len(stamps) >= check and not self._warned_uneven:
                        check *= 2  # as soon as the stamps show it, not at the end only
                        self._warn_uneven(stamps, whole=False)
                # a frame's number is its place in the decoded order, as a detector's loop
                # counts it; the stamps only say, after a frame that fails, where to go on
                if ok and timed:
                    stamp = _stamp_index(cap, rate)
                    if decoded == 0:
                        start = stamp
                        if start > 0:
                            self._warn_cut_start(start, float(cap.get(cv2.CAP_PROP_POS_MSEC)))
                    elif stamp - start > decoded:  # frames a decoder dropped without failing
                        # (H.264): numbered by counting, as ever, and the stamps counted from
                        # here, so that a later frame that fails is read on past (recount
                        # alike); was: no resuming, the run ended there (stop 66's flip_h.mp4)
                        skip = skip or (decoded, stamp - start)
                        start = stamp - decoded
                    elif stamp - start != decoded:
                        timed = False  # not a constant-rate file: no resuming after damage
                if not ok:
                    if not timed or decoded >= self.n_frames:
                        break
                    resumed = _resume(cap, rate, start, decoded, self.n_frames, cap.read)
                    if resumed is None:
                        break
                    index, frame = resumed
                    # no step across the frames that failed (a nan: left out), whose stamps
                    # are missing: a damaged file's are no variable frame rate's (was: said
                    # of a 10 fps file with 2 frames lost in 30, "100 to 300 ms apart")
                    stamps += [math.nan, float(cap.get(cv2.CAP_PROP_POS_MSEC))]
                    if last is None:  # its first frames: a black frame stands in for each
                        last = np.zeros_like(self._resize(frame))
                        self._warn_lead(index)
                    else:
                        lost.extend(range(decoded, index))
                        self._warn_lost(lost, at_end=False)  # before its stand-ins
                    for _ in range(decoded, index):  # the damaged frames: the last good one
                        decoded += 1
                        yield last
                decoded += 1
                last = self._resize(frame)
                yield last
        finally:
            cap.release()
        self._warn_lost(lost, at_end=True)
        if skip is not None and decoded < self._header_frames:  # not a variable rate's step
            self._warn_skip(*skip)
        if not self._warned_short:  # read to the end (a stopped reader never gets here)
            self._warn_frame_count(decoded, stamps[-1] if stamps else None)
        if not self._warned_uneven:
            self._warn_uneven(stamps, whole=True)

    def _warn_lost(self, lost: list[int], *, at_end: bool) -> None:
        """Warn that the frames `lost` (0-based) inside the video could not be decoded.

        Between frames (`at_end` False: as the reader goes on after a failure, before it gives
        the stand-ins), once a source: a loop over the source, or a run under ``-W error``,
        learns it at that frame (was: only once the pass had read every frame; never, for a
        ``"first"`` bootstrap's pass that stops after its frames). At the end of a pass, the
        whole pass's frames, only if they are more than those said already (a later failure):
        the same thing is never said twice.
        """
        if not lost or (not at_end and self._said_lost) or set(lost) <= self._said_lost:
            return
        self._said_lost |= frozenset(lost)  # first: said once, raised as an error or not
        kept = (  # not where FFmpeg numbers the frames after the break by counting them
            ", so the later frames keep their numbers" if self._broken is None else ""
        )
        warn_outside(
            f"{self.path}: {_frame_list(lost)} could not be decoded (a damaged file?): the "
            f"frame before stands in for each{kept}",
            UserWarning,
        )

    def _image_frame(
        self, i: int, lost: list[int], before: NDArray[np.uint8] | None = None
    ) -> NDArray[np.uint8]:
        """Image `i` of the folder as a frame; if it cannot be read, the frame that stands in.

        The frame before (`before`, when the caller holds it; else the nearest image before
        `i` that can be read), or a black frame when none before it can be (the folder's first
        images: :attr:`lead_black`), as a video's frames that fail to decode (was: the run
        ended with an error, every frame tracked before it lost; a user trial). `i` is added
        to `lost` and said (:meth:`_warn_unread`) before its stand-in is given.
        """
        frame = self._try_image(i)
        if frame is not None:
            return frame
        lost.append(i)
        self._warn_unread(lost, at_end=False)
        if before is not None:
            return before
        for j in range(i - 1, -1, -1):
            frame = self._try_image(j)
            if frame is not None:
                return frame
        return np.zeros((self.height, self.width, 3), np.uint8)

    def _try_image(self, i: int) -> NDArray[np.uint8] | None:
        """Image `i` of the folder, read (:meth:`_read_image`); None if it cannot be (kept)."""
        assert self._images is not None
        if i in self._bad:  # not read again: a pass's stand-ins are those of every other pass
            return None
        try:
            return self._read_image(self._images[i])
        except _Unreadable as error:
            self._bad[i] = error
            return None

    def _warn_unread(self, lost: list[int], *, at_end: bool) -> None:
        """Warn that the images at `lost` (0-based) could not be read (stand-ins given).

        As :meth:`_warn_lost` says a video's frames: the first as it is met, naming its file
        and why; at the end of a pass, the pass's count and first names, only if more than
        those said already. The same thing is never said twice.
        """
        if not lost or (not at_end and self._said_bad) or set(lost) <= self._said_bad:
            return
        self._said_bad |= frozenset(lost)
        black = sum(i < self.lead_black for i in lost)
        if not at_end:
            error = self._bad[lost[0]]
            stand = (
                "a black frame (no image before it can be read)" if black else "the frame before"
            )
            warn_outside(
                f"frame {lost[0] + 1}: {error}; {stand} stands in for it, so the later frames "
                "keep their numbers",
                UserWarning,
            )
            return
        assert self._images is not None
        names = listed([self._images[i].name for i in lost])
        first = f" (a black frame for {_frame_list(lost[:black])}: no image before it can be read)"
        warn_outside(
            f"{self._folder}: {counted(len(lost), 'image')} could not be read ({names}; "
            f"{_frame_list(lost)}): the frame before stands in for each{first * (black > 0)}",
            UserWarning,
        )

    def _warn_lead(self, index: int) -> None:
        """Warn, once, that the first `index` frames could not be decoded (stand-ins given)."""
        self.lead_black = index
        if self._warned_lead:
            return
        self._warned_lead = True
        warn_outside(
            f"{self.path}: {_frame_list(list(range(index)))} could not be decoded (a damaged "
            f"start?): a black frame stands in for each (the detector learns nothing from "
            f"one), so frame {index + 1}, the first that decodes, and the later frames keep "
            "their numbers (by their time stamps)",
            UserWarning,
        )

    def _warn_skip(self, decoded: int, index: int) -> None:
        """Warn, once, that the frame read as `decoded` (0-based) was stamped as frame `index`.

        A damaged H.264 packet can make FFmpeg's decoder drop its frame, and the frames that
        refer to it up to the next key frame, without failing a read: the stamps of the frames
        read so far were in step with their count, and jump (a packet overwritten in a 60-frame
        test file: frames 25-36 missing, 49 read). The frames are numbered as read, by
        counting, as before; this says that from frame `decoded` + 1 on they are early against
        tracks, detections or ground truth of the whole stream (was: only "its header says 60
        frames but it holds 49 (counted): a truncated or damaged file"). Said at the end of a
        whole pass, and only of a file whose header counts more frames than it read: a
        variable rate's longer step (a Matroska file's) is no loss, and a file whose index
        lost the packet as well (its header counts the frames it holds) cannot be told from
        one. Forward jumps only.
        """
        if self._warned_skip or not decoded < index < self._header_frames:
            return
        self._warned_skip = True
        warn_outside(
            f"{self.path}: the time stamps skip from frame {decoded} to frame {index + 1}: "
            f"{_frame_list(list(range(decoded, index)))} did not come from the decoder, without "
            "an error (a damaged H.264 stream drops a frame and the frames up to the next key "
            "frame); the later frames are numbered by counting, "
            f"{index - decoded} early against detections or ground truth of the whole video",
            UserWarning,
        )

    def _warn_cut_start(self, index: int, ms: float) -> None:
        """Warn, once, that the first `index` frames were left out by FFmpeg (a live cut).

        The first frame read is stamped `ms` after the stream's start (frame `index` + 1 of
        it), and the stream begins without a key frame (:func:`_starts_without_key_frame`):
        the frames before the first key frame could not be decoded, and FFmpeg dropped them
        (was: without a word, every frame number `index` off against a count from the
        stream's start). A stamp after the start with a key frame first is a decoder's delay,
        not missing frames (PETS09-S2L1's AVI: 200 ms, 2 frames at its header's 10 fps).
        """
        if self._warned_cut or self.path is None:
            return
        self._warned_cut = True
        if not _starts_without_key_frame(self.path):
            return
        warn_outside(
            f"{self.path}: the video stream begins without a key frame (cut from a live "
            f"stream?) and its first frame that decodes is stamped {ms:.0f} ms after its "
            f"start: {counted(index, 'frame')} before it appear to be missing (FFmpeg cannot "
            f"decode them and leaves them out), so frame 1 here is the stream's frame "
            f"{index + 1}; detections or ground truth numbered from the stream's start are "
            f"{index} ahead of these frames (drop their frames 1-{index} and number the rest "
            "from 1)",
            UserWarning,
        )

    def _warn_uneven(self, stamps: list[float], *, whole: bool) -> None:
        """Warn, once, if a video's time stamps show a variable frame rate (:func:`_uneven_steps`).

        `stamps` are those of its first frames (`whole` False: :data:`UNEVEN_FIRST_CHECK`, then
        twice as many, ... while it is read; the message gives their figures, ``its first 50
        frames are ...``), or of all its frames once read to its end, which decide. Only when
        its rate came from the file (or the default): a rate given or a sequence's is the one
        its frames are meant to have.
        """
        if self.fps_origin in ("given", "seqinfo.ini"):
            self._warned_uneven = True  # nothing to say, whatever the stamps
            return
        uneven = _uneven_steps(stamps)
        if whole or uneven is not None:
            self._warned_uneven = True  # said, or the stamps of one whole read decided: once
        if uneven is None:
            return
        lo, median, hi = uneven
        which = "frames" if whole else f"first {len(stamps)} frames"
        origin = {"container": "the header's", "time stamps": "from its first frames' stamps"}
        warn_outside(
            f"{self.path}: variable frame rate: its {which} are {lo:.3g} to {hi:.3g} ms apart "
            f"(median {median:.3g} ms), but it is read at one rate, {self.fps:g} fps "
            f"({origin.get(self.fps_origin, self.fps_origin)}): a video rendered from it plays "
            "its frames evenly spaced at that rate, and the tracker takes each step between "
            "frames as one frame's (give the rate to render at with --fps)",
            UserWarning,
        )

    def _warn_frame_count(self, decoded: int, last_ms: float | None = None) -> None:
        """Warn, once, if a video read to its end had other than its header's or seqLength's frames.

        A sequence's ``seqLength`` is checked against the frames read only for a video (an image
        folder's count is checked when it is opened): a video's header count may be wrong, and
        a second decoding pass to count its frames would cost as much as the run. A container
        without a frame count (Matroska, WebM, MPEG streams) says its duration instead: decoding
        that stopped more than a second (and 3 frames) before it, by the time stamp `last_ms`
        of the last frame decoded, is said too (was: a truncated Matroska file tracked to its
        cut without a word; its frame count, FFmpeg's estimate from the duration and a rate, is
        no count to hold a variable-rate file to, but the duration holds for any rate).
        """
        said = []
        header = self.counted_frames  # not FFmpeg's estimate (Matroska)
        short = decoded < header
        if short:
            said.append(f"its header says {header}")
        elif 0 < header < decoded and self.path is not None:
            self._warn_long(header, decoded)
        elif not header and self._span_ms is not None and last_ms is not None and decoded:
            step = self._span_ms / max(self.n_frames, 1)  # one frame, at the header's rate
            if self._span_ms - (last_ms + step) > max(3 * step, 1000.0):
                said.append(
                    f"its container says {self._span_ms / 1000:.1f} s (frame {decoded} is at "
                    f"{last_ms / 1000:.1f} s)"
                )
                short = True
        seq = self.sequence
        if seq is not None and seq.length is not None and decoded != seq.length:
            said.append(f"{seq.folder / 'seqinfo.ini'} says seqLength={seq.length}")
        if not said:
            return
        self._warned_short = True  # once, not on every pass
        damaged = ": a truncated or damaged file?" if short else ""
        warn_outside(
            f"{self.path} ended after {counted(decoded, 'frame')} but "
            f"{' and '.join(said)}{damaged}",
            UserWarning,
        )

    def _warn_long(self, header: int, decoded: int) -> None:
        """Warn that a video read to its end held more frames than its header says; count them.

        Every frame was read and tracked, but what was chosen from the header's count before
        the run was chosen from its first `header` frames only: the spread bootstrap's
        background frames (the built-in detector's), a progress bar's total (a user trial: an
        AVI whose header said 20 of its 40 frames gave tracks other than the mended file's,
        without a word; a frame asked for past the header's count was recounted and said,
        :meth:`recount`, but nothing asks when no detection lies past it). The count is taken,
        as :meth:`recount` takes it, for any later pass.
        """
        self.n_frames, self.count_known = decoded, True
        path = Path(self.name) if self.path is None else self.path  # a file: path is set
        warn_outside(
            f"{self.path}: its header says {counted(header, 'frame')} but {decoded} were read "
            f"to its end: the header is wrong, and what was chosen from its count before the "
            f"run was chosen from frames 1-{header} alone (the built-in detector's background, "
            f"from 30 frames spread over the video); every frame was tracked. Rewrite the "
            f"header for a run that sees the whole video: ffmpeg -i {path.name} -c copy "
            f"fixed{path.suffix}",
            UserWarning,
        )

    def _iter_live(self) -> Generator[NDArray[np.uint8], None, None]:
        if self._read_past_replay:
            raise ValueError(f"live source {self.name} was read already; open it again")
        yield from list(self._replay)
        while True:
            with _LIVE_CAPTURE:
                cap = self._cap
                if cap is None:
                    break
                self._reading = True
            try:
                ok, frame = cap.read()
            finally:
                with _LIVE_CAPTURE:
                    self._reading = False
                    closed = self._cap is None
                if closed:  # close() came during the read: released here, not under it
                    cap.release()
            if closed:
                break
            if not ok:
                self.close()
                break
            frame = self._resize(frame)
            if len(self._replay) < REPLAY_FRAMES:
                self._replay.append(frame)
            else:
                self._read_past_replay = True
                self._replay.clear()
            yield frame

    def close(self) -> None:
        """Release a live source's capture (files and folders hold nothing open).

        From another thread while one reads the source, the reader releases it when its
        ``read()`` returns, and stops (was: released under the read, a segmentation fault).
        """
        with _LIVE_CAPTURE:
            cap, self._cap = self._cap, None
            reading = self._reading
        if cap is not None and not reading:
            cap.release()

    def __enter__(self) -> FrameSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class FrameSequence(Sequence[NDArray[np.uint8]]):
    """The frames of a stored source as a sequence whose items are read when asked for.

    Indexed in increasing order, a video file is decoded once, from its start to the last
    frame asked for, holding one frame at a time (the frames in between are only grabbed, as
    :meth:`FrameSource.frames_at` does); an index lower than the last one asked for starts a
    new pass. An image folder reads only the images asked for. What
    :func:`pftrack.recovery.link_tracklets` takes for its colour term, instead of every frame
    of the video in memory (:func:`read_frames`).

    Parameters
    ----------
    source : FrameSource, str or os.PathLike
        A video file, an image folder or a sequence folder (not a live source).

    Raises
    ------
    ValueError
        A live source (it can be read only once, in order).

    Notes
    -----
    The length is :attr:`FrameSource.n_frames`: a video's header count. A video that ends
    before it fails on the first frame asked for past its end (ValueError naming both counts).
    """

    def __init__(self, source: FrameSource | PathLike) -> None:
        self.source = source if isinstance(source, FrameSource) else FrameSource(source)
        if self.source.live:
            raise ValueError(f"live source {self.source.name} cannot be read at chosen frames")
        self._cap: Any = None
        self._at = 0  # the index of the frame self._cap reads next
        self._last: tuple[int, NDArray[np.uint8]] | None = None
        # after a frame inside the video failed to decode (a pass of grabs ends there): its
        # frames as iterating reads them, stand-ins too, and the index of the next one
        self._stored: Generator[NDArray[np.uint8], None, None] | None = None
        self._stored_at = 0

    def __len__(self) -> int:
        return self.source.n_frames

    def __getitem__(self, index: Any) -> Any:
        """The frame at 0-based `index` (an int; negative counts from the end)."""
        if isinstance(index, slice):
            raise TypeError("FrameSequence takes one index, not a slice")
        i = operator.index(index)
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError(f"frame index {index} is out of range for {counted(n, 'frame')}")
        if self._last is not None and self._last[0] == i:
            return self._last[1]
        self.source._refuse_stopped()  # was: "the video ended after 0 frames"
        if self.source._images is not None:
            frame = self.source._image_frame(i, [])
        elif self._stored is None:
            if self._cap is None or i < self._at:  # a new pass from the start
                self.close()
                self._cap = _file_capture(str(self.source.path))
                self._at = 0
            try:
                picked, _, self._at = self.source._read_at(self._cap, self._at, [i])
            except _DamagedInside:
                # a frame inside the video failed to decode: read on as iterating reads (the
                # frame before stands in), from here on (was: "the video ended", an error)
                self.close()
                self._stored = self.source._iter_stored()
                return self[i]
            if not picked:
                ended = self._at  # before close() starts the count over
                self.close()
                raise ValueError(
                    f"{self.source.name}: frame {i + 1} cannot be decoded: the video ended after "
                    f"{counted(ended, 'frame')} but its header says {n}"
                )
            frame = picked[0]
        else:
            if i < self._stored_at:  # a new pass from the start
                self._stored.close()
                self._stored, self._stored_at = self.source._iter_stored(), 0
            while self._stored_at <= i:
                try:
                    got = next(self._stored, None)
                except Warning:  # made an error (-W error), the pass ended: a new one next time
                    self.close()
                    raise
                if got is None:
                    ended = self._stored_at
                    self.close()
                    raise ValueError(
                        f"{self.source.name}: frame {i + 1} cannot be decoded: the video ended "
                        f"after {counted(ended, 'frame')} but its header says {n}"
                    )
                frame, self._stored_at = got, self._stored_at + 1
        self._last = (i, frame)
        return frame

    def close(self) -> None:
        """Release the video file's decoder (a later item opens it again)."""
        if self._cap is not None:
            self._cap.release()
            self._cap = None
        self._at = 0
        if self._stored is not None:
            self._stored.close()
            self._stored, self._stored_at = None, 0

    def __enter__(self) -> FrameSequence:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_frames(source: PathLike, *, scale: float = 1.0) -> list[NDArray[np.uint8]]:
    """All frames of `source` in memory (fine for short sequences; see :class:`FrameSequence`)."""
    return list(FrameSource(source, scale=scale))
