"""One-line refusals that name the function the caller called and the argument it gave.

Stop 63's leftovers (docs/results.md, "Leftovers of stop 63"): ``track_frames`` named
``prime``, the ``evaluate_*`` functions named their argument but not themselves, and the
``bhattacharyya_*`` functions given a NaN as `hists` blamed `ref`'s size.
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack import bhattacharyya_coefficient, bhattacharyya_distance, bhattacharyya_weights
from pftrack.eval import evaluate_hota, evaluate_mot, evaluate_sequence
from pftrack.tracking import track_frames

GT = np.array([[1, 1, 10, 10, 20, 40, 1, 1, 1, 1.0]])


@pytest.mark.parametrize("dets", [None, {1: np.array([[10.0, 10.0, 20.0, 40.0, 0.9]])}])
@pytest.mark.parametrize(
    ("frames", "error", "said"),
    [
        (np.zeros((3, 24, 32, 3)), TypeError, "source frame dtype is float64, expected uint8"),
        ([np.zeros((24, 32, 3), np.int32)] * 3, TypeError, "source frame dtype is int32"),
        (np.zeros((3, 24, 32), np.uint8), ValueError, r"source frame must have shape \(H, W, 3\)"),
    ],
)
def test_track_frames_names_itself_and_its_source_not_prime(frames, error, said, dets):
    # was "prime frame dtype is float64, expected uint8": the caller gave track_frames a
    # source, and called no prime
    with pytest.raises(error, match=f"^track_frames: {said}") as e:
        track_frames(frames, detections=dets, show_progress=False)
    assert "prime" not in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("fn", [evaluate_hota, evaluate_mot, evaluate_sequence])
@pytest.mark.parametrize(
    ("gt", "result", "said"),
    [
        (np.full((1, 10), "a"), GT, "gt must hold real numbers, got dtype <U1"),
        (GT, GT.astype(complex), "result must hold real numbers, got dtype complex128"),
        (np.zeros((1, 3)), GT, r"gt has shape \(1, 3\), expected \(M, 6..10\) MOT rows"),
        (GT, "res.txt", r"result is a path \('res.txt'\); read it with pftrack.read_mot\(path\)"),
    ],
)
def test_each_evaluate_function_names_itself_and_the_argument(fn, gt, result, said):
    # evaluate_hota and evaluate_sequence said "ground truth must hold real numbers": the
    # argument, in words, but not the function (evaluate_mot's words are the model)
    with pytest.raises((TypeError, ValueError), match=rf"^{fn.__name__}: {said}$"):
        fn(gt, result)


def test_evaluate_functions_score_as_before_once_checked():
    # the rows checked up front are the rows scored: a 6-column result pads as read_mot pads
    res = GT[:, :6] + [0, 0, 1, 0, 0, 0]
    s = evaluate_sequence(GT, res)
    assert s.hota.hota == evaluate_hota(GT, res).hota
    assert s.mot.mota == evaluate_mot(GT, res).mota == 1.0


@pytest.mark.parametrize("fn", [bhattacharyya_coefficient, bhattacharyya_distance,
                                bhattacharyya_weights])  # fmt: skip
@pytest.mark.parametrize("hists", [np.nan, float("inf"), np.float32(np.nan), 3.0])
def test_bhattacharyya_given_a_number_for_hists_names_hists(fn, hists):
    # was "ref size is 3, expected 1": the number taken for one 1-bin histogram, and ref,
    # which was right, blamed
    with pytest.raises(ValueError, match=rf"^{fn.__name__}: hists is one number \(") as e:
        fn(hists, [1.0, 0.0, 0.0])
    assert "expected (K, 3) histograms" in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("fn", [bhattacharyya_coefficient, bhattacharyya_distance,
                                bhattacharyya_weights])  # fmt: skip
def test_bhattacharyya_rows_of_other_bins_name_both_arguments(fn):
    with pytest.raises(
        ValueError, match=rf"^{fn.__name__}: ref size is 3, expected 1, the length of hists' rows$"
    ):
        fn([np.nan], [1.0, 0.0, 0.0])
    # a right call is untouched: the NumPy reference of the coefficient
    h, r = np.array([[1.0, 1.0, 0.0], [2.0, 0.0, 0.0]]), np.array([1.0, 0.0, 0.0])
    rho = np.sqrt(h / h.sum(1, keepdims=True) * (r / r.sum())).sum(1)
    np.testing.assert_allclose(bhattacharyya_coefficient(h, r), rho, rtol=1e-12)
