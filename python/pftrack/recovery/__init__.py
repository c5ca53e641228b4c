"""Trajectory recovery: goal-directed tracking (Oh & Jung 2015), baselines, tracklet linking."""

from __future__ import annotations

from pftrack.recovery.gdt import (
    GdtModel,
    GdtSolution,
    constant_velocity_A,
    goal_directed_path,
    sample_goal_directed_paths,
)
from pftrack.recovery.methods import (
    METHODS,
    NoiseEstimate,
    estimate_noise,
    recover_gap,
    recover_gaps,
)

__all__ = [
    "METHODS",
    "GdtModel",
    "GdtSolution",
    "NoiseEstimate",
    "constant_velocity_A",
    "estimate_noise",
    "goal_directed_path",
    "recover_gap",
    "recover_gaps",
    "sample_goal_directed_paths",
]
