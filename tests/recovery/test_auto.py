"""The calibrated default ``"auto"``: choice, no peeking at the deleted points, determinism."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from pftrack.recovery import DEFAULT_METHOD, fill_gaps, recover_gaps
from pftrack.recovery.calibrate import (
    BAGS,
    BucketChoice,
    Calibration,
    bucket_of,
    calibrate,
    recover_auto,
)
from pftrack.recovery.experiment import auto_masks, find_gaps, trajectories

from ..conftest import dataset


def _straight_tracks(rng: np.random.Generator, n: int = 30, length: int = 120) -> list[np.ndarray]:
    """Straight one-frame steps in independent random directions, 0.3 px jitter: (frame, x, y).

    A random walk: the velocity next to a gap says nothing about the path inside it, and the
    best guess between two ends (a Brownian bridge's mean) is the straight line.
    """
    out = []
    for _ in range(n):
        steps = rng.uniform(-3, 3, (length, 2))
        xy = rng.uniform(0, 500, 2) + np.cumsum(steps, axis=0) + rng.normal(0, 0.3, (length, 2))
        out.append(np.column_stack([np.arange(length, dtype=np.float64), xy]))
    return out


def _manoeuvring_tracks(
    rng: np.random.Generator, n: int = 30, length: int = 160
) -> list[np.ndarray]:
    """Smooth curving paths (turning at varying rates), little measurement noise."""
    out = []
    for _ in range(n):
        t = np.arange(length, dtype=np.float64)
        heading = rng.uniform(0, 2 * np.pi) + np.cumsum(0.06 * np.sin(t / rng.uniform(8, 14)))
        speed = 3.0
        xy = np.cumsum(speed * np.column_stack([np.cos(heading), np.sin(heading)]), axis=0)
        xy += rng.normal(0, 0.05, xy.shape)
        out.append(np.column_stack([t, xy + 300.0]))
    return out


def _cut(tracks: list[np.ndarray], length: int) -> list[tuple[np.ndarray, np.ndarray]]:
    pairs = []
    for tr in tracks:
        s = len(tr) // 2
        pairs.append((tr[:s], tr[s + length :]))
    return pairs


def test_default_is_auto() -> None:
    assert DEFAULT_METHOD == "auto"


def test_picks_linear_on_straight_jittered_segments() -> None:
    tracks = _straight_tracks(np.random.default_rng(0))
    cal = calibrate(tracks, [5, 12, 25])
    assert [c.method for c in cal.buckets] == ["linear"] * 3, cal.describe()
    paths, cal2 = recover_auto(_cut(tracks, 12), tracks)
    a, b = _cut(tracks, 12)[0]
    # a straight line between the two end points, exactly
    s = np.arange(1, 13) / 13.0
    line = (1 - s)[:, None] * a[-1, 1:3] + s[:, None] * b[0, 1:3]
    np.testing.assert_allclose(paths[0], line, atol=1e-9)
    assert cal2.method_for(12) == "linear"


@pytest.mark.parametrize("bags", [0, None])
def test_a_tie_at_rounding_keeps_linear(bags: int | None) -> None:
    """A user trial: constant box sizes (linear errs by 1e-15, rts by 0) chose rts, and
    noise-free straight centres gdt-bi, by a paired test on rounding alone."""
    rng = np.random.default_rng(3)
    sizes = [np.column_stack([np.arange(80.0), np.full(80, w), np.full(80, 2.5 * w)])
             for w in rng.uniform(10, 60, 30)]  # fmt: skip
    cal = calibrate(sizes, [4, 10, 12, 20, 7, 5], candidates=("linear", "rts"), bags=bags)
    assert cal.pooled == "linear" and {c.method for c in cal.buckets} == {"linear"}, cal.describe()
    t = np.arange(80.0)
    lines = [np.column_stack([t, 3.0 + 0.7 * t, 5.0 + 0.3 * t]) for _ in range(30)]
    cal = calibrate(lines, [4, 10, 12, 20], bags=bags)
    assert cal.pooled == "linear" and {c.method for c in cal.buckets} == {"linear"}, cal.describe()


def test_picks_goal_directed_on_manoeuvring_data() -> None:
    tracks = _manoeuvring_tracks(np.random.default_rng(1))
    cal = calibrate(tracks, [20, 40])
    assert all(c.method.startswith("gdt") for c in cal.buckets), cal.describe()


def _mot_rows(truth: list[np.ndarray]) -> np.ndarray:
    """MOTChallenge rows of fixed 20x40 boxes centred on each track's (x, y)."""
    rows = []
    for tid, tr in enumerate(truth, start=1):
        w, h = 20.0, 40.0
        r = np.column_stack([tr[:, 0] + 1, np.full(len(tr), tid), tr[:, 1] - w / 2,
                             tr[:, 2] - h / 2, np.full((len(tr), 2), (w, h)),
                             np.ones(len(tr)), -np.ones((len(tr), 3))])  # fmt: skip
        rows.append(r)
    return np.vstack(rows)


@pytest.mark.parametrize("combine", [True, False])
def test_calibration_never_reads_the_deleted_points(combine: bool) -> None:
    rng = np.random.default_rng(2)
    full = _mot_rows(_manoeuvring_tracks(rng, n=20))
    holes = (full[:, 0] >= 60) & (full[:, 0] < 75)
    cut = full[~holes]
    out1, rep1 = fill_gaps(cut, max_gap=50, combine=combine)
    poisoned = full.copy()
    poisoned[holes, 2:4] = 1e9  # the deleted points, poisoned in a copy: never seen
    out2, rep2 = fill_gaps(poisoned[~holes], max_gap=50, combine=combine)
    np.testing.assert_array_equal(out1, out2)
    assert rep1.calibration == rep2.calibration
    assert rep1.calibration is not None and rep1.calibration.buckets[0].n_validation > 0


def test_deterministic() -> None:
    tracks = _manoeuvring_tracks(np.random.default_rng(3), n=10)
    pairs = _cut(tracks, 17)
    p1, c1 = recover_auto(pairs, tracks)
    p2, c2 = recover_auto(pairs, tracks)
    assert c1 == c2
    for a, b in zip(p1, p2, strict=True):
        np.testing.assert_array_equal(a, b)
    assert isinstance(c1, Calibration)
    assert "chosen" in c1.describe()


def test_recover_gaps_auto_matches_recover_auto() -> None:
    tracks = _straight_tracks(np.random.default_rng(4), n=8)
    pairs = _cut(tracks, 6)
    got = recover_gaps(pairs, "auto", observed=tracks)
    want, _ = recover_auto(pairs, tracks)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)


def test_pairs_checked_at_once_or_one_by_one_agree() -> None:
    """Float64 arrays (checked in one pass) and lists of (frame, x, y, w, h) rows (checked pair
    by pair) give the same bits; a bad pair among good ones is still named."""
    tracks = _manoeuvring_tracks(np.random.default_rng(6), n=8)
    pairs = _cut(tracks, 9)
    want, cal = recover_auto(pairs, tracks)
    wide = [
        (np.column_stack([a, a[:, 1:3]]).tolist(), np.column_stack([b, b[:, 1:3]]).tolist())
        for a, b in pairs
    ]
    got, cal2 = recover_auto(wide, tracks)
    assert cal == cal2
    for x, y in zip(got, want, strict=True):
        np.testing.assert_array_equal(x, y)
    late = pairs[:3] + [(pairs[3][0], pairs[3][0][-1:])] + pairs[4:]
    with pytest.raises(ValueError, match="gap 3: segment_b starts at frame"):
        recover_auto(late, tracks)
    jumpy = [(pairs[0][0][::-1], pairs[0][1])] + pairs[1:]
    with pytest.raises(ValueError, match="segment_a frames must increase strictly"):
        recover_auto(jumpy, tracks)


def test_no_runs_long_enough_falls_back_to_linear() -> None:
    a = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    b = np.array([[10.0, 10.0, 10.0], [11.0, 11.0, 11.0]])
    paths, cal = recover_auto([(a, b)])
    assert cal.buckets[0].method == "linear" and cal.buckets[0].n_validation == 0
    np.testing.assert_allclose(paths[0][:, 0], np.arange(2, 10))


def test_buckets() -> None:
    assert [bucket_of(v) for v in (1, 2, 3, 4, 5, 8, 9, 16, 17)] == [0, 1, 2, 2, 3, 3, 4, 4, 5]


def test_bad_input() -> None:
    tracks = _straight_tracks(np.random.default_rng(5), n=3)
    with pytest.raises(ValueError, match=r"a gap length is 0, expected an integer in \[1, "):
        calibrate(tracks, [0])
    with pytest.raises(ValueError, match="max_gaps"):
        calibrate(tracks, [3], max_gaps=0)
    with pytest.raises(ValueError, match="candidate 'spline9'"):
        calibrate(tracks, [3], candidates=["spline9"])
    with pytest.raises(ValueError, match="1 contexts for 2 gap lengths"):
        calibrate(tracks, [3, 4], contexts=[(3, 3)])
    with pytest.raises(ValueError, match=r"a context is 0, expected an integer in \[1, "):
        calibrate(tracks, [3], contexts=[(0, 3)])
    a = np.array([[5.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="segment_b starts at frame"):
        recover_auto([(a, a)])
    with pytest.raises(ValueError, match="non-finite"):
        recover_auto([(np.array([[0.0, np.nan, 0.0]]), np.array([[3.0, 0.0, 0.0]]))])


def test_auto_masks_rules() -> None:
    rng = np.random.default_rng(6)
    trajs = {k: t for k, t in enumerate(_straight_tracks(rng, n=40, length=200))}
    masks = auto_masks(trajs, 768, 576)
    assert 1 <= len(masks) <= 3
    for x, y, w, h in masks:
        assert w == h == 100 and x % 4 == 0 and y % 4 == 0
        assert 0 <= x and x + w <= 768 and 0 <= y and y + h <= 576
        assert find_gaps(trajs, (x, y, w, h))[0]
    for i, m in enumerate(masks):
        for n in masks[i + 1 :]:
            assert abs(m[0] - n[0]) >= 100 or abs(m[1] - n[1]) >= 100
    assert auto_masks(trajs, 768, 576) == masks
    with pytest.raises(ValueError, match="image size"):
        auto_masks(trajs, 0, 576)


def test_auto_never_worse_than_linear_on_tud() -> None:
    from pftrack.io.mot import read_mot
    from pftrack.recovery.experiment import run_sequence

    gt = read_mot(dataset("tud-campus") / "gt.txt")
    r = run_sequence("tud", trajectories(gt), 640, 480, ["auto", "linear"])
    assert r.n_gaps > 0
    assert r.mmae("auto") <= r.mmae("linear") + 1e-9


def test_paired_test_keeps_the_reference_within_noise() -> None:
    from pftrack.recovery.calibrate import _better

    rng = np.random.default_rng(7)
    ref = rng.uniform(1.0, 2.0, 40)
    assert not _better(ref - 0.001, ref, float(ref.mean()))  # below the 1 % margin
    noisy = ref + rng.normal(0, 0.5, 40)
    noisy -= noisy.mean() - ref.mean() + 0.02  # 1.3 % better on average, but within noise
    assert not _better(noisy, ref, float(ref.mean()))
    assert _better(0.8 * ref, ref, float(ref.mean()))  # clearly better on every gap


def test_small_buckets_take_the_files_choice() -> None:
    """A bucket with too few validation gaps follows the file's pooled choice, not linear."""
    tracks = _manoeuvring_tracks(np.random.default_rng(8))
    cal = calibrate(tracks, [20] * 20 + [200])  # no run can hold a 200-frame gap
    long = [c for c in cal.buckets if c.lengths[0] > 128][0]
    assert long.n_validation == 0 and long.method == cal.pooled
    assert cal.pooled.startswith("gdt") and cal.method_for(1000) == cal.pooled


def test_matched_validation_gaps_have_the_real_speed() -> None:
    """Artificial gaps are drawn near each real gap's end-point distance."""
    from pftrack.recovery.calibrate import _artificial_gaps

    rng = np.random.default_rng(9)
    runs = []
    for k in range(40):  # slow and fast walkers
        v = 0.5 if k % 2 else 6.0
        t = np.arange(100.0)
        runs.append(np.column_stack([t, v * t, np.zeros(100)]))
    for dist, lo, hi in ((5.0, 4.0, 6.0), (60.0, 50.0, 70.0)):
        cut = _artificial_gaps(runs, [(10, dist)], 30, np.random.default_rng(1))
        d = [np.hypot(*(b[0, 1:3] - a[-1, 1:3])) for a, b, _, _ in cut]
        assert len(cut) >= 20 and lo <= np.median(d) <= hi
    assert rng is not None


def test_validation_gaps_keep_the_real_context() -> None:
    """Artificial gaps keep as many observed points on each side as the real gap they match."""
    from pftrack.recovery.calibrate import CONTEXT, MAX_CONTEXT, _artificial_gaps

    t = np.arange(100.0)
    runs = [np.column_stack([t, k * t, np.zeros(100)]) for k in range(1, 21)]
    for n_a, n_b in ((1, 2), (4, 7), (60, 40)):
        cut = _artificial_gaps(runs, [(10, -1.0, n_a, n_b)], 40, np.random.default_rng(2))
        assert len(cut) == 40
        for a, b, truth, _ in cut:
            assert len(truth) == 10 and b[0, 0] - a[-1, 0] == 11
            assert len(b) == n_b if n_b <= MAX_CONTEXT else MAX_CONTEXT <= len(b) <= n_b
            start = int(truth[0, 0])  # frame 0 is the run's first point
            assert start >= min(max(n_a, CONTEXT), MAX_CONTEXT) and len(a) == min(n_a, start)
    whole = _artificial_gaps(runs, [(10, -1.0)], 40, np.random.default_rng(2))
    assert all(a[0, 0] == 0 and b[-1, 0] == 99 for a, b, _, _ in whole)  # whole runs without


def test_box_sizes_are_calibrated_too() -> None:
    """Boxes that grow and shrink smoothly: the sizes of filled rows follow the curve."""
    rng = np.random.default_rng(10)
    rows = []
    for tid in range(1, 31):
        t = np.arange(150.0)
        w = 40 + 15 * np.sin(t / rng.uniform(12, 20) + rng.uniform(0, 6))
        h = 2 * w
        cx, cy = 300 + 2 * t, 200 + 0.5 * t
        r = np.column_stack([t + 1, np.full(150, tid), cx - w / 2, cy - h / 2, w, h,
                             np.ones(150), -np.ones((150, 3))])  # fmt: skip
        rows.append(r)
    full = np.vstack(rows)
    hole = (full[:, 0] >= 70) & (full[:, 0] < 86)
    out, rep = fill_gaps(full[~hole])
    assert rep.size_calibration is not None and rep.size_calibration.pooled != "linear"
    lin, _ = fill_gaps(full[~hole], method="linear")
    key = full[hole][:, :2]

    def err(o: np.ndarray) -> float:
        got = o[np.isin(o[:, 0] * 1000 + o[:, 1], key[:, 0] * 1000 + key[:, 1])]
        got = got[np.lexsort((got[:, 0], got[:, 1]))]
        want = full[hole][np.lexsort((full[hole][:, 0], full[hole][:, 1]))]
        return float(np.abs(got[:, 4:6] - want[:, 4:6]).mean())

    assert err(out) < 0.5 * err(lin)
    assert np.all(out[:, 4:6] > 0)


def test_fill_report_records_its_method() -> None:
    """Regression (user trial): ``FillReport.describe(method)`` trusted its argument:
    ``fill_gaps(rows, "linear")[1].describe("auto")`` said "auto: no gap to fill" of 22 gaps
    filled, ``fill_gaps(rows)[1].describe("linear")`` printed auto's table, and a named
    method's line spoke of ``--explain`` from Python."""
    full = _mot_rows(_manoeuvring_tracks(np.random.default_rng(5), n=8))
    cut = full[~((full[:, 0] >= 60) & (full[:, 0] < 66))]
    _, lin = fill_gaps(cut, "linear")
    assert lin.method == "linear" and lin.n_gaps == 8
    said = lin.describe()
    assert said == "linear: 8 gaps filled by the method given, nothing was chosen (auto " \
        "chooses a method per gap length)"  # fmt: skip
    assert lin.describe("linear") == said  # the argument, kept for compatibility, agrees
    with pytest.raises(ValueError, match="FillReport.describe: the fill used 'linear', not 'auto'"):
        lin.describe("auto")
    _, auto = fill_gaps(cut)
    assert auto.method == "auto" and auto.describe().startswith("box centres (x, y):")
    with pytest.raises(ValueError, match="the fill used 'auto', not 'linear'"):
        auto.describe("linear")
    _, none = fill_gaps(full)  # no hole
    assert none.method == "auto" and none.describe() == "auto: no gap to fill"
    # holes, all longer than max_gap: was "auto: no gap to fill", of a file with 8 gaps
    _, long = fill_gaps(cut, max_gap=5)
    assert (long.n_gaps, long.n_long_holes, long.longest_hole) == (0, 8, 6)
    assert long.describe() == (
        "auto: no gap of at most max_gap frames to fill, nothing was chosen (8 holes longer, "
        "left unfilled; the longest 6 frames)"
    )
    _, one = fill_gaps(cut[(cut[:, 1] == cut[0, 1])], max_gap=5)
    assert one.describe() == (
        "auto: no gap of at most max_gap frames to fill, nothing was chosen (1 hole longer, "
        "left unfilled: 6 frames)"
    )


def test_cli_explain_prints_centres_and_sizes(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    from pftrack.cli import main
    from pftrack.io.mot import write_mot

    rng = np.random.default_rng(11)
    rows = []
    for tid, tr in enumerate(_manoeuvring_tracks(rng, n=12), start=1):
        keep = np.ones(len(tr), bool)
        keep[50:58] = False
        r = np.column_stack([tr[:, 0] + 1, np.full(len(tr), tid), tr[:, 1] - 10, tr[:, 2] - 20,
                             np.full((len(tr), 2), (20.0, 40.0)), np.ones(len(tr)),
                             -np.ones((len(tr), 3))])  # fmt: skip
        rows.append(r[keep])
    src = tmp_path / "t.txt"
    write_mot(src, np.vstack(rows))
    assert main(["recover", str(src), "--out", str(tmp_path / "o.txt"), "--explain"]) == 0
    out = capsys.readouterr().out
    assert "box centres (x, y):" in out and "box sizes (w, h):" in out
    assert "file's choice" in out and "5-8" in out
    assert main(["recover", str(src), "--out", str(tmp_path / "l.txt"), "--method", "linear",
                 "--explain"]) == 0  # fmt: skip
    assert "nothing was chosen" in capsys.readouterr().out


def test_combination_falls_back_to_linear_on_straight_jittered_segments() -> None:
    tracks = _straight_tracks(np.random.default_rng(0))
    cal = calibrate(tracks, [5, 12, 25], combine=True)
    assert [c.method for c in cal.buckets] == ["linear"] * 3, cal.describe()
    assert all(c.weights == () for c in cal.buckets)
    assert cal.weights_for(12) == (("linear", 1.0),)
    paths, _ = recover_auto(_cut(tracks, 12), tracks, combine=True)
    a, b = _cut(tracks, 12)[0]
    s = np.arange(1, 13) / 13.0
    line = (1 - s)[:, None] * a[-1, 1:3] + s[:, None] * b[0, 1:3]
    np.testing.assert_allclose(paths[0], line, atol=1e-9)


def _two_method_paths(rng: np.random.Generator, n: int) -> tuple[list, list, list]:
    """Truth and two predictors with independent errors of the same size (3-frame gaps)."""
    truth = [np.column_stack([np.arange(3.0), rng.uniform(0, 100, (3, 2))]) for _ in range(n)]
    first = [t[:, 1:3] + rng.normal(0, 1.0, (3, 2)) for t in truth]
    second = [t[:, 1:3] + rng.normal(0, 1.0, (3, 2)) for t in truth]
    return first, second, truth


def test_combination_weight_fitted_and_shrunk() -> None:
    """Two equally good, independent predictors: the fitted weight is near 1/2, shrunk by n."""
    from pftrack.recovery.calibrate import COMBINE_SHRINK, _combine, _gap_errors

    first, second, truth = _two_method_paths(np.random.default_rng(9), 400)
    w, err = _combine(first, second, truth)
    shrink = 400 / (400 + COMBINE_SHRINK)
    assert 0.4 * shrink <= w <= 0.6 * shrink
    # the errors are those of the blended paths, and lower than either predictor's
    blend = [(1 - w) * a + w * b for a, b in zip(first, second, strict=True)]
    np.testing.assert_allclose(err, _gap_errors(blend, truth), rtol=1e-12)
    assert err.mean() < _gap_errors(first, truth).mean()
    assert err.mean() < _gap_errors(second, truth).mean()
    # a useless second predictor gets no weight
    far = [a + 50.0 for a in second]
    assert _combine(first, far, truth)[0] == 0.0


def test_combination_weights_sum_to_one_and_are_reported() -> None:
    tracks = _manoeuvring_tracks(np.random.default_rng(1))
    pairs = _cut(tracks, 20)
    paths, cal = recover_auto(pairs, tracks, combine=True)
    for c in cal.buckets:
        mix = c.weights or ((c.method, 1.0),)
        assert abs(sum(w for _, w in mix) - 1.0) < 1e-12
        assert all(0.0 <= w <= 1.0 for _, w in mix)
        if c.weights:
            assert c.method == "+".join(m for m, _ in c.weights)
            assert c.combined_mmae is not None
            assert f"combination {c.weights[0][1]:.2f} {c.weights[0][0]}" in cal.describe()


def test_recover_auto_blends_a_combined_bucket(monkeypatch: pytest.MonkeyPatch) -> None:
    """A bucket's combination gives the weighted sum of its methods' paths."""
    import pftrack.recovery.calibrate as cal_mod
    from pftrack.recovery.calibrate import BucketChoice, recover_with
    from pftrack.recovery.noise import estimate_noise

    tracks = _manoeuvring_tracks(np.random.default_rng(1), n=8)
    pairs = _cut(tracks, 20)
    mix = (("rts", 0.3), ("gdt-bi", 0.7))
    fixed = Calibration((BucketChoice((17, 32), "rts+gdt-bi", 8, 50, (), mix, 1.0),), "linear")
    monkeypatch.setattr(cal_mod, "calibrate", lambda *a, **k: fixed)
    noise = estimate_noise(tracks)
    paths, cal = recover_auto(pairs, tracks, noise, candidates=("linear", "rts", "gdt-bi"))
    assert cal is fixed and cal.weights_for(20) == mix
    rts = recover_with("rts", pairs, noise, None)  # type: ignore[arg-type]
    bi = recover_with("gdt-bi", pairs, noise, None)  # type: ignore[arg-type]
    for p, r, g in zip(paths, rts, bi, strict=True):
        np.testing.assert_allclose(p, 0.3 * r + 0.7 * g, atol=1e-9)
    assert "combination 0.30 rts + 0.70 gdt-bi, validation MMAE 1.000" in cal.describe()


def test_combination_is_the_default_everywhere_auto_runs() -> None:
    """``fill_gaps`` (recover, smooth, the offline pass) blends by default; False: one method."""
    import inspect

    from pftrack.recovery.fill import fill_rows

    for fn in (calibrate, recover_auto, fill_gaps, fill_rows):
        assert inspect.signature(fn).parameters["combine"].default is True, fn.__name__
    full = _mot_rows(_manoeuvring_tracks(np.random.default_rng(0)))
    cut = full[~((full[:, 0] >= 80) & (full[:, 0] < 85))]  # 5-frame holes
    out, rep = fill_gaps(cut)
    out_on, rep_on = fill_gaps(cut, combine=True)
    out_off, rep_off = fill_gaps(cut, combine=False)
    assert rep.calibration is not None and rep_off.calibration is not None
    assert rep.calibration == rep_on.calibration
    np.testing.assert_array_equal(out, out_on)
    assert any(c.weights for c in rep.calibration.buckets), rep.calibration.describe()
    assert all(c.weights == () for c in rep_off.calibration.buckets)
    assert all("+" not in c.method for c in rep_off.calibration.buckets)
    # the blend moves the filled centres; observed rows are untouched
    assert out.shape == out_off.shape
    observed = out[:, 7] != 1
    np.testing.assert_array_equal(out[observed], out_off[observed])
    assert np.abs(out[~observed, 2:4] - out_off[~observed, 2:4]).max() > 1e-6
    # recover_gaps("auto") follows the same default
    pairs = _cut(_manoeuvring_tracks(np.random.default_rng(0)), 5)
    tracks = _manoeuvring_tracks(np.random.default_rng(0))
    got = recover_gaps(pairs, "auto", observed=tracks)
    want, cal = recover_auto(pairs, tracks, combine=True)
    assert any(c.weights for c in cal.buckets)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)


def test_fill_gaps_combine_must_be_a_bool() -> None:
    full = _mot_rows(_straight_tracks(np.random.default_rng(0), n=3))
    with pytest.raises(TypeError, match="combine must be a bool"):
        fill_gaps(full, combine="no")  # type: ignore[arg-type]


def test_combination_is_deterministic() -> None:
    tracks = _manoeuvring_tracks(np.random.default_rng(3), n=10)
    pairs = _cut(tracks, 17)
    p1, c1 = recover_auto(pairs, tracks, combine=True)
    p2, c2 = recover_auto(pairs, tracks, combine=True)
    assert c1 == c2
    for a, b in zip(p1, p2, strict=True):
        np.testing.assert_array_equal(a, b)


def test_cli_explain_prints_the_blend_weights(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """``pftrack recover --explain`` (default auto) names the blended methods and weights."""
    from pftrack.cli import main
    from pftrack.io.mot import read_mot, write_mot
    from pftrack.recovery.calibrate import _weight

    full = _mot_rows(_manoeuvring_tracks(np.random.default_rng(0)))
    src = tmp_path / "t.txt"
    write_mot(src, full[~((full[:, 0] >= 80) & (full[:, 0] < 85))])
    assert main(["recover", str(src), "--out", str(tmp_path / "o.txt"), "--explain"]) == 0
    out = capsys.readouterr().out
    _, rep = fill_gaps(read_mot(src))
    assert rep.calibration is not None
    blended = [c for c in rep.calibration.buckets if c.weights]
    assert blended, rep.calibration.describe()
    for c in blended:  # two methods or more (bagging averages the resamples' choices)
        mix = " + ".join(f"{_weight(w)} {m}" for m, w in c.weights)
        assert f"combination {mix}, validation MMAE" in out
    # the file holds the blended fill (written with 2 decimals)
    want, _ = fill_gaps(read_mot(src))
    np.testing.assert_allclose(read_mot(tmp_path / "o.txt"), want, rtol=0, atol=0.006)


def test_bucket_quotas_follow_the_real_gaps_with_a_floor():
    from pftrack.recovery.calibrate import MIN_VALIDATION_GAPS, bucket_quotas

    q = bucket_quotas({1: 1, 4: 1, 16: 8, 32: 10}, 300)
    assert q == {1: 15, 4: 15, 16: 120, 32: 150}  # 300 in proportion to 1 : 1 : 8 : 10
    q = bucket_quotas({1: 1, 64: 999}, 300)
    assert q[1] == MIN_VALIDATION_GAPS and q[64] == 300
    assert bucket_quotas({8: 3}, 120) == {8: 120}
    assert bucket_quotas({}, 300) == {}


def test_calibration_cuts_its_gaps_where_the_real_ones_are():
    rng = np.random.default_rng(5)
    observed = [
        np.column_stack([np.arange(200.0), np.cumsum(rng.normal(1.0, 0.3, 200)), np.zeros(200)])
        for _ in range(6)
    ]
    cal = calibrate(observed, [1] + [12] * 9, max_gaps=100)
    counts = {c.lengths: c.n_validation for c in cal.buckets}
    assert counts == {(1, 1): 10, (9, 16): 90}  # 100 in proportion to 1 : 9


def test_explain_says_a_blend_is_compared_with_the_chosen_method_only() -> None:
    """Regression: ``--explain`` showed "0.25 linear + 0.75 rts, validation MMAE 5.421" while
    rts alone scored 5.417, without saying why: the blend is tested against the chosen method
    (linear) only, and rts alone did not beat linear by the paired test."""
    mmae = (("linear", 5.6), ("rts", 5.417), ("gdt-bi", 6.0))
    mix = (("linear", 0.25), ("rts", 0.75))
    cal = Calibration((BucketChoice((1, 1), "linear+rts", 9, 60, mmae, mix, 5.421),), "linear")
    line = cal.describe().splitlines()[-1]
    assert line.startswith("gap length 1: combination 0.25 linear + 0.75 rts, validation MMAE "
                           "5.421; beats linear alone (5.600), the chosen method, by the paired "
                           "test; rts alone (5.417) did not, so it is not chosen (the blend is "
                           "compared with linear, not with every candidate)")  # fmt: skip
    better = (("linear", 5.6), ("rts", 5.5))  # the blend beats both parts: nothing to explain
    cal = Calibration((BucketChoice((1, 1), "linear+rts", 9, 60, better, mix, 5.421),), "linear")
    assert cal.describe().splitlines()[-1].endswith("by the paired test")


def test_bagging_is_the_default_and_keeps_straight_lines_straight() -> None:
    """Every resample of straight jittered data keeps linear: the fill is exactly a line."""
    import inspect

    from pftrack.recovery.calibrate import BAGS

    assert BAGS > 0
    from pftrack.recovery.fill import fill_rows

    for fn in (calibrate, recover_auto, recover_gaps, fill_gaps, fill_rows):
        # None: BAGS with the default combine=True (0 with combine=False)
        assert inspect.signature(fn).parameters["bags"].default is None, fn.__name__
    tracks = _straight_tracks(np.random.default_rng(0))
    cal = calibrate(tracks, [5, 12, 25])
    assert cal.bags == BAGS
    assert all(c.weights == () and c.method == "linear" for c in cal.buckets), cal.describe()
    assert cal.weights_for(12) == (("linear", 1.0),)


def test_bagging_averages_the_choices_of_the_resamples(monkeypatch: pytest.MonkeyPatch) -> None:
    """The weights are the share of resamples choosing each method, for buckets and file."""
    import pftrack.recovery.calibrate as cal_mod

    calls: list[object] = []
    real_choose = cal_mod._choose

    def fake(stacked, weights, names, combine, blends, idx=None):  # type: ignore[no-untyped-def]
        real_choose(stacked, weights, names, combine, blends, idx)  # the resample is valid
        calls.append(idx)
        m = "rts" if idx is not None and len(calls) % 4 == 0 else "linear"  # 1 in 4 resamples
        return m, {b: ((m, 1.0),) for b in stacked}

    monkeypatch.setattr(cal_mod, "_choose", fake)
    tracks = _manoeuvring_tracks(np.random.default_rng(1), n=12)
    cal = calibrate(tracks, [3, 20], candidates=("linear", "rts"), bags=8)
    assert len(calls) == 9 and calls[0] is None  # the rule as drawn, then 8 resamples
    for c in cal.buckets:
        assert c.weights == (("linear", 0.75), ("rts", 0.25)), cal.describe()
        assert c.method == "linear+rts" and c.combined_mmae is not None
    assert cal.pooled == "linear"  # the rule on the gaps as drawn
    assert cal.pooled_weights == (("linear", 0.75), ("rts", 0.25))
    assert cal.weights_for(300) == cal.pooled_weights  # an unseen bucket takes the file's
    assert "mean of the choices on 8 bootstrap resamples" in cal.describe()
    # the header says the weights too (was "file's choice linear" above a bucket line calling
    # "0.75 linear + 0.25 rts" the file's choice)
    assert (
        cal.describe()
        .splitlines()[0]
        .endswith("file's choice linear (0.75 linear + 0.25 rts over 8 bootstrap resamples)")
    )
    unseen = dataclasses.replace(
        cal.buckets[0], n_validation=0, mmae=(), weights=cal.pooled_weights, combined_mmae=None
    )
    said = dataclasses.replace(cal, buckets=(unseen,)).describe().splitlines()[-1]
    assert said.endswith(
        "combination 0.75 linear + 0.25 rts, the file's choice over the resamples (no "
        "validation gap of this length)"
    )


def test_bagging_is_seeded_and_reported() -> None:
    """The same seed gives the same bagged choice and fill; bags=0 is recorded as no bagging."""
    tracks = _manoeuvring_tracks(np.random.default_rng(4), n=10)
    pairs = _cut(tracks, 6)
    p1, c1 = recover_auto(pairs, tracks, seed=3)
    p2, c2 = recover_auto(pairs, tracks, seed=3)
    assert c1 == c2
    for a, b in zip(p1, p2, strict=True):
        np.testing.assert_array_equal(a, b)
    _, single = recover_auto(pairs, tracks, seed=3, bags=0)
    assert single.bags == 0 and c1.bags > 0
    for c in c1.buckets:
        mix = c.weights or ((c.method, 1.0),)
        assert abs(sum(w for _, w in mix) - 1.0) < 1e-12


def test_combine_false_is_one_method_per_bucket_without_bagging() -> None:
    """Regression (user trial): ``fill_gaps(rows, combine=False)`` came back with buckets such
    as ``gdt-mix+rts`` (KITTI-17: ``gdt-bi+gdt-mix+rts+linear``): bagging, on by default,
    averaged the single methods 32 resamples chose into a blend. combine=False now means no
    bagging (``bags=None``: 32 with combine, 0 without) and refuses ``bags > 0``."""
    full = _mot_rows(_manoeuvring_tracks(np.random.default_rng(3)))
    f = full[:, 0]
    cut = full[~(((f >= 40) & (f < 42)) | ((f >= 80) & (f < 85)) | ((f >= 120) & (f < 132)))]
    _, rep = fill_gaps(cut, combine=False)
    for cal in (rep.calibration, rep.size_calibration):
        assert cal is not None and cal.bags == 0 and cal.pooled_weights == ()
        assert all("+" not in c.method and c.weights == () for c in cal.buckets), cal.describe()
    _, bagged = fill_gaps(cut)  # the default: blends allowed, bagged
    assert bagged.calibration is not None and bagged.calibration.bags == BAGS
    _, also_bagged = fill_gaps(cut, bags=8)
    assert also_bagged.calibration is not None and also_bagged.calibration.bags == 8
    for call, who in (
        (lambda: fill_gaps(cut, combine=False, bags=8), "fill_gaps"),
        (lambda: calibrate(_straight_tracks(np.random.default_rng(0), n=5), [5], combine=False,
                           bags=8), "calibrate"),
        (lambda: recover_auto([(_A, _B)], combine=False, bags=1), "recover_auto"),
        (lambda: recover_gaps([(_A, _B)], combine=False, bags=2), "recover_gaps"),
    ):  # fmt: skip
        with pytest.raises(ValueError, match=rf"^{who}: bags is \d+ with combine=False"):
            call()
    with pytest.raises(ValueError, match=r"fill_gaps: bags is -1, expected an integer"):
        fill_gaps(cut, bags=-1)
    tracks = _straight_tracks(np.random.default_rng(0), n=5)
    assert calibrate(tracks, [5], combine=False).bags == 0
    assert calibrate(tracks, [5]).bags == BAGS


def test_explain_says_why_a_bucket_without_validation_gaps_takes_the_files_choice() -> None:
    """Regression (user trial): a bucket with ``val. 0`` (gaps longer than every observed run
    less its context) printed a row saying ``linear`` and no reason."""
    rng = np.random.default_rng(0)
    rows = []
    for k in range(12):
        n = 45 if k == 0 else 20  # id 1: a 25-frame hole; every run shorter than 25 + 6
        t = np.arange(n, dtype=np.float64)
        keep = np.ones(n, bool)
        keep[10:35] = k != 0
        keep[8:11] &= k not in (1, 2, 3)  # three 3-frame holes
        xy = np.column_stack([100 + 3 * t, 200 + 30 * k + 0 * t]) + rng.normal(0, 0.5, (n, 2))
        rows.append(np.column_stack([1 + t, np.full(n, k + 1), xy, np.full((n, 2), (20.0, 40.0)),
                                     np.ones(n), -np.ones((n, 3))])[keep])  # fmt: skip
    _, rep = fill_gaps(np.vstack(rows))
    assert rep.size_calibration is not None
    sizes = {c.lengths: c for c in rep.size_calibration.buckets}
    assert sizes[17, 32].n_validation == 0 and sizes[17, 32].method == "linear"
    said = rep.describe()
    assert "gap length 17-32: linear, the file's choice (no validation gap of this length)" in said
    assert re.search(
        r"gap length 3-4: linear, the file's choice \(only [1-4] validation gaps? of this "
        r"length, fewer than the 5 a bucket needs\)",
        said,
    )
    # the centres' bucket too, whatever the file's choice (one method or the resamples' mix)
    why = r"gap length 17-32: .*the file's choice.*\(no validation gap of this length\)$"
    assert len(re.findall(why, said, flags=re.M)) == 2, said


def test_bags_must_not_be_negative() -> None:
    tracks = _straight_tracks(np.random.default_rng(0), n=5)
    with pytest.raises(ValueError, match=r"bags is -1, expected an integer in \[0, "):
        calibrate(tracks, [5], bags=-1)


_RUN = np.column_stack([np.arange(1.0, 40), np.arange(39.0) * 2, np.arange(39.0)])
_A, _B = _RUN[:10], _RUN[15:]


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        # each was taken, or failed deep inside without the argument's name
        # a wrong type is a TypeError, an int out of range a ValueError
        ({"bags": 1.5}, TypeError,
         r"calibrate: bags must be an integer in \[0, 10000\], got float 1.5"),
        ({"bags": True}, TypeError, "calibrate: bags must be an integer .*, got bool True"),
        ({"bags": -1}, ValueError, r"calibrate: bags is -1, expected an integer in \[0, 10000\]"),
        ({"seed": -1}, ValueError, "calibrate: seed is -1, expected an int >= 0"),
        ({"seed": None}, TypeError, "calibrate: seed must be an int >= 0"),
        ({"seed": True}, TypeError, "calibrate: seed must be an int >= 0"),
        ({"max_gaps": 1.5}, TypeError, "calibrate: max_gaps must be an integer .*, got float"),
        ({"max_gaps": True}, TypeError, "calibrate: max_gaps must be an integer .*, got bool"),
        ({"combine": 1}, TypeError, "calibrate: combine"),
        ({"spans": [np.nan]}, ValueError, "calibrate: spans must be finite"),
        ({"contexts": [(1.5, 2)]}, TypeError, "calibrate: a context must be an integer .* 1.5"),
    ],
)  # fmt: skip
def test_calibrate_names_a_bad_setting(kwargs: dict, error: type, match: str) -> None:
    from pftrack.recovery.calibrate import calibrate

    with pytest.raises(error, match=match):
        calibrate([_RUN], [3], **kwargs)


@pytest.mark.parametrize(
    ("observed", "lengths", "error", "match"),
    [
        ([_RUN], [2.7], TypeError, "calibrate: a gap length must be an integer .*, got float 2.7"),
        ([_RUN], ["3"], TypeError, "calibrate: a gap length must be an integer .*, got str '3'"),
        ([_RUN], [0], ValueError, r"calibrate: a gap length is 0, expected an integer in \[1, "),
        ([np.where(np.arange(39)[:, None] == 5, np.nan, _RUN)], [3], ValueError,
         r"calibrate: observed run 0 has a non-finite frame, x or y"),  # was left out silently
        ([np.zeros((30, 2))], [3], ValueError, r"observed\[0\] has shape \(30, 2\)"),
        ("abc", [3], TypeError, "calibrate: observed must be a sequence"),
        ([["a", "b", "c"]], [3], TypeError, r"calibrate: observed\[0\] must hold real numbers"),
    ],
)  # fmt: skip
def test_calibrate_names_bad_observed_runs(observed, lengths, error, match) -> None:
    from pftrack.recovery.calibrate import calibrate

    with pytest.raises(error, match=match):
        calibrate(observed, lengths)


def test_recover_auto_and_recover_gaps_name_bad_settings() -> None:
    from pftrack.recovery import recover_gaps
    from pftrack.recovery.calibrate import recover_auto

    with pytest.raises(ValueError, match="recover_auto: bags is -1"):
        recover_auto([(_A, _B)], bags=-1)
    with pytest.raises(TypeError, match="recover_auto: seed must be an int"):
        recover_auto([(_A, _B)], seed="0")
    with pytest.raises(TypeError, match="recover_auto: combine"):
        recover_auto([(_A, _B)], combine="yes")
    with pytest.raises(ValueError, match=r"recover_auto: observed run 0 has a non-finite"):
        recover_auto([(_A, _B)], observed=[np.where(_RUN == 4, np.nan, _RUN)])
    # history 1.5 acted as 1, "2" and True were taken; combine=1 was taken
    for history in (1.5, "2", True):  # a wrong type: TypeError (was ValueError)
        with pytest.raises(TypeError, match="recover_gaps: history must be an integer in"):
            recover_gaps([(_A, _B)], "gdt", history=history)
    with pytest.raises(ValueError, match="recover_gaps: history is 0"):
        recover_gaps([(_A, _B)], "gdt", history=0)
    with pytest.raises(TypeError, match="recover_gaps: combine"):
        recover_gaps([(_A, _B)], combine=1)
    for method in ("linear-nb", "auto"):
        with pytest.raises(ValueError, match=r"observed\[0\] has shape \(30, 2\)"):
            recover_gaps([(_A, _B)], method, observed=[np.zeros((30, 2))])
    with pytest.raises(TypeError, match="observed must be a sequence"):
        recover_gaps([(_A, _B)], "linear-nb", observed="abc")
    # the same calls with good settings work
    assert recover_gaps([(_A, _B)], "gdt", history=5)[0].shape == (5, 2)
    assert recover_gaps([(_A, _B)], "linear-nb", observed=[_RUN])[0].shape == (5, 2)


def test_explain_prints_a_small_weight_as_what_it_is() -> None:
    """A bagged bucket of 0.998 linear + 0.002 rts was printed 'combination 1.00 linear +
    0.00 rts'."""
    from pftrack.recovery.calibrate import _weight

    assert [_weight(w) for w in (0.998, 0.0016, 0.25, 1.0)] == ["1.00", "0.0016", "0.25", "1.00"]


def test_a_bad_observed_run_is_named_by_its_place_in_observed() -> None:
    """An empty run before it shifted the number: the third run was named 'run 1'."""
    from pftrack.recovery.calibrate import calibrate

    bad = np.where(np.arange(39)[:, None] == 5, np.nan, _RUN)
    with pytest.raises(ValueError, match="calibrate: observed run 2 has a non-finite"):
        calibrate([_RUN, np.zeros((0, 3)), bad], [3])


def _holes(rows: np.ndarray, rng: np.random.Generator, n: int = 3) -> np.ndarray:
    """`rows` without `n` holes of 1-30 frames per track, at random places (seeded)."""
    keep = np.ones(len(rows), dtype=bool)
    for tid in np.unique(rows[:, 1]):
        at = np.flatnonzero(rows[:, 1] == tid)
        for _ in range(n):
            length = int(rng.integers(1, 31))
            start = int(rng.integers(5, max(6, len(at) - length - 5)))
            keep[at[start : start + length]] = False
    return rows[keep]


def test_fill_does_not_depend_on_how_the_ids_are_numbered() -> None:
    """The same tracks under other ids are filled alike (a trial found 647 of 744 rows moved).

    The artificial gaps are matched to the real gaps taken in turn: in the file's id order,
    until the real gaps were put in a canonical order.
    """
    rng = np.random.default_rng(11)
    rows = _holes(_mot_rows(_manoeuvring_tracks(rng, n=16)), rng)
    ids = np.unique(rows[:, 1])
    new = dict(zip(ids, rng.permutation(ids) + 100, strict=True))
    renamed = rows.copy()
    renamed[:, 1] = [new[i] for i in rows[:, 1]]
    out, rep = fill_gaps(rows, max_gap=50)
    out2, rep2 = fill_gaps(renamed, max_gap=50)
    back = {v: k for k, v in new.items()}
    out2[:, 1] = [back[i] for i in out2[:, 1]]

    def canon(o: np.ndarray) -> np.ndarray:
        return o[np.lexsort((o[:, 1], o[:, 0]))]

    assert rep.n_filled_rows > 0
    np.testing.assert_array_equal(canon(out), canon(out2))


def test_a_bucket_never_does_worse_than_linear_on_its_validation_gaps() -> None:
    """Where the rule's choice (a bagged blend) scores worse than linear, linear is used.

    PETS09-S2L1's box sizes with random holes: a bucket's bagged choice of ``rts`` and
    ``linear`` scored worse than ``linear`` alone on the bucket's own validation gaps.
    """
    gt = np.loadtxt(dataset("pets09-s2l1") / "gt.txt", delimiter=",")
    rows = _holes(gt, np.random.default_rng(0))
    _, rep = fill_gaps(rows)
    replaced = 0
    for cal in (rep.calibration, rep.size_calibration):
        assert cal is not None
        for c in cal.buckets:
            if not c.mmae:
                continue
            vals = dict(c.mmae)
            used = c.combined_mmae if c.combined_mmae is not None else vals[c.method]
            assert used <= vals["linear"] + 1e-12, cal.describe()
            if c.replaced is not None:
                replaced += 1
                assert c.method == "linear" and c.replaced[1] > vals["linear"]
                assert "did worse than linear" in cal.describe()
    assert replaced > 0  # the data exercise the rule


@pytest.mark.parametrize("shift", [1000.0, -777.0])
def test_fill_does_not_depend_on_where_the_tracks_are(shift: float) -> None:
    """A translated copy of a file is filled alike, up to round-off (a trial: 0.23 px apart).

    Distances between gap ends differ by round-off once translated; the calibration sorted the
    real gaps by them and kept the nearest of the drawn places, so round-off reordered exact
    ties (steps of 0.1 px make many) and another set of validation gaps was cut.
    """
    rng = np.random.default_rng(2)
    rows = []
    for i in range(12):
        xy = np.array([100.1 + 37.3 * i, 50.7 + 20.9 * i]) + np.cumsum(
            rng.integers(-15, 16, (120, 2)) / 10, axis=0
        )
        keep = rng.random(120) > 0.2
        keep[[0, -1]] = True
        track = np.column_stack([np.arange(1.0, 121.0), np.full(120, i + 1.0), xy])
        rows.append(np.column_stack([track, np.full((120, 2), [40.0, 80.0])])[keep])
    tracks = np.vstack(rows)
    moved = tracks.copy()
    moved[:, 2:4] += shift
    out, rep = fill_gaps(tracks)
    out2, rep2 = fill_gaps(moved)
    assert rep.n_filled_rows > 0
    np.testing.assert_allclose(out2[:, 2:4] - shift, out[:, 2:4], rtol=0, atol=1e-9)
    assert rep.describe() == rep2.describe()


@pytest.mark.parametrize("seed", range(6))
def test_artificial_gaps_are_one_attempt_at_a_time(seed):
    """The places of several attempts are matched in a few array operations: the same gaps
    as one attempt at a time (tests/reference/calibrate.py), and the same draws (the
    generator's state after the call), with or without distances and contexts, places
    drawn twice (few runs, many gaps wanted) and lengths no run has room for."""
    from pftrack.recovery.calibrate import _artificial_gaps
    from tests.reference.calibrate import artificial_gaps

    rng = np.random.default_rng(seed)
    runs = []
    for _ in range(int(rng.integers(1, 12))):
        k = int(rng.integers(1, 70))
        frames = np.arange(k, dtype=float) + float(rng.integers(1, 500))
        xy = np.cumsum(rng.normal(0, 2, (k, 2)), axis=0)
        runs.append(np.column_stack([frames, xy]))
    cut = 0
    for kind in ("plain", "distance", "context"):
        targets = []
        for _ in range(int(rng.integers(1, 6))):
            L, dist = int(rng.integers(1, 60)), float(rng.exponential(8))
            if kind == "plain":
                targets.append((L, -1.0))
            elif kind == "distance":
                targets.append((L, dist))
            else:
                targets.append((L, dist, int(rng.integers(-1, 30)), int(rng.integers(-1, 30))))
        n = int(rng.integers(1, 150))
        got_rng, want_rng = np.random.default_rng([seed, 1]), np.random.default_rng([seed, 1])
        got = _artificial_gaps(runs, targets, n, got_rng)
        want = artificial_gaps(runs, targets, n, want_rng)
        assert len(got) == len(want)
        cut += len(got)
        for g, w in zip(got, want, strict=True):
            assert g[3] == w[3]  # the run cut from, then its segments and truth
            assert all(np.array_equal(a, b) for a, b in zip(g[:3], w[:3], strict=True))
        assert got_rng.integers(1 << 62) == want_rng.integers(1 << 62)
    assert cut > 0
