"""Moving-object detection by background subtraction: the paper's detector, MOG2, KNN.

Every detector has ``detect(frame) -> Detections`` (boxes, scores, cleaned mask, foreground-only
HSV bins) and ``reset()``. `make_detector` builds one by name from flat keyword settings.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from pftrack._lazy import lazy_exports
from pftrack.detection.base import (
    BlobConfig,
    Detections,
    Detector,
    FrameDetector,
    check_detections,
    check_frame,
)
from pftrack.detection.opencv_bg import KnnConfig, KnnDetector, Mog2Config, Mog2Detector
from pftrack.detection.paper import PaperConfig, PaperDetector
from pftrack.detection.refine import refine_boxes
from pftrack.particle_filter.colour import HsvBinning

DETECTORS = ("paper", "mog2", "knn")
#: The settings class of each built-in detector, by name (``TrackerConfig(detector=...)`` takes
#: a name or one of these).
DETECTOR_CONFIGS: dict[str, type[PaperConfig | Mog2Config | KnnConfig]] = {
    "paper": PaperConfig,
    "mog2": Mog2Config,
    "knn": KnnConfig,
}

__all__ = [
    "DETECTORS",
    "DETECTOR_CONFIGS",
    "BlobConfig",
    "Detections",
    "Detector",
    "FrameDetector",
    "KnnConfig",
    "KnnDetector",
    "Mog2Config",
    "Mog2Detector",
    "PaperConfig",
    "PaperDetector",
    "check_detections",
    "check_frame",
    "detector_from",
    "make_detector",
    "refine_boxes",
]


def _split(cls: type, config: dict[str, Any], name: str) -> Any:
    """Build `cls` from flat keywords: its own fields, plus those of its blobs/hsv sub-configs."""
    own = {f.name for f in dataclasses.fields(cls)} - {"blobs", "hsv"}
    blob_fields = {f.name for f in dataclasses.fields(BlobConfig)}
    hsv_fields = {f.name for f in dataclasses.fields(HsvBinning)}
    unknown = sorted(set(config) - own - blob_fields - hsv_fields - {"blobs", "hsv"})
    if unknown:
        raise TypeError(
            f"make_detector: unknown setting(s) {', '.join(unknown)} for detector '{name}'; "
            f"expected some of {', '.join(sorted(own | blob_fields | hsv_fields))}"
        )
    blobs = config.get("blobs") or BlobConfig(
        **{k: v for k, v in config.items() if k in blob_fields}
    )
    hsv = config.get("hsv") or HsvBinning(**{k: v for k, v in config.items() if k in hsv_fields})
    return cls(**{k: v for k, v in config.items() if k in own}, blobs=blobs, hsv=hsv)


def make_detector(
    name: str, *, seed: int = 0, **config: Any
) -> PaperDetector | Mog2Detector | KnnDetector:
    """Build a detector by name.

    Parameters
    ----------
    name : {"paper", "mog2", "knn"}
        The paper's detector (C++ pass), or OpenCV's MOG2 / KNN subtractors.
    seed : int
        Seed of KNN's random sample updates (`KnnDetector`); the paper's detector and MOG2
        draw no random numbers and ignore it.
    **config
        Fields of `PaperConfig` / `Mog2Config` / `KnnConfig`, of `BlobConfig` (``min_area`` …)
        and of `HsvBinning` (``n_h`` …), flat; or ``blobs=`` / ``hsv=`` config objects.

    Returns
    -------
    PaperDetector or Mog2Detector or KnnDetector

    Raises
    ------
    ValueError
        Unknown `name`, or a setting out of range.
    TypeError
        Unknown setting.
    """
    if name == "paper":
        return PaperDetector(_split(PaperConfig, config, name))
    if name == "mog2":
        return Mog2Detector(_split(Mog2Config, config, name))
    if name == "knn":
        return KnnDetector(_split(KnnConfig, config, name), seed=seed)
    raise ValueError(f"make_detector: name is {name!r}, expected one of {', '.join(DETECTORS)}")


def detector_from(
    config: PaperConfig | Mog2Config | KnnConfig, *, seed: int = 0
) -> PaperDetector | Mog2Detector | KnnDetector:
    """Build the detector `config` sets: :func:`make_detector` from a settings object.

    ``make_detector("paper", **flat)`` builds ``PaperDetector(PaperConfig(...))``: the same
    detector as ``detector_from(PaperConfig(...))``. `seed` as :func:`make_detector`'s (KNN's).

    Raises
    ------
    TypeError
        `config` is not a PaperConfig, Mog2Config or KnnConfig.
    """
    if isinstance(config, PaperConfig):
        return PaperDetector(config)
    if isinstance(config, Mog2Config):
        return Mog2Detector(config)
    if isinstance(config, KnnConfig):
        return KnnDetector(config, seed=seed)
    raise TypeError(
        f"detector_from: config must be a PaperConfig, Mog2Config or KnnConfig, got "
        f"{type(config).__name__}"
    )


# a public submodule loads on first use after a bare ``import pftrack`` (``pftrack.detection.x``)
_, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
