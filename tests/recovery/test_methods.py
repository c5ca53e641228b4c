"""recover_gap and its baselines, noise estimation."""

from __future__ import annotations

import re

import numpy as np
import pytest

from pftrack.recovery import (
    DEFAULT_METHOD,
    METHODS,
    estimate_noise,
    fill_gaps,
    fit_motion,
    goal_directed_path,
    recover_gap,
    recover_gaps,
)
from pftrack.recovery.calibrate import fixed_noise_model
from pftrack.recovery.demo import demo_report
from pftrack.recovery.gdt import GdtModel
from pftrack.recovery.noise import DEFAULT_NOISE, MAX_R_RATIO, MIN_R, NoiseEstimate
from pftrack.recovery.problems import GdtProblem, SegmentModel, gdt_bi_problem, gdt_problem
from tests.reference import bridge as ref


def line(frames, x0=10.0, y0=20.0, vx=1.5, vy=-0.7, w=30.0, h=60.0, dw=0.1):
    f = np.asarray(frames, dtype=float)
    return np.column_stack([f, x0 + vx * f, y0 + vy * f, w + dw * f, h + 2 * dw * f])


@pytest.mark.parametrize("method", METHODS)
def test_straight_constant_velocity_path_is_recovered_exactly(method):
    a = line(np.arange(1, 31))
    b = line(np.arange(45, 80))
    got = recover_gap(a, b, method=method)
    truth = line(np.arange(31, 45))
    tol = 1e-3 if method == "gsi" else 1e-6
    np.testing.assert_allclose(got[:, :2], truth[:, 1:3], atol=tol)
    np.testing.assert_allclose(got[:, 2:], truth[:, 3:5], atol=1e-9)  # sizes: linear


def test_frames_subset_and_no_sizes():
    a = line(np.arange(1, 20))[:, :3]
    b = line(np.arange(30, 50))[:, :3]
    got = recover_gap(a, b, frames=[22, 25], method="gdt-bi")
    assert got.shape == (2, 2)
    np.testing.assert_allclose(got, line([22, 25])[:, 1:3], atol=1e-6)


def test_recover_gaps_equals_recover_gap():
    rng = np.random.default_rng(0)
    gaps = []
    for k in range(6):
        t = np.arange(1, 80)
        xy = np.cumsum(np.cumsum(rng.normal(0, 0.1, (len(t), 2)), axis=0), axis=0)
        tr = np.column_stack([t, xy])
        s = 20 + 3 * k
        gaps.append((tr[:s], tr[s + 5 + k :]))
    for m in ("gdt", "gdt-bi", "bspline"):
        batch = recover_gaps(gaps, m)
        noise = estimate_noise([g[0] for g in gaps] + [g[1] for g in gaps])
        for (a, b), p in zip(gaps, batch, strict=True):
            np.testing.assert_allclose(recover_gap(a, b, method=m, noise=noise), p, atol=1e-12)


def test_paper_gdt_equals_kalman_plus_reference_equation():
    rng = np.random.default_rng(1)
    t = np.arange(1, 60)
    xy = 100 + np.cumsum(np.cumsum(rng.normal(0, 0.2, (len(t), 2)), axis=0), axis=0)
    a = np.column_stack([t[:30], xy[:30]])
    b = np.column_stack([t[42:], xy[42:]])
    model = GdtModel()
    z = a[:, 1:3]
    m_init = np.array([z[0, 0], z[0, 1], *(z[1] - z[0])])
    P_init = np.diag([*model.r, model.p_init_velocity, model.p_init_velocity])
    m0, P0 = ref.kalman_filter(z, model.A, model.Q, model.H, model.R, m_init, P_init)
    path, *_ = ref.gdt_general(
        model.A, model.Q, model.H, model.R, m0, P0, b[0, 1:3], 13, start_conditioned=False
    )
    got = recover_gap(a, b, method="gdt")
    np.testing.assert_allclose(got, path[1:-1, :2], rtol=1e-7, atol=1e-6)
    # the Python problem builder + general solver agree too
    p = gdt_problem(a, b)
    assert isinstance(p, GdtProblem) and p.T == 13
    sol = goal_directed_path(
        p.A, p.Q, p.H_T, p.Pi_T, p.m0, p.Pi_0, p.y_T, p.T, start_conditioned=False
    )
    np.testing.assert_allclose(got, sol.path[1:-1, :2], atol=1e-9)
    np.testing.assert_array_equal(p.solve(start_conditioned=False).path, sol.path)


def test_gdt_bi_problem_solves_to_the_batch_path():
    rng = np.random.default_rng(6)
    t = np.arange(1, 70)
    xy = 50 + np.cumsum(np.cumsum(rng.normal(0, 0.2, (len(t), 2)), axis=0), axis=0)
    a = np.column_stack([t[:30], xy[:30]])
    b = np.column_stack([t[41:], xy[41:]])
    noise = estimate_noise([a, b])
    p = gdt_bi_problem(a, b, noise)
    assert p.H_T.shape == (4, 4) and p.T == 12
    np.testing.assert_allclose(p.Pi_T, p.Pi_T.T, atol=0)
    got = recover_gap(a, b, method="gdt-bi", noise=noise)
    np.testing.assert_allclose(p.solve().path[1:-1, :2], got, atol=1e-8)


def _walk(n=40, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(1.0, n + 1)
    return np.column_stack([t, 3 * t + rng.normal(0, 1, n), 0.05 * t**2 + rng.normal(0, 1, n)])


@pytest.mark.parametrize("fit", [estimate_noise, fit_motion])
@pytest.mark.parametrize(
    ("segments", "error", "match"),
    [
        # one segment given alone: its rows were read as segments and left out
        (_walk(), ValueError, r"segments is one \(40, 3\) array, .*pass \[segment\] for one"),
        (list(_walk()), ValueError, r"segments\[0\] has shape \(3,\), .*pass \[segment\]"),
        ([_walk()[::-1]], ValueError, r"segments\[0\] frames must increase strictly"),
        ([_walk()[:, [1, 0, 2]]], ValueError, r"segments\[0\] row 0 has frame 3\.\d+, expected"),
        ([_walk(), np.r_[_walk()[:-1], [[40, np.nan, 0]]]], ValueError, r"segments\[1\] has a non"),
        ([[["a", "b", "c"]]], TypeError, r"segments\[0\] must hold real numbers"),
        ("walk.txt", TypeError, "segments must be a sequence of"),
        (3.0, TypeError, "segments must be a sequence of"),
    ],
)
def test_noise_and_motion_fits_refuse_segments_they_cannot_read(fit, segments, error, match):
    """Was: each of these gave the default model (DEFAULT_NOISE; fit_motion's white
    acceleration q=0.1 r=1 with no stands) without a word, as if fitted to the data."""
    with pytest.raises(error, match=rf"^{fit.__name__}: {match}"):
        fit(segments)


def test_noise_and_motion_fits_of_good_segments_are_unchanged():
    a, b = _walk(), _walk(30, seed=1)
    b[:, 0] += 60
    lists = [a.tolist(), b.tolist(), np.zeros((0, 3))]  # an empty segment adds nothing
    assert estimate_noise(lists) == estimate_noise([a, b]) != DEFAULT_NOISE
    assert fit_motion(lists) == fit_motion([a, b])
    wide = [np.column_stack([s, np.ones((len(s), 7))]) for s in (a, b)]  # MOT-like columns
    assert estimate_noise(wide) == estimate_noise([a, b])
    assert estimate_noise(np.stack([a[:20], a[20:]])) == estimate_noise([a[:20], a[20:]])


@pytest.mark.parametrize("make", [gdt_problem, gdt_bi_problem])
@pytest.mark.parametrize(
    ("seg_a", "seg_b", "kwargs", "error", "match"),
    [
        # was: a problem with T = -14, solved without a word
        (_walk()[:15], _walk()[:5], {}, ValueError, "segment_b starts at frame 1, expected after"),
        (np.zeros((0, 3)), _walk()[25:], {}, ValueError, r"seg_a must have shape \(k, 3\|5\), no"),
        (_walk()[0], _walk()[25:], {}, ValueError, r"seg_a must have shape .*got \(3,\)"),
        (_walk()[:15], np.r_[[[26, np.nan, 0]]], {}, ValueError, "seg_b has a non-finite value"),
        (_walk()[:15], _walk()[25:], {"history": 0}, ValueError, r"history is 0, expected"),
        (_walk()[:15], _walk()[25:], {"history": 2.5}, TypeError, "history must be an int"),
    ],
)
def test_problem_builders_check_their_segments(make, seg_a, seg_b, kwargs, error, match):
    """Was: an IndexError (empty or 1-D segment), the core's message naming kalman_filter or
    noise_loglik_grid (NaN), "list indices must be integers" (lists), or a problem with a
    negative T (segment B before A)."""
    with pytest.raises(error, match=rf"^{make.__name__}: {match}"):
        make(seg_a, seg_b, **kwargs)


def test_problem_builders_take_lists_as_arrays():
    a, b = _walk()[:15], _walk()[25:]
    for make in (gdt_problem, gdt_bi_problem):
        got, want = make(a.tolist(), b.tolist()), make(a, b)
        assert got.T == want.T == 11
        np.testing.assert_array_equal(got.m0, want.m0)
        np.testing.assert_array_equal(got.y_T, want.y_T)
    with pytest.raises(TypeError, match="^gdt_problem: model must be a GdtModel, got dict$"):
        gdt_problem(a, b, {})
    with pytest.raises(TypeError, match="^gdt_bi_problem: noise must be a NoiseEstimate or"):
        gdt_bi_problem(a, b, (0.1, 0.1))


def test_default_method_is_auto_everywhere():
    assert DEFAULT_METHOD == "auto"
    rng = np.random.default_rng(7)
    t = np.arange(1, 90)
    xy = 80 + np.cumsum(np.cumsum(rng.normal(0, 0.1, (len(t), 2)), axis=0), axis=0)
    a = np.column_stack([t[:40], xy[:40]])
    b = np.column_stack([t[52:], xy[52:]])
    want = recover_gap(a, b, method="auto")
    np.testing.assert_array_equal(recover_gap(a, b), want)
    np.testing.assert_array_equal(recover_gaps([(a, b)])[0], want)
    rows = np.zeros((len(a) + len(b), 10))
    rows[:, 0] = np.r_[a[:, 0], b[:, 0]]
    rows[:, 1] = 1
    rows[:, 2:4] = np.r_[a[:, 1:3], b[:, 1:3]] - 5.0
    rows[:, 4:6] = 10.0
    assert np.array_equal(fill_gaps(rows)[0], fill_gaps(rows, "auto")[0])


@pytest.mark.parametrize("method", ["ml", "moments"])
def test_noise_estimates_recover_simulated_levels(method):
    rng = np.random.default_rng(2)
    q, r = 0.2, 0.5
    segs = []
    for _ in range(20):
        n = 200
        x = np.zeros((n, 2))
        v = np.zeros(2)
        for k in range(1, n):
            # exact discretisation of continuous white-noise acceleration, one frame
            cov = q * np.array([[1 / 3, 1 / 2], [1 / 2, 1]])
            L = np.linalg.cholesky(cov)
            for ax in range(2):
                e = L @ rng.standard_normal(2)
                x[k, ax] = x[k - 1, ax] + v[ax] + e[0]
                v[ax] += e[1]
        z = x + rng.normal(0, np.sqrt(r), x.shape)
        segs.append(np.column_stack([np.arange(n), z]))
    est = estimate_noise(segs, method=method)
    for ax in range(2):
        assert 0.6 * q < est.q[ax] < 1.6 * q, est
        assert 0.6 * r < est.r[ax] < 1.6 * r, est


@pytest.mark.parametrize("q", [(0.0, 0.0), (0.0, 1e5), (1e-300, 2.0)])
@pytest.mark.parametrize("r", [(MIN_R, MIN_R), (1.0, 0.999 * MAX_R_RATIO), (MIN_R, 1e-3)])
@pytest.mark.parametrize("method", ["gdt-bi", "gdt-mix"])
def test_every_noise_estimate_taken_is_solved(q, r, method):
    """At the bounds NoiseEstimate checks, the C++ core solves: no error of its own.

    Were taken and failed in gdt_recover_batch: ``r`` of 1e-13 px² with ``q = 0`` ("Pi_T +
    H S H^T is not positive definite"; now refused as below MIN_R) and ``r`` 1e10 apart ("R
    is not positive definite"; now refused as MAX_R_RATIO apart or more).
    """
    noise = NoiseEstimate(q=q, r=r)
    pairs = [
        (line(np.arange(1, 3)), line(np.arange(4, 6))),  # the shortest runs, the most fragile
        (line(np.arange(1, 31)), line(np.arange(45, 80))),
        (line(np.arange(1, 400)), line(np.arange(430, 800))),
    ]
    for path in recover_gaps(pairs, method, noise=noise):
        assert np.isfinite(path).all()


@pytest.mark.parametrize("method", ["gdt-bi", "gdt-mix"])
def test_a_path_that_overflows_is_an_error_not_nan(method):
    """A finite ``q`` NoiseEstimate takes can overflow over a long gap (``q T^3``): the
    paths came back NaN without a word (1e300 px²/frame³ over 1000 frames; a user trial)."""
    noise = NoiseEstimate(q=(1e300, 1e300), r=(1.0, 1.0))
    pairs = [
        (line(np.arange(1, 31)), line(np.arange(45, 80))),
        (line(np.arange(1, 21)), line(np.arange(1021, 1041))),
    ]
    with pytest.raises(ValueError, match=r"gap 1 \(1000 missing frames\) overflows"):
        recover_gaps(pairs, method, noise=noise)
    short = recover_gaps(pairs[:1], method, noise=NoiseEstimate(q=(1e100, 1e100), r=(1.0, 1.0)))
    assert np.isfinite(short[0]).all()  # huge, but finite over its gap: no error


@pytest.mark.parametrize("method", METHODS)
def test_a_translated_gap_is_recovered_translated(method):
    """Every method moves with the tracks: at 1e7 px only round-off may differ.

    ``gsi``'s Gaussian process had a zero prior mean (StrongSORT's): it pulled the path toward
    the image origin by 1.9e-7 of the coordinates, 1.9 px at 1e7 px.
    """
    rng = np.random.default_rng(0)
    fa, fb = np.arange(1.0, 41), np.arange(52.0, 92)
    a = np.column_stack([fa, 10 + 0.5 * fa + rng.normal(0, 1, 40), 5 + 0.2 * fa])
    b = np.column_stack([fb, 40 + 0.5 * fb + rng.normal(0, 1, 40), 5 + 0.2 * fb])
    base = recover_gap(a, b, method=method)
    tol = 1e-4 if method == "gsi" else 1e-5  # gsi's kernel matrix (jitter 1e-10) amplifies more
    for shift in (1e7, -1e7):
        got = recover_gap(a + [0, shift, shift], b + [0, shift, shift], method=method)
        np.testing.assert_allclose(got - shift, base, rtol=0, atol=tol)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        # were: the core's "noise_loglik_grid: q and r must be finite and > 0 (pair 0)" after
        # a NumPy RuntimeWarning, NumPy's TypeError, a NoiseEstimate error naming its own
        # field, or an estimate below its floor (floor_r 1e300 gave r = 4.5e6)
        ({"floor_r": 0.0}, ValueError, "estimate_noise: floor_r is 0.0, expected"),
        ({"floor_q": -1.0}, ValueError, "estimate_noise: floor_q is -1.0, expected"),
        ({"floor_q": 0.0}, ValueError, "estimate_noise: floor_q is 0.0, expected"),
        ({"floor_r": float("nan")}, ValueError, "estimate_noise: floor_r is nan, expected"),
        ({"floor_r": 1e-15}, ValueError, "estimate_noise: floor_r is 1e-15, expected"),
        ({"floor_r": 1e300}, ValueError, "estimate_noise: floor_r is 1e+300, expected"),
        ({"floor_r": "a"}, TypeError, "estimate_noise: floor_r must be a number, got str"),
        ({"min_points": 2.5}, TypeError, "estimate_noise: min_points must be an integer"),
    ],
)
@pytest.mark.parametrize("method", ["ml", "moments"])
def test_estimate_noise_names_a_bad_floor(kwargs, error, message, method):
    rng = np.random.default_rng(0)
    run = np.column_stack([np.arange(50.0), rng.normal(0, 1, (50, 2)).cumsum(axis=0)])
    with pytest.raises(error, match="^" + re.escape(message)):
        estimate_noise([run], method=method, **kwargs)


def test_noise_estimate_defaults_without_data():
    # two points (frames 1, 2) are too few to fit; np.zeros((2, 3)), two rows of frame 0,
    # is refused since 5 December (frames must increase)
    assert estimate_noise([[[1, 0, 0], [2, 0, 0]]]) == DEFAULT_NOISE
    assert estimate_noise([]) == DEFAULT_NOISE
    with pytest.raises(ValueError, match="method"):
        estimate_noise([], method="bad")


def test_bad_segments_raise():
    a = line(np.arange(1, 10))
    b = line(np.arange(15, 20))
    with pytest.raises(ValueError, match="segment_a is empty"):
        recover_gap(np.zeros((0, 3)), b, method="gdt")
    with pytest.raises(ValueError, match="segment_b must have shape"):
        recover_gap(a, np.zeros((4, 2)), method="gdt")
    nan = a.copy()
    nan[3, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        recover_gap(nan, b, method="gdt")
    with pytest.raises(ValueError, match="starts at frame"):
        recover_gap(b, a, method="gdt")
    with pytest.raises(ValueError, match="method"):
        recover_gap(a, b, method="magic")
    with pytest.raises(ValueError, match="strictly between"):
        recover_gap(a, b, frames=[9], method="gdt")
    with pytest.raises(ValueError, match="increase"):
        recover_gap(a[::-1], b, method="gdt")
    with pytest.raises(ValueError, match="segment_a of gap 0"):
        recover_gaps([(np.zeros((0, 3)), b)], "gdt")


def test_a_method_given_third_is_named_as_the_mix_up():
    """recover_gaps(gaps, "linear") takes the method second; recover_gap's third is frames."""
    a, b = line(np.arange(1, 10)), line(np.arange(15, 20))
    message = r"recover_gap: frames must be .*'linear'; the method goes by keyword: method='linear'"
    with pytest.raises(TypeError, match=message):  # was "frames must be a 1-D array of integers"
        recover_gap(a, b, "linear")
    with pytest.raises(TypeError, match=r"got the string 'fast'$"):
        recover_gap(a, b, "fast")
    np.testing.assert_array_equal(
        recover_gap(a, b, None, "linear"), recover_gap(a, b, method="linear")
    )


def test_demo_report_runs_and_names_every_method():
    rng = np.random.default_rng(3)
    rows = []
    for tid in range(1, 4):
        t = np.arange(1, 120)
        xy = 200 + np.cumsum(np.cumsum(rng.normal(0, 0.1, (len(t), 2)), axis=0), axis=0)
        for f, (x, y) in zip(t, xy, strict=True):
            rows.append([f, tid, x - 10, y - 20, 20, 40, 1, -1, -1, -1])
    text = demo_report(np.array(rows), rng=4)
    for m in METHODS:
        assert m in text
    lines = text.splitlines()
    assert len(lines) == 2 + len(METHODS)
    errs = {ln.split()[0]: float(ln.split()[1]) for ln in lines[2:]}
    assert all(np.isfinite(v) and v >= 0 for v in errs.values())
    # same seed, same gaps, same errors (timings aside)
    again = demo_report(np.array(rows), rng=4).splitlines()
    assert [ln.split()[:2] for ln in again[2:]] == [ln.split()[:2] for ln in lines[2:]]


def test_noise_loglik_grid_matches_reference():
    from pftrack import _core

    rng = np.random.default_rng(8)
    runs = [
        np.column_stack([np.arange(n), np.cumsum(rng.normal(0, 1, (n, 2)), axis=0)])
        for n in (3, 10, 25, 4)
    ]
    q = np.array([0.01, 0.1, 1.0, 3.0])
    r = np.array([0.5, 0.01, 2.0, 1.0])
    for axis in range(2):
        z = np.concatenate([run[:, 1 + axis] for run in runs])
        got = _core.noise_loglik_grid(z, np.array([len(x) for x in runs], np.int32), q, r)
        np.testing.assert_allclose(got, ref.loglik_grid(runs, axis, q, r), rtol=1e-12)
    with pytest.raises(ValueError, match="q and r must be finite and > 0"):
        _core.noise_loglik_grid(z, np.array([len(z)], np.int32), np.array([0.0]), np.array([1.0]))


def test_noise_loglik_grid_long_runs_match_reference():
    """Runs far longer than the covariance takes to settle (the steps after it reuse it)."""
    from pftrack import _core

    rng = np.random.default_rng(9)
    runs = [
        np.column_stack([np.arange(n), np.cumsum(rng.normal(0, 1, (n, 2)), axis=0)])
        for n in (1200, 5, 300)
    ]
    q = np.array([0.01, 1.0, 1e-5])
    r = np.array([0.5, 2.0, 50.0])
    z = np.concatenate([run[:, 1] for run in runs])
    got = _core.noise_loglik_grid(z, np.array([len(x) for x in runs], np.int32), q, r)
    np.testing.assert_allclose(got, ref.loglik_grid(runs, 0, q, r), rtol=1e-12)


@pytest.mark.parametrize("history", [None, 4])
@pytest.mark.parametrize(
    "model",
    [
        SegmentModel.two_sided(NoiseEstimate(q=(0.3, 0.05), r=(2.0, 0.5))),
        SegmentModel.paper(),
        fixed_noise_model(),
    ],
)
def test_gdt_recover_batch_shared_gains_are_exact(model: SegmentModel, history: int | None):
    """Gains shared by the gaps of one call (the segments' filter, the goal's path per Pi_T)
    give every gap the bits of a call of its own, whatever the order of lengths."""
    rng = np.random.default_rng(12)
    seg_a, seg_b = [], []
    for na, nb, T in [(5, 7, 9), (12, 7, 3), (5, 2, 15), (30, 7, 9), (1, 1, 2), (8, 30, 15)]:
        xy = np.cumsum(rng.normal(0, 2, (na + T - 1 + nb, 2)), axis=0)
        fr = np.arange(len(xy), dtype=float)
        rows = np.column_stack([fr, xy])
        seg_a.append(rows[:na])
        seg_b.append(rows[na + T - 1 :])
    together = model.recover(seg_a, seg_b, history)
    for k in range(len(seg_a)):
        alone = model.recover(seg_a[k : k + 1], seg_b[k : k + 1], history)[0]
        assert np.array_equal(alone, together[k])


def test_a_coarse_scale_with_few_points_does_not_replace_the_fine_estimate():
    """A user trial: on a file with many short holes, 5 points at scale 8 (one straight run)
    replaced 316 at scale 1: q at its floor, r 64 px², and GDT's filled boxes 12 times
    linear's error."""
    rng = np.random.default_rng(0)
    segments = []
    for k in range(40):  # short jittery runs: scales 1, 2 see them, 8 does not
        f = np.arange(10.0) + 20 * k
        xy = 100 + np.cumsum(np.cumsum(rng.normal(0, 0.5, (10, 2)), axis=0), axis=0)
        segments.append(np.column_stack([f, xy + rng.normal(0, 1.0, (10, 2))]))
    f = np.arange(32.0) + 1000  # and one long straight run: 8 points at scale 8
    segments.append(np.column_stack([f, 3 + 0.5 * f, 7 - 0.25 * f]))
    assert estimate_noise(segments) == estimate_noise(segments, scales=(1, 2, 4))
    assert estimate_noise(segments, scales=(1, 8)) == estimate_noise(segments, scales=(1,))
    # with enough points a coarse scale does replace the fine one, as before
    sway = [  # gait sway of 8 frames: wiggly frame to frame, straight every 8th frame
        np.column_stack([f, 3 + 0.5 * f + 2 * np.sin(np.pi * f / 4), 7 - 0.25 * f])
        for f in np.arange(300.0).reshape(3, -1)
    ]
    wide = estimate_noise(segments + sway, scales=(1, 8))
    assert wide.q[0] < estimate_noise(segments + sway, scales=(1,)).q[0] / 2


def test_fill_gaps_refuses_what_its_method_does_not_use():
    """A user trial: ``fill_gaps(rows, "linear", noise=..., seed=5)`` ignored both silently,
    while the command refuses ``--seed`` with a named method."""
    rows = np.array([[1, 1, 10, 10, 5, 5], [5, 1, 20, 10, 5, 5]], float)
    with pytest.raises(ValueError, match="seed is used by method 'auto' only, not 'linear'"):
        fill_gaps(rows, "linear", seed=5)
    with pytest.raises(ValueError, match=r"noise is used by methods auto, gdt-bi, gdt-mix, not"):
        fill_gaps(rows, "rts", noise=DEFAULT_NOISE)
    assert (
        len(fill_gaps(rows, "auto", seed=5)[0])
        == len(fill_gaps(rows, "gdt-bi", noise=DEFAULT_NOISE)[0])
        == 5
    )


def test_explain_tells_two_close_errors_apart():
    """A user trial: "did worse than linear (0.019)" after "validation MMAE 0.019"."""
    from pftrack.recovery.calibrate import _apart

    assert _apart(0.0191234, 0.0193) == ("0.0191", "0.0193")
    assert _apart(1.5, 2.25) == ("1.500", "2.250")
    assert _apart(1.0, 1.0) == ("1.000000000", "1.000000000")


@pytest.mark.parametrize(
    ("method", "who"), [("auto", "recover_auto"), ("linear-nb", "recover_gaps")]
)
@pytest.mark.parametrize(
    ("observed", "match"),
    [
        # were taken: each track cut into runs of one point and left out, without a word
        ([_walk()[::-1]], r"observed\[0\] row 1 has frame 39 after 40: a track's frames must"),
        ([_walk(), _walk()[:, [2, 0, 1]]], r"observed\[1\] row \d+ has frame -?\d.* after "),
        ([np.r_[_walk(), _walk()[-1:]]], r"observed\[0\] row 40 has frame 40 after 40: "),
        (_walk(), r"observed\[0\] has shape \(3,\), .* \(one track given alone\? pass \[track\]\)"),
    ],
)
def test_observed_tracks_whose_frames_do_not_increase_are_refused(method, who, observed, match):
    a, b = _walk()[:15], _walk()[25:]
    with pytest.raises(ValueError, match=rf"^{who}: {match}"):
        recover_gaps([(a, b)], method, observed=observed)


def test_observed_tracks_that_are_good_give_what_they_gave():
    a, b = _walk()[:15], _walk()[25:]
    others = [_walk(seed=s) for s in range(1, 4)]
    for method in ("auto", "linear-nb"):
        want = recover_gaps([(a, b)], method, observed=others)
        got = recover_gaps([(a, b)], method, observed=[o.tolist() for o in others])
        np.testing.assert_array_equal(got[0], want[0])
