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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pftrack._typing import F64

__all__ = [
    "EPOCH",
    "BoxTrackerSettings",
    "box_tracker",
    "cv_models",
    "stonesoup_rts_smooth",
    "stonesoup_track",
]

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


@dataclass(frozen=True)
class BoxTrackerSettings:
    """The settings of :func:`box_tracker`, in pixels and frames.

    Attributes
    ----------
    q_pos : float
        ``ConstantVelocity`` ``noise_diff_coeff`` of the box centre's x and y (px²/frame³).
    q_size : float
        ``RandomWalk`` ``noise_diff_coeff`` of the box's width and height (px²/frame).
    r_pos, r_size : float
        Measurement variance of the centre and of the size (px²).
    velocity_sd : float
        Prior standard deviation of a new track's velocity (px/frame).
    gate : float
        ``DistanceHypothesiser``'s ``missed_distance``: the largest Mahalanobis distance a
        track may be matched at.
    max_missed : int
        ``UpdateTimeStepsDeleter``'s ``time_steps_since_update``: a track without an update in
        this many frames is deleted.
    min_points : int
        ``MultiMeasurementInitiator``'s ``min_points``: updates before a track is confirmed.
    """

    q_pos: float = 1.0
    q_size: float = 1.0
    r_pos: float = 25.0
    r_size: float = 100.0
    velocity_sd: float = 5.0
    gate: float = 5.0
    max_missed: int = 5
    min_points: int = 3


def box_tracker(settings: BoxTrackerSettings) -> Callable[[int, F64], list[tuple[int, F64]]]:
    """A Stone Soup multi-target tracker of boxes, built as its tutorials build one.

    The state is ``(cx, vx, cy, vy, w, h)``: constant velocity on the centre, a random walk on
    the size (``CombinedLinearGaussianTransitionModel``); ``LinearGaussian`` measures
    ``(cx, cy, w, h)``; ``KalmanPredictor``, ``KalmanUpdater``;
    ``DistanceHypothesiser(Mahalanobis)`` + ``GNNWith2DAssignment``; ``UpdateTimeStepsDeleter``;
    ``MultiMeasurementInitiator`` (sharing the deleter and associator, as the tutorials do);
    ``MultiTargetTracker`` stepped by ``update_tracker``.

    Returns
    -------
    step(frame, boxes) -> [(id, (left, top, w, h)), ...]
        `boxes` is ``(k, >= 4)`` ``[left, top, w, h, ...]``; the tracks reported are those
        updated with a detection in this frame (a coasting track is not reported), with their
        filtered box. Ids count from 1 in order of first report.
    """
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.deleter.time import UpdateTimeStepsDeleter
    from stonesoup.hypothesiser.distance import DistanceHypothesiser
    from stonesoup.initiator.simple import MultiMeasurementInitiator
    from stonesoup.measures import Mahalanobis
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel,
        ConstantVelocity,
        RandomWalk,
    )
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.tracker.simple import MultiTargetTracker
    from stonesoup.types.detection import Detection
    from stonesoup.types.state import GaussianState
    from stonesoup.types.update import Update
    from stonesoup.updater.kalman import KalmanUpdater

    s = settings
    transition = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(s.q_pos), ConstantVelocity(s.q_pos), RandomWalk(s.q_size),
         RandomWalk(s.q_size)]
    )  # fmt: skip
    measurement = LinearGaussian(
        ndim_state=6,
        mapping=(0, 2, 4, 5),
        noise_covar=np.diag([s.r_pos, s.r_pos, s.r_size, s.r_size]),
    )
    predictor, updater = KalmanPredictor(transition), KalmanUpdater(measurement)
    hypothesiser = DistanceHypothesiser(
        predictor, updater, measure=Mahalanobis(), missed_distance=s.gate
    )
    associator = GNNWith2DAssignment(hypothesiser)
    deleter = UpdateTimeStepsDeleter(time_steps_since_update=s.max_missed)
    v2 = s.velocity_sd**2
    initiator = MultiMeasurementInitiator(
        prior_state=GaussianState(np.zeros((6, 1)), np.diag([0.0, v2, 0.0, v2, 0.0, 0.0])),
        measurement_model=measurement,
        deleter=deleter,
        data_associator=associator,
        updater=updater,
        min_points=s.min_points,
    )
    tracker = MultiTargetTracker(
        initiator=initiator,
        deleter=deleter,
        detector=None,
        data_associator=associator,
        updater=updater,
    )
    ids: dict[str, int] = {}

    def step(frame: int, boxes: F64) -> list[tuple[int, F64]]:
        when = at(frame)
        b = np.asarray(boxes, dtype=np.float64).reshape(-1, boxes.shape[-1] if len(boxes) else 4)
        dets = {
            Detection(
                np.array([[x + w / 2], [y + h / 2], [w], [h]]),
                timestamp=when,
                measurement_model=measurement,
            )
            for x, y, w, h in b[:, :4]
        }
        _, tracks = tracker.update_tracker(when, dets)
        out = []
        for track in tracks:
            state = track.state
            if isinstance(state, Update) and state.timestamp == when:
                cx, _, cy, _, w, h = np.asarray(state.state_vector, float)[:, 0]
                k = ids.setdefault(track.id, len(ids) + 1)
                out.append((k, np.array([cx - w / 2, cy - h / 2, w, h])))
        return sorted(out, key=lambda r: r[0])

    return step
