from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("PFTRACK_DATA", ROOT.parent / "shared" / "data"))


def pets_frame(size: tuple[int, int]) -> np.ndarray:
    """Frame 100 of PETS09-S2L1 resized to `size` (W, H), or a synthetic textured frame."""
    video = DATA / "pets09-s2l1" / "video.avi"
    frame = None
    if video.is_file():
        cap = cv2.VideoCapture(str(video))
        cap.set(cv2.CAP_PROP_POS_FRAMES, 100)
        ok, frame = cap.read()
        cap.release()
        frame = frame if ok else None
    if frame is None:
        rng = np.random.default_rng(0)
        frame = rng.integers(0, 256, (360, 480, 3), dtype=np.uint8)
    return cv2.resize(frame, size, interpolation=cv2.INTER_LINEAR)


@pytest.fixture(scope="session")
def frame_480() -> np.ndarray:
    return pets_frame((480, 360))


@pytest.fixture(scope="session")
def frame_720() -> np.ndarray:
    return pets_frame((1280, 720))
