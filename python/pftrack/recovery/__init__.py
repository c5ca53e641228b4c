"""Trajectory recovery: goal-directed tracking (Oh & Jung 2015), baselines, tracklet linking.

One concept per module, from the bottom up:

- :mod:`~pftrack.recovery.segments`: checking observed segments, cutting them into runs;
- :mod:`~pftrack.recovery.noise`: noise levels of the constant-velocity model;
- :mod:`~pftrack.recovery.gdt`: the goal-directed state equation (the solver);
- :mod:`~pftrack.recovery.problems`: the ``gdt`` and ``gdt-bi`` problems of one gap;
- :mod:`~pftrack.recovery.baselines`: ``linear``, ``cubic``, ``bspline``, ``gsi``, ``rts``;
- :mod:`~pftrack.recovery.mixture`: ``gdt-mix``;
- :mod:`~pftrack.recovery.names`, :mod:`~pftrack.recovery.registry`: the methods by name,
  :func:`recover_gap`, :func:`recover_gaps`;
- :mod:`~pftrack.recovery.linking`, :mod:`~pftrack.recovery.fill`: tracklet linking and gap
  filling of MOTChallenge files;
- :mod:`~pftrack.recovery.experiment`, :mod:`~pftrack.recovery.demo`: the paper's experiment
  and the demo's table.

The names below load their module on first use (PEP 562), so listing the methods
(:mod:`~pftrack.recovery.names`) does not load SciPy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pftrack._lazy import lazy_exports

if TYPE_CHECKING:
    from pftrack.recovery.fill import FillReport, fill_gaps
    from pftrack.recovery.gdt import (
        GdtModel,
        GdtSolution,
        goal_directed_path,
        sample_goal_directed_paths,
    )
    from pftrack.recovery.linking import (
        FLAG_COLUMN,
        LinkConfig,
        check_unique,
        filled_mask,
        link_tracklets,
    )
    from pftrack.recovery.mixture import MotionFit, fit_motion
    from pftrack.recovery.names import DEFAULT_METHOD, METHODS
    from pftrack.recovery.noise import NoiseEstimate, estimate_noise
    from pftrack.recovery.problems import GdtProblem, SegmentModel, gdt_bi_problem, gdt_problem
    from pftrack.recovery.registry import recover_gap, recover_gaps

_HOME = {
    "pftrack.recovery.fill": ("FillReport", "fill_gaps"),
    "pftrack.recovery.gdt": (
        "GdtModel",
        "GdtSolution",
        "goal_directed_path",
        "sample_goal_directed_paths",
    ),
    "pftrack.recovery.linking": (
        "FLAG_COLUMN",
        "LinkConfig",
        "check_unique",
        "filled_mask",
        "link_tracklets",
    ),
    "pftrack.recovery.mixture": ("MotionFit", "fit_motion"),
    "pftrack.recovery.noise": ("NoiseEstimate", "estimate_noise"),
    "pftrack.recovery.problems": ("GdtProblem", "SegmentModel", "gdt_bi_problem", "gdt_problem"),
    "pftrack.recovery.registry": ("recover_gap", "recover_gaps"),
    "pftrack.recovery.names": ("DEFAULT_METHOD", "METHODS"),
}

__all__ = [
    "DEFAULT_METHOD",
    "FLAG_COLUMN",
    "FillReport",
    "GdtModel",
    "GdtProblem",
    "GdtSolution",
    "LinkConfig",
    "METHODS",
    "MotionFit",
    "NoiseEstimate",
    "SegmentModel",
    "check_unique",
    "estimate_noise",
    "fill_gaps",
    "filled_mask",
    "fit_motion",
    "gdt_bi_problem",
    "gdt_problem",
    "goal_directed_path",
    "link_tracklets",
    "recover_gap",
    "recover_gaps",
    "sample_goal_directed_paths",
]


_MODULE_OF, __getattr__, __dir__ = lazy_exports(__name__, _HOME, globals())
