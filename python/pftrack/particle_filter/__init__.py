"""Colour particle filters and their building blocks (resampling, dynamics, likelihood)."""

from __future__ import annotations

from pftrack._lazy import lazy_exports
from pftrack.particle_filter.colour import (
    BinnedImage,
    HsvBinning,
    bhattacharyya_coefficient,
    bhattacharyya_distance,
    bhattacharyya_weights,
    box_histograms,
    box_weights,
    hsv_bins,
)
from pftrack.particle_filter.dynamics import Ar2Model, estimate, propagate
from pftrack.particle_filter.filter import ColourParticleFilter, FilterConfig, FilterState
from pftrack.particle_filter.mh import MHColourParticleFilter
from pftrack.particle_filter.resample import (
    multinomial_resample,
    residual_resample,
    stratified_resample,
    systematic_resample,
)
from pftrack.particle_filter.rjmcmc import RJMCMCConfig, RJMCMCFilter, RJTrack

__all__ = [
    "Ar2Model",
    "BinnedImage",
    "ColourParticleFilter",
    "FilterConfig",
    "FilterState",
    "HsvBinning",
    "MHColourParticleFilter",
    "RJMCMCConfig",
    "RJMCMCFilter",
    "RJTrack",
    "bhattacharyya_coefficient",
    "bhattacharyya_distance",
    "bhattacharyya_weights",
    "box_histograms",
    "box_weights",
    "estimate",
    "hsv_bins",
    "multinomial_resample",
    "propagate",
    "residual_resample",
    "stratified_resample",
    "systematic_resample",
]

# public submodules load on first use after a bare ``import pftrack``
_, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
