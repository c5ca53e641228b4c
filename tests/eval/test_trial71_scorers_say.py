"""``evaluate_mot`` and ``evaluate_hota`` called alone say when a result matches nothing.

Stop 70 made :func:`~pftrack.eval.evaluate_sequence` warn of a result none of whose boxes
matches a ground-truth box (frames numbered otherwise, another sequence's tracks); the two
scorers under it, called alone, still returned MOTA -1.0 and HOTA 0 without a word. One rule
(``pftrack.eval.rows.say_none_matched``) now says it for all three; ``evaluate_sequence``
says it once.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from pftrack.eval import evaluate_hota, evaluate_mot, evaluate_sequence
from tests.eval.test_trial70_nothing_matched import walkers

SHIFTED = (
    "none of the result's 284 boxes (frames 101-171) matches a ground-truth box (frames 1-71) "
    "with IoU {} or more, on any frame: no frame of it is a frame of the ground truth: frames "
    "numbered otherwise (shifted?), or the tracks of another sequence? (scored as given: {})"
)


def shifted() -> tuple[np.ndarray, np.ndarray]:
    """A truth of frames 1-71 and the same boxes numbered from frame 101."""
    gt = walkers()
    res = gt.copy()
    res[:, 0] += 100
    return gt, res


def test_evaluate_mot_alone_warns_from_the_callers_line() -> None:
    gt, res = shifted()
    with pytest.warns(UserWarning) as caught:
        m = evaluate_mot(gt, res)
    assert [str(w.message) for w in caught] == [
        "evaluate_mot: " + SHIFTED.format("0.5", "MOTA -1.000")
    ]
    assert caught[0].filename == __file__
    assert m.mota == -1.0 and m.num_matches == 0 and m.false_positives == len(res)


def test_evaluate_hota_alone_warns_from_the_callers_line() -> None:
    gt, res = shifted()
    with pytest.warns(UserWarning) as caught:
        h = evaluate_hota(gt, res)
    assert [str(w.message) for w in caught] == [
        "evaluate_hota: " + SHIFTED.format("0.05", "HOTA 0.000")
    ]
    assert caught[0].filename == __file__
    assert h.hota == 0.0 and not h.tp.any() and (h.fp == len(res)).all()


def test_evaluate_sequence_says_it_once_and_scores_as_the_two_scorers() -> None:
    gt, res = shifted()
    with pytest.warns(UserWarning) as caught:
        s = evaluate_sequence(gt, res)
    assert [str(w.message) for w in caught] == [
        "evaluate_sequence: " + SHIFTED.format("0.5", "MOTA -1.000")
    ]  # not three warnings: the scorers under it are not heard
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m, h = evaluate_mot(gt, res), evaluate_hota(gt, res)
    assert repr(s.mot) == repr(m)  # NaN fields: compared by repr
    assert repr(s.hota) == repr(h)


def test_each_scorer_holds_its_own_threshold() -> None:
    """Boxes moved half a width: IoU 1/3, under CLEAR-MOT's 0.5, over HOTA's lowest 0.05."""
    gt = walkers()
    res = gt.copy()
    res[:, 2] += 15  # 30 wide: overlap 15 of a union of 45
    with pytest.warns(UserWarning, match=r"^evaluate_mot: none of the result's 284 boxes "):
        m = evaluate_mot(gt, res)
    assert m.num_matches == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        h = evaluate_hota(gt, res)  # matched at alpha 0.05 ... 0.30: nothing to say
        m3 = evaluate_mot(gt, res, iou_threshold=0.3)
    assert h.tp[0] == len(gt) and h.tp[-1] == 0
    assert m3.num_matches == len(gt)


@pytest.mark.parametrize("case", ["own", "empty", "one match", "no truth scored", "lists"])
def test_nothing_said_when_something_matches_or_nothing_is_there(case: str) -> None:
    gt = walkers()
    res = gt.copy()
    if case == "empty":
        res = res[:0]  # a tracker that found nothing: a finding, not a mix-up
    elif case == "one match":
        res[1:, 2] += 500
    elif case == "no truth scored":
        gt[:, 6] = 0  # every truth row "not considered": nothing to match
        res[:, 0] += 100
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if case == "lists":  # array_like rows, as the scorers take them
            evaluate_mot(gt.tolist(), res.tolist())
            evaluate_hota(gt.tolist(), res.tolist())
        else:
            evaluate_mot(gt, res)
            evaluate_hota(gt, res)


def test_rows_given_as_lists_are_said_of_too() -> None:
    gt, res = shifted()
    with pytest.warns(UserWarning, match=r"^evaluate_mot: none of the result's 284 boxes"):
        evaluate_mot(gt.tolist(), res.tolist())
    with pytest.warns(UserWarning, match=r"^evaluate_hota: none of the result's 284 boxes"):
        evaluate_hota(gt.tolist(), res.tolist())
