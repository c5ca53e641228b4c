"""Metropolis-Hastings colour particle filter, one per object (the first paper's method 2).

Each frame the particle set is resampled, then every particle runs a short Metropolis-Hastings
chain whose target is its posterior ``p(z | x) p(x | x_{t-1})``; a proposal ``x* ~ q(x* | x)`` is
accepted with probability ``min(1, a)``,

.. math:: a = \\frac{p(z|x^*)\\, p(x^*|x_{t-1})\\, q(x|x^*)}{p(z|x)\\, p(x|x_{t-1})\\, q(x^*|x)}
   \\qquad \\text{(eq. 5)}

otherwise the chain keeps ``x``. The kernel is ``pftrack._core.mh_step`` (cpp/include/pftrack/mh.hpp).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._typing import RngLike
from pftrack.particle_filter.filter import ColourParticleFilter, FilterConfig, FilterState

_PROPOSALS = ("dynamics", "random_walk")
_KERNELS = ("uniform", "epanechnikov")


@dataclass(frozen=True)
class MHConfig:
    """Settings of a Metropolis-Hastings particle filter.

    Parameters
    ----------
    n_particles : int
        Number of particles (= number of parallel chains).
    n_iter : int
        Metropolis-Hastings iterations per particle and frame (chain length per particle). A step
        evaluates the likelihood ``n_particles * (n_iter + 1)`` times.
    burn_in : int
        Leading iterations of each chain left out of the acceptance rate and the mean estimate;
        ``0 <= burn_in < n_iter``.
    proposal : {"dynamics", "random_walk"}
        ``q(x* | x)``: a fresh draw of the AR2 dynamics (independence sampler), or a Gaussian random
        walk around ``x`` with standard deviations ``rw_sigma``.
    rw_sigma : tuple of 3 float
        Random-walk standard deviations of cx, cy (pixels) and s.
    a, b, sigma : tuple of 3 float
        AR2 dynamics ``x_t = a x_{t-1} + b x_{t-2} + sigma w`` per component (cx, cy, s).
    s_min, s_max : float
        Scale bounds; the dynamics density is truncated to them.
    use_means : bool
        Predict from the particle-set means (eq. 8) instead of each particle's own past (eq. 7).
    lam : float
        ``lambda`` of the colour likelihood ``exp(-lambda D^2)``.
    kernel : {"uniform", "epanechnikov"}
        Histogram kernel.
    estimate : {"mean", "map"}
        Which estimate ``step`` reports as the box.
    """

    n_particles: int = 100
    n_iter: int = 1
    burn_in: int = 0
    proposal: str = "dynamics"
    rw_sigma: tuple[float, float, float] = (2.0, 2.0, 0.01)
    a: tuple[float, float, float] = (2.0, 2.0, 2.0)
    b: tuple[float, float, float] = (-1.0, -1.0, -1.0)
    sigma: tuple[float, float, float] = (4.0, 4.0, 0.02)
    s_min: float = 0.2
    s_max: float = 5.0
    use_means: bool = False
    lam: float = 20.0
    kernel: str = "uniform"
    estimate: str = "mean"

    def __post_init__(self) -> None:
        if self.n_particles < 1:
            raise ValueError(f"MHConfig: n_particles is {self.n_particles}, expected >= 1")
        if self.n_iter < 1:
            raise ValueError(f"MHConfig: n_iter is {self.n_iter}, expected >= 1")
        if not 0 <= self.burn_in < self.n_iter:
            raise ValueError(f"MHConfig: burn_in is {self.burn_in}, expected in [0, n_iter)")
        if self.proposal not in _PROPOSALS:
            raise ValueError(f"MHConfig: proposal is {self.proposal!r}, expected one of {_PROPOSALS}")
        if self.kernel not in _KERNELS:
            raise ValueError(f"MHConfig: kernel is {self.kernel!r}, expected one of {_KERNELS}")
        if self.estimate not in ("mean", "map"):
            raise ValueError(f"MHConfig: estimate is {self.estimate!r}, expected 'mean' or 'map'")


@dataclass(frozen=True)
class MHState:
    """What one step of an :class:`MHParticleFilter` reports.

    Attributes
    ----------
    box_cxcywh : (4,) ndarray of float64
        Estimated box (cx, cy, w, h).
    acceptance : float
        Accepted / proposed moves over the post-burn-in iterations of this step.
    rho : float
        Mean Bhattacharyya coefficient of the particles (how well the track is explained).
    rho_max : float
        Best coefficient among the particles.
    ess : float
        Effective sample size (``n_particles``: MCMC samples are equally weighted).
    foreground : float
        Mean counted (foreground) pixels per particle box.
    """

    box_cxcywh: NDArray[np.float64]
    acceptance: float
    rho: float
    rho_max: float
    ess: float
    foreground: float


def mh_step(
    particles: NDArray[np.float64],
    weights: NDArray[np.float64],
    means: NDArray[np.float64],
    image: _core.BinnedImage,
    ref: ArrayLike,
    w0: float,
    h0: float,
    config: MHConfig,
    seed: int,
    step: int,
) -> dict[str, Any]:
    """Advance one particle set by one frame with per-particle Metropolis-Hastings chains.

    Parameters
    ----------
    particles : (N, 6) ndarray of float64, C-contiguous
        Rows ``[cx, cy, s, prev cx, prev cy, prev s]``, updated in place.
    weights : (N,) ndarray of float64
        Weights, used for resampling and then set to ``1/N`` in place.
    means : (2, 3) ndarray of float64
        Particle-set mean states at t-1 and t-2, updated in place.
    image : pftrack._core.BinnedImage
        The frame's bins (``hsv_bins``).
    ref : (B,) array_like of float
        Reference histogram.
    w0, h0 : float
        Base box size: a particle's box is ``(cx, cy, s w0, s h0)``.
    config : MHConfig
        Sampler settings.
    seed, step : int
        Key of the counter-based random numbers: fixed ``(seed, step)``, fixed result.

    Returns
    -------
    dict
        ``mean``, ``map`` (3,), ``map_index``, ``ess``, ``rho_max``, ``rho_mean``, ``fg_mean`` as
        ``sis_step``, plus ``acceptance``.

    References
    ----------
    .. [1] Metropolis, N. et al. (1953); Hastings, W. K. (1970). Biometrika 57(1).
    """
    c = config
    return dict(
        _core.mh_step(
            particles, weights, means, image, np.ascontiguousarray(ref, dtype=np.float64),
            float(w0), float(h0), np.asarray(c.a, float), np.asarray(c.b, float),
            np.asarray(c.sigma, float), c.s_min, c.s_max, c.use_means, c.lam, c.kernel, True,
            int(seed), int(step), n_iter=c.n_iter, burn_in=c.burn_in, proposal=c.proposal,
            rw_sigma=np.asarray(c.rw_sigma, float),
        )
    )


class MHParticleFilter:
    """A colour particle filter whose particles move by Metropolis-Hastings (one per object).

    Parameters
    ----------
    box_cxcywh : (4,) array_like of float
        Initial box (cx, cy, w, h); (w, h) is the base size, scale 1.
    ref_hist : (B,) array_like of float
        Reference colour histogram of the object.
    config : MHConfig, optional
        Settings (default ``MHConfig()``).
    rng : numpy.random.Generator, int or None
        Source of the seed of the C++ counter-based draws.

    References
    ----------
    .. [1] Khan, Z., Balch, T., Dellaert, F. (2005). MCMC-based particle filtering for tracking a
       variable number of interacting targets. IEEE TPAMI 27(11).
    """

    def __init__(
        self,
        box_cxcywh: ArrayLike,
        ref_hist: ArrayLike,
        config: MHConfig | None = None,
        rng: RngLike = None,
    ) -> None:
        box = np.asarray(box_cxcywh, dtype=np.float64).reshape(-1)
        if box.shape != (4,) or not np.all(np.isfinite(box)) or box[2] <= 0 or box[3] <= 0:
            raise ValueError(f"MHParticleFilter: box_cxcywh is {box}, expected finite (cx, cy, w, h) with w, h > 0")
        self.config = config if config is not None else MHConfig()
        self.ref = np.ascontiguousarray(ref_hist, dtype=np.float64).reshape(-1)
        self.w0, self.h0 = float(box[2]), float(box[3])
        n = self.config.n_particles
        state = np.array([box[0], box[1], 1.0])
        self.particles = np.ascontiguousarray(np.tile(np.concatenate([state, state]), (n, 1)))
        self.weights = np.full(n, 1.0 / n)
        self.means = np.ascontiguousarray(np.tile(state, (2, 1)))
        self.seed = int(np.random.default_rng(rng).integers(2**63))
        self.n_steps = 0
        self.last: dict[str, Any] = {}

    def step(self, image: _core.BinnedImage) -> MHState:
        """Track the object into the next frame.

        Parameters
        ----------
        image : pftrack._core.BinnedImage
            The frame's bins.

        Returns
        -------
        MHState
            The box estimate and the step's diagnostics (acceptance rate among them).
        """
        r = mh_step(self.particles, self.weights, self.means, image, self.ref, self.w0, self.h0,
                    self.config, self.seed, self.n_steps)
        self.n_steps += 1
        self.last = r
        x = r["mean"] if self.config.estimate == "mean" else r["map"]
        box = np.array([x[0], x[1], x[2] * self.w0, x[2] * self.h0])
        return MHState(box, float(r["acceptance"]), float(r["rho_mean"]), float(r["rho_max"]),
                       float(r["ess"]), float(r["fg_mean"]))


class MHColourParticleFilter(ColourParticleFilter):
    """:class:`~pftrack.particle_filter.ColourParticleFilter` whose step is Metropolis-Hastings.

    Same construction, re-seeding and reference handling as the SIS filter (so the tracker can
    swap samplers), with ``_core.mh_step`` in place of ``sis_step``: resample, then for each
    particle propose ``x*`` from the AR(2) dynamics and accept with the paper's eq. 5.

    Parameters
    ----------
    box_cxcywh, reference, config, rng, velocity
        As for :class:`~pftrack.particle_filter.ColourParticleFilter`.
    n_iter : int
        MH iterations per particle and frame.
    """

    def __init__(self, box_cxcywh: ArrayLike, reference: ArrayLike,
                 config: FilterConfig = FilterConfig(), rng: RngLike = None,
                 velocity: ArrayLike = (0.0, 0.0), n_iter: int = 1) -> None:  # fmt: skip
        super().__init__(box_cxcywh, reference, config, rng, velocity)
        self.n_iter = int(n_iter)
        self.acceptance = float("nan")

    def step(self, image: _core.BinnedImage) -> FilterState:
        """Advance one frame with MH moves; records ``acceptance``."""
        m = self.config.model
        r = _core.mh_step(
            self.particles, self.weights, self.means, image, self.reference,
            self.w0, self.h0, m.a, m.b, m.sigma, m.s_min, m.s_max, m.use_means,
            self.config.lam, self.config.kernel, True, self._seed, self._step,
            n_iter=self.n_iter, burn_in=0, proposal="dynamics",
            rw_sigma=np.array([2.0, 2.0, 0.01]),
        )  # fmt: skip
        self._step += 1
        self.acceptance = float(r["acceptance"])
        cx, cy, s = r["map"] if self.config.estimate == "map" else r["mean"]
        state = FilterState(np.array([cx, cy, s * self.w0, s * self.h0]), float(r["rho_mean"]),
                            float(r["rho_max"]), float(r["ess"]), float(r["fg_mean"]))  # fmt: skip
        self.last = state
        return state
