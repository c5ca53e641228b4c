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
from pftrack._check import (
    byte_order_hint,
    first_at,
    flag,
    number,
    real_array,
    refuse_masked_weights,
    shown,
)

__all__ = ["Ar2Model", "estimate", "propagate"]

#: Largest ``Ar2Model.sigma_xy`` (pixels per frame): ten times the widest working frame
#: (``TrackerConfig.max_side`` is at most 100 000 px) and a thousandth of the ±1e9 px that
#: boxes may span (:data:`pftrack._check.MAX_COORD`).
MAX_SIGMA_XY = 1e6
#: Largest ``Ar2Model.s_max``: an object a thousand times its first size.
MAX_SCALE = 1e3


@dataclass(frozen=True)
class Ar2Model:
    """Parameters of the AR(2) model.

    Attributes
    ----------
    sigma_xy : float
        Standard deviation of the centre noise, pixels per frame; in [0, 1e6]
        (:data:`MAX_SIGMA_XY`).
    sigma_s : float
        Standard deviation of the scale noise per frame; finite and >= 0 (the scale is
        clamped to [`s_min`, `s_max`]).
    velocity_gain : float
        ``A = 1 + g``, ``B = -g`` for the centre: 1 is the paper's constant velocity, 0 a random
        walk, values in between damp the velocity. In [0, 1]: the AR(2) recursion's roots are 1
        and `g`, so a gain above 1 makes every particle's velocity grow as ``g**t`` (1e6 took
        a filter's estimate to 1e293 px in 50 frames).
    scale_gain : float
        The same for the scale (1: the paper's AR(2) on scale too; 0: a random walk), in [0, 1].
    s_min, s_max : float
        Bounds on the scale relative to the track's base size: ``0 < s_min <= s_max <= 1000``
        (:data:`MAX_SCALE`).
    use_means : bool
        eq. 8 (particle-set means) instead of eq. 7.

    Raises
    ------
    TypeError
        A number that is not a number (text, a bool), `use_means` not a bool.
    ValueError
        A value out of its range above (NaN and infinities included).

    Notes
    -----
    The bounds keep a filter's boxes in the domain its constructor accepts (each value within
    ±1e9 px, :data:`pftrack._check.MAX_COORD`): one step moves a particle by a few `sigma_xy`
    (at most ~8.6 standard deviations, the largest draw of the core's normals), under 1e7 px,
    and a box grows to at most 1000 times its first size. A lost object's particles still
    drift as a random walk, so the bound is not a guarantee over an unlimited number of
    frames; ``sigma_xy=1e12`` or ``s_max=1e300`` left the domain within a step.
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
        for name, span, hi in (
            ("sigma_xy", "[0", MAX_SIGMA_XY),
            ("s_max", "(0", MAX_SCALE),
            ("velocity_gain", "[0", 1.0),
            ("scale_gain", "[0", 1.0),
        ):
            v = getattr(self, name)
            if v > hi:
                raise ValueError(f"Ar2Model: {name} is {v}, expected a value in {span}, {hi:g}]")
        flag(self.use_means, "Ar2Model: use_means")

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

    Each row ``[x, x']``, ``x = (cx, cy, s)``, becomes ``[A x + B x' + C w, x]`` (eq. 7; with
    ``model.use_means``, eq. 8: the means ``m[0]``, ``m[1]`` stand for ``x``, ``x'`` in the
    sum), the new scale clamped to ``[s_min, s_max]``.

    Parameters
    ----------
    particles : (N, 6) ndarray of float64, C-contiguous and writeable
        One row per particle, ``cx, cy, s, cx', cy', s'``: the current state (box centre in
        pixels, scale relative to the track's base size ``(w0, h0)``, so the box is ``(cx, cy,
        s*w0, s*h0)``), then the previous frame's. Updated in place (it is never copied, so it
        must be such an array already): columns 0-2 get the new state, 3-5 the one it moved
        from.
    noise : (N, 3) array_like of float
        Standard-normal draws of ``(cx, cy, s)`` per particle, e.g.
        ``rng.standard_normal((N, 3))``; ``C = (sigma_xy, sigma_xy, sigma_s)`` scales them.
    model : Ar2Model
        Dynamics.
    means : (2, 3) array_like, optional
        Particle-set means ``(cx, cy, s)`` at t-1 (row 0) and t-2 (row 1), needed when
        ``model.use_means``.

    Raises
    ------
    TypeError
        `particles` not a float64 array, `noise` or `means` not real numbers, `model` not an
        :class:`Ar2Model`.
    ValueError
        `particles` not C-contiguous, read-only or not of shape (N, 6) with N >= 1; `noise`
        not (N, 3) or `means` not (2, 3); a value that is not finite; ``model.use_means``
        without `means`; a new state that is not finite (the step overflowed: states or
        noise near 1e308). `particles` is left as it was whenever an error is raised.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack.particle_filter import Ar2Model, propagate
    >>> particles = np.array([[12.0, 20.0, 1.0, 10.0, 20.0, 1.0]])  # moving 2 px a frame in x
    >>> propagate(particles, np.zeros((1, 3)))  # no noise: constant velocity
    >>> particles
    array([[14., 20.,  1., 12., 20.,  1.]])
    >>> propagate(particles, np.zeros((1, 3)), Ar2Model(velocity_gain=0.5))  # damped
    >>> particles
    array([[15., 20.,  1., 14., 20.,  1.]])
    >>> rng = np.random.default_rng(0)  # a filter's step: noise drawn in Python
    >>> propagate(particles, rng.standard_normal((len(particles), 3)))
    """
    fn = "propagate"
    error = _particles_error(particles, fn)
    if error is not None:
        raise error
    if not isinstance(model, Ar2Model):
        raise TypeError(f"{fn}: model must be an Ar2Model, got {shown(model)}")
    w = np.ascontiguousarray(real_array(noise, f"{fn}: noise", booleans=False))
    if w.shape != (len(particles), 3):
        raise ValueError(
            f"{fn}: noise shape is {w.shape}, expected ({len(particles)}, 3): one standard-normal "
            "draw of (cx, cy, s) per particle"
        )
    if model.use_means and means is None:
        raise ValueError(f"{fn}: means are required with use_means=True (eq. 8)")
    m = np.zeros((2, 3)) if means is None else real_array(means, f"{fn}: means", booleans=False)
    if m.shape != (2, 3):
        raise ValueError(f"{fn}: means shape is {m.shape}, expected (2, 3)")
    # the core writes the new state over the previous one (columns 3-5) after moving the
    # current one (columns 0-2) there: keeping the previous one is enough to undo a step
    previous = particles[:, 3:].copy()
    _core.propagate(
        particles, w, model.a, model.b, model.sigma, model.s_min, model.s_max,
        model.use_means, m[0], m[1],
    )  # fmt: skip
    bad = ~np.isfinite(particles[:, :3])
    if bad.any():
        (row, col), _ = first_at(bad)
        value = particles[row, col]
        particles[:, :3] = particles[:, 3:]
        particles[:, 3:] = previous
        raise ValueError(
            f"{fn}: particle {row}'s new {('cx', 'cy', 's')[col]} is {value}: the step "
            "overflowed (states, means or noise too large); particles are left as they were"
        )


def _particles_error(particles: object, fn: str) -> TypeError | ValueError | None:
    """Why the core cannot update `particles` in place, or None when it can.

    The core takes only a C-contiguous, writeable float64 array of shape (N, 6), N >= 1; any
    other (a read-only one too) got pybind11's list of signatures instead of a message.
    """
    what = "a C-contiguous, writeable float64 array (updated in place, never copied)"
    if not isinstance(particles, np.ndarray):
        return TypeError(f"{fn}: particles must be {what}, got {type(particles).__name__}")
    if particles.dtype != np.float64:
        return TypeError(
            f"{fn}: particles must be {what}, got dtype {particles.dtype}"
            + byte_order_hint(particles, "particles")
        )
    if not particles.flags.c_contiguous or not particles.flags.writeable:
        got = "a read-only one" if particles.flags.c_contiguous else "one not C-contiguous"
        return ValueError(f"{fn}: particles must be {what}, got {got}")
    if particles.ndim != 2 or particles.shape[1] != 6 or particles.shape[0] == 0:
        return ValueError(
            f"{fn}: particles shape is {particles.shape}, expected (N, 6) with N >= 1: one row "
            "(cx, cy, s, previous cx, cy, s) per particle"
        )
    return None


def estimate(
    particles: ArrayLike, weights: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Weighted mean and maximum-weight (eq. 2) estimates of ``(cx, cy, s)``.

    Parameters
    ----------
    particles : (N, 6) array_like of float
        One row ``(cx, cy, s, previous cx, cy, s)`` per particle, N >= 1.
    weights : (N,) array_like of float
        One weight per particle: finite, >= 0, not all 0 (need not be normalised).

    Returns
    -------
    mean, map : (3,) ndarray
        The weighted mean of ``(cx, cy, s)``, and the maximum-weight particle's.

    Raises
    ------
    TypeError
        `particles` or `weights` not real numbers (text, objects); `weights` a
        ``numpy.ma.MaskedArray`` with a masked value (pass ``weights.filled(0)``).
    ValueError
        `particles` not of shape (N, 6) with N >= 1, `weights` not (N,); a weight negative or
        not finite, or all 0.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack.particle_filter import estimate
    >>> particles = np.array([[10, 20, 1.0, 9, 20, 1.0], [14, 22, 1.2, 13, 22, 1.2]])
    >>> estimate(particles, [1, 3])  # weights need not sum to 1
    (array([13.  , 21.5 ,  1.15]), array([14. , 22. ,  1.2]))
    """
    fn = "estimate"
    p = np.ascontiguousarray(real_array(particles, f"{fn}: particles", booleans=False))
    if p.ndim != 2 or p.shape[1] != 6 or p.shape[0] == 0:
        raise ValueError(
            f"{fn}: particles shape is {p.shape}, expected (N, 6) with N >= 1: one row "
            "(cx, cy, s, previous cx, cy, s) per particle"
        )
    refuse_masked_weights(weights, fn)
    w = np.ascontiguousarray(real_array(weights, f"{fn}: weights"))
    if w.shape != (len(p),):
        raise ValueError(
            f"{fn}: weights shape is {w.shape}, expected ({len(p)},): one weight per particle"
        )
    mean, map_, _ = _core.estimate(p, w)
    return mean, map_
