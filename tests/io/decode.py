"""Reading back a written video: its codec, pixel format, rate and frames (PyAV)."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import NamedTuple

import av
import cv2
import numpy as np


class Info(NamedTuple):
    codec: str
    pix_fmt: str
    average_rate: Fraction | None


def decode(path: Path) -> tuple[Info, list[np.ndarray]]:
    """The video's codec, pixel format and rate, and its frames decoded (BGR)."""
    with av.open(str(path)) as container:
        stream = container.streams.video[0]
        frames = [f.to_ndarray(format="bgr24") for f in container.decode(stream)]
        ctx = stream.codec_context
        info = Info(ctx.name, ctx.pix_fmt, stream.average_rate)
    return info, frames


def capture_frames(path: Path) -> list[np.ndarray]:
    """Every frame of the video as ``cv2.VideoCapture`` reads it (OpenCV's own backend choice)."""
    cap = cv2.VideoCapture(str(path))
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame)
    cap.release()
    return frames


def grabs_before_failure(path: Path) -> int:
    """The frames ``cv2.VideoCapture`` grabs of the video before its first failure."""
    cap = cv2.VideoCapture(str(path))
    n = 0
    while cap.grab():
        n += 1
    cap.release()
    return n
