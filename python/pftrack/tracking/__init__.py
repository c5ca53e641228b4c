"""Multi-object tracking: the online tracker, its settings and the offline pass.

- :class:`MultiObjectTracker` (:mod:`.tracker`): frame by frame, one colour particle filter per
  object; :class:`TrackerConfig` and its parts (:mod:`.config`); :class:`Track` (:mod:`.track`).
- :class:`TrackWriter` (:mod:`.writer`): a run's tracks as MOTChallenge rows.
- :class:`BoxSmoother`, :func:`smooth_tracks` (:mod:`.offline`): link, fill and smooth a
  finished run (any tracker's); :func:`repair_crossings` (:class:`CrossingConfig`): tracks
  swapped where they crossed, exchanged back.
- :class:`Tracker` (:mod:`.api`): the drop-in tracker (``update(dets, frame)``, ``finalize()``),
  the one object behind both a user's loop and ``pftrack track``.
- :func:`track_frames`, :func:`load_detections` (:mod:`.run`): a whole video, end to end.
"""

from __future__ import annotations

from pftrack._lazy import lazy_exports
from pftrack.tracking.api import Tracker
from pftrack.tracking.config import (
    AssociationConfig,
    CameraConfig,
    LifecycleConfig,
    MotionConfig,
    RefineConfig,
    TrackerConfig,
)
from pftrack.tracking.offline import BoxSmoother, CrossingConfig, repair_crossings, smooth_tracks
from pftrack.tracking.run import TrackingRun, load_detections, track_frames
from pftrack.tracking.track import Track
from pftrack.tracking.tracker import MultiObjectTracker
from pftrack.tracking.writer import TrackWriter

__all__ = [
    "AssociationConfig",
    "BoxSmoother",
    "CameraConfig",
    "CrossingConfig",
    "LifecycleConfig",
    "MotionConfig",
    "MultiObjectTracker",
    "RefineConfig",
    "Track",
    "TrackWriter",
    "Tracker",
    "TrackerConfig",
    "TrackingRun",
    "load_detections",
    "repair_crossings",
    "smooth_tracks",
    "track_frames",
]

# a public submodule loads on first use after a bare ``import pftrack`` (``pftrack.tracking.x``)
_, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
