"""Straightforward NumPy references for the ``gdt-mix`` kernels (tests only)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def step_models(F: F64, Q: F64, v2: float, T: int, t1: int, t2: int) -> tuple[list[F64], list[F64]]:
    """``F_k, Q_k`` of gap steps ``k = 1..T`` under the stand hypothesis ``(t1, t2)``."""
    d = F.shape[0]
    stand = np.zeros((d, d))
    stand[0, 0] = 1.0
    q_stand = np.zeros((d, d))
    q_stand[0, 0] = Q[0, 0]
    Fs, Qs = [], []
    for k in range(1, T + 1):
        if t1 >= 0 and t1 + 1 <= k <= t2 + 1:
            Qk = q_stand.copy()
            if k == t2 + 1:
                Qk[1, 1] = v2
            Fs.append(stand)
            Qs.append(Qk)
        else:
            Fs.append(F)
            Qs.append(Q)
    return Fs, Qs


def gap_mixture(
    z: F64, fa: int, fb: int, F: F64, Q: F64, r: float, p0: F64, t1s, t2s, v2: float
) -> tuple[F64, F64]:
    """One Kalman filter + RTS smoother per hypothesis, written out step by step."""
    n, d, T = len(z), F.shape[0], fb - fa
    paths, lls = [], []
    for t1, t2 in zip(t1s, t2s, strict=True):
        Fg, Qg = step_models(F, Q, v2, T, int(t1), int(t2))
        Ft = [F if (t <= fa or t > fb) else Fg[t - fa - 1] for t in range(n)]
        Qt = [Q if (t <= fa or t > fb) else Qg[t - fa - 1] for t in range(n)]
        m = np.zeros(d)
        m[0] = z[0]
        P = np.diag(p0).astype(float)
        mp, Pp, ms, Ps = [], [], [], []
        ll, seen = 0.0, 0
        for t in range(n):
            if t > 0:
                m = Ft[t] @ m
                P = Ft[t] @ P @ Ft[t].T + Qt[t]
            mp.append(m.copy())
            Pp.append(P.copy())
            if np.isfinite(z[t]):
                s = P[0, 0] + r
                v = z[t] - m[0]
                if seen >= d:
                    ll += -0.5 * (np.log(2 * np.pi * s) + v * v / s)
                seen += 1
                k = P[:, 0] / s
                m = m + k * v
                P = P - np.outer(k, P[0])
            ms.append(m.copy())
            Ps.append(P.copy())
        for t in range(n - 2, -1, -1):
            C = Ps[t] @ Ft[t + 1].T @ np.linalg.pinv(Pp[t + 1])
            ms[t] = ms[t] + C @ (ms[t + 1] - mp[t + 1])
        paths.append([ms[t][0] for t in range(fa + 1, fb)])
        lls.append(ll)
    return np.array(paths), np.array(lls)


def state_loglik(z_runs: list[F64], F: F64, Q: F64, r: float, big: float) -> float:
    """Kalman prediction-error log-likelihood, first ``d`` innovations of each run skipped."""
    d = F.shape[0]
    total = 0.0
    for z in z_runs:
        if len(z) < d + 2:
            continue
        m = np.zeros(d)
        m[0] = z[0]
        P = np.eye(d) * big
        for i, zi in enumerate(z):
            if i > 0:
                m = F @ m
                P = F @ P @ F.T + Q
            s = P[0, 0] + r
            v = zi - m[0]
            if i >= d:
                total += -0.5 * (np.log(2 * np.pi * s) + v * v / s)
            k = P[:, 0] / s
            m = m + k * v
            P = P - np.outer(k, P[0])
    return total


def singer_quadrature(q: float, tau: float, nodes: int = 4001) -> tuple[F64, F64]:
    """Singer ``F`` in closed form and ``Q = int_0^1 Phi(s) G q G^T Phi(s)^T ds`` by Simpson."""
    a = 1.0 / tau

    def phi(s: float) -> F64:
        e = np.exp(-a * s)
        return np.array([[1.0, s, (a * s - 1.0 + e) / a**2], [0.0, 1.0, (1.0 - e) / a], [0, 0, e]])

    s = np.linspace(0.0, 1.0, nodes)
    g = np.array([0.0, 0.0, 1.0])
    vals = np.array([np.outer(phi(x) @ g, phi(x) @ g) * q for x in s])
    w = np.ones(nodes)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    Q = np.tensordot(w, vals, axes=1) * (s[1] - s[0]) / 3.0
    return phi(1.0), Q


def gap_mixture_vectorised(
    z: F64, fa: int, fb: int, F: F64, Q: F64, r: float, p0: F64, t1s, t2s, v2: float
) -> tuple[F64, F64]:
    """The same, vectorised over hypotheses with NumPy (the fair NumPy peer of the C++ kernel
    in bench/test_bridge.py)."""
    n, d, T, nh = len(z), F.shape[0], fb - fa, len(t1s)
    Fs = np.broadcast_to(F, (nh, n, d, d)).copy()
    Qs = np.broadcast_to(Q, (nh, n, d, d)).copy()
    for h, (t1, t2) in enumerate(zip(t1s, t2s, strict=True)):
        if t1 < 0:
            continue
        Fg, Qg = step_models(F, Q, v2, T, int(t1), int(t2))
        Fs[h, fa + 1 : fb + 1] = Fg
        Qs[h, fa + 1 : fb + 1] = Qg
    m = np.zeros((nh, d))
    m[:, 0] = z[0]
    P = np.broadcast_to(np.diag(p0).astype(float), (nh, d, d)).copy()
    ms, Ps = np.zeros((nh, n, d)), np.zeros((nh, n, d, d))
    mp, Pp = np.zeros((nh, n, d)), np.zeros((nh, n, d, d))
    ll = np.zeros(nh)
    seen = 0
    for t in range(n):
        if t > 0:
            m = np.einsum("hij,hj->hi", Fs[:, t], m)
            P = Fs[:, t] @ P @ Fs[:, t].transpose(0, 2, 1) + Qs[:, t]
        mp[:, t], Pp[:, t] = m, P
        if np.isfinite(z[t]):
            S = P[:, 0, 0] + r
            v = z[t] - m[:, 0]
            if seen >= d:
                ll -= 0.5 * (np.log(2 * np.pi * S) + v * v / S)
            seen += 1
            K = P[:, :, 0] / S[:, None]
            m = m + K * v[:, None]
            P = P - K[:, :, None] * P[:, 0, None, :]
        ms[:, t], Ps[:, t] = m, P
    for t in range(n - 2, fa, -1):
        C = Ps[:, t] @ Fs[:, t + 1].transpose(0, 2, 1) @ np.linalg.pinv(Pp[:, t + 1])
        ms[:, t] = ms[:, t] + np.einsum("hij,hj->hi", C, ms[:, t + 1] - mp[:, t + 1])
    return ms[:, fa + 1 : fb, 0], ll
