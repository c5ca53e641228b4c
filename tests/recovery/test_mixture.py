"""``gdt-mix``: the C++ kernels against NumPy references, the model fit, the method."""

from __future__ import annotations

import numpy as np
import pytest

import pftrack._core as _core
from pftrack.kalman import cv_transition, wna_Q
from pftrack.recovery import recover_gap, recover_gaps
from pftrack.recovery.mixture import (
    MotionFit,
    fit_motion,
    fit_singer,
    recover_mixture,
    recover_mixture_gaps,
    singer_model,
    stand_hypotheses,
)
from pftrack.recovery.noise import estimate_noise
from tests.reference.mixture import gap_mixture as ref_gap_mixture
from tests.reference.mixture import gap_mixture_vectorised, singer_quadrature, state_loglik


def _window(rng: np.random.Generator, n: int, fa: int, fb: int, holes: int) -> np.ndarray:
    z = np.cumsum(rng.normal(2.0, 1.0, n))
    z[fa + 1 : fb] = np.nan
    for i in rng.choice(np.r_[1:fa, fb + 1 : n], size=holes, replace=False):
        z[i] = np.nan
    return z


def _case(rng: np.random.Generator, d: int, n: int, fa: int, fb: int, holes: int, grid: int):
    """A window of `n` points with a gap (fa, fb), a d-state model and the stand hypotheses."""
    z = _window(rng, n, fa, fb, holes=holes)
    F, Q = singer_model(0.3, 2.5) if d == 3 else (cv_transition()[None], wna_Q(0.2)[None])
    t1, t2 = stand_hypotheses(fb - fa, grid=grid)
    return z, F[0], Q[0], t1, t2, np.array([1e4, 4.0, 0.5][:d])


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gap_mixture_matches_numpy(d: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    fa, fb = 22, 41
    z, F, Q, t1, t2, p0 = _case(rng, d, 60, fa, fb, holes=4, grid=7)
    got_p, got_ll = _core.gap_mixture(z, fa, fb, F, Q, 0.3, p0, t1, t2, 4.0)
    ref_p, ref_ll = ref_gap_mixture(z, fa, fb, F, Q, 0.3, p0, t1, t2, 4.0)
    assert got_p.shape == (len(t1), fb - fa - 1)
    np.testing.assert_allclose(got_p, ref_p, rtol=1e-9, atol=1e-8)
    np.testing.assert_allclose(got_ll, ref_ll, rtol=1e-10, atol=1e-8)
    vec_p, vec_ll = gap_mixture_vectorised(z, fa, fb, F, Q, 0.3, p0, t1, t2, 4.0)
    np.testing.assert_allclose(vec_p, ref_p, rtol=1e-9, atol=1e-8)
    np.testing.assert_allclose(vec_ll, ref_ll, rtol=1e-10, atol=1e-8)


@pytest.mark.parametrize("d", [2, 3])
def test_gap_mixture_shared_gains_are_exact(d: int) -> None:
    """Smoother gains shared by hypotheses (walking before t1, standing by t1) change no bit.

    Each hypothesis alone (nothing shared) and the hypotheses in another order (t1 not grouped)
    give the same bits as one call over the grouped hypotheses.
    """
    rng = np.random.default_rng(11)
    fa, fb = 25, 45
    z, F, Q, t1, t2, p0 = _case(rng, d, 70, fa, fb, holes=3, grid=8)
    all_p, all_ll = _core.gap_mixture(z, fa, fb, F, Q, 0.3, p0, t1, t2, 4.0)
    for h in range(len(t1)):
        p, ll = _core.gap_mixture(z, fa, fb, F, Q, 0.3, p0, t1[h : h + 1], t2[h : h + 1], 4.0)
        assert np.array_equal(p[0], all_p[h]) and ll[0] == all_ll[h]
    order = rng.permutation(len(t1))
    p, ll = _core.gap_mixture(z, fa, fb, F, Q, 0.3, p0, t1[order], t2[order], 4.0)
    assert np.array_equal(p, all_p[order]) and np.array_equal(ll, all_ll[order])


def test_gap_mixture_walk_hypothesis_is_the_gaussian_conditional() -> None:
    """No stand: the smoothed gap equals E[x_gap | observations] of the joint Gaussian."""
    rng = np.random.default_rng(5)
    n, fa, fb, r = 30, 9, 20, 0.4
    z = _window(rng, n, fa, fb, holes=2)
    F, Q = cv_transition(), wna_Q(0.15)
    p0 = np.array([1e4, 9.0])
    got, _ = _core.gap_mixture(
        z, fa, fb, F, Q, r, p0, np.array([-1], np.int32), np.array([-1], np.int32), 0.0
    )
    # joint covariance of the positions x_0..x_{n-1}
    d = 2
    Phi = [np.eye(d)]
    for _ in range(1, n):
        Phi.append(F @ Phi[-1])
    cov_states = np.zeros((n, n, d, d))
    P = [np.diag(p0)]
    for _ in range(1, n):
        P.append(F @ P[-1] @ F.T + Q)
    for s in range(n):
        for t in range(s, n):
            c = np.linalg.matrix_power(F, t - s) @ P[s]
            cov_states[t, s], cov_states[s, t] = c, c.T
    C = cov_states[:, :, 0, 0]
    mean = np.full(n, z[0])
    obs = np.isfinite(z)
    S = C[np.ix_(obs, obs)] + r * np.eye(obs.sum())
    gap = np.arange(fa + 1, fb)
    want = mean[gap] + C[np.ix_(gap, obs)] @ np.linalg.solve(S, z[obs] - mean[obs])
    np.testing.assert_allclose(got[0], want, rtol=1e-7, atol=1e-6)


@pytest.mark.parametrize(
    ("seed", "lengths", "q", "tau", "r"),
    [
        (3, (4, 9, 40, 17), [0.1, 2.0], [3.0, 0.5], [0.2, 1.5]),
        # runs far longer than the covariance takes to settle (the steps after it reuse it)
        (4, (1500, 6, 300), [0.1, 2.0, 1e-4], [3.0, 0.5, 80.0], [0.2, 1.5, 10.0]),
    ],
)
def test_state_loglik_batch_matches_numpy(seed, lengths, q, tau, r) -> None:
    rng = np.random.default_rng(seed)
    runs = [np.cumsum(rng.normal(1.0, 0.5, k)) for k in lengths]
    F, Q = singer_model(q, tau)
    r = np.array(r)
    got = _core.state_loglik_batch(
        np.concatenate(runs),
        np.array([len(z) for z in runs], np.int32),
        np.ascontiguousarray(F.reshape(-1, 3)),
        np.ascontiguousarray(Q.reshape(-1, 3)),
        r,
        1e4,
    )
    want = [state_loglik(runs, F[k], Q[k], r[k], 1e4) for k in range(len(q))]
    np.testing.assert_allclose(got, want, rtol=1e-10)


@pytest.mark.parametrize("d", [2, 3])
def test_state_loglik_batch_blocks_are_exact(d: int) -> None:
    """Models filtered together in blocks (the last one partial) give each model's own bits."""
    rng = np.random.default_rng(6)
    runs = [np.cumsum(rng.normal(1.0, 0.5, k)) for k in (3, 50, 7, 120)]
    z, lengths = np.concatenate(runs), np.array([len(v) for v in runs], np.int32)
    K = 7
    if d == 3:
        F, Q = singer_model(10.0 ** rng.uniform(-3, 1, K), 10.0 ** rng.uniform(-1, 2, K))
    else:
        F = np.repeat(cv_transition()[None], K, axis=0)
        Q = np.stack([wna_Q(q) for q in 10.0 ** rng.uniform(-3, 1, K)])
    F, Q = np.ascontiguousarray(F.reshape(-1, d)), np.ascontiguousarray(Q.reshape(-1, d))
    r = 10.0 ** rng.uniform(-2, 1, K)
    got = _core.state_loglik_batch(z, lengths, F, Q, r, 1e4)
    for k in range(K):
        one = _core.state_loglik_batch(
            z, lengths, F[k * d : (k + 1) * d], Q[k * d : (k + 1) * d], r[k : k + 1], 1e4
        )
        assert one[0] == got[k]


@pytest.mark.parametrize("threads", [2, 3, 8])
def test_state_loglik_batch_threads_change_no_bit(threads: int) -> None:
    """Blocks of models on several threads: each model's own bits, whatever the split."""
    rng = np.random.default_rng(8)
    runs = [np.cumsum(rng.normal(1.0, 0.5, k)) for k in (9, 60, 33)]
    z, lengths = np.concatenate(runs), np.array([len(v) for v in runs], np.int32)
    K = 23  # 5 blocks of 4, then 3 models one at a time
    F, Q = singer_model(10.0 ** rng.uniform(-3, 1, K), 10.0 ** rng.uniform(-1, 2, K))
    F, Q = np.ascontiguousarray(F.reshape(-1, 3)), np.ascontiguousarray(Q.reshape(-1, 3))
    r = 10.0 ** rng.uniform(-2, 1, K)
    one = _core.state_loglik_batch(z, lengths, F, Q, r, 1e4)
    assert np.array_equal(_core.state_loglik_batch(z, lengths, F, Q, r, 1e4, threads), one)
    with pytest.raises(ValueError, match="threads is 0"):
        _core.state_loglik_batch(z, lengths, F, Q, r, 1e4, 0)


def _mixture_jobs(rng: np.random.Generator, n_jobs: int):
    """Jobs of both state dimensions (models 0: d = 2, 1: d = 3) and the batch's models."""
    F2, Q2 = cv_transition(), wna_Q(0.2)
    F3, Q3 = singer_model(0.3, 2.5)
    p0 = [np.array([1e4, 4.0]), np.array([1e4, 4.0, 0.5])]
    models = ([F2, F3[0]], [Q2, Q3[0]], [0.3, 0.7], p0, [4.0, 2.0])
    jobs = []
    for j in range(n_jobs):
        n = int(rng.integers(12, 60))
        fa = int(rng.integers(2, n - 6))
        fb = int(rng.integers(fa + 2, n - 2))
        t1, t2 = stand_hypotheses(fb - fa, grid=int(rng.integers(1, 9)))
        jobs.append((_window(rng, n, fa, fb, holes=0), fa, fb, j % 2, t1, t2))
    return jobs, models


@pytest.mark.parametrize("threads", [1, 2, 5])
def test_gap_mixture_many_is_gap_mixture_per_job(threads: int) -> None:
    """The batch gives every job the bits of its own gap_mixture call, in the jobs' order."""
    jobs, models = _mixture_jobs(np.random.default_rng(3), 17)
    got = _core.gap_mixture_many(jobs, *models, threads)
    assert len(got) == len(jobs)
    F, Q, r, p0, v2 = models
    for (z, fa, fb, k, t1, t2), (paths, ll) in zip(jobs, got, strict=True):
        want_p, want_ll = _core.gap_mixture(z, fa, fb, F[k], Q[k], r[k], p0[k], t1, t2, v2[k])
        assert np.array_equal(paths, want_p) and np.array_equal(ll, want_ll)
    assert _core.gap_mixture_many([], *models, threads) == []


@pytest.mark.parametrize("threads", [1, 2])
def test_gap_mixture_many_shared_shapes_are_gap_mixture_per_job(threads: int) -> None:
    """Jobs of one shape (the calibration's validation gaps of a bucket) share their
    covariances in the batch: still every job's own bits. 40 jobs of each model on one window
    shape (more than one piece of shared jobs), others with holes at other places or other
    hypotheses among them, which must not share with them."""
    rng = np.random.default_rng(5)
    _, models = _mixture_jobs(rng, 0)
    n, fa, fb = 50, 29, 40
    t1, t2 = stand_hypotheses(fb - fa, grid=8)
    jobs = []
    for j in range(100):
        z = _window(rng, n, fa, fb, holes=0)
        kind = j % 5
        if kind == 3:  # a hole in segment A: another shape
            z[3 + j % 7] = np.nan
        hyp = (t1[:1], t2[:1]) if kind == 4 else (t1, t2)  # walking only: other hypotheses
        jobs.append((z, fa, fb, j % 2, *hyp))
    got = _core.gap_mixture_many(jobs, *models, threads)
    F, Q, r, p0, v2 = models
    for (z, fa_, fb_, k, h1, h2), (paths, ll) in zip(jobs, got, strict=True):
        want_p, want_ll = _core.gap_mixture(z, fa_, fb_, F[k], Q[k], r[k], p0[k], h1, h2, v2[k])
        assert np.array_equal(paths, want_p) and np.array_equal(ll, want_ll)


@pytest.mark.parametrize(
    "change, error, match",
    [
        (lambda j, m: (j[:1] + [j[1][:3] + (2,) + j[1][4:]], m), ValueError, "job 1: uses model 2"),
        (lambda j, m: (j[:2] + [(j[2][0], 9, 9) + j[2][3:]], m), ValueError, "job 2: need 0 <= fa"),
        (lambda j, m: ([j[0][:5]], m), ValueError, "jobs\\[0\\] must be a tuple"),
        (lambda j, m: ([("text",) + j[0][1:]], m), TypeError, "jobs\\[0\\].z is str"),
        (lambda j, m: (j, (m[0][:1],) + m[1:]), ValueError, "one entry per model"),
        (lambda j, m: (j, m[:2] + ([0.3, -1.0],) + m[3:]), ValueError, "job 1: r is -1"),
    ],
)
def test_gap_mixture_many_bad_input(change, error, match) -> None:
    """Every job is checked, naming it, before any runs; nothing runs on bad input."""
    jobs, models = change(*_mixture_jobs(np.random.default_rng(4), 3))
    with pytest.raises(error, match=match):
        _core.gap_mixture_many(jobs, *models, 2)
    with pytest.raises(ValueError, match="threads is 0"):
        _core.gap_mixture_many([], *_mixture_jobs(np.random.default_rng(4), 0)[1], 0)


@pytest.mark.parametrize("threads", [1, 3])
def test_recover_mixture_gaps_is_recover_mixture(threads: int) -> None:
    """The batched method gives each gap the bits :func:`recover_mixture` gives it alone."""
    runs = _walkers(np.random.default_rng(12), n=6, length=140, stand=(60, 75))
    fit = fit_motion(runs)
    assert not fit.is_gdt_bi
    gaps = [(r[: 40 + 7 * k], r[52 + 9 * k :]) for k, r in enumerate(runs)]
    gaps.append((runs[0][:50], runs[0][50:]))  # no lost step
    got = recover_mixture_gaps(gaps, fit, threads=threads)
    for (a, b), path in zip(gaps, got, strict=True):
        assert np.array_equal(path, recover_mixture(a, b, fit))
    assert got[-1].shape == (0, 2) and got[0].shape == (12, 2)  # frames 40-51


@pytest.mark.parametrize("q,tau", [(0.5, 0.3), (0.07, 2.9), (1.0, 40.0)])
def test_singer_model_matches_quadrature(q: float, tau: float) -> None:
    F, Q = singer_model(q, tau)
    F_ref, Q_ref = singer_quadrature(q, tau)
    np.testing.assert_allclose(F[0], F_ref, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(Q[0], Q_ref, rtol=1e-7, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(Q[0]) > -1e-14)


def test_singer_model_infinite_tau_is_white_jerk() -> None:
    F, Q = singer_model(2.0, np.inf)
    np.testing.assert_allclose(F[0], [[1, 1, 0.5], [0, 1, 1], [0, 0, 1]], atol=1e-12)
    want = 2.0 * np.array([[1 / 20, 1 / 8, 1 / 6], [1 / 8, 1 / 3, 1 / 2], [1 / 6, 1 / 2, 1]])
    np.testing.assert_allclose(Q[0], want, rtol=1e-10)


def _simulate_singer(rng, q, r, tau, n_runs=12, length=120):
    F, Q = singer_model(q, tau)
    L = np.linalg.cholesky(Q[0] + 1e-15 * np.eye(3))
    runs = []
    for k in range(n_runs):
        x = np.array([0.0, rng.normal(0, 3), 0.0])
        xs = []
        for _ in range(length):
            x = F[0] @ x + L @ rng.normal(size=3)
            xs.append(x[0] + rng.normal(0, np.sqrt(r)))
        f = np.arange(length, dtype=float)
        runs.append(np.column_stack([f + 1000 * k, xs, xs]))
    return runs


def test_fit_singer_recovers_parameters() -> None:
    q, r, tau = fit_singer(_simulate_singer(np.random.default_rng(0), 0.05, 0.1, 4.0), axis=0)
    assert 2.0 < tau < 8.0
    assert 0.02 < q < 0.12
    assert 0.05 < r < 0.2


def _walkers(rng, n=10, length=150, stand=None):
    """Constant-velocity walkers with white acceleration and jitter; `stand` = (start, stop)
    frames where every walker stands still."""
    out = []
    for k in range(n):
        v = rng.normal(0, 3, 2)
        p = rng.uniform(0, 300, 2)
        rows = []
        for f in range(length):
            if stand is None or not stand[0] <= f < stand[1]:
                v = v + rng.normal(0, 0.05, 2)
                p = p + v
            rows.append([f + 1000 * k, *(p + rng.normal(0, 0.3, 2))])
        out.append(np.array(rows))
    return out


def test_white_acceleration_data_gives_gdt_bi() -> None:
    runs = _walkers(np.random.default_rng(1))
    fit = fit_motion(runs)
    assert [m.kind for m in fit.axes] == ["wna", "wna"]
    assert fit.stand_rate == 0.0 and fit.is_gdt_bi
    a, b = runs[0][:60], runs[0][80:]
    np.testing.assert_array_equal(
        recover_gap(a, b, method="gdt-mix", motion=fit),
        recover_gap(a, b, method="gdt-bi", noise=fit.noise),
    )


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_stand_inside_the_gap_is_recovered(seed: int) -> None:
    rng = np.random.default_rng(seed)
    walkers = _walkers(rng, n=10, length=220, stand=(80, 150))
    # walkers 4.. are observed throughout (their stands give the stand rate); 0..3 lose 70-159
    fit = fit_motion([w[:70] for w in walkers[:4]] + [w[160:] for w in walkers[:4]] + walkers[4:])
    assert fit.stand_rate > 0.0
    errs = {}
    for method in ("gdt-bi", "gdt-mix", "linear"):
        e = []
        for w in walkers[:4]:
            a, b, truth = w[:70], w[160:], w[70:160, 1:3]
            got = recover_gap(a, b, method=method, noise=fit.noise, motion=fit)
            e.append(np.hypot(*(got - truth).T).mean())
        errs[method] = float(np.mean(e))
    # measured 0.56-0.76 of gdt-bi over seeds 0-7; linear interpolation is 2-4x gdt-bi
    assert errs["gdt-mix"] < 0.8 * errs["gdt-bi"] < 0.8 * errs["linear"], errs


def test_straight_line_is_recovered_exactly() -> None:
    f = np.arange(100.0)
    line = np.column_stack([f, 3.0 + 2.5 * f, 7.0 - 1.5 * f])
    got = recover_gaps([(line[:40], line[60:])], "gdt-mix")[0]
    np.testing.assert_allclose(got, line[40:60, 1:3], atol=1e-6)


def test_same_input_same_output() -> None:
    runs = _walkers(np.random.default_rng(4), stand=(60, 80))
    pairs = [(w[:50], w[90:]) for w in runs]
    one = recover_gaps(pairs, "gdt-mix")
    two = recover_gaps(pairs, "gdt-mix")
    for x, y in zip(one, two, strict=True):
        np.testing.assert_array_equal(x, y)


def test_stand_hypotheses() -> None:
    t1, t2 = stand_hypotheses(50, grid=20)
    assert (t1[0], t2[0]) == (-1, -1)
    assert len(t1) == 1 + 20 * 19 // 2
    assert np.all(t1[1:] < t2[1:]) and t2.max() == 49 and t1[1:].min() == 0
    t1, t2 = stand_hypotheses(3, grid=20)
    assert len(t1) == 1 + 3


def test_describe_names_the_models() -> None:
    fit = fit_motion(_simulate_singer(np.random.default_rng(0), 0.05, 0.1, 4.0))
    text = fit.describe()
    assert "Singer" in text and "stand rate" in text
    assert isinstance(fit, MotionFit)


def test_too_little_data_falls_back() -> None:
    a = np.array([[0, 0.0, 0.0], [1, 1.0, 0.5]])
    b = np.array([[5, 5.0, 2.5], [6, 6.0, 3.0]])
    fit = fit_motion([a, b])
    assert fit.is_gdt_bi
    got = recover_mixture(a, b, fit)
    assert got.shape == (3, 2) and np.all(np.isfinite(got))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(fa=5, fb=5), "fa < fb"),
        (dict(fa=5, fb=6), "no lost step"),
        (dict(fb=40), "fb < len"),
        (dict(r=0.0), "r is 0"),
        (dict(r=np.nan), "r is nan"),
        (dict(v2=-1.0), "v2 is -1"),
        (dict(t1=np.array([3], np.int32), t2=np.array([2], np.int32)), "hypothesis 0"),
        (dict(t1=np.array([0], np.int32), t2=np.array([9], np.int32)), "T-1 = 8"),
        (dict(t2=np.array([-1, -1], np.int32)), "len\\(t2s\\)"),
        (dict(p0=np.ones(3)), "len\\(p0\\)"),
        (dict(Q=np.array([[1.0, 0.5], [0.0, 1.0]])), "symmetric"),
        (dict(F=np.eye(4)), "state dimension"),
        (dict(z=np.r_[np.nan, np.zeros(29)]), "must be observed"),
    ],
)
def test_gap_mixture_bad_input(kwargs, match) -> None:
    args = dict(
        z=np.zeros(30),
        fa=5,
        fb=14,
        F=np.array([[1.0, 1.0], [0.0, 1.0]]),
        Q=np.eye(2) * 0.1,
        r=0.5,
        p0=np.ones(2),
        t1=np.array([-1], np.int32),
        t2=np.array([-1], np.int32),
        v2=1.0,
    )
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        _core.gap_mixture(**args)


def test_recover_gaps_bad_input() -> None:
    a = np.column_stack([np.arange(10.0), np.arange(10.0), np.arange(10.0)])
    with pytest.raises(ValueError, match="segment_b starts at frame"):
        recover_gaps([(a, a[5:])], "gdt-mix")
    with pytest.raises(ValueError, match="non-finite"):
        bad = a.copy()
        bad[3, 1] = np.nan
        recover_gaps([(bad, a + 20)], "gdt-mix")
    with pytest.raises(ValueError, match="increase strictly"):
        recover_gaps([(a[::-1], a + 20)], "gdt-mix")


def test_noise_fallback_is_the_given_estimate() -> None:
    runs = _walkers(np.random.default_rng(6))
    noise = estimate_noise(runs)
    fit = fit_motion(runs, noise)
    assert fit.noise == noise
