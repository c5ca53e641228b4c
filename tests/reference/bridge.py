"""Straightforward NumPy references for the goal-directed state equation (Oh & Jung 2015).

Literal transcriptions: Phi(T, i) is recomputed as an explicit product for every i (O(T^2)),
matrices are inverted with numpy.linalg.inv. Slow and obvious on purpose.
"""

from __future__ import annotations

import numpy as np


def _stack(a, T):
    a = np.asarray(a, dtype=float)
    return [a] * T if a.ndim == 2 else [a[t] for t in range(T)]


def phi(A, t, s):
    """Phi(t, s) for t >= s: A_t A_{t-1} ... A_{s+1} (A[k-1] = A_k)."""
    n = A[0].shape[0]
    out = np.eye(n)
    for k in range(s + 1, t + 1):
        out = A[k - 1] @ out
    return out


def S_sum(A, Q, T, t):
    """sum_{i=t..T} Phi(T,i) Q_i Phi(T,i)^T."""
    n = A[0].shape[0]
    s = np.zeros((n, n))
    for i in range(t, T + 1):
        P = phi(A, T, i)
        s += P @ Q[i - 1] @ P.T
    return s


def gdt_general(A, Q, H, Pi_T, m0, Pi_0, y, T, start_conditioned=True):
    """Eqs. 7-10 literally; returns path (T+1, n), eps (T, n, n), x0_mean, x0_cov."""
    A = _stack(A, T)
    Q = _stack(Q, T)
    H = np.asarray(H, float)
    M1 = Pi_T + H @ S_sum(A, Q, T, 1) @ H.T
    F = H @ phi(A, T, 0)
    x0_cov = np.linalg.inv(np.linalg.inv(Pi_0) + F.T @ np.linalg.inv(M1) @ F)
    x0_mean = m0 + x0_cov @ F.T @ np.linalg.inv(M1) @ (y - F @ m0)
    x = x0_mean if start_conditioned else np.asarray(m0, float)
    path = [x]
    eps = []
    for t in range(1, T + 1):
        M = Pi_T + H @ S_sum(A, Q, T, t) @ H.T
        Minv = np.linalg.inv(M)
        Pt = phi(A, T, t)
        u = Q[t - 1] @ Pt.T @ H.T @ Minv @ (y - H @ phi(A, T, t - 1) @ x)
        eps.append(Q[t - 1] - Q[t - 1] @ Pt.T @ H.T @ Minv @ H @ Pt @ Q[t - 1].T)
        x = A[t - 1] @ x + u
        path.append(x)
    return np.array(path), np.array(eps), x0_mean, x0_cov


def joint_conditional(A, Q, H, Pi_T, m0, Pi_0, y, T):
    """E[x_t | y_T] and cov(x_t | y_T) for t = 0..T from the joint Gaussian of (x_0..x_T, y_T)
    (independent check of the whole construction)."""
    A = _stack(A, T)
    Q = _stack(Q, T)
    n = len(m0)
    # x_t = Phi(t,0) x_0 + sum_{i<=t} Phi(t,i) w_i: build the linear map from (x0, w1..wT)
    dim = n * (T + 1)
    L = np.zeros((dim, dim))
    for t in range(T + 1):
        L[t * n : (t + 1) * n, 0:n] = phi(A, t, 0)
        for i in range(1, t + 1):
            L[t * n : (t + 1) * n, i * n : (i + 1) * n] = phi(A, t, i)
    C0 = np.zeros((dim, dim))
    C0[0:n, 0:n] = Pi_0
    for i in range(1, T + 1):
        C0[i * n : (i + 1) * n, i * n : (i + 1) * n] = Q[i - 1]
    mu = L @ np.concatenate([m0, np.zeros(n * T)])
    C = L @ C0 @ L.T
    Hy = np.zeros((H.shape[0], dim))
    Hy[:, T * n :] = H
    Syy = Hy @ C @ Hy.T + Pi_T
    K = C @ Hy.T @ np.linalg.inv(Syy)
    mean = mu + K @ (y - Hy @ mu)
    cov = C - K @ Hy @ C
    means = mean.reshape(T + 1, n)
    covs = np.array([cov[t * n : (t + 1) * n, t * n : (t + 1) * n] for t in range(T + 1)])
    return means, covs


def kalman_filter(z, A, Q, H, R, m, P):
    """Textbook Kalman filter (predict, then update), filtered state after the last point."""
    m = np.asarray(m, float)
    P = np.asarray(P, float)
    for k, zk in enumerate(z):
        if k > 0:
            m = A @ m
            P = A @ P @ A.T + Q
        S = H @ P @ H.T + R
        K = P @ H.T @ np.linalg.inv(S)
        m = m + K @ (zk - H @ m)
        P = (np.eye(len(m)) - K @ H) @ P
    return m, P


def gdt_numpy_fast(A, Q, H, Pi_T, m0, Pi_0, y, T):
    """A vectorised-as-far-as-reasonable NumPy implementation with the O(T) backward recursion
    (the peer of the C++ kernel in the benchmarks)."""
    n = len(m0)
    S = np.zeros((n, n))
    Phi = np.eye(n)
    K = np.empty((T, n, H.shape[0]))
    G = np.empty((T, H.shape[0], n))
    for t in range(T, 0, -1):
        S = S + Phi @ Q @ Phi.T
        Minv = np.linalg.inv(Pi_T + H @ S @ H.T)
        K[t - 1] = Q @ (H @ Phi).T @ Minv
        Phi = Phi @ A
        G[t - 1] = H @ Phi
    F = H @ Phi
    cov0 = np.linalg.inv(np.linalg.inv(Pi_0) + F.T @ Minv @ F)
    x = m0 + cov0 @ F.T @ Minv @ (y - F @ m0)
    path = np.empty((T + 1, n))
    path[0] = x
    for t in range(1, T + 1):
        x = A @ x + K[t - 1] @ (y - G[t - 1] @ x)
        path[t] = x
    return path


def loglik_grid(runs, axis, q, r):
    """NumPy reference of _core.noise_loglik_grid: CV model, white-noise acceleration."""
    ll = np.zeros(len(q))
    for run in runs:
        z = run[:, 1 + axis]
        if len(z) < 4:
            continue
        # condition on the first two points: x = z_1, v = z_1 - z_0
        m0 = np.full(len(q), z[1])
        m1 = np.full(len(q), z[1] - z[0])
        p00 = r.copy()
        p01 = r.copy()
        p11 = 2.0 * r + q / 3.0
        for zk in z[2:]:
            # predict with x' = x + v, v' = v, Q = q [[1/3, 1/2], [1/2, 1]]
            m0 = m0 + m1
            a00 = p00 + 2.0 * p01 + p11 + q / 3.0
            a01 = p01 + p11 + q / 2.0
            a11 = p11 + q
            s = a00 + r
            v = zk - m0
            ll -= 0.5 * (np.log(s) + v * v / s)
            k0 = a00 / s
            k1 = a01 / s
            m0 = m0 + k0 * v
            m1 = m1 + k1 * v
            p00 = (1.0 - k0) * a00
            p01 = (1.0 - k0) * a01
            p11 = a11 - k1 * a01
    return ll


def two_sided_posterior(za, zb, T, A, Q, H, R, prior_a, prior_b):
    """E[x_t | every point] of the whole window: segment A (consecutive frames), the gap of
    T - 1 frames, segment B (consecutive frames), with a Gaussian factor on each far end.

    Written from the model, not from the goal-directed algebra: one linear-Gaussian chain
    ``x_k = A x_{k-1} + w_k`` over every frame from A's first point to B's last, measurements
    ``z = H x + v`` on the observed frames, ``N(x_first; *prior_a)`` on A's first state and
    ``N(x_last; *prior_b)`` on B's last (:func:`chain_posterior`). Returns the means,
    ``(len(za) + T - 1 + len(zb), n)``.
    """
    N = len(za) + T - 1 + len(zb)
    observed = [(k, z) for k, z in enumerate(za)]
    observed += [(len(za) + T - 1 + k, z) for k, z in enumerate(zb)]
    return chain_posterior(N, observed, A, Q, H, R, [(0, *prior_a), (N - 1, *prior_b)])


def chain_posterior(N, observed, A, Q, H, R, priors):
    """Posterior means ``(N, n)`` of the chain ``x_k = A x_{k-1} + N(0, Q)``, k = 1..N-1.

    `Q` is one matrix or ``N - 1`` of them (``Q[k-1]`` for the step to ``x_k``). `observed`
    holds ``(k, z)``: ``z = H x_k + N(0, R)``; `priors` holds ``(k, m, P)``: a factor
    ``N(x_k; m, P)``. The joint density's precision matrix is assembled factor by
    factor and solved densely (no filter, no recursion).
    """
    n = A.shape[0]
    Lam = np.zeros((n * N, n * N))
    eta = np.zeros(n * N)

    def blk(i):
        return slice(i * n, (i + 1) * n)

    Qs = _stack(Q, N - 1)
    Ri = np.linalg.inv(R)
    for k in range(1, N):
        Qi = np.linalg.inv(Qs[k - 1])
        Lam[blk(k), blk(k)] += Qi
        Lam[blk(k - 1), blk(k - 1)] += A.T @ Qi @ A
        Lam[blk(k), blk(k - 1)] -= Qi @ A
        Lam[blk(k - 1), blk(k)] -= A.T @ Qi
    for k, z in observed:
        Lam[blk(k), blk(k)] += H.T @ Ri @ H
        eta[blk(k)] += H.T @ Ri @ z
    for k, m, P in priors:
        Pi = np.linalg.inv(P)
        Lam[blk(k), blk(k)] += Pi
        eta[blk(k)] += Pi @ m
    return np.linalg.solve(Lam, eta).reshape(N, n)
