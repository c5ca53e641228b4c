from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from pftrack import _core
from pftrack.particle_filter import Ar2Model, FilterConfig, MHColourParticleFilter
from tests.reference import mcmc as ref


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


A, B, SIGMA = [2.0, 2.0, 2.0], [-1.0, -1.0, -1.0], [4.0, 4.0, 0.02]


def scene(rng: np.random.Generator, cx: int = 40, cy: int = 30):
    frame = rng.integers(0, 256, (64, 96, 3), dtype=np.uint8)
    mask = np.zeros((64, 96), np.uint8)
    frame[cy - 10 : cy + 10, cx - 6 : cx + 6] = (30, 40, 200)
    mask[cy - 14 : cy + 14, cx - 10 : cx + 10] = 1
    return frame, mask


def particles_at(n: int, cx: float, cy: float, vx: float = 0.0) -> np.ndarray:
    return np.ascontiguousarray(np.tile([cx, cy, 1.0, cx - vx, cy, 1.0], (n, 1)))


def call(
    p,
    w,
    m,
    img,
    r,
    seed=3,
    step=0,
    lam=20.0,
    n_iter=3,
    burn_in=1,
    proposal="dynamics",
    rw=(2.0, 2.0, 0.01),
    sigma=SIGMA,
):
    return _core.mh_step(
        p,
        w,
        m,
        img,
        r,
        12.0,
        20.0,
        A,
        B,
        sigma,
        0.2,
        5.0,
        False,
        lam,
        "uniform",
        True,
        seed,
        step,
        n_iter=n_iter,
        burn_in=burn_in,
        proposal=proposal,
        rw_sigma=np.asarray(rw, float),
    )


@pytest.mark.parametrize("proposal", ["dynamics", "random_walk"])
def test_matches_numpy_reference(rng, proposal):
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    p = particles_at(12, 37.0, 31.0, vx=1.0)
    p[:, 0] += np.arange(12) * 0.5
    w = np.full(12, 1 / 12)
    m = np.zeros((2, 3))
    expect, mean, acc = ref.mh_step(
        p,
        img.bins,
        img.n_bins,
        r,
        12.0,
        20.0,
        A,
        B,
        SIGMA,
        0.2,
        5.0,
        20.0,
        11,
        4,
        5,
        2,
        proposal,
        (2.0, 2.0, 0.01),
    )
    out = call(p, w, m, img, r, seed=11, step=4, n_iter=5, burn_in=2, proposal=proposal)
    np.testing.assert_allclose(p, expect, rtol=0, atol=1e-9)
    np.testing.assert_allclose(out["mean"], mean, atol=1e-9)
    assert out["acceptance"] == pytest.approx(acc)
    assert 0.0 < acc < 1.0  # the example exercises both outcomes
    np.testing.assert_allclose(w, 1 / 12)
    np.testing.assert_allclose(m[0], mean, atol=1e-9)


def test_flat_likelihood_samples_the_dynamics(rng):
    # lam = 0: the target is p(x | x_{t-1}) = N(A x1 + B x2, C^2); a random-walk chain must keep
    # its draws distributed as that Gaussian (KS test per component).
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    n = 3000
    p = particles_at(n, 40.0, 30.0, vx=2.0)
    sigma = [4.0, 4.0, 0.05]
    out = call(
        p,
        np.full(n, 1 / n),
        np.zeros((2, 3)),
        img,
        r,
        lam=0.0,
        n_iter=20,
        burn_in=0,
        proposal="random_walk",
        rw=(6.0, 6.0, 0.08),
        sigma=sigma,
    )
    mu = [42.0, 30.0, 1.0]
    for d in range(3):
        assert stats.kstest(p[:, d], "norm", args=(mu[d], sigma[d])).pvalue > 1e-3
    assert 0.2 < out["acceptance"] < 0.9
    # a wrong proposal ratio would not keep the law: a chain targeting a different scale fails
    wrong = stats.kstest(p[:, 0], "norm", args=(mu[0], 1.3 * sigma[0])).pvalue
    assert wrong < 1e-3


def test_dynamics_proposal_with_flat_likelihood_accepts_everything(rng):
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    out = call(particles_at(50, 40, 30), np.full(50, 0.02), np.zeros((2, 3)), img, r, lam=0.0)
    assert out["acceptance"] == 1.0


@pytest.mark.parametrize("lam", [0.0, 20.0])
def test_a_chain_started_outside_the_support_leaves_it(rng, lam):
    """sigma_s = 0 and parents whose prediction of the scale lies beyond s_max: a chain started
    there is clamped onto the bound, where the deterministic scale puts no mass (target 0), so
    the first proposal of positive target must be accepted (a = +inf). Was: log a = +inf - inf
    = NaN, never accepted, and such chains stayed on the clamped box for all n_iter iterations
    (the NumPy reference did the same)."""
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    n = 20
    p = particles_at(n, 40.0, 30.0)
    p[: n // 2, 2], p[: n // 2, 5] = 3.0, 0.5  # predicted scale 2 * 3 - 0.5 = 5.5 > s_max 5
    before = p.copy()
    out = call(p, np.full(n, 1 / n), np.zeros((2, 3)), img, r, lam=lam, n_iter=20, burn_in=0,
               sigma=[4.0, 4.0, 0.0])  # fmt: skip
    np.testing.assert_array_equal(p[:, 2], 1.0)  # every chain on a parent of scale 1
    expect, _, acc = ref.mh_step(before, img.bins, img.n_bins, r, 12.0, 20.0, A, B,
                                 [4.0, 4.0, 0.0], 0.2, 5.0, lam, 3, 0, 20, 0, "dynamics",
                                 (2.0, 2.0, 0.01))  # fmt: skip
    np.testing.assert_allclose(p, expect, rtol=0, atol=1e-9)
    assert out["acceptance"] == pytest.approx(acc)


def test_fixed_seed_fixed_result(rng):
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    runs = []
    for seed in (5, 5, 6):
        p = particles_at(40, 38, 29)
        call(p, np.full(40, 1 / 40), np.zeros((2, 3)), img, r, seed=seed)
        runs.append(p)
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])


def test_errors(rng):
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    p, w, m = particles_at(4, 40, 30), np.full(4, 0.25), np.zeros((2, 3))
    with pytest.raises(ValueError, match="burn_in"):
        call(p, w, m, img, r, n_iter=2, burn_in=2)
    with pytest.raises(ValueError, match="n_iter"):
        call(p, w, m, img, r, n_iter=0, burn_in=0)
    with pytest.raises(ValueError, match="proposal"):
        call(p, w, m, img, r, proposal="gibbs")
    with pytest.raises(ValueError, match="weights size"):
        call(p, np.full(3, 1 / 3), m, img, r)
    with pytest.raises(ValueError, match="n_iter is 0"):
        MHColourParticleFilter([40, 30, 12, 20], r, n_iter=0)
    with pytest.raises(ValueError, match=r"box is \[1.0, 2.0, 0.0, 4.0\]"):
        MHColourParticleFilter([1, 2, 0, 4], r)


#: AR(2) with A = 2, B = -1 (constant velocity) and the kernel tests' noise, as a filter model
MODEL = Ar2Model(
    sigma_xy=4.0, sigma_s=0.02, velocity_gain=1.0, scale_gain=1.0, s_min=0.2, s_max=5.0
)


@pytest.mark.parametrize("n_iter", [1, 4])
def test_filter_step_matches_numpy_reference(rng, n_iter):
    """The tracker's MH filter is the kernel with the dynamics proposal and no burn-in."""
    frame, mask = scene(rng)
    img = _core.hsv_bins(frame, mask)
    r = _core.box_histograms(img, np.array([[40.0, 30, 12, 20]]))[0]
    f = MHColourParticleFilter(
        [38.0, 31, 12, 20],
        r,
        FilterConfig(n_particles=12, model=MODEL),
        rng=4,
        velocity=(1.0, 0.0),
        n_iter=n_iter,
    )
    np.testing.assert_array_equal(MODEL.a, A)
    np.testing.assert_array_equal(MODEL.b, B)
    np.testing.assert_array_equal(MODEL.sigma, SIGMA)
    for step in range(3):
        before = f.particles.copy()
        expect, mean, acc = ref.mh_step(
            before,
            img.bins,
            img.n_bins,
            f.reference,
            12.0,
            20.0,
            A,
            B,
            SIGMA,
            0.2,
            5.0,
            20.0,
            f._seed,
            step,
            n_iter,
            0,
            "dynamics",
            (2.0, 2.0, 0.01),
        )
        state = f.step(img)
        np.testing.assert_allclose(f.particles, expect, rtol=0, atol=1e-9)
        np.testing.assert_allclose(
            state.box_cxcywh, [mean[0], mean[1], 12 * mean[2], 20 * mean[2]], atol=1e-9
        )
        assert f.acceptance == pytest.approx(acc)
        np.testing.assert_allclose(f.weights, 1 / 12)
    assert 0.0 < f.acceptance < 1.0


def test_filter_follows_a_moving_object(rng):
    cfg = FilterConfig(
        n_particles=150, model=Ar2Model(sigma_xy=3.0, sigma_s=0.01, s_min=0.2, s_max=5.0)
    )
    frame, _ = scene(rng, 30, 30)
    img = _core.hsv_bins(frame)
    r = _core.box_histograms(img, np.array([[30.0, 30, 12, 20]]))[0]
    f = MHColourParticleFilter([30, 30, 12, 20], r, cfg, rng=1, n_iter=2)
    for t in range(1, 16):
        cx = 30 + 2 * t
        frame, _ = scene(np.random.default_rng(t), cx, 30)
        state = f.step(_core.hsv_bins(frame))  # every pixel counted: shifts add clutter
        assert 0.0 <= f.acceptance <= 1.0
    assert abs(state.box_cxcywh[0] - cx) < 4 and abs(state.box_cxcywh[1] - 30) < 4
    assert state.rho > 0.8


# ---- large boxes on a lattice (FilterConfig.min_samples), as the SIS filter counts them ----


def _big_scene(rng: np.random.Generator):
    frame = rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)
    frame[40:200, 100:160] = (30, 40, 200)  # a red walker (BGR)
    frame[120:200, 100:160] = (200, 120, 20)  # in blue trousers
    mask = np.zeros(frame.shape[:2], np.uint8)
    mask[20:220, 60:260] = 1
    return _core.hsv_bins(frame, mask)


def _big_call(p, w, m, img, r, min_samples=None, **kw):
    extra = {} if min_samples is None else {"min_samples": float(min_samples)}
    return _core.mh_step(
        p, w, m, img, r, 60.0, 160.0, A, B, [3.0, 3.0, 0.02], 0.5, 2.0, False, 20.0,
        "uniform", True, 11, 4, n_iter=kw.get("n_iter", 5), burn_in=2,
        proposal=kw.get("proposal", "dynamics"), rw_sigma=np.array([2.0, 2.0, 0.01]), **extra,
    )  # fmt: skip


@pytest.mark.parametrize("proposal", ["dynamics", "random_walk"])
@pytest.mark.parametrize("min_samples", [0, 200, 1000, 3000])
def test_min_samples_counts_the_lattice_of_the_sis_filter(rng, proposal, min_samples):
    """mh_step counts each box on the lattice sis_step uses (lattice_step of the previous mean
    state's box): the chains, the coefficients and the counted pixels of the NumPy reference
    whose histograms are tests/reference/kernels.py::box_histograms(..., step) (was: every
    pixel, whatever min_samples)."""
    from tests.reference import kernels

    img = _big_scene(rng)
    r = kernels.box_histograms(img.bins, img.n_bins, [[130, 120, 60, 160]])[0] + 1e-3
    n = 12
    p = particles_at(n, 128.0, 121.0, vx=1.0)
    p[:, 0] += np.arange(n) * 0.5
    p[:, 2] = p[:, 5] = 1.02
    w = np.full(n, 1 / n)
    m = np.array([[130.0, 120.0, 1.02], [129.0, 119.0, 1.0]])
    k = kernels.lattice_step(1.02 * 60, 1.02 * 160, min_samples)
    assert k == {0: 1, 200: 7, 1000: 3, 3000: 1}[min_samples]
    details: dict[str, list[float]] = {}
    expect, mean, acc = ref.mh_step(
        p, img.bins, img.n_bins, r, 60.0, 160.0, A, B, [3.0, 3.0, 0.02], 0.5, 2.0, 20.0, 11, 4,
        5, 2, proposal, (2.0, 2.0, 0.01), lattice=k, details=details,
    )  # fmt: skip
    out = _big_call(p, w, m, img, r, min_samples, proposal=proposal)
    np.testing.assert_allclose(p, expect, rtol=0, atol=1e-9)
    np.testing.assert_allclose(out["mean"], mean, atol=1e-9)
    assert out["acceptance"] == pytest.approx(acc)
    assert out["rho_max"] == pytest.approx(max(details["rho"]), rel=1e-12)
    assert out["rho_mean"] == pytest.approx(np.mean(details["rho"]), rel=1e-12)
    assert out["fg_mean"] == pytest.approx(np.mean(details["counted"]), rel=1e-12)


def test_min_samples_box_coefficient_equals_the_sis_filters(rng):
    """The same box on the same lattice has the same coefficient in mh_step as in sis_step: a
    single particle, no noise, one rejected-or-not move back to the same state."""
    img = _big_scene(rng)
    r = _core.box_histograms(img, np.array([[130.0, 120, 60, 160]]))[0] + 1e-3
    model = Ar2Model(sigma_xy=0.0, sigma_s=0.0, s_min=0.5, s_max=2.0)
    got = {}
    for name in ("sis", "mh"):
        p = np.array([[131.3, 119.6, 1.1, 131.3, 119.6, 1.1]])
        w, m = np.ones(1), np.array([[131.3, 119.6, 1.1], [131.3, 119.6, 1.1]])
        args = (p, w, m, img, r, 60.0, 160.0, model.a, model.b, model.sigma, model.s_min,
                model.s_max, False, 20.0, "uniform", True, 5, 0)  # fmt: skip
        if name == "sis":
            got[name] = _core.sis_step(*args, 1000.0)
        else:
            got[name] = _core.mh_step(*args, n_iter=1, min_samples=1000.0)
    assert got["mh"]["rho_max"] == got["sis"]["rho_max"]  # bit for bit
    assert got["mh"]["fg_mean"] == got["sis"]["fg_mean"]
    full = _core.mh_step(
        np.array([[131.3, 119.6, 1.1, 131.3, 119.6, 1.1]]), np.ones(1),
        np.array([[131.3, 119.6, 1.1], [131.3, 119.6, 1.1]]), img, r, 60.0, 160.0, model.a,
        model.b, model.sigma, model.s_min, model.s_max, False, 20.0, "uniform", True, 5, 0,
    )  # fmt: skip
    assert full["fg_mean"] != got["mh"]["fg_mean"]  # the lattice was used (step 3)


def test_min_samples_zero_is_every_pixel_bit_for_bit(rng):
    """min_samples=0 (and boxes under 4 min_samples pixels) leave mh_step as it was: the same
    bits as without the argument, which counts every pixel."""
    img = _big_scene(rng)
    r = _core.box_histograms(img, np.array([[130.0, 120, 60, 160]]))[0] + 1e-3
    runs = []
    for ms in (None, 0, 1e6):  # 1e6: the 60x160 box is under 4 min_samples pixels: step 1
        p = particles_at(20, 128.0, 121.0, vx=1.0)
        p[:, 0] += np.arange(20) * 0.5
        w, m = np.full(20, 1 / 20), np.array([[130.0, 120.0, 1.0], [129.0, 119.0, 1.0]])
        out = _big_call(p, w, m, img, r, ms)
        runs.append((p.tobytes(), m.tobytes(), repr(sorted(out.items(), key=lambda kv: kv[0]))))
    assert runs[0] == runs[1] == runs[2]


def test_filter_passes_min_samples(rng):
    """MHColourParticleFilter steps with its FilterConfig.min_samples (was: every pixel, the
    core's default), bit for bit the core's step given the same value."""
    import dataclasses

    from pftrack.particle_filter import hsv_bins

    frame = rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)
    frame[40:200, 100:160] = (30, 40, 200)
    img = hsv_bins(frame)
    box = np.array([130.0, 120.0, 60.0, 160.0])
    r = _core.box_histograms(img, box[None])[0] + 1e-3
    rho = {}
    for ms in (0, 300):
        cfg = dataclasses.replace(FilterConfig(n_particles=30), min_samples=ms)
        f = MHColourParticleFilter(box, r, cfg, rng=4)
        g = MHColourParticleFilter(box, r, cfg, rng=4)
        mm = g.config.model
        rho[ms] = []
        for _ in range(3):
            st = f.step(img)
            out = _core.mh_step(
                g.particles, g.weights, g.means, img, g.reference, g.w0, g.h0, mm.a, mm.b,
                mm.sigma, mm.s_min, mm.s_max, mm.use_means, g.config.lam, g.config.kernel, True,
                g._seed, g._step, n_iter=1, burn_in=0, proposal="dynamics",
                rw_sigma=np.array([2.0, 2.0, 0.01]), min_samples=float(ms),
            )  # fmt: skip
            g._step += 1
            assert (out["fg_mean"], out["rho_mean"]) == (st.foreground, st.rho)
            np.testing.assert_array_equal(f.particles, g.particles)
            rho[ms].append(st.rho)
    assert rho[0] != rho[300]  # 60x160 boxes: every pixel, or a lattice of step 5
