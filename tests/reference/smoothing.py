"""Dense reference for the box smoother: the posterior mean of a Gaussian, by conditioning."""

from __future__ import annotations

import numpy as np


def cv_posterior_mean(z: np.ndarray, has: np.ndarray, q: float, r: float, velocity_sd: float) -> np.ndarray:
    """Posterior mean of the positions of one constant-velocity axis, from the joint Gaussian.

    States s_t = (p_t, v_t), s_0 ~ N([z_0, 0], diag(r², velocity_sd²)), s_t = F s_{t-1} + w_t with
    w_t ~ N(0, q² [[1/4, 1/2], [1/2, 1]]); measurements z_t = p_t + N(0, r²) at every t >= 1 with
    `has`. Builds the (2T, 2T) prior covariance of all states and conditions on the measurements.
    """
    steps = len(z)
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = q * q * np.array([[0.25, 0.5], [0.5, 1.0]])
    mean = np.zeros(2 * steps)
    cov = np.zeros((2 * steps, 2 * steps))
    m = np.array([z[0], 0.0])
    marg = [np.diag([r * r, velocity_sd**2])]
    mean[:2] = m
    for t in range(1, steps):
        m = F @ m
        mean[2 * t : 2 * t + 2] = m
        marg.append(F @ marg[-1] @ F.T + Q)
    for t in range(steps):
        cov[2 * t : 2 * t + 2, 2 * t : 2 * t + 2] = marg[t]
        block = marg[t]
        for u in range(t + 1, steps):  # cov(s_u, s_t) = F^(u-t) Σ_t
            block = F @ block
            cov[2 * u : 2 * u + 2, 2 * t : 2 * t + 2] = block
            cov[2 * t : 2 * t + 2, 2 * u : 2 * u + 2] = block.T
    rows = [t for t in range(1, steps) if has[t]]
    if not rows:
        return mean[0::2]
    H = np.zeros((len(rows), 2 * steps))
    for k, t in enumerate(rows):
        H[k, 2 * t] = 1.0
    S = H @ cov @ H.T + r * r * np.eye(len(rows))
    post = mean + cov @ H.T @ np.linalg.solve(S, z[rows] - H @ mean)
    return post[0::2]
