"""A MOT file with no row: a tracks file is a tracker's finding, a ground truth is refused.

trial63 (6 December): a 0-byte file was read as a tracks file with no rows everywhere, and
``pftrack eval --gt`` of one scored the result against nothing, every box a false positive
(HOTA 0, exit 0, without a word). docs/io.md, "A tracks file with no row".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import no_rows, read_mot
from pftrack.synthetic import make_scene

#: name -> what a file of no row holds
EMPTY = {"empty.txt": "", "blank.txt": "# frame,id,...\n\n  \n"}
SAID = {"empty.txt": "is empty (0 bytes)", "blank.txt": "holds no row (only blank or comment"}


@pytest.fixture
def files(tmp_path: Path) -> Path:
    for name, text in EMPTY.items():
        (tmp_path / name).write_text(text)
    make_scene(n_frames=10, width=96, height=72, n_walkers=2, rng=0).write_truth(
        tmp_path / "gt.txt"
    )
    return tmp_path


@pytest.mark.parametrize("name", list(EMPTY))
def test_a_tracks_file_of_no_row_is_no_rows(
    files: Path, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    src = files / name
    assert read_mot(src).shape == (0, 10)
    assert no_rows(src).startswith(SAID[name])
    for command in ("recover", "smooth"):
        out = files / f"{command}.txt"
        assert main([command, str(src), "--out", str(out)]) == 0
        assert out.read_bytes() == b"" and "0 rows" in capsys.readouterr().out
    assert main(["eval", "--gt", str(files / "gt.txt"), "--res", str(src)]) == 0
    err = capsys.readouterr().err
    assert err == (
        f"pftrack eval: warning: {src} {no_rows(src)}: scored as tracks of nothing, every "
        "ground-truth box missed\n"
    )


@pytest.mark.parametrize("name", list(EMPTY))
def test_a_ground_truth_of_no_row_is_refused(
    files: Path, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = files / name
    report = files / "s.json"
    argv = ["eval", "--gt", str(gt), "--res", str(files / "gt.txt"), "--json", str(report)]
    assert main(argv) == 2  # was: scored, every result box a false positive, exit 0
    err = capsys.readouterr().err
    assert err == (
        f"pftrack eval: error: ground truth {gt} {SAID[name]}"
        + (" lines)" if name == "blank.txt" else "")
        + ": nothing to score against (a cut download or copy?)\n"
    )
    assert not report.exists()
    assert main(["experiment", "gaps", "--gt", str(gt)]) == 2  # as before
    assert f"ground truth {gt} is empty" in capsys.readouterr().err


def test_a_tracks_file_with_rows_is_scored_without_the_note(
    files: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = files / "gt.txt"
    assert main(["eval", "--gt", str(gt), "--res", str(gt)]) == 0
    captured = capsys.readouterr()
    assert captured.err == "" and "100.0" in captured.out
    assert len(read_mot(gt)) and np.all(read_mot(gt)[:, 0] >= 1)
