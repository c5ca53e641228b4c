"""A user's trial at stop 69: inputs named as other tools and systems name them."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.batch import find_track_files
from pftrack.cli import main
from pftrack.io.mot import read_mot, write_mot

ROWS = np.array([[f, 1, 10.0 + f, 20.0, 30.0, 60.0, 1, -1, -1, -1] for f in (1, 2, 5, 6)])


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_a_folders_upper_case_txt_files_are_its_tracks_files(tmp_path, capsys, command):
    """Was: ``B.TXT`` (a Windows tracker's output) passed over without a word, exit 0."""
    folder = tmp_path / "results"
    folder.mkdir()
    write_mot(folder / "a.txt", ROWS)
    write_mot(folder / "B.TXT", ROWS)
    write_mot(folder / "c.Txt", ROWS)
    assert [p.name for p in find_track_files([folder])] == ["a.txt", "B.TXT", "c.Txt"]
    out = tmp_path / "out"
    assert main([command, "-q", str(folder), "--out", str(out), "--workers", "0"]) == 0
    assert sorted(p.name for p in out.glob("*.txt")) == ["B.txt", "a.txt", "c.txt"]
    filled = read_mot(out / "B.txt")
    assert filled[:, 0].tolist() == [1, 2, 3, 4, 5, 6]  # the hole of frames 3-4 filled
    np.testing.assert_array_equal(read_mot(out / "a.txt"), filled)
    capsys.readouterr()


def test_one_name_in_two_cases_is_refused(tmp_path, capsys):
    """``a.txt`` and ``a.TXT`` would write one output, ``a.txt``: refused before work."""
    folder = tmp_path / "results"
    folder.mkdir()
    write_mot(folder / "a.txt", ROWS)
    write_mot(folder / "a.TXT", ROWS)
    out = tmp_path / "out"
    assert main(["recover", "-q", str(folder), "--out", str(out), "--workers", "0"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "two inputs are both named 'a'" in err
    assert not out.exists()
