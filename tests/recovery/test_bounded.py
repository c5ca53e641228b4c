"""Bounded work and memory of hole filling, refused absurd input, batched kernels = references."""

from __future__ import annotations

import time
import tracemalloc
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np
import pytest

from pftrack.recovery import fill_gaps
from pftrack.recovery.baselines import rts, rts_batch
from pftrack.recovery.fill import DEFAULT_MAX_GAP, MAX_GAP_LIMIT
from pftrack.tracking import BoxSmoother, smooth_tracks


def _rows(frames: list[int], ids: list[int]) -> np.ndarray:
    n = len(frames)
    x = np.arange(n, dtype=np.float64)
    return np.column_stack([frames, ids, 10 + x, 20 + 0.5 * x, np.full((n, 2), (20.0, 40.0)),
                            np.ones(n), -np.ones((n, 3))])  # fmt: skip


T = TypeVar("T")
FAR = _rows([1, 2, 3, 10_000_000, 10_000_001, 5, 9], [1, 1, 1, 1, 1, 2, 2])


def _bounded(fn: Callable[[], T], seconds: float = 10.0, megabytes: float = 50.0) -> T:
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        out = fn()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - t0 < seconds
    assert peak < megabytes * 2**20, f"peak {peak / 2**20:.0f} MB"
    return out


@pytest.mark.parametrize("method", ["auto", "linear", "gdt-bi", "rts"])
def test_fill_gaps_leaves_a_ten_million_frame_hole(method: str) -> None:
    out, rep = _bounded(lambda: fill_gaps(FAR, method))
    assert rep.n_gaps == 1 and rep.n_filled_rows == 3  # only id 2's 3-frame hole
    assert len(out) == len(FAR) + 3


def test_smooth_tracks_is_bounded_by_rows_not_frames() -> None:
    out = _bounded(lambda: smooth_tracks(FAR))
    assert len(out) == len(FAR) + 3  # id 2's hole filled, id 1's 10M-frame hole left alone
    assert np.all(np.isfinite(out))
    sm = _bounded(lambda: BoxSmoother().smooth(FAR[:5, 0], FAR[:5, 2:6], np.ones(5, bool)))
    assert np.all(np.isfinite(sm))


def test_smoother_pieces_equal_separate_runs() -> None:
    """Split at a hole longer than max_hole: each piece is smoothed on its own."""
    sm = BoxSmoother(max_hole=50)
    rows = _rows([*range(1, 21), *range(200, 230)], [1] * 50)
    obs = np.ones(50, bool)
    both = sm.smooth(rows[:, 0], rows[:, 2:6], obs)
    np.testing.assert_array_equal(both[:20], sm.smooth(rows[:20, 0], rows[:20, 2:6], obs[:20]))
    np.testing.assert_array_equal(both[20:], sm.smooth(rows[20:, 0], rows[20:, 2:6], obs[20:]))


def test_default_max_gap_everywhere() -> None:
    import inspect

    from pftrack.recovery.fill import fill_rows

    assert DEFAULT_MAX_GAP == 30
    for fn in (fill_gaps, fill_rows):
        assert inspect.signature(fn).parameters["max_gap"].default == DEFAULT_MAX_GAP


@pytest.mark.parametrize(
    ("bad", "match"),
    [
        (1e12, "row 0 has frame 1000000000000, not an integer"),  # was 1e+12
        (2.0**31, "row 0 has frame 2147483648, not an integer"),  # was 2.14748e+09
        (1 + 1e-12, r"row 0 has frame 1\.000000000001, not an integer"),  # was "frame 1, not"
        (2.5, "row 0 has frame 2.5, not an integer"),
        (0, "row 0 has frame 0, not an integer .*add 1 to every frame"),
        (np.nan, "non-finite"),
    ],
)
def test_absurd_frames_refused(bad: float, match: str) -> None:
    rows = FAR.copy()
    rows[0, 0] = bad
    with pytest.raises(ValueError, match=match):
        fill_gaps(rows)
    with pytest.raises(ValueError, match=match):
        smooth_tracks(rows)


def test_bad_shapes_ids_and_max_gap_refused() -> None:
    for shape in [(6, 2), (6, 11), (10,)]:
        with pytest.raises(ValueError, match=r"shape \(M, 6\.\.10\)"):
            smooth_tracks(np.ones(shape))
        with pytest.raises(ValueError, match=r"shape \(M, 6\.\.10\)"):
            fill_gaps(np.ones(shape))
    rows = FAR.copy()
    rows[0, 1] = 2.5
    with pytest.raises(ValueError, match="track id 2.5"):
        fill_gaps(rows)
    rows[0, 1] = 1e19
    with pytest.raises(ValueError, match="track id 1e\\+19"):
        smooth_tracks(rows)
    for g in (0, MAX_GAP_LIMIT + 1):
        with pytest.raises(ValueError, match="max_gap"):
            fill_gaps(FAR, max_gap=g)
    for bad in (True, 2.0, "5"):  # not an int: TypeError, as every integer argument
        with pytest.raises(TypeError, match="fill_gaps: max_gap must be an integer"):
            fill_gaps(FAR, max_gap=bad)  # type: ignore[arg-type]
        with pytest.raises(TypeError, match="smooth_tracks: max_gap must be an integer"):
            smooth_tracks(FAR, max_gap=bad)  # type: ignore[arg-type]
        with pytest.raises(TypeError, match="BoxSmoother: max_hole must be an integer"):
            BoxSmoother(max_hole=bad)  # type: ignore[arg-type]
    for bad in ("x", True, None):
        with pytest.raises(TypeError, match="BoxSmoother: noise must be a number"):
            BoxSmoother(noise=bad)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="real"):
        fill_gaps(np.full((2, 10), 1 + 1j))
    with pytest.raises(ValueError, match="size_noise"):
        BoxSmoother(size_noise=1e308)
    with pytest.raises(ValueError, match="max_hole"):
        BoxSmoother(max_hole=0)


def test_rts_batch_equals_rts_per_gap() -> None:
    rng = np.random.default_rng(0)
    pairs = []
    for _ in range(60):
        na, nb, L = (int(v) for v in rng.integers(1, 45, 3))
        f0 = int(rng.integers(1, 100))
        fa, fb = np.arange(f0, f0 + na), np.arange(f0 + na + L, f0 + na + L + nb)
        a = np.column_stack([fa, np.cumsum(rng.normal(0, 2, (na, 2)), axis=0)])
        b = np.column_stack([fb, np.cumsum(rng.normal(0, 2, (nb, 2)), axis=0) + 5])
        if na > 5:
            a = np.delete(a, 2, axis=0)  # a hole inside the segment
        pairs.append((a, b))
    got = rts_batch(pairs)
    for (a, b), g in zip(pairs, got, strict=True):
        fr = np.arange(a[-1, 0] + 1, b[0, 0]).astype(np.int64)
        np.testing.assert_allclose(g, rts(a, b, fr), rtol=1e-12, atol=1e-9)
    assert rts_batch([]) == []


def test_numpy_expm_matches_scipy() -> None:
    from scipy.linalg import expm

    from pftrack.recovery.mixture import _expm

    rng = np.random.default_rng(1)
    for scale in (1e-3, 1.0, 30.0):
        M = rng.normal(0, scale, (20, 6, 6))
        want = expm(M)
        np.testing.assert_allclose(_expm(M), want, rtol=1e-9, atol=1e-12 * np.abs(want).max())


def test_cli_smooth_and_recover_bounded_and_refusing(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    from pftrack.cli import main
    from pftrack.io.mot import read_mot, write_mot

    src = tmp_path / "far.txt"
    write_mot(src, FAR)
    t0 = time.perf_counter()
    assert main(["smooth", str(src), "--out", str(tmp_path / "s.txt")]) == 0
    assert main(["recover", str(src), "--out", str(tmp_path / "r.txt")]) == 0
    assert time.perf_counter() - t0 < 20.0
    assert len(read_mot(tmp_path / "s.txt")) == len(FAR) + 3
    assert len(read_mot(tmp_path / "r.txt")) == len(FAR) + 3
    bad = tmp_path / "bad.txt"
    bad.write_text("1,1,10,10,20,40\n3000000000,1,12,10,20,40\n")
    for cmd in ("smooth", "recover"):
        assert main([cmd, str(bad), "--out", str(tmp_path / "o.txt")]) == 2
        err = capsys.readouterr().err
        assert (
            f"pftrack {cmd}: error: {bad}:2: frame is 3000000000, expected an integer in "
            "1..2147483647" in err
        )  # the reader names the line
    assert not (tmp_path / "o.txt").exists()
    with pytest.raises(SystemExit) as exc:  # refused by the option's own bound, named
        main(["recover", str(src), "--out", str(tmp_path / "o.txt"), "--max-gap", "200000"])
    assert exc.value.code == 2
    assert "argument --max-gap: expected an integer in [1, 100000], got 200000" in (
        capsys.readouterr().err
    )


def test_sweep_refuses_huge_grids_and_non_finite_sizes() -> None:
    from pftrack.recovery.experiment import MAX_SWEEP_POSITIONS, sweep

    trajs = {1: np.column_stack([np.arange(1.0, 11), np.arange(10.0), np.arange(10.0)])}
    assert len(sweep(trajs, 5.0, 20.0, 20.0, 1.0, min_gaps=0)) == 16 * 16
    with pytest.raises(ValueError, match=f"more than the limit of {MAX_SWEEP_POSITIONS}"):
        sweep(trajs, 1.0, 1e5, 1e5, 0.1)
    with pytest.raises(ValueError, match="must be finite"):
        sweep(trajs, 1.0, np.nan, 20.0, 1.0)
    with pytest.raises(ValueError, match="must be finite and > 0"):
        sweep(trajs, np.inf, 20.0, 20.0, 1.0)


@pytest.mark.parametrize("method", ["linear", "cubic", "bspline", "gsi", "rts", "gdt", "gdt-bi"])
def test_recover_gap_refuses_far_coordinates(method: str) -> None:
    # the fuzz suite's find: x = 1e308 overflowed inside SciPy's CubicSpline (RuntimeWarning)
    from pftrack.recovery import recover_gap

    a = np.array([[1.0, 0, 0], [2, 0, 0]])
    b = np.array([[20.0, 1e308, 0], [21, 0, 0]])
    with pytest.raises(ValueError, match=r"segment_b row 0 has x = 1e\+308, beyond ±1e\+09 px"):
        recover_gap(a, b, None, method)
    a5 = np.array([[1.0, 0, 0, 10, 2e9]])
    with pytest.raises(ValueError, match=r"segment_a row 0 has h = 2e\+09"):
        recover_gap(a5, np.array([[5.0, 0, 0, 10, 20]]), None, method)
    got = recover_gap(a, np.array([[20.0, 1e9, 0], [21, 0, 0]]), None, method)
    assert np.all(np.isfinite(got))  # the bound itself is accepted


SEG_A = [[1.0, 10, 20, 5, 4], [2, 12, 21, 5, 4]]
SEG_B = [[7.0, 24, 27, 5, 4], [9, 26, 28, 5, 4]]


def _seg(seg: list[list[float]], row: int, col: int, value: float) -> np.ndarray:
    s = np.array(seg)
    s[row, col] = value
    return s


@pytest.mark.parametrize("method", ["linear", "rts", "gdt", "gdt-bi", "gdt-mix", "auto"])
@pytest.mark.parametrize(
    ("a", "b", "match"),
    [
        # were taken: frames must be whole, as recover_gap's own `frames` and fill_gaps' rows
        (_seg(SEG_A, 0, 0, 1.5), SEG_B, r"segment_a row 0 has frame 1.5, expected an integer"),
        (SEG_A, _seg(SEG_B, 0, 0, 7.5), r"segment_b row 0 has frame 7.5, expected an integer"),
        (SEG_A, _seg(SEG_B, 1, 0, 3e9), r"segment_b row 1 has frame 3000000000, expected"),
        # was taken: a negative size, which read_mot and fill_gaps refuse
        (_seg(SEG_A, 1, 3, -5), SEG_B, r"segment_a row 1 has w = -5: negative box width"),
        (SEG_A, _seg(SEG_B, 0, 4, -1e-9), r"segment_b row 0 has h = -1e-09: negative box width"),
    ],
)
def test_segments_need_whole_frames_and_sizes_not_negative(
    method: str, a: Any, b: Any, match: str
) -> None:
    from pftrack.recovery import recover_gap, recover_gaps

    with pytest.raises(ValueError, match="recover_gap: " + match):
        recover_gap(a, b, method=method)
    with pytest.raises(ValueError, match="recover_gaps: " + match.replace(" row", " of gap 0 row")):
        recover_gaps([(a, b)], method)


@pytest.mark.parametrize("method", ["linear", "rts", "linear-nb", "gdt", "gdt-mix", "auto"])
def test_a_gap_longer_than_the_fill_limit_is_refused(method: str) -> None:
    # was: np.arange over the gap's 2e9 frames (16 GB; the process was killed), or bad_alloc
    from pftrack.recovery import recover_gap, recover_gaps

    a = np.array([[1.0, 0, 0], [2, 1, 0]])
    b = np.array([[2e9, 5, 0], [2e9 + 1, 6, 0]])
    match = f"the gap from frame 2 to 2000000000 misses 1999999997 frames, more than {100_000}"
    with pytest.raises(ValueError, match="recover_gap: " + match):
        _bounded(lambda: recover_gap(a, b, method=method), seconds=5.0)
    with pytest.raises(ValueError, match="recover_gaps: gap 0: " + match):
        _bounded(lambda: recover_gaps([(a, b)], method), seconds=5.0)
    ok = np.array([[MAX_GAP_LIMIT + 3.0, 9, 0], [MAX_GAP_LIMIT + 4.0, 9, 0]])
    assert recover_gap(a, ok, frames=[3], method=method).shape == (1, 2)  # the limit itself


def test_recover_gap_frames_must_be_real_integers() -> None:
    from pftrack.recovery import recover_gap

    a, b = np.array([[1.0, 0, 0]]), np.array([[9.0, 8, 0]])
    with pytest.raises(TypeError, match="recover_gap: frames must hold real numbers"):
        recover_gap(a, b, frames=np.array([3 + 1j]), method="linear")  # was a ComplexWarning
    with pytest.raises(ValueError, match="recover_gap: frames must lie strictly between 1 and 9"):
        recover_gap(a, b, frames=[1e300], method="linear")  # was a cast of 1e300 to int64
    for frames in ([5, 5], [6, 4]):  # were rows given twice, or out of order
        with pytest.raises(ValueError, match="recover_gap: frames must increase strictly"):
            recover_gap(a, b, frames=frames, method="linear")
    with pytest.raises(TypeError, match="recover_gap: frames must hold real numbers"):
        recover_gap(a, b, frames=[True, False], method="linear")  # were frames 1 and 0
    far = np.array([[2.0**31, 0, 0]])
    with pytest.raises(ValueError, match="row 0 has frame 2147483648, expected an integer"):
        recover_gap(far, far + [9, 0, 0], method="linear")  # was printed as 2.14748e+09


def test_gsi_fills_a_long_gap_in_blocks_with_the_numbers_of_one_solve() -> None:
    """`--method gsi` solved one GP over every frame of a gap: 12.6 GB for 20 000 frames, out
    of memory for 100 000. Beyond GSI_BLOCK frames it goes block by block, each from the points
    within 3 length scales of it, which gives the one solve's numbers."""
    from pftrack.recovery import baselines as B

    rng = np.random.default_rng(0)
    fa, fb = np.arange(1.0, 41), np.arange(3041.0, 3081)
    a = np.column_stack([fa, 10 + 0.5 * fa + rng.normal(0, 1, 40), 5 + 0.2 * fa])
    b = np.column_stack([fb, 40 + 0.5 * fb + rng.normal(0, 1, 40), 5 + 0.2 * fb])
    frames = np.arange(41, 3041)
    assert len(frames) > 2 * B.GSI_BLOCK  # three blocks
    t_all = np.concatenate([a[:, 0], frames, b[:, 0]])
    xy = np.vstack([a[:, 1:3], B.linear(a, b, frames), b[:, 1:3]])
    ls = float(np.clip(10 * np.log(1000 / len(t_all)), 0.1, 100))
    centre = 0.5 * (a[-1, 1:3] + b[0, 1:3])  # gsi's origin: the middle of the gap's ends
    whole = B._gp_smooth(t_all, xy - centre, frames, ls) + centre  # one solve, every frame
    np.testing.assert_allclose(B.gsi(a, b, frames), whole, rtol=0, atol=1e-9)
    # a gap of one block is the one solve itself
    short = np.arange(41, 41 + B.GSI_BLOCK)
    b2 = b.copy()
    b2[:, 0] -= 3041 - (41 + B.GSI_BLOCK)
    t2 = np.concatenate([a[:, 0], short, b2[:, 0]])
    xy2 = np.vstack([a[:, 1:3], B.linear(a, b2, short), b2[:, 1:3]])
    ls2 = float(np.clip(10 * np.log(1000 / len(t2)), 0.1, 100))
    centre2 = 0.5 * (a[-1, 1:3] + b2[0, 1:3])
    np.testing.assert_array_equal(
        B.gsi(a, b2, short), B._gp_smooth(t2, xy2 - centre2, short, ls2) + centre2
    )


def test_gsi_memory_does_not_grow_with_the_square_of_the_gap() -> None:
    import tracemalloc

    from pftrack.recovery import recover_gap

    a = np.array([[1.0, 10, 10], [2, 11, 10]])
    b = np.array([[6003.0, 20, 10], [6004, 21, 10]])
    tracemalloc.start()
    try:
        got = recover_gap(a, b, None, "gsi")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert got.shape == (6000, 2)
    assert peak < 100e6  # one solve: three 6004 x 6004 float64 matrices, about 0.9 GB


def test_rows_and_segments_of_booleans_are_refused() -> None:
    """Boolean rows were read as 0 and 1: fill_gaps said 'duplicate rows for frame 1, id 1',
    recover_gap 'frames must increase strictly'."""
    from pftrack.recovery import fill_gaps, recover_gap

    rows = np.array([[1, 1, 10, 10, 5, 5, 1, -1, -1, -1], [5, 1, 14, 10, 5, 5, 1, -1, -1, -1.0]])
    with pytest.raises(TypeError, match="fill_gaps: tracks must hold real numbers, got dtype bool"):
        fill_gaps(rows.astype(bool))
    seg = rows[:, [0, 2, 3]]
    with pytest.raises(TypeError, match="segment_a must hold real numbers, got dtype bool"):
        recover_gap(seg[:1].astype(bool), seg[1:], None, "linear")


def test_holes_longer_than_max_gap_are_counted() -> None:
    """Regression: they were left unfilled without a word (``0 gaps filled with 0 rows``)."""
    from pftrack.recovery.fill import long_holes, unfilled_note

    rows = _rows([1, 2, 40, 41, 100, 1, 5], [1, 1, 1, 1, 1, 2, 2])  # holes of 37, 58 and 3
    _, rep = fill_gaps(rows, "linear", max_gap=30)
    assert (rep.n_gaps, rep.n_long_holes, rep.longest_hole) == (1, 2, 58)
    assert long_holes(rows, 30) == (2, 58)
    _, rep = fill_gaps(rows, "linear", max_gap=58)  # at most max_gap: filled, not counted
    assert (rep.n_gaps, rep.n_long_holes, rep.longest_hole) == (3, 0, 0)
    assert long_holes(rows, 58) == (0, 0)
    _, rep = fill_gaps(FAR, "auto")
    assert (rep.n_long_holes, rep.longest_hole) == (1, 9_999_996)
    assert long_holes(smooth_tracks(FAR), DEFAULT_MAX_GAP) == (1, 9_999_996)
    assert unfilled_note(3, 9_999_998, 30) == (
        "3 holes longer than --max-gap 30 left unfilled (longest 9999998 frames)"
    )
    assert unfilled_note(1, 31, 30) == "1 hole longer than --max-gap 30 left unfilled (31 frames)"
    assert unfilled_note(0, 0, 30) == ""


def test_cli_says_how_many_holes_were_left_unfilled(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    import json

    from pftrack.cli import main

    huge = tmp_path / "huge.txt"
    huge.write_text("1,1,10,10,20,40\n2,1,11,10,20,40\n10000000,1,20,10,20,40\n"
                    "10000001,1,21,10,20,40\n")  # fmt: skip
    two = tmp_path / "two.txt"
    two.write_text("1,1,10,10,20,40\n40,1,11,10,20,40\n100,1,12,10,20,40\n1,2,10,10,20,40\n")
    note = "2 holes longer than --max-gap 30 left unfilled (longest 59 frames)"
    one = "1 hole longer than --max-gap 30 left unfilled (9999997 frames)"
    for argv, line in (
        (["recover", str(huge), "--explain"], f"{huge}: {one}"),  # was: "auto: no gap to fill"
        (["-q", "smooth", str(huge)], f"{huge}: {one}"),  # printed as the summary line is
        (["recover", str(two)], f"{two}: {note}"),
        (["smooth", str(two), "--no-link"], f"{two}: {note}"),
    ):
        assert main([*argv, "--out", str(tmp_path / "o.txt")]) == 0
        out = capsys.readouterr().out.splitlines()
        assert out[1] == line, out
    for argv in (["recover", str(two), "--max-gap", "59"], ["smooth", str(two), "--max-gap", "59"]):
        assert main([*argv, "--out", str(tmp_path / "o.txt")]) == 0
        assert "left unfilled" not in capsys.readouterr().out  # none: no line
    (tmp_path / "in").mkdir()
    for p in (huge, two):
        p.rename(tmp_path / "in" / p.name)
    for cmd in ("recover", "smooth"):  # the batch's summary: one line per file that has some
        argv = [cmd, str(tmp_path / "in"), "--out", str(tmp_path / cmd), "--workers", "0"]
        assert main(argv) == 0
        out = capsys.readouterr().out
        assert f"\nhuge: {one}\n" in out
        assert f"\ntwo: {note}\n" in out
        files = json.loads((tmp_path / cmd / "summary.json").read_text())["files"]
        assert [(f["long_holes"], f["longest_hole"]) for f in files] == [(1, 9999997), (2, 59)]
