"""Chosen frames of an intra-only video file, decoded from their own packets alone (PyAV).

The spread bootstrap wants 30 frames spread over a file. OpenCV gives the frame at an index
only by decoding every frame before it (its seeking is not frame-exact in every container), so
that pass decodes the whole file. In a file whose every frame is a key frame (MJPEG: a camera's
or OpenCV's ``MJPG`` AVI, the synthetic AVI videos) frame ``i`` is its ``i``-th packet, which
decodes on its own: reading the packets (no decoding) and decoding only the chosen ones gives
the same frames for a tenth of the work or less. A file of other codecs (H.264, MPEG-4 part 2)
predicts frames from others, and its pass stays OpenCV's.

PyAV decodes with FFmpeg, as OpenCV does, and ``to_ndarray(format="bgr24")`` converts as
OpenCV does: the same pixels, bit for bit, on every frame of PETS09 (H.264), TUD-Campus
(MPEG-4), a 1280x720 MJPEG AVI and the synthetic AVI (MJPEG) and MP4 (MPEG-4) videos
(docs/io.md). The caller still compares one frame with OpenCV's (another build of either
library could differ) and reads the OpenCV way when they differ.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["INTRA_FOURCCS", "PACKET_PASS_MIN_PIXELS", "intra_frames_at"]

#: OpenCV's four-character codes of intra-only codecs read this way (AVI's ``MJPG``, a
#: QuickTime file's ``jpeg``, ``mjpa``, ``AVRn``); PyAV must then also name the codec
#: ``mjpeg`` and flag every packet a key frame.
INTRA_FOURCCS = frozenset({"MJPG", "mjpg", "jpeg", "mjpa", "AVRn"})
#: Pixels of the frames left undecoded below which the packet pass does not pay: importing
#: PyAV costs about 0.05 s of CPU, about 2e7 pixels of MJPEG decoding (a 1280x720 frame
#: decodes in about 2.2 ms); twice that, so that it gains at least as much as it costs.
PACKET_PASS_MIN_PIXELS = 40_000_000
#: The decoded formats whose ``bgr24`` conversion was compared with OpenCV's, bit for bit.
SAME_PIXEL_FORMATS = frozenset({"yuv420p", "yuvj420p"})


def intra_frames_at(
    path: str,
    wanted: list[int],
    n_frames: int,
    stopped: Callable[[], bool] | None = None,
) -> list[NDArray[np.uint8]] | None:
    """The BGR frames at `wanted` of an intra-only video, each decoded from its own packet.

    Parameters
    ----------
    path : str
        A video file.
    wanted : list of int
        0-based frame indices, increasing, each once, all below `n_frames`.
    n_frames : int
        The file's frame count (its header's): the packets must be that many.
    stopped : callable, optional
        Polled before each frame: when it returns True, the frames so far are returned.

    Returns
    -------
    list of (H, W, 3) uint8 arrays, or None
        The frames as ``cv2.VideoCapture`` reads them; None when this way cannot promise
        that (PyAV missing or failing on the file, a codec other than MJPEG, a packet that is
        no key frame or empty, a packet count other than `n_frames`, a decoded format whose
        conversion was not compared with OpenCV's): read the file the OpenCV way.
    """
    try:
        import av
    except ImportError:  # pragma: no cover - PyAV is a dependency
        return None
    try:
        with av.open(path) as container:
            return _decode_wanted(container, wanted, n_frames, stopped)
    except (av.FFmpegError, OSError, ValueError):
        return None


def _decode_wanted(
    container: Any, wanted: list[int], n_frames: int, stopped: Callable[[], bool] | None
) -> list[NDArray[np.uint8]] | None:
    """:func:`intra_frames_at` of an open PyAV container."""
    if not container.streams.video:
        return None
    stream = container.streams.video[0]  # OpenCV's too: the first video stream
    if stream.codec_context.name != "mjpeg":
        return None
    stream.codec_context.thread_count = 1  # as OpenCV's pass: the calling thread decodes
    packets: list[Any] = []  # av.Packet, or None for one not wanted
    kept = set(wanted)
    for packet in container.demux(stream):
        if packet.size == 0 and packet.dts is None:
            continue  # the demuxer's end-of-stream packet
        if packet.size == 0 or not packet.is_keyframe:
            return None  # an empty (dropped) frame or a predicted one: not packet i = frame i
        packets.append(packet if len(packets) in kept else None)  # others: counted only
    if len(packets) != n_frames:
        return None
    out: list[NDArray[np.uint8]] = []
    for i in wanted:
        if stopped is not None and stopped():
            break
        frames = stream.codec_context.decode(packets[i])
        if len(frames) != 1 or frames[0].format.name not in SAME_PIXEL_FORMATS:
            return None
        out.append(frames[0].to_ndarray(format="bgr24"))
    return out
