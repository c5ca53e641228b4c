"""Stone Soup built the way its documentation builds it, for the comparisons with pftrack.

Stone Soup (``pip install stonesoup``, in the ``peers`` extra) is imported inside each function,
so this module imports without it. Used by ``tests/experiments/test_stonesoup.py`` (the same
smoothed means as :func:`pftrack.kalman.rts_smooth`), ``bench/test_stonesoup.py`` (speed) and
``experiments/compare_stonesoup.py`` (a multi-target tracker on public detections).

Time is one second per frame: Stone Soup's models take ``timedelta`` intervals, pftrack counts
frames, and with ``dt = 1 s`` the matrices are the same numbers.

The model
---------
Stone Soup's ``ConstantVelocity(noise_diff_coeff=q)`` has ``F = [[1, dt], [0, 1]]`` and
``Q = q [[dt³/3, dt²/2], [dt²/2, dt]]``, the continuous white-noise acceleration model of
:func:`pftrack.kalman.wna_Q`: the same `q` means the same filter. Axes are stacked with
``CombinedLinearGaussianTransitionModel``, so the state is ``(x, vx, y, vy, ...)``: position and
velocity of each axis side by side (pftrack's ``_xy`` matrices put positions first).
"""

from __future__ import annotations

import datetime
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pftrack._typing import F64

__all__ = ["EPOCH", "cv_models", "stonesoup_rts_smooth", "stonesoup_track"]

EPOCH = datetime.datetime(2000, 1, 1)
"""Frame 0's timestamp; frame ``t`` is ``EPOCH + t`` seconds."""


def at(t: int) -> datetime.datetime:
    """The timestamp of frame `t`."""
    return EPOCH + datetime.timedelta(seconds=t)


def cv_models(q: ArrayLike, r2: ArrayLike) -> tuple[Any, Any]:
    """Stone Soup's transition and measurement models of independent constant-velocity axes.

    Parameters
    ----------
    q : (n,) array_like
        ``noise_diff_coeff`` of each axis' ``ConstantVelocity`` (pftrack's `q`).
    r2 : (n,) array_like
        Variance of each axis' position measurement.

    Returns
    -------
    transition, measurement
        ``CombinedLinearGaussianTransitionModel`` over the state ``(p_1, v_1, p_2, v_2, ...)``
        and ``LinearGaussian`` reading the positions.
    """
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel,
        ConstantVelocity,
    )

    qq, rr = np.atleast_1d(np.asarray(q, float)), np.atleast_1d(np.asarray(r2, float))
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(float(v)) for v in qq])
    measurement = LinearGaussian(
        ndim_state=2 * len(qq), mapping=tuple(range(0, 2 * len(qq), 2)), noise_covar=np.diag(rr)
    )
    return transition, measurement


def stonesoup_track(
    z: ArrayLike,
    has: ArrayLike,
    q: ArrayLike,
    r2: ArrayLike,
    *,
    velocity_sd: float,
    update_first: bool,
    missed: str = "skip",
) -> tuple[Any, Any]:
    """Kalman-filter one track with Stone Soup: the filtered ``Track`` and the transition model.

    The arguments are :func:`pftrack.kalman.rts_smooth`'s (`has` one flag per frame). Frame 0
    is the prior ``N([z_0, 0], diag(r2, velocity_sd²))``, kept as a ``GaussianStatePrediction``
    so that the smoother smooths it too (it leaves a plain ``GaussianState`` first state as it
    is), and updated with ``z_0`` when `update_first`. Then each frame with a measurement is
    ``KalmanPredictor.predict`` from the last state, then ``KalmanUpdater.update``.

    `missed` says what a frame without a measurement adds to the track: ``"skip"`` nothing (the
    next prediction spans the hole, ``dt`` > 1), ``"predict"`` its prediction, as Stone Soup's
    ``MultiTargetTracker`` appends a missed detection's prediction. ``KalmanSmoother`` is exact
    only on the first: it replaces each state by its smoothed copy as it goes back and then
    reads a ``Prediction`` state's own (now smoothed) mean and covariance as the prediction of
    that frame, so the correction through a missed frame is zero (Stone Soup issue #178,
    "Resolve handling on non-update states in smoother", open).
    """
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.types.detection import Detection
    from stonesoup.types.hypothesis import SingleHypothesis
    from stonesoup.types.prediction import GaussianStatePrediction
    from stonesoup.types.track import Track
    from stonesoup.updater.kalman import KalmanUpdater

    zz, hh = np.asarray(z, dtype=np.float64), np.asarray(has, dtype=bool)
    if hh.ndim != 1 or len(hh) != len(zz) or not hh[0]:
        raise ValueError("stonesoup_track: has must be (T,) with has[0] True")
    if missed not in ("skip", "predict"):
        raise ValueError(f"stonesoup_track: missed is {missed!r}, expected 'skip' or 'predict'")
    transition, measurement = cv_models(q, r2)
    predictor, updater = KalmanPredictor(transition), KalmanUpdater(measurement)
    n = zz.shape[1]
    mean = np.zeros(2 * n)
    mean[0::2] = zz[0]
    var = np.empty(2 * n)
    var[0::2], var[1::2] = np.asarray(r2, float), velocity_sd**2
    state = GaussianStatePrediction(mean.reshape(-1, 1), np.diag(var), timestamp=at(0))
    if update_first:
        det = Detection(zz[0].reshape(-1, 1), timestamp=at(0), measurement_model=measurement)
        state = updater.update(SingleHypothesis(state, det))
    track = Track([state])
    for t in range(1, len(zz)):
        if hh[t]:
            pred = predictor.predict(state, timestamp=at(t))
            det = Detection(zz[t].reshape(-1, 1), timestamp=at(t), measurement_model=measurement)
            state = updater.update(SingleHypothesis(pred, det))
            track.append(state)
        elif missed == "predict":
            state = predictor.predict(state, timestamp=at(t))
            track.append(state)
    return track, transition


def stonesoup_rts_smooth(
    z: ArrayLike,
    has: ArrayLike,
    q: ArrayLike,
    r2: ArrayLike,
    *,
    velocity_sd: float,
    update_first: bool,
    missed: str = "skip",
) -> F64:
    """:func:`pftrack.kalman.rts_smooth` done by Stone Soup: filter, then ``KalmanSmoother``.

    Stone Soup's Rauch-Tung-Striebel smoother is ``stonesoup.smoother.kalman.KalmanSmoother``.
    Returns the ``(T, n)`` smoothed positions; with ``missed="skip"`` (see
    :func:`stonesoup_track`) the frames without a measurement have no state and are NaN.
    """
    from stonesoup.smoother.kalman import KalmanSmoother

    track, transition = stonesoup_track(
        z, has, q, r2, velocity_sd=velocity_sd, update_first=update_first, missed=missed
    )
    smoothed = KalmanSmoother(transition).smooth(track)
    zz = np.asarray(z, dtype=np.float64)
    out: F64 = np.full(zz.shape, np.nan)
    for s in smoothed.states:
        t = round((s.timestamp - EPOCH).total_seconds())
        out[t] = np.asarray(s.state_vector, float)[0::2, 0]
    return out


def many_rts_smooth(
    tracks: Sequence[tuple[F64, Any]], q: ArrayLike, r2: ArrayLike, velocity_sd: float
) -> list[F64]:
    """:func:`stonesoup_rts_smooth` of every ``(z, has)`` in `tracks` (``update_first=False``)."""
    return [
        stonesoup_rts_smooth(z, h, q, r2, velocity_sd=velocity_sd, update_first=False)
        for z, h in tracks
    ]
