"""Propagation, estimates, the fused sis_step (against a NumPy composition of the same draws),
determinism, threads, and a filter that actually tracks."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import (
    Ar2Model,
    ColourParticleFilter,
    FilterConfig,
    box_histograms,
    estimate,
    hsv_bins,
    propagate,
)
from tests.reference import kernels as ref


def _particles(rng, n=64):
    p = np.empty((n, 6))
    p[:, :2] = rng.normal(40, 5, (n, 2))
    p[:, 2] = rng.uniform(0.8, 1.2, n)
    p[:, 3:5] = p[:, :2] - rng.normal(1, 1, (n, 2))
    p[:, 5] = p[:, 2] * rng.uniform(0.95, 1.05, n)
    return p


@pytest.mark.parametrize("use_means", [False, True])
def test_propagate_matches_reference(rng, use_means):
    p = _particles(rng)
    noise = rng.standard_normal((len(p), 3))
    model = Ar2Model(sigma_xy=3.0, sigma_s=0.05, velocity_gain=0.7, scale_gain=1.0, s_min=0.9,
                     s_max=1.1, use_means=use_means)  # fmt: skip
    means = rng.normal(40, 2, (2, 3))
    want = ref.propagate(
        p, noise, model.a, model.b, model.sigma, 0.9, 1.1, use_means, means[0], means[1]
    )
    propagate(p, noise, model, means)
    np.testing.assert_array_equal(p, want)


def test_constant_velocity_without_noise_moves_straight():
    p = np.array([[10.0, 20.0, 1.0, 8.0, 21.0, 1.0]])
    for _ in range(3):
        propagate(p, np.zeros((1, 3)), Ar2Model())
    np.testing.assert_allclose(p[0], [16.0, 17.0, 1.0, 14.0, 18.0, 1.0])


def test_estimate_mean_and_map(rng):
    p = _particles(rng, 10)
    w = rng.random(10)
    mean, map_ = estimate(p, w)
    np.testing.assert_allclose(mean, (w / w.sum()) @ p[:, :3])
    np.testing.assert_array_equal(map_, p[np.argmax(w), :3])


def test_estimate_of_subnormal_weights_is_their_convex_combination(rng):
    """Weights that need not be normalised, all subnormal: the same mean as the weights scaled
    up (a kernel trial: one weight of 5e-324 gave a mean 0.3 px from the only weighted
    particle, sum(w x) keeping a few bits)."""
    p = _particles(rng, 50)
    w = np.zeros(50)
    w[0] = 5e-324
    np.testing.assert_array_equal(estimate(p, w)[0], p[0, :3])
    w[:3] = [1e-320, 3e-321, 7e-322]
    scaled = w / w.max()  # exact: normal numbers again
    np.testing.assert_allclose(estimate(p, w)[0], (scaled / scaled.sum()) @ p[:, :3], rtol=1e-12)


@pytest.mark.parametrize("kernel", ["uniform", "epanechnikov"])
@pytest.mark.parametrize("use_means", [False, True])
def test_sis_step_matches_numpy_composition(textured_frame, rng, kernel, use_means):
    mask = np.zeros(textured_frame.shape[:2], np.uint8)
    mask[5:70, 10:90] = 1
    image = hsv_bins(textured_frame, mask)
    reference = box_histograms(image, [[30, 25, 20, 30]])[0] + 1e-3
    p = _particles(rng)
    w = rng.random(len(p))
    means = rng.normal(40, 2, (2, 3))
    model = Ar2Model(sigma_xy=2.0, sigma_s=0.03, use_means=use_means)
    seed, step = 987654321, 5
    u0 = _core.counter_uniforms(seed, step, 2**64 - 1, 1)[0]
    normals = _core.counter_normals(seed, step, 3 * len(p)).reshape(-1, 3)
    want_p, want_w, want_mean, _ = ref.sis_step(
        p, w, means, image.bins, image.n_bins, reference, 20.0, 30.0, model.a, model.b,
        model.sigma, model.s_min, model.s_max, use_means, 20.0, kernel, u0, normals,
    )  # fmt: skip
    m_before = means.copy()
    out = _core.sis_step(
        p,
        w,
        means,
        image,
        reference,
        20.0,
        30.0,
        model.a,
        model.b,
        model.sigma,
        model.s_min,
        model.s_max,
        use_means,
        20.0,
        kernel,
        True,
        seed,
        step,
    )
    np.testing.assert_allclose(p, want_p, rtol=0, atol=1e-12)
    np.testing.assert_allclose(w, want_w, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(out["mean"], want_mean, rtol=1e-12)
    assert w[out["map_index"]] == pytest.approx(want_w.max(), rel=1e-9)
    assert out["ess"] == pytest.approx(1 / np.sum(want_w**2), rel=1e-9)
    np.testing.assert_allclose(means[0], want_mean, rtol=1e-12)
    np.testing.assert_array_equal(means[1], m_before[0])


def test_counter_normals_are_standard_normal():
    z = _core.counter_normals(1, 2, 200_000)
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1) < 0.01
    u = _core.counter_uniforms(3, 4, 0, 200_000)
    assert u.min() >= 0 and u.max() < 1 and abs(u.mean() - 0.5) < 0.005


def _scene(shift=0):
    rng = np.random.default_rng(0)
    frame = rng.integers(60, 120, (120, 160, 3), dtype=np.uint8)
    frame[40:80, 50 + shift : 70 + shift] = (20, 20, 220)  # red walker
    frame[60:80, 50 + shift : 70 + shift] = (200, 60, 20)  # blue trousers
    return frame


def test_filter_follows_a_moving_object():
    frame0 = _scene()
    image0 = hsv_bins(frame0)
    reference = box_histograms(image0, [[60, 60, 20, 40]])[0]
    f = ColourParticleFilter([60, 60, 20, 40], reference, FilterConfig(n_particles=200), rng=1)
    for t in range(1, 16):
        state = f.step(hsv_bins(_scene(shift=2 * t)))
    assert abs(state.box_cxcywh[0] - (60 + 30)) < 4
    assert abs(state.box_cxcywh[1] - 60) < 4
    assert state.rho > 0.8


def test_same_seed_same_result_and_different_seed_differs():
    image = hsv_bins(_scene(4))
    reference = box_histograms(hsv_bins(_scene()), [[60, 60, 20, 40]])[0]

    def run(seed):
        f = ColourParticleFilter([60, 60, 20, 40], reference, rng=seed)
        return np.array([f.step(image).box_cxcywh for _ in range(5)]), f.particles.copy()

    a, pa = run(3)
    b, pb = run(3)
    c, _ = run(4)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(pa, pb)
    assert not np.array_equal(a, c)


def test_four_threads_equal_serial():
    """The kernels release the GIL; results from 4 concurrent threads equal the serial ones."""
    frames = [hsv_bins(_scene(s)) for s in range(0, 40, 2)]
    reference = box_histograms(frames[0], [[60, 60, 20, 40]])[0]

    def run(seed, out, k):
        f = ColourParticleFilter(
            [60, 60, 20, 40], reference, FilterConfig(n_particles=300), rng=seed
        )
        out[k] = np.array([f.step(img).box_cxcywh for img in frames])

    serial = [None] * 8
    for k in range(8):
        run(k, serial, k)
    threaded = [None] * 8
    threads = [threading.Thread(target=run, args=(k, threaded, k)) for k in range(8)]
    for t in threads[:4]:
        t.start()
    for t in threads[:4]:
        t.join()
    for t in threads[4:]:
        t.start()
    for t in threads[4:]:
        t.join()
    for s, t in zip(serial, threaded, strict=True):
        np.testing.assert_array_equal(s, t)


def test_filter_survives_an_empty_frame_region():
    """All particles outside the image: weights stay finite (all equal), no error."""
    image = hsv_bins(_scene())
    reference = np.ones(image.n_bins)
    f = ColourParticleFilter([-500, -500, 20, 40], reference, rng=0)
    s = f.step(image)
    assert np.isfinite(s.box_cxcywh).all() and s.rho == 0.0
    assert np.allclose(f.weights, 1 / len(f.weights))


REF = np.ones(110)
BOX = [20.0, 20.0, 10.0, 10.0]


def _filter(**kw) -> ColourParticleFilter:
    return ColourParticleFilter(kw.pop("box", BOX), kw.pop("reference", REF), rng=0, **kw)


def _reinitialised(**kw) -> None:
    _filter().reinitialise(BOX, **kw)


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        # was taken: the third value dropped; (1,) gave an IndexError
        (lambda: _filter(velocity=(1, 2, 3)), ValueError, r"velocity must have shape \(2,\)"),
        (lambda: _filter(velocity=(1,)), ValueError, r"velocity must have shape \(2,\) \(vx, vy\)"),
        # was taken, then refused by box_histograms at the first step
        (lambda: _filter(box=[1e300, 20, 10, 10]), ValueError, r"box is \[1e\+300, .*within ±1e"),
        (
            lambda: _filter(box=[20, 20, 1e12, 10]),
            ValueError,
            r"box is .*, each value within ±1e\+09",
        ),
        # was taken; "a" failed inside NumPy
        (
            lambda: _reinitialised(spread=-5),
            ValueError,
            "spread is -5, expected a finite number >=",
        ),
        (lambda: _reinitialised(spread="a"), TypeError, "spread must be a number, got str 'a'"),
        # NaN was refused at the next step(), as "particles" with a non-finite value
        (lambda: _reinitialised(spread=np.nan), ValueError, "spread is nan, expected a finite"),
        (lambda: _reinitialised(velocity=(np.nan, 0)), ValueError, r"velocity is \[nan, 0.0\]"),
        (lambda: _filter(velocity=(0, np.inf)), ValueError, r"velocity is \[0.0, inf\], expected"),
        # "could not convert string to float"
        (lambda: _filter(reference=["a"] * 110), TypeError, "reference must hold real numbers"),
        (lambda: _filter(velocity=("a", "b")), TypeError, "velocity must hold real numbers"),
        (lambda: _filter(box=["a", 1, 2, 3]), TypeError, "box must hold real numbers"),
    ],
)
def test_filter_refuses_bad_arguments_at_once(call, error, match):
    with pytest.raises(error, match=match):
        call()


def _read_only(a: np.ndarray) -> np.ndarray:
    a = a.copy()
    a.setflags(write=False)
    return a


@pytest.mark.parametrize("sampler", ["sis", "mh"])  # sis_step_batch names them itself
@pytest.mark.parametrize(
    ("name", "value", "match"),
    [  # each was pybind11's list of sis_step's signatures
        (
            "particles",
            lambda p: p.astype(np.float32),
            r"particles must be .* float64 .*got float32",
        ),
        ("particles", np.asfortranarray, r"particles must be a C-contiguous.*not C-contiguous"),
        ("particles", _read_only, r"particles must be .*writeable.*read-only"),
        ("particles", lambda p: p.tolist(), r"particles must be .*float64 array.*got list"),
        ("weights", lambda w: w.astype(np.float32), r"weights must be .*float64.*got float32"),
        ("means", lambda m: m.astype(np.float32), r"means must be .*float64.*got float32"),
        ("reference", lambda r: np.vstack([r, r]), r"reference must be a \(B,\) float64 array"),
    ],
)
def test_step_names_what_it_cannot_update(sampler, name, value, match):
    from pftrack.particle_filter import MHColourParticleFilter

    image = hsv_bins(np.zeros((40, 40, 3), np.uint8))
    f = (MHColourParticleFilter if sampler == "mh" else ColourParticleFilter)(BOX, REF, rng=0)
    setattr(f, name, value(getattr(f, name)))
    with pytest.raises(TypeError, match=f"{type(f).__name__}.{match}"):
        f.step(image)


@pytest.mark.parametrize("sampler", ["sis", "mh"])
def test_step_refuses_particles_beyond_the_box_bound(sampler):
    """A user trial: particles set to 1e300 were stepped, and the filter's box was 2e300 px
    (the constructor's bound is ±1e9 px, as every box's)."""
    from pftrack.particle_filter import MHColourParticleFilter
    from pftrack.particle_filter.filter import step_filters

    image = hsv_bins(np.zeros((40, 40, 3), np.uint8))
    f = (MHColourParticleFilter if sampler == "mh" else ColourParticleFilter)(BOX, REF, rng=0)
    f.particles[3, 0] = 1e300
    with pytest.raises(ValueError, match=r"particles has a value 1e\+300 at \[3, 0\] beyond"):
        f.step(image)
    with pytest.raises(ValueError, match=r"particles has a value 1e\+300 at \[3, 0\] beyond"):
        step_filters([f], image)


def test_weights_of_no_histograms_are_refused_by_name():
    """``box_histograms`` of no boxes gives (0, B): its coefficients are empty, its weights
    (summing to 1) cannot be; the message was the core's "hists rows is 0"."""
    from pftrack.particle_filter import bhattacharyya_coefficient, bhattacharyya_weights

    empty = box_histograms(hsv_bins(np.zeros((40, 40, 3), np.uint8)), np.zeros((0, 4)))
    assert bhattacharyya_coefficient(empty, REF).shape == (0,)
    with pytest.raises(ValueError, match="bhattacharyya_weights: hists has no rows"):
        bhattacharyya_weights(empty, REF)


@pytest.mark.parametrize("frame", [np.zeros((40, 40, 3), np.uint8), None, "frame.png"])
def test_step_wants_binned_image(frame):
    from pftrack.particle_filter import MHColourParticleFilter
    from pftrack.particle_filter.filter import step_filters

    match = "image must be a BinnedImage from hsv_bins\\(frame\\), got " + type(frame).__name__
    for f in (_filter(), MHColourParticleFilter(BOX, REF, rng=0)):
        with pytest.raises(TypeError, match=match):
            f.step(frame)
    with pytest.raises(TypeError, match=match):
        step_filters([_filter()], frame)


def test_spread_keeps_the_particles_within_the_box_bound():
    # spread=1e300 was taken: particles at 1e301 px
    from pftrack.particle_filter.filter import reinitialise_filters

    f = _filter()
    before = f.particles.copy()
    match = (
        r"spread is 1e\+300, expected at most 250000: the particles' position spread, "
        r"spread \* model.sigma_xy \(4 px\), is at most 1e\+06 px"
    )
    with pytest.raises(ValueError, match=match):
        f.reinitialise([30.0, 20, 10, 10], spread=1e300)
    with pytest.raises(ValueError, match=match):
        reinitialise_filters([f], [[30.0, 20, 10, 10]], [[0.0, 0.0]], spread=1e300)
    np.testing.assert_array_equal(f.particles, before)  # refused before any change
    with pytest.raises(ValueError, match="spread is 2.5e\\+06, expected at most 250000"):
        reinitialise_filters([f], [[30.0, 20, 10, 10]], [[0.0, 0.0]], spread=2.5e6)
    f.reinitialise([30.0, 20, 10, 10], spread=250_000.0)  # the bound itself is taken
    assert np.abs(f.particles[:, :2]).max() < 1e7
    still = ColourParticleFilter(BOX, REF, FilterConfig(model=Ar2Model(sigma_xy=0.0)), rng=0)
    still.reinitialise(BOX, spread=1e300)  # no position spread at all: nothing to bound
    assert np.all(still.particles[:, :2] == BOX[:2])


def test_mixed_filters_are_refused_a_spread_before_any_is_reseeded():
    from pftrack.particle_filter.filter import reinitialise_filters

    wide = ColourParticleFilter(BOX, REF, FilterConfig(model=Ar2Model(sigma_xy=1e3)), rng=0)
    a = _filter()
    before = a.particles.copy()
    with pytest.raises(ValueError, match=r"spread is 5000, expected at most 1000"):
        reinitialise_filters([a, wide], [BOX, BOX], [[0.0, 0.0]] * 2, spread=5000.0)
    np.testing.assert_array_equal(a.particles, before)


def test_reference_length_is_the_filters_binning():
    from pftrack.particle_filter import HsvBinning, MHColourParticleFilter

    f = _filter()
    # was taken, then refused at the next step: "sis_step: ref size is 3, expected 110"
    with pytest.raises(ValueError, match=r"reference has 3 bins, expected 110 \(the filter's"):
        f.set_reference(np.ones(3))
    np.testing.assert_array_equal(f.reference, REF / REF.sum())  # unchanged
    f.set_reference(np.arange(110.0))
    small = HsvBinning(n_h=4, n_s=4, n_v=4)
    for cls in (ColourParticleFilter, MHColourParticleFilter):
        with pytest.raises(ValueError, match=r"reference has 3 bins, expected 110 \(the binning"):
            cls(BOX, np.ones(3), binning=HsvBinning())
        with pytest.raises(TypeError, match=f"{cls.__name__}: binning must be an HsvBinning"):
            cls(BOX, REF, binning=110)
        g = cls(BOX, np.ones(20), rng=0, binning=small)
        g.step(hsv_bins(_scene(), binning=small))
        with pytest.raises(ValueError, match="reference has 110 bins, expected 20"):
            g.set_reference(REF)


def test_propagate_documents_the_particle_columns():
    # help() said only "(N, 6)"
    doc = propagate.__doc__ or ""
    assert "cx, cy, s, cx', cy', s'" in doc and "previous frame's" in doc
