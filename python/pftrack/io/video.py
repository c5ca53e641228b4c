"""Frames from a video file or a folder of images (MOTChallenge ``img1/``), via OpenCV."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._typing import PathLike

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".webp")


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


class FrameSource:
    """Iterate over BGR uint8 frames of a video file or an image folder.

    Parameters
    ----------
    source : str or os.PathLike
        A video file OpenCV can decode, or a folder of images in natural order (``2.jpg``
        before ``10.jpg``; see :func:`natural_key`). A MOTChallenge sequence folder with an
        ``img1/`` sub-folder is accepted too.
    scale : float
        Resize factor applied to every frame (1 keeps the size).

    Raises
    ------
    FileNotFoundError
        If `source` does not exist.
    ValueError
        If it cannot be decoded, or holds no frame.
    """

    def __init__(self, source: PathLike, *, scale: float = 1.0) -> None:
        self.path = Path(source)
        if not self.path.exists():
            raise FileNotFoundError(f"video source not found: {self.path}")
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale is {scale}, expected a finite value > 0")
        self.scale = float(scale)
        self._images: list[Path] | None = None
        if self.path.is_dir():
            folder = self.path / "img1" if (self.path / "img1").is_dir() else self.path
            images = (p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
            self._images = sorted(images, key=lambda p: natural_key(p.name))
            if not self._images:
                raise ValueError(f"no images ({', '.join(IMAGE_SUFFIXES)}) in folder {folder}")
            first = cv2.imread(str(self._images[0]), cv2.IMREAD_COLOR)
            if first is None:
                raise ValueError(f"cannot read image {self._images[0]}")
            self.n_frames = len(self._images)
            self.fps = 25.0
        else:
            cap = cv2.VideoCapture(str(self.path))
            ok, first = cap.read() if cap.isOpened() else (False, None)
            fps = cap.get(cv2.CAP_PROP_FPS) if cap.isOpened() else 0.0
            count = int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) if cap.isOpened() else 0
            cap.release()
            if not ok or first is None:
                raise ValueError(
                    f"cannot decode a frame from {self.path}: not a video OpenCV can read, or empty"
                )
            self.n_frames = max(count, 0)
            self.fps = fps if fps and np.isfinite(fps) and fps > 0 else 25.0
        first = self._resize(first)
        self.height, self.width = int(first.shape[0]), int(first.shape[1])

    def _resize(self, frame: NDArray[Any]) -> NDArray[np.uint8]:
        if self.scale != 1.0:
            size = (round(frame.shape[1] * self.scale), round(frame.shape[0] * self.scale))
            frame = cv2.resize(frame, size, interpolation=cv2.INTER_LINEAR)
        return np.asarray(frame, dtype=np.uint8)  # OpenCV's colour reads are uint8: no copy

    def __len__(self) -> int:
        return self.n_frames

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        if self._images is not None:
            for p in self._images:
                img = cv2.imread(str(p), cv2.IMREAD_COLOR)
                if img is None:
                    raise ValueError(f"cannot read image {p}")
                yield self._resize(img)
            return
        cap = cv2.VideoCapture(str(self.path))
        try:
            while True:
                ok, frame = cap.read()
                if not ok:
                    break
                yield self._resize(frame)
        finally:
            cap.release()


def read_frames(source: PathLike, *, scale: float = 1.0) -> list[NDArray[np.uint8]]:
    """All frames of `source` in memory (fine for short sequences)."""
    return list(FrameSource(source, scale=scale))
