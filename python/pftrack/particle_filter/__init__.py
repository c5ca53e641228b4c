"""Colour particle filters and their building blocks (resampling, dynamics, likelihood)."""

from __future__ import annotations

from pftrack.particle_filter.colour import (
    BinnedImage,
    HsvBinning,
    bhattacharyya_coefficient,
    bhattacharyya_distance,
    bhattacharyya_weights,
    box_histograms,
    hsv_bins,
)
from pftrack.particle_filter.dynamics import Ar2Model, estimate, propagate
from pftrack.particle_filter.filter import ColourParticleFilter, FilterConfig, FilterState
from pftrack.particle_filter.mh import (
    MHColourParticleFilter,
    MHConfig,
    MHParticleFilter,
    MHState,
    mh_step,
)
from pftrack.particle_filter.rjmcmc import RJMCMCConfig, RJMCMCFilter, RJTrack
from pftrack.particle_filter.resample import (
    multinomial_resample,
    residual_resample,
    stratified_resample,
    systematic_resample,
)

__all__ = [
    "Ar2Model",
    "BinnedImage",
    "ColourParticleFilter",
    "FilterConfig",
    "FilterState",
    "HsvBinning",
    "MHColourParticleFilter",
    "MHConfig",
    "MHParticleFilter",
    "MHState",
    "RJMCMCConfig",
    "RJMCMCFilter",
    "RJTrack",
    "bhattacharyya_coefficient",
    "bhattacharyya_distance",
    "bhattacharyya_weights",
    "box_histograms",
    "estimate",
    "hsv_bins",
    "mh_step",
    "multinomial_resample",
    "propagate",
    "residual_resample",
    "stratified_resample",
    "systematic_resample",
]
