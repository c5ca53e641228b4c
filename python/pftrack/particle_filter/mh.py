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
from pftrack._check import integer
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

    Raises
    ------
    TypeError
        `n_iter` not an int (a string, a float, a bool); else as
        :class:`~pftrack.particle_filter.ColourParticleFilter`.
    ValueError
        `n_iter` not in [1, 2147483647]; else as
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
    ) -> None:
        integer(n_iter, "MHColourParticleFilter: n_iter", 1, 2**31 - 1)
        super().__init__(box_cxcywh, reference, config, rng, velocity, binning=binning)
        self.n_iter = int(n_iter)
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
                n_iter=self.n_iter, burn_in=0, proposal="dynamics",
                rw_sigma=np.array([2.0, 2.0, 0.01]),
                min_samples=float(self.config.min_samples),
            )  # fmt: skip
            self.acceptance = float(r["acceptance"])
            return r

        return self._advance(image, "mh_step", mh_step)
