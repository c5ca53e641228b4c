"""``pftrack eval`` says when the truth and the result cover different frames.

A user's trial at stop 73: TUD-Campus's truth cut to frames 1-40 against tracks of its 71
frames scored 133 false positives, MOTA 21.4 (81.4 on the frames both cover), exit 0 and no
word; tracks of frames 1-40 against the whole truth, 181 misses, likewise. A truth annotated
over part of a video, or a run stopped early, is a user's mistake as often as a finding: the
scores stay as they are (TrackEval's), and the frames each file has outside the other's are
said, with the cut that scores the frames both cover.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval.rows import APART_FRAMES, frame_ranges_notes
from pftrack.synthetic import make_scene

FRAMES = 40


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    """A 40-frame scene's truth, a box on every frame."""
    rows = make_scene(n_frames=FRAMES, rng=1).truth
    assert set(rows[:, 0].astype(int)) == set(range(1, FRAMES + 1))
    return rows


def write(path: Path, rows: np.ndarray) -> Path:
    np.savetxt(path, rows, fmt="%g", delimiter=",")
    return path


def evaluate(
    gt: Path, res: Path, capsys: pytest.CaptureFixture[str]
) -> tuple[list[str], dict[str, float]]:
    """``pftrack eval``'s warnings and its JSON's figures (exit 0 asserted)."""
    out = gt.parent / f"{gt.stem}-{res.stem}.json"
    assert main(["-q", "eval", "--gt", str(gt), "--res", str(res), "--json", str(out)]) == 0
    said = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    doc = json.loads(out.read_text())
    return said, {"fp": doc["false_positives"], "fn": doc["misses"]}


def test_a_truth_of_part_of_the_frames_is_said_and_scored_as_before(
    truth: np.ndarray, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = write(tmp_path / "gt20.txt", truth[truth[:, 0] <= 20])
    res = write(tmp_path / "res.txt", truth)
    said, scores = evaluate(gt, res, capsys)
    n = int((truth[:, 0] > 20).sum())
    assert scores["fp"] == n and scores["fn"] == 0  # every box after frame 20: TrackEval's
    assert said == [
        f"pftrack eval: warning: {res}: {n} of its {len(truth)} boxes "
        f"({100 * n / len(truth):.0f} %) lie on 20 frames outside {gt}'s frames 1-20 (frames "
        f"21-40), all scored as false positives: does {gt} cover only part of the video? If "
        f"so, score the frames both cover (awk -F, '$1>=1 && $1<=20' {res} > cut.txt)"
    ]


def test_a_result_of_part_of_the_frames_is_said(
    truth: np.ndarray, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = write(tmp_path / "gt.txt", truth)
    res = write(tmp_path / "res.txt", truth[truth[:, 0] > 15])  # frames 16-40
    said, scores = evaluate(gt, res, capsys)
    n = int((truth[:, 0] <= 15).sum())
    assert scores["fn"] == n and scores["fp"] == 0
    assert len(said) == 1
    assert said[0].startswith(
        f"pftrack eval: warning: {gt}: {n} of its {len(truth)} boxes "
        f"({100 * n / len(truth):.0f} %) lie on 15 frames outside {res}'s frames 16-40 "
        "(frames 1-15), all scored as misses: does "
    )


def test_the_same_frames_or_a_few_apart_say_nothing(
    truth: np.ndarray, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = write(tmp_path / "gt.txt", truth)
    assert evaluate(gt, write(tmp_path / "res.txt", truth), capsys)[0] == []
    # a tracker's boxes on 9 frames after the truth's last person left: false positives,
    # as they are, and nothing said
    cut = truth[truth[:, 0] <= FRAMES - APART_FRAMES + 1]
    gt_cut = write(tmp_path / "gt_cut.txt", cut)
    said, scores = evaluate(gt_cut, tmp_path / "res.txt", capsys)
    assert said == [] and scores["fp"] == len(truth) - len(cut)


def test_the_notes_of_rows() -> None:
    rows = np.array([[f, 1, 10, 10, 5, 5, 1, -1, -1, -1] for f in range(1, 41)], float)
    assert frame_ranges_notes(rows, rows, gt_name="g", res_name="r") == []
    assert frame_ranges_notes(rows[:0], rows, gt_name="g", res_name="r") == []  # empty: its own
    both = frame_ranges_notes(rows[:25], rows[10:], gt_name="g", res_name="r")  # 1-25, 11-40
    assert len(both) == 2
    assert both[0].startswith(
        "r: 15 of its 30 boxes (50 %) lie on 15 frames outside g's frames 1-25 (frames 26-40), "
        "all scored as false positives"
    )
    assert both[1].startswith(
        "g: 10 of its 25 boxes (40 %) lie on 10 frames outside r's frames 11-40 (frames 1-10), "
        "all scored as misses"
    )
    # one frame fewer on a side: that side says nothing
    assert len(frame_ranges_notes(rows[:25], rows[9:], gt_name="g", res_name="r")) == 1
