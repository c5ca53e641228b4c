"""Trajectory recovery: goal-directed tracking (Oh & Jung 2015), baselines, tracklet linking.

One concept per module, from the bottom up:

- :mod:`~pftrack.recovery.segments`: checking observed segments, cutting them into runs;
- :mod:`~pftrack.recovery.noise`: noise levels of the constant-velocity model;
- :mod:`~pftrack.recovery.gdt`: the goal-directed state equation (the solver);
- :mod:`~pftrack.recovery.problems`: the ``gdt`` and ``gdt-bi`` problems of one gap;
- :mod:`~pftrack.recovery.baselines`: ``linear``, ``cubic``, ``bspline``, ``gsi``, ``rts``;
- :mod:`~pftrack.recovery.mixture`: ``gdt-mix``;
- :mod:`~pftrack.recovery.registry`: the methods by name, :func:`recover_gap`,
  :func:`recover_gaps`;
- :mod:`~pftrack.recovery.linking`, :mod:`~pftrack.recovery.fill`: tracklet linking and gap
  filling of MOTChallenge files;
- :mod:`~pftrack.recovery.experiment`, :mod:`~pftrack.recovery.demo`: the paper's experiment
  and the demo's table.
"""

from __future__ import annotations

from pftrack.recovery.fill import FillReport, fill_gaps
from pftrack.recovery.gdt import (
    GdtModel,
    GdtSolution,
    goal_directed_path,
    sample_goal_directed_paths,
)
from pftrack.recovery.linking import FLAG_COLUMN, LinkConfig, check_unique, link_tracklets
from pftrack.recovery.mixture import MotionFit, fit_motion
from pftrack.recovery.noise import NoiseEstimate, estimate_noise
from pftrack.recovery.problems import GdtProblem, SegmentModel, gdt_bi_problem, gdt_problem
from pftrack.recovery.registry import DEFAULT_METHOD, METHODS, recover_gap, recover_gaps

__all__ = [
    "DEFAULT_METHOD",
    "FLAG_COLUMN",
    "METHODS",
    "FillReport",
    "GdtModel",
    "GdtProblem",
    "GdtSolution",
    "LinkConfig",
    "MotionFit",
    "NoiseEstimate",
    "SegmentModel",
    "check_unique",
    "estimate_noise",
    "fill_gaps",
    "fit_motion",
    "gdt_bi_problem",
    "gdt_problem",
    "goal_directed_path",
    "link_tracklets",
    "recover_gap",
    "recover_gaps",
    "sample_goal_directed_paths",
]
