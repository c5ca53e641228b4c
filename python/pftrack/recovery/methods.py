"""Recovering the path of one object across a gap between two observed segments.

A *segment* is an ``(k, 3)`` or ``(k, 5)`` array of rows ``(frame, x, y[, w, h])`` with
increasing frames; the gap is every frame strictly between the last frame of segment A and the
first frame of segment B. Time is measured in frames (``dt = 1``).

Methods
-------
``"gdt"``
    Goal-directed tracking exactly as in Oh & Jung (2015): Kalman filter over segment A with the
    paper's A, Q, H, R (:class:`~pftrack.recovery.gdt.GdtModel`), goal = first point of B with
    ``H_T = [I 0]`` and ``Pi_T = R``, ``T`` = frame difference; the path starts at the filter's
    state (the paper's framework).
``"gdt-bi"`` (pftrack's variant)
    Goal-directed tracking whose goal is the full state (position *and* velocity) estimated by a
    Kalman filter run backwards over segment B, with that filter's covariance as ``Pi_T``
    (``H_T = I``), and whose noise levels (white-noise-acceleration ``q`` and measurement
    ``r``, per axis) are estimated from the observed segments by the method of moments on
    second differences (:func:`estimate_noise`). The path starts at ``E[x_0 | y_T]``.
``"gdt-mix"`` (pftrack's default)
    ``gdt-bi`` mixed over "walks through" and "stands still for a while" hypotheses, each
    weighted by its evidence, with the Singer motion model (correlated acceleration) where the
    observed points support it; every parameter estimated from the observed points
    (:mod:`pftrack.recovery.mixture`).
``"linear"``
    Straight line between the two ends (ByteTrack's post-processing).
``"cubic"``
    Interpolating cubic spline (not-a-knot) through the points of both segments near the gap.
``"bspline"``
    Weighted least-squares cubic B-spline (Sun et al. 2005) over the points near the gap.
``"gsi"``
    Gaussian-smoothed interpolation (StrongSORT): linear fill, then Gaussian-process regression
    with an RBF kernel of length ``clip(tau log(tau^3 / n), 1/tau, tau^2)``, ``tau = 10``.
``"rts"``
    Constant-velocity Kalman filter + Rauch-Tung-Striebel smoother over both segments and the
    gap, with fixed noise (``q = 0.1 px^2/frame^3``, ``r = 1 px^2``).

Box sizes (``w, h``), when given, are interpolated linearly by every method.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

import pftrack._core as _core
from pftrack.recovery.gdt import GdtModel, constant_velocity_A

if TYPE_CHECKING:
    from pftrack.recovery.mixture import MotionFit

METHODS = ("gdt", "gdt-bi", "gdt-mix", "linear", "cubic", "bspline", "gsi", "rts")
PFTRACK_METHODS = ("gdt", "gdt-bi", "gdt-mix")
F64 = NDArray[np.float64]

_PAPER = GdtModel()
_J = np.diag([1.0, 1.0, -1.0, -1.0])  # reverses time: velocity changes sign


def as_segment(seg: ArrayLike, name: str) -> F64:
    """Check and convert one segment to a C-contiguous ``(k, 3|5)`` float64 array."""
    a = np.asarray(seg, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] not in (3, 5):
        raise ValueError(f"recover_gap: {name} must have shape (k, 3) or (k, 5), got {a.shape}")
    if a.shape[0] == 0:
        raise ValueError(f"recover_gap: {name} is empty")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"recover_gap: {name} has a non-finite value")
    if np.any(np.diff(a[:, 0]) <= 0):
        raise ValueError(f"recover_gap: {name} frames must increase strictly")
    return np.ascontiguousarray(a)


@dataclass(frozen=True)
class NoiseEstimate:
    """Noise levels per axis (x, y).

    ``q``: white-noise-acceleration intensity (px²/frame³); ``r``: measurement variance (px²).
    """

    q: tuple[float, float]
    r: tuple[float, float]


#: Used when the segments are too short to estimate anything.
DEFAULT_NOISE = NoiseEstimate(q=(0.1, 0.1), r=(1.0, 1.0))


def _moments_noise(segments: Sequence[F64], floor_q: float, floor_r: float) -> NoiseEstimate:
    # Second differences d_t = z_{t+1} - 2 z_t + z_{t-1} of a continuous white-noise-
    # acceleration path measured with variance r: var d = 2q/3 + 6r, cov(d_t, d_{t+1}) = q/6 - 4r.
    c0 = np.zeros(2)
    c1 = np.zeros(2)
    n0 = n1 = 0
    for run in segments:
        if len(run) < 4:
            continue
        d = run[2:, 1:3] - 2.0 * run[1:-1, 1:3] + run[:-2, 1:3]
        c0 += np.sum(d * d, axis=0)
        c1 += np.sum(d[1:] * d[:-1], axis=0)
        n0 += len(d)
        n1 += len(d) - 1
    if n1 < 4:
        return DEFAULT_NOISE
    c0 /= n0
    c1 /= n1
    r = np.maximum((c0 - 4.0 * c1) / 22.0, floor_r)
    q = np.maximum(1.5 * (c0 - 6.0 * r), floor_q)
    return NoiseEstimate(q=(float(q[0]), float(q[1])), r=(float(r[0]), float(r[1])))


def _loglik_grid(runs: Sequence[F64], axis: int, q: F64, r: F64) -> F64:
    """Kalman log-likelihood of one axis of every run, for each (q, r) pair (C++)."""
    z = np.ascontiguousarray(np.concatenate([run[:, 1 + axis] for run in runs]))
    lengths = np.array([len(run) for run in runs], dtype=np.int32)
    out: F64 = _core.noise_loglik_grid(z, lengths, np.ascontiguousarray(q), np.ascontiguousarray(r))
    return out


def _ml_noise(segments: Sequence[F64], floor_q: float, floor_r: float) -> NoiseEstimate:
    qs, rs = [], []
    for axis in range(2):
        lq_lo, lq_hi, lr_lo, lr_hi = np.log10(floor_q), 2.0, np.log10(floor_r), 2.0
        best = (0.0, 0.0)
        for _ in range(3):  # coarse-to-fine grid on log10 q, log10 r
            lq, lr = np.meshgrid(np.linspace(lq_lo, lq_hi, 9), np.linspace(lr_lo, lr_hi, 9))
            q, r = 10.0 ** lq.ravel(), 10.0 ** lr.ravel()
            i = int(np.argmax(_loglik_grid(segments, axis, q, r)))
            best = (float(q[i]), float(r[i]))
            dq, dr = (lq_hi - lq_lo) / 8.0, (lr_hi - lr_lo) / 8.0
            lq_lo, lq_hi = max(np.log10(q[i]) - dq, np.log10(floor_q)), np.log10(q[i]) + dq
            lr_lo, lr_hi = max(np.log10(r[i]) - dr, np.log10(floor_r)), np.log10(r[i]) + dr
        qs.append(best[0])
        rs.append(best[1])
    return NoiseEstimate(q=(qs[0], qs[1]), r=(rs[0], rs[1]))


def consecutive_runs(segments: Sequence[ArrayLike], min_points: int) -> list[F64]:
    """Split segments (rows ``(frame, x, y, ...)``) into runs of consecutive frames.

    Runs shorter than `min_points` and malformed or empty segments are skipped.
    """
    runs: list[F64] = []
    for s in segments:
        a = np.asarray(s, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] < 3 or len(a) == 0:
            continue
        for run in np.split(a, np.flatnonzero(np.diff(a[:, 0]) != 1) + 1):
            if len(run) >= min_points:
                runs.append(run)
    return runs


def estimate_noise(
    segments: Sequence[ArrayLike],
    *,
    method: str = "ml",
    floor_q: float = 1e-5,
    floor_r: float = 1e-3,
    min_points: int = 4,
    scales: Sequence[int] = (1, 2, 4, 8),
) -> NoiseEstimate:
    """Estimate the motion noise ``q`` and measurement noise ``r`` per axis from observed data.

    The model is a constant-velocity path driven by continuous white-noise acceleration of
    intensity ``q`` (px²/frame³), observed every frame with variance ``r`` (px²). Segments are
    split into runs of consecutive frames; runs shorter than `min_points` are ignored.

    Parameters
    ----------
    segments : sequence of (k, 3+) array_like
        Observed rows ``(frame, x, y, ...)``.
    method : {"ml", "moments"}
        ``"ml"``: maximum likelihood (Kalman-filter prediction-error likelihood, pooled over all
        runs, maximised on a coarse-to-fine log grid); ``"moments"``: method of moments on
        second differences (``r = (c0 - 4 c1) / 22``, ``q = 3 (c0 - 6 r) / 2``).
    floor_q, floor_r : float
        Lower bounds of the estimates.
    min_points : int
        Shortest run used.
    scales : sequence of int
        ``"ml"`` only: the model is fitted to the runs sampled every ``s`` frames for each
        ``s``; per axis, going from fine to coarse, a scale replaces the current estimate when
        its ``q`` (in per-frame units, ``q_s / s^3``) is less than half the current one, and
        its ``r`` comes with it. White acceleration gives the same ``q`` at every scale (within
        sampling error, hence the factor 2); jitter correlated over a few frames (gait sway,
        box annotation noise) inflates ``q`` at the finest scales and would make long
        predictions too wiggly.

    Returns
    -------
    NoiseEstimate
        :data:`DEFAULT_NOISE` when no run is long enough.
    """
    if method not in ("ml", "moments"):
        raise ValueError(f"estimate_noise: method is {method!r}, expected 'ml' or 'moments'")
    runs = consecutive_runs(segments, max(min_points, 4))
    if sum(len(r) - 3 for r in runs) < 4:
        return DEFAULT_NOISE
    if not scales or any(int(v) < 1 for v in scales):
        raise ValueError(f"estimate_noise: scales is {scales!r}, expected integers >= 1")
    if method == "moments":
        return _moments_noise(runs, floor_q, floor_r)
    best: list[tuple[float, float]] = []
    for s in (int(v) for v in scales):
        sub: list[F64] = []
        for run in runs:
            for j in range(s):
                part = run[j::s]
                if len(part) >= 4:
                    sub.append(part)
        if sum(len(r) - 3 for r in sub) < 4:
            continue
        est = _ml_noise(sub, floor_q * s**3, floor_r)
        for axis in range(2):
            q = est.q[axis] / s**3  # per s frames -> per frame
            if len(best) <= axis:
                best.append((q, est.r[axis]))
            elif q < 0.5 * best[axis][0]:  # clearly smaller at this scale: correlated jitter
                best[axis] = (q, est.r[axis])
    if len(best) < 2:
        return DEFAULT_NOISE
    return NoiseEstimate(q=(best[0][0], best[1][0]), r=(best[0][1], best[1][1]))


def wna_Q(q: Sequence[float], dt: float = 1.0) -> F64:  # noqa: N802
    """Discretised continuous white-noise-acceleration covariance for ``(x, y, vx, vy)``."""
    Q = np.zeros((4, 4))
    for axis in range(2):
        i, j = axis, axis + 2
        Q[i, i] = q[axis] * dt**3 / 3.0
        Q[i, j] = Q[j, i] = q[axis] * dt**2 / 2.0
        Q[j, j] = q[axis] * dt
    return Q


def _kf_init(seg: F64, r: Sequence[float], p_vel: float) -> tuple[F64, F64]:
    m = np.array([seg[0, 1], seg[0, 2], 0.0, 0.0])
    if len(seg) > 1:
        m[2:] = seg[1, 1:3] - seg[0, 1:3]
    P = np.diag([r[0], r[1], p_vel, p_vel])
    return m, P


def _contiguous_tail(seg: F64) -> F64:
    """Return the last run of consecutive frames (the Kalman filter steps one frame at a time)."""
    br = np.flatnonzero(np.diff(seg[:, 0]) != 1)
    return seg[br[-1] + 1 :] if len(br) else seg


def _contiguous_head(seg: F64) -> F64:
    br = np.flatnonzero(np.diff(seg[:, 0]) != 1)
    return seg[: br[0] + 1] if len(br) else seg


def gdt_problem(
    seg_a: F64, seg_b: F64, model: GdtModel = _PAPER, history: int = 30
) -> tuple[Any, ...]:
    """Build the paper's problem tuple ``(A, Q, H, Pi_T, m0, Pi_0, y, T)`` for one gap.

    The Kalman filter runs over the last `history` points of segment A's final run of
    consecutive frames (the paper's noise levels give a filter whose memory is a few frames,
    so a longer history changes nothing measurable).
    """
    tail = _contiguous_tail(seg_a)[-history:]
    A, Q, H, R = model.A, model.Q, model.H, model.R
    m_init, P_init = _kf_init(tail, model.r, model.p_init_velocity)
    m0, P0 = _core.kalman_filter(np.ascontiguousarray(tail[:, 1:3]), A, Q, H, R, m_init, P_init)
    T = int(seg_b[0, 0] - seg_a[-1, 0])
    return (A, Q, H, R, m0, P0, np.ascontiguousarray(seg_b[0, 1:3]), T)


def gdt_bi_problem(
    seg_a: F64, seg_b: F64, noise: NoiseEstimate | None = None, history: int = 30
) -> tuple[Any, ...]:
    """Pftrack's two-sided problem: forward filter on A, backward filter on B, noise estimated."""
    if noise is None:
        noise = estimate_noise([seg_a, seg_b])
    A = constant_velocity_A(1.0)
    Q = wna_Q(noise.q)
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = np.diag(noise.r)
    p_vel = 1e2
    tail = _contiguous_tail(seg_a)[-history:]
    m_init, P_init = _kf_init(tail, noise.r, p_vel)
    m0, P0 = _core.kalman_filter(np.ascontiguousarray(tail[:, 1:3]), A, Q, H, R, m_init, P_init)
    head = _contiguous_head(seg_b)[:history][::-1]
    mb_init, Pb_init = _kf_init(head, noise.r, p_vel)
    mb, Pb = _core.kalman_filter(np.ascontiguousarray(head[:, 1:3]), A, Q, H, R, mb_init, Pb_init)
    y = _J @ mb
    Pi_T = _J @ Pb @ _J
    T = int(seg_b[0, 0] - seg_a[-1, 0])
    return (A, Q, np.eye(4), 0.5 * (Pi_T + Pi_T.T), m0, P0, y, T)


def _fill_sizes(seg_a: F64, seg_b: F64, frames: NDArray[np.int64]) -> F64 | None:
    if seg_a.shape[1] < 5 or seg_b.shape[1] < 5:
        return None
    f0, f1 = seg_a[-1, 0], seg_b[0, 0]
    s = (frames - f0) / (f1 - f0)
    out: F64 = (1.0 - s)[:, None] * seg_a[-1, 3:5] + s[:, None] * seg_b[0, 3:5]
    return out


def _window(seg_a: F64, seg_b: F64, k: int) -> tuple[F64, F64]:
    pts = np.vstack([seg_a[-k:, :3], seg_b[:k, :3]])
    return pts[:, 0], pts[:, 1:3]


def _linear(seg_a: F64, seg_b: F64, frames: NDArray[np.int64]) -> F64:
    f0, f1 = seg_a[-1, 0], seg_b[0, 0]
    s = (frames - f0) / (f1 - f0)
    out: F64 = (1.0 - s)[:, None] * seg_a[-1, 1:3] + s[:, None] * seg_b[0, 1:3]
    return out


def _cubic(seg_a: F64, seg_b: F64, frames: NDArray[np.int64], window: int = 30) -> F64:
    from scipy.interpolate import CubicSpline

    t, xy = _window(seg_a, seg_b, window)
    if len(t) < 4:
        return _linear(seg_a, seg_b, frames)
    return np.asarray(CubicSpline(t, xy, axis=0)(frames), dtype=np.float64)


def _bspline(
    seg_a: F64, seg_b: F64, frames: NDArray[np.int64], window: int = 12, spacing: int = 4
) -> F64:
    from scipy.interpolate import make_lsq_spline

    t, xy = _window(seg_a, seg_b, window)
    if len(t) < 8:
        return _cubic(seg_a, seg_b, frames)
    f0, f1 = seg_a[-1, 0], seg_b[0, 0]
    # interior knots every `spacing` frames inside each observed window, none inside the gap
    # (no data there: Schoenberg-Whitney), so one cubic piece spans the gap
    left = np.arange(f0 - spacing, t[0] + spacing / 2, -spacing)[::-1]
    right = np.arange(f1 + spacing, t[-1] - spacing / 2, spacing)
    interior = np.concatenate([left, right])
    k = 3
    knots = np.concatenate([[t[0]] * (k + 1), interior, [t[-1]] * (k + 1)])
    dist = np.where(t <= f0, f0 - t, t - f1)
    w = 1.0 / (1.0 + dist / 5.0)  # points near the gap count more
    try:
        spl = make_lsq_spline(t, xy, knots, k=k, w=w, axis=0)
    except (ValueError, np.linalg.LinAlgError):
        return _cubic(seg_a, seg_b, frames)
    return np.asarray(spl(frames), dtype=np.float64)


def _gsi(seg_a: F64, seg_b: F64, frames: NDArray[np.int64], tau: float = 10.0) -> F64:
    # StrongSORT's GSI: linear interpolation, then GP regression (RBF, fixed length) over the
    # whole track; here over the observed points within 3 length scales of the gap.
    t_all = np.concatenate([seg_a[:, 0], frames, seg_b[:, 0]])
    xy_all = np.vstack([seg_a[:, 1:3], _linear(seg_a, seg_b, frames), seg_b[:, 1:3]])
    n_track = len(t_all)
    ls = float(np.clip(tau * np.log(tau**3 / n_track), 1.0 / tau, tau**2))
    keep = (t_all >= frames[0] - 3 * ls - 1) & (t_all <= frames[-1] + 3 * ls + 1)
    t, xy = t_all[keep], xy_all[keep]
    K = np.exp(-0.5 * ((t[:, None] - t[None, :]) / ls) ** 2)
    jitter = 1e-10
    while True:
        try:
            L = np.linalg.cholesky(K + jitter * np.eye(len(t)))
            break
        except np.linalg.LinAlgError:
            jitter *= 10.0
    alpha = np.linalg.solve(L.T, np.linalg.solve(L, xy))
    Ks = np.exp(-0.5 * ((frames[:, None] - t[None, :]) / ls) ** 2)
    return np.asarray(Ks @ alpha, dtype=np.float64)


def _rts(
    seg_a: F64,
    seg_b: F64,
    frames: NDArray[np.int64],
    q: float = 0.1,
    r: float = 1.0,
    history: int = 30,
) -> F64:
    a = seg_a[-history:]
    b = seg_b[:history]
    f_first, f_last = int(a[0, 0]), int(b[-1, 0])
    n = f_last - f_first + 1
    z = np.full((n, 2), np.nan)
    z[(a[:, 0] - f_first).astype(int)] = a[:, 1:3]
    z[(b[:, 0] - f_first).astype(int)] = b[:, 1:3]
    A = constant_velocity_A(1.0)
    Q = wna_Q((q, q))
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = np.eye(2) * r
    m = np.array([z[0, 0], z[0, 1], 0.0, 0.0])
    P = np.diag([r, r, 1e2, 1e2])
    ms = np.zeros((n, 4))
    Ps = np.zeros((n, 4, 4))
    mp = np.zeros((n, 4))
    Pp = np.zeros((n, 4, 4))
    for k in range(n):
        if k > 0:
            m = A @ m
            P = A @ P @ A.T + Q
        mp[k], Pp[k] = m, P
        if not np.isnan(z[k, 0]):
            S = H @ P @ H.T + R
            K = P @ H.T @ np.linalg.inv(S)
            m = m + K @ (z[k] - H @ m)
            P = (np.eye(4) - K @ H) @ P
        ms[k], Ps[k] = m, P
    for k in range(n - 2, -1, -1):
        C = Ps[k] @ A.T @ np.linalg.inv(Pp[k + 1])
        ms[k] = ms[k] + C @ (ms[k + 1] - mp[k + 1])
        Ps[k] = Ps[k] + C @ (Ps[k + 1] - Pp[k + 1]) @ C.T
    return ms[(frames - f_first).astype(int), :2]


def _gdt_path(
    problem: tuple[Any, ...], start_conditioned: bool, frames: NDArray[np.int64], f0: float
) -> F64:
    r = _core.gdt_solve(*problem, "general", start_conditioned)
    return np.asarray(r["path"][(frames - f0).astype(int), :2], dtype=np.float64)


def _check_frames(seg_a: F64, seg_b: F64, frames: ArrayLike | None) -> NDArray[np.int64]:
    f0, f1 = int(seg_a[-1, 0]), int(seg_b[0, 0])
    if f1 <= f0:
        raise ValueError(
            f"recover_gap: segment_b starts at frame {f1}, expected after segment_a's end {f0}"
        )
    if frames is None:
        return np.arange(f0 + 1, f1, dtype=np.int64)
    fr = np.asarray(frames)
    if fr.ndim != 1 or (fr.size and not np.all(fr == np.round(fr))):
        raise ValueError("recover_gap: frames must be a 1-D array of integers")
    fr = fr.astype(np.int64)
    if fr.size and (fr.min() <= f0 or fr.max() >= f1):
        raise ValueError(f"recover_gap: frames must lie strictly between {f0} and {f1}")
    return fr


def recover_gap(
    segment_a: ArrayLike,
    segment_b: ArrayLike,
    frames: ArrayLike | None = None,
    method: str = "gdt",
    *,
    noise: NoiseEstimate | None = None,
    motion: MotionFit | None = None,
) -> F64:
    """Positions (and sizes) of an object in the frames between two observed segments.

    Parameters
    ----------
    segment_a, segment_b : (k, 3) or (k, 5) array_like
        Rows ``(frame, x, y[, w, h])`` before and after the gap, frames increasing.
    frames : (F,) array_like of int, optional
        Frames to fill, strictly between the two segments; default: all of them.
    method : str
        One of :data:`METHODS` (see the module docstring).
    noise : NoiseEstimate, optional
        For ``"gdt-bi"``: noise levels to use instead of estimating them from the two segments
        (e.g. pooled over a whole file with :func:`estimate_noise`).
    motion : MotionFit, optional
        For ``"gdt-mix"``: the model to use instead of fitting it to the two segments
        (e.g. fitted to a whole file with :func:`pftrack.recovery.mixture.fit_motion`).

    Returns
    -------
    (F, 2) or (F, 4) ndarray of float64
        ``(x, y)`` per frame, plus ``(w, h)`` (linear) when both segments carry sizes.

    Raises
    ------
    ValueError
        Empty or malformed segments, NaN, overlapping segments, frames outside the gap or an
        unknown method.
    """
    a = as_segment(segment_a, "segment_a")
    b = as_segment(segment_b, "segment_b")
    fr = _check_frames(a, b, frames)
    if method not in METHODS:
        raise ValueError(f"recover_gap: method is {method!r}, expected one of {METHODS}")
    if fr.size == 0:
        return np.zeros((0, 4 if a.shape[1] == 5 and b.shape[1] == 5 else 2))
    f0 = a[-1, 0]
    if method in PFTRACK_METHODS:
        full = recover_gaps([(a, b)], method, noise=noise, motion=motion)[0]
        xy = full[(fr - f0 - 1).astype(int)]
    elif method == "linear":
        xy = _linear(a, b, fr)
    elif method == "cubic":
        xy = _cubic(a, b, fr)
    elif method == "bspline":
        xy = _bspline(a, b, fr)
    elif method == "gsi":
        xy = _gsi(a, b, fr)
    else:
        xy = _rts(a, b, fr)
    wh = _fill_sizes(a, b, fr)
    return xy if wh is None else np.hstack([xy, wh])


def _segment_model(method: str, noise: NoiseEstimate | None) -> tuple[Any, ...]:
    if method == "gdt":
        m = _PAPER
        return (m.A, m.Q, m.H, m.R, m.p_init_velocity, "first_point", False)
    assert noise is not None
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    return (
        constant_velocity_A(1.0),
        wna_Q(noise.q),
        H,
        np.diag(noise.r),
        1e2,
        "backward_state",
        True,
    )


def recover_gaps(
    gaps: Sequence[tuple[ArrayLike, ArrayLike]],
    method: str = "gdt",
    *,
    noise: NoiseEstimate | None = None,
    history: int | None = None,
    motion: MotionFit | None = None,
) -> list[F64]:
    """Recover many gaps at once.

    Parameters
    ----------
    gaps : sequence of (segment_a, segment_b)
        Segments as in :func:`recover_gap` (only ``frame, x, y`` are used).
    method : str
        One of :data:`METHODS`.
    noise : NoiseEstimate, optional
        For ``"gdt-bi"``: noise levels shared by all gaps; default: estimated from all the
        segments given (:func:`estimate_noise`).
    history : int, optional
        The Kalman filters of the goal-directed methods use at most this many points of the run
        of consecutive frames next to the gap; default: the whole run.
    motion : MotionFit, optional
        For ``"gdt-mix"``: the model shared by all gaps; default: fitted to all the segments
        given (:func:`pftrack.recovery.mixture.fit_motion`, with `noise` as its fallback).

    Returns
    -------
    list of (T_g - 1, 2) ndarray
        ``(x, y)`` of every frame inside each gap.

    Notes
    -----
    The goal-directed methods filter the segments and solve every gap in one C++ call with the
    GIL released (O(T) per gap).
    """
    if method not in METHODS:
        raise ValueError(f"recover_gaps: method is {method!r}, expected one of {METHODS}")
    if method not in PFTRACK_METHODS:
        return [recover_gap(a, b, method=method, noise=noise)[:, :2] for a, b in gaps]
    if not gaps:
        return []
    seg_a = [np.asarray(a, dtype=np.float64) for a, _ in gaps]
    seg_b = [np.asarray(b, dtype=np.float64) for _, b in gaps]
    for k, s in enumerate(seg_a + seg_b):
        if s.ndim != 2 or s.shape[1] < 3 or s.shape[0] == 0:
            name = "segment_a" if k < len(gaps) else "segment_b"
            raise ValueError(
                f"recover_gaps: {name} of gap {k % len(gaps)} must have shape (k, 3|5), "
                f"non-empty; got {s.shape}"
            )
    if method == "gdt-mix":
        from pftrack.recovery.mixture import fit_motion, recover_mixture_gaps

        pairs = [
            (as_segment(a, "segment_a"), as_segment(b, "segment_b")) for a, b in zip(seg_a, seg_b)
        ]
        for k, (a, b) in enumerate(pairs):
            if b[0, 0] <= a[-1, 0]:
                raise ValueError(
                    f"recover_gaps: gap {k}: segment_b starts at frame {b[0, 0]:g}, expected "
                    f"after segment_a's end {a[-1, 0]:g}"
                )
        if motion is None:
            motion = fit_motion(seg_a + seg_b, noise)
        return recover_mixture_gaps(pairs, motion)
    if method == "gdt-bi" and noise is None:
        noise = estimate_noise(seg_a + seg_b)
    a_len = np.array([len(s) for s in seg_a], dtype=np.int32)
    b_len = np.array([len(s) for s in seg_b], dtype=np.int32)
    a = np.ascontiguousarray(np.concatenate(seg_a)[:, :3])
    b = np.ascontiguousarray(np.concatenate(seg_b)[:, :3])
    out = _core.gdt_recover_batch(
        a,
        a_len,
        b,
        b_len,
        *_segment_model(method, noise)[:6],
        2**31 - 1 if history is None else int(history),
        _segment_model(method, noise)[6],
    )
    T = (b[np.cumsum(b_len) - b_len, 0] - a[np.cumsum(a_len) - 1, 0]).astype(np.int64)
    return np.split(out, np.cumsum(T - 1)[:-1])
