"""Type aliases shared across pftrack: each is defined here once."""

from __future__ import annotations

import numbers
import os
from typing import Any, Literal, TypeAlias

import numpy as np
from numpy.typing import NDArray

RngLike: TypeAlias = np.random.Generator | int | None
"""What every function that draws accepts: a generator, a seed, or None (fresh entropy)."""

PathLike: TypeAlias = str | os.PathLike[str]
"""A file or folder path."""

RealLike: TypeAlias = float | numbers.Real | np.floating[Any] | np.integer[Any]
"""A frame rate or a time in seconds: any real number (a ``fractions.Fraction``, PyAV's
``stream.average_rate``; a NumPy scalar), taken as its float (:func:`pftrack._check.real`)."""

IntLike: TypeAlias = int | np.integer[Any]
"""A count of frames: an int, NumPy's too (not a bool; :func:`pftrack._check.integer`)."""

F64: TypeAlias = NDArray[np.float64]
"""A float64 array (shapes are given in each docstring)."""

RecoveryMethod: TypeAlias = Literal[
    "auto", "gdt", "gdt-bi", "gdt-mix", "gdt-fixed", "linear", "cubic", "bspline", "gsi", "rts",
    "linear-nb", "rts-nb",
]  # fmt: skip
"""A recovery method's name (:data:`pftrack.recovery.METHODS`, the same values)."""

DetectorName: TypeAlias = Literal["paper", "mog2", "knn"]
"""A built-in detector (:data:`pftrack.detection.DETECTORS`)."""

SamplerName: TypeAlias = Literal["sis", "mh", "rjmcmc"]
"""A sampler of the tracker (:data:`pftrack.tracking.config.SAMPLERS`)."""

DynamicsName: TypeAlias = Literal["ar2", "ar2-mean"]
"""The particles' AR(2) model: on each particle's states, or on the particle set's means."""

CameraMotion: TypeAlias = Literal["auto", "on", "off"]
"""Camera-motion compensation (:data:`pftrack.tracking.config.CAMERA_MOTION`)."""

FillMode: TypeAlias = Literal["linear", "pf"]
"""How a tracker fills a track's coasted frames: interpolated, or the particle filter's boxes."""

BootstrapMode: TypeAlias = Literal["auto", "spread", "first", "none"]
"""Which frames prime the background model (:func:`pftrack.tracking.track_frames`)."""

BenchmarkName: TypeAlias = Literal["auto", "MOT15", "MOT16", "MOT17", "MOT20"]
"""MOTChallenge ground-truth rules of an evaluation (``"auto"``: guessed from the columns)."""

__all__ = [
    "F64",
    "BenchmarkName",
    "BootstrapMode",
    "CameraMotion",
    "DetectorName",
    "DynamicsName",
    "FillMode",
    "PathLike",
    "RecoveryMethod",
    "RngLike",
    "SamplerName",
]
