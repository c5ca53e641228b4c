"""``auto`` recovers the gaps a block at a time (:data:`~pftrack.recovery.calibrate.RECOVER_BLOCK`).

``recover_auto`` checked every gap's segments into one copy, recovered every gap with each
chosen method in one call and kept every gap's ``"-nb"`` neighbour windows: ``fill_gaps(rows,
"auto")`` peaked at 233 MB of ``tracemalloc`` on 200 170 rows with 39 830 holes (1.2 KB a row,
``linear`` 0.3 KB), and the size columns of every hole's segments were copied at once in
``fill_rows`` (84 MB there). Now the calibration reads every gap's length, distance and context
first, then the gaps are checked and recovered a block at a time, with the same bits.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from pftrack.recovery import calibrate, fill, fill_gaps, recover_gaps, registry
from pftrack.recovery.calibrate import gap_windows, recover_auto
from pftrack.recovery.names import NEIGHBOUR_METHODS
from tests.recovery.test_row_memory import _peak


def _walkers(n_ids: int, n_frames: int, seed: int = 0) -> np.ndarray:
    """`n_ids` walkers sharing a camera's wobble (so the ``-nb`` and ``gdt`` methods win),
    a fifth of their rows lost at random: MOTChallenge rows."""
    rng = np.random.default_rng(seed)
    f = np.tile(np.arange(1.0, n_frames + 1), n_ids)
    i = np.repeat(np.arange(1.0, n_ids + 1), n_frames)
    cam = 15 * np.sin(np.arange(n_frames) / 4.0)
    x = (np.cumsum(rng.normal(0, 0.5, (n_ids, n_frames)), 1) + cam).ravel() + 500
    y = (np.cumsum(rng.normal(0, 0.5, (n_ids, n_frames)), 1) + cam).ravel() + 300
    wh = np.column_stack([30 + rng.normal(0, 1, len(f)), 80 + rng.normal(0, 2, len(f))])
    rows = np.column_stack([f, i, x, y, wh, np.ones(len(f)), -np.ones((len(f), 3))])
    return rows[rng.random(len(rows)) > 0.2]


@pytest.mark.parametrize("kw", [{}, {"combine": False}, {"seed": 3}])
def test_blocks_change_no_bit(monkeypatch: pytest.MonkeyPatch, kw: dict[str, object]) -> None:
    rows = np.vstack([_walkers(6, 120), _walkers(4, 90, seed=1) + [0, 6, *[0] * 8]])
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 10**9)  # every gap in one block
    want, rep = fill_gaps(rows, **kw)  # type: ignore[arg-type]
    assert rep.calibration is not None
    used = {m for b in rep.calibration.buckets for m, _ in (b.weights or ((b.method, 1.0),))}
    assert used - {"linear"} and rep.n_gaps > 100, (used, rep.n_gaps)
    for block in (1, 3, 64):
        monkeypatch.setattr(calibrate, "RECOVER_BLOCK", block)
        got, got_rep = fill_gaps(rows, **kw)  # type: ignore[arg-type]
        assert got.tobytes() == want.tobytes(), block
        assert got_rep.describe() == rep.describe()


def test_blocks_of_gaps_calibrated_on_themselves(monkeypatch: pytest.MonkeyPatch) -> None:
    """Without `observed` the checked segments are the calibration's runs: kept, not rechecked."""
    rows = _walkers(5, 100)
    seg = np.column_stack([rows[:, 0], rows[:, 2:4]])
    w = gap_windows(seg[:, 0], rows[:, 1])
    pairs = [(seg[a : e + 1], seg[e + 1 : b]) for e, a, b in zip(w.holes, w.lo, w.hi, strict=True)]
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 10**9)
    want = recover_gaps(pairs)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 2)
    got = recover_gaps(pairs)
    assert len(got) == len(want) == len(pairs)
    assert all(a.tobytes() == b.tobytes() for a, b in zip(got, want, strict=True))


def test_a_bad_gap_of_a_later_block_is_named_by_its_place(monkeypatch: pytest.MonkeyPatch) -> None:
    a = np.array([[1.0, 10, 10], [2, 11, 10]])
    pairs = [(a, a + [5, 0, 0])] * 7
    pairs[5] = (a, a)  # segment B does not start after A
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 2)
    with pytest.raises(ValueError, match="recover_gaps: gap 5: segment_b starts at frame 1"):
        recover_auto(pairs)
    pairs[5] = (a, [[9.0, np.nan, 1]])  # named pair by pair in its block
    with pytest.raises(ValueError, match="non-finite"):
        recover_auto(pairs)


def test_peak_is_a_blocks_not_every_gaps(monkeypatch: pytest.MonkeyPatch) -> None:
    """6406 gaps of 100 walkers (``gdt-mix`` chosen): main's code (every gap's copies, windows
    and temporaries at once) peaked at 30.1 MiB here, blocks of 256 gaps at 7.8."""
    rows = _walkers(100, 400)
    seg = np.column_stack([rows[:, 0], rows[:, 2:4]])
    w = gap_windows(seg[:, 0], rows[:, 1])
    pairs = [(seg[a : e + 1], seg[e + 1 : b]) for e, a, b in zip(w.holes, w.lo, w.hi, strict=True)]
    contexts = list(
        zip((w.holes + 1 - w.first).tolist(), (w.end - w.holes - 1).tolist(), strict=True)
    )
    starts = np.flatnonzero(np.r_[True, rows[1:, 1] != rows[:-1, 1]])
    whole = np.split(seg, starts[1:])
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 256)
    tracemalloc.start()
    try:
        paths, cal = recover_auto(
            pairs, whole, contexts=contexts, max_gaps=20, bags=0, combine=False
        )
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(paths) == len(pairs) > 6000 and cal.pooled != "linear"
    assert peak < 9 * 2**20, f"peak {peak / 2**20:.1f} MiB (31.4 in one block)"


@pytest.mark.parametrize("method", fill.BLOCK_METHODS)
def test_named_methods_blocks_change_no_bit(monkeypatch: pytest.MonkeyPatch, method: str) -> None:
    """The batched named methods fill a block of holes at a time too, with the same bits."""
    rows = _walkers(6, 120)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 10**9)
    want, rep = fill_gaps(rows, method)  # type: ignore[arg-type]
    assert rep.n_gaps > 100
    calls: list[int] = []

    def spy(gaps, *args, **kwargs):  # type: ignore[no-untyped-def]
        calls.append(len(gaps))
        return recover_gaps(gaps, *args, **kwargs)

    monkeypatch.setattr(fill, "recover_gaps", spy)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 7)
    got, _ = fill_gaps(rows, method)  # type: ignore[arg-type]
    assert got.tobytes() == want.tobytes()
    assert max(calls) == 7 and sum(calls) == rep.n_gaps


def _pairs_and_tracks(rows: np.ndarray) -> tuple[list[tuple[np.ndarray, np.ndarray]], list]:
    """Each hole's windows (``frame, x, y`` views) and every track, as ``fill_rows`` gives them."""
    seg = np.column_stack([rows[:, 0], rows[:, 2:4]])
    w = gap_windows(seg[:, 0], rows[:, 1])
    pairs = [(seg[a : e + 1], seg[e + 1 : b]) for e, a, b in zip(w.holes, w.lo, w.hi, strict=True)]
    starts = np.flatnonzero(np.r_[True, rows[1:, 1] != rows[:-1, 1]])
    return pairs, np.split(seg, starts[1:])


@pytest.mark.parametrize("as_lists", [False, True])
@pytest.mark.parametrize("given", [True, False])
def test_each_block_is_checked_once(
    monkeypatch: pytest.MonkeyPatch, given: bool, as_lists: bool
) -> None:
    """With `observed`, ``recover_auto`` checked each block twice: as the calibration read the
    gaps' lengths, and again before recovering it (the copies are dropped in between). Now
    once: in a few passes (``segments.checked_at_once``) for float64 arrays, one segment at a
    time (``as_segment``) for lists; the second pass only converts, with the same bits."""
    pairs, whole = _pairs_and_tracks(_walkers(5, 100))
    given_pairs: list = [(a.tolist(), b.tolist()) for a, b in pairs] if as_lists else pairs
    observed = whole if given else None
    want, cal = recover_auto(pairs, observed)
    fast: list[int] = []
    one: list[int] = []
    real_fast, real_one = calibrate.checked_at_once, calibrate.as_segment
    monkeypatch.setattr(
        calibrate, "checked_at_once", lambda g, **k: fast.append(1) or real_fast(g, **k)
    )
    monkeypatch.setattr(calibrate, "as_segment", lambda *a: one.append(1) or real_one(*a))
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 7)
    got, got_cal = recover_auto(given_pairs, observed)
    blocks = -(-len(pairs) // 7)
    assert len(pairs) > 50 and len(fast) == blocks  # main: 2 * blocks with `observed`
    assert len(one) == (2 * len(pairs) if as_lists else 0)  # main: 4 * len(pairs) with it
    assert got_cal == cal
    assert all(a.tobytes() == b.tobytes() for a, b in zip(got, want, strict=True))


@pytest.mark.parametrize("method", NEIGHBOUR_METHODS)
def test_nb_methods_blocks_change_no_bit(monkeypatch: pytest.MonkeyPatch, method: str) -> None:
    """The ``-nb`` methods took every hole of a file in one call; now a block at a time, one
    neighbourhood for the file (its windows forgotten after each block), the same bits, in
    ``fill_gaps`` and in ``recover_gaps``."""
    rows = _walkers(6, 120)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 10**9)
    want, rep = fill_gaps(rows, method)  # type: ignore[arg-type]
    base = method.removesuffix("-nb")
    assert rep.n_gaps > 100
    assert want.tobytes() != fill_gaps(rows, base)[0].tobytes()  # neighbours corrected paths
    pairs, whole = _pairs_and_tracks(rows)
    want_gaps = recover_gaps(pairs, method, observed=whole)
    calls: list[int] = []
    real = registry.correct_by_neighbours

    def spy(recover, pairs, hood, *args):  # type: ignore[no-untyped-def]
        calls.append(len(pairs))
        return real(recover, pairs, hood, *args)

    monkeypatch.setattr(registry, "correct_by_neighbours", spy)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 7)
    got, _ = fill_gaps(rows, method)  # type: ignore[arg-type]
    assert got.tobytes() == want.tobytes()
    assert max(calls) == 7 and sum(calls) == rep.n_gaps
    calls.clear()
    got_gaps = recover_gaps(pairs, method, observed=whole)
    assert max(calls) == 7 and sum(calls) == len(pairs)
    assert all(a.tobytes() == b.tobytes() for a, b in zip(got_gaps, want_gaps, strict=True))


@pytest.mark.parametrize("method", NEIGHBOUR_METHODS)
def test_nb_peak_is_a_blocks_not_every_gaps(monkeypatch: pytest.MonkeyPatch, method: str) -> None:
    """2885 holes of 60 walkers, blocks of 128: main's code (every hole's neighbour windows,
    their paths and errors at once) peaked at 25.0 MiB (``linear-nb``) and 34.5 (``rts-nb``)
    of ``tracemalloc`` here, 5.0 and 4.1 now (``linear``: 7.1 on 100 walkers)."""
    rows = _walkers(60, 300)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 128)
    got: list = []
    peak = _peak(lambda: got.append(fill_gaps(rows, method)))  # type: ignore[arg-type]
    out, rep = got[0]
    assert rep.n_gaps > 2500 and len(out) > len(rows)
    assert peak < 10 * 2**20, f"peak {peak / 2**20:.1f} MiB (main: 25.0 and 34.5)"


def test_nb_methods_draw_one_bar_over_the_blocks(monkeypatch: pytest.MonkeyPatch) -> None:
    """A long ``-nb`` run shows one bar over its blocks, with the time left, as before the
    blocks it showed one over its gaps (each block's own bar would be short, or none)."""
    import io
    import sys

    from pftrack import _progress

    pairs, whole = _pairs_and_tracks(_walkers(4, 60))
    err = io.StringIO()
    err.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr(sys, "stderr", err)
    monkeypatch.setattr(_progress, "_quiet", False)
    monkeypatch.setattr(_progress, "DELAY", 0.0)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 7)
    recover_gaps(pairs, "linear-nb", observed=whole)
    blocks = -(-len(pairs) // 7)
    assert len(pairs) > 20
    assert "linear-nb" in err.getvalue() and f"{blocks}/{blocks}" in err.getvalue()


@pytest.mark.parametrize("width", [3, 5, 10])
@pytest.mark.parametrize("given", [True, False])
def test_recover_gaps_auto_checks_each_pair_once(
    monkeypatch: pytest.MonkeyPatch, given: bool, width: int
) -> None:
    """``recover_gaps(..., "auto")`` checked its pairs (``registry._checked_pairs``), then
    ``recover_auto`` checked every block of them again (``calibrate.checked_at_once``, or
    ``as_segment`` pair by pair). Now once: ``recover_auto`` is told they are checked and
    only takes their ``frame, x, y``; the same bits, with 3, 5 or 10 columns."""
    pairs, whole = _pairs_and_tracks(_walkers(5, 100))
    given_pairs = [  # sizes (w, h) = 1 with 5 columns; MOTChallenge-like rows with 10
        tuple(np.column_stack([s, np.ones((len(s), width - 3))]) for s in p) for p in pairs
    ]
    observed = whole if given else None
    want, _ = recover_auto(pairs, observed)
    counts = {"fast": 0, "one": 0}
    real_fast, real_one = calibrate.checked_at_once, calibrate.as_segment

    def fast(g, **k):  # type: ignore[no-untyped-def]
        counts["fast"] += 1
        return real_fast(g, **k)

    def one(*a):  # type: ignore[no-untyped-def]
        counts["one"] += 1
        return real_one(*a)

    monkeypatch.setattr(calibrate, "checked_at_once", fast)
    monkeypatch.setattr(calibrate, "as_segment", one)
    monkeypatch.setattr(calibrate, "RECOVER_BLOCK", 7)
    got = recover_gaps(given_pairs, "auto", observed=observed)
    assert len(pairs) > 50 and counts == {"fast": 0, "one": 0}  # main: a check of every block
    assert all(a.tobytes() == b.tobytes() for a, b in zip(got, want, strict=True))
    with pytest.raises(ValueError, match="recover_gaps: gap 1: segment_b starts at frame"):
        recover_gaps([given_pairs[0], given_pairs[0][::-1]], "auto")  # still checked, once
