"""``"auto"``'s validation gaps cut by square regions, as a mask or an occluder cuts real gaps."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pftrack.recovery.calibrate as cal
from pftrack.recovery import fill_gaps
from pftrack.recovery.calibrate import (
    SPAN_DECIMALS,
    RegionBlocks,
    _artificial_gaps,
    _flat,
    _region_blocks,
    calibrate,
    recover_auto,
)
from tests.reference.regions import region_blocks as reference_blocks

from .test_auto import _cut, _manoeuvring_tracks, _mot_rows


def _walks(rng: np.random.Generator, n: int = 12, length: int = 60) -> list[np.ndarray]:
    """Random walks ``(frame, x, y)`` of 2 px steps in a 100 px field, one run each."""
    out = []
    for _ in range(n):
        xy = rng.uniform(0, 100, 2) + np.cumsum(rng.normal(0, 2.0, (length, 2)), axis=0)
        out.append(np.column_stack([np.arange(length, dtype=np.float64), xy]))
    return out


def _literal_blocks(runs: list[np.ndarray], centres: np.ndarray, side: float) -> RegionBlocks:
    """Square by square, run by run, point by point: every stretch inside a square with a
    point outside it before and after in its run."""
    run, start, length = [], [], []
    for c in centres:
        for i, r in enumerate(runs):
            inside = [bool(np.all(np.round(np.abs(p[1:3] - c), 6) <= side / 2)) for p in r]
            k = 0
            while k < len(r):
                if not inside[k]:
                    k += 1
                    continue
                e = k
                while e + 1 < len(r) and inside[e + 1]:
                    e += 1
                if k > 0 and e < len(r) - 1:
                    run.append(i)
                    start.append(k)
                    length.append(e - k + 1)
                k = e + 1
    i64 = np.int64
    return RegionBlocks(np.array(run, i64), np.array(start, i64), np.array(length, i64))


@pytest.mark.parametrize("side", [3.0, 15.0, 60.0])
def test_region_blocks_are_the_stretches_inside_each_square(side: float) -> None:
    runs = _walks(np.random.default_rng(4))
    flat = _flat(runs)
    got = _region_blocks(flat, side, np.random.default_rng(7), squares=40)
    centres = flat[2][np.random.default_rng(7).integers(len(flat[2]), size=40)]
    want = _literal_blocks(runs, centres, side)
    assert len(want.run) > 0
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)


def test_region_work_bounds_the_squares(monkeypatch: pytest.MonkeyPatch) -> None:
    """With no work left for a second square, one square is laid (the first)."""
    import pftrack.recovery.calibrate as cal

    runs = _walks(np.random.default_rng(5))
    flat = _flat(runs)
    monkeypatch.setattr(cal, "REGION_WORK", 0)
    got = _region_blocks(flat, 30.0, np.random.default_rng(3), squares=40)
    first = flat[2][np.random.default_rng(3).integers(len(flat[2]), size=40)][:1]
    for g, w in zip(got, _literal_blocks(runs, first, 30.0), strict=True):
        np.testing.assert_array_equal(g, w)


def test_no_side_no_region() -> None:
    flat = _flat(_walks(np.random.default_rng(6)))
    for side in (0.0, float("nan")):
        assert all(len(v) == 0 for v in _region_blocks(flat, side, np.random.default_rng(0)))


def test_region_gaps_are_lost_inside_a_square_and_ends_outside() -> None:
    """Every validation gap cut by a region: its lost points inside one square of the side, its
    two end points outside it; the rest (lengths no square cuts) at random places."""
    runs = _walks(np.random.default_rng(8), n=20, length=80)
    flat = _flat(runs)
    side = 12.0
    rng = np.random.default_rng(1)
    blocks = _region_blocks(flat, side, rng)
    marks: list[bool] = []
    targets = [(2, 4.0, 5, 5), (3, 6.0, 5, 5), (40, 20.0, 5, 5)]
    cut = _artificial_gaps(runs, targets, 60, np.random.default_rng(2), flat, blocks, marks)
    assert len(marks) == len(cut) == 60
    by_region = [g for g, m in zip(cut, marks, strict=True) if m]
    assert 0 < len(by_region) < len(cut)  # no square holds a walk for 40 frames: random places
    stretches = set(
        zip(blocks.run.tolist(), blocks.start.tolist(), blocks.length.tolist(), strict=True)
    )
    for a, b, truth, i in by_region:  # each run starts at frame 0: a frame is its index
        assert (i, int(truth[0, 0]), len(truth)) in stretches  # inside a square, ends outside
        assert len(truth) in (2, 3) and len(a) == len(b) == 5
        lo, hi = truth[:, 1:3].min(axis=0), truth[:, 1:3].max(axis=0)
        assert np.all(hi - lo <= side)
    assert all(len(t) == 40 for (_, _, t, _), m in zip(cut, marks, strict=True) if not m)


def test_calibration_says_the_regions_it_cut_by() -> None:
    tracks = _manoeuvring_tracks(np.random.default_rng(0))
    pairs = _cut(tracks, 5)
    _, cal = recover_auto(pairs, tracks)
    spans = [np.hypot(*(b[0, 1:3] - a[-1, 1:3])) for a, b in pairs]
    assert cal.region == round(max(spans), SPAN_DECIMALS)
    n_reg = sum(c.n_region for c in cal.buckets)
    assert 0 < n_reg <= sum(c.n_validation for c in cal.buckets)
    said = cal.describe().splitlines()[0]
    assert f"where a square of side {cal.region:.3g} px crosses them" in said
    n_val = sum(c.n_validation for c in cal.buckets)
    assert f"({n_reg} of {n_val} where" in said
    assert ("the others at random places" in said) == (n_reg < n_val)
    _, off = recover_auto(pairs, tracks, regions=False)
    assert off.region is None and all(c.n_region == 0 for c in off.buckets)
    assert "square" not in off.describe()
    # without the real gaps' end-point distances there is no side: random places only
    lengths = [5] * len(pairs)
    assert calibrate(tracks, lengths, bags=0).region is None


def test_fill_cuts_centres_by_regions_not_sizes() -> None:
    """Box sizes are not image positions: their calibration keeps random places."""
    full = _mot_rows(_manoeuvring_tracks(np.random.default_rng(0)))
    _, rep = fill_gaps(full[~((full[:, 0] >= 80) & (full[:, 0] < 85))])
    assert rep.calibration is not None and rep.calibration.region is not None
    assert rep.size_calibration is not None and rep.size_calibration.region is None


def test_a_translated_file_is_cut_by_the_same_squares() -> None:
    """Points on a half-pixel grid sit exactly on square edges; a translated copy, whose
    differences equal the original's only up to round-off, keeps them on the same side."""
    runs = [
        np.column_stack([r[:, 0], np.round(r[:, 1:3]) + 0.5])
        for r in _walks(np.random.default_rng(9))
    ]
    moved = [np.column_stack([r[:, 0], r[:, 1:3] + [0.1, 0.2]]) for r in runs]
    a = _region_blocks(_flat(runs), 4.0, np.random.default_rng(5))
    b = _region_blocks(_flat(moved), 4.0, np.random.default_rng(5))
    assert len(a.run) > 0
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


@st.composite
def _region_inputs(draw: st.DrawFn) -> tuple[list[np.ndarray], float, int, int, int]:
    """Runs (one-point runs and no run included), a side, squares, a work budget and a seed.

    Points on a grid of half the side (on the squares' edges), sometimes translated (distances
    equal to half a side up to round-off), or anywhere (up to 1.7e308: differences overflow);
    sides from subnormal to 1e12 px; budgets that cut the squares short (0: the first square
    alone) or not."""
    sizes = draw(st.lists(st.integers(1, 30), min_size=0, max_size=12))
    side = draw(st.sampled_from([5e-324, 1e-9, 1e-6, 0.5, 2.0, 3.0, 4.0, 7.25, 40.0, 1e12]))
    grid = draw(st.sampled_from(["grid", "translated", "uniform", "huge", "vast"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    total = sum(sizes)
    if grid == "uniform":
        xy = rng.uniform(-50.0, 50.0, (total, 2))
    elif grid == "huge":
        xy = rng.uniform(-1e9, 1e9, (total, 2))
    elif grid == "vast":  # differences that overflow to inf
        xy = rng.uniform(-1.0, 1.0, (total, 2)) * 1.7e308
    else:
        step = 0.5 * side if side >= 1e-6 else 1.0
        xy = rng.integers(-8, 9, (total, 2)) * step
        if grid == "translated":
            xy = xy + [0.1, 0.2]
    runs = []
    for k, n in enumerate(sizes):
        at = sum(sizes[:k])
        runs.append(np.column_stack([np.arange(n, dtype=np.float64), xy[at : at + n]]))
    squares = draw(st.integers(1, 60))
    work = draw(st.sampled_from([0, 1, 10, 100, 10**9]))
    return runs, side, squares, work, draw(st.integers(0, 2**32 - 1))


@settings(max_examples=400, deadline=None)
@given(_region_inputs())
def test_region_blocks_equal_the_numpy_loop_bit_for_bit(
    args: tuple[list[np.ndarray], float, int, int, int],
) -> None:
    """The C++ squares (``_core.region_blocks``) give the stretches of the NumPy loop they
    replaced (tests/reference/regions.py) in the same order, from the same draws."""
    runs, side, squares, work, seed = args
    flat = _flat(runs)
    g_rng, w_rng = np.random.default_rng(seed), np.random.default_rng(seed)
    want = reference_blocks(flat, side, w_rng, squares, work)
    with mock.patch.object(cal, "REGION_WORK", work):
        got = _region_blocks(flat, side, g_rng, squares)
    for g, w in zip(got, want, strict=True):
        assert g.dtype == w.dtype == np.int64
        np.testing.assert_array_equal(g, w)
    assert g_rng.integers(2**62) == w_rng.integers(2**62)  # the same draws taken


def test_region_blocks_on_the_500_track_file_equal_the_numpy_loop() -> None:
    """The squares of the 500-track benchmark file (its budget cuts them at about 1700) and of
    a side of 5 px and 300 px: the same stretches as the NumPy loop."""
    from bench.recovery_file import synthetic_tracks

    rows = synthetic_tracks(500, seed=0)
    runs = [rows[rows[:, 1] == i][:, [0, 2, 3]] for i in np.unique(rows[:, 1])]
    flat = _flat(runs)
    for side in (5.0, 57.25, 300.0):
        got = _region_blocks(flat, side, np.random.default_rng(1))
        want = reference_blocks(flat, side, np.random.default_rng(1))
        assert len(want.run) > 0
        for g, w in zip(got, want, strict=True):
            np.testing.assert_array_equal(g, w)


def test_calibration_without_validation_gaps_says_none_could_be_cut() -> None:
    """Was: "(0 of 0 where a square of side 9.49 px crosses them)": runs of 2 frames only."""
    rows = np.array(
        [[f, i, 10.0 + 3 * f + 50 * i, 20.0 + f, 30.0, 60.0, 1, -1, -1, -1] for i in (1, 2, 3)
         for f in (1, 2, 5, 6, 9, 10)]
    )  # fmt: skip
    _, rep = fill_gaps(rows, "auto", 10)
    said = [line for line in rep.describe().splitlines() if line.startswith("auto:")]
    assert len(said) == 2  # box centres (cut by squares), box sizes (at random places)
    for line in said:
        assert "0 of 0" not in line and "square" not in line and "MMAE" not in line
        assert line.startswith("auto: no validation gap could be cut: no observed run holds ")
        assert line.endswith("; file's choice linear")
