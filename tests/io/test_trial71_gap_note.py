"""An image folder whose names skip numbers, tracked without detections, says how it numbers.

A user's trial at stop 71: ``pftrack track imgs/`` of ``0001.png .. 0030.png`` without
``0011`` and ``0012`` wrote 28 frames numbered 1..28 by position (image ``0013`` as frame 11),
exit 0 and not a word; a ground truth numbered by the names then scored them shifted. With
detections such a folder was refused already; ``pftrack batch`` refused only to score it.
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot
from pftrack.synthetic import make_scene

NOTE = (
    "{}: image 0005 is missing (names 0001..0012 skip numbers): the rows number the frames "
    "1..N in the names' order (row frame k is the k-th image), not by the names: a ground "
    "truth numbered by the names does not line up with them past the gap"
)


def images(folder: Path, skip: tuple[int, ...]) -> None:
    """Frames 1-12 of a synthetic scene as ``0001.png`` ..., less the numbers in `skip`."""
    folder.mkdir(parents=True)
    for k, frame in enumerate(make_scene(n_frames=12, rng=0).frames, start=1):
        if k not in skip:
            assert cv2.imwrite(str(folder / f"{k:04d}.png"), frame)


def test_track_says_it_once_and_tracks_as_before(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "imgs"
    images(folder, skip=(5, 6))
    out = tmp_path / "t.txt"
    assert main(["-q", "track", str(folder), "--out", str(out)]) == 0
    err = capsys.readouterr().err.splitlines()
    said = [line for line in err if "skip numbers" in line]
    assert said == [f"pftrack track: warning: {NOTE.format(folder)}"]
    rows = read_mot(out)
    assert rows[:, 0].max() <= 10  # 10 images: frames numbered by position, as before


@pytest.mark.parametrize("skip", [(), (2, 4, 6, 8, 10, 12)])
def test_a_folder_numbered_without_a_hole_says_nothing(tmp_path: Path, capsys, skip) -> None:
    """No gap, or names stepping evenly by 2 (every other frame kept: no frame count, as
    tests/test_cli_io.py's time stamps and every fifth frame)."""
    folder = tmp_path / "imgs"
    images(folder, skip=skip)
    assert main(["-q", "track", str(folder), "--out", str(tmp_path / "t.txt")]) == 0
    assert "skip numbers" not in capsys.readouterr().err


def test_detections_are_still_refused_with_a_gap(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "imgs"
    images(folder, skip=(5, 6))
    det = tmp_path / "det.txt"
    det.write_text("1,-1,10,20,30,60,0.9,-1,-1,-1\n")
    args = ["-q", "track", str(folder), "--detections", str(det)]
    assert main([*args, "--out", str(tmp_path / "t.txt")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "image 0005 is missing" in err[0]


@pytest.mark.parametrize("gap", [True, False])
def test_batch_says_it_as_the_sequences_warning(tmp_path: Path, capsys, gap: bool) -> None:
    folder = tmp_path / "videos" / "imgs"
    images(folder, skip=(5, 6) if gap else ())
    out = tmp_path / "res"
    assert main(["-q", "batch", str(tmp_path / "videos"), "--out", str(out), "--workers", "0"]) == 0
    said = json.loads((out / "imgs.json").read_text()).get("warnings", [])
    assert [w for w in said if "skip numbers" in w] == ([NOTE.format(folder)] if gap else [])
    capsys.readouterr()
