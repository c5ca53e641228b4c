"""The ``gdt-mix`` method: goal-directed recovery mixed over walk/stand hypotheses.

``gdt-bi`` conditions one smooth motion model on both segments. Its errors come from two
things a single smooth model cannot express (docs/recovery.md): people who stop, linger or turn
round inside the gap, and acceleration that is correlated over a few frames (gait, keyframed
annotation). ``gdt-mix`` adds both, with every parameter estimated from the observed points:

* **Motion model, per axis** (:func:`fit_motion`): the Singer model (acceleration an
  Ornstein-Uhlenbeck process of time constant ``tau``: ``da = -a/tau dt + sqrt(q) dW``) with
  ``q``, ``r`` and ``tau`` by maximum likelihood of the observed runs. When the fitted ``tau``
  is below one frame the data cannot tell correlated acceleration from jitter (the fit then
  describes box noise, not motion), so the axis falls back to ``gdt-bi``'s white-noise-
  acceleration model with the multi-scale noise estimate (:func:`estimate_noise`).
* **Stand hypotheses**: "walks through the gap" and "stands still from step ``t1`` to ``t2``,
  then walks on with a fresh velocity" for ``t1 < t2`` on a grid of ``grid`` steps. Standing:
  velocity and acceleration reset to 0, the position wanders with the model's one-frame
  variance; the new velocity has the mean squared velocity of the observed points as variance.
  The prior ``P(no stand) = exp(-rate T)`` uses the stand rate of the observed runs
  (:func:`stand_rate`); the posterior weights are the evidence of each hypothesis.
* For each hypothesis a Kalman filter and RTS smoother run over ``window`` points on each side
  and the gap (C++, ``_core.gap_mixture``); for a linear-Gaussian model this smoothed mean is
  the goal-directed path conditioned on the filtered states at both ends. The result is the
  posterior mean over the hypotheses.

With no stand seen in the observed runs (``rate = 0``) and ``tau < 1`` on both axes, it reduces
to a fixed-interval smoother of the ``gdt-bi`` model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

import pftrack._core as _core
from pftrack._stats import unique_values
from pftrack._threads import kernel_threads
from pftrack._typing import F64
from pftrack.kalman import cv_transition, wna_Q
from pftrack.recovery.noise import NoiseEstimate, _estimate_noise
from pftrack.recovery.problems import SegmentModel, check_finite_paths
from pftrack.recovery.segments import consecutive_runs, observed_segments

__all__ = [
    "DIFFUSE",
    "GRID",
    "WINDOW",
    "AxisModel",
    "MotionFit",
    "check_models",
    "fit_motion",
    "fit_singer",
    "recover_mixture",
    "recover_mixture_gaps",
    "singer_model",
    "stand_hypotheses",
    "stand_rate",
]

#: Prior variance of the position at the start of a window (px^2): uninformative.
DIFFUSE = 1e4
#: Candidate times of standing still per gap (191 hypotheses with 20).
GRID = 20
#: Observed points used on each side of a gap.
WINDOW = 30


def _expm(M: F64) -> F64:
    """Matrix exponential of a ``(K, n, n)`` stack: scaling and squaring of a Taylor series.

    For the small Van Loan matrices of :func:`singer_model` (NumPy only: no SciPy import on
    the recovery path). Each matrix is scaled to a 1-norm of at most 1/2, where 18 terms are
    exact to double precision.
    """
    norm = np.abs(M).sum(axis=1).max(axis=-1)
    s = np.maximum(0, np.ceil(np.log2(np.maximum(norm, 1e-300) / 0.5))).astype(np.int64)
    A = M / (2.0**s)[:, None, None]
    eye = np.broadcast_to(np.eye(M.shape[-1]), M.shape)
    out = eye.copy()
    term = eye.copy()
    for k in range(1, 19):
        term = term @ A / k
        out = out + term
    for k in range(int(s.max()) if len(s) else 0):
        sq = out @ out
        out = np.where((k < s)[:, None, None], sq, out)
    return np.asarray(out, dtype=np.float64)


def singer_model(q: ArrayLike, tau: ArrayLike) -> tuple[F64, F64]:
    """One-frame transition ``F`` and noise ``Q`` of ``(position, velocity, acceleration)``.

    Continuous model ``da = -a/tau dt + sqrt(q) dW`` (``tau = inf``: white jerk), discretised
    exactly (Van Loan). ``q`` and ``tau`` broadcast; returns ``(K, 3, 3)`` stacks.
    """
    q, tau = np.broadcast_arrays(np.atleast_1d(np.asarray(q, float)), np.atleast_1d(tau))
    K = q.size
    M = np.zeros((K, 6, 6))
    Fc = np.zeros((K, 3, 3))
    Fc[:, 0, 1] = Fc[:, 1, 2] = 1.0
    with np.errstate(divide="ignore"):
        Fc[:, 2, 2] = np.where(np.isinf(tau), 0.0, -1.0 / tau).ravel()
    M[:, :3, :3] = -Fc
    M[:, 2, 5] = q.ravel()
    M[:, 3:, 3:] = Fc.transpose(0, 2, 1)
    V = _expm(M)
    F = V[:, 3:, 3:].transpose(0, 2, 1)
    Q = F @ V[:, :3, 3:]
    return F, 0.5 * (Q + Q.transpose(0, 2, 1))


@dataclass(frozen=True)
class AxisModel:
    """Motion model of one axis.

    ``kind`` is ``"singer"`` or ``"wna"`` (white-noise acceleration); ``tau`` (frames) is the
    Singer time constant found by maximum likelihood, also kept when the axis fell back to
    ``"wna"``.
    """

    kind: str
    q: float
    r: float
    tau: float

    @cached_property
    def matrices(self) -> tuple[F64, F64]:
        """One-frame ``F`` and ``Q`` (computed once per model, not once per gap)."""
        if self.kind == "singer":
            F, Q = singer_model(self.q, self.tau)
            return F[0], Q[0]
        return cv_transition(), wna_Q(self.q)

    def prior(self, v2: float) -> F64:
        """Prior variances of the state at a window's first point."""
        if self.kind == "singer":
            a2 = self.q * self.tau / 2.0  # stationary variance of the acceleration
            return np.array([DIFFUSE, v2, a2])
        return np.array([DIFFUSE, v2])


@dataclass(frozen=True)
class MotionFit:
    """Everything ``gdt-mix`` estimates from the observed points (:func:`fit_motion`).

    ``axes``: the (x, y) models; ``stand_rate``: stands per walking frame; ``v2``: mean squared
    velocity per axis (px^2/frame^2), the variance of a velocity after standing still.
    """

    axes: tuple[AxisModel, AxisModel]
    stand_rate: float
    v2: tuple[float, float]
    noise: NoiseEstimate

    def __str__(self) -> str:
        """:meth:`describe`, what ``print(fit)`` shows (``repr``: every field)."""
        return self.describe()

    def describe(self) -> str:
        """One line: the model of each axis, the stand rate and the restart velocity."""
        parts = []
        for name, m in zip("xy", self.axes, strict=True):
            if m.kind == "singer":
                parts.append(f"{name}: Singer q={m.q:.3g} r={m.r:.3g} tau={m.tau:.2f} frames")
            else:
                parts.append(
                    f"{name}: white acceleration q={m.q:.3g} r={m.r:.3g} (tau={m.tau:.2f})"
                )
        parts.append(f"stand rate {self.stand_rate:.4f}/frame")
        parts.append(f"velocity variance {self.v2[0]:.3g}, {self.v2[1]:.3g} px^2/frame^2")
        return "; ".join(parts)

    @cached_property
    def priors(self) -> tuple[F64, F64]:
        """:meth:`AxisModel.prior` of each axis with its restart velocity variance (once)."""
        px, py = (m.prior(v2) for m, v2 in zip(self.axes, self.v2, strict=True))
        return px, py

    @property
    def is_gdt_bi(self) -> bool:
        """No stand seen and white-noise acceleration on both axes: the ``gdt-bi`` model."""
        return self.stand_rate == 0.0 and all(m.kind == "wna" for m in self.axes)


def check_models(noise: object, motion: object, who: str) -> None:
    """Refuse a `noise` that is not a :class:`NoiseEstimate` or a `motion` not a :class:`MotionFit`.

    None passes (estimated from the data). Anything else would fail deep inside (``'str'
    object has no attribute 'q'``).

    Raises
    ------
    TypeError
        Naming `who`, the parameter and the type expected.
    """
    for name, value, kind, maker in (
        ("noise", noise, NoiseEstimate, "estimate_noise"),
        ("motion", motion, MotionFit, "fit_motion"),
    ):
        if value is not None and not isinstance(value, kind):
            raise TypeError(
                f"{who}: {name} must be a {kind.__name__} (pftrack.recovery.{maker}) or None, "
                f"got {type(value).__name__}"
            )


def _stack_runs(runs: Sequence[F64], axis: int) -> tuple[F64, NDArray[np.int32]]:
    z = np.ascontiguousarray(np.concatenate([r[:, 1 + axis] for r in runs]))
    return z, np.array([len(r) for r in runs], dtype=np.int32)


def fit_singer(runs: Sequence[F64], axis: int, levels: int = 4) -> tuple[float, float, float]:
    """Maximum-likelihood ``(q, r, tau)`` of the Singer model for one axis of the runs.

    Kalman prediction-error likelihood (C++, ``_core.state_loglik_batch``) maximised on a
    coarse-to-fine 7x7x7 grid of ``log q``, ``log r``, ``log tau``.
    """
    z, lengths = _stack_runs(runs, axis)
    lo = np.array([-5.0, -3.0, -1.5])  # log10 of q, r, tau
    hi = np.array([3.0, 3.0, 2.5])
    best = (lo + hi) / 2.0
    for _ in range(levels):
        axes = [np.linspace(lo[i], hi[i], 7) for i in range(3)]
        g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        r = 10.0 ** g[:, 1]
        # F and Q do not depend on r: the 7 x 7 distinct (q, tau), each repeated over the 7 r
        # of the grid (rows ordered q, r, tau), instead of 343 matrix exponentials.
        F, Q = singer_model(10.0 ** axes[0][:, None], 10.0 ** axes[2][None, :])
        F = np.repeat(F.reshape(7, 1, 7, 3, 3), 7, axis=1)
        Q = np.repeat(Q.reshape(7, 1, 7, 3, 3), 7, axis=1)
        ll = _core.state_loglik_batch(
            z,
            lengths,
            np.ascontiguousarray(F.reshape(-1, 3)),
            np.ascontiguousarray(Q.reshape(-1, 3)),
            r,
            DIFFUSE,
            kernel_threads(),
        )
        best = g[int(np.argmax(ll))]
        step = (hi - lo) / 6.0
        lo, hi = best - step, best + step
    q, r, tau = 10.0**best
    return float(q), float(r), float(tau)


def stand_rate(runs: Sequence[F64], noise: NoiseEstimate, k: int = 8) -> float:
    """Stands per walking frame in the observed runs.

    A frame is *standing* when its ``k``-frame displacement is, on both axes, within two
    standard deviations of what a standing object gives (position random walk ``q/3`` per frame
    plus measurement noise: ``sqrt(k q / 3 + 2 r)``); a stand starts at a walking-to-standing
    change. ``k = 8`` is the coarsest scale of :func:`estimate_noise`.
    """
    sd = np.sqrt(k * np.asarray(noise.q) / 3.0 + 2.0 * np.asarray(noise.r))
    onsets = walking = 0
    for r in runs:
        if len(r) <= k:
            continue
        standing = np.all(np.abs(r[k:, 1:3] - r[:-k, 1:3]) < 2.0 * sd, axis=1)
        onsets += int(np.sum(standing[1:] & ~standing[:-1]))
        walking += int(np.sum(~standing))
    return onsets / max(walking, 1)


def fit_motion(segments: Sequence[ArrayLike], noise: NoiseEstimate | None = None) -> MotionFit:
    """Estimate the ``gdt-mix`` model from observed segments (rows ``(frame, x, y, ...)``).

    ``noise``: the white-noise-acceleration estimate used as fallback and for the stand rate;
    default :func:`estimate_noise` of the same segments.

    Raises
    ------
    TypeError
        `noise` not a NoiseEstimate; `segments` not a sequence of arrays of real numbers.
    ValueError
        A segment :func:`~pftrack.recovery.segments.observed_segments` refuses (one segment
        given alone, NaN, frames that are not whole or do not increase).
    """
    check_models(noise, None, "fit_motion")
    return _fit_motion(observed_segments(segments, "fit_motion"), noise)


def _fit_motion(segments: Sequence[F64], noise: NoiseEstimate | None = None) -> MotionFit:
    """:func:`fit_motion` of segments the recovery checked itself (its runs, its gaps)."""
    runs = consecutive_runs(segments, 6)
    if noise is None:
        noise = _estimate_noise(runs)
    if sum(len(r) for r in runs) < 20:  # too little to fit anything: gdt-bi's model, no stands
        axes = tuple(AxisModel("wna", noise.q[i], noise.r[i], 0.0) for i in range(2))
        return MotionFit((axes[0], axes[1]), 0.0, (1.0, 1.0), noise)
    models = []
    for axis in range(2):
        q, r, tau = fit_singer(runs, axis)
        if tau >= 1.0:
            models.append(AxisModel("singer", q, r, tau))
        else:
            models.append(AxisModel("wna", noise.q[axis], noise.r[axis], tau))
    vel = np.vstack([np.diff(r[:, 1:3], axis=0) for r in runs])
    v2 = np.mean(vel**2, axis=0)
    return MotionFit(
        (models[0], models[1]), stand_rate(runs, noise), (float(v2[0]), float(v2[1])), noise
    )


def stand_hypotheses(T: int, grid: int = GRID) -> tuple[NDArray[np.int32], NDArray[np.int32]]:
    """Return ``(t1, t2)`` of every stand hypothesis of a gap of ``T`` steps.

    First ``(-1, -1)`` (no stand), then every ``t1 < t2`` on ``min(grid, T)`` evenly spaced
    steps of ``0 .. T-1``.
    """
    return _stand_hypotheses(int(T), int(grid))


@lru_cache(maxsize=1024)
def _stand_hypotheses(T: int, grid: int) -> tuple[NDArray[np.int32], NDArray[np.int32]]:
    ks = unique_values(np.round(np.linspace(0, T - 1, min(grid, T))).astype(np.int32))
    i, j = np.triu_indices(len(ks), k=1)
    t1 = np.concatenate([[-1], ks[i]]).astype(np.int32)
    t2 = np.concatenate([[-1], ks[j]]).astype(np.int32)
    t1.setflags(write=False)  # shared by every gap of this length
    t2.setflags(write=False)
    return t1, t2


_WALK_ONLY = np.array([-1], dtype=np.int32)
_WALK_ONLY.setflags(write=False)


@lru_cache(maxsize=1024)
def _hypotheses(T: int, grid: int, rate: float) -> tuple[NDArray[np.int32], NDArray[np.int32], F64]:
    """Stand hypotheses of a gap of ``T`` steps and their log prior (read-only, shared)."""
    if rate > 0.0:
        t1, t2 = stand_hypotheses(T, grid)
        n_stand = len(t1) - 1
        log_prior = np.full(len(t1), np.log(-np.expm1(-rate * T) / max(n_stand, 1)))
        log_prior[0] = -rate * T
    else:
        t1 = t2 = _WALK_ONLY
        log_prior = np.zeros(1)
    log_prior.setflags(write=False)
    return t1, t2, log_prior


class _Window(NamedTuple):
    """One gap's window for ``_core.gap_mixture``: both axes' observations and its hypotheses."""

    z: F64  # (2, n): one row per axis, NaN where unobserved
    fa: int
    fb: int
    t1: NDArray[np.int32]
    t2: NDArray[np.int32]
    log_prior: F64


def _window(seg_a: F64, seg_b: F64, fit: MotionFit, grid: int, window: int) -> _Window | None:
    """The window of the gap between two segments; None when it has no lost step."""
    a, b = seg_a[-window:], seg_b[:window]
    f0 = int(a[0, 0])
    n = int(b[-1, 0]) - f0 + 1
    fa, fb = int(a[-1, 0]) - f0, int(b[0, 0]) - f0
    T = fb - fa
    if T < 2:
        return None
    t1, t2, log_prior = _hypotheses(T, grid, fit.stand_rate)
    z = np.full((2, n), np.nan)
    z[:, (a[:, 0] - f0).astype(int)] = a[:, 1:3].T
    z[:, (b[:, 0] - f0).astype(int)] = b[:, 1:3].T
    return _Window(z, fa, fb, t1, t2, log_prior)


def _posterior_mean(w: _Window, axes: Sequence[tuple[F64, F64]]) -> F64:
    """The hypotheses' paths of both axes weighted by their posterior probabilities."""
    loglik = w.log_prior.copy()
    for _, ll in axes:
        loglik += ll
    p = np.exp(loglik - loglik.max())
    p /= p.sum()
    return np.column_stack([p @ axes[0][0], p @ axes[1][0]])


def recover_mixture(
    seg_a: F64, seg_b: F64, fit: MotionFit, grid: int = GRID, window: int = WINDOW
) -> F64:
    """``(T - 1, 2)`` positions inside the gap between two segments (``(frame, x, y, ...)``)."""
    w = _window(seg_a, seg_b, fit, grid, window)
    if w is None:
        return np.zeros((0, 2))
    axes = []
    for axis, model in enumerate(fit.axes):
        F, Q = model.matrices
        axes.append(
            _core.gap_mixture(
                w.z[axis], w.fa, w.fb, F, Q, model.r, fit.priors[axis], w.t1, w.t2, fit.v2[axis]
            )
        )
    return _posterior_mean(w, axes)


def recover_mixture_gaps(
    gaps: Sequence[tuple[F64, F64]], fit: MotionFit, threads: int | None = None
) -> list[F64]:
    """Recover many gaps with :func:`recover_mixture`: the same paths, in one C++ call.

    When the fitted model is ``gdt-bi``'s (:attr:`MotionFit.is_gdt_bi`), ``gdt-bi`` itself runs
    (:meth:`SegmentModel.two_sided <pftrack.recovery.problems.SegmentModel.two_sided>`, one C++
    call for all gaps). Else the gaps' hypotheses run on `threads` threads
    (``_core.gap_mixture_many``; default :func:`pftrack._threads.kernel_threads`), which does
    not change a bit of the result.
    """
    if fit.is_gdt_bi:
        if not gaps:
            return []
        model = SegmentModel.two_sided(fit.noise)
        return model.recover([a for a, _ in gaps], [b for _, b in gaps])
    windows = [_window(a, b, fit, GRID, WINDOW) for a, b in gaps]
    jobs = [
        (w.z[axis], w.fa, w.fb, axis, w.t1, w.t2)
        for w in windows
        if w is not None
        for axis in range(2)
    ]
    matrices = [m.matrices for m in fit.axes]
    results = _core.gap_mixture_many(
        jobs,
        [F for F, _ in matrices],
        [Q for _, Q in matrices],
        [m.r for m in fit.axes],
        list(fit.priors),
        list(fit.v2),
        kernel_threads() if threads is None else threads,
    )
    out, at = [], 0
    for w in windows:
        if w is None:
            out.append(np.zeros((0, 2)))
        else:
            out.append(_posterior_mean(w, results[at : at + 2]))
            at += 2
    T = [int(b[0, 0] - a[-1, 0]) for a, b in gaps]
    q = max(m.q for m in fit.axes)
    check_finite_paths(out, T, f"the motion model's process noise {q:.3g}")
    return out
