"""Run a tracker over a whole video or image folder: the library behind ``pftrack track``."""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pftrack._progress import progress
from pftrack._typing import F64, PathLike, RngLike
from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.io.mot import group_by_frame, read_mot
from pftrack.io.video import FrameSource
from pftrack.recovery.linking import LinkConfig
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.offline import BoxSmoother
from pftrack.tracking.tracker import MultiObjectTracker
from pftrack.tracking.writer import TrackWriter

__all__ = ["TrackingRun", "load_detections", "track_frames"]


@dataclass(frozen=True)
class TrackingRun:
    """Result of :func:`track_frames`.

    Attributes
    ----------
    rows : (M, 10) ndarray
        MOTChallenge rows (1-based frames) in the frame's pixel coordinates.
    n_frames : int
        Frames processed.
    seconds : float
        Wall time of decoding, detection and tracking.
    """

    rows: F64
    n_frames: int
    seconds: float

    @property
    def fps(self) -> float:
        """Frames per second over the whole run."""
        return self.n_frames / self.seconds if self.seconds > 0 else float("inf")


def load_detections(path: PathLike, scale: float = 1.0) -> dict[int, F64]:
    """Read a MOTChallenge detection file as ``{frame: (k, 5) [left, top, w, h, score]}``.

    Parameters
    ----------
    path : str or os.PathLike
        ``det.txt`` (``frame,-1,left,top,width,height,score,...``).
    scale : float
        Multiplies the box coordinates (e.g. 0.625 for PETS09 boxes on the 480x360 video).
    """
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"detection scale is {scale}, expected a finite value > 0")
    rows = read_mot(path, what="detection file")
    return {
        f: np.column_stack([r[:, 2:6] * scale, r[:, 6]]) for f, r in group_by_frame(rows).items()
    }


def track_frames(
    source: PathLike | FrameSource | Sequence[NDArray[np.uint8]],
    *,
    detections: dict[int, F64] | None = None,
    config: TrackerConfig | None = None,
    rng: RngLike = None,
    coasting: str = "confirmed",
    fill: str = "linear",
    show_progress: bool | None = None,
    prime_frames: int = 30,
    bootstrap: str = "spread",
    smoother: BoxSmoother | None = BoxSmoother(),  # noqa: B008 - frozen, shared safely
    link: LinkConfig | None = LinkConfig(),  # noqa: B008 - frozen, shared safely
) -> TrackingRun:
    """Track every frame of `source`.

    Parameters
    ----------
    source : path, FrameSource or sequence of frames
        Video file or image folder, or BGR uint8 frames in memory.
    detections : dict, optional
        Per-frame detections from :func:`load_detections`; None uses the built-in detector.
    config : TrackerConfig, optional
        Tracker settings (default ``TrackerConfig()``).
    rng : numpy.random.Generator, int or None
        Seed.
    coasting, fill : str
        How gaps bridged by the particle filters are written (see
        :class:`~pftrack.tracking.TrackWriter`).
    show_progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal).
    prime_frames : int
        Start the built-in detector's background from the median of this many frames (0: learn
        from frame 1 on).
    bootstrap : {"spread", "first", "none"}
        Which frames (:func:`pftrack.detection.bootstrap.bootstrap_frames`): spread over the
        whole video (a first pass over a file or in-memory frames), the first ones, or none.
    smoother : BoxSmoother or None
        Offline smoothing of every track's boxes once the run is over (None: boxes as the
        tracker reported them, frame by frame).
    link : LinkConfig or None
        Join fragments of one object once the run is over (None: keep every id).
    """
    config = config if config is not None else TrackerConfig()
    frames = FrameSource(source) if isinstance(source, (str, os.PathLike)) else source
    if detections is not None and len(detections) and max(detections) > max(len(frames), 1) > 1:
        raise ValueError(
            f"detections go up to frame {max(detections)} but the video has {len(frames)} frames"
        )
    tracker = MultiObjectTracker(config, rng=rng)
    if prime_frames > 0 and (detections is None or config.refine.enabled):
        primer = bootstrap_frames(frames, prime_frames, bootstrap)
        if primer:
            tracker.prime(primer)
    writer = TrackWriter(coasting, fill, smoother, link)
    empty = np.zeros((0, 5))
    start = time.perf_counter()
    n = 0
    total = len(frames) or None
    for n, frame in enumerate(
        progress(frames, total=total, desc="tracking", enable=show_progress), start=1
    ):
        dets = None if detections is None else detections.get(n, empty)
        writer.add(n, tracker.update(frame, dets))
    if n == 0:
        raise ValueError(f"no frame could be read from {source}")
    return TrackingRun(writer.result(), n, time.perf_counter() - start)
