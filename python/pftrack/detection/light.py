"""Footage the detector's per-pixel tests assume away: grey video, and a global light change.

Two rules of `PaperDetector` (docs/detection.md, "Grey video and changing light"):

* **Grey video.** The shadow test calls a candidate pixel shadow when it is darker than the
  background with the background's chromaticity. In a grey video (B = G = R) every pixel has
  the same, grey, chromaticity, so every darker pixel within the brightness bound is "shadow":
  dark clothes vanish from the mask. :func:`looks_grey` tells such a video from its first
  frames; the detector then uses ``PaperConfig.grey_shadow_lo`` as the bound (1: no shadow
  test).
* **Dark frames.** A black frame (a dropout, a cut or fade to black) has no light to compare:
  its gain against the background is 0 and scaling the background by it would erase the
  model. A frame whose mean level is at most :data:`DARK_LEVEL` (:func:`is_dark`) is neither
  learnt nor compared: the detector reports no foreground on it, leaves the background as it
  was, and does not start or prime a background from it. A blank frame (:func:`is_blank`: one
  flat level, as ``np.zeros`` placeholders are) gives the colour filters nothing either;
  ``pftrack.Tracker.update`` says so when a run opens on one.
* **Global gain.** A background learnt at one brightness reads a whole frame taken at another
  as foreground, and the selective update (slow where foreground) does not catch up.
  ``BackgroundModel.global_gain`` measures the frame's gain against the background (median
  ratio of the pixel sums over a grid); when it leaves ``1 +- PaperConfig.gain_band`` the
  background is scaled by it (``BackgroundModel.scale``) before the frame is compared, and
  the grey-level thresholds by the gain accumulated since the first frame
  (``BackgroundModel.set_threshold_scale``). :func:`level_frames` brings the priming frames
  to one brightness before their median.
* **Texture on grey video** (``PaperConfig.grey_texture``, off: docs/detection.md, "Stop
  68"). A grey pixel differs from the background by ``|Y - Y_B|`` only, and people of the
  ground's brightness come apart in pieces. :func:`texture_changed` marks where the frame's
  local pattern no longer correlates with the background's (a person hides the ground's
  texture), which a shadow or a change of light (a gain) leaves correlated.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack._check import integer, shown
from pftrack._stats import median, percentile
from pftrack.detection.base import check_frame

__all__ = [
    "BLANK_LEVELS",
    "DARK_LEVEL",
    "GAIN_SAMPLE_STEP",
    "GREY_SAMPLE_STEP",
    "MIN_CONTENT",
    "channel_spread",
    "frame_gain",
    "is_blank",
    "is_dark",
    "level_frames",
    "looks_grey",
    "sample_step",
    "texture_changed",
]

GREY_SAMPLE_STEP = 4
"""Every how many rows and columns the light's measures read a pixel, up to 640x480."""

GAIN_SAMPLE_STEP = 8
"""The step of the detector's per-frame gain (``BackgroundModel.global_gain``) up to 640x480:
4 800 samples there, 0.026 ms a 480x360 frame against 0.096 ms at every 4th pixel."""

_MAX_STEP = 2**31 - 1
"""Largest sampling step :func:`is_dark` takes (any frame's side is smaller)."""

_STEP_PIXELS = 640 * 480
"""Frames larger than this are sampled more sparsely (:func:`sample_step`)."""


def sample_step(shape: tuple[int, ...], base: int = GREY_SAMPLE_STEP) -> int:
    """Sampling step in rows and columns of the light's measures for frames of `shape`.

    :data:`GREY_SAMPLE_STEP` up to 640x480 (19 200 samples there); on larger frames the step
    grows with the side so that the sample count stays about that: a 1280x720 frame is read
    every 7th row and column (0.45 ms of ``BackgroundModel.global_gain`` a frame at step 4, a
    third of that at 7), with as many samples for the medians as a 640x480 one.
    """
    if not isinstance(shape, tuple) or len(shape) < 2:  # was: an IndexError, or a TypeError's
        raise TypeError(f"sample_step: shape must be a frame's (H, W, 3), got {shown(shape)}")
    pixels = int(shape[0]) * int(shape[1])
    return max(base, round(base * math.sqrt(pixels / _STEP_PIXELS)))


DARK_LEVEL = 8.0
"""Mean level (0-255, over the sampled pixels and channels) at or below which a frame is dark
(:func:`is_dark`): PETS09 and TUD-Campus frames lie near 100, a fade to black passes it in its
last frames, a dropout's black frame is 0."""


def is_dark(frame: NDArray[np.uint8], step: int | None = None) -> bool:
    """Tell whether `frame` is dark: the mean of its sampled levels is at most `DARK_LEVEL`.

    Parameters
    ----------
    frame : (H, W, 3) ndarray of uint8
        A BGR frame.
    step : int, optional
        Sampling step in rows and columns (default: :func:`sample_step` of the frame).
    """
    frame = check_frame(frame, "is_dark")  # was: an AttributeError of None, text, a number
    step = (
        sample_step(frame.shape) if step is None else integer(step, "is_dark: step", 1, _MAX_STEP)
    )
    # frame[::step, ::step].mean()'s value in C++ (the same double, at any strides): a tenth
    # of NumPy's strided reduction's time, and the detector asks it of every frame
    return _core.sampled_mean(frame, step) <= DARK_LEVEL


BLANK_LEVELS = 2
"""Largest spread of a frame's levels (max - min) that :func:`is_blank` calls blank."""


def is_blank(frame: NDArray[np.uint8]) -> bool:
    """Tell whether `frame` is one flat level (a placeholder: ``np.zeros``, a black frame).

    Unlike :func:`is_dark` (a low mean), a flat white or grey frame is blank too, and a dark
    scene with any content is not. Every pixel is read (call it once, not per frame): a picture
    of a scene is never within :data:`BLANK_LEVELS` levels everywhere; a placeholder always is,
    and so is a black frame unless compression left more than that of noise in it.

    Parameters
    ----------
    frame : (H, W, 3) ndarray of uint8
        A BGR frame.
    """
    frame = check_frame(frame, "is_blank")
    return int(frame.max()) - int(frame.min()) <= BLANK_LEVELS


MIN_CONTENT = 8.0
"""Least standard deviation of the sampled levels for :func:`looks_grey` to call frames grey."""


def channel_spread(frame: NDArray[np.uint8], step: int | None = None) -> NDArray[np.int16]:
    """``max_c I_c - min_c I_c`` of every `step`-th pixel of every `step`-th row, flattened.

    Parameters
    ----------
    frame : (H, W, 3) ndarray of uint8
        A BGR frame.
    step : int, optional
        Sampling step in rows and columns (default: :func:`sample_step` of the frame).

    Returns
    -------
    (K,) ndarray of int16
    """
    frame = check_frame(frame, "channel_spread")
    step = sample_step(frame.shape) if step is None else step
    px = np.asarray(frame[::step, ::step], np.int16).reshape(-1, 3)
    return np.asarray(px.max(axis=1) - px.min(axis=1), np.int16)


def looks_grey(frames: Iterable[NDArray[np.uint8]], tolerance: float = 3.0) -> bool:
    """True when the frames are grey (B = G = R up to compression).

    Grey when 99 % of their sampled pixels have channels within `tolerance` grey levels of
    each other: compression leaves grey video a level or two of colour, where the 99th
    percentile is 92 on PETS09-S2L1 and 41 on TUD-Campus (their first 30 frames).

    Parameters
    ----------
    frames : iterable of (H, W, 3) uint8 arrays
        E.g. the frames that prime the background, or the first frame.
    tolerance : float
        Largest channel spread of a grey pixel, in grey levels.

    Returns
    -------
    bool
        False for no frames, and for frames whose sampled levels vary by less than
        `MIN_CONTENT` (standard deviation): black or flat frames.
    """
    frames = list(frames)
    if not frames:
        return False
    spreads = []
    for f in frames:  # a colour video is told from its first frame: the others are not read
        spreads.append(channel_spread(f))
        if percentile(spreads[-1], 99) > tolerance:
            return False
    spread = np.concatenate(spreads)
    step = sample_step(frames[0].shape)
    level = np.concatenate([f[::step, ::step, 1].ravel() for f in frames])
    # a blank or flat picture (no video, a test pattern) tells nothing about colour
    return bool(percentile(spread, 99) <= tolerance and level.std() >= MIN_CONTENT)


def frame_gain(
    frame: NDArray[np.uint8],
    reference: NDArray[np.uint8] | NDArray[np.float32],
    step: int | None = None,
    min_sum: float = 30.0,
) -> float:
    """Global gain of `frame` against `reference`: ``BackgroundModel.global_gain``'s measure.

    The median, over every `step`-th pixel of every `step`-th row whose reference sum
    ``R_b + R_g + R_r`` is at least `min_sum`, of ``sum(I) / sum(R)``; 1 when none qualifies.
    With a model's float background as `reference` it is the NumPy reference the tests hold
    the C++ measure to.

    Parameters
    ----------
    frame : (H, W, 3) ndarray of uint8
        A BGR frame.
    reference : (H, W, 3) ndarray of uint8 or float32
        A BGR frame of the same size, or a background (``BackgroundModel.background``).
    step : int, optional
        Sampling step in rows and columns (default: :func:`sample_step` of the frame).
    min_sum : float
        Least reference sum of a sampled pixel (dark pixels give noisy ratios).

    Returns
    -------
    float
    """
    frame = check_frame(frame, "frame_gain")
    if not isinstance(reference, np.ndarray):
        raise TypeError(f"frame_gain: reference must be an array, got {shown(reference)}")
    if reference.shape != frame.shape:
        raise ValueError(
            f"frame_gain: reference must be an array of the frame's shape {frame.shape}, got "
            f"{reference.shape}"
        )
    step = sample_step(frame.shape) if step is None else step
    sr = _pixel_sums(reference[::step, ::step])
    si = _pixel_sums(frame[::step, ::step])
    keep = (sr >= min_sum) & (sr > 0)
    return median(si[keep] / sr[keep]) if keep.any() else 1.0


def _pixel_sums(image: NDArray[Any]) -> NDArray[np.float64]:
    """``image.astype(np.float64).sum(axis=2)``: B + G + R of each pixel of an (H, W, 3) array.

    uint8 channels add up to integers below 2**53, exact in any order: three slices added are
    the same sums at a fifteenth of the time of NumPy's reduction over an axis of 3 (0.02
    against 0.35 ms a 480x360 frame at step 4; :func:`level_frames` measures 29 of them).
    """
    if image.dtype != np.uint8:  # float sums depend on their order: NumPy's own
        total: NDArray[np.float64] = image.astype(np.float64).sum(axis=2)
        return total
    sums = image[..., 0].astype(np.float64)
    sums += image[..., 1]
    sums += image[..., 2]
    return sums


def level_frames(frames: list[NDArray[np.uint8]], band: float) -> list[NDArray[np.uint8]]:
    """The frames brought to the first one's brightness, for a per-pixel median.

    Under a global light change the median of frames spread over a video is biased wherever
    people stand in many of them: the background values then span the light's range and the
    median is their upper or lower end, not the middle. Each frame whose `frame_gain` against
    the first leaves ``1 +- band`` is divided by it (rounded, clipped to 0..255); the others
    are returned as they are (the same objects), so steady video is unchanged.

    Parameters
    ----------
    frames : list of (H, W, 3) uint8 arrays
        E.g. the frames that prime the background.
    band : float
        Gains within ``1 +- band`` are left alone; 0 returns `frames` unchanged.

    Returns
    -------
    list of (H, W, 3) uint8 arrays
    """
    if band <= 0 or len(frames) < 2:
        return frames
    out = [frames[0]]
    for f in frames[1:]:
        g = frame_gain(f, frames[0])
        if abs(g - 1.0) > band:
            f = np.clip(np.rint(f.astype(np.float32) / np.float32(g)), 0, 255).astype(np.uint8)
        out.append(f)
    return out


#: Rows of the frames a masked median takes at once (:func:`levelled_median`): bounds its
#: float stack to about 30 frames x 64 rows x W x 3 values.
MEDIAN_ROWS = 64


def levelled_median(frames: list[NDArray[np.uint8]], band: float, fn: str) -> NDArray[np.float32]:
    """The per-pixel median of `frames` brought to the first one's light (a background's start).

    :func:`level_frames`, then :func:`~pftrack.detection.base.median_frame`, except where a
    frame brighter than the first was saturated: a channel at 255 there says only that the
    value lies at or above it, and divided by the frame's gain it reads as a darker value than
    the first frame shows. There the median is the larger of the levelled frames' median (a
    lower bound where the frame's gain is measured right, i.e. most of it is not saturated:
    every censored value is at least its levelled one) and the median of the
    frames that were not saturated at that pixel (the estimate, which people standing in the
    few dark frames can drag down; when every frame is saturated, the bound alone). Without
    it, a light that rose by 1.4 a third of the way into PETS09 made most of the priming frames
    bright, their saturated pixels came back as 255 / 1.4 = 182 where the first frames show
    200 or more, and the frames before the change filled with false foreground (MOTA 71.3
    against 80.9; docs/detection.md). Frames darker than the first lose nothing that matters
    (a value scaled past 255 is one the first frame saturates too). Steady and darkening video
    give exactly ``median_frame(level_frames(...))``.
    """
    from pftrack.detection.base import median_frame

    levelled = level_frames(frames, band)
    median = median_frame(levelled, fn)  # checks the frames; kept where no value was lost
    brighter = [
        k
        for k, (a, b) in enumerate(zip(frames, levelled, strict=True))
        if a is not b and frame_gain(a, frames[0]) > 1.0
    ]
    if not brighter:
        return median
    for y0 in range(0, median.shape[0], MEDIAN_ROWS):
        rows = slice(y0, y0 + MEDIAN_ROWS)
        lost = np.zeros((len(frames), *median[rows].shape[:2]), dtype=bool)
        for k in brighter:
            lost[k] = (frames[k][rows] == 255).any(axis=2)
        if not lost.any():
            continue
        stack = np.stack([f[rows] for f in levelled]).astype(np.float32)
        kept = ~lost.all(axis=0)  # pixels with some frame left
        stack[lost] = np.nan
        sub = median[rows]  # a view: written into the median, never below its bound
        sub[kept] = np.maximum(sub[kept], np.nanmedian(stack[:, kept], axis=0))
    return median


def texture_changed(
    grey: NDArray[np.uint8],
    background: NDArray[np.float32],
    ncc_max: float,
    window: int = 5,
    erode: int = 5,
    min_variance: float = 25.0,
) -> NDArray[np.bool_]:
    """Where a grey frame's local pattern does not correlate with its background's.

    The normalised cross-correlation of the frame and the background over the `window` x
    `window` box around each pixel (borders reflected, OpenCV's ``boxFilter``) is below
    `ncc_max` where either box's variance is above `min_variance` (grey levels squared: 25 is
    a standard deviation of 5; flat boxes, of noise alone, tell nothing), and that set is
    eroded by an `erode` x `erode` square (0 or 1: not at all), which takes back the band of
    about half a window by which a changed box reaches past a person's outline. A gain (a
    shadow, a change of light) leaves the correlation at 1.

    Parameters
    ----------
    grey : (H, W) uint8 ndarray
        The frame's grey level.
    background : (H, W) float32 ndarray
        The background's grey level.
    ncc_max : float
        The correlation below which a pixel's box has changed, in (-1, 1].
    window, erode : int
        Box side (odd, >= 3) and erosion side (>= 0).
    min_variance : float
        The variance one of the two boxes needs for its correlation to count.

    Returns
    -------
    (H, W) bool ndarray
    """
    # centred on mid-grey: the boxes' sums of products stay small, so float32 rounding stays
    # far below the variance floor of 1 (a flat box, a saturated one, is then exactly "no
    # correlation" against a textured one, not rounding noise)
    i = np.asarray(grey, np.float32) - 128.0
    b = np.asarray(background, np.float32) - 128.0
    size = (window, window)
    mi = cv2.boxFilter(i, -1, size)
    mb = cv2.boxFilter(b, -1, size)
    vi = cv2.boxFilter(i * i, -1, size) - mi * mi
    vb = cv2.boxFilter(b * b, -1, size) - mb * mb
    cov = cv2.boxFilter(i * b, -1, size) - mi * mb
    # cov < ncc_max sqrt(vi vb), without a division (variances floored at 1 grey level squared)
    changed: NDArray[np.bool_] = (
        cov < ncc_max * np.sqrt(np.maximum(vi, 1.0) * np.maximum(vb, 1.0))
    ) & (np.maximum(vi, vb) > min_variance)
    if erode > 1:
        out = cv2.erode(changed.view(np.uint8), np.ones((erode, erode), np.uint8))
        changed = np.asarray(out, np.bool_)
    return changed
