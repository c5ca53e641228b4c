"""Mathematical properties of the recovery methods, against references derived from the model.

``gdt-bi`` is checked against the posterior mean of the whole linear-Gaussian chain over both
segments and the gap (``tests/reference/bridge.py: two_sided_posterior``, assembled factor by
factor from the model and solved densely, with no goal-directed algebra and no Kalman filter),
and every method against the symmetries its equations have.
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.kalman import cv_transition_xy, wna_Q_xy
from pftrack.recovery import METHODS, goal_directed_path, recover_gap, recover_gaps
from pftrack.recovery.baselines import bspline, rts, rts_batch
from pftrack.recovery.gdt import GdtModel
from pftrack.recovery.noise import NoiseEstimate
from tests.recovery.test_bridge import problem
from tests.reference import bridge as ref
from tests.reference import splines

_H = np.hstack([np.eye(2), np.zeros((2, 2))])
_J = np.diag([1.0, 1.0, -1.0, -1.0])  # time reversal: the velocity changes sign
#: A Kalman filter's start in pftrack.recovery.problems: the first point (variance r), the
#: first difference as velocity (variance 100); the first point is then also measured.
_P_VELOCITY = 100.0


def _far_end_prior(z: np.ndarray, r: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The prior a filter from ``z[0]`` towards ``z[-1]`` puts on ``z[0]``'s state."""
    velocity = z[1] - z[0] if len(z) > 1 else np.zeros(2)  # one point: velocity 0
    return np.r_[z[0], velocity], np.diag([r[0], r[1], _P_VELOCITY, _P_VELOCITY])


def _pair(seed: int, T: int, na: int, nb: int, start: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
    """Two runs of consecutive frames around a gap of `T` frames (T - 1 missing), curved + noise."""
    rng = np.random.default_rng(seed)
    fa = np.arange(start, start + na)
    fb = np.arange(fa[-1] + T, fa[-1] + T + nb)
    f = np.r_[fa, fb]
    xy = np.column_stack([3 + 1.3 * f + 0.02 * f**2, 50 - 0.6 * f - 0.01 * f**2])
    xy += rng.normal(0.0, 0.7, xy.shape)
    return np.column_stack([fa, xy[:na]]), np.column_stack([fb, xy[na:]])


@pytest.mark.parametrize(
    ("T", "na", "nb"), [(12, 9, 7), (2, 9, 7), (2, 2, 2), (30, 2, 15), (6, 1, 1), (9, 6, 1)]
)
@pytest.mark.parametrize("seed", [0, 1])
def test_gdt_bi_is_the_posterior_mean_of_both_segments(T, na, nb, seed):
    """The forward filter over A, the backward filter over B as the goal and the goal-directed
    path are together the exact smoother of the whole window (the white-noise-acceleration
    model is its own time reversal), a gap of one missing frame (T = 2) included."""
    a, b = _pair(seed, T, na, nb)
    noise = NoiseEstimate(q=(0.05, 0.3), r=(0.5, 0.8))
    got = recover_gap(a, b, method="gdt-bi", noise=noise)
    m_b, P_b = _far_end_prior(b[::-1, 1:3], noise.r)  # B's filter runs backwards from its end
    means = ref.two_sided_posterior(
        a[:, 1:3],
        b[:, 1:3],
        T,
        cv_transition_xy(1.0),
        wna_Q_xy(noise.q),
        _H,
        np.diag(noise.r),
        _far_end_prior(a[:, 1:3], noise.r),
        (_J @ m_b, P_b),
    )
    assert got.shape == (T - 1, 2)
    np.testing.assert_allclose(got, means[na : na + T - 1, :2], rtol=0, atol=1e-9)


#: Methods whose equations are symmetric in time: the gap recovered on the time-reversed
#: track is the same path. (Not ``gdt``, the paper's one-sided filter; not ``rts``, whose
#: prior sits on the window's first point; not ``gdt-fixed``, see the test below.)
_TIME_SYMMETRIC = ("gdt-bi", "linear", "cubic", "bspline", "gsi")


@pytest.mark.parametrize("method", _TIME_SYMMETRIC)
@pytest.mark.parametrize("seed", [0, 1])
def test_time_symmetric_methods_recover_a_reversed_gap_reversed(method, seed):
    a, b = _pair(seed, T=15, na=35, nb=40)
    forward = recover_gap(a, b, method=method)
    # frame f -> 1000 - f: B comes first, A second, each with its rows in increasing frames
    ra, rb = (np.column_stack([1000.0 - s[::-1, 0], s[::-1, 1:]]) for s in (b, a))
    backward = recover_gap(ra, rb, method=method)[::-1]
    tol = 1e-4 if method == "gsi" else 1e-9  # gsi's RBF kernel matrix is ill-conditioned
    np.testing.assert_allclose(backward, forward, rtol=0, atol=tol)


@pytest.mark.parametrize("method", [m for m in METHODS if m != "auto"])
def test_swapping_x_and_y_swaps_the_path(method):
    """Every method treats the two axes alike: no axis is special in any of the models."""
    a, b = _pair(3, T=15, na=35, nb=40)
    got = recover_gap(a, b, method=method)
    swapped = recover_gap(a[:, [0, 2, 1]], b[:, [0, 2, 1]], method=method)
    np.testing.assert_allclose(swapped[:, ::-1], got, rtol=0, atol=1e-9)


def test_auto_swaps_with_the_axes_too():
    a, b = _pair(3, T=15, na=35, nb=40)
    pairs = [(a, b), _pair(4, T=9, na=30, nb=30, start=200.0)]
    got = recover_gaps(pairs, "auto")
    swapped = recover_gaps([(p[:, [0, 2, 1]], q[:, [0, 2, 1]]) for p, q in pairs], "auto")
    for g, s in zip(got, swapped, strict=True):
        np.testing.assert_allclose(s[:, ::-1], g, rtol=0, atol=1e-9)


@pytest.mark.parametrize("method", ["gdt", "gdt-bi", "gdt-fixed", "rts", "linear", "cubic"])
def test_mirroring_an_axis_mirrors_the_path(method):
    a, b = _pair(5, T=15, na=35, nb=40)
    got = recover_gap(a, b, method=method)
    flip = np.array([1.0, -1.0, 1.0])
    mirrored = recover_gap(a * flip, b * flip, method=method)
    np.testing.assert_allclose(mirrored * [-1.0, 1.0], got, rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("history", "na", "nb", "holes"),
    [(30, 20, 25, False), (30, 50, 45, True), (5, 12, 12, True), (30, 1, 1, False)],
)
def test_rts_is_the_posterior_mean_of_its_window(history, na, nb, holes):
    """``rts`` (and its batch) is the exact smoother of `history` points a side and the gap:
    prior ``N([z_0, 0], diag(r, 100))`` on the window's first state, which is then also
    measured, holes inside the segments included."""
    rng = np.random.default_rng(na + nb)
    fa = np.arange(10.0, 10 + na)
    fb = np.arange(fa[-1] + 9, fa[-1] + 9 + nb)
    if holes:
        fa, fb = np.delete(fa, [3, 4, 7]), np.delete(fb, [2, 5])
    a, b = (
        np.column_stack([f, 2 * f + rng.normal(0, 1, len(f)), -f + rng.normal(0, 1, len(f))])
        for f in (fa, fb)
    )
    q, r = 0.1, 1.0  # the baseline's fixed levels
    window = np.vstack([a[-history:], b[:history]])
    f0 = window[0, 0]
    means = ref.chain_posterior(
        int(window[-1, 0] - f0 + 1),
        [(int(row[0] - f0), row[1:3]) for row in window],
        cv_transition_xy(1.0),
        wna_Q_xy((q, q)),
        _H,
        np.diag([r, r]),
        [(0, np.r_[window[0, 1:3], 0.0, 0.0], np.diag([r, r, 100.0, 100.0]))],
    )
    gap = np.arange(a[-1, 0] + 1, b[0, 0]).astype(np.int64)
    expected = means[(gap - f0).astype(int), :2]
    np.testing.assert_allclose(rts(a, b, gap, history=history), expected, rtol=0, atol=1e-9)
    batch = rts_batch([(a, b)], history=history)[0]
    np.testing.assert_allclose(batch, expected, rtol=0, atol=1e-9)


def _curve(na: int, nb: int, T: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    fa = np.arange(0.0, na)
    fb = np.arange(na - 1 + T, na - 1 + T + nb)
    f = np.r_[fa, fb]
    xy = np.column_stack([3 * f + 5 * np.sin(f / 4), -f + 0.05 * f**2])
    xy += rng.normal(0, 1, xy.shape)
    frames = np.arange(fa[-1] + 1, fb[0]).astype(np.int64)
    return np.column_stack([fa, xy[:na]]), np.column_stack([fb, xy[na:]]), frames


@pytest.mark.parametrize(("na", "nb", "T"), [(20, 20, 10), (12, 12, 5), (30, 9, 17), (5, 4, 3)])
def test_bspline_is_the_documented_weighted_least_squares_fit(na, nb, T):
    """Against a Cox-de Boor basis and the weighted normal equations (no SciPy): the residual
    of a point `d` frames from the gap is multiplied by ``1 / (1 + d / 5)`` (SciPy's ``w``),
    so its square weighs ``1 / (1 + d / 5)²``."""
    a, b, frames = _curve(na, nb, T, seed=na + T)
    np.testing.assert_allclose(
        bspline(a, b, frames), splines.weighted_bspline(a, b, frames), rtol=0, atol=1e-9
    )


@pytest.mark.parametrize("method", ["cubic", "bspline"])
def test_splines_recover_a_cubic_track_exactly(method):
    """A cubic polynomial lies in both spline spaces: the interpolating not-a-knot spline and
    the least-squares fit both reproduce it, whatever the weights and knots."""
    fa, fb = np.arange(0.0, 20), np.arange(31.0, 50)
    f = np.r_[fa, fb]
    xy = np.column_stack([2 + 0.5 * f - 0.03 * f**2 + 1e-3 * f**3, 7 - 0.2 * f + 2e-4 * f**3])
    a, b = np.column_stack([fa, xy[:20]]), np.column_stack([fb, xy[20:]])
    g = np.arange(20.0, 31)
    truth = np.column_stack([2 + 0.5 * g - 0.03 * g**2 + 1e-3 * g**3, 7 - 0.2 * g + 2e-4 * g**3])
    np.testing.assert_allclose(recover_gap(a, b, method=method), truth, rtol=0, atol=1e-9)


@pytest.mark.parametrize("T", [1, 4, 9])
@pytest.mark.parametrize("start_conditioned", [False, True])
@pytest.mark.parametrize("form", ["general", "invertible", "pseudo_inverse"])
def test_state_covariances_propagate_the_linear_drift(T, start_conditioned, form):
    """The drift is linear, ``u_t = K_t (y_T - H Phi(T, t-1) x_{t-1})``, so the state's
    covariance obeys ``C_t = (A_t - K_t H Phi(T, t-1)) C_{t-1} (...)^T + eps_t`` from
    ``C_0 = cov(x_0 | y_T)``, or ``Pi_0`` when the path starts at ``m0`` (not covered by the
    joint conditional, which holds for a conditioned start only)."""
    rng = np.random.default_rng(T)
    p = problem(rng, n=4, m=4, T=T, varying=True)
    got = goal_directed_path(**p, form=form, start_conditioned=start_conditioned)
    A, Q, H = list(p["A"]), list(p["Q"]), p["H_T"]
    C = got.x0_cov if start_conditioned else p["Pi_0"]
    expected = [C]
    for t in range(1, T + 1):
        M = p["Pi_T"] + H @ ref.S_sum(A, Q, T, t) @ H.T
        K = Q[t - 1] @ ref.phi(A, T, t).T @ H.T @ np.linalg.inv(M)
        F = A[t - 1] - K @ H @ ref.phi(A, T, t - 1)
        C = F @ C @ F.T + (Q[t - 1] - K @ H @ ref.phi(A, T, t) @ Q[t - 1])
        expected.append(C)
    np.testing.assert_allclose(got.cov, np.array(expected), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gdt_fixed_is_the_posterior_of_a_chain_reversed_inside_b(seed):
    """``gdt-fixed``'s backward filter runs the paper's ``A``, ``Q`` on B's points in reverse
    order: in forward time, B's steps have the noise ``A J Q J A^T``, which for the paper's
    diagonal ``Q`` is not ``Q`` (the white-noise-acceleration ``Q`` of ``gdt-bi`` is its own
    reversal). So ``gdt-fixed`` is the exact posterior of that chain, not of the paper's
    model over the whole window, and not symmetric in time (docs/recovery.md, methods)."""
    T, na, nb = 12, 9, 7
    a, b = _pair(seed, T, na, nb)
    paper = GdtModel()
    A, Q, r = paper.A, paper.Q, paper.r
    m_b, P_b = _far_end_prior(b[::-1, 1:3], r)
    N = na + T - 1 + nb
    into_b = na + T - 1  # the step to B's first frame is the gap's last: Q
    chain = np.array([Q if k < into_b else A @ _J @ Q @ _J @ A.T for k in range(N - 1)])
    posterior = {
        name: ref.two_sided_posterior(
            a[:, 1:3],
            b[:, 1:3],
            T,
            A,
            q,
            _H,
            paper.R,
            _far_end_prior(a[:, 1:3], r),
            (_J @ m_b, P_b),
        )[na : na + T - 1, :2]
        for name, q in (("reversed inside B", chain), ("paper's model", Q))
    }
    got = recover_gap(a, b, method="gdt-fixed")
    np.testing.assert_allclose(got, posterior["reversed inside B"], rtol=0, atol=1e-8)
    assert np.abs(got - posterior["paper's model"]).max() > 0.02  # 0.04-0.32 px here
