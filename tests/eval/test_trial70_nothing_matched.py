"""``evaluate_sequence`` of a result that matches nothing says so, as ``pftrack eval`` does.

Stop 69's trial: results numbered from frame 101 against a truth of frames 1-71 scored MOTA
-1.0 through the Python API without a word, while ``pftrack eval`` warned.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval import evaluate_mot, evaluate_sequence
from tests.eval.cases import write_rows


def walkers(n_frames: int = 71, n_ids: int = 4) -> np.ndarray:
    """MOT15-style truth: `n_ids` boxes walking right over frames 1..`n_frames`."""
    rows = [
        [f, k, 20.0 + 60 * k + 2 * f, 40.0 + 10 * k, 30.0, 80.0, 1, -1, -1, -1]
        for f in range(1, n_frames + 1)
        for k in range(1, n_ids + 1)
    ]
    return np.asarray(rows)


def test_frames_with_none_in_common_are_warned_about_and_scored_as_given() -> None:
    gt = walkers()
    res = gt.copy()
    res[:, 0] += 100  # frames 101-171: numbered otherwise
    with pytest.warns(UserWarning, match="^evaluate_mot: none of "):  # as stop 71 made it
        expected = evaluate_mot(gt, res)
    assert expected.mota == -1.0
    with pytest.warns(UserWarning) as caught:
        s = evaluate_sequence(gt, res)
    assert [str(w.message) for w in caught] == [
        "evaluate_sequence: none of the result's 284 boxes (frames 101-171) matches a "
        "ground-truth box (frames 1-71) with IoU 0.5 or more, on any frame: no frame of it is "
        "a frame of the ground truth: frames numbered otherwise (shifted?), or the tracks of "
        "another sequence? (scored as given: MOTA -1.000)"
    ]
    assert caught[0].filename == __file__  # the caller's line, not the library's
    assert repr(s.mot) == repr(expected)  # the scores unchanged by the warning (NaN: repr)


def test_boxes_elsewhere_on_the_same_frames_are_warned_about() -> None:
    gt = walkers()
    res = gt.copy()
    res[:, 2] += 500  # another scene's boxes on the same frames
    with pytest.warns(UserWarning, match=r"^evaluate_sequence: none of the result's 284 boxes "):
        s = evaluate_sequence(gt, res, iou_threshold=0.3)
    assert s.mot.num_matches == 0
    with pytest.warns(UserWarning) as caught:
        evaluate_sequence(gt, res, iou_threshold=0.3)
    message = str(caught[0].message)
    assert "with IoU 0.3 or more" in message
    assert "the tracks of another sequence or video, or frames numbered otherwise?" in message
    assert "no frame of it" not in message  # the frames are the truth's


@pytest.mark.parametrize("case", ["own", "empty", "one match", "partial frames"])
def test_nothing_said_of_a_result_that_matches_or_is_empty(case: str) -> None:
    gt = walkers()
    res = gt.copy()
    if case == "empty":
        res = res[:0]  # a tracker that found nothing: a finding, not a mix-up
    elif case == "one match":
        res[1:, 2] += 500  # every box but the first elsewhere
    elif case == "partial frames":
        res[:, 0] += 60  # frames 61-71 still in common
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = evaluate_sequence(gt, res)
    assert s.mot.num_objects == len(gt)


def test_pftrack_eval_says_it_once_naming_the_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The CLI's note (with the files' names) and not the API's warning as well."""
    gt = walkers()
    res = gt.copy()
    res[:, 0] += 100
    g, r = write_rows(tmp_path / "gt.txt", gt), write_rows(tmp_path / "res.txt", res)
    argv = ["eval", "-q", "--gt", str(g), "--res", str(r)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the API's warning, not filtered, would raise here
        assert main(argv) == 0
    out, err = capsys.readouterr()
    assert err == (
        f"pftrack eval: warning: {r}: none of its 284 boxes (frames 101-171) matches a "
        f"ground-truth box of {g} (frames 1-71) with IoU 0.5 or more, on any frame: no frame of "
        "it is a frame of the ground truth: frames numbered otherwise (shifted?), or the tracks "
        "of another sequence?\n"
    )
    assert re.search(r"-100\.0", out)  # MOTA -100.0 % in the table
