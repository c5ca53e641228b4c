"""Every function taking MOTChallenge rows checks their layout first, one way, one message.

Regressions: ``fill_gaps(np.zeros((0,)))`` said ``rows must have shape (M, 10)`` where
``smooth_tracks`` of the same array returned no rows; ``smooth_tracks([[1, 2, 3], [1, 2]])``
(and ``filled_mask``, ``repair_crossings``, ``drop_nested``, ``gate_for_rows``) answered with
NumPy's "setting an array element with a sequence ... inhomogeneous shape" where
``fill_gaps`` said ``rows must be a rectangular array of numbers``; and ``fill_gaps``,
``smooth_tracks`` and ``link_tracklets`` refused the (M, 6..9) arrays that ``write_mot`` and
``evaluate_mot`` take and that ``pftrack recover`` and ``pftrack smooth`` take as files.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.io.mot import mot_text, read_mot, write_mot
from pftrack.recovery import check_unique, fill_gaps, filled_mask, link_tracklets
from pftrack.recovery.experiment import trajectories
from pftrack.recovery.linking import LinkConfig, gate_for_rows
from pftrack.tracking import repair_crossings, smooth_tracks
from pftrack.tracking.offline import complete_boxes, drop_nested

#: Each entry point, with what it returns as rows (None: it returns no rows).
ENTRY_POINTS: dict[str, tuple[Callable[[Any], Any], Callable[[Any], Any] | None]] = {
    "fill_gaps": (fill_gaps, lambda out: out[0]),
    "smooth_tracks": (smooth_tracks, lambda out: out),
    "link_tracklets": (link_tracklets, lambda out: out[0]),
    "repair_crossings": (repair_crossings, lambda out: out),
    "drop_nested": (drop_nested, lambda out: out),
    "complete_boxes": (
        lambda r: complete_boxes(r, [[0.5, 10.0], [0.2, 5.0]], 0.8),
        lambda out: out,
    ),
    "filled_mask": (filled_mask, None),
    "mot_text": (mot_text, None),
    "gate_for_rows": (lambda r: gate_for_rows(LinkConfig(), r), None),
    "check_unique": (lambda r: check_unique(r, who="check_unique"), None),
    "trajectories": (trajectories, None),
}

#: The argument each names in its messages, where it is not ``rows`` (its own name).
ARGUMENT = {"fill_gaps": "tracks", "link_tracklets": "tracks"}

LAYOUT = "(6 to 10 columns: frame, id, left, top, width, height[, conf, x, y, z])"

ROWS = np.array(  # sorted by (frame, id), as write_mot writes them
    [
        [1, 1, 10, 10, 20, 40, 0.9, -1, -1, -1],
        [1, 2, 90, 10, 20, 40, 1, -1, -1, -1],
        [2, 1, 12, 10, 20, 40, 0.8, -1, -1, -1],
        [4, 2, 96, 10, 20, 40, 1, -1, -1, -1],
        [6, 1, 20, 10, 20, 40, 0.9, -1, -1, -1],
        [7, 1, 22, 10, 20, 40, 0.7, -1, -1, -1.0],
    ]
)


@pytest.mark.parametrize("name", list(ENTRY_POINTS))
@pytest.mark.parametrize(
    "empty",
    [[], np.zeros((0,)), np.zeros((0, 10)), np.zeros((0, 6)), np.zeros((0, 10), np.int64)],
    ids=["list", "0", "0x10", "0x6", "int"],
)
def test_an_array_without_values_is_no_rows_everywhere(name: str, empty: Any) -> None:
    call, rows_of = ENTRY_POINTS[name]
    out = call(empty)
    if rows_of is not None:
        assert rows_of(out).shape == (0, 10)


@pytest.mark.parametrize("name", list(ENTRY_POINTS))
def test_ragged_rows_are_named(name: str) -> None:
    arg = ARGUMENT.get(name, "rows")
    message = f"{name}: {arg} must be a rectangular array of numbers, got rows of different lengths"
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        ENTRY_POINTS[name][0]([[1, 2, 3], [1, 2]])


@pytest.mark.parametrize("name", list(ENTRY_POINTS))
@pytest.mark.parametrize(
    "rows", [[["a"] * 10], ROWS.astype(complex), ROWS > 0], ids=["text", "complex", "bool"]
)
def test_rows_that_are_not_real_numbers_are_named(name: str, rows: Any) -> None:
    arg = ARGUMENT.get(name, "rows")
    with pytest.raises(TypeError, match=f"^{name}: {arg} must hold real numbers, got dtype "):
        ENTRY_POINTS[name][0](rows)


@pytest.mark.parametrize("name", list(ENTRY_POINTS))
@pytest.mark.parametrize("shape", [(10,), (2, 3), (2, 5), (2, 11), (1, 1, 10)])
def test_a_wrong_shape_has_one_message(name: str, shape: tuple[int, ...]) -> None:
    message = (
        f"{name}: {ARGUMENT.get(name, 'rows')} must have shape (M, 6..10) {LAYOUT}, got {shape}"
    )
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        ENTRY_POINTS[name][0](np.ones(shape))


@pytest.mark.parametrize("name", [n for n, (_, rows_of) in ENTRY_POINTS.items() if rows_of])
@pytest.mark.parametrize("columns", [6, 7, 9])
def test_short_rows_are_the_rows_of_a_file_of_them(tmp_path: Path, name: str, columns: int) -> None:
    """(M, 6..9) rows give what the same rows read from a file give (``pftrack recover`` and
    ``pftrack smooth`` read them so): the missing columns conf 1, x, y, z -1."""
    short = ROWS[:, :columns]
    path = tmp_path / "short.txt"
    write_mot(path, short)
    read = read_mot(path)
    assert read.shape == (len(ROWS), 10)
    call, rows_of = ENTRY_POINTS[name]
    assert rows_of is not None
    expected = rows_of(call(read))
    got = rows_of(call(short))
    np.testing.assert_array_equal(got, expected)
    assert got.shape[1] == 10


def test_fill_gaps_fills_short_rows_as_recover_fills_their_file(tmp_path: Path) -> None:
    from pftrack.cli import main

    path, out = tmp_path / "six.txt", tmp_path / "out.txt"
    write_mot(path, ROWS[:, :6])
    assert main(["-q", "recover", str(path), "--out", str(out)]) == 0
    filled, report = fill_gaps(ROWS[:, :6])
    assert report.n_filled_rows > 0
    assert out.read_text() == mot_text(filled)


def test_filled_mask_of_short_rows_marks_none() -> None:
    """Padded as a file's lines (x, y, z -1), a row of 6 to 9 columns is never a filled one."""
    filled, _ = fill_gaps(ROWS)
    assert filled_mask(filled).any()
    assert not filled_mask(filled[:, :7]).any()
    np.testing.assert_array_equal(filled_mask(filled[:, :9]), filled_mask(filled))


def test_normalised_boxes_are_warned_about(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Boxes within [0, 1] x [0, 1] (a detector's normalised output) went through ``recover`` and
    ``smooth`` without a word: the 50 px linking gate spans 50 frames' widths (ADL-Rundle-6's
    ground truth so written: 24 ids joined into 18) and the filled and smoothed boxes were
    written with 2 decimals (a width of 0.08 +- 0.005: 6 %)."""
    import warnings

    from pftrack.cli import main
    from pftrack.recovery.linking import read_tracks

    norm = tmp_path / "norm.txt"
    rows = [[f, 1, 0.1 + 0.01 * f, 0.2, 0.05, 0.3] for f in (1, 2, 3, 6, 7)]
    write_mot(norm, [*rows, [1, 2, 0.5, 0.52, 0.5, 0.5]])  # a tracker's box past the edge
    said = (
        f"{norm}: every box lies within 1 x 1.02 (its rightmost and lowest edges): normalised "
        "coordinates? pftrack works in pixels (its linking gate, boxes written with 2 decimals): "
        "give pixels (x times the image width, y times its height)"
    )
    with pytest.warns(UserWarning) as caught:
        read_tracks(norm)
    assert [str(w.message) for w in caught] == [said]
    for command in ("recover", "smooth"):
        with warnings.catch_warnings():
            warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
            assert main(["-q", command, str(norm), "--out", str(tmp_path / "o.txt")]) == 0
        assert capsys.readouterr().err == f"pftrack {command}: warning: {said}\n"
    pixels = tmp_path / "px.txt"  # one box reaching past 2: pixels, nothing said
    write_mot(pixels, [*rows, [1, 2, 0.5, 0.5, 0.5, 1.6]])
    read_tracks(pixels)  # warnings are errors here
    (tmp_path / "empty.txt").write_text("")
    read_tracks(tmp_path / "empty.txt")


#: The words a frame 0 gets, wherever rows or a file are refused for it.
ZERO_BASED = "MOTChallenge frames count from 1: numbered from 0? add 1 to every frame"


@pytest.mark.parametrize(
    "name", ["fill_gaps", "smooth_tracks", "link_tracklets", "repair_crossings", "mot_text"]
)
def test_rows_numbered_from_0_are_refused_with_the_mend(name: str) -> None:
    """A user trial: another tracker's rows numbered from 0 (``enumerate`` over frames) were
    refused as "frame 0 is not an integer in 1..2147483647 (refused)", no word of why or
    what to do. MOTChallenge frames count from 1 (``read_mot``, ``eval`` and TrackEval refuse
    frame 0 too), so the rows stay refused, with the mend; a frame -1 gets no such hint."""
    call, _ = ENTRY_POINTS[name]
    rows = ROWS.copy()
    rows[:, 0] -= 1
    mend = re.escape(f"({ZERO_BASED}, rows[:, 0] += 1)")
    with pytest.raises(ValueError, match="frame 0, .*" + mend):
        call(rows)
    rows[0, 0] = -1
    with pytest.raises(ValueError, match=r"frame -1, .* \(frames count from 1\)$"):
        call(rows)
    rows[:, 0] += 2  # what the words say: the rows of the same tracks from frame 1
    call(rows)


def test_a_file_numbered_from_0_is_refused_with_the_mend(tmp_path: Path, capsys: Any) -> None:
    """The same for a file: ``pftrack recover`` / ``smooth`` / ``eval`` and ``read_mot``."""
    from pftrack.cli import main
    from pftrack.eval import evaluate_mot

    rows = ROWS.copy()
    rows[:, 0] -= 1
    path = tmp_path / "zero.txt"
    path.write_text("".join(",".join(f"{v:g}" for v in r) + "\n" for r in rows))
    said = f"zero.txt:1: frame is 0, expected an integer in 1..2147483647 ({ZERO_BASED}, the "
    with pytest.raises(ValueError, match=re.escape(said)):
        read_mot(path)
    for argv in (["recover", str(path), "--out", str(tmp_path / "r.txt")],
                 ["smooth", str(path), "--out", str(tmp_path / "s.txt")],
                 ["eval", "--gt", str(path), "--res", str(path)]):  # fmt: skip
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert said in err and err.count("\n") == 1, err
    gt = re.escape(f"gt row 0 has frame 0, expected >= 1 ({ZERO_BASED}")
    with pytest.raises(ValueError, match=gt):
        evaluate_mot(rows, ROWS)
