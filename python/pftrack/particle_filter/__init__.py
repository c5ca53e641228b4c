"""Colour particle filters and the comparison samplers (Metropolis-Hastings, RJ-MCMC)."""

from __future__ import annotations

from pftrack.particle_filter.mh import MHConfig, MHParticleFilter, MHState, mh_step
from pftrack.particle_filter.rjmcmc import RJMCMCConfig, RJMCMCFilter, RJTrack

__all__ = [
    "MHConfig",
    "MHParticleFilter",
    "MHState",
    "RJMCMCConfig",
    "RJMCMCFilter",
    "RJTrack",
    "mh_step",
]
