"""Every bad input gives a ValueError/TypeError that names the problem (never a crash)."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import (
    Ar2Model,
    BinnedImage,
    ColourParticleFilter,
    FilterConfig,
    HsvBinning,
    bhattacharyya_coefficient,
    bhattacharyya_distance,
    bhattacharyya_weights,
    box_histograms,
    estimate,
    hsv_bins,
    multinomial_resample,
    propagate,
    residual_resample,
    stratified_resample,
    systematic_resample,
)

RESAMPLERS = [systematic_resample, stratified_resample, multinomial_resample, residual_resample]


@pytest.mark.parametrize("fn", RESAMPLERS)
@pytest.mark.parametrize(
    ("weights", "match"),
    [
        ([], "weights is empty"),
        ([0.5, -0.1], r"weights\[1\] is -0.1"),
        ([0.5, np.nan], r"weights\[1\] is nan"),
        ([0.5, np.inf], r"weights\[1\] is inf"),
        ([0.0, 0.0], "sum to 0"),
        ([1e308] * 3, r"weights sum is not finite \(overflow"),  # was "sum to 0 (all ... 0"
        ([[0.5, 0.5]], "1-D"),
    ],
)
def test_resample_bad_weights(fn, weights, match):
    with pytest.raises(ValueError, match=match):
        fn(weights, rng=0)


@pytest.mark.parametrize("fn", RESAMPLERS)
def test_resample_messages_name_the_function_and_no_particle_filter(fn):
    # was "weights sum to 0 (all weights are 0: reference histogram empty, or every particle
    # outside the image?)", the particle filter's hint, for any caller of the resamplers; and
    # the 1-D and dtype errors had no "systematic_resample: " in front, as the others have
    name = fn.__name__
    with pytest.raises(
        ValueError,
        match=rf"^{name}: weights sum to 0 \(every value is 0; at least one must be > 0\)$",
    ):
        fn([0, 0, 0], rng=0)
    with pytest.raises(
        ValueError, match=rf"^{name}: weights must be 1-D \(N,\), got shape \(1, 2\)$"
    ):
        fn([[0.5, 0.5]], rng=0)
    with pytest.raises(TypeError, match=rf"^{name}: weights must be numeric, got dtype <U1$"):
        fn(["a", "b"], rng=0)
    with pytest.raises(TypeError, match=rf"^{name}: weights must be real, got dtype complex128$"):
        fn([1j, 1], rng=0)
    with pytest.raises(TypeError, match=rf"^{name}: weights must be numeric, got dtype timedelta"):
        fn(np.array([1, 2], dtype="m8[s]"), rng=0)  # NumPy's integer kind; was resampled
    with pytest.raises(
        TypeError, match=rf"^{name}: weights must be an array or a sequence, got generator"
    ):
        fn((w for w in [0.5, 0.5]), rng=0)  # was "must be numeric, got dtype object"


@pytest.mark.parametrize("fn", [*RESAMPLERS, estimate])
def test_masked_weights_are_refused_not_unmasked(fn):
    """Was: the mask dropped (np.asarray), the masked particle resampled (systematic_resample
    gave [1, 2, 3, 3], particle 3 masked; filterpy fails with an IndexError) and weighed in
    estimate's mean. A mask may mean weight 0 or a value to skip: the caller says which."""
    name = fn.__name__
    particles = np.arange(24.0).reshape(4, 6)

    def call(weights):
        return fn(particles, weights) if fn is estimate else fn(weights, rng=0)

    w = np.ma.masked_array([0.1, 0.2, 0.3, 0.4], mask=[False, False, False, True])
    with pytest.raises(TypeError) as exc:
        call(w)
    assert str(exc.value) == (
        f"{name}: weights is a numpy.ma.MaskedArray with 1 masked value, whose mask NumPy "
        "would drop (the masked values used as they are); pass weights.filled(0) to give "
        "masked particles weight 0"
    )
    plain = np.ma.masked_array([0.1, 0.2, 0.3, 0.4])  # nothing masked: its values
    np.testing.assert_array_equal(np.asarray(call(plain)), np.asarray(call(plain.data)))
    np.testing.assert_array_equal(
        np.asarray(call(w.filled(0))), np.asarray(call([0.1, 0.2, 0.3, 0]))
    )


def test_the_particle_filter_keeps_its_zero_weights_hint():
    hint = r"weights sum to 0 \(all weights are 0: reference histogram empty, or every particle"
    with pytest.raises(ValueError, match=rf"^estimate: {hint}"):
        _core.estimate(np.zeros((3, 6)), np.zeros(3))


def test_resample_wrong_type():
    with pytest.raises(TypeError, match="numeric"):
        systematic_resample(["a", "b"])


def test_core_u0_range():
    with pytest.raises(ValueError, match="u0 is 1"):
        _core.systematic_resample(np.ones(3), 1.0)
    with pytest.raises(ValueError, match="u size is 2, expected at least N"):
        _core.stratified_resample(np.ones(3), np.zeros(2))


def test_hsv_bins_bad_frames():
    with pytest.raises(TypeError, match="frame dtype is float64"):
        hsv_bins(np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match=r"shape \(H, W, 3\)"):
        hsv_bins(np.zeros((4, 4), np.uint8))
    with pytest.raises(TypeError, match="frame dtype is float32, expected uint8"):
        _core.hsv_bins(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match="frame is empty"):
        _core.hsv_bins(np.zeros((0, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="mask shape"):
        hsv_bins(np.zeros((4, 4, 3), np.uint8), np.ones((4, 5), np.uint8))
    with pytest.raises(ValueError, match="n_h is 0"):
        hsv_bins(np.zeros((4, 4, 3), np.uint8), binning=HsvBinning(n_h=0))
    for bad in (True, 4.0, "4"):  # a bool is an int to Python, not a number of bins
        with pytest.raises(
            TypeError, match=rf"HsvBinning: n_s must be an integer in \[1, 64\], got \w+ {bad!r}"
        ):
            HsvBinning(n_s=bad)  # type: ignore[arg-type]
    # named with the class: Ar2Model has an s_min too (a scale), so "s_min is 2" alone was
    # ambiguous inside a TrackerConfig
    with pytest.raises(
        ValueError, match=r"^HsvBinning: s_min is 2\.0, expected a value in \[0, 1\]"
    ):
        hsv_bins(np.zeros((4, 4, 3), np.uint8), binning=HsvBinning(s_min=2.0))
    with pytest.raises(ValueError, match=r"^HsvBinning: v_min is nan"):
        HsvBinning(v_min=float("nan"))


def test_box_histograms_bad_boxes():
    image = hsv_bins(np.zeros((8, 8, 3), np.uint8))
    with pytest.raises(ValueError, match=r"boxes\[1\] is \(1, 1, nan, 2\)"):
        box_histograms(image, [[1, 1, 2, 2], [1, 1, np.nan, 2]])
    with pytest.raises(ValueError, match="w, h >= 0"):
        box_histograms(image, [[1, 1, -2, 2]])
    with pytest.raises(ValueError, match="boxes cols is 3"):
        box_histograms(image, [[1, 1, 2]])
    with pytest.raises(ValueError, match="kernel is 'gauss'"):
        box_histograms(image, [[1, 1, 2, 2]], kernel="gauss")


def test_binned_image_rejects_out_of_range_bins():
    with pytest.raises(ValueError, match="bins value is 7, expected in \\[-1, n_bins\\)"):
        _core.BinnedImage(np.array([[0, 7]], np.int16), 5)
    with pytest.raises(ValueError, match="bins value is -2"):
        _core.BinnedImage(np.array([[0, -2]], np.int16), 5)


def test_binned_image_names_a_bad_n_bins_or_bins():
    # were pybind11's "incompatible constructor arguments" and its list of signatures (2**31,
    # a list), and n_bins=True taken as 1 bin
    bins = np.zeros((2, 2), np.int16)
    with pytest.raises(
        ValueError, match=r"n_bins is 2147483648, expected an integer in \[1, 32767\]"
    ):
        _core.BinnedImage(bins, 2**31)
    with pytest.raises(ValueError, match="n_bins is 10{30}, expected"):
        _core.BinnedImage(bins, 10**30)
    for bad, kind in ((True, "bool"), (2.0, "float"), ("3", "str")):
        with pytest.raises(TypeError, match=f"BinnedImage: n_bins must be an int, got {kind}"):
            _core.BinnedImage(bins, bad)
    with pytest.raises(ValueError, match="bins must be an \\(H, W\\) array .* got a list"):
        _core.BinnedImage([[0, 1], [1]], 3)
    listed = _core.BinnedImage([[0, 1], [2, -1]], np.int64(3))  # a list, a NumPy integer
    assert listed.n_bins == 3


def test_likelihood_bad_inputs():
    h = np.full((2, 4), 0.25)
    with pytest.raises(ValueError, match="ref size is 3, expected 4"):
        bhattacharyya_weights(h, np.ones(3))
    with pytest.raises(ValueError, match="ref sums to 0"):
        bhattacharyya_weights(h, np.zeros(4))
    with pytest.raises(ValueError, match=r"ref sum is not finite \(overflow"):
        bhattacharyya_weights(h, np.full(4, 1e308))
    with pytest.raises(ValueError, match=r"hists\[1, 2\] is nan"):
        bad = h.copy()
        bad[1, 2] = np.nan
        bhattacharyya_weights(bad, np.ones(4))
    with pytest.raises(ValueError, match="lam is -1"):
        bhattacharyya_weights(h, np.ones(4), lam=-1)
    with pytest.raises(ValueError, match="lambda is -1"):  # the core's own check
        _core.bhattacharyya_weights(h, np.ones(4), -1.0)
    with pytest.raises(TypeError, match="hists must hold real numbers"):
        bhattacharyya_weights(h.astype(complex), np.ones(4))


def test_propagate_bad_inputs():
    p = np.zeros((5, 6))
    p[:, 2] = p[:, 5] = 1
    with pytest.raises(ValueError, match=r"noise shape is \(4, 3\), expected \(5, 3\)"):
        propagate(p, np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"particles has a non-finite value nan at \[0, 0\]"):
        q = p.copy()
        q[0, 0] = np.nan
        propagate(q, np.zeros((5, 3)))
    with pytest.raises(ValueError, match="C-contiguous"):
        propagate(np.asfortranarray(p), np.zeros((5, 3)))
    with pytest.raises(TypeError, match="float64"):
        propagate(p.astype(np.float32), np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"particles shape is \(5, 5\), expected \(N, 6\)"):
        propagate(np.zeros((5, 5)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match="means are required"):
        propagate(p, np.zeros((5, 3)), Ar2Model(use_means=True))
    with pytest.raises(ValueError, match="sigma_xy is -1"):
        Ar2Model(sigma_xy=-1)


def _read_only(shape: tuple[int, ...]) -> np.ndarray:
    a = np.ones(shape)
    a.flags.writeable = False
    return a


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        # was pybind11's "incompatible function arguments" with every signature (20 lines)
        (
            lambda: propagate(_read_only((3, 6)), np.zeros((3, 3))),
            ValueError,
            r"^propagate: particles must be a C-contiguous, writeable float64 array \(updated in "
            r"place, never copied\), got a read-only one$",
        ),
        (
            lambda: propagate(np.ones((1, 6, 1)), np.zeros((1, 3))),
            ValueError,
            r"^propagate: particles shape is \(1, 6, 1\), expected \(N, 6\)",
        ),
        (lambda: propagate([[1.0] * 6], np.zeros((1, 3))), TypeError, "particles must be a C-"),
        # was "particles cols is 1, expected 6"
        (
            lambda: propagate(np.ones(6), np.zeros((1, 3))),
            ValueError,
            r"^propagate: particles shape is \(6,\), expected \(N, 6\) with N >= 1",
        ),
        # was AttributeError: 'NoneType' object has no attribute 'use_means'
        (
            lambda: propagate(np.ones((1, 6)), np.zeros((1, 3)), None),
            TypeError,
            "^propagate: model must be an Ar2Model, got NoneType None$",
        ),
        # was NumPy's "could not convert string to float: 'a'"
        (
            lambda: propagate(np.ones((3, 6)), [["a"] * 3] * 3),
            TypeError,
            "^propagate: noise must hold real numbers, got dtype <U1$",
        ),
        (
            lambda: propagate(np.ones((1, 6)), np.zeros((1, 3)), means=[["a"] * 3] * 2),
            TypeError,
            "^propagate: means must hold real numbers",
        ),
        # was "noise rows is 3, expected 1"
        (
            lambda: propagate(np.ones((1, 6)), np.zeros(3)),
            ValueError,
            r"^propagate: noise shape is \(3,\), expected \(1, 3\)",
        ),
    ],
)
def test_propagate_names_the_bad_argument(call, error, match):
    with pytest.raises(error, match=match):
        call()


@pytest.mark.parametrize(
    ("particles", "model", "means", "match"),
    [
        # was [[inf 0 1 1e308 0 1]], silently
        ([[1e308, 0, 1, -1e308, 0, 1]], Ar2Model(), None, "particle 0's new cx is inf"),
        (
            [[1, 0, 1, 1, 0, 1], [0, 1e308, 1, 0, -1e308, 1]],
            Ar2Model(),
            None,
            "particle 1's new cy is inf",
        ),
        (
            [[1, 0, 1, 1, 0, 1]],
            Ar2Model(use_means=True),
            [[1e308] * 3, [-1e308] * 3],
            "particle 0's new cx is inf",
        ),
    ],
)
def test_propagate_refuses_an_overflow_and_leaves_the_particles(particles, model, means, match):
    p = np.array(particles, dtype=np.float64)
    before = p.copy()
    with pytest.raises(ValueError, match=f"^propagate: {match}: the step overflowed"):
        propagate(p, np.zeros((len(p), 3)), model, means)
    np.testing.assert_array_equal(p, before)
    # the same particles one step later than the largest finite ones: still a step
    p[np.abs(p) == 1e308] /= 4
    propagate(p, np.zeros((len(p), 3)), model, None if means is None else np.array(means) / 4)
    assert np.isfinite(p).all()


@pytest.mark.parametrize("lam", [0.0, -1.0, np.inf, np.nan])
def test_filter_config_and_bhattacharyya_weights_agree_on_lam(lam):
    # FilterConfig(lam=0) was accepted (a filter blind to colour: every particle weighs the
    # same) while bhattacharyya_weights(..., lam=0) was refused
    with pytest.raises(
        ValueError, match=f"^FilterConfig: lam is {lam}, expected a finite number > 0"
    ):
        FilterConfig(lam=lam)
    with pytest.raises(
        ValueError, match=f"^bhattacharyya_weights: lam is {lam}, expected a finite number > 0$"
    ):
        bhattacharyya_weights(np.ones((2, 4)), np.ones(4), lam=lam)
    FilterConfig(lam=1e-9)  # any positive lam is a colour likelihood
    bhattacharyya_weights(np.ones((2, 4)), np.ones(4), lam=1e-9)


def test_filter_bad_inputs():
    ref = np.ones(110)
    with pytest.raises(ValueError, match="box is"):
        ColourParticleFilter([0, 0, 0, 10], ref)
    with pytest.raises(ValueError, match="reference histogram"):
        ColourParticleFilter([5, 5, 10, 10], np.zeros(110))
    with pytest.raises(ValueError, match="n_particles is 0"):
        FilterConfig(n_particles=0)
    f = ColourParticleFilter([5, 5, 4, 4], np.ones(7), rng=0)
    image = hsv_bins(np.zeros((10, 10, 3), np.uint8))
    with pytest.raises(
        ValueError, match=r"ColourParticleFilter.step: reference has 7 bins, the image 110"
    ):
        f.step(image)


def test_arrays_through_pickle_are_accepted():
    # an array that went through pickle has an equal but distinct dtype object
    import pickle

    frame = pickle.loads(pickle.dumps(np.zeros((8, 8, 3), np.uint8)))
    mask = pickle.loads(pickle.dumps(np.ones((8, 8), np.uint8)))
    binned = _core.hsv_bins(frame, mask)
    assert binned.shape == (8, 8)
    boxes = pickle.loads(pickle.dumps(np.array([[1.0, 1.0, 4.0, 4.0]])))
    assert _core.refine_boxes(boxes, mask, 0.05, 0.1).shape == (1, 4)
    with pytest.raises(TypeError, match="frame dtype is >u2"):
        _core.hsv_bins(np.zeros((8, 8, 3), ">u2"), None)


IMAGE = hsv_bins(np.zeros((8, 8, 3), np.uint8))


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        # each was pybind11's list of box_histograms' signatures
        (
            lambda: box_histograms(np.zeros((8, 8, 3), np.uint8), [[1, 1, 2, 2]]),
            TypeError,
            r"box_histograms: image must be a BinnedImage from hsv_bins\(frame\), got ndarray "
            r"\(a frame\? bin it first\)",
        ),
        (lambda: box_histograms(None, [[1, 1, 2, 2]]), TypeError, "got NoneType"),
        (
            lambda: box_histograms(IMAGE, np.ones((2, 2, 4))),
            ValueError,
            r"box_histograms: boxes must have shape \(K, 4\) \(cx, cy, w, h\), got \(2, 2, 4\)",
        ),
        # was cast to its real part with a ComplexWarning; "could not convert string to float"
        (lambda: box_histograms(IMAGE, np.ones((1, 4)) + 0j), TypeError, "boxes must hold real"),
        (lambda: box_histograms(IMAGE, [["a"] * 4]), TypeError, "boxes must hold real numbers"),
        # was "expected finite (cx, cy, w, h) with w, h >= 0", not saying the limit
        (
            lambda: box_histograms(IMAGE, [[20, 20, 1e12, 10]]),
            ValueError,
            r"boxes\[0\] is \(20, 20, 1e\+12, 10\), expected .* within ±1e\+09 px",
        ),
        # was pybind11's list of signatures
        (
            lambda: bhattacharyya_weights(np.ones((2, 4)), np.ones((2, 4))),
            ValueError,
            r"bhattacharyya_weights: ref must have shape \(B,\), one histogram, got \(2, 4\)",
        ),
        # each began "bhattacharyya_coefficient:", the core's inner function
        (
            lambda: bhattacharyya_distance(np.ones((2, 4)), np.ones(3)),
            ValueError,
            "^bhattacharyya_distance: ref size is 3, expected 4",
        ),
        (
            lambda: bhattacharyya_weights([[1.0, -1.0]], np.ones(2)),
            ValueError,
            r"^bhattacharyya_weights: hists\[0, 1\] is -1",
        ),
        # was "ref sum to 0 (all weights are 0: ... every particle outside the image?)"
        (
            lambda: bhattacharyya_distance(np.ones((2, 4)), np.zeros(4)),
            ValueError,
            r"^bhattacharyya_distance: ref sums to 0 \(an empty reference histogram",
        ),
        (
            lambda: bhattacharyya_coefficient(np.ones((2, 4)), np.zeros(4)),
            ValueError,
            "^bhattacharyya_coefficient: ref sums to 0",
        ),
        # was the wrapped int16 value 4464; 1.5 was read as 1
        (
            lambda: BinnedImage(np.full((2, 2), 70000, np.int32), 110),
            ValueError,
            r"BinnedImage: bins value is 70000, expected in \[-1, n_bins\)",
        ),
        (
            lambda: BinnedImage(np.array([[0, 64000]], np.uint16), 5),
            ValueError,
            "bins value is 64000",
        ),
        (lambda: BinnedImage(np.array([[0.0, 1.5]]), 5), ValueError, "bins value is 1.5"),
        (lambda: BinnedImage(np.array([["a"]]), 5), TypeError, "bins must hold bin indices"),
        # was AttributeError: 'str' object has no attribute 'n_h'
        (
            lambda: hsv_bins(np.zeros((4, 4, 3), np.uint8), binning="x"),
            TypeError,
            "hsv_bins: binning must be an HsvBinning, got str 'x'",
        ),
    ],
)
def test_colour_entry_points_name_the_argument(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_box_histograms_takes_an_empty_list_as_no_box():
    # was "boxes cols is 0", where np.zeros((0, 4)) was taken
    assert box_histograms(IMAGE, []).shape == (0, IMAGE.n_bins)
    assert box_histograms(IMAGE, np.zeros((0, 4))).shape == (0, IMAGE.n_bins)


def test_binned_image_from_wider_integers_keeps_the_bins():
    bins = np.array([[0, 4, -1]], np.int64)
    np.testing.assert_array_equal(BinnedImage(bins, 5).bins, bins)
    np.testing.assert_array_equal(BinnedImage(bins.astype(float), 5).bins, bins)


def test_mh_step_takes_and_checks_min_samples():
    """mh_step takes sis_step's min_samples (was refused as an unknown argument, so the fuzz
    target, which passes it, never reached the kernel) and checks it as sis_step does."""
    image = _core.hsv_bins(np.zeros((20, 20, 3), np.uint8), None, 4, 4, 4)
    args = (np.tile([10.0, 10, 1, 10, 10, 1], (4, 1)), np.full(4, 0.25),
            np.tile([10.0, 10, 1], (2, 1)), image, np.ones(20), 4.0, 4.0, [2.0] * 3, [-1.0] * 3,
            [1.0, 1.0, 0.01], 0.5, 2.0, False, 20.0, "uniform", True, 1, 0)  # fmt: skip
    for bad in (np.nan, -1.0, np.inf):
        with pytest.raises(ValueError, match="mh_step: min_samples must be finite and >= 0"):
            _core.mh_step(*[a.copy() if isinstance(a, np.ndarray) else a for a in args],
                          min_samples=bad)  # fmt: skip
    out = _core.mh_step(*args, min_samples=3.0)
    assert np.isfinite(out["rho_mean"])


def _masked_calls():
    """(name, call, values, argument): every kernel-level entry point that takes arrays of
    numbers, `call` giving it `values` as its `argument` and returning an array."""
    from pftrack import Tracker, fill_gaps, goal_directed_path, recover_gap
    from pftrack.kalman import rts_smooth

    frame = np.zeros((20, 30, 3), np.uint8)
    frame[5:15, 10:20] = (0, 0, 255)
    image = hsv_bins(frame)
    ref = box_histograms(image, [[15, 10, 10, 10]])[0]
    eye = np.eye(2)
    seg_b = [[7, 6, 6], [8, 7, 7.0]]
    rows = [[f, 1, 2.0 * f, 5, 4, 8, 1, -1, -1, -1] for f in (1, 2, 3, 6, 7)]
    particles = np.tile([15.0, 10, 1, 15, 10, 1], (4, 1))

    def moved(noise):
        p = particles.copy()
        propagate(p, noise)
        return p

    return [
        ("hsv_bins", lambda f: hsv_bins(f).bins, frame, "frame"),
        ("box_histograms", lambda b: box_histograms(image, b), [[15, 10, 10, 10.0]], "boxes"),
        ("bhattacharyya_coefficient", lambda r: bhattacharyya_coefficient([ref], r), ref, "ref"),
        ("bhattacharyya_distance", lambda h: bhattacharyya_distance(h, ref), [ref, ref], "hists"),
        ("bhattacharyya_weights", lambda h: bhattacharyya_weights(h, ref), [ref, ref], "hists"),
        ("propagate", moved, np.ones((4, 3)), "noise"),
        ("estimate", lambda p: estimate(p, [1, 2, 3, 4])[0], particles, "particles"),
        (
            "ColourParticleFilter",
            lambda r: ColourParticleFilter([15, 10, 10, 10], r).reference,
            ref,
            "reference",
        ),
        (
            "recover_gap",
            lambda a: recover_gap(a, seg_b, method="linear"),
            [[1, 0, 0], [2, 1, 1], [3, 2, 2.0]],
            "segment_a",
        ),
        (
            "rts_smooth",
            lambda z: rts_smooth(z, [1, 1, 1], [1], [1], velocity_sd=1.0, update_first=True),
            [[0.0], [1], [2]],
            "z",
        ),
        (
            "goal_directed_path",
            lambda m: goal_directed_path(eye, eye, eye, eye, m, eye, [4, 2], 3).path,
            [0.0, 1.0],
            "m0",
        ),
        ("fill_gaps", lambda r: fill_gaps(r, "linear")[0], rows, "tracks"),
        (
            "Tracker.update",
            lambda d: Tracker(seed=0).update(d, frame),
            [[10, 5, 20, 15, 0.9, 0]],
            "dets",
        ),
    ]


@pytest.mark.parametrize("case", _masked_calls(), ids=lambda c: c[0])
def test_masked_arrays_are_refused_wherever_arrays_are_taken(case):
    """Was: the mask dropped (np.asarray) and the values under it used, with no word: a
    masked row of segment_a recovered from (recover_gap's path went through the masked
    point), a masked box or histogram bin counted, a masked detection tracked. As for the
    resamplers' weights (above), the caller says what a masked entry stands for."""
    _, call, values, arg = case
    a = np.asarray(values)
    mask = np.zeros(a.shape, bool)
    mask.flat[-1] = True
    with pytest.raises(TypeError, match=r"is a numpy\.ma\.MaskedArray with 1 masked value, ") as e:
        call(np.ma.masked_array(a, mask=mask))
    assert arg in str(e.value)
    assert "\n" not in str(e.value)
    # nothing masked: the array's values, as before
    np.testing.assert_array_equal(call(np.ma.masked_array(a.copy())), call(a.copy()))
