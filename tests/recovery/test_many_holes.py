"""``auto`` on one track with thousands of holes: memory grows with the track, not per hole.

A user trial: ``fill_gaps`` (``"auto"``) on one track seen every other frame (8000 holes) took
4.1 GB, because every hole's segments held the whole track before and after it and were copied
(checked, their sizes cut out, stacked for the ``gdt`` batch): the track's length times its
holes (the ``gdt`` methods' batch stacked them too). Now each hole's segments are cut to the
points the methods read (:func:`pftrack.recovery.calibrate.gap_windows`; not for ``gsi``),
with the same bits.
"""

from __future__ import annotations

import re
import time
import tracemalloc

import numpy as np
import pytest

from pftrack.recovery import fill, fill_gaps, recover_gaps, registry
from pftrack.recovery.calibrate import WINDOW_POINTS, GapWindows, gap_windows, recover_auto
from pftrack.recovery.registry import METHODS


def _one_track(n_holes: int, seed: int = 0) -> np.ndarray:
    """One id seen on every other frame: `n_holes` holes of 1 frame."""
    rng = np.random.default_rng(seed)
    fr = np.arange(1.0, 2 * n_holes + 2, 2.0)
    k = len(fr)
    x = 500 + np.cumsum(rng.normal(0, 1, k))
    return np.column_stack([fr, np.ones(k), x, 300 + 0.1 * fr, np.full((k, 2), (20.0, 40.0)),
                            np.ones(k), -np.ones((k, 3))])  # fmt: skip


def _tracks(seed: int = 0) -> np.ndarray:
    """Walkers with holes of 1-12 frames, runs both shorter and longer than WINDOW_POINTS."""
    rng = np.random.default_rng(seed)
    out = []
    for tid in range(1, 9):
        n = int(rng.integers(150, 400))
        v = rng.normal(0, 2.0, 2)
        p = rng.uniform(200, 800, 2)
        pts = np.empty((n, 2))
        for k in range(n):
            v += -0.05 * v + rng.normal(0, 0.3, 2)
            p = p + v
            pts[k] = p
        pts += rng.normal(0, 0.5, pts.shape)
        keep = np.ones(n, dtype=bool)
        for _ in range(int(rng.integers(3, 12))):
            s, length = int(rng.integers(3, n - 20)), int(rng.integers(1, 13))
            keep[s : s + length] = False
        fr = 1 + int(rng.integers(0, 50)) + np.arange(n)
        w, h = rng.uniform(20, 60), rng.uniform(60, 150)
        box = np.column_stack([pts - (w / 2, h / 2), np.full((n, 2), (w, h))])
        rows = np.column_stack([fr, np.full(n, tid), box, np.ones(n), -np.ones((n, 3))])
        out.append(rows[keep])
    return np.vstack(out)


def _whole(frames: np.ndarray, ids: np.ndarray) -> GapWindows:
    """:func:`gap_windows` with every window the whole track: the segments as they were."""
    w = gap_windows(frames, ids)
    return GapWindows(w.holes, w.first, w.end, w.first, w.end)


@pytest.mark.parametrize("method", ["auto", "gdt-bi", "gdt-mix"])
def test_one_track_of_many_holes_is_bounded_in_memory(method: str) -> None:
    rows = _one_track(1000)
    tracemalloc.start()
    try:
        out, rep = fill_gaps(rows, method)  # type: ignore[arg-type]
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert rep.n_gaps == 1000 and len(out) == len(rows) + 1000
    # auto 64 MB before, gdt-bi 42 MB (the track's length per hole: auto 4.1 GB for 8000
    # holes); 6 MB now
    assert peak < 25 * 2**20, f"peak {peak / 2**20:.0f} MB"


def test_segments_given_to_auto_grow_with_the_track(monkeypatch: pytest.MonkeyPatch) -> None:
    """What the tracemalloc test measures, counted: the rows of every segment given to auto."""
    seen: list[int] = []

    def spy(pairs, *args, **kwargs):  # type: ignore[no-untyped-def]
        seen.append(sum(len(a) + len(b) for a, b in pairs))
        return recover_auto(pairs, *args, **kwargs)

    monkeypatch.setattr(fill, "recover_auto", spy)
    rows = _one_track(3000)
    fill.fill_rows(rows, combine=False)
    assert len(seen) == 2  # centres, then sizes
    # was 3000 * 3001 rows each (the whole track around every hole)
    assert max(seen) <= 3000 * (2 * WINDOW_POINTS), seen


def test_windows_change_no_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    """``auto`` on the windows fills what it filled on whole segments, bit for bit."""
    rows = _tracks()
    got = [fill_gaps(rows, seed=s, **kw) for s, kw in ((0, {}), (1, {"combine": False}))]
    chosen = set()
    for _, rep in got:
        for cal in (rep.calibration, rep.size_calibration):
            assert cal is not None
            chosen |= {m for b in cal.buckets for m, _ in (b.weights or ((b.method, 1.0),))}
    assert chosen - {"linear"}  # more than straight lines: the other candidates ran

    monkeypatch.setattr(fill, "gap_windows", _whole)  # the segments as they were: whole
    want = [fill_gaps(rows, seed=s, **kw) for s, kw in ((0, {}), (1, {"combine": False}))]
    for (a, ra), (b, rb) in zip(got, want, strict=True):
        assert a.tobytes() == b.tobytes()
        assert ra.describe() == rb.describe()


@pytest.mark.parametrize("method", sorted(set(METHODS) - {"auto", *fill.WHOLE_SEGMENT_METHODS}))
def test_named_methods_on_the_windows_change_no_bit(
    method: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    rows = _tracks(1)
    got, rep = fill_gaps(rows, method)  # type: ignore[arg-type]
    assert rep.n_gaps > 40
    monkeypatch.setattr(fill, "gap_windows", _whole)
    assert got.tobytes() == fill_gaps(rows, method)[0].tobytes()  # type: ignore[arg-type]


def test_gap_windows_hold_the_runs_next_to_each_hole() -> None:
    one = np.r_[1:100, 102:105, 110:180, 200:201, 203:260, 262:263].astype(np.float64)
    two = np.r_[5:8, 9:50, 52:53].astype(np.float64)
    frames, ids = np.r_[one, two, 7.0], np.r_[np.full(len(one), 3.0), np.full(len(two), 8.0), 9]
    w = gap_windows(frames, ids)
    assert w.holes.tolist() == [98, 101, 171, 172, 229, 233, 274]
    for h, a, b, t0, t1 in zip(*(v.tolist() for v in w), strict=True):
        assert (t0, t1) == ((0, len(one)) if h < len(one) else (len(one), len(frames) - 1))
        run_a = 1  # the run of consecutive frames ending at the hole, and the one after it
        while h - run_a >= t0 and frames[h - run_a + 1] - frames[h - run_a] == 1:
            run_a += 1
        run_b = 1
        while h + run_b + 1 < t1 and frames[h + run_b + 1] - frames[h + run_b] == 1:
            run_b += 1
        assert h + 1 - a == max(min(WINDOW_POINTS, h + 1 - t0), run_a)
        assert b - (h + 1) == max(min(WINDOW_POINTS, t1 - h - 1), run_b)
    alone = gap_windows(one)  # one track: no ids needed
    ids = np.zeros(len(one))
    assert all(map(np.array_equal, alone, gap_windows(one, ids)))
    for frames in (np.arange(1.0, 5.0), np.zeros(0), np.ones(1)):
        assert all(len(v) == 0 for v in gap_windows(frames))


@pytest.mark.parametrize("method", ["auto", "gdt-bi"])
def test_far_centre_outside_the_window_still_refused(method: str) -> None:
    """A centre beyond 1e9 px far from the hole is refused, where the rows are checked (was:
    by the kernel, "segment_a row 0 has x = 1.44e+09", naming no row of the file)."""
    fr = np.r_[1:80, 85:200].astype(np.float64)
    k = len(fr)
    box = np.column_stack([10 + fr, np.full(k, 20.0), np.full((k, 2), (20.0, 40.0))])
    rows = np.column_stack([fr, np.ones(k), box, np.ones(k), -np.ones((k, 3))])
    rows[0, 2], rows[0, 4] = 9.9e8, 9e8  # its centre: 1.44e9 px, 78 rows before the hole
    match = r"row 0 \(frame 1, id 1\) has width 9e\+08: a box's right or bottom edge is beyond"
    with pytest.raises(ValueError, match=match):
        fill_gaps(rows, method)  # type: ignore[arg-type]


def test_recover_auto_refuses_contexts_of_another_length() -> None:
    a = np.column_stack([np.arange(1.0, 6), np.arange(5.0), np.zeros(5)])
    b = np.column_stack([np.arange(9.0, 14), np.arange(5.0), np.zeros(5)])
    with pytest.raises(ValueError, match="recover_auto: 2 contexts for 1 pairs"):
        recover_auto([(a, b)], contexts=[(5, 5), (5, 5)])


@pytest.mark.slow
def test_eight_thousand_holes_in_seconds_not_gigabytes() -> None:
    """The user trial's size: one track, 8000 holes (4.1 GB and 14 s before)."""
    rows = _one_track(8000)
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        out, rep = fill_gaps(rows)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert rep.n_gaps == 8000 and len(out) == len(rows) + 8000
    assert peak < 100 * 2**20, f"peak {peak / 2**20:.0f} MB"
    assert time.perf_counter() - t0 < 120.0


def test_holes_checked_in_one_batch_not_one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """A user trial: ``fill_gaps(rows, "linear")`` of 200 000 rows spent half its time checking
    each hole's segments one at a time (``as_observed`` twice a hole), segments ``fill_gaps``
    had checked already. Valid gaps are now checked in a few passes over all their rows
    (:func:`pftrack.recovery.segments.checked_at_once`), with the same bits."""
    rows = _one_track(300)
    before = {m: fill_gaps(rows, m)[0] for m in ("linear", "rts", "gdt-bi")}
    calls = []
    real = registry.as_observed
    monkeypatch.setattr(registry, "as_observed", lambda *a: calls.append(1) or real(*a))
    for m, want in before.items():
        np.testing.assert_array_equal(fill_gaps(rows, m)[0], want)
    assert not calls


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        (lambda a, b: (a, b[::-1].copy()), "segment_b of gap 2 frames must increase"),
        (lambda a, b: (a, np.vstack([a[-1:], b])), "gap 2: segment_b starts at frame"),
        (lambda a, b: (a, b + [0, 2e9, 0, 0, 0]), "segment_b of gap 2 row 0 has x = 2"),
        (lambda a, b: (a, b * [1, 1, 1, -1, 1]), "segment_b of gap 2 row 0 has w = -"),
        (lambda a, b: (a, b + [2e5, 0, 0, 0, 0]), "gap 2: the gap from frame"),
        (lambda a, b: (a, b + [0.5, 0, 0, 0, 0]), "segment_b of gap 2 row 0 has frame"),
        (lambda a, b: (a, b * [1, np.nan, 1, 1, 1]), "segment_b of gap 2 has a non-finite"),
    ],
)
def test_a_bad_gap_in_a_batch_is_still_named(bad, message: str) -> None:
    """The batch check only says yes or no: a gap it refuses is named as before."""
    rng = np.random.default_rng(4)
    gaps = []
    for k in range(5):
        a = np.column_stack([np.arange(1.0, 6), rng.normal(100, 5, (5, 2)), np.full((5, 2), 9.0)])
        b = a + [10 + k, 3, 3, 0, 0]
        gaps.append(bad(a, b) if k == 2 else (a, b))
    with pytest.raises(ValueError, match=re.escape(message)):
        recover_gaps(gaps, "linear")


def test_frame_x_y_copies_of_the_batch_check() -> None:
    """``recover_auto``'s one-pass check was its own function (``calibrate._checked_at_once``,
    without the gap length rule); ``segments.checked_at_once`` serves both now, its `xy`
    giving the contiguous ``frame, x, y`` copies ``recover_auto`` reads, of any layout."""
    from pftrack.recovery.segments import checked_at_once

    rng = np.random.default_rng(5)
    gaps = []
    for k in range(600):  # more than segments.CHECK_BLOCK pairs
        a = np.column_stack([np.arange(1.0, 6), rng.normal(100, 5, (5, 2)), np.full((5, 2), 9.0)])
        gaps.append((a, a + [10 + k % 7, 3, 3, 0, 0]))
    same = checked_at_once(gaps)
    got = checked_at_once(gaps, xy=True)
    assert same is not None and got is not None and len(got) == len(gaps)
    for (a, b), (sa, sb), (xa, xb) in zip(gaps, same, got, strict=True):
        assert sa is a and sb is b
        for x, s in ((xa, a), (xb, b)):
            assert x.flags.c_contiguous and x.dtype == np.float64
            assert x.tobytes() == np.ascontiguousarray(s[:, :3]).tobytes()
    a, b = gaps[0]
    cols = [(s[:, [0, 3, 4]], t[:, [0, 3, 4]]) for s, t in gaps]  # fill_rows' size columns
    assert not cols[0][0].flags.c_contiguous and checked_at_once(cols) is None
    wide = checked_at_once(cols, xy=True)  # not C-contiguous: taken with xy, copied
    assert wide is not None and wide[0][0].tobytes() == np.ascontiguousarray(cols[0][0]).tobytes()
    negative_w = (a, b * [1, 1, 1, -1, 1])  # w, h are not read with xy: not checked
    assert checked_at_once([*gaps[:300], negative_w]) is None
    assert checked_at_once([*gaps[:300], negative_w], xy=True) is not None
    long_gap = (a, b + [2e5, 0, 0, 0, 0])
    assert checked_at_once([*gaps[:300], long_gap], xy=True) is None


def test_recover_auto_refuses_a_gap_recover_gaps_refuses() -> None:
    """A gap of more than MAX_GAP_LIMIT frames: ``recover_gaps`` refused it, ``recover_auto``
    filled its 200 002 frames (its own one-pass check did not look at the length)."""
    a = np.array([[1.0, 10, 10], [2, 11, 10], [3, 12, 10]])
    for fn in (recover_auto, lambda g: recover_gaps(g, "linear")):
        with pytest.raises(ValueError, match=r"recover_gaps: gap 1: the gap from frame 3 to "):
            fn([(a, a + [9, 0, 0]), (a, a + [200_005, 0, 0])])
