"""Heavily compressed footage: the 8x8 blocks of a low JPEG or MPEG quality.

A video compressed hard (a low bitrate, JPEG quality 10 or less) is cut into 8x8 blocks whose
edges are steps of their own. The detector's per-pixel background tests and the colour
histograms see those steps as change: people are split or missed, blocks become blobs.
:func:`blockiness` measures them, the mean step across the lines between 8x8 blocks over the
mean step across their middles (1 where there are no blocks); ``pftrack.Tracker.update`` says
so when the median over a run's first :data:`BLOCK_FRAMES` frames is :data:`BLOCKY` or more.

Measured (docs/robustness.md, "Heavily compressed video"), the median over the first 8
frames: PETS09-S2L1 as read 0.95, TUD-Campus 1.25, synthetic scenes 0.95-1.45 as JPEG, PNG, AVI
or MP4 (1.08 enlarged 2x by repeating pixels); re-saved at JPEG quality 40, 20, 10, 5: PETS09
1.43, 1.79, 2.40, 3.27 and TUD-Campus 1.44, 1.68, 2.11, 2.78. With the built-in detector
(seed 0), MOTA 84.3, 84.6, 78.2, 48.0 on PETS09 (82.9 as read) and 51.3, 41.5, 19.8, -72.7 on
TUD-Campus (52.1).
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._stats import median

__all__ = ["BLOCKY", "BLOCK_FRAMES", "BLOCK_SIZE", "MIN_STEP", "blockiness", "is_blocky"]

BLOCK_SIZE = 8
"""The side of the blocks of JPEG, MPEG-2, MPEG-4 part 2 and H.264 transforms (px)."""

BLOCKY = 1.95
"""Median :func:`blockiness` of a run's first :data:`BLOCK_FRAMES` frames from which it is
said: above PETS09-S2L1 (0.95), TUD-Campus (1.25), the synthetic scenes (0.95-1.45 as JPEG,
PNG, AVI or MP4) and both sequences re-saved at JPEG quality 20 (1.79, 1.68); below both at
quality 10 (2.40, 2.11). The mean of seeds 0-2 with the built-in detector: at quality 10 MOTA
fell from 83.1 to 77.9 on PETS09 and from 46.2 to 26.4 on TUD-Campus (HOTA 59.1 -> 49.0,
44.2 -> 38.7); at quality 20 it was 84.6 and 41.5 (HOTA 58.3, 44.9), within the seeds'
spread (TUD-Campus as read: MOTA 39.3 to 52.1)."""

MIN_STEP = 1.0
"""Least mean step (grey levels) across the blocks' middles for :func:`blockiness` to tell
blocks: a flat frame, or a drawing of flat areas whose edges fall on the grid, has none to
tell (PETS09's is 6.5; re-saved at JPEG quality 5, 3.3)."""

BLOCK_FRAMES = 8
"""The first frames of a run whose median :func:`blockiness` decides (one noisy frame does
not)."""


def blockiness(frame: NDArray[np.uint8]) -> float:
    """Mean step across the lines between 8x8 blocks over the mean step across their middles.

    The steps are absolute differences of neighbouring grey levels, across columns and across
    rows; those between pixels 8k-1 and 8k are the blocks' edges (the grid of a frame decoded
    at its own size), those between 8k+3 and 8k+4 their middles (not every other step: a
    frame enlarged 2x by repeating pixels has steps on every second line, whose middles are
    on them too). About 1 for a picture without blocks, more the more the blocks show (3.3
    for PETS09-S2L1 re-saved at JPEG quality 5); 1 for a frame too flat to tell (a mean step
    across the blocks' middles under :data:`MIN_STEP`).

    Parameters
    ----------
    frame : (H, W, 3) or (H, W) ndarray of uint8
        A BGR or grey frame, at least 16 pixels a side (else 1: no block to tell).

    References
    ----------
    .. [1] Wang, Z., Bovik, A. C. and Evans, B. L. (2000). Blind measurement of blocking
       artifacts in images. ICIP 2000, vol. 3, 981-984.
    """
    grey = frame if frame.ndim == 2 else cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    h, w = grey.shape
    if min(h, w) < 2 * BLOCK_SIZE:
        return 1.0
    across = cv2.absdiff(grey[:, 1:], grey[:, :-1]).mean(axis=0)  # (W-1,) per column pair
    down = cv2.absdiff(grey[1:], grey[:-1]).mean(axis=1)  # (H-1,) per row pair
    at_x = np.arange(w - 1) % BLOCK_SIZE
    at_y = np.arange(h - 1) % BLOCK_SIZE
    edges = float(across[at_x == BLOCK_SIZE - 1].mean() + down[at_y == BLOCK_SIZE - 1].mean())
    # the middle of the blocks, between pixels 8k+3 and 8k+4: on a grid of 2 and 4 too, so
    # frames enlarged by repeating pixels are no blocks (every step inside was 2.5 for 2x)
    middle = BLOCK_SIZE // 2 - 1
    inside = float(across[at_x == middle].mean() + down[at_y == middle].mean())
    return edges / inside if inside >= 2 * MIN_STEP else 1.0


def is_blocky(values: list[float]) -> bool:
    """Whether the median of `values` (:func:`blockiness` of frames) is :data:`BLOCKY` or more."""
    return bool(values) and median(values) >= BLOCKY
