"""The online motion model of a track: a constant-velocity Kalman filter of its centre."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pftrack._typing import F64
from pftrack.kalman import Cov, _cv_predict, _cv_update  # unchecked: every frame, every track

__all__ = ["CentreKalman"]


class CentreKalman:
    """Constant-velocity Kalman filter of a track's centre, both axes sharing one covariance.

    Noise levels are in units of the track's height ``h`` so that one rule fits any image scale:
    white-noise acceleration of spectral density ``(accel·h)²`` (px²/frame³), and a measurement
    standard deviation given at each update (a detection's or the colour filter's, in pixels).
    The equations are :func:`pftrack.kalman.cv_predict` and :func:`~pftrack.kalman.cv_update`,
    run on both axes at once.

    Parameters
    ----------
    centre : (2,) array_like
        Initial centre (the first detection's); the velocity starts at 0.
    height : float
        The track's height, pixels.
    accel : float
        Square root of the acceleration's spectral density, in heights (per frame^1.5).

    Attributes
    ----------
    p, v : (2,) ndarray
        Centre and velocity (pixels, pixels per frame).
    """

    def __init__(self, centre: ArrayLike, height: float, accel: float) -> None:
        self.p: F64 = np.array(centre, dtype=np.float64)
        self.v: F64 = np.zeros(2)
        self.accel = accel
        # unknown initial velocity: about a third of a height per frame (a fast walker at 5 fps)
        self.cov: Cov = ((0.05 * height) ** 2, 0.0, (0.3 * height) ** 2)  # p00, p01, p11

    @property
    def P(self) -> F64:  # noqa: N802 - the usual name
        """The (position, velocity) covariance of one axis, 2x2."""
        p00, p01, p11 = self.cov
        return np.array([[p00, p01], [p01, p11]], dtype=np.float64)

    def predict(self, height: float, gain: float = 1.0) -> None:
        """Advance one frame, with the acceleration scaled by the track's current `height`.

        `gain` multiplies `accel` (faster footage, :meth:`MultiObjectTracker.motion_gain`).
        """
        q = (self.accel * gain * height) ** 2
        (p, v), self.cov = _cv_predict((self.p, self.v), self.cov, q)
        self.p, self.v = np.asarray(p), np.asarray(v)

    def update(self, z: ArrayLike, sigma: float) -> None:
        """Correct with a measured centre `z` of standard deviation `sigma` (pixels)."""
        (p, v), self.cov = _cv_update(
            (self.p, self.v), self.cov, np.asarray(z, dtype=np.float64), sigma**2
        )
        self.p, self.v = np.asarray(p), np.asarray(v)
