"""The goal-directed state equation (Oh & Jung 2015, eqs. 7-18) and its model defaults.

The heavy lifting is in C++ (``cpp/include/pftrack/bridge.hpp``); this module checks Python-side
arguments, converts them and documents the maths.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np
from numpy.typing import ArrayLike

import pftrack._core as _core
from pftrack._check import MAX_FRAME, first_at, flag, generator, number, option, real_array
from pftrack._typing import F64, RngLike
from pftrack.kalman import cv_transition_xy

__all__ = ["Form", "GdtModel", "GdtSolution", "goal_directed_path", "sample_goal_directed_paths"]

#: Which of the paper's equivalent forms solves the problem.
Form: TypeAlias = Literal["general", "invertible", "pseudo_inverse"]
_FORMS = ("general", "invertible", "pseudo_inverse")


@dataclass(frozen=True)
class GdtModel:
    """The paper's model (eqs. 19-22), as documented defaults.

    Attributes
    ----------
    dt : float
        Frame interval in frames (1.0): pftrack measures time in frames, so velocities are
        pixels per frame (the paper does not say which unit it used).
    q : tuple of 4 float
        Diagonal of the process noise ``Q`` (px², px², (px/frame)², (px/frame)²), eq. (20).
    r : tuple of 2 float
        Diagonal of the measurement noise ``R`` (px²), eq. (22); also the goal's ``Pi_T``.
    p_init_velocity : float
        Prior variance of the velocity when the Kalman filter over segment A starts (the paper
        does not give one; the position starts at the first point with variance ``r``).
    """

    dt: float = 1.0
    q: tuple[float, float, float, float] = (1e-6, 1e-6, 1e-4, 1e-4)
    r: tuple[float, float] = (1e-6, 1e-6)
    p_init_velocity: float = 1e2

    def __post_init__(self) -> None:
        """Refuse settings that are not finite numbers (were taken: a DataFrame for `dt`).

        `q` and `r` may be any sequence (a list, a (4,) array) of 4 and 2 numbers, kept as a
        tuple of floats (a frozen model stays hashable and comparable).

        Raises
        ------
        TypeError
            A setting that is not a number (`q`, `r`: not real numbers).
        ValueError
            NaN or infinite; `q` or `r` not of 4 or 2 values; a value out of its range: `dt`
            > 0, `q` and `p_init_velocity` >= 0 (variances), `r` > 0 (``R`` is inverted), and
            `p_init_velocity` > 0 where a velocity variance of `q` is 0. Were
            taken: a negative variance failed at the first gap in ``kalman_filter``, naming no
            setting, and a negative `dt` ran the model backwards, silently.
        """
        for name, strict in (("dt", True), ("p_init_velocity", False)):
            x = number(getattr(self, name), f"GdtModel: {name}")
            if not (x > 0 if strict else x >= 0):
                raise ValueError(f"GdtModel: {name} is {x}, expected {'>' if strict else '>='} 0")
        for name, n, strict in (("q", 4, False), ("r", 2, True)):
            v = real_array(getattr(self, name), f"GdtModel: {name}", booleans=False)
            if v.shape != (n,):
                raise ValueError(f"GdtModel: {name} has shape {v.shape}, expected ({n},)")
            if not np.isfinite(v).all():
                raise ValueError(f"GdtModel: {name} is {tuple(v.tolist())}, expected finite values")
            if not (v > 0 if strict else v >= 0).all():
                raise ValueError(
                    f"GdtModel: {name} is {tuple(v.tolist())}, expected variances "
                    f"{'> 0' if strict else '>= 0'}"
                )
            object.__setattr__(self, name, tuple(float(x) for x in v))
        if self.p_init_velocity == 0 and min(self.q[2:]) == 0:  # no velocity noise anywhere
            k = 2 if self.q[2] == 0 else 3
            raise ValueError(
                f"GdtModel: p_init_velocity is 0 and q[{k}] (a velocity variance) is 0: the "
                "segment filter's covariance would be singular; give one of them > 0"
            )

    @property
    def A(self) -> F64:  # noqa: N802 - the paper's name
        """Constant-velocity transition, eq. (19) (:func:`pftrack.kalman.cv_transition_xy`)."""
        return cv_transition_xy(self.dt)

    @property
    def Q(self) -> F64:  # noqa: N802
        """Process noise, eq. (20)."""
        return np.diag(np.asarray(self.q, dtype=np.float64))

    @property
    def H(self) -> F64:  # noqa: N802
        """``[I_2 0_2]``, eq. (21)."""
        return np.hstack([np.eye(2), np.zeros((2, 2))])

    @property
    def R(self) -> F64:  # noqa: N802
        """Measurement noise, eq. (22)."""
        return np.diag(np.asarray(self.r, dtype=np.float64))


@dataclass(frozen=True)
class GdtSolution:
    """Result of :func:`goal_directed_path`.

    Attributes
    ----------
    path : (T+1, n) ndarray
        Mean states ``x_0 .. x_T``.
    eps : (T, n, n) ndarray
        Covariances ``eps_t = cov(w_t | x_{t-1}, y_T)``, t = 1..T (eqs. 8, 12).
    cov : (T+1, n, n) ndarray
        Covariances of the states along the path.
    x0_mean : (n,) ndarray
        ``E[x_0 | y_T]`` (eqs. 10, 15, 18).
    x0_cov : (n, n) ndarray
        ``cov(x_0 | y_T)`` (eqs. 9, 14).
    """

    path: F64
    eps: F64
    cov: F64
    x0_mean: F64
    x0_cov: F64


def _count(value: object, name: str, fn: str) -> int:
    """`value`, argument `name` of `fn` (``T``, ``n_samples``), as an int in ``[1, MAX_FRAME]``.

    ``MAX_FRAME`` is ``2**31 - 1``: the core takes a 32-bit int.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{fn}: {name} must be an int, got {type(value).__name__}")
    if not 0 < value <= MAX_FRAME:
        raise ValueError(f"{fn}: {name} is {value}, expected an int in [1, {MAX_FRAME}]")
    return int(value)


def _check_form(form: str, fn: str) -> None:
    option(form, f"{fn}: form", _FORMS)
    if form not in _FORMS:
        raise ValueError(f"{fn}: form is {form!r}, expected one of {_FORMS}")


def _model_arrays(
    fn: str,
    A: ArrayLike,  # noqa: N803 - the paper's names
    Q: ArrayLike,  # noqa: N803
    H_T: ArrayLike,  # noqa: N803
    Pi_T: ArrayLike,  # noqa: N803
    m0: ArrayLike,
    Pi_0: ArrayLike,  # noqa: N803
    y_T: ArrayLike,  # noqa: N803
    T: int,  # noqa: N803
) -> tuple[F64, F64, F64, F64, F64, F64, F64]:
    """The model as the float64 arrays ``gdt_solve``/``gdt_sample`` take (A, Q stacked per step).

    The state size n is A's; every other shape is checked against it (and the goal's size
    m, ``len(y_T)``) here, so that a message names the argument that does not fit and `fn`
    (the core would blame ``A[0]`` for a short `m0`, under its own name).

    Raises
    ------
    TypeError
        An argument that is not real numbers.
    ValueError
        A shape that does not fit n or m, more than one but not T matrices in `A` or `Q`, a
        value that is not finite.
    """
    a = _real(A, "A", fn)
    if a.ndim not in (2, 3) or a.shape[-1] != a.shape[-2] or a.shape[-1] == 0:
        raise ValueError(f"{fn}: A has shape {a.shape}, expected (n, n) or (T, n, n) with n >= 1")
    n = a.shape[-1]
    size = f"(A is {n}x{n})"
    q = _real(Q, "Q", fn)
    if q.ndim not in (2, 3) or q.shape[-2:] != (n, n):
        raise ValueError(
            f"{fn}: Q has shape {q.shape}, expected ({n}, {n}) or (T, {n}, {n}) {size}"
        )
    for name, stack in (("A", a), ("Q", q)):
        if stack.ndim == 3 and len(stack) not in (1, T):
            raise ValueError(f"{fn}: {name} holds {len(stack)} matrices, expected 1 or T = {T}")
    m0_ = _real(m0, "m0", fn)
    if m0_.shape != (n,):
        got = f"{m0_.size} entries" if m0_.ndim == 1 else f"shape {m0_.shape}"
        raise ValueError(f"{fn}: m0 has {got}, expected {n} {size}")
    pi_0 = np.atleast_2d(_real(Pi_0, "Pi_0", fn))
    if pi_0.shape != (n, n):
        raise ValueError(f"{fn}: Pi_0 has shape {pi_0.shape}, expected ({n}, {n}) {size}")
    y = _real(y_T, "y_T", fn)
    if y.ndim != 1 or y.size == 0:
        raise ValueError(f"{fn}: y_T has shape {y.shape}, expected (m,) with m >= 1 (the goal)")
    m = y.size
    h = np.atleast_2d(_real(H_T, "H_T", fn))
    if h.shape != (m, n):
        raise ValueError(
            f"{fn}: H_T has shape {h.shape}, expected ({m}, {n}) (y_T has {m} entries, A is "
            f"{n}x{n})"
        )
    pi_t = np.atleast_2d(_real(Pi_T, "Pi_T", fn))
    if pi_t.shape != (m, m):
        raise ValueError(
            f"{fn}: Pi_T has shape {pi_t.shape}, expected ({m}, {m}) (y_T has {m} entries)"
        )
    arrays = {"A": a, "Q": q, "H_T": h, "Pi_T": pi_t, "m0": m0_, "Pi_0": pi_0, "y_T": y}
    for name, arr in arrays.items():
        bad = ~np.isfinite(arr)
        if bad.any():
            k, at = first_at(bad)
            raise ValueError(f"{fn}: {name}{at} is {arr[k]}, expected finite")
    return (np.ascontiguousarray(a), np.ascontiguousarray(q), h, pi_t, m0_, pi_0, y)


def _real(a: ArrayLike, name: str, fn: str) -> F64:
    """`a` as float64, refusing complex numbers (cast with a warning) and text."""
    return real_array(a, f"{fn}: {name}")


def _core_error(error: ValueError, core: str, fn: str) -> ValueError:
    """The core's refusal (a non-PSD ``Q``, a singular ``H``, ...) under the name `fn`.

    The core names its own function (``gdt_solve``) and the goal's matrix ``H``; the caller
    knows `fn` and ``H_T``.
    """
    message = str(error)
    if not message.startswith(f"{core}: "):
        return error
    return ValueError(f"{fn}: " + re.sub(r"\bH\b", "H_T", message[len(core) + 2 :]))


def goal_directed_path(
    A: ArrayLike,  # noqa: N803 - the paper's names
    Q: ArrayLike,  # noqa: N803
    H_T: ArrayLike,  # noqa: N803
    Pi_T: ArrayLike,  # noqa: N803
    m0: ArrayLike,
    Pi_0: ArrayLike,  # noqa: N803
    y_T: ArrayLike,  # noqa: N803
    T: int,  # noqa: N803
    *,
    form: Form = "general",
    start_conditioned: bool = True,
) -> GdtSolution:
    """Mean path and covariances of the goal-directed state equation.

    ``x_t = A_t x_{t-1} + u_t + eps_t`` with drift ``u_t = E[w_t | x_{t-1}, y_T]`` and noise
    covariance ``eps_t = cov(w_t | x_{t-1}, y_T)``, for a goal ``y_T = H_T x_T + v_T``,
    ``v_T ~ N(0, Pi_T)`` and an initial state ``x_0 ~ N(m0, Pi_0)``.

    Parameters
    ----------
    A, Q : (n, n) or (T, n, n) array_like
        Transition and process noise, constant or one per step (``A[t-1] = A_t``).
    H_T : (m, n) array_like
        Goal measurement matrix.
    Pi_T : (m, m) array_like
        Goal covariance (symmetric positive definite).
    m0 : (n,) array_like
        Initial mean.
    Pi_0 : (n, n) array_like
        Initial covariance (symmetric positive definite).
    y_T : (m,) array_like
        The goal.
    T : int
        Steps from ``x_0`` to the goal's state ``x_T``, in [1, 2**31 - 1].
    form : {"general", "invertible", "pseudo_inverse"}
        Eqs. 7-10 (any ``H_T``), 11-15 (square invertible ``H_T``) or 16-18 (``H_T`` of full
        column rank; the paper's eq. 17 reads ``H^+ Pi_T H^+T`` with ``H^+ = (H^T H)^-1 H^T``,
        which equals the general form when ``Pi_T`` is a multiple of the identity or ``H_T`` is
        square). The latter two also need invertible ``A_t``.
    start_conditioned : bool
        Start the path at ``E[x_0 | y_T]`` (then ``path[t] = E[x_t | y_T]``), else at ``m0``
        (the paper's framework, where ``x_0`` is the Kalman estimate at the end of segment A).

    Returns
    -------
    GdtSolution

    Raises
    ------
    TypeError
        `T` not an int, `start_conditioned` not a bool (``"no"`` would be True).
    ValueError
        `T` not in [1, 2**31 - 1]; a shape that does not fit the state size n of `A` (or the
        goal's size, ``len(y_T)``), named with it (``m0 has 3 entries, expected 4 (A is
        4x4)``); NaN or infinities, non-symmetric or non-PSD ``Q``, singular or non-PD
        ``Pi_0``/``Pi_T``, ``H_T`` unfit for `form`, a model whose path is not finite.

    References
    ----------
    .. [1] Oh, S. H. & Jung, S. K. (2015). Trajectory recovery using goal-directed tracking.
       Journal of Korea Multimedia Society 18(5).
    .. [2] Srinivasan, L. et al. (2006). A state-space analysis for reconstruction of
       goal-directed movements using neural signals. Neural Computation 18(10).

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack import goal_directed_path
    >>> eye = np.eye(2)  # a random walk in (x, y) from near (0, 0) to the goal (4, 2)
    >>> s = goal_directed_path(eye, 0.1 * eye, eye, 0.01 * eye, [0, 0], 0.01 * eye, [4, 2], 4)
    >>> s.path.round(3)
    array([[0.095, 0.048],
           [1.048, 0.524],
           [2.   , 1.   ],
           [2.952, 1.476],
           [3.905, 1.952]])
    >>> s.eps.shape, s.cov.shape
    ((4, 2, 2), (5, 2, 2))
    """
    fn = "goal_directed_path"
    T = _count(T, "T", fn)
    _check_form(form, fn)
    conditioned = flag(start_conditioned, f"{fn}: start_conditioned")
    arrays = _model_arrays(fn, A, Q, H_T, Pi_T, m0, Pi_0, y_T, T)
    try:
        r = _core.gdt_solve(*arrays, T, form, conditioned)
    except ValueError as e:
        raise _core_error(e, "gdt_solve", fn) from None
    return GdtSolution(r["path"], r["eps"], r["cov"], r["x0_mean"], r["x0_cov"])


def sample_goal_directed_paths(
    A: ArrayLike,  # noqa: N803
    Q: ArrayLike,  # noqa: N803
    H_T: ArrayLike,  # noqa: N803
    Pi_T: ArrayLike,  # noqa: N803
    m0: ArrayLike,
    Pi_0: ArrayLike,  # noqa: N803
    y_T: ArrayLike,  # noqa: N803
    T: int,  # noqa: N803
    n_samples: int,
    *,
    rng: RngLike = None,
    form: Form = "general",
    start_conditioned: bool = True,
) -> F64:
    """Random paths ``(n_samples, T+1, n)`` of the goal-directed process with ``eps_t`` noise.

    Arguments as :func:`goal_directed_path`, and its errors (named
    ``sample_goal_directed_paths``); `n_samples` is an int in [1, 2**31 - 1]. `rng` gives one
    63-bit seed for the C++ counter-based generator, so results do not depend on thread count.

    The paths are distributed as :func:`goal_directed_path` with the same `start_conditioned`
    describes them (mean ``path[t]``, covariance ``cov[t]``): ``x_0 ~ N(E[x_0 | y_T],
    cov(x_0 | y_T))``, or ``x_0 ~ N(m0, Pi_0)`` when not `start_conditioned`, then
    ``x_t = A_t x_{t-1} + u_t + eps_t``.
    """
    fn = "sample_goal_directed_paths"
    T = _count(T, "T", fn)
    _check_form(form, fn)
    n_samples = _count(n_samples, "n_samples", fn)
    conditioned = flag(start_conditioned, f"{fn}: start_conditioned")
    seed = int(generator(rng, f"{fn}: rng").integers(2**63))
    arrays = _model_arrays(fn, A, Q, H_T, Pi_T, m0, Pi_0, y_T, T)
    try:
        out: F64 = _core.gdt_sample(*arrays, T, n_samples, seed, form, conditioned)
    except ValueError as e:
        raise _core_error(e, "gdt_sample", fn) from None
    return out
