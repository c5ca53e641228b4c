r"""Metropolis-Hastings colour particle filter, one per object (the first paper's method 2).

Each frame the particle set is resampled, then every particle runs a short Metropolis-Hastings
chain whose target is its posterior ``p(z | x) p(x | x_{t-1})``; a proposal ``x* ~ q(x* | x)`` is
accepted with probability ``min(1, a)``,

.. math:: a = \frac{p(z|x^*)\, p(x^*|x_{t-1})\, q(x|x^*)}{p(z|x)\, p(x|x_{t-1})\, q(x^*|x)}
   \qquad \text{(eq. 5)}

otherwise the chain keeps ``x``. The kernel is ``pftrack._core.mh_step``
(cpp/include/pftrack/mh.hpp).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pftrack import _core
from pftrack._check import integer, option, real_array
from pftrack._limits import (
    DEFAULT_MH_PROPOSAL,
    DEFAULT_MH_RW_SIGMA,
    MH_PROPOSALS,
    proposal_error,
)
from pftrack._typing import RngLike
from pftrack.particle_filter.colour import HsvBinning
from pftrack.particle_filter.filter import ColourParticleFilter, FilterConfig, FilterState

__all__ = ["MHColourParticleFilter"]


class MHColourParticleFilter(ColourParticleFilter):
    """:class:`~pftrack.particle_filter.ColourParticleFilter` whose step is Metropolis-Hastings.

    Same construction, re-seeding and reference handling as the SIS filter (so the tracker can
    swap samplers), with ``_core.mh_step`` in place of ``sis_step``: resample, then for each
    particle propose ``x*`` from the AR(2) dynamics and accept with the paper's eq. 5.

    Parameters
    ----------
    box_cxcywh, reference, config, rng, velocity, binning
        As for :class:`~pftrack.particle_filter.ColourParticleFilter`.
    n_iter : int
        MH iterations per particle and frame, in [1, 2147483647] (the core's 32-bit int); a
        step evaluates the likelihood ``n_particles * (n_iter + 1)`` times.
    proposal : {"dynamics", "random_walk"}
        ``q(x* | x)``: ``"dynamics"`` (the default, the paper's) draws ``x*`` from the AR(2)
        dynamics of a parent chosen uniformly from the resampled set, independent of ``x``;
        ``"random_walk"`` moves ``x`` by a Gaussian step of `rw_sigma`, keeping its parent
        (cpp/include/pftrack/mh.hpp). ``TrackerConfig.mh_proposal``, ``--mh-proposal``.
    rw_sigma : (3,) array_like of float
        Standard deviations of the random-walk step (cx, cy in pixels, scale), each in [0,
        10000]; the dynamics proposal does not read them. Default ``(2.0, 2.0, 0.01)``.

    Raises
    ------
    TypeError
        `n_iter` not an int (a string, a float, a bool), `proposal` not text, `rw_sigma` not
        real numbers; else as :class:`~pftrack.particle_filter.ColourParticleFilter`.
    ValueError
        `n_iter` not in [1, 2147483647], `proposal` not one of the two, `rw_sigma` not 3
        finite values in [0, 10000], or other than its default with the dynamics proposal
        (it would do nothing); else as
        :class:`~pftrack.particle_filter.ColourParticleFilter`.

    Attributes
    ----------
    acceptance : float
        Accepted / proposed moves in the last step (NaN before the first).

    References
    ----------
    .. [1] Khan, Z., Balch, T., Dellaert, F. (2005). MCMC-based particle filtering for tracking a
       variable number of interacting targets. IEEE TPAMI 27(11).
    """

    def __init__(
        self,
        box_cxcywh: ArrayLike,
        reference: ArrayLike,
        config: FilterConfig | None = None,
        rng: RngLike = None,
        velocity: ArrayLike = (0.0, 0.0),
        n_iter: int = 1,
        *,
        binning: HsvBinning | None = None,
        proposal: str = DEFAULT_MH_PROPOSAL,
        rw_sigma: ArrayLike = DEFAULT_MH_RW_SIGMA,
    ) -> None:
        own = "MHColourParticleFilter"
        integer(n_iter, f"{own}: n_iter", 1, 2**31 - 1)
        option(proposal, f"{own}: proposal", MH_PROPOSALS)
        tau = real_array(rw_sigma, f"{own}: rw_sigma", booleans=False)
        if tau.ndim != 1:
            raise ValueError(f"{own}: rw_sigma has shape {tau.shape}, expected (3,)")
        refused = proposal_error(
            proposal, tuple(tau.tolist()), (f"{own}: proposal", f"{own}: rw_sigma"), cli=False
        )
        if refused:  # the tracker's and the command's check (pftrack._limits)
            raise ValueError(refused)
        super().__init__(box_cxcywh, reference, config, rng, velocity, binning=binning)
        self.n_iter = int(n_iter)
        self.proposal = proposal
        self.rw_sigma = tau.astype(np.float64)
        self.acceptance = float("nan")

    def step(self, image: _core.BinnedImage) -> FilterState:
        """Advance one frame with MH moves; records ``acceptance``.

        Raises as :meth:`ColourParticleFilter.step
        <pftrack.particle_filter.ColourParticleFilter.step>` (RuntimeError: another thread is
        inside this filter).
        """
        m = self.config.model

        def mh_step() -> dict[str, Any]:
            r: dict[str, Any] = _core.mh_step(
                self.particles, self.weights, self.means, image, self.reference,
                self.w0, self.h0, m.a, m.b, m.sigma, m.s_min, m.s_max, m.use_means,
                self.config.lam, self.config.kernel, True, self._seed, self._step,
                n_iter=self.n_iter, burn_in=0, proposal=self.proposal,
                rw_sigma=self.rw_sigma,
                min_samples=float(self.config.min_samples),
            )  # fmt: skip
            self.acceptance = float(r["acceptance"])
            return r

        return self._advance(image, "mh_step", mh_step)
