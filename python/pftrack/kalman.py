"""The constant-velocity Kalman filter and Rauch-Tung-Striebel smoother of pftrack.

One model serves the whole package: each axis (a box centre's x, a box's width, ...) has the
state ``(position, velocity)``, moves at constant velocity, and is pushed by white-noise
acceleration; measurements see the position only. Axes are independent, so every function
here runs any number of them at once: means and covariance entries are arrays over axes (or
plain floats), and a covariance is kept as its three entries ``(p00, p01, p11)``.

Time is measured in frames. Over one frame, continuous white-noise acceleration of spectral
density ``q`` (px²/frame³) adds the covariance

    Q = q [[1/3, 1/2], [1/2, 1]]                                     (:func:`wna_Q`)

to the state (Bar-Shalom et al. 2001, sec. 6.2.2). This is the model's discretisation.

Users
-----
- the online tracker's centre filter (:mod:`pftrack.tracking.motion`):
  :func:`cv_predict`, :func:`cv_update`;
- the offline box smoother (:class:`pftrack.tracking.BoxSmoother`) and the recovery ``rts``
  baseline: :func:`rts_smooth` (``update_first=False``: the first measurement *is* the
  initial state; ``update_first=True``: a prior centred on it, then the usual update);
- the recovery code that builds matrices for the C++ filters (``_core.kalman_filter``,
  goal-directed tracking): :func:`cv_transition`, :func:`wna_Q` (one axis, ``(2, 2)``),
  :func:`cv_transition_xy`, :func:`wna_Q_xy` (state ``(x, y, vx, vy)``, ``(4, 4)``).

Every public function checks its noise and variance arguments (``q``, ``r2``, the covariance
entries, ``dt``: finite, and ``> 0`` or ``>= 0`` as the equations need; a covariance positive
semi-definite, ``p01² <= p00 p11`` up to round-off), and its result (finite; an update's
``p00 + r2`` too), with a one-line ValueError, and computes in float64 whatever it is given
(lists, float32 arrays, NumPy scalars; lists failed in the arithmetic, float32 was stepped in
float32 until 5 December). The tracker
runs :func:`cv_predict` and :func:`cv_update` for every track on every frame with values it
made itself: it calls the unchecked ``_cv_predict``, ``_cv_update`` and ``_cv_update_where``,
which compute the same floats.

The tracker and the box smoother once used the piecewise-constant discretisation
``q [[1/4, 1/2], [1/2, 1]]`` instead; with the same noise levels, the continuous one scores
the same or better on every sequence measured (docs/tracking.md), so it is the only one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike

from pftrack import _core
from pftrack._check import bool_array, first_at, flag, number, real_array
from pftrack._typing import F64

__all__ = [
    "Cov",
    "Mean",
    "Value",
    "cv_predict",
    "cv_transition",
    "cv_transition_xy",
    "cv_update",
    "cv_update_where",
    "rts_smooth",
    "wna_Q",
    "wna_Q_xy",
]

#: One axis quantity (or one per axis): a float or an array over axes.
Value: TypeAlias = float | F64
#: Mean of the state: ``(position, velocity)``.
Mean: TypeAlias = tuple[Value, Value]
#: Covariance of the state, as its entries ``(p00, p01, p11)``.
Cov: TypeAlias = tuple[Value, Value, Value]


def _require(fn: str, name: str, value: ArrayLike, bound: str = "") -> None:
    """Raise a ValueError unless every entry of `value` is finite and ``> 0`` / ``>= 0``.

    Parameters
    ----------
    fn, name : str
        The function and the argument, for the message (``"cv_update"``, ``"r2"``).
    value : float or array_like
        The argument.
    bound : {"", ">= 0", "> 0"}
        What the entries must be beyond finite.

    Raises
    ------
    TypeError
        Not real numbers.
    ValueError
        ``fn: name is -1, expected finite and >= 0`` (``name[i]`` naming an array's entry).
    """
    v = real_array(value, f"{fn}: {name}")
    ok = np.isfinite(v)
    if bound == "> 0":
        ok &= v > 0
    elif bound == ">= 0":
        ok &= v >= 0
    if not ok.all():
        k, at = first_at(~ok)
        want = f"finite and {bound}" if bound else "finite"
        raise ValueError(f"{fn}: {name}{at} is {v[k]:g}, expected {want}")


def _require_cov(fn: str, cov: Cov) -> None:
    """:func:`_require` for a covariance ``(p00, p01, p11)``: variances ``>= 0``, p01 finite."""
    if len(cov) != 3:
        raise ValueError(f"{fn}: cov has {len(cov)} entries, expected 3 (p00, p01, p11)")
    for name, value, bound in zip(("p00", "p01", "p11"), cov, (">= 0", "", ">= 0"), strict=True):
        _require(fn, f"cov's {name}", value, bound)


def _require_mean(fn: str, mean: Mean) -> None:
    """:func:`_require` for a mean ``(position, velocity)``: both finite."""
    if len(mean) != 2:
        raise ValueError(f"{fn}: mean has {len(mean)} entries, expected 2 (position, velocity)")
    for name, value in zip(("position", "velocity"), mean, strict=True):
        _require(fn, f"mean's {name}", value)


def _require_state(fn: str, mean: Mean, cov: Cov, **others: ArrayLike) -> None:
    """Check a state (:func:`_require_mean`, :func:`_require_cov`) and its arrays' shapes.

    The entries of `mean` and `cov` and the arrays of `others` (``q``, ``z``, ...) are one
    value per axis: their shapes must broadcast together, or the state comes out ragged
    (a mean over 3 axes beside a covariance over 4).
    """
    _require_mean(fn, mean)
    _require_cov(fn, cov)
    named: dict[str, ArrayLike] = {"mean's position": mean[0], "mean's velocity": mean[1]}
    named.update({"cov's p00": cov[0], "cov's p01": cov[1], "cov's p11": cov[2], **others})
    shapes = {name: np.shape(value) for name, value in named.items()}
    seen: dict[str, tuple[int, ...]] = {}
    for name, shape in shapes.items():
        for other, got in seen.items():
            try:
                np.broadcast_shapes(got, shape)
            except ValueError:
                raise ValueError(
                    f"{fn}: {other} has shape {got} and {name} {shape}, which do not broadcast "
                    "together (one value per axis)"
                ) from None
        seen[name] = shape
    _require_psd(fn, cov)


#: Round-off :func:`_require_psd` forgives: ``|p01|`` up to ``sqrt(p00 p11)`` times
#: ``1 + PSD_RTOL``, plus the smallest normal float (p01 of a covariance whose variances
#: underflowed to 0).
PSD_RTOL = 1e-9


def _require_psd(fn: str, cov: Cov) -> None:
    """Raise a ValueError unless the covariance ``(p00, p01, p11)`` is positive semi-definite.

    A 2x2 covariance with variances ``>= 0`` (checked first, by :func:`_require_cov`) is PSD
    when ``p01² <= p00 p11``; the test is ``|p01| <= sqrt(p00) sqrt(p11) (1 + PSD_RTOL) +
    tiny``, which never overflows (``p01²`` does from 1.4e154) and forgives the round-off of
    a predict or update. Per axis: the first bad one is named.
    """
    p00, p01, p11 = np.broadcast_arrays(*(np.asarray(c, dtype=np.float64) for c in cov))
    bound = np.sqrt(p00) * np.sqrt(p11) * (1.0 + PSD_RTOL) + np.finfo(np.float64).tiny
    bad = np.abs(p01) > bound
    if bad.any():
        k, at = first_at(bad)
        shown = ", ".join(str(float(c[k])) for c in (p00, p01, p11))  # 1.00000001, not 1
        raise ValueError(
            f"{fn}: cov{at} (p00, p01, p11) = ({shown}) is not positive semi-definite: "
            "expected p01² <= p00 * p11"
        )


def _require_innovation(fn: str, cov: Cov, r2: Value, where: ArrayLike) -> None:
    """Refuse an innovation variance ``p00 + r2`` that overflows where `where` holds.

    The gain ``p00 / (p00 + r2)`` would be 0: the measurement silently ignored (p00 and r2
    of 1e308 each), with a filtered state that still looks finite.
    """
    with np.errstate(over="ignore"):
        s = np.asarray(cov[0], dtype=np.float64) + np.asarray(r2, dtype=np.float64)
    bad = np.broadcast_to(where, np.broadcast_shapes(np.shape(where), s.shape)) & ~np.isfinite(s)
    if bad.any():
        raise ValueError(
            f"{fn}: cov's p00 + r2 (the innovation variance) overflows: p00 or r2 too extreme "
            "(the measurement would be ignored)"
        )


def _float64(value: object) -> Value:
    """A checked value in float64: a real scalar as a Python float, the rest as an array.

    The public steps compute in float64 whatever they are given, as the tracker's do: a list
    (``mean=([1, 2], [0, 0])``) was multiplied as a Python list ("can't multiply sequence by
    non-int of type 'float'", naming nothing), and float32 arrays were stepped in float32.
    """
    if isinstance(value, (bool, int, float, np.bool_, np.integer, np.floating)):
        return float(value)
    return np.asarray(value, dtype=np.float64)


def _state64(mean: Mean, cov: Cov) -> tuple[Mean, Cov]:
    """`mean` and `cov`, checked by :func:`_require_state`, in float64 (:func:`_float64`)."""
    m0, m1 = (_float64(v) for v in mean)
    c0, c1, c2 = (_float64(v) for v in cov)
    return (m0, m1), (c0, c1, c2)


def _finite_result(
    fn: str, what: str, causes: str, step: Callable[..., tuple[Mean, Cov]], *args: object
) -> tuple[Mean, Cov]:
    """``step(*args)``, refused with a ValueError naming `fn` unless every entry is finite.

    The checks of the arguments bound each one, not their products: a mean of 1e308 moving
    at 1e308 px a frame would come out infinite (as :func:`rts_smooth` refuses it).
    """
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            out = step(*args)
    except OverflowError:  # a Python float's ``dt**3``
        out = ((math.inf, math.inf), (math.inf, math.inf, math.inf))
    (m0, m1), (c0, c1, c2) = out
    if not all(np.all(np.isfinite(v)) for v in (m0, m1, c0, c1, c2)):
        raise ValueError(f"{fn}: the {what} state is not finite ({causes} too extreme)")
    return out


def cv_transition(dt: float = 1.0) -> F64:
    """Transition ``F = [[1, dt], [0, 1]]`` of one axis' ``(position, velocity)``.

    Raises
    ------
    ValueError
        `dt` not finite.
    """
    _require("cv_transition", "dt", dt)
    return _cv_transition(dt)


def _cv_transition(dt: float) -> F64:
    """:func:`cv_transition` without its check."""
    return np.array([[1.0, dt], [0.0, 1.0]])


def wna_Q(q: float, dt: float = 1.0) -> F64:  # noqa: N802 - the usual name
    """Process noise of one axis over `dt` frames: ``q [[dt³/3, dt²/2], [dt²/2, dt]]``.

    Parameters
    ----------
    q : float
        Spectral density of the white-noise acceleration (px²/frame³).
    dt : float
        Time step in frames.

    Raises
    ------
    ValueError
        `q` or `dt` not finite and ``>= 0``.
    """
    _require("wna_Q", "q", q, ">= 0")
    _require("wna_Q", "dt", dt, ">= 0")
    return _wna_Q(q, dt)


def _wna_Q(q: float, dt: float) -> F64:  # noqa: N802 - the usual name
    """:func:`wna_Q` without its checks."""
    c = q * dt**2 / 2.0
    return np.array([[q * dt**3 / 3.0, c], [c, q * dt]])


def _xy_block(blocks: Sequence[F64]) -> F64:
    """Arrange per-axis ``(position, velocity)`` 2x2 blocks for the state ``(p_1.., v_1..)``."""
    n = len(blocks)
    out = np.zeros((2 * n, 2 * n))
    for axis, b in enumerate(blocks):
        i, j = axis, axis + n
        out[i, i], out[i, j], out[j, i], out[j, j] = b[0, 0], b[0, 1], b[1, 0], b[1, 1]
    return out


def cv_transition_xy(dt: float = 1.0) -> F64:
    """Transition of the state ``(x, y, vx, vy)``, ``(4, 4)``.

    Raises
    ------
    ValueError
        `dt` not finite.
    """
    _require("cv_transition_xy", "dt", dt)
    f = _cv_transition(dt)
    return _xy_block([f, f])


def wna_Q_xy(q: Sequence[float], dt: float = 1.0) -> F64:  # noqa: N802 - the usual name
    """Process noise of the state ``(x, y, vx, vy)``, ``(4, 4)``: :func:`wna_Q` per axis.

    Parameters
    ----------
    q : sequence of 2 float
        Spectral densities of the x and y accelerations (px²/frame³).
    dt : float
        Time step in frames.

    Raises
    ------
    TypeError
        `q` or `dt` not real numbers.
    ValueError
        Not 2 values in `q` (one number is refused: which axis would it be?), or `q` or `dt`
        not finite and ``>= 0``.
    """
    v = real_array(q, "wna_Q_xy: q")
    if v.shape != (2,):
        got = f"is {v.item():g}" if v.ndim == 0 else f"has shape {v.shape}"
        raise ValueError(f"wna_Q_xy: q {got}, expected 2 values (x, y): one density per axis")
    _require("wna_Q_xy", "q", v, ">= 0")
    _require("wna_Q_xy", "dt", dt, ">= 0")
    return _xy_block([_wna_Q(float(qi), dt) for qi in v])


def cv_predict(mean: Mean, cov: Cov, q: Value, dt: Value = 1.0) -> tuple[Mean, Cov]:
    """Advance independent constant-velocity axes by `dt` frames (one by default).

    Parameters
    ----------
    mean : (position, velocity)
        Floats or arrays over axes.
    cov : (p00, p01, p11)
        Covariance entries, floats or arrays over axes.
    q : float or ndarray
        Spectral density of the acceleration (px²/frame³): ``Q = q [[dt³/3, dt²/2], [dt²/2,
        dt]]`` (:func:`wna_Q`).
    dt : float or ndarray
        Frames to advance, per axis when an array (0: the state stays).

    Returns
    -------
    mean, cov
        The predicted state.

    Raises
    ------
    TypeError
        Values that are not real numbers.
    ValueError
        A variance of `cov` (p00, p11), `q` or `dt` not finite and ``>= 0``, p01 or `mean`
        not finite, `cov` not positive semi-definite (``p01² > p00 p11`` beyond a relative
        round-off of 1e-9), arrays whose shapes do not broadcast together, or a predicted
        state that is not finite (values too extreme: a position of 1e308 moving at 1e308).

    Examples
    --------
    >>> from pftrack.kalman import cv_predict
    >>> cv_predict((10.0, 2.0), (1.0, 0.0, 0.5), q=0.1)  # at 10 px, moving 2 px a frame
    ((12.0, 2.0), (1.5333333333333334, 0.55, 0.6))
    """
    fn = "cv_predict"
    _require_state(fn, mean, cov, q=q, dt=dt)
    _require(fn, "q", q, ">= 0")
    _require(fn, "dt", dt, ">= 0")
    m, c = _state64(mean, cov)
    q, dt = _float64(q), _float64(dt)
    return _finite_result(fn, "predicted", "mean, cov, q or dt", _cv_predict, m, c, q, dt)


def _cv_predict(mean: Mean, cov: Cov, q: Value, dt: Value = 1.0) -> tuple[Mean, Cov]:
    """:func:`cv_predict` without its checks: the tracker's per-frame call."""
    p00, p01, p11 = cov
    # P' = F P F^T + Q with F = [[1, dt], [0, 1]] (dt = 1: products by 1.0 are exact, so one
    # frame gives the same floats as the one-frame formula)
    return (mean[0] + dt * mean[1], mean[1]), (
        p00 + 2 * dt * p01 + dt * dt * p11 + q * dt**3 / 3.0,
        p01 + dt * p11 + q * dt * dt / 2,
        p11 + q * dt,
    )


def cv_update(mean: Mean, cov: Cov, z: Value, r2: Value) -> tuple[Mean, Cov]:
    """Kalman update of independent constant-velocity axes with position measurements.

    Parameters
    ----------
    mean, cov
        The predicted state (see :func:`cv_predict`).
    z : float or ndarray
        Measured positions.
    r2 : float or ndarray
        Their variances.

    Returns
    -------
    mean, cov
        The filtered state.

    Raises
    ------
    TypeError
        Values that are not real numbers.
    ValueError
        A variance of `cov` (p00, p11) not finite and ``>= 0``, p01, `mean` or `z` not finite,
        `cov` not positive semi-definite (as :func:`cv_predict`'s), `r2` not finite and ``> 0``
        (as :func:`rts_smooth`'s), arrays whose shapes do not broadcast together, ``p00 + r2``
        overflowing (the measurement would be ignored) or a filtered state that is not finite.

    Examples
    --------
    >>> from pftrack.kalman import cv_predict, cv_update
    >>> mean, cov = cv_predict((10.0, 2.0), (1.0, 0.0, 0.5), q=0.1)
    >>> mean, cov = cv_update(mean, cov, z=12.5, r2=1.0)  # measured at 12.5 px
    >>> round(mean[0], 4), round(mean[1], 4), round(cov[0], 4)
    (12.3026, 2.1086, 0.6053)
    """
    fn = "cv_update"
    _require_state(fn, mean, cov, z=z, r2=r2)
    _require(fn, "z", z)
    _require(fn, "r2", r2, "> 0")
    _require_innovation(fn, cov, r2, True)
    m, c = _state64(mean, cov)
    z, r2 = _float64(z), _float64(r2)
    return _finite_result(fn, "filtered", "mean, cov, z or r2", _cv_update, m, c, z, r2)


def _cv_update(mean: Mean, cov: Cov, z: Value, r2: Value) -> tuple[Mean, Cov]:
    """:func:`cv_update` without its checks: the tracker's per-frame call."""
    p00, p01, p11 = cov
    s = p00 + r2
    k0, k1 = p00 / s, p01 / s
    e = z - mean[0]
    return (mean[0] + k0 * e, mean[1] + k1 * e), ((1 - k0) * p00, (1 - k0) * p01, p11 - k1 * p01)


def cv_update_where(
    mean: Mean, cov: Cov, z: Value, r2: Value, where: ArrayLike
) -> tuple[Mean, Cov]:
    """:func:`cv_update` where `where` holds; elsewhere the predicted state stays.

    `where` broadcasts against the state's arrays (e.g. (n,) over axes, or (K, 1) over rows
    of K tracks). All True is exactly :func:`cv_update`; all False returns `mean`, `cov`.
    The arguments are checked as :func:`cv_update`'s, wherever `where` holds or not, but for
    `z`, which may hold anything (NaN included) where `where` does not hold.

    Raises
    ------
    TypeError
        Values that are not real numbers, or a `where` that is not bools (``"no"`` would
        count as True).
    ValueError
        What :func:`cv_update` refuses (`z` and ``p00 + r2`` only where `where` holds), or a
        `where` entry other than True and False (or 1 and 0; NaN would count as True).
    """
    fn = "cv_update_where"
    w = bool_array(where, f"{fn}: where")
    _require_state(fn, mean, cov, z=z, r2=r2, where=w)
    zz, ww = np.broadcast_arrays(real_array(z, f"{fn}: z"), w)
    missing = ww & ~np.isfinite(zz)
    if missing.any():
        k, at = first_at(missing)
        raise ValueError(f"{fn}: z{at} is {zz[k]:g} where `where` holds, expected finite")
    _require(fn, "r2", r2, "> 0")
    _require_innovation(fn, cov, r2, w)
    m, c = _state64(mean, cov)
    z, r2 = _float64(z), _float64(r2)
    return _finite_result(fn, "filtered", "mean, cov, z or r2", _cv_update_where, m, c, z, r2, w)


def _cv_update_where(
    mean: Mean, cov: Cov, z: Value, r2: Value, where: ArrayLike
) -> tuple[Mean, Cov]:
    """:func:`cv_update_where` without its checks: the tracker's per-frame call."""
    w = np.asarray(where, dtype=bool)
    if w.all():
        return _cv_update(mean, cov, z, r2)
    if not w.any():
        return mean, cov
    mu, cu = _cv_update(mean, cov, z, r2)
    m0, m1 = (np.where(w, a, b) for a, b in zip(mu, mean, strict=True))
    c0, c1, c2 = (np.where(w, a, b) for a, b in zip(cu, cov, strict=True))
    return (m0, m1), (c0, c1, c2)


def rts_smooth(
    z: ArrayLike,
    has: ArrayLike,
    q: ArrayLike,
    r2: ArrayLike,
    *,
    velocity_sd: float,
    update_first: bool,
) -> F64:
    """Smoothed positions of independent constant-velocity axes (Rauch-Tung-Striebel).

    Parameters
    ----------
    z : (T, n) array_like
        Position measurements, one column per axis, one row per frame; rows without a
        measurement may hold anything (NaN included).
    has : (T,) or (T, n) array_like of bool
        Which frames have a measurement, for every axis or per axis. The first must: the
        initial state is ``N([z_0, 0], diag(r2, velocity_sd²))``.
    q : (n,) array_like
        Noise intensity per axis (see :func:`cv_predict`).
    r2 : (n,) array_like
        Measurement variance per axis.
    velocity_sd : float
        Prior standard deviation of the initial velocity (wide: the data decide).
    update_first : bool
        Also apply the Kalman update with ``z_0`` at frame 0 (halves the initial position
        variance); False takes ``z_0`` as the initial state only.

    Returns
    -------
    (T, n) ndarray
        Mean of each position given every measurement.

    Raises
    ------
    TypeError
        `z`, `q`, `r2` not real numbers, `has` not of bools or numbers, `velocity_sd` not a
        number or `update_first` not a bool (``"no"`` would be True).
    ValueError
        Shapes that do not match, a value of `has` other than True, False, 1 or 0 (``NaN``
        or ``2`` would count as observed), a first frame without a measurement, a measured
        `z` not finite, `q` or `velocity_sd` not finite and ``>= 0``, `r2` not finite and
        ``> 0``.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack.kalman import rts_smooth
    >>> z = np.array([[0.0], [1.2], [np.nan], [2.9], [4.1]])  # one axis, frame 2 missed
    >>> has = ~np.isnan(z[:, 0])
    >>> rts_smooth(z, has, [0.1], [0.25], velocity_sd=5.0, update_first=True).round(3)
    array([[0.041],
           [1.051],
           [2.042],
           [3.031],
           [4.037]])
    """
    # one C++ loop over frames per axis (tests/reference/smoothing.py holds the NumPy loop it
    # equals), which checks the shapes, the first frame and every value it reads; rows without
    # a measurement are never read
    fn = "rts_smooth"
    zz, hh = real_array(z, f"{fn}: z"), bool_array(has, f"{fn}: has")
    q2, rr = real_array(q, f"{fn}: q"), real_array(r2, f"{fn}: r2")
    sd = number(velocity_sd, f"{fn}: velocity_sd", finite=False)  # the core names NaN, < 0
    try:
        out: F64 = _core.rts_smooth(zz, hh, q2, rr, sd, flag(update_first, f"{fn}: update_first"))
    except ValueError:
        # the core's refusal of q or r2 names neither the entry nor its value: name them, as
        # cv_update does (checked here only on the way out, at no cost to the smoother's calls)
        _require(fn, "q", q2, ">= 0")
        _require(fn, "r2", rr, "> 0")
        raise
    return out
