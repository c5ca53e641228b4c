"""OpenCV's background subtractors (MOG2, KNN) behind the `Detector` interface."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack._check import brief, instance, integer, number
from pftrack._check import seed as check_seed
from pftrack.detection.base import (
    BlobConfig,
    BlobExtractor,
    Detections,
    check_frame,
    median_frame,
)
from pftrack.detection.size_model import PersonSizeModel
from pftrack.particle_filter.colour import HsvBinning


@dataclass(frozen=True)
class Mog2Config:
    """Settings of `Mog2Detector` (OpenCV's defaults).

    Attributes
    ----------
    history : int
        Frames that shape the mixture, in [1, 2147483647] (OpenCV's int).
    var_threshold : float
        Squared Mahalanobis distance above which a pixel is foreground; finite and > 0.
    learning_rate : float
        -1 lets OpenCV choose (1 / min(frames seen, history)); else in [0, 1] (0: the model
        is never updated, 1: it is the last frame).
    blobs, hsv : BlobConfig, HsvBinning
        As for `PaperDetector`.

    Raises
    ------
    TypeError
        `var_threshold` or `learning_rate` not a number, `history` not an int (a bool).
    ValueError
        A setting out of its range above (NaN included).
    """

    history: int = 500
    var_threshold: float = 16.0
    learning_rate: float = -1.0
    blobs: BlobConfig = field(default_factory=BlobConfig)
    hsv: HsvBinning = field(default_factory=HsvBinning)

    def __post_init__(self) -> None:
        _check_subtractor(self, "Mog2Config", "var_threshold")


@dataclass(frozen=True)
class KnnConfig:
    """Settings of `KnnDetector` (OpenCV's defaults).

    Attributes
    ----------
    history : int
        Frames kept as samples, in [1, 2147483647] (OpenCV's int).
    dist2_threshold : float
        Squared distance under which a sample counts as near; finite and > 0.
    learning_rate : float
        -1 lets OpenCV choose; else in [0, 1].
    blobs, hsv : BlobConfig, HsvBinning
        As for `PaperDetector`.

    Raises
    ------
    TypeError
        `dist2_threshold` or `learning_rate` not a number, `history` not an int (a bool).
    ValueError
        A setting out of its range above (NaN included).
    """

    history: int = 500
    dist2_threshold: float = 400.0
    learning_rate: float = -1.0
    blobs: BlobConfig = field(default_factory=BlobConfig)
    hsv: HsvBinning = field(default_factory=HsvBinning)

    def __post_init__(self) -> None:
        _check_subtractor(self, "KnnConfig", "dist2_threshold")


def _check_subtractor(config: Mog2Config | KnnConfig, owner: str, threshold: str) -> None:
    """The settings OpenCV takes without a word but cannot use (or refuses unnamed).

    A negative `history` or a NaN threshold ran; a learning rate of NaN or above 1 found
    nothing; a float `history` failed in OpenCV's argument parsing.
    """
    integer(config.history, f"{owner}: history", 1, 2**31 - 1)
    instance(config.blobs, f"{owner}: blobs", BlobConfig)
    instance(config.hsv, f"{owner}: hsv", HsvBinning)
    t = number(getattr(config, threshold), f"{owner}: {threshold}", finite=False)
    if not (np.isfinite(t) and t > 0):
        raise ValueError(f"{owner}: {threshold} is {t}, expected a finite value > 0")
    rate = number(config.learning_rate, f"{owner}: learning_rate", finite=False)
    if not (rate == -1 or 0 <= rate <= 1):
        raise ValueError(
            f"{owner}: learning_rate is {rate}, expected -1 (OpenCV's choice) or a value in [0, 1]"
        )


class _OpenCvDetector:
    """Shared body: subtractor mask (shadows 127 -> background) -> blobs -> masked bins."""

    _name = "detector"

    def __init__(self, blobs: BlobConfig, hsv: HsvBinning, learning_rate: float) -> None:
        self._blobs = BlobExtractor(blobs)
        self._hsv = asdict(hsv)
        self._learning_rate = float(learning_rate)
        self._sub: Any = self._make()
        self._shape: tuple[int, ...] | None = None

    @property
    def size_model(self) -> PersonSizeModel:
        """The person-size model learnt from this video's isolated blobs (see `BlobConfig`)."""
        return self._blobs.size_model

    def _make(self) -> Any:  # pragma: no cover - overridden
        raise NotImplementedError

    def reset(self) -> None:
        """Forget the background model."""
        self._sub = self._make()
        self._blobs.reset()
        self._shape = None

    def _apply(self, image: NDArray[np.uint8], learning_rate: float) -> Any:
        """One frame (or a priming image) through the subtractor: its raw mask."""
        return self._sub.apply(image, learningRate=learning_rate)

    def prime(self, frames: Iterable[NDArray[np.uint8]], repeats: int = 30) -> None:
        """Start from the per-pixel median of `frames`, shown `repeats` times to a new subtractor.

        OpenCV's subtractors cannot be given a background; learning the median image as
        `repeats` frames of an empty scene does the same (see `pftrack.detection.bootstrap`).

        Parameters
        ----------
        frames : iterable of (H, W, 3) uint8 arrays
            At least one frame; all of one size.
        repeats : int
            How many times the median is learnt (>= 1).
        """
        fn = f"{type(self).__name__}.prime"
        median_f = median_frame(frames, fn)
        if not (isinstance(repeats, int) and repeats >= 1):
            raise ValueError(f"{fn}: repeats is {brief(repeats)}, expected an int >= 1")
        median = median_f.round().astype(np.uint8)  # numpy.median's values
        self.reset()
        for _ in range(repeats):
            self._apply(median, -1.0)
        self._shape = median.shape

    def detect(self, frame: NDArray[np.uint8]) -> Detections:
        """Detect the moving objects of one BGR uint8 frame (H, W, 3); see `Detections`."""
        frame = check_frame(frame, f"{type(self).__name__}.detect")
        mask, _ = self.foreground(frame)
        boxes, scores = self._blobs.boxes(mask)
        return Detections(boxes, scores, mask, _core.hsv_bins(frame, mask, **self._hsv))

    def foreground(
        self, frame: NDArray[np.uint8], shadows: bool = False
    ) -> tuple[NDArray[np.uint8], None]:
        """Return the cleaned foreground mask (shadows are background), without blobs or boxes.

        With `shadows` the mask keeps OpenCV's shadow pixels as 127 (255 foreground, 0
        background). No full-frame bins come with it (None: OpenCV's subtractors do not make
        them).
        """
        fn = f"{type(self).__name__}.foreground"
        frame = check_frame(frame, fn)
        if self._shape is not None and frame.shape != self._shape:
            raise ValueError(
                f"{fn}: frame shape is {frame.shape}, expected {self._shape} as the earlier "
                "frames (call reset() before a new video)"
            )
        self._shape = frame.shape
        # 255 = foreground, 127 = shadow: kept with `shadows` (the grey-level cleaning keeps
        # both), else shadows are background
        raw = np.asarray(self._apply(frame, self._learning_rate), np.uint8)
        if not shadows:
            raw = np.where(raw == 255, np.uint8(255), np.uint8(0))
        return self._blobs.clean(raw), None


class Mog2Detector(_OpenCvDetector):
    """OpenCV's Gaussian-mixture background subtractor (Zivkovic 2004), shadows as background.

    Parameters
    ----------
    config : Mog2Config, optional

    References
    ----------
    .. [1] Zivkovic, Z. (2004). Improved adaptive Gaussian mixture model for background
       subtraction. ICPR.
    """

    def __init__(self, config: Mog2Config | None = None) -> None:
        own = "Mog2Detector: config"
        self.config = Mog2Config() if config is None else instance(config, own, Mog2Config)
        super().__init__(self.config.blobs, self.config.hsv, self.config.learning_rate)

    def _make(self) -> Any:
        return cv2.createBackgroundSubtractorMOG2(
            history=self.config.history, varThreshold=self.config.var_threshold, detectShadows=True
        )


class KnnDetector(_OpenCvDetector):
    """OpenCV's k-nearest-neighbour background subtractor, shadows as background.

    Parameters
    ----------
    config : KnnConfig, optional
    seed : int
        Seed of the subtractor's random sample updates (an int >= 0): the same seed and
        frames give the same masks, on any thread and with any number of OpenCV threads.

    Raises
    ------
    TypeError, ValueError
        `seed` not an int >= 0.

    Notes
    -----
    OpenCV's KNN model picks at random, every few frames, the frame at which each pixel's
    sample lists are next updated, drawing from OpenCV's random generator of the calling
    thread (``cv::theRNG()``), which nothing seeds: the same frames gave other masks after
    other OpenCV work on the thread, or on another thread. Before each ``apply`` (priming
    included) that generator is seeded from `seed` and the number of images the model has
    seen since its last reset, so a run's masks depend on `seed` and its frames alone (the
    draws come after OpenCV's parallel per-row pass, on the calling thread: the masks are the
    same with one OpenCV thread or many). The calling thread's OpenCV generator is left
    seeded: code that draws from it afterwards (``cv2.randu``) gets a state set here.

    References
    ----------
    .. [1] Zivkovic, Z., van der Heijden, F. (2006). Efficient adaptive density estimation per
       image pixel for the task of background subtraction. Pattern Recognition Letters 27(7).
    """

    def __init__(self, config: KnnConfig | None = None, seed: int = 0) -> None:
        own = "KnnDetector: config"
        self.config = KnnConfig() if config is None else instance(config, own, KnnConfig)
        self.seed = check_seed(seed, "KnnDetector: seed")
        self._seen = 0  # images applied since the model was made: the next one's seed
        super().__init__(self.config.blobs, self.config.hsv, self.config.learning_rate)

    def reset(self) -> None:
        """Forget the background model (its random draws start again from `seed`)."""
        super().reset()
        self._seen = 0

    def _apply(self, image: NDArray[np.uint8], learning_rate: float) -> Any:
        cv2.setRNGSeed(apply_seed(self.seed, self._seen))
        raw = self._sub.apply(image, learningRate=learning_rate)
        self._seen += 1
        return raw

    def _make(self) -> Any:
        return cv2.createBackgroundSubtractorKNN(
            history=self.config.history,
            dist2Threshold=self.config.dist2_threshold,
            detectShadows=True,
        )


_MASK64 = (1 << 64) - 1


def apply_seed(seed: int, n: int) -> int:
    """The OpenCV seed (in [0, 2**31 - 1]) of image `n` (from 0) of a `KnnDetector` of `seed`.

    SplitMix64's finaliser of ``seed + (n + 1) * golden ratio`` (mod 2**64): neighbouring
    images and seeds get unrelated streams.
    """
    z = (seed + (n + 1) * 0x9E3779B97F4A7C15) & _MASK64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK64
    return (z ^ (z >> 31)) & 0x7FFFFFFF
