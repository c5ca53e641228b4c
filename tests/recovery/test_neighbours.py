"""Common-motion correction (``"linear-nb"``, ``"rts-nb"``) and its place in ``"auto"``."""

from __future__ import annotations

import numpy as np
import pytest

import pftrack.recovery.neighbours as neighbours
from pftrack.recovery import recover_gaps
from pftrack.recovery.calibrate import CANDIDATES, calibrate, recover_auto
from pftrack.recovery.neighbours import (
    MAX_NEIGHBOURS,
    Neighbourhood,
    correct_by_neighbours,
)
from pftrack.recovery.segments import distinct_runs
from tests.reference.neighbours import windows as reference_windows


def _bob(t: np.ndarray) -> np.ndarray:
    """A carried camera's bob and sway, shared by every object in the image (px)."""
    return np.column_stack([3.0 * np.sin(t / 5.0), 6.0 * np.sin(t / 3.0 + 1.0)])


def _carried_camera_tracks(
    rng: np.random.Generator, n: int = 20, length: int = 150, own: float = 0.0
) -> list[np.ndarray]:
    """Walkers at constant velocity (plus `own` px of smooth wander) seen by a bobbing camera."""
    t = np.arange(length, dtype=np.float64)
    out = []
    for _ in range(n):
        v = rng.uniform(-2, 2, 2)
        wander = own * np.column_stack(
            [np.sin(t / rng.uniform(6, 12) + rng.uniform(0, 6)) for _ in range(2)]
        )
        xy = rng.uniform(100, 500, 2) + t[:, None] * v + wander + _bob(t)
        out.append(np.column_stack([t, xy]))
    return out


def _linear_path(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    n = int(b[0, 0] - a[-1, 0]) - 1
    s = (np.arange(1, n + 1) / (n + 1))[:, None]
    return (1 - s) * a[-1, 1:3] + s * b[0, 1:3]


def _reference_correction(
    pair: tuple[np.ndarray, np.ndarray], others: list[np.ndarray]
) -> np.ndarray:
    """Plain NumPy: each track seen over the gap, cut like it; median of linear's errors."""
    a, b = pair
    fa, fb = a[-1, 0], b[0, 0]
    errs = []
    for r in others:
        if r[0, 0] <= fa and r[-1, 0] >= fb:
            inside = (r[:, 0] > fa) & (r[:, 0] < fb)
            ra, rb = r[r[:, 0] <= fa], r[r[:, 0] >= fb]
            errs.append(r[inside, 1:3] - _linear_path(ra, rb))
    errs = errs[:MAX_NEIGHBOURS]  # the test keeps the others fewer than the cap
    n = len(errs)
    return _linear_path(a, b) + np.median(np.array(errs), axis=0) * n / (n + 1)


def _linear(pairs: list[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    return [_linear_path(a, b) for a, b in pairs]


def test_correction_matches_a_numpy_reference() -> None:
    tracks = _carried_camera_tracks(np.random.default_rng(0), n=6, own=1.0)
    gap = tracks[0]
    pair = (gap[:60], gap[75:])
    others = tracks[1:]
    got = correct_by_neighbours(_linear, [pair], Neighbourhood(distinct_runs(others)))[0]
    np.testing.assert_allclose(got, _reference_correction(pair, others), atol=1e-9)


def test_shared_motion_is_recovered_up_to_the_shrinkage() -> None:
    """Only the camera bends the paths: the error left is linear's over (n + 1)."""
    tracks = _carried_camera_tracks(np.random.default_rng(1), n=5)
    gap = tracks[0]
    pair = (gap[:50], gap[70:])
    truth = gap[50:70, 1:3]
    plain = _linear([pair])[0]
    hood = Neighbourhood(distinct_runs(tracks[1:]))
    got = correct_by_neighbours(_linear, [pair], hood)[0]
    np.testing.assert_allclose(got - truth, (plain - truth) / 5.0, atol=1e-9)
    assert np.abs(plain - truth).max() > 3.0  # the bob bends the path: a real correction


def test_windows_leave_out_the_excluded_run_and_cap_the_count() -> None:
    tracks = _carried_camera_tracks(np.random.default_rng(2), n=12)
    runs = distinct_runs(tracks)
    hood = Neighbourhood(runs)
    a, b = runs[3][:40], runs[3][55:]
    wins = hood.windows(a, b, exclude=3)
    assert len(wins) == MAX_NEIGHBOURS
    for wa, wb, truth in wins:
        assert len(wa) == len(a) and len(wb) == len(b) and len(truth) == 15
        assert wa[-1, 0] == a[-1, 0] and wb[0, 0] == b[0, 0]
    deleted = runs[3][40:55]
    assert not any(np.array_equal(t, deleted) for _, _, t in wins)
    np.testing.assert_array_equal(hood.windows(a, b)[0][2], deleted)  # unless left out
    d = [np.hypot(*(w[0][-1, 1:3] - a[-1, 1:3])) for w in wins]
    assert d == sorted(d)  # nearest first
    every = sorted(np.hypot(*(r[39, 1:3] - a[-1, 1:3])) for r in runs if r is not runs[3])
    assert d == every[:MAX_NEIGHBOURS]  # the nearest ones
    short = [r[:45] for r in tracks[1:]]  # nobody is seen up to the gap's far end
    assert Neighbourhood(distinct_runs(short)).windows(a, b) == []


def test_a_track_on_other_frame_times_is_no_neighbour() -> None:
    """Observed frames half a frame off the gap's (fractional frame numbers) are not its frames."""
    tracks = _carried_camera_tracks(np.random.default_rng(9), n=3)
    pair = (tracks[0][:50], tracks[0][70:])
    shifted = [np.column_stack([tr[:, 0] + 0.5, tr[:, 1:]]) for tr in tracks[1:]]
    assert Neighbourhood(distinct_runs(shifted)).windows(*pair) == []
    np.testing.assert_array_equal(
        recover_gaps([pair], "linear-nb", observed=shifted)[0], recover_gaps([pair], "linear")[0]
    )
    assert len(Neighbourhood(distinct_runs(tracks[1:])).windows(*pair)) == 2


def test_without_neighbours_the_method_is_unchanged() -> None:
    tracks = _carried_camera_tracks(np.random.default_rng(3), n=1)
    pair = (tracks[0][:50], tracks[0][70:])
    for method in ("linear", "rts"):
        base = recover_gaps([pair], method)[0]
        np.testing.assert_array_equal(recover_gaps([pair], f"{method}-nb")[0], base)


def test_recover_gaps_uses_the_observed_tracks() -> None:
    tracks = _carried_camera_tracks(np.random.default_rng(4), own=0.5)
    pairs = [(tr[:50], tr[66:]) for tr in tracks[:5]]
    truth = [tr[50:66, 1:3] for tr in tracks[:5]]

    def mmae(paths: list[np.ndarray]) -> float:
        errors = [np.hypot(*(p - t).T).mean() for p, t in zip(paths, truth, strict=True)]
        return float(np.mean(errors))

    for method in ("linear", "rts"):
        plain = mmae(recover_gaps(pairs, method))
        corrected = mmae(recover_gaps(pairs, f"{method}-nb", observed=tracks[5:]))
        assert corrected < 0.5 * plain, (method, corrected, plain)


def test_auto_picks_the_correction_under_a_carried_camera() -> None:
    tracks = _carried_camera_tracks(np.random.default_rng(5), own=0.5)
    cal = calibrate(tracks, [6, 12, 20] * 4)
    assert cal.pooled.endswith("-nb"), cal.describe()
    pairs = [(tr[:60], tr[72:]) for tr in tracks[:6]]
    truth = [tr[60:72, 1:3] for tr in tracks[:6]]
    paths, _ = recover_auto(pairs, tracks)
    lin = recover_gaps(pairs, "linear")
    err = [np.hypot(*(p - t).T).mean() for p, t in zip(paths, truth, strict=True)]
    err_lin = [np.hypot(*(p - t).T).mean() for p, t in zip(lin, truth, strict=True)]
    assert np.mean(err) < 0.5 * np.mean(err_lin)


def test_auto_leaves_the_correction_out_when_objects_move_alone() -> None:
    """Still camera, walkers that wander each on their own: no shared motion to borrow."""
    rng = np.random.default_rng(6)
    t = np.arange(150.0)
    tracks = []
    for _ in range(20):
        wander = 6.0 * np.column_stack(
            [np.sin(t / rng.uniform(4, 9) + rng.uniform(0, 6)) for _ in range(2)]
        )
        tracks.append(np.column_stack([t, rng.uniform(100, 500, 2) + wander]))
    cal = calibrate(tracks, [6, 12, 20] * 4)
    assert not any(c.method.endswith("-nb") or "-nb+" in c.method for c in cal.buckets)
    assert not cal.pooled.endswith("-nb"), cal.describe()


def test_calibration_never_borrows_the_cut_runs_own_points() -> None:
    """One track alone: its artificial gaps have no neighbour, so "-nb" scores as its base.

    Were the run an artificial gap was cut from its own neighbour, the correction would see
    the deleted points and "linear-nb" would score far below "linear".
    """
    rng = np.random.default_rng(7)
    track = _carried_camera_tracks(rng, n=1, length=400, own=2.0)
    cal = calibrate(track, [8, 8, 8, 16, 16], candidates=("linear", "linear-nb", "rts", "rts-nb"))
    for c in cal.buckets:
        scores = dict(c.mmae)
        assert scores["linear-nb"] == scores["linear"] and scores["rts-nb"] == scores["rts"]


def test_candidates_include_the_corrected_methods() -> None:
    assert "linear-nb" in CANDIDATES and "rts-nb" in CANDIDATES


@pytest.mark.parametrize("seed", [0, 1])
def test_deterministic(seed: int) -> None:
    tracks = _carried_camera_tracks(np.random.default_rng(8), own=0.5)
    pairs = [(tr[:60], tr[72:]) for tr in tracks[:6]]
    p1, c1 = recover_auto(pairs, tracks, seed=seed)
    p2, c2 = recover_auto(pairs, tracks, seed=seed)
    assert c1 == c2
    for a, b in zip(p1, p2, strict=True):
        np.testing.assert_array_equal(a, b)


def test_windows_many_is_windows_pair_by_pair() -> None:
    """The vectorised search finds the same windows, in the same order, as the reference's one
    run at a time (excluded runs, no neighbour, a repeated pair, fewer neighbours than the
    cap)."""
    rng = np.random.default_rng(4)
    tracks = _carried_camera_tracks(rng, n=15)
    tracks.append(tracks[2].copy())  # a run twice: distinct_runs keeps one
    tracks += [tr[20:90] for tr in tracks[5:8]]  # shorter runs: some gaps have fewer
    runs = distinct_runs(tracks)
    pairs, excludes = [], []
    for k in range(40):
        i = int(rng.integers(len(runs)))
        r = runs[i]
        s, L = int(rng.integers(1, len(r) - 10)), int(rng.integers(1, 8))
        pairs.append((r[:s], r[s + L :]))
        excludes.append(i if k % 3 else -1)
    pairs.append(pairs[0])
    excludes.append(excludes[0])
    pairs.append((runs[0][:5] + [0.0, 0.0, 0.0], runs[0][-5:] + [500.0, 0.0, 0.0]))
    excludes.append(-1)
    got = Neighbourhood(runs).windows_many(pairs, excludes)
    for ws, (a, b), e in zip(got, pairs, excludes, strict=True):
        want = reference_windows(runs, a, b, e, MAX_NEIGHBOURS)
        assert len(ws) == len(want)
        for w, v in zip(ws, want, strict=True):
            for x, y in zip(w, v, strict=True):
                np.testing.assert_array_equal(x, y)
    assert got[-1] == []


def _covering_runs(n_runs: int, n_gaps: int) -> tuple[list[np.ndarray], list[tuple]]:
    """`n_runs` runs over frames 1-200, every one a neighbour of each of `n_gaps` gaps."""
    rng = np.random.default_rng(0)
    runs = [
        np.column_stack([np.arange(1, 201.0), rng.uniform(0, 500, (200, 2))]) for _ in range(n_runs)
    ]
    pairs = []
    for g in range(n_gaps):
        r = runs[g % n_runs] + [0.0, 0.5, 0.5]
        s = int(rng.integers(20, 150))
        pairs.append((r[:s], r[s + 5 :]))
    return runs, pairs


@pytest.mark.parametrize("block", [1, 50, 1000])
def test_windows_many_in_blocks_are_the_windows_at_once(monkeypatch, block) -> None:
    """(gap, run) pairs searched SEARCH_BLOCK at a time (one gap's at least): the windows of
    the search over every pair at once, in the same order."""
    runs, pairs = _covering_runs(30, 60)
    excludes = [g % 30 if g % 2 else -1 for g in range(60)]
    monkeypatch.setattr(neighbours, "SEARCH_BLOCK", 1 << 40)
    whole = Neighbourhood(runs).windows_many(pairs, excludes)
    monkeypatch.setattr(neighbours, "SEARCH_BLOCK", block)
    got = Neighbourhood(runs).windows_many(pairs, excludes)
    assert [len(w) for w in got] == [len(w) for w in whole] == [MAX_NEIGHBOURS] * 60
    for ws, vs in zip(got, whole, strict=True):
        for w, v in zip(ws, vs, strict=True):
            assert all(x.tobytes() == y.tobytes() for x, y in zip(w, v, strict=True))


def test_windows_many_searches_in_bounded_memory() -> None:
    """1000 runs, each a neighbour of 1000 gaps: the search took 2**22 (gap, run) pairs at a
    time, about 80 bytes each in temporaries (tracemalloc peak 82 MB here, 329 MB for 2000 x
    2000); now SEARCH_BLOCK = 2**16: 9 MB."""
    import tracemalloc

    runs, pairs = _covering_runs(1000, 1000)
    hood = Neighbourhood(runs)
    tracemalloc.start()
    try:
        got = hood.windows_many(pairs, [-1] * len(pairs))
        peak = tracemalloc.get_traced_memory()[1] / 1e6
    finally:
        tracemalloc.stop()
    assert peak < 30, f"{peak:.0f} MB"
    assert all(len(w) == MAX_NEIGHBOURS for w in got)
