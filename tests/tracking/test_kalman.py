"""pftrack.kalman against NumPy references: a dense matrix Kalman/RTS loop, the joint Gaussian."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.kalman import (
    cv_predict,
    cv_transition,
    cv_transition_xy,
    cv_update,
    cv_update_where,
    rts_smooth,
    wna_Q,
    wna_Q_xy,
)
from tests.reference.smoothing import dense_kalman_rts, rts_smooth_numpy, wna_posterior_mean


def _problem(
    seed: int, steps: int, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    z = np.cumsum(rng.normal(1.0, 2.0, (steps, n)), axis=0)
    has = rng.random(steps) < 0.7
    has[0] = True
    z[~has] = np.nan  # never read
    return z, has, rng.uniform(0.01, 2.0, n), rng.uniform(0.1, 4.0, n)


def test_matrices():
    np.testing.assert_array_equal(cv_transition(2.0), [[1, 2], [0, 1]])
    np.testing.assert_allclose(wna_Q(0.6, 2.0), 0.6 * np.array([[8 / 3, 2], [2, 2]]), rtol=1e-15)
    F, Q = cv_transition_xy(1.5), wna_Q_xy((0.2, 0.7), 1.5)
    for axis, q in enumerate((0.2, 0.7)):
        idx = np.ix_([axis, axis + 2], [axis, axis + 2])
        np.testing.assert_array_equal(F[idx], cv_transition(1.5))
        np.testing.assert_array_equal(Q[idx], wna_Q(q, 1.5))
    assert np.count_nonzero(Q) == 8 and np.count_nonzero(F) == 6
    with pytest.raises(ValueError, match="expected 2"):
        wna_Q_xy((1.0, 2.0, 3.0))


def test_predict_update_match_matrix_form():
    rng = np.random.default_rng(4)
    F = cv_transition()
    for _ in range(20):
        L = rng.normal(size=(2, 2))
        P = L @ L.T + 0.1 * np.eye(2)
        m = rng.normal(size=2)
        q, r2, z = rng.uniform(0.01, 3), rng.uniform(0.1, 3), rng.normal()
        (p, v), (a, b, c) = cv_predict((m[0], m[1]), (P[0, 0], P[0, 1], P[1, 1]), q)
        Pp = F @ P @ F.T + wna_Q(q)
        np.testing.assert_allclose([p, v], F @ m, rtol=1e-13)
        np.testing.assert_allclose([[a, b], [b, c]], Pp, rtol=1e-12)
        (p2, v2), (a2, b2, c2) = cv_update((p, v), (a, b, c), z, r2)
        K = Pp[:, 0] / (Pp[0, 0] + r2)
        np.testing.assert_allclose([p2, v2], F @ m + K * (z - p), rtol=1e-12)
        np.testing.assert_allclose(
            [[a2, b2], [b2, c2]], (np.eye(2) - np.outer(K, [1, 0])) @ Pp, rtol=1e-12, atol=1e-14
        )


def test_predict_over_dt_frames_matches_matrix_form():
    rng = np.random.default_rng(5)
    for dt in (0.0, 0.5, 2.0, 7.0):
        F = cv_transition(dt)
        L = rng.normal(size=(2, 2))
        P = L @ L.T + 0.1 * np.eye(2)
        m = rng.normal(size=2)
        q = rng.uniform(0.01, 3)
        (p, v), (a, b, c) = cv_predict((m[0], m[1]), (P[0, 0], P[0, 1], P[1, 1]), q, dt)
        np.testing.assert_allclose([p, v], F @ m, rtol=1e-13)
        np.testing.assert_allclose([[a, b], [b, c]], F @ P @ F.T + wna_Q(q, dt), rtol=1e-12)


def test_predict_one_frame_is_the_one_frame_formula_bit_for_bit():
    rng = np.random.default_rng(6)
    m0, m1, p00, p11, q = rng.normal(size=(5, 50))
    p00, p11, q = abs(p00), abs(p11), abs(q)  # variances and noise: negative ones are refused
    p01 = rng.uniform(-1, 1, 50) * np.sqrt(p00 * p11)  # and covariances that are not PSD
    (p, v), (a, b, c) = cv_predict((m0, m1), (p00, p01, p11), q)
    assert np.array_equal(p, m0 + m1) and np.array_equal(v, m1)
    assert np.array_equal(a, p00 + 2 * p01 + p11 + q / 3.0)
    assert np.array_equal(b, p01 + p11 + q / 2) and np.array_equal(c, p11 + q)


def test_predict_update_vectorised_over_axes():
    """Arrays over axes give what each axis gives alone (the tracker shares one covariance)."""
    m = (np.array([1.0, -2.0]), np.array([0.5, 0.25]))
    cov = (2.0, 0.3, 1.5)  # floats: one covariance for both axes
    (p, v), c = cv_update(*cv_predict(m, cov, 0.4), np.array([2.0, -1.0]), 0.8)
    for k in range(2):
        (pk, vk), ck = cv_update(
            *cv_predict((m[0][k], m[1][k]), cov, 0.4),
            [2.0, -1.0][k],
            0.8,
        )
        assert (p[k], v[k]) == (pk, vk) and c == ck


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), steps=st.integers(1, 40), update_first=st.booleans())
def test_rts_matches_dense_matrix_loop(seed, steps, update_first):
    """Two axes at once against the (x, y, vx, vy) 4x4 matrix filter (the rts baseline's form)."""
    z, has, q, r2 = _problem(seed, steps, 2)
    vsd = 10.0
    got = rts_smooth(z, has, q, r2, velocity_sd=vsd, update_first=update_first)
    F = cv_transition_xy()
    Q = wna_Q_xy(q)
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    m0 = np.r_[z[0], 0.0, 0.0]
    P0 = np.diag([r2[0], r2[1], vsd**2, vsd**2])
    _, sm, _ = dense_kalman_rts(z, has, F, Q, H, np.diag(r2), m0, P0, update_first)
    np.testing.assert_allclose(got, sm[:, :2], rtol=1e-9, atol=1e-8)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), steps=st.integers(1, 30), update_first=st.booleans())
def test_rts_is_the_posterior_mean(seed, steps, update_first):
    """The smoother's means are the joint Gaussian's conditional means (continuous model)."""
    z, has, q, r2 = _problem(seed, steps, 3)
    got = rts_smooth(z, has, q, r2, velocity_sd=5.0, update_first=update_first)
    want = np.column_stack(
        [wna_posterior_mean(z[:, k], has, q[k], r2[k], 5.0, update_first) for k in range(3)]
    )
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-6)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), steps=st.integers(1, 30), update_first=st.booleans())
def test_rts_per_axis_mask_is_each_axis_alone(seed, steps, update_first):
    """A (T, n) mask smooths each axis as a (T,) mask of its own would."""
    z, _, q, r2 = _problem(seed, steps, 3)
    has = np.random.default_rng(seed).random((steps, 3)) < 0.6
    has[0] = True
    z = np.where(has, np.nan_to_num(z, nan=3.0), np.nan)  # measured: finite; the rest unread
    got = rts_smooth(z, has, q, r2, velocity_sd=5.0, update_first=update_first)
    for k in range(3):
        alone = rts_smooth(
            z[:, k : k + 1],
            has[:, k],
            q[k : k + 1],
            r2[k : k + 1],
            velocity_sd=5.0,
            update_first=update_first,
        )
        np.testing.assert_allclose(got[:, k], alone[:, 0], rtol=1e-12, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    steps=st.integers(1, 60),
    n=st.integers(1, 5),
    per_axis=st.booleans(),
    update_first=st.booleans(),
)
def test_rts_is_the_numpy_loop(seed, steps, n, per_axis, update_first):
    """The C++ smoother against the NumPy loop it replaced (tests/reference/smoothing.py)."""
    z, has, q, r2 = _problem(seed, steps, n)
    if per_axis:
        has = np.random.default_rng(seed + 1).random((steps, n)) < 0.6
        has[0] = True
        z = np.where(has, np.nan_to_num(z, nan=7.0), np.inf)  # unmeasured: never read
    vsd = float(np.random.default_rng(seed).uniform(0.5, 20.0))
    got = rts_smooth(z, has, q, r2, velocity_sd=vsd, update_first=update_first)
    want = rts_smooth_numpy(z, has, q, r2, vsd, update_first)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)
    assert np.isfinite(got).all()


@pytest.mark.parametrize("update_first", [True, False])
@pytest.mark.parametrize("velocity_sd", [0.0, 1e-200])
def test_rts_without_any_noise_is_a_constant(update_first: bool, velocity_sd: float) -> None:
    """q = 0 and no initial velocity variance (or one that squares to 0): the position is one
    constant, the measurements' mean (with z_0 twice when it is also an update). Was: NaN,
    refused as "too extreme" (the smoother's gain divided by a singular covariance)."""
    z = np.array([[1.0, 5.0], [2.0, 5.0], [3.0, 5.0], [6.0, 5.0]])
    has = np.ones(4, bool)
    got = rts_smooth(z, has, [0.0, 0.0], [1.0, 1.0], velocity_sd=velocity_sd,
                     update_first=update_first)  # fmt: skip
    mean = (1 + 1 + 2 + 3 + 6) / 5 if update_first else (1 + 2 + 3 + 6) / 4
    np.testing.assert_allclose(got, [[mean, 5.0]] * 4, rtol=1e-12)
    want = rts_smooth_numpy(z, has, np.zeros(2), np.ones(2), velocity_sd, update_first)
    np.testing.assert_allclose(got, want, rtol=1e-12)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros((3, 2)), np.array([0, 1, 1], np.uint8), [1.0, 1.0], [1.0, 1.0]), "first frame"),
        ((np.zeros((3, 2)), np.ones(3, np.uint8), [1.0], [1.0, 1.0]), "q and r2"),
        ((np.zeros(3), np.ones(3, np.uint8), [1.0], [1.0]), "z must"),
        ((np.zeros((3, 2)), np.ones(4, np.uint8), [1.0, 1.0], [1.0, 1.0]), "has must"),
        ((np.zeros((3, 2)), np.ones((3, 1), np.uint8), [1.0, 1.0], [1.0, 1.0]), "has must"),
        ((np.zeros((0, 2)), np.ones(0, np.uint8), [1.0, 1.0], [1.0, 1.0]), "first frame"),
        ((np.zeros((3, 2)), np.ones(3, np.uint8), [np.nan, 1.0], [1.0, 1.0]), "q must be"),
        ((np.zeros((3, 2)), np.ones(3, np.uint8), [1.0, 1.0], [1.0, 0.0]), "r2 finite and > 0"),
        ((np.full((3, 1), np.inf), np.ones(3, np.uint8), [1.0], [1.0]), "frame 0, axis 0"),
        ((np.array([[0.0], [np.nan], [2.0]]), np.ones(3, np.uint8), [1.0], [1.0]), "frame 1"),
    ],
)
def test_rts_core_refuses_bad_arrays(args, match):
    """The kernel checks what it reads itself (one-line ValueError, never a crash)."""
    with pytest.raises(ValueError, match=match):
        _core.rts_smooth(*args, 1.0, False)
    with pytest.raises(ValueError, match="rts_smooth"):
        rts_smooth(*args, velocity_sd=1.0, update_first=False)


def test_update_where_updates_only_the_rows_asked() -> None:
    rng = np.random.default_rng(3)
    mean = (rng.normal(size=(4, 2)), rng.normal(size=(4, 2)))
    cov = (rng.uniform(1, 2, (4, 1)), rng.uniform(0, 0.5, (4, 1)), rng.uniform(1, 2, (4, 1)))
    z, r2 = rng.normal(size=(4, 2)), rng.uniform(0.5, 1, (4, 1))
    full = cv_update(mean, cov, z, r2)
    got = cv_update_where(mean, cov, z, r2, np.ones((4, 1), bool))
    for a, b in zip([*got[0], *got[1]], [*full[0], *full[1]], strict=True):
        np.testing.assert_array_equal(a, b)
    assert cv_update_where(mean, cov, z, r2, np.zeros((4, 1), bool)) == (mean, cov)
    rows = np.array([[True], [False], [True], [False]])
    got = cv_update_where(mean, cov, z, r2, rows)
    for new, upd, old in zip([*got[0], *got[1]], [*full[0], *full[1]], [*mean, *cov], strict=True):
        np.testing.assert_array_equal(new[[0, 2]], upd[[0, 2]])
        np.testing.assert_array_equal(new[[1, 3]], old[[1, 3]])


def test_rts_bad_input():
    z = np.zeros((4, 2))
    with pytest.raises(ValueError, match="first frame"):
        rts_smooth(z, [False, True, True, True], [1, 1], [1, 1], velocity_sd=1.0, update_first=True)
    with pytest.raises(ValueError, match="must be"):
        rts_smooth(z, [True] * 4, [1, 1, 1], [1, 1], velocity_sd=1.0, update_first=True)
    with pytest.raises(ValueError, match="must be"):
        rts_smooth(z, np.ones((4, 3), bool), [1, 1], [1, 1], velocity_sd=1.0, update_first=True)
    with pytest.raises(ValueError, match="first frame"):
        has = np.ones((4, 2), bool)
        has[0, 1] = False
        rts_smooth(z, has, [1, 1], [1, 1], velocity_sd=1.0, update_first=True)
    with pytest.raises(ValueError, match="first frame"):
        rts_smooth(
            np.zeros((0, 2)), np.zeros(0, bool), [1, 1], [1, 1], velocity_sd=1.0, update_first=True
        )
    # the entry and its value are named, as cv_update names them (was: "q must be finite and
    # >= 0, r2 finite and > 0", whichever of the two, on whichever axis)
    for q, r2, match in (
        ([1, -1], [1, 1], r"^rts_smooth: q\[1\] is -1, expected finite and >= 0$"),
        ([1, np.nan], [1, 1], r"^rts_smooth: q\[1\] is nan, expected finite and >= 0$"),
        ([1, 1], [0, 1], r"^rts_smooth: r2\[0\] is 0, expected finite and > 0$"),
        ([1, 1], [1, np.inf], r"^rts_smooth: r2\[1\] is inf, expected finite and > 0$"),
    ):
        with pytest.raises(ValueError, match=match):
            rts_smooth(z, [True] * 4, q, r2, velocity_sd=1.0, update_first=True)


MEAN = (np.array([1.0, 2.0]), np.array([0.5, -0.5]))
COV = (np.array([2.0, 3.0]), np.array([0.1, -0.2]), np.array([1.0, 4.0]))


@pytest.mark.parametrize(
    ("call", "match"),
    [
        # was: ZeroDivisionError: float division by zero
        (lambda: cv_update((0.0, 1.0), (0.0, 0.0, 1.0), 1.0, 0.0), "cv_update: r2 is 0, expected"),
        (lambda: cv_update(MEAN, COV, 1.0, np.array([1.0, -2.0])), r"r2\[1\] is -2, expected fin"),
        (lambda: cv_update(MEAN, COV, 1.0, np.nan), "r2 is nan, expected finite and > 0"),
        (lambda: cv_update((0.0, 1.0), (-1.0, 0.0, 1.0), 1.0, 1.0), "cov's p00 is -1, expected"),
        (lambda: cv_update(MEAN, (COV[0], np.inf, COV[2]), 1.0, 1.0), "cov's p01 is inf, expected"),
        (lambda: cv_update(MEAN, COV[:2], 1.0, 1.0), "cov has 2 entries, expected 3"),
        # was: a velocity variance of 0.0 (1 - 1), silently
        (lambda: cv_predict((0.0, 1.0), (1.0, 0.0, 1.0), -1.0), "cv_predict: q is -1, expected"),
        (lambda: cv_predict(MEAN, COV, 1.0, -1.0), "cv_predict: dt is -1, expected finite and >="),
        (lambda: cv_predict(MEAN, (1.0, 0.0, -1e-9), 1.0), "cov's p11 is -1e-09, expected"),
        (lambda: cv_update_where(MEAN, COV, 1.0, 0.0, False), "cv_update_where: r2 is 0"),
        # was accepted: a "covariance" with p01² > p00 p11 (a negative variance along a
        # direction), which the update took on
        (
            lambda: cv_predict((0.0, 1.0), (1.0, 5.0, 1.0), 1.0),
            r"^cv_predict: cov \(p00, p01, p11\) = \(1.0, 5.0, 1.0\) is not positive semi-def",
        ),
        (
            lambda: cv_update(MEAN, (COV[0], np.array([0.1, -3.5]), COV[2]), 1.0, 1.0),
            r"^cv_update: cov\[1\] \(p00, p01, p11\) = \(3.0, -3.5, 4.0\) is not positive",
        ),
        # wherever `where` holds or not
        (
            lambda: cv_update_where(MEAN, (1.0, 1.0 + 1e-8, 1.0), 1.0, 1.0, False),
            r"^cv_update_where: cov \(p00, p01, p11\) = \(1.0, 1.00000001, 1.0\) is not",
        ),
        # p00 p11 overflows to inf, but p01² = 1e320 > 1e310 all the same
        (lambda: cv_predict(MEAN, (1e300, 1e160, 1e10), 1.0), "cv_predict: cov .* is not posit"),
        # was: a negative "covariance"
        (lambda: wna_Q(-1.0), "wna_Q: q is -1, expected finite and >= 0"),
        (lambda: wna_Q(1.0, np.inf), "wna_Q: dt is inf, expected finite and >= 0"),
        (lambda: wna_Q_xy((0.5, -1.0)), r"wna_Q_xy: q\[1\] is -1, expected finite and >= 0"),
        (lambda: wna_Q_xy((0.5, 1.0), -2.0), "wna_Q_xy: dt is -2, expected finite and >= 0"),
        (lambda: cv_transition(np.nan), "cv_transition: dt is nan, expected finite"),
        (lambda: cv_transition_xy(np.inf), "cv_transition_xy: dt is inf, expected finite"),
    ],
)
def test_helpers_refuse_bad_noise_levels(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_helpers_refuse_what_is_not_real_numbers():
    with pytest.raises(TypeError, match="cv_predict: q must hold real numbers"):
        cv_predict(MEAN, COV, 1j)
    with pytest.raises(TypeError, match="cv_update: r2 must hold real numbers"):
        cv_update(MEAN, COV, 1.0, "1")


def test_helpers_take_the_bounds_the_equations_allow():
    # q = 0, dt = 0 and zero variances are a model; r2 > 0 keeps the update's division finite
    assert cv_predict((0.0, 1.0), (0.0, 0.0, 0.0), 0.0, 0.0) == ((0.0, 1.0), (0.0, 0.0, 0.0))
    (p, v), (a, b, c) = cv_update((0.0, 1.0), (0.0, 0.0, 1.0), 3.0, 5e-324)
    assert (p, v, a, b, c) == (0.0, 1.0, 0.0, 0.0, 1.0)
    np.testing.assert_array_equal(wna_Q(0.0, 0.0), np.zeros((2, 2)))
    np.testing.assert_array_equal(cv_transition(-1.0), [[1.0, -1.0], [0.0, 1.0]])


def test_covariances_on_the_psd_boundary_are_taken():
    # p01² = p00 p11 (a singular covariance, e.g. no velocity of its own), its round-off, and
    # products that overflow: still covariances
    for cov in [(1.0, 1.0, 1.0), (2.0, -np.sqrt(2.0 * 3.0), 3.0), (1.0, 1.0 + 1e-12, 1.0)]:
        cv_predict((0.0, 1.0), cov, 1.0)
        cv_update((0.0, 1.0), cov, 1.0, 1.0)
    assert cv_predict((0.0, 0.0), (1e300, 1e300, 1e300), 0.0, 0.0)[1] == (1e300, 1e300, 1e300)
    # a long run of checked predicts and updates (noise levels over many decades) is never
    # refused for the round-off of its own covariances
    rng = np.random.default_rng(3)
    for _ in range(20):
        mean, cov = (0.0, 0.0), (rng.uniform(0, 10), 0.0, rng.uniform(0, 10))
        q = 10 ** rng.uniform(-12, 6)
        for _ in range(100):
            mean, cov = cv_predict(mean, cov, q, rng.choice([0.0, 1e-3, 1.0, 2.5]))
            mean, cov = cv_update(mean, cov, rng.normal(), 10 ** rng.uniform(-300, 8))


def test_the_trackers_unchecked_calls_give_the_same_floats():
    """The tracker calls ``_cv_*`` every frame; the public functions check, then call them."""
    from pftrack.kalman import _cv_predict, _cv_update, _cv_update_where

    rng = np.random.default_rng(5)
    z, r2, q = rng.normal(size=2), rng.uniform(0.5, 2.0, 2), rng.uniform(0.1, 1.0, 2)
    where = np.array([True, False])
    pairs = [
        (cv_predict(MEAN, COV, q), _cv_predict(MEAN, COV, q)),
        (cv_predict(MEAN, COV, q, 2.5), _cv_predict(MEAN, COV, q, 2.5)),
        (cv_update(MEAN, COV, z, r2), _cv_update(MEAN, COV, z, r2)),
        (cv_update_where(MEAN, COV, z, r2, where), _cv_update_where(MEAN, COV, z, r2, where)),
    ]
    for checked, unchecked in pairs:
        for a, b in zip([*checked[0], *checked[1]], [*unchecked[0], *unchecked[1]], strict=True):
            np.testing.assert_array_equal(a, b)


Z3 = np.array([[1.0], [2.0], [3.0]])


def _rts(**kw):
    args = {"z": Z3, "has": [True] * 3, "q": [1.0], "r2": [1.0], "velocity_sd": 10.0}
    args.update(kw)
    return rts_smooth(**{"update_first": True, **args})


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        # each was taken: "no" as True, "10" as 10, NaN and 2 as observed, complex cast with a
        # ComplexWarning, "no" and "False" as a bool that updates, a ragged (3,) / (4,) state
        (lambda: _rts(update_first="no"), TypeError, "rts_smooth: update_first must be True or"),
        (lambda: _rts(velocity_sd="10"), TypeError, "rts_smooth: velocity_sd must be a number"),
        (lambda: _rts(has=[1.0, np.nan, 1.0]), ValueError, r"rts_smooth: has\[1\] is nan, expec"),
        (lambda: _rts(has=[1, 2, 1]), ValueError, r"rts_smooth: has\[1\] is 2, expected True"),
        (lambda: _rts(has=["yes"] * 3), TypeError, "rts_smooth: has must hold True or False"),
        (lambda: _rts(z=Z3 + 1j), TypeError, "rts_smooth: z must hold real numbers"),
        (lambda: _rts(q=["a"]), TypeError, "rts_smooth: q must hold real numbers"),
        (lambda: cv_update_where(MEAN, COV, 1.0, 1.0, "no"), TypeError, "where must hold True"),
        (lambda: cv_update_where(MEAN, COV, 1.0, 1.0, "False"), TypeError, "where must hold Tru"),
        (lambda: cv_update_where(MEAN, COV, 1.0, 1.0, np.nan), ValueError, "where is nan, expec"),
        (
            lambda: cv_predict((np.zeros(3),) * 2, (np.ones(4), np.zeros(4), np.ones(4)), 1.0),
            ValueError,
            r"cv_predict: mean's position has shape \(3,\) and cov's p00 \(4,\), which do not",
        ),
        (
            lambda: cv_update(MEAN, COV, np.zeros(3), 1.0),
            ValueError,
            r"cv_update: mean's position has shape \(2,\) and z \(3,\), which do not broadcast",
        ),
        (lambda: cv_predict((1.0, 2.0, 3.0), COV, 1.0), ValueError, "mean has 3 entries, expec"),
        # NaN in the state or a measurement: refused by the checked helpers (NaN came out)
        (lambda: cv_predict((np.nan, 0.0), COV, 1.0), ValueError, "mean's position is nan, exp"),
        (lambda: cv_update((0.0, np.inf), COV, 1.0, 1.0), ValueError, "mean's velocity is inf"),
        (lambda: cv_update(MEAN, COV, np.nan, 1.0), ValueError, "cv_update: z is nan, expected"),
        (lambda: cv_update(MEAN, COV, 1j, 1.0), TypeError, "cv_update: z must hold real numbers"),
        (
            lambda: cv_update_where(MEAN, COV, [1.0, np.nan], 1.0, [False, True]),
            ValueError,
            r"cv_update_where: z\[1\] is nan where `where` holds, expected finite",
        ),
    ],
)
def test_helpers_refuse_what_would_be_taken_wrongly(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_update_where_takes_anything_in_z_where_it_does_not_update():
    got = cv_update_where(MEAN, COV, [np.nan, 1.0], 1.0, [0, 1])  # 0/1 count as bools
    want = cv_update_where(MEAN, COV, [0.0, 1.0], 1.0, [False, True])
    for a, b in zip([*got[0], *got[1]], [*want[0], *want[1]], strict=True):
        np.testing.assert_array_equal(a, b)
    assert np.isfinite(_rts(has=np.array([1, 0, 1]), z=[[1.0], [np.nan], [3.0]])).all()


@pytest.mark.parametrize(
    ("call", "match"),
    [
        # p00 + r2 overflowed: the gain was 0 and the measurement ignored, the state finite
        (
            lambda: cv_update((0.0, 0.0), (1e308, 0.0, 1e308), 1e308, 1e308),
            r"^cv_update: cov's p00 \+ r2 \(the innovation variance\) overflows",
        ),
        (
            lambda: cv_update_where(
                (np.zeros(2), np.zeros(2)),
                (np.array([1.0, 1e308]), 0.0, 1.0),
                1.0,
                np.array([1.0, 1e308]),
                [False, True],
            ),
            r"^cv_update_where: cov's p00 \+ r2 .* overflows",
        ),
        # inf came out
        (
            lambda: cv_predict((1e308, 1e308), (1.0, 0.0, 1.0), 1.0),
            r"^cv_predict: the predicted state is not finite \(mean, cov, q or dt too extreme\)$",
        ),
        (
            lambda: cv_predict((np.zeros(2), np.array([0.0, 1e308])), COV, 1.0, 3.0),
            r"^cv_predict: the predicted state is not finite",
        ),
        (  # a Python float's dt**3 raised OverflowError
            lambda: cv_predict((0.0, 0.0), (1.0, 0.0, 1.0), 1.0, 1e200),
            r"^cv_predict: the predicted state is not finite",
        ),
        (
            lambda: cv_update((-1e308, 0.0), (1.0, 0.0, 1.0), 1e308, 1.0),
            r"^cv_update: the filtered state is not finite \(mean, cov, z or r2 too extreme\)$",
        ),
    ],
)
def test_helpers_refuse_values_whose_result_overflows(call, match):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nor any overflow warning on the way
        with pytest.raises(ValueError, match=match):
            call()


def test_update_where_takes_an_overflow_where_it_does_not_update():
    mean, cov = (np.zeros(2), np.zeros(2)), (np.array([1e308, 1.0]), np.zeros(2), np.ones(2))
    (m0, _), (c0, _, _) = cv_update_where(mean, cov, 1.0, np.array([1e308, 1.0]), [False, True])
    np.testing.assert_array_equal(m0, [0.0, 0.5])
    np.testing.assert_array_equal(c0, [1e308, 0.5])


def test_type_aliases_are_types_at_run_time():
    # Value, Mean and Cov were the strings "float | F64", ... in __all__
    import typing

    import pftrack.kalman as kalman

    for name in ("Value", "Mean", "Cov"):
        assert name in kalman.__all__ and not isinstance(getattr(kalman, name), str), name
    assert typing.get_origin(kalman.Mean) is tuple and len(typing.get_args(kalman.Cov)) == 3
    assert float in typing.get_args(kalman.Value)


def _cast(value, to):
    """`value` (an argument of a step: a number, an array or a tuple of them) with each
    float array made `to(array)`; bool arrays (`where`) and numbers stay."""
    if isinstance(value, tuple):
        return tuple(_cast(v, to) for v in value)
    if isinstance(value, np.ndarray) and value.dtype != bool:
        return to(value)
    return value


@pytest.mark.parametrize("step", ["cv_predict", "cv_update", "cv_update_where"])
def test_steps_compute_in_float64_whatever_they_are_given(step) -> None:
    """Was: lists failed inside the arithmetic ("can't multiply sequence by non-int of type
    'float'", naming nothing) and float32 arrays were stepped in float32 (covariances of
    1e4 px² off by ~1e-3 after one step); every value is now taken as float64."""
    rng = np.random.default_rng(3)
    pos, vel, z = rng.normal(0, 1000, 4), rng.normal(0, 5, 4), rng.normal(0, 1000, 4)
    cov = (1e4 + rng.random(4), 0.3 * rng.random(4), 1 + rng.random(4))
    r2, where = 2.5 + rng.random(4), np.array([True, False, True, True])
    args = {
        "cv_predict": (cv_predict, ((pos, vel), cov, 0.7)),
        "cv_update": (cv_update, ((pos, vel), cov, z, r2)),
        "cv_update_where": (cv_update_where, ((pos, vel), cov, z, r2, where)),
    }
    fn, given = args[step]
    want = fn(*given)
    np.testing.assert_array_equal(fn(*_cast(given, np.ndarray.tolist))[1], want[1])
    f32 = _cast(given, lambda a: a.astype(np.float32))
    got = fn(*f32)
    exact = fn(*_cast(f32, lambda a: a.astype(np.float64)))
    for g, e in zip((*got[0], *got[1]), (*exact[0], *exact[1]), strict=True):
        assert g.dtype == np.float64
        np.testing.assert_array_equal(g, e)
