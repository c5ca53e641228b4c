"""Dense references for pftrack.kalman: a matrix Kalman/RTS loop, and the posterior mean of the
joint Gaussian by conditioning."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pftrack.kalman import Cov, Mean, _cv_predict, _cv_update_where, rts_smooth


def dense_kalman_rts(
    z: np.ndarray,
    has: np.ndarray,
    F: np.ndarray,
    Q: np.ndarray,
    H: np.ndarray,
    R: np.ndarray,
    m0: np.ndarray,
    P0: np.ndarray,
    update_first: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Textbook matrix Kalman filter + RTS smoother (one loop over frames, full covariances).

    States s_0 ~ N(m0, P0), s_t = F s_{t-1} + N(0, Q); measurements z_t = H s_t + N(0, R) where
    `has` (frame 0 only with `update_first`). Returns the filtered means, smoothed means and
    smoothed covariances, (T, d), (T, d) and (T, d, d).
    """
    steps, d = len(z), len(m0)
    m, P = m0.astype(float).copy(), P0.astype(float).copy()
    fm, fP = np.zeros((steps, d)), np.zeros((steps, d, d))
    pm, pP = np.zeros((steps, d)), np.zeros((steps, d, d))
    for t in range(steps):
        if t > 0:
            m, P = F @ m, F @ P @ F.T + Q
        pm[t], pP[t] = m, P
        if has[t] and (t > 0 or update_first):
            S = H @ P @ H.T + R
            K = P @ H.T @ np.linalg.inv(S)
            m = m + K @ (z[t] - H @ m)
            P = (np.eye(d) - K @ H) @ P
        fm[t], fP[t] = m, P
    sm, sP = fm.copy(), fP.copy()
    for t in range(steps - 2, -1, -1):
        C = fP[t] @ F.T @ np.linalg.inv(pP[t + 1])
        sm[t] = fm[t] + C @ (sm[t + 1] - pm[t + 1])
        sP[t] = fP[t] + C @ (sP[t + 1] - pP[t + 1]) @ C.T
    return fm, sm, sP


def wna_posterior_mean(
    z: np.ndarray,
    has: np.ndarray,
    q: float,
    r2: float,
    velocity_sd: float,
    update_first: bool,
) -> np.ndarray:
    """Posterior mean of one constant-velocity axis's positions, from the joint Gaussian.

    States s_t = (p_t, v_t), s_0 ~ N([z_0, 0], diag(r2, velocity_sd²)), s_t = F s_{t-1} + w_t
    with w_t ~ N(0, q [[1/3, 1/2], [1/2, 1]]) (continuous white-noise acceleration of spectral
    density `q`); measurements z_t = p_t + N(0, r2) where `has` (frame 0 only when
    `update_first`: otherwise z_0 is the prior's mean alone). Builds the (2T, 2T) prior
    covariance of all states and conditions on the measurements.
    """
    steps = len(z)
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = q * np.array([[1.0 / 3.0, 0.5], [0.5, 1.0]])
    mean = np.zeros(2 * steps)
    m = np.array([z[0], 0.0])
    marg = [np.diag([r2, velocity_sd**2])]
    mean[:2] = m
    for t in range(1, steps):
        m = F @ m
        mean[2 * t : 2 * t + 2] = m
        marg.append(F @ marg[-1] @ F.T + Q)
    cov = np.zeros((2 * steps, 2 * steps))
    for t in range(steps):
        block = marg[t]
        cov[2 * t : 2 * t + 2, 2 * t : 2 * t + 2] = block
        for u in range(t + 1, steps):
            block = F @ block
            cov[2 * u : 2 * u + 2, 2 * t : 2 * t + 2] = block
            cov[2 * t : 2 * t + 2, 2 * u : 2 * u + 2] = block.T
    rows = [t for t in range(steps) if has[t] and (t > 0 or update_first)]
    if not rows:
        return mean[0::2]
    H = np.zeros((len(rows), 2 * steps))
    for k, t in enumerate(rows):
        H[k, 2 * t] = 1.0
    S = H @ cov @ H.T + r2 * np.eye(len(rows))
    post = mean + cov @ H.T @ np.linalg.solve(S, z[rows] - H @ mean)
    return post[0::2]


def rts_batch_numpy(
    pairs: Sequence[tuple[np.ndarray, np.ndarray]],
    q: float = 0.1,
    r: float = 1.0,
    history: int = 30,
) -> list[np.ndarray]:
    """NumPy reference of ``pftrack.recovery.baselines.rts_batch`` (``_core.rts_gaps_batch``).

    The windows of all gaps (up to `history` points each side and the gap) are stacked as
    columns of one array and smoothed together by ``pftrack.kalman.rts_smooth`` with a
    measurement mask per column: one vectorised step per frame of the longest window.
    """
    if not pairs:
        return []
    wins = [(a[-history:], b[:history]) for a, b in pairs]
    first = np.array([a[0, 0] for a, _ in wins])
    steps = np.array([b[-1, 0] for _, b in wins]) - first + 1
    T, n = int(steps.max()), 2 * len(wins)
    z = np.zeros((T, n))
    has = np.zeros((T, n), dtype=bool)
    for g, (a, b) in enumerate(wins):
        for seg in (a, b):
            rows = (seg[:, 0] - first[g]).astype(np.int64)
            z[rows, 2 * g : 2 * g + 2] = seg[:, 1:3]
            has[rows, 2 * g : 2 * g + 2] = True
    out = rts_smooth(z, has, np.full(n, q), np.full(n, r), velocity_sd=10.0, update_first=True)
    res = []
    for g, (a, b) in enumerate(wins):
        lo, hi = int(a[-1, 0] - first[g]) + 1, int(b[0, 0] - first[g])
        res.append(np.ascontiguousarray(out[lo:hi, 2 * g : 2 * g + 2]))
    return res


def rts_smooth_numpy(
    z: np.ndarray, has: np.ndarray, q: np.ndarray, r2: np.ndarray, velocity_sd: float,
    update_first: bool,
) -> np.ndarray:  # fmt: skip
    """pftrack.kalman.rts_smooth as NumPy arrays over axes, one Python step per frame.

    The statement the C++ ``_core.rts_smooth`` is held to (it was the library's code before):
    every axis at once through the arithmetic of :func:`pftrack.kalman.cv_predict` and
    :func:`~pftrack.kalman.cv_update_where` without their argument checks (``_cv_predict``,
    ``_cv_update_where``, the tracker's per-frame calls), then the RTS backward pass. The checks,
    added to the public calls after the loop moved to C++, took most of this loop's time: over
    the 500 tracks of bench/test_recovery.py 29.7 s with them, 4.1 s without (6 December, load
    3-4; 1.9 s for the loop it replaced on 24 November), so that its "rts smooth" ratio over
    NumPy was 3400x instead of 320x.
    """
    zz, hh = np.asarray(z, np.float64), np.asarray(has, bool)
    q2, rr = np.asarray(q, np.float64), np.asarray(r2, np.float64)
    steps, n = zz.shape
    m: Mean = (zz[0].copy(), np.zeros_like(q2))
    p: Cov = (rr.copy(), np.zeros_like(q2), np.full_like(q2, velocity_sd**2))
    fm, fp = np.empty((steps, 2, n)), np.empty((steps, 3, n))  # filtered mean, covariance
    pm, pp = np.empty((steps, 2, n)), np.empty((steps, 3, n))  # predicted mean, covariance
    for t in range(steps):
        if t > 0:
            m, p = _cv_predict(m, p, q2)
        pm[t], pp[t] = m, p
        if t > 0 or update_first:
            m, p = _cv_update_where(m, p, zz[t], rr, hh[t])
        fm[t], fp[t] = m, p
    out = np.empty((steps, n))
    s0, s1 = fm[-1, 0].copy(), fm[-1, 1].copy()
    out[-1] = s0
    for t in range(steps - 2, -1, -1):
        a, b, c = fp[t]
        # gain C = P_f F^T P_pred^-1 with F = [[1, 1], [0, 1]]
        u00, u01, u10, u11 = a + b, b, b + c, c
        x, y, w = pp[t + 1]
        det = x * w - y * y
        with np.errstate(divide="ignore", invalid="ignore"):
            c00, c01 = (u00 * w - u01 * y) / det, (u01 * x - u00 * y) / det
            c10, c11 = (u10 * w - u11 * y) / det, (u11 * x - u10 * y) / det
        # singular (no process noise, no initial velocity variance): the pseudo-inverse,
        # M / trace(M)^2 at rank <= 1
        single = ~(det > 0)
        if np.any(single):
            s = x + w
            k = np.where(s > 0, 1.0 / np.where(s > 0, s * s, 1.0), 0.0)
            ix, iy, iw = x * k, y * k, w * k
            c00 = np.where(single, u00 * ix + u01 * iy, c00)
            c01 = np.where(single, u00 * iy + u01 * iw, c01)
            c10 = np.where(single, u10 * ix + u11 * iy, c10)
            c11 = np.where(single, u10 * iy + u11 * iw, c11)
        d0, d1 = s0 - pm[t + 1, 0], s1 - pm[t + 1, 1]
        s0, s1 = fm[t, 0] + c00 * d0 + c01 * d1, fm[t, 1] + c10 * d0 + c11 * d1
        out[t] = s0
    return out
