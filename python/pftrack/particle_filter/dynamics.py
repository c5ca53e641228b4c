"""Second-order autoregressive dynamics over a box's centre and scale (the first paper's eq. 6-8).

A particle is one row ``[cx, cy, s, cx', cy', s']``: the current state and the previous one.
Its box is ``(cx, cy, s*w0, s*h0)`` for the track's base size ``(w0, h0)``.

- eq. 7, ``"ar2"``: ``x_t = A x_{t-1} + B x_{t-2} + C w_t`` per particle, ``w_t ~ N(0, I)``;
  ``A = 2, B = -1`` is constant velocity.
- eq. 8, ``"ar2-mean"``: the particle-set means ``m_{t-1}, m_{t-2}`` replace each particle's own
  previous states: ``x_t = A m_{t-1} + B m_{t-2} + C w_t``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import number

__all__ = ["Ar2Model", "estimate", "propagate"]


@dataclass(frozen=True)
class Ar2Model:
    """Parameters of the AR(2) model.

    Attributes
    ----------
    sigma_xy : float
        Standard deviation of the centre noise, pixels per frame.
    sigma_s : float
        Standard deviation of the scale noise per frame.
    velocity_gain : float
        ``A = 1 + g``, ``B = -g`` for the centre: 1 is the paper's constant velocity, 0 a random
        walk, values in between damp the velocity.
    scale_gain : float
        The same for the scale (1: the paper's AR(2) on scale too; 0: a random walk).
    s_min, s_max : float
        Bounds on the scale relative to the track's base size.
    use_means : bool
        eq. 8 (particle-set means) instead of eq. 7.
    """

    sigma_xy: float = 4.0
    sigma_s: float = 0.02
    velocity_gain: float = 1.0
    scale_gain: float = 1.0
    s_min: float = 0.5
    s_max: float = 2.0
    use_means: bool = False

    def __post_init__(self) -> None:
        for name in ("sigma_xy", "sigma_s", "velocity_gain", "scale_gain", "s_min", "s_max"):
            v = number(getattr(self, name), f"Ar2Model: {name}", finite=False)
            if not np.isfinite(v) or v < 0:
                raise ValueError(f"Ar2Model: {name} is {v}, expected a finite value >= 0")
        if not 0 < self.s_min <= self.s_max:
            raise ValueError(f"Ar2Model: need 0 < s_min <= s_max, got {self.s_min}, {self.s_max}")

    @property
    def a(self) -> NDArray[np.float64]:
        """A, per state component (cx, cy, s)."""
        g, k = self.velocity_gain, self.scale_gain
        return np.array([1.0 + g, 1.0 + g, 1.0 + k])

    @property
    def b(self) -> NDArray[np.float64]:
        """B, per state component."""
        g, k = self.velocity_gain, self.scale_gain
        return np.array([-g, -g, -k])

    @property
    def sigma(self) -> NDArray[np.float64]:
        """C, the noise standard deviations of (cx, cy, s)."""
        return np.array([self.sigma_xy, self.sigma_xy, self.sigma_s])


def propagate(
    particles: NDArray[np.float64],
    noise: ArrayLike,
    model: Ar2Model = Ar2Model(),
    means: ArrayLike | None = None,
) -> None:
    """Advance particles one frame in place.

    Parameters
    ----------
    particles : (N, 6) ndarray of float64, C-contiguous
        Updated in place (it must be float64 and C-contiguous; it is never copied).
    noise : (N, 3) array_like of float
        Standard-normal draws, e.g. ``rng.standard_normal((N, 3))``.
    model : Ar2Model
        Dynamics.
    means : (2, 3) array_like, optional
        Particle-set means at t-1 and t-2, needed when ``model.use_means``.
    """
    if not isinstance(particles, np.ndarray) or particles.dtype != np.float64:
        raise TypeError("particles must be a float64 numpy array (updated in place)")
    if not particles.flags.c_contiguous:
        raise ValueError("particles must be C-contiguous (updated in place, never copied)")
    m = np.zeros((2, 3)) if means is None else np.asarray(means, dtype=np.float64)
    if m.shape != (2, 3):
        raise ValueError(f"means shape is {m.shape}, expected (2, 3)")
    if model.use_means and means is None:
        raise ValueError("means are required with use_means=True (eq. 8)")
    _core.propagate(
        particles,
        np.ascontiguousarray(noise, dtype=np.float64),
        model.a,
        model.b,
        model.sigma,
        model.s_min,
        model.s_max,
        model.use_means,
        m[0],
        m[1],
    )


def estimate(
    particles: ArrayLike, weights: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Weighted mean and maximum-weight (eq. 2) estimates of ``(cx, cy, s)``."""
    p = np.ascontiguousarray(particles, dtype=np.float64)
    mean, map_, _ = _core.estimate(p, np.asarray(weights, dtype=np.float64))
    return mean, map_
