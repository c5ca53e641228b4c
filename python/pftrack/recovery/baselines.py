"""The baselines pftrack compares goal-directed recovery with.

Every baseline takes two segments (rows ``(frame, x, y[, w, h])``, see
:mod:`pftrack.recovery.segments`) and the frames to fill, strictly inside the gap (default:
every frame of it), and returns ``(F, 2)`` positions ``(x, y)``. Box sizes are filled by
:func:`interpolate_sizes` (linear) for every method. The public functions check their
arguments (a one-line ``TypeError`` or ``ValueError`` naming the function and the argument);
the recovery's own calls, on segments it has checked, use the unchecked ``_linear``, ... and
``_BASELINES``.

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
    Constant-velocity Kalman filter + Rauch-Tung-Striebel smoother (:mod:`pftrack.kalman`)
    over both segments and the gap, with fixed noise (``q = 0.1 px^2/frame^3``,
    ``r = 1 px^2``).

References
----------
.. [1] Zhang, Y. et al. (2022). ByteTrack: multi-object tracking by associating every detection
   box. ECCV 2022.
.. [2] Du, Y. et al. (2023). StrongSORT: make DeepSORT great again. IEEE TMM 25.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from types import MappingProxyType
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import integer, number
from pftrack._typing import F64
from pftrack.kalman import rts_smooth
from pftrack.recovery.segments import as_segment, gap_ends, gap_frames, split_rows

__all__ = [
    "BASELINES",
    "RTS_HISTORY",
    "Baseline",
    "bspline",
    "cubic",
    "gsi",
    "interpolate_sizes",
    "linear",
    "rts",
    "rts_batch",
]

#: A baseline: ``(segment_a, segment_b, frames) -> (F, 2)`` positions.
Baseline: TypeAlias = Callable[[F64, F64, NDArray[np.int64]], F64]
#: Points of each segment next to the gap :func:`rts` and :func:`rts_batch` use by default.
RTS_HISTORY = 30
#: Most points a window or history may hold (a 32-bit int: the core's offsets are int32).
_MAX_POINTS = 2**31 - 1


def _interpolate_sizes(seg_a: F64, seg_b: F64, frames: NDArray[np.int64]) -> F64 | None:
    """Box sizes ``(w, h)`` linearly interpolated between the two ends, ``(F, 2)``.

    None when either segment carries no sizes (3 columns).
    """
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
    """Straight line from segment A's last point to segment B's first."""
    f0, f1 = seg_a[-1, 0], seg_b[0, 0]
    s = (frames - f0) / (f1 - f0)
    out: F64 = (1.0 - s)[:, None] * seg_a[-1, 1:3] + s[:, None] * seg_b[0, 1:3]
    return out


def _cubic(seg_a: F64, seg_b: F64, frames: NDArray[np.int64], window: int = 30) -> F64:
    """Not-a-knot cubic spline through `window` points on each side (linear if fewer than 4)."""
    from scipy.interpolate import CubicSpline

    t, xy = _window(seg_a, seg_b, window)
    if len(t) < 4:
        return _linear(seg_a, seg_b, frames)
    return np.asarray(CubicSpline(t, xy, axis=0)(frames), dtype=np.float64)


def _bspline(
    seg_a: F64, seg_b: F64, frames: NDArray[np.int64], window: int = 12, spacing: int = 4
) -> F64:
    """Weighted least-squares cubic B-spline over `window` points on each side.

    Interior knots every `spacing` frames inside each observed window; points near the gap
    weigh more: the residual of a point ``d`` frames from the gap is multiplied by
    ``1 / (1 + d / 5)`` (SciPy's ``w``), so its square weighs ``1 / (1 + d / 5)²`` (Sun et al.
    2005, the paper's first baseline). Falls back to :func:`cubic`
    with fewer than 8 points or a singular fit (an error or a non-finite result).
    """
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
    out = np.asarray(spl(frames), dtype=np.float64)
    if not np.all(np.isfinite(out)):  # SciPy may return NaN for a rank-deficient fit
        return _cubic(seg_a, seg_b, frames)
    return out


#: Gap frames :func:`gsi` solves at once; a longer gap is filled in blocks of this many frames,
#: each from the points within 3 length scales of it, so work grows with the gap's length and
#: memory stays bounded (one solve of a 100 000-frame gap needed 80 GB).
GSI_BLOCK = 1024


def _gsi(seg_a: F64, seg_b: F64, frames: NDArray[np.int64], tau: float = 10.0) -> F64:
    """StrongSORT's Gaussian-smoothed interpolation.

    Linear interpolation, then Gaussian-process regression (RBF kernel, fixed length
    ``clip(tau log(tau^3 / n), 1/tau, tau^2)`` for a track of ``n`` points) over the whole
    track; here over the points within 3 length scales of the gap, and for a gap of more than
    :data:`GSI_BLOCK` frames block by block, each block over the points within 3 length
    scales of it (the same numbers up to the points' weight beyond them: tested; StrongSORT's
    regression over the whole track differs by up to 0.05-0.15 px on tracks of 200-600
    points; doubling its 1e-10 jitter moves the path by 0.02-0.05 px). The
    coordinates are taken from the middle of the gap's two ends: the process has a zero prior
    mean (StrongSORT's), which pulled the path toward the image origin by about 2e-7 of the
    coordinates (1.9 px at 1e7 px; a user trial), so the path did not move with the track.
    """
    centre = 0.5 * (seg_a[-1, 1:3] + seg_b[0, 1:3])
    t_all = np.concatenate([seg_a[:, 0], frames, seg_b[:, 0]])
    xy_all = np.vstack([seg_a[:, 1:3], _linear(seg_a, seg_b, frames), seg_b[:, 1:3]]) - centre
    n_track = len(t_all)
    ls = float(np.clip(tau * np.log(tau**3 / n_track), 1.0 / tau, tau**2))
    if len(frames) <= GSI_BLOCK:
        return _gp_smooth(t_all, xy_all, frames, ls) + centre
    return (
        np.vstack(
            [
                _gp_smooth(t_all, xy_all, frames[k : k + GSI_BLOCK], ls)
                for k in range(0, len(frames), GSI_BLOCK)
            ]
        )
        + centre
    )


def _gp_smooth(t_all: F64, xy_all: F64, frames: NDArray[np.int64], ls: float) -> F64:
    """GP posterior mean at `frames` from the points of `t_all` within 3 `ls` of them."""
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
    history: int = RTS_HISTORY,
) -> F64:
    """Kalman filter + RTS smoother over `history` points on each side and the gap.

    Parameters
    ----------
    seg_a, seg_b : (k, 3+) ndarray
        Checked segments.
    frames : (F,) ndarray of int64
        Frames to fill.
    q : float
        White-noise-acceleration intensity (px²/frame³), both axes.
    r : float
        Measurement variance (px²), both axes.
    history : int
        Points used on each side.

    Notes
    -----
    :func:`pftrack.kalman.rts_smooth` with the continuous discretisation; the first point is
    both the prior's centre (velocity standard deviation 10 px/frame) and a measurement.
    """
    a = seg_a[-history:]
    b = seg_b[:history]
    f_first, f_last = int(a[0, 0]), int(b[-1, 0])
    n = f_last - f_first + 1
    z = np.full((n, 2), np.nan)
    z[(a[:, 0] - f_first).astype(int)] = a[:, 1:3]
    z[(b[:, 0] - f_first).astype(int)] = b[:, 1:3]
    smoothed = rts_smooth(
        z,
        ~np.isnan(z[:, 0]),
        np.array([q, q]),
        np.array([r, r]),
        velocity_sd=10.0,
        update_first=True,
    )
    out: F64 = smoothed[(frames - f_first).astype(int)]
    return out


def _rts_batch(
    pairs: Sequence[tuple[F64, F64]], q: float = 0.1, r: float = 1.0, history: int = RTS_HISTORY
) -> list[F64]:
    """:func:`rts` for many gaps at once: every frame inside each gap, ``(x, y)``.

    The windows of all gaps (up to `history` points each side and the gap) go to one C++ call
    (``_core.rts_gaps_batch``, GIL released), which filters and smooths each window with the
    equations of :func:`pftrack.kalman.rts_smooth` (x and y share one covariance recursion).
    ``tests/reference/smoothing.py`` holds the vectorised NumPy version it is tested against.
    Segments must be checked, B after A.
    """
    if not pairs:
        return []
    wins = [(a[-history:, :3], b[:history, :3]) for a, b in pairs]
    sizes = np.array([len(a) + len(b) for a, b in wins], dtype=np.int64)
    if int(sizes.sum()) >= 2**31:
        raise ValueError(f"rts_batch: {int(sizes.sum())} window points, expected < 2^31")
    points = np.ascontiguousarray(np.vstack([s for w in wins for s in w]), dtype=np.float64)
    offsets = np.r_[0, np.cumsum(sizes)].astype(np.int32)
    n_before = np.array([len(a) for a, _ in wins], dtype=np.int32)
    out = _core.rts_gaps_batch(points, offsets, n_before, q, r, 100.0)
    lengths = np.array([b[0, 0] - a[-1, 0] - 1 for a, b in wins], dtype=np.int64)
    return split_rows(out, lengths)


#: The unchecked baselines by method name, for callers whose segments are checked, B after A.
_BASELINES: Mapping[str, Baseline] = MappingProxyType(
    {"linear": _linear, "cubic": _cubic, "bspline": _bspline, "gsi": _gsi, "rts": _rts}
)


# --- the public, checked entry points ------------------------------------------------------


def _gap(
    fn: str, seg_a: ArrayLike, seg_b: ArrayLike, frames: ArrayLike | None
) -> tuple[F64, F64, NDArray[np.int64]]:
    """`seg_a`, `seg_b` and `frames` of the public baseline `fn`, checked.

    Each segment as :func:`~pftrack.recovery.segments.as_segment` takes it, B starting after
    A ends, the frames strictly inside the gap (:func:`~pftrack.recovery.segments.gap_frames`).
    """
    a = as_segment(seg_a, "segment_a", fn)
    b = as_segment(seg_b, "segment_b", fn)
    return a, b, gap_frames(a, b, frames, fn)


def interpolate_sizes(
    seg_a: ArrayLike, seg_b: ArrayLike, frames: ArrayLike | None = None
) -> F64 | None:
    """Box sizes ``(w, h)`` linearly interpolated between the two ends, ``(F, 2)``.

    Parameters
    ----------
    seg_a, seg_b : (k, 3) or (k, 5) array_like
        The segments before and after the gap, rows ``(frame, x, y[, w, h])``.
    frames : (F,) array_like of int, optional
        Frames to fill, strictly inside the gap, increasing (default: every frame of it).

    Returns
    -------
    (F, 2) ndarray of float64 or None
        None when either segment carries no sizes (3 columns).

    Raises
    ------
    TypeError
        Segments or frames that are not real numbers (a list of lists is fine).
    ValueError
        A segment not of shape (k, 3) or (k, 5), empty, with a non-finite value, frames not
        whole or not increasing, a negative size or a value beyond ±1e9 px; segment B not
        after A; frames not inside the gap.
    """
    return _interpolate_sizes(*_gap("interpolate_sizes", seg_a, seg_b, frames))


def linear(seg_a: ArrayLike, seg_b: ArrayLike, frames: ArrayLike | None = None) -> F64:
    """Straight line from segment A's last point to segment B's first.

    Parameters
    ----------
    seg_a, seg_b : (k, 3) or (k, 5) array_like
        The segments before and after the gap, rows ``(frame, x, y[, w, h])``.
    frames : (F,) array_like of int, optional
        Frames to fill, strictly inside the gap, increasing (default: every frame of it).

    Returns
    -------
    (F, 2) ndarray of float64
        Positions ``(x, y)``, one row per frame.

    Raises
    ------
    TypeError, ValueError
        As :func:`interpolate_sizes`.
    """
    return _linear(*_gap("linear", seg_a, seg_b, frames))


def cubic(
    seg_a: ArrayLike, seg_b: ArrayLike, frames: ArrayLike | None = None, window: int = 30
) -> F64:
    """Not-a-knot cubic spline through `window` points on each side (linear if fewer than 4).

    Parameters
    ----------
    seg_a, seg_b, frames
        As :func:`linear`.
    window : int
        Points of each segment next to the gap the spline goes through (>= 1).

    Returns
    -------
    (F, 2) ndarray of float64
        Positions ``(x, y)``, one row per frame.

    Raises
    ------
    TypeError, ValueError
        As :func:`interpolate_sizes`; a `window` that is not an int >= 1.
    """
    window = integer(window, "cubic: window", 1, _MAX_POINTS)
    a, b, fr = _gap("cubic", seg_a, seg_b, frames)
    return _cubic(a, b, fr, window) if fr.size else np.zeros((0, 2))


def bspline(
    seg_a: ArrayLike,
    seg_b: ArrayLike,
    frames: ArrayLike | None = None,
    window: int = 12,
    spacing: int = 4,
) -> F64:
    """Weighted least-squares cubic B-spline over `window` points on each side (Sun et al. 2005).

    Interior knots every `spacing` frames inside each observed window, none in the gap; the
    residual of a point ``d`` frames from the gap is multiplied by ``1 / (1 + d / 5)``. Falls
    back to :func:`cubic` with fewer than 8 points or a singular fit.

    Parameters
    ----------
    seg_a, seg_b, frames
        As :func:`linear`.
    window : int
        Points of each segment next to the gap fitted (>= 1).
    spacing : int
        Frames between interior knots (>= 1).

    Returns
    -------
    (F, 2) ndarray of float64
        Positions ``(x, y)``, one row per frame.

    Raises
    ------
    TypeError, ValueError
        As :func:`interpolate_sizes`; a `window` or `spacing` that is not an int >= 1.
    """
    window = integer(window, "bspline: window", 1, _MAX_POINTS)
    spacing = integer(spacing, "bspline: spacing", 1, _MAX_POINTS)
    a, b, fr = _gap("bspline", seg_a, seg_b, frames)
    return _bspline(a, b, fr, window, spacing) if fr.size else np.zeros((0, 2))


def gsi(
    seg_a: ArrayLike, seg_b: ArrayLike, frames: ArrayLike | None = None, tau: float = 10.0
) -> F64:
    """StrongSORT's Gaussian-smoothed interpolation (linear fill, then GP regression).

    Parameters
    ----------
    seg_a, seg_b, frames
        As :func:`linear`.
    tau : float
        Sets the RBF kernel's length ``clip(tau log(tau^3 / n), 1/tau, tau^2)`` for ``n``
        points (finite, > 0; StrongSORT's 10).

    Returns
    -------
    (F, 2) ndarray of float64
        Positions ``(x, y)``, one row per frame.

    Raises
    ------
    TypeError, ValueError
        As :func:`interpolate_sizes`; a `tau` that is not a finite number > 0.
    """
    tau = number(tau, "gsi: tau")
    if not tau > 0:
        raise ValueError(f"gsi: tau is {tau:g}, expected a finite number > 0")
    a, b, fr = _gap("gsi", seg_a, seg_b, frames)
    return _gsi(a, b, fr, tau) if fr.size else np.zeros((0, 2))


def _rts_options(fn: str, q: float, r: float, history: int) -> tuple[float, float, int]:
    """`q` finite >= 0, `r` finite > 0 and `history` an int >= 1, of `fn`, checked."""
    q, r = number(q, f"{fn}: q"), number(r, f"{fn}: r")
    if not q >= 0:
        raise ValueError(f"{fn}: q is {q:g}, expected a finite number >= 0")
    if not r > 0:
        raise ValueError(f"{fn}: r is {r:g}, expected a finite number > 0")
    return q, r, integer(history, f"{fn}: history", 1, _MAX_POINTS)


def rts(
    seg_a: ArrayLike,
    seg_b: ArrayLike,
    frames: ArrayLike | None = None,
    q: float = 0.1,
    r: float = 1.0,
    history: int = RTS_HISTORY,
) -> F64:
    """Kalman filter + RTS smoother over `history` points on each side and the gap.

    Parameters
    ----------
    seg_a, seg_b, frames
        As :func:`linear`.
    q : float
        White-noise-acceleration intensity (px²/frame³), both axes: finite, >= 0.
    r : float
        Measurement variance (px²), both axes: finite, > 0.
    history : int
        Points used on each side (>= 1).

    Returns
    -------
    (F, 2) ndarray of float64
        Positions ``(x, y)``, one row per frame.

    Raises
    ------
    TypeError, ValueError
        As :func:`interpolate_sizes`; `q`, `r` or `history` out of their ranges.

    Notes
    -----
    :func:`pftrack.kalman.rts_smooth` with the continuous discretisation; the first point is
    both the prior's centre (velocity standard deviation 10 px/frame) and a measurement.
    """
    q, r, history = _rts_options("rts", q, r, history)
    a, b, fr = _gap("rts", seg_a, seg_b, frames)
    return _rts(a, b, fr, q, r, history)


def rts_batch(
    pairs: Sequence[tuple[ArrayLike, ArrayLike]],
    q: float = 0.1,
    r: float = 1.0,
    history: int = RTS_HISTORY,
) -> list[F64]:
    """:func:`rts` for many gaps at once: every frame inside each gap, ``(x, y)``.

    The windows of all gaps go to one C++ call (``_core.rts_gaps_batch``, GIL released).

    Parameters
    ----------
    pairs : sequence of (segment_a, segment_b)
        One pair of segments per gap, each as :func:`linear` takes them.
    q, r, history
        As :func:`rts`.

    Returns
    -------
    list of (F_k, 2) ndarray of float64
        One per gap, every frame inside it.

    Raises
    ------
    TypeError, ValueError
        As :func:`rts`, naming the pair (``rts_batch: pairs[2] segment_b ...``); `pairs` not
        a sequence of pairs.
    """
    fn = "rts_batch"
    q, r, history = _rts_options(fn, q, r, history)
    if isinstance(pairs, (str, bytes, np.ndarray)) or not isinstance(pairs, Sequence):
        raise TypeError(
            f"{fn}: pairs must be a sequence of (segment_a, segment_b) pairs, got "
            f"{type(pairs).__name__}"
        )
    checked = []
    for k, pair in enumerate(pairs):
        if not (isinstance(pair, Sequence) and len(pair) == 2):
            raise ValueError(f"{fn}: pairs[{k}] is not a pair (segment_a, segment_b)")
        a = as_segment(pair[0], "segment_a", f"{fn}: pairs[{k}]")
        b = as_segment(pair[1], "segment_b", f"{fn}: pairs[{k}]")
        gap_ends(a, b, f"{fn}: pairs[{k}]")
        checked.append((a, b))
    return _rts_batch(checked, q, r, history)


#: The baselines by method name (read-only): the checked public functions.
BASELINES: Mapping[str, Baseline] = MappingProxyType(
    {"linear": linear, "cubic": cubic, "bspline": bspline, "gsi": gsi, "rts": rts}
)
