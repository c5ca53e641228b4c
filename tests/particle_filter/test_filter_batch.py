"""One C++ call for every object's filter step: sis_step_batch and step_filters against the
per-object sis_step / ColourParticleFilter.step (bit for bit) and the NumPy composition, and
the tracker's predict_tracks against LiveTrack.predict."""

from __future__ import annotations

import copy
import re
import threading

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import (
    Ar2Model,
    ColourParticleFilter,
    FilterConfig,
    HsvBinning,
    MHColourParticleFilter,
    box_histograms,
    hsv_bins,
)
from pftrack.particle_filter.filter import (
    reinitialise_filters,
    step_filters,
    step_filters_summary,
)
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.track import LiveTrack, follow_tracks_motion, predict_tracks, reseed_tracks
from tests.particle_filter.test_filter import _particles
from tests.reference import kernels as ref


def _objects(rng: np.random.Generator, image: _core.BinnedImage, k: int) -> list[dict]:
    objs = []
    for i in range(k):
        box = [25 + 8 * i, 20 + 5 * i, 16 + 2 * i, 24 + i]
        objs.append(
            {
                "p": _particles(rng, 20 + 13 * i),  # a different N per object
                "w": rng.random(20 + 13 * i) + 0.01,
                "m": rng.normal(40, 2, (2, 3)),
                "ref": box_histograms(image, [box])[0] + 1e-3,
                "w0": float(box[2]),
                "h0": float(box[3]),
                "seed": int(rng.integers(2**63)),
                "step": int(rng.integers(0, 50)),
            }
        )
    return objs


@pytest.mark.parametrize("kernel", ["uniform", "epanechnikov"])
@pytest.mark.parametrize("use_means", [False, True])
def test_batch_equals_per_object_sis_step_bit_for_bit(textured_frame, rng, kernel, use_means):
    mask = np.zeros(textured_frame.shape[:2], np.uint8)
    mask[5:70, 10:90] = 1
    image = hsv_bins(textured_frame, mask)
    model = Ar2Model(sigma_xy=2.0, sigma_s=0.03, use_means=use_means)
    objs = _objects(rng, image, 5)
    single = copy.deepcopy(objs)
    args = (model.a, model.b, model.sigma, model.s_min, model.s_max, use_means, 20.0, kernel, True)
    out = _core.sis_step_batch(
        [o["p"] for o in objs], [o["w"] for o in objs], [o["m"] for o in objs], image,
        [o["ref"] for o in objs], np.array([o["w0"] for o in objs]),
        np.array([o["h0"] for o in objs]), *args, [o["seed"] for o in objs],
        [o["step"] for o in objs],
    )  # fmt: skip
    assert out.shape == (5, 11)
    for o, s, row in zip(objs, single, out, strict=True):
        r = _core.sis_step(s["p"], s["w"], s["m"], image, s["ref"], s["w0"], s["h0"], *args,
                           s["seed"], s["step"])  # fmt: skip
        np.testing.assert_array_equal(o["p"], s["p"])
        np.testing.assert_array_equal(o["w"], s["w"])
        np.testing.assert_array_equal(o["m"], s["m"])
        want = [*r["mean"], *r["map"], r["map_index"], r["ess"], r["rho_max"], r["rho_mean"]]
        np.testing.assert_array_equal(row, [*want, r["fg_mean"]])


@pytest.mark.parametrize("min_samples", [0.0, 20.0])
def test_batch_scratch_reused_across_objects_of_any_size(textured_frame, rng, min_samples):
    """One batch reuses its count scratch (integral tables, per-box counts) from object to
    object: large boxes, then small, then large again, one far outside the image, each on the
    lattice or not, give what one sis_step per object gives, bit for bit."""
    image = hsv_bins(textured_frame)
    model = Ar2Model(sigma_xy=2.0, sigma_s=0.03)
    sizes = [(40.0, 60.0), (4.0, 6.0), (50.0, 70.0), (10.0, 12.0), (30.0, 30.0)]
    objs = _objects(rng, image, len(sizes))
    for o, (w0, h0) in zip(objs, sizes, strict=True):
        o["w0"], o["h0"] = w0, h0
    objs[3]["p"][:, [0, 3]] -= 500.0  # every box outside the image: rho 0
    objs[3]["m"][:, 0] -= 500.0
    single = copy.deepcopy(objs)
    args = (model.a, model.b, model.sigma, model.s_min, model.s_max, False, 20.0, "uniform", True)
    out = _core.sis_step_batch(
        [o["p"] for o in objs], [o["w"] for o in objs], [o["m"] for o in objs], image,
        [o["ref"] for o in objs], np.array([o["w0"] for o in objs]),
        np.array([o["h0"] for o in objs]), *args, [o["seed"] for o in objs],
        [o["step"] for o in objs], min_samples,
    )  # fmt: skip
    assert out[3, 8] == 0.0  # rho_max of the object outside the image
    assert np.all(out[[0, 2, 4], 8] > 0.0)
    for o, s, row in zip(objs, single, out, strict=True):
        r = _core.sis_step(s["p"], s["w"], s["m"], image, s["ref"], s["w0"], s["h0"], *args,
                           s["seed"], s["step"], min_samples)  # fmt: skip
        np.testing.assert_array_equal(o["p"], s["p"])
        np.testing.assert_array_equal(o["w"], s["w"])
        want = [*r["mean"], *r["map"], r["map_index"], r["ess"], r["rho_max"], r["rho_mean"]]
        np.testing.assert_array_equal(row, [*want, r["fg_mean"]])


def _batch(image: _core.BinnedImage, objs: list[dict], min_samples: float) -> np.ndarray:
    model = Ar2Model(sigma_xy=2.0, sigma_s=0.03)
    args = (model.a, model.b, model.sigma, model.s_min, model.s_max, False, 20.0, "uniform", True)
    return _core.sis_step_batch(
        [o["p"] for o in objs], [o["w"] for o in objs], [o["m"] for o in objs], image,
        [o["ref"] for o in objs], np.array([o["w0"] for o in objs]),
        np.array([o["h0"] for o in objs]), *args, [o["seed"] for o in objs],
        [o["step"] for o in objs], min_samples,
    )  # fmt: skip


@pytest.mark.parametrize("min_samples", [0.0, 20.0])
def test_batch_workspace_kept_across_calls_carries_nothing(textured_frame, rng, min_samples):
    """The thread's workspace (integral tables, per-particle arrays) outlives a call: a step
    after calls on other images (larger boxes, other bin counts, more particles) gives what
    the first call of a fresh thread gives, bit for bit."""
    image = hsv_bins(textured_frame)
    objs = _objects(rng, image, 3)
    fresh = copy.deepcopy(objs)
    out: list[np.ndarray] = []
    worker = threading.Thread(target=lambda: out.append(_batch(image, fresh, min_samples)))
    worker.start()
    worker.join()

    big = np.tile(textured_frame, (3, 3, 1))  # larger regions, then other bins
    for other in (hsv_bins(big), hsv_bins(big, binning=HsvBinning(n_h=6, n_s=6, n_v=4))):
        others = _objects(rng, other, 4)
        for o in others:
            o["p"] = np.tile(o["p"], (5, 1))  # more particles than `objs` have
            o["w"] = np.tile(o["w"], 5)
            o["w0"], o["h0"] = 90.0, 120.0
        _batch(other, others, min_samples)
    again = _batch(image, objs, min_samples)
    np.testing.assert_array_equal(again, out[0])
    for o, f in zip(objs, fresh, strict=True):
        np.testing.assert_array_equal(o["p"], f["p"])
        np.testing.assert_array_equal(o["w"], f["w"])
        np.testing.assert_array_equal(o["m"], f["m"])


def test_batch_matches_numpy_composition(textured_frame, rng):
    image = hsv_bins(textured_frame)
    model = Ar2Model(sigma_xy=2.0, sigma_s=0.03)
    objs = _objects(rng, image, 3)
    wants = []
    for o in objs:
        u0 = _core.counter_uniforms(o["seed"], o["step"], 2**64 - 1, 1)[0]
        normals = _core.counter_normals(o["seed"], o["step"], 3 * len(o["p"])).reshape(-1, 3)
        wants.append(
            ref.sis_step(
                o["p"],
                o["w"],
                o["m"],
                image.bins,
                image.n_bins,
                o["ref"],
                o["w0"],
                o["h0"],
                model.a,
                model.b,
                model.sigma,
                model.s_min,
                model.s_max,
                False,
                20.0,
                "uniform",
                u0,
                normals,
            )  # fmt: skip
        )
    out = _core.sis_step_batch(
        [o["p"] for o in objs], [o["w"] for o in objs], [o["m"] for o in objs], image,
        [o["ref"] for o in objs], np.array([o["w0"] for o in objs]),
        np.array([o["h0"] for o in objs]), model.a, model.b, model.sigma, model.s_min,
        model.s_max, False, 20.0, "uniform", True, [o["seed"] for o in objs],
        [o["step"] for o in objs],
    )  # fmt: skip
    for o, (want_p, want_w, want_mean, _), row in zip(objs, wants, out, strict=True):
        np.testing.assert_allclose(o["p"], want_p, rtol=0, atol=1e-12)
        np.testing.assert_allclose(o["w"], want_w, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(row[:3], want_mean, rtol=1e-12)
        assert row[7] == pytest.approx(1 / np.sum(want_w**2), rel=1e-9)


def test_batch_rejects_bad_input_and_changes_nothing(textured_frame, rng):
    image = hsv_bins(textured_frame)
    model = Ar2Model()
    objs = _objects(rng, image, 2)
    before = copy.deepcopy(objs)

    def call(particles, weights, seeds):
        return _core.sis_step_batch(
            particles, weights, [o["m"] for o in objs], image, [o["ref"] for o in objs],
            np.array([o["w0"] for o in objs]), np.array([o["h0"] for o in objs]), model.a,
            model.b, model.sigma, model.s_min, model.s_max, False, 20.0, "uniform", True, seeds,
            [o["step"] for o in objs],
        )  # fmt: skip

    ps, ws, seeds = [o["p"] for o in objs], [o["w"] for o in objs], [o["seed"] for o in objs]
    with pytest.raises(ValueError, match="one entry per object"):
        call(ps, ws, seeds[:1])
    # a wrong dtype is a TypeError (was ValueError "particles[1] dtype is float32"), a layout
    # it cannot write through a ValueError, as from sis_step and propagate
    inplace = re.escape(
        "must be a C-contiguous, writeable float64 array (updated in place, never copied)"
    )
    with pytest.raises(
        TypeError, match=rf"^sis_step_batch: particles\[1\] {inplace}, got dtype float32$"
    ):
        call([ps[0], ps[1].astype(np.float32)], ws, seeds)
    with pytest.raises(TypeError, match=r"^sis_step_batch: weights\[0\] .*, got list$"):
        call(ps, [ws[0].tolist(), ws[1]], seeds)
    with pytest.raises(ValueError, match=r"weights\[1\] must have shape"):
        call(ps, [ws[0], ws[1][:-1]], seeds)
    with pytest.raises(ValueError, match=rf"particles\[0\] {inplace}, got one not C-contiguous"):
        call([np.asfortranarray(ps[0]), ps[1]], ws, seeds)
    # the values sis_step checks, in the entry after one that would step (were: entry 0 had
    # stepped when entry 1 was refused)
    nan = ps[1].copy()
    nan[3, 0] = np.nan
    with pytest.raises(ValueError, match="sis_step_batch: entry 1: .*finite"):
        call([ps[0], nan], ws, seeds)
    with pytest.raises(ValueError, match="sis_step_batch: entry 1: .*weights"):
        call(ps, [ws[0], np.zeros_like(ws[1])], seeds)
    for o, b in zip(objs, before, strict=True):
        np.testing.assert_array_equal(o["p"], b["p"])
        np.testing.assert_array_equal(o["w"], b["w"])
    empty = _core.sis_step_batch([], [], [], image, [], np.zeros(0), np.zeros(0), model.a,
                                 model.b, model.sigma, model.s_min, model.s_max, False, 20.0,
                                 "uniform", True, [], [])  # fmt: skip
    assert empty.shape == (0, 11)


def test_step_filters_refuses_a_bad_filter_before_any_steps(textured_frame, rng):
    """A reference of another binning than the image's: named, and no filter has stepped."""
    image = hsv_bins(textured_frame)
    coarse = hsv_bins(textured_frame, binning=HsvBinning(4, 4, 4))
    box = np.array([20.0, 15.0, 30.0, 40.0])
    good = ColourParticleFilter(box, box_histograms(image, [box])[0], rng=1)
    twin = copy.deepcopy(good)
    bad = ColourParticleFilter(box, box_histograms(coarse, [box])[0], rng=2)
    with pytest.raises(ValueError, match=r"filters\[1\]: reference has 20 bins, the image 110"):
        step_filters([good, bad], image)
    np.testing.assert_array_equal(good.particles, twin.particles)
    np.testing.assert_array_equal(good.weights, twin.weights)
    # its random stream has not moved either: it steps as its untouched twin does
    a, b = good.step(image), twin.step(image)
    np.testing.assert_array_equal(a.box_cxcywh, b.box_cxcywh)
    np.testing.assert_array_equal(good.particles, twin.particles)


def test_a_shallow_copy_of_a_filter_is_refused(textured_frame):
    """A user trial: copy.copy shared the particle arrays under a lock of its own, so two
    threads stepped one particle set at once, and step_filters([f, copy.copy(f)]) stepped it
    twice."""
    image = hsv_bins(textured_frame)
    box = np.array([20.0, 15.0, 30.0, 40.0])
    f = ColourParticleFilter(box, box_histograms(image, [box])[0], rng=1)
    with pytest.raises(TypeError, match=r"copy.copy\(ColourParticleFilter\) would share the"):
        copy.copy(f)
    twin = copy.deepcopy(f)
    assert twin.particles is not f.particles
    np.testing.assert_array_equal(twin.step(image).box_cxcywh, f.step(image).box_cxcywh)


def _scene(shift: int = 0) -> np.ndarray:
    rng = np.random.default_rng(0)
    frame = rng.integers(60, 120, (120, 160, 3), dtype=np.uint8)
    frame[40:80, 30 + shift : 50 + shift] = (20, 20, 220)
    frame[30:60, 100 - shift : 115 - shift] = (200, 60, 20)
    return frame


def _live_tracks(image: _core.BinnedImage, cfg: TrackerConfig, boxes) -> list[LiveTrack]:
    """One LiveTrack per box (left, top, w, h), its reference the box's colour."""
    out = []
    for k, b in enumerate(boxes):
        c = b[:2] + b[2:] / 2
        hist = box_histograms(image, [[*c, *b[2:]]])[0] + 1e-3
        out.append(LiveTrack(k + 1, b, hist, cfg, 100 + k, 0.9))
    return out


@pytest.mark.parametrize("estimate", ["mean", "map"])
def test_step_filters_equals_step_each(estimate):
    image0 = hsv_bins(_scene())
    cfg = FilterConfig(n_particles=50, estimate=estimate)
    boxes = [[40, 60, 20, 40], [107, 45, 15, 30], [60, 60, 20, 40]]

    def make() -> list[ColourParticleFilter]:
        fs = [
            ColourParticleFilter(b, box_histograms(image0, [b])[0] + 1e-3, cfg, rng=k)
            for k, b in enumerate(boxes)
        ]
        # an MH filter and one of another configuration step one by one, in their place
        fs.insert(1, MHColourParticleFilter(boxes[0], fs[0].reference, cfg, rng=7))
        fs.append(ColourParticleFilter(boxes[1], fs[1].reference, FilterConfig(30), rng=8))
        return fs

    batched, single = make(), make()
    for t in range(1, 6):
        image = hsv_bins(_scene(2 * t))
        got = step_filters(batched, image)
        want = [f.step(image) for f in single]
        for g, w, fb, fs in zip(got, want, batched, single, strict=True):
            np.testing.assert_array_equal(g.box_cxcywh, w.box_cxcywh)
            assert (g.rho, g.rho_max, g.ess, g.foreground) == (w.rho, w.rho_max, w.ess,
                                                               w.foreground)  # fmt: skip
            np.testing.assert_array_equal(fb.particles, fs.particles)
            np.testing.assert_array_equal(fb.means, fs.means)
            assert fb.last == g
    assert step_filters([], image0) == []

    # the summary array holds the states' numbers, batched filters and the others alike
    image = hsv_bins(_scene(12))
    summary = step_filters_summary(batched, image)
    want = [f.step(image) for f in single]
    assert summary.shape == (len(batched), 4)
    for f, w, row in zip(batched, want, summary.tolist(), strict=True):
        assert row == [w.box_cxcywh[0], w.box_cxcywh[1], w.rho, w.rho_max]
        got = f.last  # made on reading: the filter's own step's state
        assert got is not None and got is f.last
        np.testing.assert_array_equal(got.box_cxcywh, w.box_cxcywh)
        assert (got.rho, got.rho_max, got.ess, got.foreground) == (w.rho, w.rho_max, w.ess,
                                                                   w.foreground)  # fmt: skip
    assert step_filters_summary([], image).shape == (0, 4)


def test_predict_tracks_equals_predict_each():
    image0 = hsv_bins(_scene())
    cfg = TrackerConfig()
    boxes = [np.array([30.0, 40.0, 20.0, 40.0]), np.array([100.0, 30.0, 15.0, 30.0])]

    batched, single = _live_tracks(image0, cfg, boxes), _live_tracks(image0, cfg, boxes)
    for t in range(1, 6):
        image = hsv_bins(_scene(2 * t))
        predict_tracks(batched, image, cfg.motion.colour_noise)
        for s in single:
            s.predict(image, cfg.motion.colour_noise)
        if t == 3:  # a matched detection in between: follow() after a batched predict
            for group in (batched, single):
                group[0].follow(np.array([36.0, 41.0, 21.0, 39.0]), group[0].filter.reference,
                                cfg, True)  # fmt: skip
        for b, s in zip(batched, single, strict=True):
            np.testing.assert_array_equal(b.box, s.box)
            np.testing.assert_array_equal(b.motion.p, s.motion.p)
            np.testing.assert_array_equal(b.motion.v, s.motion.v)
            assert b.motion.cov == pytest.approx(s.motion.cov, rel=0, abs=0)
            assert (b.rho, b.age) == (s.rho, s.age)
            assert (b.measured is None) == (s.measured is None)
            np.testing.assert_array_equal(b.filter.particles, s.filter.particles)


def test_reinitialise_filters_equals_one_at_a_time():
    cfg = FilterConfig(n_particles=50)
    other = FilterConfig(n_particles=30)
    ref0 = np.ones(110)

    def make() -> list[ColourParticleFilter]:
        return [
            ColourParticleFilter(
                [40.0 + 9 * k, 30.0, 12.0 + k, 30.0 - k], ref0, other if k == 3 else cfg, rng=k
            )  # fmt: skip
            for k in range(5)
        ]

    rng = np.random.default_rng(7)
    boxes = np.column_stack([rng.uniform(20, 90, (5, 2)), rng.uniform(5, 40, (5, 2))])
    boxes[1, 2:] = [1e3, 1e3]  # a scale clipped to s_max
    vel = rng.normal(0, 2, (5, 2))
    for mixed in (False, True):
        batched, single = make(), make()
        if not mixed:  # one configuration: the array path
            del batched[3], single[3]
        b = boxes[: len(batched)]
        v = vel[: len(batched)]
        reinitialise_filters(batched, b, v, spread=0.7)
        for f, box, vv in zip(single, b, v, strict=True):
            f.reinitialise(box, velocity=vv, spread=0.7)
        for fb, fs in zip(batched, single, strict=True):
            np.testing.assert_array_equal(fb.particles, fs.particles)
            np.testing.assert_array_equal(fb.weights, fs.weights)
            np.testing.assert_array_equal(fb.means, fs.means)
            assert fb._rng.random() == fs._rng.random()  # the same draws were taken


def test_reinitialise_filters_checks_its_input():
    fs = [ColourParticleFilter([40.0, 30.0, 12.0, 30.0], np.ones(110), rng=k) for k in range(2)]
    match = r"boxes_cxcywh \(2, 4\) and velocities \(1, 2\) for 2 filters, expected"
    with pytest.raises(ValueError, match=match):
        reinitialise_filters(fs, np.ones((2, 4)), np.zeros((1, 2)))
    # was taken: (2, 3) velocities read as (3, 2) for 3 filters
    with pytest.raises(ValueError, match=r"velocities \(2, 3\) for 3 filters"):
        reinitialise_filters([*fs, fs[0]], np.ones((3, 4)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="velocity is \\[nan, 0.0\\], expected finite"):
        reinitialise_filters(fs, np.ones((2, 4)), [[0.0, 0.0], [np.nan, 0.0]])
    with pytest.raises(ValueError, match="spread is -1, expected a finite number >= 0"):
        reinitialise_filters(fs, np.ones((2, 4)), np.zeros((2, 2)), spread=-1)
    with pytest.raises(ValueError, match=r"box is \[1e\+300, 1.0, 5.0, 5.0\], expected finite"):
        reinitialise_filters(fs, [[1.0, 1, 5, 5], [1e300, 1, 5, 5]], np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"expected finite \(cx, cy, w, h\)"):
        reinitialise_filters(fs, [[1.0, 1, 5, 5], [1.0, 1, 0, 5]], np.zeros((2, 2)))


def test_reseed_tracks_equals_follow_one_at_a_time():
    image = hsv_bins(_scene())
    cfg = TrackerConfig()
    boxes = np.array([[30.0, 40.0, 20.0, 40.0], [100.0, 30.0, 15.0, 30.0], [60, 10, 10, 20]])

    def make() -> list[LiveTrack]:
        return _live_tracks(image, cfg, boxes)

    batched, single = make(), make()
    det = boxes + [[2.0, -1.0, 1.0, 0.5]]
    hists = box_histograms(image, np.column_stack([det[:, :2] + det[:, 2:] / 2, det[:, 2:]]))
    hists[2] = 0.0  # a detection without colour: the reference stays
    for t, b in zip(batched, det, strict=True):
        t.follow_motion(b, cfg, True)
    reseed_tracks(batched, det, hists, cfg)
    for t, b, h in zip(single, det, hists, strict=True):
        t.follow(b, h, cfg, True)
    for b, s in zip(batched, single, strict=True):
        np.testing.assert_array_equal(b.box, s.box)
        np.testing.assert_array_equal(b.filter.particles, s.filter.particles)
        np.testing.assert_array_equal(b.filter.means, s.filter.means)
        np.testing.assert_array_equal(b.filter.reference, s.filter.reference)
    assert not np.array_equal(batched[0].filter.reference, make()[0].filter.reference)
    np.testing.assert_array_equal(batched[2].filter.reference, make()[2].filter.reference)


@pytest.mark.parametrize("smooth", [True, False])
def test_follow_tracks_motion_equals_follow_motion_each(smooth: bool):
    image = hsv_bins(_scene())
    cfg = TrackerConfig()
    boxes = np.array([[30.0, 40.0, 20.0, 40.0], [100.0, 30.0, 15.0, 30.0], [60, 10, 10, 20]])

    def make() -> list[LiveTrack]:
        out = _live_tracks(image, cfg, boxes)
        predict_tracks(out, image, cfg.motion.colour_noise)  # a velocity and a covariance
        return out

    batched, single = make(), make()
    det = boxes + [[2.0, -1.0, 1.5, 0.5], [0.3, 0.2, -1.0, 2.0], [-4.0, 1.0, 0.0, 0.0]]
    follow_tracks_motion(batched, det, cfg, smooth)
    for t, b in zip(single, det, strict=True):
        t.follow_motion(b, cfg, smooth)
    for b, s in zip(batched, single, strict=True):
        np.testing.assert_array_equal(b.box, s.box)
        np.testing.assert_array_equal(b.size, s.size)
        np.testing.assert_array_equal(b.measured, s.measured)
        np.testing.assert_array_equal(b.motion.p, s.motion.p)
        np.testing.assert_array_equal(b.motion.v, s.motion.v)
        assert b.motion.cov == s.motion.cov
    assert not np.array_equal(batched[0].box, make()[0].box)


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({(1, 0): 2e9}, r"particles has a value 2e\+09 at \[1, 0\] beyond \+-1e\+09 px"),
        ({(2, 4): -1e9}, r"particles has a value -1e\+09 at \[2, 4\] beyond \+-1e\+09 px"),
        # every value checked finite before any is checked within the bound
        ({(1, 0): 2e9, (4, 2): np.inf}, r"particles has a non-finite value inf at \[4, 2\]"),
        ({(3, 5): np.nan}, r"particles has a non-finite value nan at \[3, 5\]"),
    ],
)
def test_particles_beyond_the_bound_are_named(textured_frame, rng, bad, message):
    """sis_step and sis_step_batch name the first bad particle value, and change nothing."""
    image = hsv_bins(textured_frame)
    model = Ar2Model()
    (o,) = _objects(rng, image, 1)
    for (i, j), v in bad.items():
        o["p"][i, j] = v
    before = copy.deepcopy(o)
    args = (model.a, model.b, model.sigma, model.s_min, model.s_max, False, 20.0, "uniform", True)
    with pytest.raises(ValueError, match="sis_step: " + message):
        _core.sis_step(o["p"], o["w"], o["m"], image, o["ref"], o["w0"], o["h0"], *args,
                       o["seed"], o["step"])  # fmt: skip
    with pytest.raises(ValueError, match="sis_step_batch: entry 0: " + message):
        _core.sis_step_batch(
            [o["p"]], [o["w"]], [o["m"]], image, [o["ref"]], np.array([o["w0"]]),
            np.array([o["h0"]]), *args, [o["seed"]], [o["step"]],
        )  # fmt: skip
    for key in ("p", "w", "m"):
        np.testing.assert_array_equal(o[key], before[key])
