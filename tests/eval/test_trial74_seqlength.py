"""A refusal by ``seqLength`` names the ``seqinfo.ini`` it came from (a user's trial at stop 74).

``pftrack eval --gt SEQ`` refuses a ground truth or result row past the sequence's
``seqLength``, as TrackEval does; it said ``... beyond the sequence's 40 frames (seqLength)``,
leaving the user to find which ``seqinfo.ini`` (a TrackEval tree holds one per sequence) and
that the mend may be there (a length cut short) as well as in the rows. Now ``(seqLength in
SEQ/seqinfo.ini)``, for the sequence folder, its ``gt/gt.txt``, a folder of sequences, and a
``pftrack batch`` task's scoring error.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.synthetic import make_scene


def rows(frames: range) -> np.ndarray:
    return np.array([[f, 1, 10, 10, 20, 40, 1, 1, 1] for f in frames], dtype=float)


def sequence(root: Path, gt_frames: range, length: int) -> Path:
    seq = root / "SEQ"
    (seq / "gt").mkdir(parents=True)
    np.savetxt(seq / "gt" / "gt.txt", rows(gt_frames), fmt="%g", delimiter=",")
    (seq / "seqinfo.ini").write_text(
        f"[Sequence]\nname=SEQ\nseqLength={length}\nimWidth=480\nimHeight=360\n"
    )
    return seq


def test_name_seqinfo_adds_the_file_to_a_seqlength_refusal_only() -> None:
    from pftrack.eval.sequences import name_seqinfo

    said = "ground truth has frame 50, beyond the sequence's 40 frames (seqLength)"
    assert name_seqinfo(said, Path("A/seqinfo.ini")) == said.replace(
        "(seqLength)", "(seqLength in A/seqinfo.ini)"
    )
    assert name_seqinfo(said, None) == said
    assert name_seqinfo("ground truth has class 0", Path("A/seqinfo.ini")) == (
        "ground truth has class 0"
    )


@pytest.mark.parametrize("which", ["gt", "res"])
def test_eval_names_the_seqinfo_ini(
    which: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seq = sequence(tmp_path, range(1, 51 if which == "gt" else 41), 40)
    res = tmp_path / "SEQ.txt"
    np.savetxt(res, rows(range(1, 41 if which == "gt" else 51)), fmt="%g", delimiter=",")
    ini = seq / "seqinfo.ini"
    for gt, result in ((seq, res), (seq / "gt" / "gt.txt", res), (tmp_path, tmp_path)):
        assert main(["eval", "--gt", str(gt), "--res", str(result)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        whose = "ground truth" if which == "gt" else "result"
        assert len(err) == 1 and err[0].endswith(
            f"{whose} has frame 50, beyond the sequence's 40 frames (seqLength in {ini})"
        ), err


def test_batch_names_the_seqinfo_ini_in_the_tasks_error(tmp_path: Path) -> None:
    seq = sequence(tmp_path / "in", range(1, 26), 20)
    make_scene(n_frames=20, rng=1).write_video(seq / "video.avi")
    run = subprocess.run(
        [sys.executable, "-m", "pftrack", "-q", "batch", str(tmp_path / "in"), "--out",
         str(tmp_path / "out"), "--workers", "0"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert run.returncode == 1, run.stderr
    said = f"beyond the sequence's 20 frames (seqLength in {seq / 'seqinfo.ini'})"
    assert said in run.stderr, run.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert said in json.dumps(summary)
    assert (tmp_path / "out" / "SEQ.txt").is_file()  # the tracks are written, as before
