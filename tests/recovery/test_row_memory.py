"""Memory per row of ``pftrack recover``'s two peaks, ``fill_gaps`` and ``write_mot``, and of
``pftrack smooth``'s, filling the holes of its sorted rows (``_add_hole_rows``).

Both were measured with ``tracemalloc`` on 17 200 rows (200 ids, 100 frames, every seventh
frame lost): ``fill_gaps(rows, "linear")`` 430 bytes a row before the tracks were kept as one
sorted copy (a dict of tracks and their concatenation were two), 348 after; ``write_mot`` of
rows already in (frame, id) order 304 bytes a row before, 216 after (no sorted copy of sorted
rows, no third copy of the printed values).
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np

from pftrack.io.mot import mot_text, read_mot, write_mot
from pftrack.recovery import fill_gaps
from pftrack.recovery.linking import sorted_tracks
from pftrack.tracking import offline


def _rows() -> np.ndarray:
    rng = np.random.default_rng(0)
    f = np.repeat(np.arange(1, 101), 200).astype(float)
    i = np.tile(np.arange(1, 201), 100).astype(float)
    xy = rng.uniform(0, 500, (len(f), 2)).round(2)
    rows = np.column_stack([f, i, xy, np.full((len(f), 2), 20.0), np.ones(len(f)),
                            -np.ones((len(f), 3))])  # fmt: skip
    return rows[f % 7 != 3]


def _peak(fn, *args) -> int:  # type: ignore[no-untyped-def]
    tracemalloc.start()
    try:
        fn(*args)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_fill_gaps_keeps_one_sorted_copy_of_the_rows() -> None:
    rows = _rows()
    peak = _peak(fill_gaps, rows, "linear")
    assert peak / len(rows) < 390, f"{peak / len(rows):.0f} bytes a row (430 before)"


def test_write_mot_does_not_copy_rows_in_order(tmp_path: Path) -> None:
    rows = _rows()
    peak = _peak(write_mot, tmp_path / "out.txt", rows)
    assert peak / len(rows) < 260, f"{peak / len(rows):.0f} bytes a row (304 before)"
    shuffled = rows[np.random.default_rng(1).permutation(len(rows))]
    write_mot(tmp_path / "shuffled.txt", shuffled)  # still sorted when it was not
    assert (tmp_path / "shuffled.txt").read_bytes() == (tmp_path / "out.txt").read_bytes()
    np.testing.assert_array_equal(read_mot(tmp_path / "out.txt"), rows)


def test_smooth_fills_its_sorted_rows_without_copying_them() -> None:
    """``pftrack smooth``'s peak is in filling the holes: ``_add_hole_rows`` copied the rows to
    put the measured boxes in (the same bits, when there are no other measurements) and
    ``fill_rows`` copied them again to sort rows already sorted by id, then frame: 426 bytes a
    row here before, about 300 now (``smooth`` of the 500-track file scaled to 5000 tracks, 630 374
    rows: 537 -> 471 MB of maximum resident set, docs/recovery.md)."""
    rows = _rows()
    a = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    obs, z = np.ones(len(a), dtype=bool), a[:, 2:6].copy()
    peak = _peak(offline._add_hole_rows, a, obs, z, 30, "linear", 0)
    assert peak / len(a) < 365, f"{peak / len(a):.0f} bytes a row (426 before)"
    want = offline._add_hole_rows(a, obs, z, 30, "linear", 0)
    other = z + 0.5  # other measurements: those are what the holes are filled from
    got = offline._add_hole_rows(a, obs, other, 30, "linear", 0)
    moved = a.copy()
    moved[:, 2:6] = other
    same = offline._add_hole_rows(moved, obs, other, 30, "linear", 0)
    assert got[0][got[3], 2:6].tobytes() != want[0][want[3], 2:6].tobytes()
    assert got[0][got[3]].tobytes() == same[0][same[3]].tobytes()


def test_sorted_tracks_shares_only_rows_already_in_order() -> None:
    rows = _rows()
    a = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    r, ends = sorted_tracks(a, share=True)
    assert r is a
    copied, copied_ends = sorted_tracks(a)
    assert copied is not a and copied.tobytes() == a.tobytes()
    assert ends.tolist() == copied_ends.tolist()
    for unsorted in (rows, a[::-1]):  # by frame; by id and frame, descending
        r, ends = sorted_tracks(unsorted, share=True)
        assert r is not unsorted
        assert r.tobytes() == copied.tobytes() and ends.tolist() == copied_ends.tolist()


def test_printing_never_changes_the_rows() -> None:
    """The printed values are changed in place (-0.0 -> 0.0, rounding): on a copy, also for
    one row, whose columns 3-10 are contiguous (a view where several rows are not)."""
    for rows in (np.array([[1, 1, -0.0, 1.23456789012, 3, 4, 1, -1, -1, -1]]),
                 np.array([[1, 1, -0.0, 1.23456789012, 3, 4, 1, -1, -1, -1]] * 3)):  # fmt: skip
        before = rows.copy()
        assert mot_text(rows).splitlines()[0] == "1,1,0,1.23,3,4,1,-1,-1,-1"
        np.testing.assert_array_equal(rows, before)
        assert np.signbit(rows[:, 2]).all()
