"""Large boxes counted on a lattice (``FilterConfig.min_samples``): the C++ counts against the
NumPy reference, the step rule, what the lattice reads, and the filter's results."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import Ar2Model, ColourParticleFilter, FilterConfig, hsv_bins
from pftrack.particle_filter.filter import step_filters
from tests.reference import kernels as ref


@pytest.fixture
def big_frame(rng: np.random.Generator) -> np.ndarray:
    frame = rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)
    frame[40:200, 100:160] = (30, 40, 200)  # a red walker (BGR)
    frame[120:200, 100:160] = (200, 120, 20)  # in blue trousers
    return frame


def _boxes(rng: np.random.Generator, n: int = 40) -> np.ndarray:
    b = np.column_stack(
        [
            rng.uniform(-30, 350, n),
            rng.uniform(-30, 270, n),
            rng.uniform(0, 200, n),
            rng.uniform(0, 260, n),
        ]
    )
    b[:4] = [[130, 120, 60, 160], [0, 0, 7, 7], [319.6, 239.6, 3, 3], [130.3, 120.7, 61.1, 159.4]]
    return b


@pytest.mark.parametrize("step", [1, 2, 3, 5, 8])
@pytest.mark.parametrize("kernel", ["uniform", "epanechnikov"])
def test_box_weights_on_a_lattice_match_numpy(big_frame, rng, kernel, step):
    mask = np.zeros(big_frame.shape[:2], np.uint8)
    mask[20:220, 60:260] = 1
    image = hsv_bins(big_frame, mask)
    boxes = _boxes(rng)
    r = ref.box_histograms(image.bins, image.n_bins, [[130, 120, 60, 160]])[0] + 1e-3
    want = ref.bhattacharyya_weights(
        ref.box_histograms(image.bins, image.n_bins, boxes, kernel, step), r, 20.0
    )
    got = _core.box_weights(image, boxes, r, 20.0, kernel, "auto", step)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-300)


def test_lattice_step_one_is_every_pixel(big_frame, rng):
    image = hsv_bins(big_frame)
    boxes = _boxes(rng)
    r = np.ones(image.n_bins)
    for method in ("auto", "direct", "integral"):
        np.testing.assert_array_equal(
            _core.box_weights(image, boxes, r, 20.0, "uniform", method, 1),
            _core.box_weights(image, boxes, r, 20.0, "uniform", method),
        )


def test_lattice_reads_only_its_points(big_frame):
    """Pixels off the lattice may change without changing the weights; a lattice pixel cannot."""
    boxes = np.array([[130.0, 120.0, 60.0, 160.0], [160.0, 100.0, 90.0, 90.0]])
    r = np.ones(110)
    step = 4
    before = _core.box_weights(hsv_bins(big_frame), boxes, r, 20.0, "uniform", "auto", step)
    off = big_frame.copy()
    ys, xs = np.mgrid[0 : off.shape[0], 0 : off.shape[1]]
    off[(ys % step != 0) | (xs % step != 0)] = (0, 255, 0)
    after = _core.box_weights(hsv_bins(off), boxes, r, 20.0, "uniform", "auto", step)
    np.testing.assert_array_equal(after, before)
    on = big_frame.copy()
    on[(ys % step == 0) & (xs % step == 0) & (ys < 120)] = (0, 255, 0)
    moved = _core.box_weights(hsv_bins(on), boxes, r, 20.0, "uniform", "auto", step)
    assert not np.allclose(moved, before)


def test_box_weights_refuses_a_bad_step(big_frame):
    image = hsv_bins(big_frame)
    for step in (0, -1, 65):
        with pytest.raises(ValueError, match="step"):
            _core.box_weights(image, np.array([[50.0, 50.0, 10.0, 10.0]]), np.ones(110), 20.0,
                              "uniform", "auto", step)  # fmt: skip


@pytest.mark.parametrize(
    ("w", "h", "min_samples", "step"),
    [
        (30, 80, 2048, 1),  # a PETS09 walker: every pixel
        (90, 90, 2048, 1),  # 8100 < 4 x 2048
        (91, 91, 2048, 2),  # 8281: the first box on a lattice
        (90, 240, 2048, 3),
        (250, 600, 2048, 8),
        (1e5, 1e5, 1, 64),  # capped
        (90, 240, 0, 1),  # 0: every pixel
        (float("nan"), 10, 2048, 1),
        (22, 98, 1, 11),  # half the shorter side (was 46: 0-2 pixels of the box)
        (3, 4000, 1, 1),
    ],
)
def test_lattice_step_rule(w, h, min_samples, step):
    assert ref.lattice_step(w, h, min_samples) == step


def test_a_small_min_samples_still_sees_the_box() -> None:
    """min_samples 1 on a 22x98 walker: on the frame its reference came from, the filter
    scores it as every pixel does (was rho 0.54 against 0.99: 46-pixel steps)."""
    from pftrack.particle_filter import box_histograms
    from pftrack.synthetic import make_scene

    frame = make_scene(n_frames=3, rng=0).frames[1]
    image = hsv_bins(frame)
    box = np.array([112.0, 201.0, 22.0, 98.0])
    reference = box_histograms(image, box)[0]
    every = ColourParticleFilter(box, reference, FilterConfig(min_samples=0), rng=0).step(image)
    few = ColourParticleFilter(box, reference, FilterConfig(min_samples=1), rng=0).step(image)
    assert every.rho > 0.95 and few.rho > 0.85, (every.rho, few.rho)
    assert few.foreground < 1.2 * 22 * 98  # an estimate of the pixels counted (was 4230)


@pytest.mark.parametrize("kernel", ["uniform", "epanechnikov"])
@pytest.mark.parametrize("min_samples", [0, 200, 1000, 3000])
def test_sis_step_with_min_samples_matches_numpy(big_frame, rng, kernel, min_samples):
    mask = np.zeros(big_frame.shape[:2], np.uint8)
    mask[20:220, 60:260] = 1
    image = hsv_bins(big_frame, mask)
    reference = ref.box_histograms(image.bins, image.n_bins, [[130, 120, 60, 160]])[0] + 1e-3
    n = 64
    p = np.empty((n, 6))
    p[:, :2] = rng.normal((130, 120), 6, (n, 2))
    p[:, 2] = rng.uniform(0.9, 1.1, n)
    p[:, 3:5] = p[:, :2] - rng.normal(1, 1, (n, 2))
    p[:, 5] = p[:, 2]
    w = rng.random(n)
    means = np.array([[130.0, 120.0, 1.02], [129.0, 119.0, 1.0]])
    model = Ar2Model(sigma_xy=2.0, sigma_s=0.03, s_min=0.5, s_max=2.0)
    seed, step = 424242, 3
    u0 = _core.counter_uniforms(seed, step, 2**64 - 1, 1)[0]
    normals = _core.counter_normals(seed, step, 3 * n).reshape(-1, 3)
    k = ref.lattice_step(1.02 * 60, 1.02 * 160, min_samples)
    assert k == {0: 1, 200: 7, 1000: 3, 3000: 1}[min_samples]
    want_p, want_w, want_mean, _ = ref.sis_step(
        p, w, means, image.bins, image.n_bins, reference, 60.0, 160.0, model.a, model.b,
        model.sigma, model.s_min, model.s_max, False, 20.0, kernel, u0, normals, min_samples,
    )  # fmt: skip
    out = _core.sis_step(
        p, w, means, image, reference, 60.0, 160.0, model.a, model.b, model.sigma, model.s_min,
        model.s_max, False, 20.0, kernel, True, seed, step, float(min_samples),
    )  # fmt: skip
    np.testing.assert_allclose(p, want_p, rtol=0, atol=1e-12)
    np.testing.assert_allclose(w, want_w, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(out["mean"], want_mean, rtol=1e-12)


def test_batch_equals_one_by_one_on_a_lattice(big_frame):
    """step_filters (one C++ call) and each filter's step give the same states with a lattice."""
    cfg = FilterConfig(n_particles=80, min_samples=300)
    image = hsv_bins(big_frame)
    boxes = [(130, 120, 60, 160), (200, 100, 80, 120), (60, 60, 20, 30)]

    def filters() -> list[ColourParticleFilter]:
        return [
            ColourParticleFilter(
                b, _core.box_histograms(image, np.array([b], float))[0] + 1e-3, cfg, rng=i
            )  # fmt: skip
            for i, b in enumerate(boxes)
        ]

    batch, single = filters(), filters()
    for _ in range(3):
        states = step_filters(batch, image)
        for f, st in zip(single, states, strict=True):
            one = f.step(image)
            np.testing.assert_array_equal(one.box_cxcywh, st.box_cxcywh)
            assert one.rho == st.rho


def test_min_samples_is_checked():
    with pytest.raises(ValueError, match=r"^FilterConfig: min_samples is -1, expected an int"):
        FilterConfig(min_samples=-1)
    for bad in (1.5, True, "2048"):  # a wrong type: TypeError as a number's (was ValueError)
        with pytest.raises(TypeError, match=r"^FilterConfig: min_samples must be an integer in"):
            FilterConfig(min_samples=bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="min_samples"):
        _core.sis_step(
            np.zeros((4, 6)) + 10, np.full(4, 0.25), np.full((2, 3), 10.0),
            hsv_bins(np.zeros((32, 32, 3), np.uint8)), np.ones(110), 5.0, 5.0, np.ones(3),
            np.zeros(3), np.ones(3), 0.5, 2.0, False, 20.0, "uniform", True, 1, 0, -1.0,
        )  # fmt: skip


def test_a_lattice_tracks_like_every_pixel(big_frame):
    """A walker of 60x160 px moving 3 px a frame: the lattice filter (step 3) stays on it as
    the full count does."""
    rng = np.random.default_rng(5)
    got = {}
    for ms in (0, 1024):
        cfg = dataclasses.replace(FilterConfig(n_particles=150), min_samples=ms)
        background = rng.integers(0, 256, big_frame.shape, dtype=np.uint8)
        for t in range(12):
            frame = background.copy()
            x = 60 + 3 * t
            frame[40:200, x : x + 60] = (30, 40, 200)
            frame[120:200, x : x + 60] = (200, 120, 20)
            image = hsv_bins(frame)
            if t == 0:
                box = np.array([[x + 30.0, 120.0, 60.0, 160.0]])
                f = ColourParticleFilter(box[0], _core.box_histograms(image, box)[0], cfg, rng=1)
            else:
                st = f.step(image)
        got[ms] = st.box_cxcywh[0]
    assert ref.lattice_step(60, 160, 1024) == 3
    assert abs(got[0] - (60 + 33 + 30)) < 3
    assert abs(got[1024] - (60 + 33 + 30)) < 3
