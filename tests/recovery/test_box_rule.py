"""The entry points that take MOTChallenge rows refuse the boxes the file reader refuses.

Regression: ``fill_gaps`` (and ``smooth_tracks``, ``link_tracklets``, ...) took a row of width
-5 and returned filled rows of negative width, where ``pftrack recover`` on the same rows in a
file said ``negative box width or height``; a box value of 1e300 was refused by ``fill_gaps``
under the name of ``recover_gap``'s segments and taken by ``link_tracklets``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import mot_text, read_mot, write_mot
from pftrack.recovery import fill_gaps, link_tracklets
from pftrack.recovery.linking import check_rows
from pftrack.tracking import repair_crossings, smooth_tracks
from pftrack.tracking.offline import complete_boxes, drop_nested

ROWS = np.array(
    [
        [1, 1, 10, 10, 20, 40, 1, -1, -1, -1],
        [3, 1, 14, 10, 20, 40, 1, -1, -1, -1],
        [6, 1, 20, 10, 20, 40, 1, -1, -1, -1],
        [1, 2, 90, 10, 20, 40, 1, -1, -1, -1.0],
    ]
)

ENTRY_POINTS: dict[str, Callable[[Any], object]] = {
    "fill_gaps": fill_gaps,
    "smooth_tracks": smooth_tracks,
    "link_tracklets": link_tracklets,
    "repair_crossings": repair_crossings,
    "drop_nested": drop_nested,
    "complete_boxes": lambda r: complete_boxes(r, [[0.5, 10.0], [0.2, 5.0]], 0.8),
    "mot_text": mot_text,  # write_mot's rows: what the file reader refuses is never written
}


def _with(col: int, value: float) -> np.ndarray:
    r = ROWS.copy()
    r[1, col] = value
    return r


@pytest.mark.parametrize("name", list(ENTRY_POINTS))
@pytest.mark.parametrize(
    ("col", "value", "match"),
    [
        (4, -5.0, r"row 1 \(frame 3, id 1\) has width -5: negative box width or height"),
        (5, -1e-300, r"row 1 \(frame 3, id 1\) has height -1e-300: negative box width or height"),
        (2, 1e300, r"row 1 \(frame 3, id 1\) has left 1e\+300: a box value is beyond ±1e\+09 px"),
        (3, -2e9, r"row 1 \(frame 3, id 1\) has top -2e\+09: a box value is beyond ±1e\+09 px"),
    ],
)
def test_bad_boxes_are_refused_naming_row_frame_id_and_value(
    name: str, col: int, value: float, match: str
) -> None:
    with pytest.raises(ValueError, match=f"^{name}: {match}$"):
        ENTRY_POINTS[name](_with(col, value))


@pytest.mark.parametrize("name", list(ENTRY_POINTS))
def test_zero_sizes_and_the_bound_itself_are_taken_as_the_reader_takes_them(name: str) -> None:
    r = ROWS.copy()
    r[1, 4:6] = 0.0
    r[2, 2] = -1e9
    ENTRY_POINTS[name](r)


@pytest.mark.parametrize(
    ("col", "value"),
    [(4, -5.0), (5, -0.5), (4, 0.0), (5, 0.0), (2, 1e9), (2, 1e9 + 1), (3, -2e9), (4, 1e10)],
)
def test_the_api_and_the_file_reader_share_one_rule(tmp_path: Path, col: int, value: float) -> None:
    rows = _with(col, value)
    path = tmp_path / "t.txt"
    path.write_text("\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n")
    try:
        read_mot(path)
        file_error = None
    except ValueError as e:
        file_error = str(e)
    try:
        check_rows(rows, "api")
        api_error = None
    except ValueError as e:
        api_error = str(e)
    assert (file_error is None) == (api_error is None)
    if file_error is not None and api_error is not None:
        assert file_error.split(": ")[1] == api_error.split(": ")[-1]  # the same words


def test_cli_and_api_refuse_the_same_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _with(4, -5.0)
    src = tmp_path / "t.txt"
    write_mot(src, ROWS)
    src.write_text(src.read_text().replace("3,1,14,10,20,", "3,1,14,10,-5,"))  # write_mot refuses
    assert main(["recover", str(src), "--out", str(tmp_path / "o.txt")]) == 2
    assert "negative box width or height" in capsys.readouterr().err
    with pytest.raises(ValueError, match="negative box width or height"):
        fill_gaps(bad)


def test_smooth_tracks_refuses_bad_measurements() -> None:
    z = ROWS[:, 2:6].copy()
    z[2, 3] = -1.0
    with pytest.raises(
        ValueError,
        match=r"^smooth_tracks: measurements row 2 \(frame 6, id 1\) has height -1: negative box",
    ):
        smooth_tracks(ROWS, measurements=z)
    z[2, 3] = 0.0
    smooth_tracks(ROWS, measurements=z)
