"""The goal-directed state equation in C++ against literal NumPy references."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from pftrack import _core
from pftrack.kalman import cv_transition_xy, wna_Q_xy
from pftrack.recovery import GdtModel, goal_directed_path, sample_goal_directed_paths
from tests.reference import bridge as ref


def spd(rng, n, scale=1.0):
    a = rng.standard_normal((n, n))
    return scale * (a @ a.T + n * np.eye(n))


def problem(rng, n=4, m=2, T=7, varying=False):
    if varying:
        A = np.stack([np.eye(n) + 0.2 * rng.standard_normal((n, n)) for _ in range(T)])
        Q = np.stack([spd(rng, n, 0.1) for _ in range(T)])
    else:
        A = np.eye(n) + 0.2 * rng.standard_normal((n, n))
        Q = spd(rng, n, 0.1)
    H = rng.standard_normal((m, n))
    return dict(
        A=A,
        Q=Q,
        H_T=H,
        Pi_T=spd(rng, m, 0.05),
        m0=rng.standard_normal(n),
        Pi_0=spd(rng, n, 0.2),
        y_T=rng.standard_normal(m),
        T=T,
    )


def as_ref(p):
    return (p["A"], p["Q"], p["H_T"], p["Pi_T"], p["m0"], p["Pi_0"], p["y_T"], p["T"])


@pytest.mark.parametrize("T", [1, 2, 7, 25])
@pytest.mark.parametrize("varying", [False, True])
@pytest.mark.parametrize("start_conditioned", [False, True])
def test_general_form_matches_reference(T, varying, start_conditioned):
    rng = np.random.default_rng(T + 10 * varying)
    p = problem(rng, T=T, varying=varying)
    got = goal_directed_path(**p, start_conditioned=start_conditioned)
    path, eps, x0m, x0c = ref.gdt_general(*as_ref(p), start_conditioned=start_conditioned)
    np.testing.assert_allclose(got.path, path, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(got.eps, eps, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(got.x0_mean, x0m, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(got.x0_cov, x0c, rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize("T", [1, 5, 12])
def test_path_is_the_exact_conditional_mean_and_covariance(T):
    # Independent of the paper's algebra: condition the joint Gaussian of (x_0..x_T, y_T).
    rng = np.random.default_rng(100 + T)
    p = problem(rng, T=T, varying=True)
    got = goal_directed_path(**p, start_conditioned=True)
    means, covs = ref.joint_conditional(*as_ref(p))
    np.testing.assert_allclose(got.path, means, rtol=1e-7, atol=1e-8)
    np.testing.assert_allclose(got.cov, covs, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("T", [1, 3, 10])
def test_forms_agree_for_invertible_H(T):
    rng = np.random.default_rng(7 * T)
    p = problem(rng, n=4, m=4, T=T, varying=True)
    g = goal_directed_path(**p, form="general")
    i = goal_directed_path(**p, form="invertible")
    q = goal_directed_path(**p, form="pseudo_inverse")
    for other in (i, q):
        np.testing.assert_allclose(other.path, g.path, rtol=1e-7, atol=1e-8)
        np.testing.assert_allclose(other.eps, g.eps, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(other.cov, g.cov, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(other.x0_mean, g.x0_mean, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(other.x0_cov, g.x0_cov, rtol=1e-7, atol=1e-9)


def test_pseudo_inverse_form_agrees_for_tall_H_with_isotropic_goal_noise():
    rng = np.random.default_rng(3)
    p = problem(rng, n=3, m=5, T=6)
    p["Pi_T"] = 0.3 * np.eye(5)
    g = goal_directed_path(**p, form="general")
    q = goal_directed_path(**p, form="pseudo_inverse")
    np.testing.assert_allclose(q.path, g.path, rtol=1e-7, atol=1e-8)
    np.testing.assert_allclose(q.cov, g.cov, rtol=1e-7, atol=1e-9)


def test_forms_reject_what_they_cannot_handle():
    rng = np.random.default_rng(4)
    p = problem(rng, n=4, m=2, T=5)
    with pytest.raises(ValueError, match="^goal_directed_path: H_T must be square"):
        goal_directed_path(**p, form="invertible")
    with pytest.raises(ValueError, match="^goal_directed_path: H_T\\^T H_T is singular"):
        goal_directed_path(**p, form="pseudo_inverse")
    p4 = problem(rng, n=4, m=4, T=5)
    p4["A"] = np.zeros((4, 4))
    with pytest.raises(ValueError, match="A\\[0\\] is singular"):
        goal_directed_path(**p4, form="invertible")


def cv_problem(T=10, Pi_T=1e-6):
    A = cv_transition_xy(1.0)
    Q = np.diag([1e-2, 1e-2, 1e-2, 1e-2])
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    return dict(
        A=A,
        Q=Q,
        H_T=H,
        Pi_T=Pi_T * np.eye(2),
        m0=np.array([0.0, 0.0, 1.0, 0.5]),
        Pi_0=1e-3 * np.eye(4),
        y_T=np.array([30.0, -20.0]),
        T=T,
    )


def test_huge_goal_covariance_follows_the_kalman_prediction():
    p = cv_problem(Pi_T=1e12)
    got = goal_directed_path(**p, start_conditioned=False)
    pred = np.array([np.linalg.matrix_power(p["A"], t) @ p["m0"] for t in range(p["T"] + 1)])
    np.testing.assert_allclose(got.path, pred, atol=1e-6)


def test_tiny_goal_covariance_ends_on_the_goal():
    p = cv_problem(Pi_T=1e-10)
    got = goal_directed_path(**p, start_conditioned=False)
    np.testing.assert_allclose(got.path[-1, :2], p["y_T"], atol=1e-6)
    # and the uncertainty of the final position collapses to (at most) Pi_T
    assert np.all(np.linalg.eigvalsh(got.cov[-1][:2, :2]) < 1e-6)


def test_constant_velocity_path_is_exact():
    p = cv_problem()
    p["y_T"] = p["m0"][:2] + p["T"] * p["m0"][2:]  # consistent goal
    got = goal_directed_path(**p, start_conditioned=False)
    exact = np.array([p["m0"][:2] + t * p["m0"][2:] for t in range(p["T"] + 1)])
    np.testing.assert_allclose(got.path[:, :2], exact, atol=1e-9)


@pytest.mark.parametrize("seed", range(5))
def test_covariances_symmetric_psd_and_match_the_ends(seed):
    rng = np.random.default_rng(seed)
    p = problem(rng, T=9, varying=True)
    got = goal_directed_path(**p)
    for c in list(got.cov) + list(got.eps):
        np.testing.assert_allclose(c, c.T, atol=1e-12)
        assert np.linalg.eigvalsh(c).min() > -1e-10
    np.testing.assert_allclose(got.cov[0], got.x0_cov, rtol=1e-12)
    # conditioning on the goal can only shrink the uncertainty of H x_T below Pi_T
    H = p["H_T"]
    assert np.linalg.eigvalsh(p["Pi_T"] - H @ got.cov[-1] @ H.T).min() > -1e-9


def test_bad_input_names_the_problem():
    rng = np.random.default_rng(5)
    p = problem(rng, T=4)
    with pytest.raises(ValueError, match="T is 0"):
        goal_directed_path(**{**p, "T": 0})
    with pytest.raises(ValueError, match="T is -3"):
        goal_directed_path(**{**p, "T": -3})
    with pytest.raises(ValueError, match=r"H_T has shape \(2, 3\), expected \(2, 4\)"):
        goal_directed_path(**{**p, "H_T": np.ones((2, 3))})
    with pytest.raises(ValueError, match="A holds 3 matrices, expected 1 or T = 4"):
        goal_directed_path(**{**p, "A": np.stack([np.eye(4)] * 3)})
    with pytest.raises(ValueError, match="Pi_0 is not positive definite"):
        goal_directed_path(**{**p, "Pi_0": np.zeros((4, 4))})
    with pytest.raises(ValueError, match="Pi_T is not positive definite"):
        goal_directed_path(**{**p, "Pi_T": -np.eye(2)})
    with pytest.raises(ValueError, match="Pi_T is not symmetric"):
        goal_directed_path(**{**p, "Pi_T": np.array([[1.0, 0.5], [0.0, 1.0]])})
    with pytest.raises(ValueError, match="Q\\[0\\] is not positive semi-definite"):
        goal_directed_path(**{**p, "Q": -np.eye(4)})
    bad = p["m0"].copy()
    bad[1] = np.nan
    with pytest.raises(ValueError, match=r"m0\[1\] is nan, expected finite"):
        goal_directed_path(**{**p, "m0": bad})
    with pytest.raises(ValueError, match=r"y_T\[0\] is inf, expected finite"):
        goal_directed_path(**{**p, "y_T": np.array([np.inf, 0.0])})
    with pytest.raises(ValueError, match="form is"):
        goal_directed_path(**p, form="nope")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="T must be an int"):
        goal_directed_path(**{**p, "T": 2.5})


N4 = np.eye(4)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        # was "gdt_solve: A[0] shape is (4, 4), expected (3, 3)": the state size is A's
        ({"m0": np.zeros(3)}, r"m0 has 3 entries, expected 4 \(A is 4x4\)$"),
        ({"m0": np.zeros((1, 4))}, r"m0 has shape \(1, 4\), expected 4 \(A is 4x4\)$"),
        ({"Q": np.eye(3)}, r"Q has shape \(3, 3\), expected \(4, 4\) or \(T, 4, 4\) \(A is"),
        ({"Pi_0": np.eye(5)}, r"Pi_0 has shape \(5, 5\), expected \(4, 4\) \(A is 4x4\)$"),
        ({"A": np.ones((4, 3))}, r"A has shape \(4, 3\), expected \(n, n\) or \(T, n, n\)"),
        ({"Q": np.stack([N4] * 2)}, "Q holds 2 matrices, expected 1 or T = 10$"),
        ({"y_T": np.zeros(3)}, r"H_T has shape \(4, 4\), expected \(3, 4\) \(y_T has 3 entr"),
        ({"Pi_T": np.eye(3)}, r"Pi_T has shape \(3, 3\), expected \(4, 4\) \(y_T has 4 ent"),
        ({"y_T": np.zeros((2, 2))}, r"y_T has shape \(2, 2\), expected \(m,\) with m >= 1"),
        ({"A": np.full((4, 4), np.nan)}, r"A\[0, 0\] is nan, expected finite$"),
        # the core's own refusals, under the caller's name (was "gdt_solve: ...")
        ({"A": 1e200 * N4}, "the result is not finite: A is unstable"),
        ({"Q": -N4}, r"Q\[0\] is not positive semi-definite$"),
        # was pybind11's "incompatible function arguments" and its signatures
        ({"T": 2**40}, r"T is 1099511627776, expected an int in \[1, 2147483647\]$"),
    ],
)
@pytest.mark.parametrize("fn", ["goal_directed_path", "sample_goal_directed_paths"])
def test_shapes_are_checked_against_A_and_messages_name_the_function(fn, change, match):
    args = dict(A=N4, Q=0.1 * N4, H_T=N4, Pi_T=N4, m0=np.zeros(4), Pi_0=N4, y_T=np.zeros(4), T=10)
    args.update(change)
    if fn == "goal_directed_path":
        call = goal_directed_path
    else:
        call, args = sample_goal_directed_paths, {**args, "n_samples": 2, "rng": 0}
    with pytest.raises(ValueError, match=f"^{fn}: {match}"):
        call(**args)


def test_sample_count_is_bounded():
    p = problem(np.random.default_rng(5), T=4)
    # was pybind11's "incompatible function arguments" and its signatures
    with pytest.raises(ValueError, match=r"n_samples is 4294967296, expected an int in \[1, "):
        sample_goal_directed_paths(**p, n_samples=2**32)


def test_batch_equals_single_and_threads_equal_serial():
    rng = np.random.default_rng(9)
    ps = [problem(rng, T=int(rng.integers(1, 30))) for _ in range(20)]
    tuples = [as_ref(p) for p in ps]
    batch = _core.gdt_solve_batch(tuples, "general", True, False)
    for p, b in zip(ps, batch, strict=True):
        single = goal_directed_path(**p)
        np.testing.assert_array_equal(b["path"], single.path)
        np.testing.assert_array_equal(b["cov"], single.cov)
    results = [None] * 4

    def work(k):
        results[k] = _core.gdt_solve_batch(tuples, "general", True, True)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        for a, b in zip(r, batch, strict=True):
            np.testing.assert_array_equal(a["path"], b["path"])


def test_samples_reproducible_and_centred_on_the_mean_path():
    p = cv_problem(T=8, Pi_T=0.5)
    p["Q"] = np.diag([0.1, 0.1, 0.05, 0.05])
    a = sample_goal_directed_paths(**p, n_samples=4000, rng=1)
    b = sample_goal_directed_paths(**p, n_samples=4000, rng=1)
    np.testing.assert_array_equal(a, b)
    assert a.shape == (4000, 9, 4)
    mean = goal_directed_path(**p)
    se = np.sqrt(np.einsum("tii->ti", mean.cov) / 4000)
    assert np.all(np.abs(a.mean(axis=0) - mean.path) < 5 * se + 1e-12)
    cov_t = np.cov(a[:, 5].T)
    np.testing.assert_allclose(cov_t, mean.cov[5], atol=0.15 * np.abs(mean.cov[5]).max())
    c = sample_goal_directed_paths(**p, n_samples=10, rng=2)
    assert not np.array_equal(a[:10], c)
    with pytest.raises(ValueError, match="n_samples"):
        sample_goal_directed_paths(**p, n_samples=0)


@pytest.mark.parametrize("form", ["general", "invertible"])
@pytest.mark.parametrize("start_conditioned", [True, False], ids=["conditioned", "prior"])
def test_samples_are_distributed_as_the_solution_says(start_conditioned, form):
    # was (start_conditioned=False): every sample started at m0 exactly (sample covariance 0
    # at t = 0 where cov[0] is Pi_0, and 2.37 where cov[4] says 3.545); now x_0 ~ N(m0, Pi_0)
    p = dict(
        A=cv_transition_xy(1.0),
        Q=wna_Q_xy([0.5, 0.2]),
        H_T=np.eye(4) if form == "invertible" else np.eye(4)[:2],
        Pi_T=0.5 * np.eye(4 if form == "invertible" else 2),
        m0=np.array([0.0, 0.0, 1.0, 0.5]),
        Pi_0=np.diag([1.0, 1.0, 0.3, 0.3]),
        y_T=np.array([12.0, 3.0, 1.5, 0.4])[: 4 if form == "invertible" else 2],
        T=8,
    )
    n = 20_000
    sol = goal_directed_path(**p, form=form, start_conditioned=start_conditioned)
    paths = sample_goal_directed_paths(
        **p, n_samples=n, rng=0, form=form, start_conditioned=start_conditioned
    )
    var = np.einsum("tii->ti", sol.cov)
    # standard errors of a sample mean and of a sample covariance entry (Gaussian samples)
    se_mean = np.sqrt(var / n)
    se_cov = np.sqrt((var[:, :, None] * var[:, None, :] + sol.cov**2) / n)
    assert np.all(np.abs(paths.mean(axis=0) - sol.path) < 5 * se_mean)
    cov = np.array([np.cov(paths[:, t].T) for t in range(p["T"] + 1)])
    assert np.all(np.abs(cov - sol.cov) < 5 * se_cov), np.abs(cov - sol.cov).max()
    x0 = sol.x0_cov if start_conditioned else p["Pi_0"]
    np.testing.assert_array_equal(sol.cov[0], x0)


def test_kalman_filter_matches_reference():
    rng = np.random.default_rng(11)
    A = cv_transition_xy(1.0)
    Q = np.diag([0.01, 0.01, 0.1, 0.1])
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = 0.5 * np.eye(2)
    z = np.cumsum(rng.standard_normal((30, 2)), axis=0)
    m0 = np.array([z[0, 0], z[0, 1], 0.0, 0.0])
    P0 = np.diag([0.5, 0.5, 100.0, 100.0])
    m, P = _core.kalman_filter(z, A, Q, H, R, m0, P0)
    mr, Pr = ref.kalman_filter(z, A, Q, H, R, m0, P0)
    np.testing.assert_allclose(m, mr, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(P, Pr, rtol=1e-7, atol=1e-9)
    with pytest.raises(ValueError, match="z \\(the segment\\) is empty"):
        _core.kalman_filter(np.zeros((0, 2)), A, Q, H, R, m0, P0)
    with pytest.raises(ValueError, match="R is not positive definite"):
        _core.kalman_filter(z, A, Q, H, np.zeros((2, 2)), m0, P0)


def test_numpy_peer_matches():
    rng = np.random.default_rng(12)
    p = problem(rng, T=40)
    np.testing.assert_allclose(
        ref.gdt_numpy_fast(*as_ref(p)), goal_directed_path(**p).path, rtol=1e-8, atol=1e-9
    )


@pytest.mark.parametrize("n,m", [(3, 1), (5, 3), (4, 3), (6, 2)])
def test_dynamic_size_path_matches_reference(n, m):
    # sizes other than the fixed-size image kernels (4, 2) and (4, 4) go through dynamic Eigen
    rng = np.random.default_rng(50 + n * m)
    p = problem(rng, n=n, m=m, T=6, varying=True)
    got = goal_directed_path(**p)
    path, eps, x0m, x0c = ref.gdt_general(*as_ref(p))
    np.testing.assert_allclose(got.path, path, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(got.eps, eps, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(got.x0_cov, x0c, rtol=1e-8, atol=1e-10)


def test_paper_model_is_the_constant_velocity_model_of_eq_19():
    m = GdtModel()
    want = np.array([[1, 0, 1, 0], [0, 1, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float)
    np.testing.assert_array_equal(m.A, want)
    np.testing.assert_array_equal(m.A, cv_transition_xy(m.dt))
    np.testing.assert_array_equal(m.H, np.hstack([np.eye(2), np.zeros((2, 2))]))
    np.testing.assert_array_equal(np.diag(m.Q), m.q)


@pytest.mark.parametrize("fn", ["goal_directed_path", "sample_goal_directed_paths"])
def test_options_and_matrices_of_the_wrong_type_are_refused(fn):
    from pftrack.recovery import sample_goal_directed_paths

    p = problem(np.random.default_rng(5), T=4)
    call = goal_directed_path if fn == "goal_directed_path" else sample_goal_directed_paths
    extra = {} if fn == "goal_directed_path" else {"n_samples": 2, "rng": 0}
    # was True: a non-empty string is truthy
    with pytest.raises(TypeError, match=f"{fn}: start_conditioned must be True or False, got str"):
        call(**p, **extra, start_conditioned="no")
    # was cast to its real part with a ComplexWarning
    with pytest.raises(TypeError, match=f"{fn}: Q must hold real numbers"):
        call(**{**p, "Q": p["Q"] + 0j}, **extra)
    with pytest.raises(TypeError, match=f"{fn}: y_T must hold real numbers"):
        call(**{**p, "y_T": ["a", "b"]}, **extra)
    got = call(**p, **extra, start_conditioned=np.False_)  # NumPy's bools are bools
    want = call(**p, **extra, start_conditioned=False)
    np.testing.assert_array_equal(getattr(got, "path", got), getattr(want, "path", want))


def test_sample_count_must_be_an_int():
    from pftrack.recovery import sample_goal_directed_paths

    p = problem(np.random.default_rng(5), T=4)
    with pytest.raises(TypeError, match="n_samples must be an int, got str"):
        sample_goal_directed_paths(**p, n_samples="3")  # was "'<=' not supported"
