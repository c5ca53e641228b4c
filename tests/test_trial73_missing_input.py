"""A missing tracks file is said first, before the options a folder would have needed.

A user's trial at stop 73: ``pftrack recover results/ --out filled/ --workers 0`` after a
batch that never ran (no ``results/``) said ``--workers applies to a batch (several files or a
folder); one file runs in this process: drop it``; dropped, ``--out filled/ names a folder;
give a file name``: two mends, neither for the folder that is not there.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from pftrack.cli import main


@pytest.mark.parametrize("command", ["recover", "smooth"])
@pytest.mark.parametrize(
    "options", [["--workers", "0"], [], ["--workers", "2"], ["--scheduler", "tcp://h:8786"]]
)
def test_a_missing_input_is_named_first(
    command: str,
    options: list[str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["-q", command, "results/", "--out", "filled/", *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"pftrack {command}: error: tracks file not found: results/"]
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing made


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_an_existing_file_still_refuses_the_batch_options(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tracks = tmp_path / "t.txt"
    tracks.write_text("1,1,10,10,5,5,1,-1,-1,-1\n")
    assert (
        main(["-q", command, str(tracks), "--out", str(tmp_path / "o.txt"), "--workers", "0"]) == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--workers applies to a batch" in err[0]
    # a broken link exists as a name: read_mot names its target, as before
    (tmp_path / "gone.txt").symlink_to(tmp_path / "nowhere.txt")
    assert main(["-q", command, str(tmp_path / "gone.txt"), "--out", str(tmp_path / "o.txt")]) == 2
    assert "is a broken symbolic link" in capsys.readouterr().err
