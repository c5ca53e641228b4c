"""experiments.person_size: every fit of the size model, and the rows under other sizes."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from experiments import person_size
from pftrack.tracking import api


@pytest.mark.filterwarnings("ignore:the video is grey:UserWarning")  # the case asked for
def test_fits_are_listed_and_the_last_size_gives_the_runs_rows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # main() raises unless finalize() again with the last fit gives the run's own rows
    person_size.main(
        ["--sequences", "walkers", "--variants", "grey", "--fits", "--out", str(tmp_path)]
    )
    out = capsys.readouterr().out
    n = int(re.search(r"walkers grey: (\d+) fits", out).group(1))  # type: ignore[union-attr]
    fits = re.findall(r"fit +\d+: seen +\d+ held +\d+ feet \d+-\d+ .*h (-?[\d.]+) y", out)
    assert n == len(fits) >= 2
    # the diagnosis of docs/detection.md: the first fit, from the first walkers only (their
    # feet on a few rows, each walker its own size), learns a height slope above 1 in a scene
    # with no perspective; the last does not
    assert float(fits[0]) > 1.0 > float(fits[-1])
    scores = dict(re.findall(r"^  (\w+|1px[-+]) +(-?[\d.]+ / -?[\d.]+ / -?[\d.]+)", out, re.M))
    assert set(scores) == {*person_size.SIZES, "1px-", "1px+"}
    assert scores["median"] != scores["last"]
    assert (tmp_path / "person_size.txt").read_text() == out


def test_bad_arguments_are_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    for args, message in (
        (["--hold-frames", "-1"], "--hold-frames is -1, expected 0 (off) or more"),
        (["--variants", "crop"], "unknown sequence(s) or variant(s): crop"),
    ):
        with pytest.raises(SystemExit) as e:
            person_size.main(["--sequences", "walkers", *args])
        assert e.value.code == 2, args
        assert message in capsys.readouterr().err


class _Finalize:
    """A tracker whose ``finalize()`` completes fixed rows as ``Tracker.finalize`` does."""

    def __init__(self, rows: np.ndarray, lines: np.ndarray) -> None:
        self.rows, self.lines = rows, lines

    def finalize(self) -> np.ndarray:
        out: np.ndarray = api.complete_boxes(self.rows, self.lines, 0.8, "side", 1.6, 360.0)
        return out


def test_ill_posed_completions_do_not_move_with_one_pixel() -> None:
    """`groups ramp`'s last fit (h = 1.033 y - 58.2: one pixel of the intercept moves h_e by
    30 px): track 1's 130 px box with its head at row 51 is completed to 167 px by the default
    and left alone with the intercept one pixel higher; `leave` leaves it alone under both
    lines, `track` completes track 2's short box to its track's median under both."""
    rows = np.zeros((4, 10))
    rows[:, 0] = [1, 2, 3, 4]
    rows[:, 1] = [1, 2, 2, 2]
    rows[:, 2:6] = [[100, 51, 71, 130], [300, 51, 71, 100], [300, 51, 71, 160], [300, 51, 71, 160]]
    lines = np.array([[1.033, -58.2], [0.035, 56.9]])
    moved = lines + [[0.0, 1.0], [0.0, 0.0]]
    rec = person_size.Recorder(tracker=_Finalize(rows, lines), rows=rows, lines=lines)
    assert person_size.head_row_sensitivity(lines) == pytest.approx(1.033 / 0.033)
    h_main = [person_size.rows_with(rec, x)[0, 5] for x in (lines, moved)]
    assert h_main[0] == pytest.approx((-58.2 + 1.033 * 51) / -0.033) and h_main[1] == 130
    for how in ("leave", "track"):
        a, b = (person_size.rows_ill_posed(rec, how, x)[:, 5] for x in (lines, moved))
        np.testing.assert_array_equal(a, b, err_msg=how)
        assert a[0] == 130 and a[1] == (160 if how == "track" else 100), how
    # `margin` only moves the flip: track 2's 100 px box is completed (100 < 0.8 (167 - 30))
    # and, one pixel higher, left alone (100 > 0.8 (137 - 30))
    a, b = (person_size.rows_ill_posed(rec, "margin", x)[:, 5] for x in (lines, moved))
    assert a[0] == b[0] == 130 and a[1] == h_main[0] and b[1] == 100


def test_nothing_to_run_is_status_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An empty ``--sequences`` (was: the header alone, status 0) or only real sequences that
    are missing under ``--data`` (was: every row 'skipped', status 0)."""
    with pytest.raises(SystemExit) as e:
        person_size.main(["--sequences", ",", "--out", str(tmp_path)])
    assert e.value.code == 2
    assert capsys.readouterr().err.endswith("error: --sequences names none\n")
    args = ["--data", str(tmp_path), "--sequences", "pets", "--variants", "ident"]
    assert person_size.main([*args, "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.endswith(
        f"no pets09-s2l1 or tud-campus video under {tmp_path}\n"
    )
