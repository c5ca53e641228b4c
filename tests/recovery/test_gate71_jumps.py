"""A hole whose two sides are two objects under one id is left unfilled (issue 12, stop 71).

A tracker that hands its ids on (each id given to another object from some frame) leaves
holes whose sides are different people; ``fill_gaps`` drew a path between them without a
word. :func:`pftrack.recovery.fill.jump_holes` judges each hole's jump against the track's own
speed and the file's; it must never refuse a true hole (docs/recovery.md, "A hole between two
objects is left").
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.io.mot import read_mot, write_mot
from pftrack.recovery import fill_gaps
from pftrack.recovery.fill import (
    JUMP_FACTOR,
    MIN_SPEED,
    OWN_STEPS,
    STEP_QUANTILE,
    jump_holes,
    jump_note,
    short_holes,
)
from pftrack.recovery.linking import filled_mask
from pftrack.synthetic import make_scene

from ..conftest import dataset


def _truth(tmp_path: Path) -> np.ndarray:
    """make_scene's default truth (5 walkers, ids 1-5) with a fifth of its rows dropped."""
    make_scene(rng=0).write_truth(tmp_path / "truth.txt")
    rows = np.asarray(read_mot(tmp_path / "truth.txt"), dtype=np.float64)
    return rows[np.random.default_rng(0).random(len(rows)) >= 0.2]


def _restarted(rows: np.ndarray) -> np.ndarray:
    """The issue's reproduction: each id k handed to ``k % 5 + 1`` from frame 31."""
    out = rows.copy()
    late = out[:, 0] > 30
    out[late, 1] = out[late, 1] % 5 + 1
    return out


def _holes(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows sorted by id, then frame, and the last row before each hole."""
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    holes = np.flatnonzero((r[1:, 1] == r[:-1, 1]) & (np.diff(r[:, 0]) > 1))
    return r, holes


def _reference(r: np.ndarray, holes: np.ndarray) -> np.ndarray:
    """:func:`jump_holes` written plainly: one hole at a time, one step at a time."""
    size = [0.5 * (row[4] + row[5]) for row in r]
    centre = [np.array([row[2] + 0.5 * row[4], row[3] + 0.5 * row[5]]) for row in r]

    def step(i: int) -> float:  # rows i and i + 1, in box sizes
        return float(np.linalg.norm(centre[i + 1] - centre[i])) / max(
            0.5 * (size[i] + size[i + 1]), 1.0
        )

    def consecutive(i: int) -> bool:
        return bool(r[i, 1] == r[i + 1, 1] and r[i + 1, 0] - r[i, 0] == 1)

    steps = [step(i) for i in range(len(r) - 1) if consecutive(i)]
    if not steps:
        return np.zeros(len(holes))
    file_speed = float(np.quantile(steps, STEP_QUANTILE))
    out = []
    for e in holes:
        own, seen = 0.0, False
        for i in range(e - OWN_STEPS, e + OWN_STEPS + 1):
            if i != e and 0 <= i < len(r) - 1 and consecutive(i) and r[i, 1] == r[e, 1]:
                own, seen = max(own, step(i)), True
        if not seen:  # no speed of its own: not judged
            out.append(0.0)
            continue
        scale = max(0.5 * (size[e] + size[e + 1]), 1.0)
        speed = max(own, file_speed, MIN_SPEED, 1.0 / scale)
        out.append(step(e) / ((r[e + 1, 0] - r[e, 0]) * speed))
    return np.array(out)


def test_the_issues_reproduction_is_caught(tmp_path: Path) -> None:
    rows = _truth(tmp_path)
    _, plain = fill_gaps(rows)
    assert plain.n_jumps == 0  # before the hand-over every hole is filled
    assert plain.largest_jump == 0.0

    restarted = _restarted(rows)
    filled, report = fill_gaps(restarted)
    # the holes that bridge two walkers: their sides held different ids in the truth
    r, holes = _holes(restarted)
    # the truth's id of every row of r: undo the hand-over
    truth_id = np.where(r[:, 0] > 30, (r[:, 1] - 2) % 5 + 1, r[:, 1])
    bridging = truth_id[holes] != truth_id[holes + 1]
    assert bridging.any()
    ratio = jump_holes(r, holes)
    refused = ratio > JUMP_FACTOR
    assert refused.any()
    assert not (refused & ~bridging).any()  # no true hole refused
    assert report.n_jumps == int(refused.sum())
    assert report.largest_jump == pytest.approx(ratio[refused].max())
    assert report.n_gaps == short_holes(restarted, 30) - int(refused.sum())
    # nothing was drawn inside a refused hole, and the rest of the holes were filled
    new = filled[filled_mask(filled)]
    for e in holes[refused]:
        tid, a, b = r[e, 1], r[e, 0], r[e + 1, 0]
        inside = (new[:, 1] == tid) & (new[:, 0] > a) & (new[:, 0] < b)
        assert not inside.any()
    assert short_holes(filled, 30) == report.n_jumps
    said = jump_note(report.n_jumps, report.largest_jump)
    assert said in report.describe()
    assert said in str(report)
    assert "two objects under one id?" in said


def test_jump_holes_matches_a_plain_reference() -> None:
    rng = np.random.default_rng(7)
    rows = []
    for tid in range(1, 9):
        frames = np.sort(rng.choice(np.arange(1, 80), size=40, replace=False))
        xy = np.cumsum(rng.normal(0, 3 * tid, size=(40, 2)), axis=0) + 200
        wh = rng.uniform(0, 60, size=(40, 2))  # 0-wide boxes too
        wh[::7] = 0.0  # and 0 x 0 ones: judged in pixels
        rows += [[f, tid, *p, *s] for f, p, s in zip(frames, xy, wh, strict=True)]
    r, holes = _holes(np.array(rows, dtype=np.float64))
    assert len(holes) > 50
    np.testing.assert_allclose(jump_holes(r, holes), _reference(r, holes), rtol=1e-12)
    assert jump_holes(r, holes[:0]).shape == (0,)


def test_nothing_judged_without_a_track_speed() -> None:
    rows = np.array([[1, 1, 0, 0, 10, 10], [5, 1, 900, 900, 10, 10]], dtype=np.float64)
    r, holes = _holes(rows)
    assert jump_holes(r, holes).tolist() == [0.0]
    assert fill_gaps(rows)[1].n_jumps == 0  # no speed to judge by: filled, as it was
    # among tracks seen on every frame, a track seen only twice has no speed of its own:
    # not judged by the others' (a detector run every few frames), and filled
    walkers = [[f, k, 10.0 * k + f, 50.0, 20.0, 40.0] for k in (1, 2) for f in range(1, 11)]
    sparse = [[1, 3, 100, 100, 20, 40], [5, 3, 300, 200, 20, 40]]
    _, report = fill_gaps(np.array(walkers + sparse, dtype=np.float64))
    assert (report.n_gaps, report.n_jumps) == (1, 0)
    seen = sparse + [[f, 3, 300, 200, 20, 40] for f in (6, 7)]  # now still after the hole
    _, report = fill_gaps(np.array(walkers + seen, dtype=np.float64))
    assert (report.n_gaps, report.n_jumps) == (0, 1)


def test_a_static_file_still_lets_a_box_move() -> None:
    """Nothing moves in the file: 1 px a frame for small boxes, MIN_SPEED box sizes for large."""
    still = [[f, 1, 10.0, 10.0, 4.0, 4.0] for f in range(1, 20)]
    moved = [[f, 2, 50.0 + (f > 10) * 3.0, 50.0, 4.0, 4.0] for f in [*range(1, 10), *range(12, 20)]]
    _, report = fill_gaps(np.array(still + moved))
    assert (report.n_gaps, report.n_jumps) == (1, 0)  # 3 px over 3 frames: within 1 px a frame
    far = [[f, 2, 50.0 + (f > 10) * 30.0, 50.0, 4.0, 4.0] for f in [*range(1, 10), *range(12, 20)]]
    assert fill_gaps(np.array(still + far))[1].n_jumps == 1  # 30 px over 3 frames of 4 px boxes
    # boxes of 40 px: 4 x 3 frames x MIN_SPEED x 40 px = 24 px allowed, at 20 px filled
    big = [
        [f, 3, 50.0 + (f > 10) * 20.0, 50.0, 40.0, 40.0] for f in [*range(1, 10), *range(12, 20)]
    ]
    assert fill_gaps(np.array(still + big))[1].n_jumps == 0


def test_fast_people_of_a_car_mounted_camera_are_not_refused() -> None:
    """KITTI-17's five fastest truth tracks (15-19 px a frame), each cut by holes of 1-6 frames."""
    gt = np.asarray(read_mot(dataset("mot15-gt/KITTI-17") / "gt.txt"), dtype=np.float64)
    r, holes = _holes(gt)
    assert len(holes) == 0  # the truth has none: every hole below is one we cut
    fast = []
    for tid in np.unique(r[:, 1]):
        t = r[r[:, 1] == tid]
        d = np.hypot(*np.diff(t[:, 2:4] + 0.5 * t[:, 4:6], axis=0).T)
        if len(t) > 40 and np.median(d) > 10:  # px a frame
            fast.append(tid)
    assert len(fast) == 5
    keep = np.ones(len(r), dtype=bool)
    for tid in fast:
        at = int(np.flatnonzero(r[:, 1] == tid)[0]) + 3
        for missing in range(1, 7):
            keep[at : at + missing] = False
            at += missing + 3
    _, report = fill_gaps(r[keep])
    assert (report.n_gaps, report.n_jumps) == (30, 0)


def test_a_sprinter_among_walkers_is_not_refused() -> None:
    """One object 20 times faster than the file's others, and one that starts to run in a hole."""
    rows = []
    for tid in range(1, 11):  # walkers at 1 px a frame
        rows += [[f, tid, 20.0 * tid + f, 100.0, 20.0, 50.0] for f in range(1, 101)]
    sprint = [[f, 20, 5.0 + 20.0 * f, 300.0, 20.0, 50.0] for f in range(1, 101) if f % 9]
    start = [[f, 21, 400.0 + max(0, f - 50) * 20.0, 30.0, 20.0, 50.0] for f in range(1, 101)]
    start = [row for row in start if not 48 <= row[0] <= 52]  # it starts to run unseen
    _, report = fill_gaps(np.array(rows + sprint + start))
    assert report.n_jumps == 0
    assert report.n_gaps == 11 + 1


def test_deterministic_and_independent_of_row_order(tmp_path: Path) -> None:
    restarted = _restarted(_truth(tmp_path))
    first, rep1 = fill_gaps(restarted)
    shuffled = restarted[np.random.default_rng(3).permutation(len(restarted))]
    second, rep2 = fill_gaps(shuffled)
    assert np.array_equal(first, second)
    assert (rep1.n_jumps, rep1.largest_jump) == (rep2.n_jumps, rep2.largest_jump)
    r, holes = _holes(restarted)
    assert np.array_equal(jump_holes(r, holes), jump_holes(r, holes))


def test_bad_input_is_refused_as_before() -> None:
    with pytest.raises(ValueError, match=r"fill_gaps: tracks must have shape \(M, 6..10\)"):
        fill_gaps(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="duplicate"):
        fill_gaps([[1, 1, 0, 0, 5, 5], [1, 1, 0, 0, 5, 5]])
    bad = [[1, 1, 0, 0, 5, 5], [3, 1, np.nan, 0, 5, 5]]
    with pytest.raises(ValueError):
        fill_gaps(bad)


def test_the_commands_say_it_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from pftrack.cli import main

    src = tmp_path / "restart.txt"
    write_mot(src, _restarted(_truth(tmp_path)), exact=True)
    _, report = fill_gaps(read_mot(src))
    said = jump_note(report.n_jumps, report.largest_jump)
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main(["recover", str(src), "--out", str(tmp_path / "r.txt"), "--explain"]) == 0
    out = capsys.readouterr()
    assert out.err == f"pftrack recover: warning: {src}: {said}\n"
    assert out.out.rstrip().endswith(said)  # --explain's last line
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        assert main(["-q", "smooth", str(src), "--out", str(tmp_path / "s.txt")]) == 0
    err = capsys.readouterr().err
    assert err.startswith(f"pftrack smooth: warning: {src}: ")
    assert err.count("\n") == 1
    assert "too far apart for one object" in err
    plain = tmp_path / "plain.txt"
    write_mot(plain, _truth(tmp_path), exact=True)
    for command in ("recover", "smooth"):  # warnings are errors here: nothing is said
        assert main(["-q", command, str(plain), "--out", str(tmp_path / "p.txt")]) == 0


def test_the_batch_says_it_of_each_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder's files through the batch layer: the summary's line per file, as one file's."""
    import json

    from pftrack.cli import main

    folder = tmp_path / "in"
    folder.mkdir()
    rows = _restarted(_truth(tmp_path))
    write_mot(folder / "restart.txt", rows, exact=True)
    write_mot(folder / "plain.txt", _truth(tmp_path), exact=True)
    _, report = fill_gaps(read_mot(folder / "restart.txt"))
    assert report.n_jumps
    for cmd in ("recover", "smooth"):
        out_dir = tmp_path / cmd
        argv = [cmd, str(folder), "--out", str(out_dir), "--workers", "0"]
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            assert main(argv) == 0
        out = capsys.readouterr().out
        said = [line for line in out.splitlines() if "too far apart for one object" in line]
        assert len(said) == 1 and said[0].startswith("restart: "), out  # plain.txt: nothing
        files = {f["name"]: f for f in json.loads((out_dir / "summary.json").read_text())["files"]}
        assert files["plain"]["jump_holes"] == 0
        assert files["restart"]["jump_holes"] >= 1
        if cmd == "recover":  # the report's own words, its ratio included
            assert said[0] == f"restart: {jump_note(report.n_jumps, report.largest_jump)}"
            assert files["restart"]["largest_jump"] == pytest.approx(report.largest_jump)
