"""Frame sources: image folders are read in natural order."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from pftrack.io.video import FrameSource, natural_key


def test_natural_key_orders_numbers_as_numbers() -> None:
    names = ["10.jpg", "2.jpg", "1.jpg", "frame_11.png", "frame_9.png", "1b.jpg", "1a.jpg"]
    assert sorted(names, key=natural_key) == [
        "1.jpg", "1a.jpg", "1b.jpg", "2.jpg", "10.jpg", "frame_9.png", "frame_11.png"
    ]  # fmt: skip


def test_unpadded_image_folder_plays_in_order(tmp_path: Path) -> None:
    """Frame k carries the grey level k: read back, the levels must come out 1, 2, ..., 12."""
    for k in range(1, 13):
        cv2.imwrite(str(tmp_path / f"{k}.png"), np.full((8, 8, 3), k, np.uint8))
    levels = [int(frame[0, 0, 0]) for frame in FrameSource(tmp_path)]
    assert levels == list(range(1, 13))
