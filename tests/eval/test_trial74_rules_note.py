"""``pftrack eval`` says what MOT16/17/20 rules left out of the score (a user's trial at stop 74).

A MOT17-style truth of five people (one a static person, one a distractor, one flagged 0 in
column 7, one barely visible) against a result equal to it scored GT 2 and 55 false positives
with only "MOT17 ground-truth rules" below the table: TrackEval's rules (``prepare_mot``, held
to TrackEval by ``tests/eval/test_hota.py``) leave out the static person's and the
distractor's rows and the result boxes matched to them, leave out the flagged rows but count
the boxes on them as false positives, and threshold no visibility. Now one line after the
table counts each.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval import evaluate_mot

FRAMES = 30


def truth() -> np.ndarray:
    """Five people 100 px apart (no two boxes overlap), classes and flags as the docstring's."""
    rows = []
    for f in range(1, FRAMES + 1):
        for k in range(5):
            cls = {0: 7, 1: 8}.get(k, 1)
            flag = 0 if k == 2 else 1
            vis = 0.05 if k == 3 else 1.0
            rows.append([f, k + 1, 10 + 100 * k + f, 50, 40, 90, flag, cls, vis])
    return np.array(rows, dtype=float)


def write(path: Path, rows: np.ndarray) -> Path:
    np.savetxt(path, rows, fmt="%g", delimiter=",")
    return path


def test_the_note_counts_what_numpy_counts() -> None:
    from pftrack.eval.rows import gt_rules_note

    gt = truth()
    result = np.hstack([gt[:, :6], np.ones((len(gt), 1)), -np.ones((len(gt), 3))])
    scored = int(np.sum((gt[:, 6] == 1) & (gt[:, 7] == 1)))  # NumPy's count of the kept rows
    assert scored == 2 * FRAMES
    note = gt_rules_note(gt, result, "MOT17")
    assert note == (
        f"MOT17 rules, as TrackEval: {scored} of its {len(gt)} rows scored (pedestrians, class "
        f"1, flagged 1); not scored: {FRAMES} of class 7 (static person), {FRAMES} of class 8 "
        f"(distractor), {FRAMES} pedestrians flagged 0 (column 7); {2 * FRAMES} result boxes "
        "matched to a distractor (classes 2, 7, 8, 12) left out, boxes on the other rows not "
        "scored count as false positives; visibility (column 9) is not thresholded"
    )
    # what it says is what is scored: the flagged person's boxes are the false positives
    m = evaluate_mot(gt, result, benchmark="MOT17")
    assert (m.num_objects, m.false_positives, m.misses) == (scored, FRAMES, 0)
    assert (m.num_ignored_gt, m.num_ignored_predictions) == (len(gt) - scored, 2 * FRAMES)
    # MOT15 rules: no classes, the flag alone
    assert gt_rules_note(gt, result, "MOT15") == (
        f"MOT15 rules, as TrackEval: {len(gt) - FRAMES} of its {len(gt)} rows scored (flagged 1 "
        f"in column 7); not scored: {FRAMES} rows flagged 0 (column 7); result boxes on them "
        "count as false positives"
    )  # no word of visibility: MOT15's columns 8-10 are world coordinates
    # every row scored: nothing to say
    every = gt[gt[:, 7] == 1][gt[gt[:, 7] == 1][:, 6] == 1]
    assert gt_rules_note(every, result, "MOT17") is None
    assert gt_rules_note(every[:, :7], result, "MOT15") is None


def test_eval_says_it_in_one_line_below_the_table(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = write(tmp_path / "gt.txt", truth())
    res = write(tmp_path / "res.txt", truth()[:, :6])
    assert main(["eval", "--gt", str(gt), "--res", str(res)]) == 0
    out = capsys.readouterr()
    said = [line for line in out.out.splitlines() if "rules, as TrackEval" in line]
    assert said == [
        f"{gt}: MOT17 rules, as TrackEval: {2 * FRAMES} of its {5 * FRAMES} rows "
        f"scored (pedestrians, class 1, flagged 1); not scored: {FRAMES} of class 7 (static "
        f"person), {FRAMES} of class 8 (distractor), {FRAMES} pedestrians flagged 0 (column 7); "
        f"{2 * FRAMES} result boxes matched to a distractor (classes 2, 7, 8, 12) left out, "
        "boxes on the other rows not scored count as false positives; visibility (column 9) is "
        "not thresholded"
    ]
    legend = out.out.splitlines()[-2]  # the table's legend, as before, then the line
    assert "MOT17 ground-truth rules" in legend and out.out.endswith(said[0] + "\n")
    assert "rules, as TrackEval" not in out.err


def test_a_truth_scored_whole_says_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rows = truth()
    rows[:, 6], rows[:, 7] = 1, 1
    gt = write(tmp_path / "gt.txt", rows)
    res = write(tmp_path / "res.txt", rows[:, :6])
    assert main(["eval", "--gt", str(gt), "--res", str(res)]) == 0
    assert "rules, as TrackEval" not in capsys.readouterr().out


@pytest.mark.dataset
def test_the_datas_truths_said_as_numpy_counts_them() -> None:
    """PETS09-S2L1's MOT15 truth flags some rows 0; TUD-Campus's flags none."""
    from pftrack.eval.rows import gt_rules_note
    from pftrack.io.mot import read_mot
    from tests.conftest import dataset

    pets = read_mot(dataset("pets09-s2l1") / "gt.txt")
    flagged = int(np.sum(pets[:, 6] == 0))
    assert flagged > 0
    assert gt_rules_note(pets, pets, "MOT15") == (
        f"MOT15 rules, as TrackEval: {len(pets) - flagged} of its {len(pets)} rows scored "
        f"(flagged 1 in column 7); not scored: {flagged} rows flagged 0 (column 7); result "
        "boxes on them count as false positives"
    )
    tud = read_mot(dataset("tud-campus") / "gt.txt")
    assert gt_rules_note(tud, tud, "MOT15") is None
