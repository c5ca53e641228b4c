"""Noise levels of the constant-velocity / white-noise-acceleration model, from observed points.

The model (:mod:`pftrack.kalman`): each axis moves at constant velocity pushed by continuous
white-noise acceleration of intensity ``q`` (px²/frame³) and is measured every frame with
variance ``r`` (px²). :func:`estimate_noise` estimates ``q`` and ``r`` per axis from the runs of
consecutive frames of observed segments.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

import pftrack._core as _core
from pftrack._check import MAX_FRAME, brief, integer, number, option, shown
from pftrack._typing import F64
from pftrack.recovery.segments import consecutive_runs, observed_segments

__all__ = ["DEFAULT_NOISE", "MAX_R_RATIO", "MIN_R", "NoiseEstimate", "estimate_noise"]


#: Smallest measurement variance (px²): below it the Kalman covariances of the C++ core lose
#: positive definiteness to round-off ("Pi_T + H S H^T is not positive definite" from 1e-13
#: px² with q = 0 on short runs; a user trial). Estimates never go below ``floor_r`` (1e-3).
MIN_R = 1e-12
#: The two axes' measurement variances must be less than this many times apart: the core
#: refuses ``diag(r)`` as singular from there ("R is not positive definite").
MAX_R_RATIO = 5e9


@dataclass(frozen=True)
class NoiseEstimate:
    """Noise levels per axis (x, y).

    ``q``: white-noise-acceleration intensity (px²/frame³); ``r``: measurement variance (px²).
    Each is 2 real numbers (a tuple, a list or an array; kept as a tuple of floats): ``q``
    finite and ``>= 0``, ``r`` finite and at least :data:`MIN_R` (a zero or tiny measurement
    variance makes the filters' covariances singular to round-off), its two values less than
    :data:`MAX_R_RATIO` times apart (the filters' measurement covariance ``diag(r)`` would be
    singular to the C++ core's check).

    Raises
    ------
    TypeError
        A field that is not 2 numbers (text, a bool, None):
        ``NoiseEstimate.q[0] must be a number, got bool True``.
    ValueError
        Not 2 values, or a value out of range:
        ``NoiseEstimate.r[1] is -1.0, expected a finite number >= 1e-12 (px²)``,
        ``NoiseEstimate.r is (1e-05, 100000.0): its values are 1e+10 times apart, expected
        less than 5e+09``.
    """

    q: tuple[float, float]
    r: tuple[float, float]

    def __post_init__(self) -> None:
        for name, lo, unit in (("q", 0.0, "px²/frame³"), ("r", MIN_R, "px²")):
            what = f"NoiseEstimate.{name}"
            raw: object = getattr(self, name)
            if isinstance(raw, (str, bytes)) or not isinstance(raw, (Sequence, np.ndarray)):
                raise TypeError(f"{what} must be 2 numbers (x, y), got {shown(raw)}")
            if isinstance(raw, np.ndarray) and raw.shape != (2,):
                raise ValueError(
                    f"{what} is an array of shape {raw.shape}, expected 2 numbers (x, y)"
                )
            if len(raw) != 2:
                raise ValueError(f"{what} is {brief(raw)}: {len(raw)} values, expected 2 (x, y)")
            pair = tuple(number(v, f"{what}[{i}]", finite=False) for i, v in enumerate(raw))
            for i, v in enumerate(pair):
                if not (np.isfinite(v) and v >= lo):
                    raise ValueError(
                        f"{what}[{i}] is {brief(v)}, expected a finite number >= {lo:g} ({unit})"
                    )
            # the core's test of a covariance, as it computes it (bridge.hpp,
            # require_covariance): every pivot above 1e-10 * size * the largest entry, so
            # the values less than 1 / (2e-10) = MAX_R_RATIO times apart
            if name == "r" and not min(pair) > 1e-10 * 2.0 * max(pair):
                raise ValueError(
                    f"{what} is {brief(pair)}: its values are {max(pair) / min(pair):.3g} times "
                    f"apart, expected less than {MAX_R_RATIO:g}"
                )
            object.__setattr__(self, name, pair)


#: Top of the maximum-likelihood grid of ``q`` and ``r`` (the floors must lie below it).
GRID_TOP = 100.0

#: Used when the segments are too short to estimate anything.
DEFAULT_NOISE = NoiseEstimate(q=(0.1, 0.1), r=(1.0, 1.0))

#: Terms of the likelihood a coarser scale needs before it may replace a finer scale's
#: estimate (a run of k points sampled at that scale adds k - 3: its prediction errors after
#: the first three). ``q`` from n of them has a relative standard error of about
#: ``sqrt(2 / n)``: "less than half" is two standard errors apart from 32 on. (Was: any 4,
#: so 5 points at scale 8 replaced 316 at scale 1 on a file with many short holes: q at its
#: floor, r 64 px², and GDT recovery 12 times linear's error; a user trial.)
MIN_SCALE_TERMS = 32


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


def _ml_noise(segments: Sequence[F64], floor_q: float, floor_r: float) -> NoiseEstimate:
    qs, rs = [], []
    lengths = np.array([len(run) for run in segments], dtype=np.int32)
    for axis in range(2):
        # the runs' values, stacked once for the three levels of the grid
        z = np.ascontiguousarray(np.concatenate([run[:, 1 + axis] for run in segments]))
        top = np.log10(GRID_TOP)
        lq_lo, lq_hi, lr_lo, lr_hi = np.log10(floor_q), top, np.log10(floor_r), top
        best = (0.0, 0.0)
        for _ in range(3):  # coarse-to-fine grid on log10 q, log10 r
            lq, lr = np.meshgrid(np.linspace(lq_lo, lq_hi, 9), np.linspace(lr_lo, lr_hi, 9))
            q, r = 10.0 ** lq.ravel(), 10.0 ** lr.ravel()
            ll = _core.noise_loglik_grid(
                z, lengths, np.ascontiguousarray(q), np.ascontiguousarray(r)
            )
            i = int(np.argmax(ll))
            best = (float(q[i]), float(r[i]))
            dq, dr = (lq_hi - lq_lo) / 8.0, (lr_hi - lr_lo) / 8.0
            lq_lo, lq_hi = max(np.log10(q[i]) - dq, np.log10(floor_q)), np.log10(q[i]) + dq
            lr_lo, lr_hi = max(np.log10(r[i]) - dr, np.log10(floor_r)), np.log10(r[i]) + dr
        qs.append(best[0])
        rs.append(best[1])
    return NoiseEstimate(q=(qs[0], qs[1]), r=(rs[0], rs[1]))


#: :func:`estimate_noise`'s default floors of ``q`` (px²/frame³) and ``r`` (px²), and scales.
FLOOR_Q, FLOOR_R, SCALES = 1e-5, 1e-3, (1, 2, 4, 8)


def estimate_noise(
    segments: Sequence[ArrayLike],
    *,
    method: str = "ml",
    floor_q: float = FLOOR_Q,
    floor_r: float = FLOOR_R,
    min_points: int = 4,
    scales: Sequence[int] = SCALES,
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
        Lower bounds of the estimates: ``0 < floor_q < 100`` (px²/frame³) and
        ``MIN_R <= floor_r < 100`` (px²; 100 is the top of the likelihood grid).
    min_points : int
        Shortest run used (an int >= 1).
    scales : sequence of int
        ``"ml"`` only: the model is fitted to the runs sampled every ``s`` frames for each
        ``s``; per axis, going from fine to coarse, a scale replaces the current estimate when
        its ``q`` (in per-frame units, ``q_s / s^3``) is less than half the current one, and
        its ``r`` comes with it, if it has at least :data:`MIN_SCALE_TERMS` terms. White
        acceleration gives the same ``q`` at every scale (within sampling error, hence the
        factor 2); jitter correlated over a few frames (gait sway,
        box annotation noise) inflates ``q`` at the finest scales and would make long
        predictions too wiggly.

    Returns
    -------
    NoiseEstimate
        :data:`DEFAULT_NOISE` when no run is long enough.

    Raises
    ------
    TypeError
        `segments` not a sequence of arrays of real numbers; an option of the wrong type.
    ValueError
        A segment :func:`~pftrack.recovery.segments.observed_segments` refuses (one segment
        given alone, NaN, frames that are not whole or do not increase); an option out of its
        range.
    """
    segs = observed_segments(segments, "estimate_noise")
    return _noise_levels(segs, method, floor_q, floor_r, min_points, scales)


def _estimate_noise(segments: Sequence[ArrayLike]) -> NoiseEstimate:
    """:func:`estimate_noise` with its defaults, of segments the recovery checked itself."""
    return _noise_levels(segments, "ml", FLOOR_Q, FLOOR_R, 4, SCALES)


def _noise_levels(
    segments: Sequence[ArrayLike],
    method: str,
    floor_q: float,
    floor_r: float,
    min_points: int,
    scales: Sequence[int],
) -> NoiseEstimate:
    """:func:`estimate_noise` of checked segments: its options checked, the levels fitted."""
    option(method, "estimate_noise: method", ("ml", "moments"))
    if method not in ("ml", "moments"):
        raise ValueError(f"estimate_noise: method is {method!r}, expected 'ml' or 'moments'")
    floor_q = number(floor_q, "estimate_noise: floor_q", finite=False)
    floor_r = number(floor_r, "estimate_noise: floor_r", finite=False)
    if not 0.0 < floor_q < GRID_TOP:  # NaN fails too
        raise ValueError(
            f"estimate_noise: floor_q is {brief(floor_q)}, expected a number in (0, {GRID_TOP:g}) "
            "(px²/frame³)"
        )
    if not MIN_R <= floor_r < GRID_TOP:
        raise ValueError(
            f"estimate_noise: floor_r is {brief(floor_r)}, expected a number in [{MIN_R:g}, "
            f"{GRID_TOP:g}) (px²)"
        )
    min_points = integer(min_points, "estimate_noise: min_points", 1, MAX_FRAME)
    runs = consecutive_runs(segments, max(min_points, 4))
    if sum(len(r) - 3 for r in runs) < 4:
        return DEFAULT_NOISE
    if not scales or any(int(v) < 1 for v in scales):
        raise ValueError(f"estimate_noise: scales is {brief(scales)}, expected integers >= 1")
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
        terms = sum(len(r) - 3 for r in sub)
        if terms < 4 or (best and terms < MIN_SCALE_TERMS):
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
