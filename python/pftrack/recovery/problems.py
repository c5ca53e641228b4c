"""Goal-directed problems built from the two segments around a gap.

Two problems (Oh & Jung 2015, sec. 3, and pftrack's variant):

``gdt`` (:func:`gdt_problem`)
    The paper's framework: a Kalman filter with the paper's A, Q, H, R
    (:class:`~pftrack.recovery.gdt.GdtModel`) runs over segment A and gives ``x_0``; the goal is
    the first point of segment B with ``H_T = [I 0]`` and ``Pi_T = R``; ``T`` is the frame
    difference. The path starts at the filter's state.
``gdt-bi`` (:func:`gdt_bi_problem`)
    The goal is the full state (position *and* velocity) estimated by a Kalman filter run
    backwards over segment B, with that filter's covariance as ``Pi_T`` (``H_T = I``); the model
    is :mod:`pftrack.kalman`'s constant velocity with white-noise acceleration, its noise levels
    estimated from the observed segments (:func:`~pftrack.recovery.noise.estimate_noise`). The
    path starts at ``E[x_0 | y_T]``.

:class:`GdtProblem` holds one such problem for the Python solver; :class:`SegmentModel` holds
what the C++ batch call (``_core.gdt_recover_batch``) needs to build and solve the problems of
many gaps at once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np
from numpy.typing import ArrayLike

import pftrack._core as _core
from pftrack._check import MAX_FRAME, integer
from pftrack._typing import F64
from pftrack.kalman import cv_transition_xy, wna_Q_xy
from pftrack.recovery.gdt import Form, GdtModel, GdtSolution, goal_directed_path
from pftrack.recovery.noise import NoiseEstimate, _estimate_noise
from pftrack.recovery.segments import (
    as_observed,
    contiguous_head,
    contiguous_tail,
    gap_ends,
    split_rows,
)

__all__ = ["GdtProblem", "Goal", "SegmentModel", "gdt_bi_problem", "gdt_problem"]

#: What the goal ``y_T`` is: segment B's first point, or the state of a backward Kalman filter.
Goal: TypeAlias = Literal["first_point", "backward_state"]

_PAPER = GdtModel()
#: Prior variance of the velocity when a ``gdt-bi`` Kalman filter starts ((px/frame)²).
_P_VELOCITY = 1e2
_J = np.diag([1.0, 1.0, -1.0, -1.0])  # reverses time: velocity changes sign


def _position_H() -> F64:  # noqa: N802 - the paper's name
    """``H = [I_2 0_2]``: the position of the state ``(x, y, vx, vy)``."""
    return np.hstack([np.eye(2), np.zeros((2, 2))])


@dataclass(frozen=True, eq=False)
class GdtProblem:
    """One goal-directed problem: the arguments of :func:`~pftrack.recovery.gdt.goal_directed_path`.

    Attributes
    ----------
    A, Q : (4, 4) ndarray
        Transition and process noise of the state ``(x, y, vx, vy)``.
    H_T : (m, 4) ndarray
        Goal measurement matrix.
    Pi_T : (m, m) ndarray
        Goal covariance.
    m0 : (4,) ndarray
        Mean of ``x_0`` (the Kalman filter's state at the end of segment A).
    Pi_0 : (4, 4) ndarray
        Covariance of ``x_0``.
    y_T : (m,) ndarray
        The goal.
    T : int
        Steps from the last frame of segment A to the first frame of segment B.
    """

    A: F64
    Q: F64
    H_T: F64
    Pi_T: F64
    m0: F64
    Pi_0: F64
    y_T: F64
    T: int

    def solve(self, *, form: Form = "general", start_conditioned: bool = True) -> GdtSolution:
        """Solve with :func:`~pftrack.recovery.gdt.goal_directed_path` (same keywords)."""
        return goal_directed_path(
            self.A,
            self.Q,
            self.H_T,
            self.Pi_T,
            self.m0,
            self.Pi_0,
            self.y_T,
            self.T,
            form=form,
            start_conditioned=start_conditioned,
        )


def _kf_init(seg: F64, r: Sequence[float], p_vel: float) -> tuple[F64, F64]:
    """Initial state of a Kalman filter over a run: first point, first difference as velocity."""
    m = np.array([seg[0, 1], seg[0, 2], 0.0, 0.0])
    if len(seg) > 1:
        m[2:] = seg[1, 1:3] - seg[0, 1:3]
    P = np.diag([r[0], r[1], p_vel, p_vel])
    return m, P


def _gap(seg_a: ArrayLike, seg_b: ArrayLike, history: object, fn: str) -> tuple[F64, F64, int]:
    """The segments around one gap and `history`, checked for `fn` (B after A, history >= 1).

    Was: taken as they came, so that lists failed with "list indices must be integers", an
    empty segment with an IndexError, NaN in the core's words, and a segment B before A gave a
    problem with a negative ``T``.
    """
    a = as_observed(seg_a, "seg_a", fn)
    b = as_observed(seg_b, "seg_b", fn)
    gap_ends(a, b, fn)
    return a, b, integer(history, f"{fn}: history", 1, MAX_FRAME)


def gdt_problem(seg_a: F64, seg_b: F64, model: GdtModel = _PAPER, history: int = 30) -> GdtProblem:
    """The paper's problem for one gap (``Pi_T = R``, ``H_T = [I 0]``, goal = B's first point).

    The Kalman filter runs over the last `history` points of segment A's final run of
    consecutive frames (the paper's noise levels give a filter whose memory is a few frames,
    so a longer history changes nothing measurable).

    Parameters
    ----------
    seg_a, seg_b : (k, 3+) array_like
        Rows ``(frame, x, y, ...)`` before and after the gap, as
        :func:`~pftrack.recovery.recover_gap` takes its segments.
    model : GdtModel
        The paper's A, Q, H, R.
    history : int
        Points of segment A the filter uses (>= 1).

    Raises
    ------
    TypeError
        Segments not of real numbers, `model` not a GdtModel, `history` not an int.
    ValueError
        A segment :func:`~pftrack.recovery.segments.as_segment` refuses, segment B not after
        segment A (was: taken, with a negative ``T``), `history` < 1.
    """
    fn = "gdt_problem"
    if not isinstance(model, GdtModel):
        raise TypeError(f"{fn}: model must be a GdtModel, got {type(model).__name__}")
    seg_a, seg_b, history = _gap(seg_a, seg_b, history, fn)
    tail = contiguous_tail(seg_a)[-history:]
    A, Q, H, R = model.A, model.Q, model.H, model.R
    m_init, P_init = _kf_init(tail, model.r, model.p_init_velocity)
    m0, P0 = _core.kalman_filter(np.ascontiguousarray(tail[:, 1:3]), A, Q, H, R, m_init, P_init)
    T = int(seg_b[0, 0] - seg_a[-1, 0])
    return GdtProblem(A, Q, H, R, m0, P0, np.ascontiguousarray(seg_b[0, 1:3]), T)


def gdt_bi_problem(
    seg_a: F64, seg_b: F64, noise: NoiseEstimate | None = None, history: int = 30
) -> GdtProblem:
    """Pftrack's two-sided problem: forward filter on A, backward filter on B, noise estimated.

    Parameters
    ----------
    seg_a, seg_b : (k, 3+) array_like
        Rows ``(frame, x, y, ...)`` before and after the gap, as
        :func:`~pftrack.recovery.recover_gap` takes its segments.
    noise : NoiseEstimate, optional
        Noise levels; default: :func:`~pftrack.recovery.noise.estimate_noise` of both segments.
    history : int
        Points of each segment's run next to the gap the filters use (>= 1).

    Raises
    ------
    TypeError, ValueError
        As :func:`gdt_problem`; `noise` not a NoiseEstimate (TypeError).
    """
    fn = "gdt_bi_problem"
    if noise is not None and not isinstance(noise, NoiseEstimate):
        raise TypeError(f"{fn}: noise must be a NoiseEstimate or None, got {type(noise).__name__}")
    seg_a, seg_b, history = _gap(seg_a, seg_b, history, fn)
    if noise is None:
        noise = _estimate_noise([seg_a, seg_b])
    A = cv_transition_xy(1.0)
    Q = wna_Q_xy(noise.q)
    H = _position_H()
    R = np.diag(noise.r)
    tail = contiguous_tail(seg_a)[-history:]
    m_init, P_init = _kf_init(tail, noise.r, _P_VELOCITY)
    m0, P0 = _core.kalman_filter(np.ascontiguousarray(tail[:, 1:3]), A, Q, H, R, m_init, P_init)
    head = contiguous_head(seg_b)[:history][::-1]
    mb_init, Pb_init = _kf_init(head, noise.r, _P_VELOCITY)
    mb, Pb = _core.kalman_filter(np.ascontiguousarray(head[:, 1:3]), A, Q, H, R, mb_init, Pb_init)
    y = _J @ mb
    Pi_T = _J @ Pb @ _J
    T = int(seg_b[0, 0] - seg_a[-1, 0])
    return GdtProblem(A, Q, np.eye(4), 0.5 * (Pi_T + Pi_T.T), m0, P0, y, T)


@dataclass(frozen=True, eq=False)
class SegmentModel:
    """What ``_core.gdt_recover_batch`` needs to build and solve the problem of every gap.

    Attributes
    ----------
    A, Q : (4, 4) ndarray
        Transition and process noise of the Kalman filters and of the goal-directed path.
    H, R : (2, 4), (2, 2) ndarray
        Position measurement and its covariance.
    p_init_velocity : float
        Prior variance of the velocity when a filter starts.
    goal : {"first_point", "backward_state"}
        The goal: segment B's first point (``Pi_T = R``) or the state of a Kalman filter run
        backwards over segment B (``Pi_T`` its covariance).
    start_conditioned : bool
        Start the path at ``E[x_0 | y_T]`` rather than at the forward filter's state.
    """

    A: F64
    Q: F64
    H: F64
    R: F64
    p_init_velocity: float
    goal: Goal
    start_conditioned: bool

    @classmethod
    def paper(cls, model: GdtModel = _PAPER) -> SegmentModel:
        """The ``gdt`` model: :func:`gdt_problem` for every gap."""
        return cls(model.A, model.Q, model.H, model.R, model.p_init_velocity, "first_point", False)

    @classmethod
    def two_sided(cls, noise: NoiseEstimate) -> SegmentModel:
        """The ``gdt-bi`` model with these noise levels: :func:`gdt_bi_problem` for every gap."""
        return cls(
            cv_transition_xy(1.0),
            wna_Q_xy(noise.q),
            _position_H(),
            np.diag(noise.r),
            _P_VELOCITY,
            "backward_state",
            True,
        )

    def recover(
        self, seg_a: Sequence[F64], seg_b: Sequence[F64], history: int | None = None
    ) -> list[F64]:
        """Positions inside every gap, in one C++ call (GIL released, O(T) per gap).

        Parameters
        ----------
        seg_a, seg_b : sequence of (k, 3+) ndarray of float64
            The segments before and after each gap (only ``frame, x, y`` are used).
        history : int, optional
            The filters use at most this many points of the run of consecutive frames next to
            the gap; default: the whole run.

        Returns
        -------
        list of (T_g - 1, 2) ndarray
            ``(x, y)`` of every frame inside each gap.
        """
        a_len = np.array([len(s) for s in seg_a], dtype=np.int32)
        b_len = np.array([len(s) for s in seg_b], dtype=np.int32)
        a = np.ascontiguousarray(np.concatenate(seg_a)[:, :3])
        b = np.ascontiguousarray(np.concatenate(seg_b)[:, :3])
        out = _core.gdt_recover_batch(
            a,
            a_len,
            b,
            b_len,
            self.A,
            self.Q,
            self.H,
            self.R,
            self.p_init_velocity,
            self.goal,
            2**31 - 1 if history is None else int(history),
            self.start_conditioned,
        )
        T = (b[np.cumsum(b_len) - b_len, 0] - a[np.cumsum(a_len) - 1, 0]).astype(np.int64)
        paths = split_rows(out, T - 1)
        check_finite_paths(paths, T, f"process noise up to {np.max(self.Q):.3g}")
        return paths


def check_finite_paths(paths: Sequence[F64], T: ArrayLike, cause: str) -> None:
    """Raise ValueError naming the first gap whose recovered path is not finite.

    A model's covariances grow with the gap (``q T^3``): noise levels that NoiseEstimate takes
    (any finite ``q``) can overflow over a long gap, which gave NaN paths without a word.
    """
    for k, p in enumerate(paths):
        if not np.isfinite(p).all():
            n = int(np.asarray(T)[k]) - 1
            raise ValueError(
                f"the goal-directed path of gap {k} ({n} missing frames) overflows: {cause} "
                "is too large for a gap this long (NoiseEstimate.q)"
            )
