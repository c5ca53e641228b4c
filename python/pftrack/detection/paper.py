"""The paper's detector: adaptive background, frame difference, threshold, morphology, blobs."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, field

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack.detection.base import (
    BlobConfig,
    BlobExtractor,
    Detections,
    check_frame,
    median_frame,
)
from pftrack.detection.ghost import GHOST_STATISTICS
from pftrack.detection.size_model import PersonSizeModel
from pftrack.particle_filter.colour import HsvBinning, hsv_bins


@dataclass(frozen=True)
class PaperConfig:
    """Settings of `PaperDetector`'s per-pixel pass (thresholds in grey levels, 0-255).

    Attributes
    ----------
    alpha : float
        Running-average rate of the background where the pixel is background (the paper's
        selective update): ``B += alpha (I - B)``. 0.05 forgets in about 20 frames.
    alpha_fg : float
        Rate where the pixel is foreground: slowly absorbs objects that stop and the ghosts
        of objects present in the first frame (0 gives the purely selective update).
    n_learn : int
        Learning phase: the k-th frame, for k = 2 .. `n_learn`, updates every pixel at rate
        ``max(1 / k, alpha)`` (a running mean of the first frames), so that objects present in
        the first frame leave no lasting ghost. 0 or 1: the selective update from the start.
    k_noise : float
        Noise-adaptive threshold ``T = k_noise * median_pixels(max_c |I_c - B_c|)`` of the
        previous frame (most pixels are background, so the median measures the noise).
    t_min, t_max : float
        Bounds of `T`.
    low_ratio : float
        A pixel that also moved since the previous frame (``max_c |I_c - I'_c| > T``) is
        foreground from ``low_ratio * T`` on.
    shadow_lo, shadow_chroma : float
        Shadow test on foreground candidates: darker than the background with brightness
        ratio ``sum(I) / sum(B)`` in ``[shadow_lo, 1)`` and chromaticity ``I_c / sum(I)`` within
        `shadow_chroma` of the background's, for every channel: background, not learnt.
        ``shadow_lo=1`` turns it off.
    ghost_support : float
        Ghost test (`pftrack.detection.ghost.edge_support`): a blob whose boundary holds less
        than this share of the frame-plus-background edges is a ghost (uncovered background
        that the background still pictures as an object): dropped, and its pixels learnt at
        `ghost_rate`. 0 turns the test off.
    ghost_rate : float
        Per-pixel update rate of the background inside a ghost, per frame, for as long as
        those pixels stay foreground.
    ghost_statistic : {"vote", "ratio"}
        How the ghost test measures the boundary's support (`edge_support`'s `statistic`):
        ``"vote"``, the share of the boundary's pixels where the frame's edge is the stronger
        (a ghost that its owner has just left keeps the owner's silhouette on one side, which
        outweighs the rest of the boundary in summed magnitudes but is one side in a vote);
        ``"ratio"``, the summed magnitudes (the test before; issue 14's ghosts).
    leg_height : float
        Lost legs (the shadow test takes dark trousers on a grey path for shadow): once the
        person-size model is fitted, a box shorter than `leg_height` times the height of a
        person whose head is at its top is extended down through the rows below it that
        shadow or foreground fills (`leg_fill`), never past that person's expected foot row
        (`PersonSizeModel.extend_legs`). 0 turns it off.
    leg_fill : float
        Share of a box's columns that a row below it must fill (shadow or foreground) for the
        box to grow into it.
    blobs : BlobConfig
        Morphology and blob filters.
    hsv : HsvBinning
        Colour binning of the frame (done in the same pass).
    """

    alpha: float = 0.05
    alpha_fg: float = 0.005
    n_learn: int = 30
    k_noise: float = 4.0
    t_min: float = 25.0
    t_max: float = 60.0
    low_ratio: float = 0.5
    shadow_lo: float = 0.5
    shadow_chroma: float = 0.03
    ghost_support: float = 0.3
    ghost_rate: float = 0.5
    ghost_statistic: str = "vote"
    leg_height: float = 0.8
    leg_fill: float = 0.2
    blobs: BlobConfig = field(default_factory=BlobConfig)
    hsv: HsvBinning = field(default_factory=HsvBinning)

    def __post_init__(self) -> None:
        if not (0.0 <= self.ghost_support <= 1.0):
            raise ValueError(f"ghost_support is {self.ghost_support}, expected in [0, 1]")
        if not (0.0 < self.ghost_rate <= 1.0):
            raise ValueError(f"ghost_rate is {self.ghost_rate}, expected in (0, 1]")
        if self.ghost_statistic not in GHOST_STATISTICS:
            raise ValueError(
                f"ghost_statistic is {self.ghost_statistic!r}, expected 'vote' or 'ratio'"
            )
        if not (0.0 <= self.leg_height < np.inf):
            raise ValueError(f"leg_height is {self.leg_height}, expected a finite value >= 0")
        if not (0.0 <= self.leg_fill <= 1.0):
            raise ValueError(f"leg_fill is {self.leg_fill}, expected in [0, 1]")


class PaperDetector:
    """Background-subtraction detector of the paper, per-pixel pass in C++.

    Each frame: one C++ pass (`pftrack._core.BackgroundModel`) bins the pixels, compares them
    with the adaptive background and the previous frame, thresholds and updates the background
    where there is no foreground; OpenCV then opens and closes the mask and labels its
    connected components; blobs outside the area, aspect and fill limits are dropped.

    Parameters
    ----------
    config : PaperConfig, optional
        Settings; the defaults are documented on `PaperConfig`.

    Notes
    -----
    The background starts as the first frame (its first mask is empty), unless `prime` gave
    it a median of frames. Objects present in the first frame leave ghosts that `alpha_fg`
    absorbs over ``~1 / alpha_fg`` frames; `prime` avoids them.

    References
    ----------
    .. [1] The detection step of the first method's paper (multi-object tracking with background
       subtraction and colour particle filters; restated in English in the project's papers
       README): adaptive background and frame differences, thresholded, cleaned by morphology.
    """

    def __init__(self, config: PaperConfig | None = None) -> None:
        self.config = config if config is not None else PaperConfig()
        c = self.config
        self._model = _core.BackgroundModel(
            alpha=c.alpha,
            alpha_fg=c.alpha_fg,
            n_learn=c.n_learn,
            k_noise=c.k_noise,
            t_min=c.t_min,
            t_max=c.t_max,
            low_ratio=c.low_ratio,
            shadow_lo=c.shadow_lo,
            shadow_chroma=c.shadow_chroma,
            **asdict(c.hsv),
        )
        self._blobs = BlobExtractor(c.blobs)
        self._ghost: NDArray[np.uint8] | None = None  # pixels of ghosts still being learnt

    @property
    def model(self) -> _core.BackgroundModel:
        """The C++ background model (read its ``background``, ``threshold``)."""
        return self._model

    @property
    def size_model(self) -> PersonSizeModel:
        """The person-size model learnt from this video's isolated blobs (see `BlobConfig`)."""
        return self._blobs.size_model

    def reset(self) -> None:
        """Forget the background; the next frame initialises it."""
        self._model.reset()
        self._blobs.reset()
        self._ghost = None

    def prime(self, frames: Iterable[NDArray[np.uint8]]) -> None:
        """Start from the per-pixel median of `frames` (e.g. frames spread over the video).

        Parameters
        ----------
        frames : iterable of (H, W, 3) uint8 arrays
            At least one frame; all of one size.
        """
        # numpy.median(stack, axis=0)'s values, in C++ without stacking the frames (tests hold
        # the two equal): 0.23 s instead of 1.4-1.7 s for 30 frames of 1280x720, no stack
        median = median_frame(frames, "PaperDetector.prime")
        self._model.reset()
        self._model.set_background(median)

    def detect(self, frame: NDArray[np.uint8]) -> Detections:
        """Detect the moving objects of one frame.

        Parameters
        ----------
        frame : (H, W, 3) ndarray of uint8
            BGR frame, the same size as the earlier ones (call `reset` between videos).

        Returns
        -------
        Detections
        """
        frame = check_frame(frame, "PaperDetector.detect")
        _, raw = self._model.apply(frame, bins=False)  # bins below, of the foreground only
        shaded = self._blobs.clean(raw)
        mask = foreground_only(shaded)
        if self.config.ghost_support > 0 and self._ghost is not None:
            # a ghost found earlier: its pixels still foreground keep being learnt fast
            carry = np.bitwise_and(mask, self._ghost)
            if carry.any():
                self._model.blend(frame, carry, self.config.ghost_rate)
                mask = np.bitwise_xor(mask, carry)
                self._ghost = carry
            else:  # learnt: no full-frame AND on the next frames
                self._ghost = None
        boxes, scores = self._blobs.boxes(mask)
        if self.config.ghost_support > 0 and len(boxes):
            mask, boxes, scores = self._drop_ghosts(frame, mask, boxes, scores)
        size = self._blobs.size_model
        if self.config.leg_height > 0 and len(boxes) and size.fitted:
            # after the size model observed the blobs' own boxes (it never learns from these);
            # no box grows into a ghost (this frame's ghost pixels are background being learnt)
            if self._ghost is not None:  # in place: `shaded` is this frame's own array
                shaded[self._ghost != 0] = 0
            boxes = size.extend_legs(shaded, boxes, self.config.leg_height, self.config.leg_fill)
        # the colours of the kept foreground only (the full frame's bins, which only a moving
        # camera needs, are binned by the tracker then)
        return Detections(boxes, scores, mask, hsv_bins(frame, mask, self.config.hsv))

    def _drop_ghosts(
        self,
        frame: NDArray[np.uint8],
        mask: NDArray[np.uint8],
        boxes: NDArray[np.float64],
        scores: NDArray[np.float64],
    ) -> tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64]]:
        """Drop the ghost blobs and learn their pixels fast (C++ ``blend``).

        The support is `pftrack.detection.ghost.edge_support` computed in C++
        (``BackgroundModel.edge_support``: the same blur, Sobel and band, read from the model's
        own background without copying it; tests hold the two equal to 1e-5), with the
        statistic of ``ghost_statistic``.
        """
        support = self._model.edge_support(frame, mask, boxes, self.config.ghost_statistic)
        ghost = support < self.config.ghost_support
        if not ghost.any():
            return mask, boxes, scores
        gmask = np.zeros_like(mask)
        for x, y, w, h in boxes[ghost].astype(int):
            gmask[y : y + h, x : x + w] = mask[y : y + h, x : x + w]
        self._model.blend(frame, gmask, self.config.ghost_rate)
        self._ghost = gmask if self._ghost is None else np.bitwise_or(self._ghost, gmask)
        mask = np.bitwise_xor(mask, gmask)
        return mask, boxes[~ghost], scores[~ghost]

    def foreground(
        self, frame: NDArray[np.uint8], shadows: bool = False, bins: bool = True
    ) -> tuple[NDArray[np.uint8], _core.BinnedImage | None]:
        """The cleaned foreground mask and the frame's HSV bins, without blobs or boxes.

        The background model advances exactly as with :meth:`detect`; a tracker fed by another
        detector needs only these (to refine that detector's boxes) and skips the blob pass.
        With `shadows` the mask keeps the shadow pixels as 127 (255 foreground, 0 background).
        With `bins` False the background pass makes no bins (None in their place): for a
        caller that bins only the pixels it reads (``hsv_bins(..., lazy=True)``).
        """
        shaded, binned = self._foreground(frame, "PaperDetector.foreground", bins)
        return (shaded if shadows else foreground_only(shaded)), binned

    def _foreground(
        self, frame: NDArray[np.uint8], fn: str, bins: bool = True
    ) -> tuple[NDArray[np.uint8], _core.BinnedImage | None]:
        """The cleaned mask with shadows (255, 127, 0) and the frame's bins (None without)."""
        binned, raw = self._model.apply(check_frame(frame, fn), bins=bins)
        return self._blobs.clean(raw), binned


def foreground_only(shaded: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """The 0/255 foreground of a mask with shadows (255 foreground, 127 shadow, 0 background).

    Opening and closing are minima and maxima over a window, which commute with a threshold:
    the foreground of the cleaned mask with shadows is the cleaned foreground, bit for bit.
    """
    return np.asarray(cv2.threshold(shaded, 127, 255, cv2.THRESH_BINARY)[1], np.uint8)
