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


@pytest.mark.parametrize("name", ["gt.txt", "tracks.csv", "det"])
def test_batch_refuses_a_tracks_file_before_work(tmp_path, capsys, name):
    """Was: a task that failed as "not a video", exit 1, ``--out`` made with a summary."""
    path = tmp_path / name
    write_mot(path, ROWS)
    out = tmp_path / "out"
    assert main(["batch", "-q", str(path), "--out", str(out), "--workers", "0"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert f"{path} holds MOTChallenge rows (tracks or detections), not frames" in err
    assert "pftrack recover or pftrack smooth take tracks files" in err
    assert not out.exists()


def test_batch_still_runs_an_empty_or_binary_file_as_a_failed_task(tmp_path, capsys):
    """Not rows: a damaged video as far as the batch can tell (its task fails, exit 1)."""
    empty = tmp_path / "empty.txt"
    empty.touch()
    binary = tmp_path / "junk.dat"
    binary.write_bytes(b"\xff\x00" * 100)
    for path in (empty, binary):
        out = tmp_path / f"out_{path.stem}"
        assert main(["batch", "-q", str(path), "--out", str(out), "--workers", "0"]) == 1
        assert (out / "summary.json").is_file()
    capsys.readouterr()
