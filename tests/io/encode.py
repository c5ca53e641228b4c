"""Writing a test video with PyAV: frames in, one encoded video stream out (see decode.py)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import av
import numpy as np


def encode(
    path: Path,
    frames: Sequence[np.ndarray],
    rate: int = 10,
    *,
    codec: str = "libx264",
    options: Mapping[str, str] | None = None,
    container: str | None = None,
    rotation: int | None = None,
) -> Path:
    """`frames` (BGR, one size) encoded to `path` at `rate` frames per second; `path`.

    `options` are the encoder's (x264's ``g``: frames from one key frame to the next, ``bf``:
    B-frames), `container` FFmpeg's format name (None: from `path`'s extension), `rotation`
    the display matrix's turn in degrees counter-clockwise (a phone's portrait video). The
    pixel format is yuv420p (yuvj420p for MJPEG). PyAV's errors (an encoder this build
    lacks) pass to the caller.
    """
    with av.open(str(path), "w", format=container) as out:
        stream = out.add_stream(codec, rate=rate, options=dict(options or {}))
        stream.height, stream.width = frames[0].shape[:2]
        stream.pix_fmt = "yuvj420p" if codec == "mjpeg" else "yuv420p"
        if rotation is not None:
            stream.set_display_rotation(rotation)
        for frame in frames:
            out.mux(stream.encode(av.VideoFrame.from_ndarray(frame, format="bgr24")))
        out.mux(stream.encode())
    return path
