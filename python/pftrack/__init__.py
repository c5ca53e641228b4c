"""pftrack: colour particle-filter multi-object tracking and trajectory recovery.

The public API, importable from the top level; each name loads its module on first use, so
``import pftrack`` (and ``pftrack --help``) stays fast:

- tracking: :class:`Tracker` (the drop-in ``update(dets, frame)`` / ``finalize()`` API),
  :class:`MultiObjectTracker`, :class:`TrackerConfig`, :class:`Track`, :func:`track_frames`,
  :class:`TrackingRun`, :func:`load_detections`, :func:`smooth_tracks`, :class:`BoxSmoother`;
- recovery: :func:`recover_gap`, :func:`recover_gaps`, :func:`fill_gaps` (its
  :class:`FillReport`), :func:`filled_mask`, :data:`METHODS`, :func:`link_tracklets`,
  :class:`LinkConfig`, :func:`goal_directed_path` (its :class:`GdtSolution`);
- MOTChallenge files and video: :func:`read_mot`, :func:`write_mot`, :class:`FrameSource`
  (files, image folders, sequences, cameras, streams), :func:`read_seqinfo`,
  :class:`SequenceInfo`, :class:`VideoWriter` (H.264 MP4);
- pictures: :class:`TrackRenderer` (annotated video while tracking),
  :func:`write_annotated_video`, :func:`plot_trajectories`;
- evaluation: :func:`evaluate_sequence` (HOTA and CLEAR-MOT/IDF1), :func:`evaluate_hota`,
  :func:`evaluate_mot` and what they return, :class:`SequenceScores`, :class:`HotaMetrics`,
  :class:`MotMetrics`; :func:`format_metrics`;
- kernels: :class:`ColourParticleFilter`, the resamplers (drop-in for
  ``filterpy.monte_carlo``) :func:`systematic_resample`, :func:`stratified_resample`,
  :func:`multinomial_resample`, :func:`residual_resample`, and :func:`hsv_bins`,
  :func:`box_histograms`, :func:`bhattacharyya_weights`, :func:`bhattacharyya_coefficient`,
  :func:`bhattacharyya_distance`, :func:`box_weights` (the last two fused: the fastest path;
  :func:`hsv_bins` gives a :class:`BinnedImage`);
- :func:`make_scene`, a synthetic :class:`Scene` with known truth.

Subpackages and modules are attributes too, loaded on first use like the names above:
``pftrack.batch.track_many``, ``pftrack.recovery.filled_mask``, ``pftrack.io.video``.
"""

from __future__ import annotations

import importlib.util
from typing import TYPE_CHECKING

from pftrack._lazy import lazy_exports


def _no_core_message() -> str:
    """Why ``pftrack._core`` cannot be found: no build, or a source checkout before the install.

    A source checkout (``python/pftrack`` on ``sys.path``: the current folder, ``PYTHONPATH``)
    hides an installed pftrack whose core is built; building is then not the fix.
    """
    import importlib.metadata
    import os

    here = os.path.dirname(os.path.abspath(__file__))
    try:
        dist = importlib.metadata.distribution("pftrack")
        init = os.path.abspath(str(dist.locate_file("pftrack/__init__.py")))
        version = dist.version
    except (importlib.metadata.PackageNotFoundError, OSError, ValueError):
        init, version = __file__, ""
    installed = os.path.dirname(init)
    if installed != here and os.path.isfile(init):  # not an editable install's redirect
        return (
            f"a source checkout at {here} is shadowing the installed pftrack {version} "
            f"({installed}), and its compiled core (pftrack._core) is not built: run from "
            "another folder (or take the checkout off PYTHONPATH)"
        )
    return (
        "pftrack's compiled core (pftrack._core) is not built: install with `pip install .` "
        "or, for development, `pip install --no-build-isolation -ve .`"
    )


# found, not imported: loading it (and NumPy) waits for the first name that needs it, so
# `pftrack --help` stays fast
if importlib.util.find_spec("pftrack._core") is None:
    raise ImportError(_no_core_message())

if TYPE_CHECKING:
    # the subpackages and modules, for type checkers: at run time __getattr__ loads them
    from pftrack import assignment as assignment
    from pftrack import batch as batch
    from pftrack import boxes as boxes
    from pftrack import cli as cli
    from pftrack import demo as demo
    from pftrack import detection as detection
    from pftrack import eval as eval
    from pftrack import integrations as integrations
    from pftrack import io as io
    from pftrack import kalman as kalman
    from pftrack import particle_filter as particle_filter
    from pftrack import recovery as recovery
    from pftrack import render as render
    from pftrack import synthetic as synthetic
    from pftrack import tracking as tracking
    from pftrack.eval import (
        HotaMetrics,
        MotMetrics,
        SequenceScores,
        evaluate_hota,
        evaluate_mot,
        evaluate_sequence,
        format_metrics,
    )
    from pftrack.io.mot import read_mot, write_mot
    from pftrack.io.video import FrameSource, SequenceInfo, read_seqinfo
    from pftrack.io.video_writer import VideoWriter
    from pftrack.particle_filter import (
        BinnedImage,
        ColourParticleFilter,
        bhattacharyya_coefficient,
        bhattacharyya_distance,
        bhattacharyya_weights,
        box_histograms,
        box_weights,
        hsv_bins,
        multinomial_resample,
        residual_resample,
        stratified_resample,
        systematic_resample,
    )
    from pftrack.recovery import (
        METHODS,
        FillReport,
        GdtSolution,
        LinkConfig,
        fill_gaps,
        filled_mask,
        goal_directed_path,
        link_tracklets,
        recover_gap,
        recover_gaps,
    )
    from pftrack.render import TrackRenderer, plot_trajectories, write_annotated_video
    from pftrack.synthetic import Scene, make_scene
    from pftrack.tracking import (
        BoxSmoother,
        MultiObjectTracker,
        Track,
        Tracker,
        TrackerConfig,
        TrackingRun,
        load_detections,
        smooth_tracks,
        track_frames,
    )

__version__ = "0.1.0"

_HOME = {
    "pftrack.tracking": (
        "BoxSmoother",
        "MultiObjectTracker",
        "Track",
        "Tracker",
        "TrackerConfig",
        "TrackingRun",
        "load_detections",
        "smooth_tracks",
        "track_frames",
    ),
    "pftrack.recovery": (
        "FillReport",
        "GdtSolution",
        "LinkConfig",
        "METHODS",
        "fill_gaps",
        "filled_mask",
        "goal_directed_path",
        "link_tracklets",
        "recover_gap",
        "recover_gaps",
    ),
    "pftrack.io.mot": ("read_mot", "write_mot"),
    "pftrack.io.video": ("FrameSource", "SequenceInfo", "read_seqinfo"),
    "pftrack.io.video_writer": ("VideoWriter",),
    "pftrack.render": ("TrackRenderer", "plot_trajectories", "write_annotated_video"),
    "pftrack.eval": (
        "HotaMetrics",
        "MotMetrics",
        "SequenceScores",
        "evaluate_hota",
        "evaluate_mot",
        "evaluate_sequence",
        "format_metrics",
    ),
    "pftrack.particle_filter": (
        "BinnedImage",
        "ColourParticleFilter",
        "bhattacharyya_coefficient",
        "bhattacharyya_distance",
        "bhattacharyya_weights",
        "box_histograms",
        "box_weights",
        "hsv_bins",
        "multinomial_resample",
        "residual_resample",
        "stratified_resample",
        "systematic_resample",
    ),
    "pftrack.synthetic": ("Scene", "make_scene"),
}

__all__ = [
    "__version__",
    "BinnedImage",
    "BoxSmoother",
    "ColourParticleFilter",
    "FillReport",
    "FrameSource",
    "GdtSolution",
    "HotaMetrics",
    "LinkConfig",
    "METHODS",
    "MotMetrics",
    "MultiObjectTracker",
    "Scene",
    "SequenceInfo",
    "SequenceScores",
    "Track",
    "TrackRenderer",
    "Tracker",
    "TrackerConfig",
    "TrackingRun",
    "VideoWriter",
    "bhattacharyya_coefficient",
    "bhattacharyya_distance",
    "bhattacharyya_weights",
    "box_histograms",
    "box_weights",
    "evaluate_hota",
    "evaluate_mot",
    "evaluate_sequence",
    "fill_gaps",
    "filled_mask",
    "format_metrics",
    "goal_directed_path",
    "hsv_bins",
    "link_tracklets",
    "load_detections",
    "make_scene",
    "multinomial_resample",
    "plot_trajectories",
    "read_mot",
    "read_seqinfo",
    "recover_gap",
    "recover_gaps",
    "residual_resample",
    "smooth_tracks",
    "stratified_resample",
    "systematic_resample",
    "track_frames",
    "write_annotated_video",
    "write_mot",
]


_MODULE_OF, __getattr__, __dir__ = lazy_exports(__name__, _HOME, globals())
