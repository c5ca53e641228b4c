"""HOTA against TrackEval 1.3.0 itself, on real sequences and on MOT17-style synthetic files.

TrackEval is installed with ``pip install --no-deps trackeval==1.3.0`` (its metadata pulls in
opencv-python, which would replace opencv-python-headless); its HOTA path needs only NumPy and
SciPy. The README's test command installs it so, and these tests run in CI.
"""

from __future__ import annotations

import contextlib
import io
import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval.hota import (
    ALPHAS,
    combine_hota,
    evaluate_hota,
    guess_benchmark,
    mot_iou,
    prepare_mot,
)
from pftrack.eval.metrics import combine_mot, evaluate_mot
from pftrack.io.mot import read_mot
from tests.conftest import dataset
from tests.eval.cases import perturbed, write_rows

if os.environ.get("CI"):  # the README's test command installs it: CI must run these tests
    import trackeval
else:
    trackeval = pytest.importorskip("trackeval", reason="pip install --no-deps trackeval==1.3.0")

FIELDS = ("HOTA", "DetA", "AssA", "DetRe", "DetPr", "AssRe", "AssPr", "LocA")
OURS = ("hota_alpha", "det_a_alpha", "ass_a", "det_re_alpha", "det_pr_alpha", "ass_re",
        "ass_pr", "loc_a")  # fmt: skip


def trackeval_hota(
    tmp: Path,
    seqs: dict[str, tuple[np.ndarray, np.ndarray]],
    benchmark: str,
    metrics: tuple[str, ...] = ("HOTA",),
    threshold: float = 0.5,
):
    """TrackEval's `metrics` per sequence and combined, through its MotChallenge2DBox dataset.

    Each sequence's (and ``"COMBINED"``'s) entry holds every metric's fields in one dict
    (their names do not collide: ``HOTA``, ``MOTA``, ``CLR_FP``, ``IDF1``, ...). CLEAR and
    Identity match at IoU `threshold`.
    """
    gt_root, tr_root = tmp / "gt", tmp / "trackers"
    lengths = {}
    for name, (gt, res) in seqs.items():
        n = int(max(gt[:, 0].max(initial=1), res[:, 0].max(initial=1)))
        lengths[name] = n
        write_rows(gt_root / name / "gt" / "gt.txt", gt)
        (gt_root / name / "seqinfo.ini").write_text(f"[Sequence]\nname={name}\nseqLength={n}\n")
        write_rows(tr_root / "t" / "data" / f"{name}.txt", res)
    config = {
        "GT_FOLDER": str(gt_root),
        "TRACKERS_FOLDER": str(tr_root),
        "BENCHMARK": benchmark,
        "SKIP_SPLIT_FOL": True,
        "SEQ_INFO": lengths,
        "TRACKERS_TO_EVAL": ["t"],
        "PRINT_CONFIG": False,
    }
    with contextlib.redirect_stdout(io.StringIO()):
        data = trackeval.datasets.MotChallenge2DBox(config)
        at = {"THRESHOLD": threshold, "PRINT_CONFIG": False}
        scorers = [
            getattr(trackeval.metrics, m)(at if m in ("CLEAR", "Identity") else None)
            for m in metrics
        ]
        per: dict[str, dict[str, dict]] = {m: {} for m in metrics}
        for name in seqs:
            raw = data.get_raw_seq_data("t", name)
            pre = data.get_preprocessed_seq_data(raw, "pedestrian")
            for m, scorer in zip(metrics, scorers, strict=True):
                per[m][name] = scorer.eval_sequence(pre)
        out: dict[str, dict] = {name: {} for name in [*seqs, "COMBINED"]}
        for m, scorer in zip(metrics, scorers, strict=True):
            for name in seqs:
                out[name].update(per[m][name])
            out["COMBINED"].update(scorer.combine_sequences(per[m]))
    return out


def assert_same(ours, ref) -> None:
    for field, attr in zip(FIELDS, OURS, strict=True):
        got = getattr(ours, attr)
        np.testing.assert_allclose(got, ref[field], rtol=0, atol=1e-9, err_msg=field)
    np.testing.assert_array_equal(ours.tp, ref["HOTA_TP"])
    np.testing.assert_array_equal(ours.fn, ref["HOTA_FN"])
    np.testing.assert_array_equal(ours.fp, ref["HOTA_FP"])
    assert abs(ours.hota - float(np.mean(ref["HOTA"]))) < 1e-9


def det_as_tracker(det: np.ndarray, seed: int) -> np.ndarray:
    """Public detections as a "tracker": ids chained frame to frame by best IoU >= 0.3."""
    rng = np.random.default_rng(seed)
    out = det.copy()
    next_id, prev = 1, None
    for f in np.unique(det[:, 0]):
        idx = np.flatnonzero(det[:, 0] == f)
        ids = np.zeros(len(idx))
        taken: set[float] = set()
        for k, i in enumerate(idx):
            if prev is not None and len(prev):
                iou = mot_iou(det[i : i + 1, 2:6], prev[:, 2:6])[0]
                j = int(np.argmax(iou))
                if iou[j] >= 0.3 and prev[j, 1] not in taken and rng.random() > 0.05:
                    ids[k] = prev[j, 1]
                    taken.add(ids[k])
                    continue
            ids[k] = next_id
            next_id += 1
        out[idx, 1] = ids
        prev = out[idx]
    return out


def real_cases() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    cases = {}
    for name in ("pets09-s2l1", "tud-campus", "mot15-gt/ADL-Rundle-6", "mot15-gt/ETH-Sunnyday",
                 "mot15-gt/KITTI-17"):  # fmt: skip
        folder = dataset(name)
        gt = read_mot(folder / "gt.txt")
        det = read_mot(folder / "det.txt")
        cases[name.split("/")[-1]] = (gt, det_as_tracker(det, seed=len(cases)))
    return cases


@pytest.mark.dataset
def test_equals_trackeval_on_real_sequences(tmp_path: Path) -> None:
    cases = real_cases()
    ref = trackeval_hota(tmp_path, cases, "MOT15")
    ours = {}
    for name in cases:
        # Both read the files TrackEval read, so both see the same numbers.
        g = read_mot(tmp_path / "gt" / name / "gt" / "gt.txt")
        r = read_mot(tmp_path / "trackers" / "t" / "data" / f"{name}.txt")
        ours[name] = evaluate_hota(g, r, benchmark=guess_benchmark(g))
        assert 0.1 < ours[name].hota < 0.9, name  # a real, non-degenerate case
        assert_same(ours[name], ref[name])
    assert_same(combine_hota(ours.values()), ref["COMBINED"])


@pytest.mark.dataset
def test_equals_trackeval_with_scale_and_perturbed_truth(tmp_path: Path) -> None:
    # PETS: results on the 480x360 video, gt in 768x576; TrackEval gets the gt scaled in a file.
    gt = read_mot(dataset("pets09-s2l1") / "gt.txt")
    res = perturbed(gt, 0)
    res[:, 2:6] *= 0.625
    scaled = gt.copy()
    scaled[:, 2:6] *= 0.625
    ref = trackeval_hota(tmp_path, {"pets": (scaled, res)}, "MOT15")
    r = read_mot(tmp_path / "trackers" / "t" / "data" / "pets.txt")
    ours = evaluate_hota(gt, r, scale=0.625)
    np.testing.assert_allclose(ours.hota_alpha, ref["pets"]["HOTA"], rtol=0, atol=1e-9)
    assert ours.hota > 0.4


#: TrackEval's CLEAR and Identity fields -> MotMetrics' (TrackEval's MOTP is the mean IoU of the
#: matches, as motp_iou).
CLEAR_FIELDS = {
    "MOTA": "mota", "MOTP": "motp_iou", "IDF1": "idf1", "IDP": "idp", "IDR": "idr",
    "CLR_FP": "false_positives", "CLR_FN": "misses", "IDSW": "num_switches",
    "CLR_TP": "num_matches", "MT": "mostly_tracked", "PT": "partially_tracked",
    "ML": "mostly_lost", "Frag": "num_fragmentations", "IDTP": "idtp", "IDFP": "idfp",
    "IDFN": "idfn",
}  # fmt: skip


def assert_same_clear(ours, ref) -> None:
    """CLEAR-MOT and IDF1 as TrackEval computes them, to the last bit.

    (Was to 1e-12: MOTA as 1 - (FN + FP + IDSW) / GT and MOTP summed match by match, or
    recombined from the sequences' means, differed from TrackEval's in the last bits.)
    """
    for field, attr in CLEAR_FIELDS.items():
        assert getattr(ours, attr) == float(ref[field]), field


@pytest.mark.dataset
def test_clear_and_identity_equal_trackeval_on_real_sequences(tmp_path: Path) -> None:
    """One set of scored rows for HOTA and CLEAR: MOTA, IDF1, ... are TrackEval's too.

    PETS09-S2L1 has 174 conf-0 ground-truth rows; under MOT15 rules the result boxes on them
    are false positives (they were once dropped here, which TrackEval does not do).
    """
    cases = real_cases()
    gt = read_mot(dataset("pets09-s2l1") / "gt.txt")
    cases["pets-perturbed"] = (gt, perturbed(gt, 4))
    ref = trackeval_hota(tmp_path, cases, "MOT15", ("HOTA", "CLEAR", "Identity"))
    ours = {}
    for name in cases:
        g = read_mot(tmp_path / "gt" / name / "gt" / "gt.txt")
        r = read_mot(tmp_path / "trackers" / "t" / "data" / f"{name}.txt")
        ours[name] = evaluate_mot(g, r)
        assert 0.1 < ours[name].mota < 0.95 and ours[name].num_switches > 0, name
        assert_same_clear(ours[name], ref[name])
    assert sum(m.num_ignored_gt for m in ours.values()) > 0  # the rule is exercised
    assert_same_clear(combine_mot(list(ours.values())), ref["COMBINED"])


@pytest.mark.parametrize("bench_name", ["MOT17", "MOT20"])
@pytest.mark.parametrize("seed", range(3))
def test_clear_and_identity_equal_trackeval_mot17(
    tmp_path: Path, bench_name: str, seed: int
) -> None:
    gt, res = mot17_case(seed)
    ref = trackeval_hota(tmp_path, {"s": (gt, res)}, bench_name, ("CLEAR", "Identity"))
    g = read_mot(tmp_path / "gt" / "s" / "gt" / "gt.txt")
    r = read_mot(tmp_path / "trackers" / "t" / "data" / "s.txt")
    m = evaluate_mot(g, r, benchmark=bench_name)
    assert m.num_ignored_predictions > 0  # distractor matches were left out
    assert_same_clear(m, ref["s"])


def test_clear_breaks_exact_ties_in_file_order_as_trackeval(tmp_path: Path) -> None:
    """Two result tracks on exactly the same box: the assignment takes the one written first.

    pftrack sorted each frame's rows by id first, so the other track won the tie: IDSW 0 and
    MOTA 0.5 below, where TrackEval (which keeps the file's order) has IDSW 1 and MOTA 0.4.
    """
    box = [100.0, 100.0, 50.0, 100.0, 1.0, -1.0, -1.0, -1.0]
    gt = np.array([[f, 1, *box] for f in range(1, 11)])
    res = np.array([[f, i, *box] for f in range(1, 11) for i in ((7, 5) if f <= 5 else (5,))])
    ref = trackeval_hota(tmp_path / "one", {"s": (gt, res)}, "MOT15", ("CLEAR", "Identity"))
    m = evaluate_mot(gt, res)
    assert (m.num_switches, m.mota) == (1, pytest.approx(0.4))
    assert_same_clear(m, ref["s"])
    # many ties: a random case with a third of its boxes copied under new ids, the copies
    # written first in their frames, or last
    from tests.eval.test_metrics import crowd_case, random_case

    cases = {}
    for seed in range(4):
        g, r = random_case(seed)
        rng = np.random.default_rng(seed)
        copies = r[rng.random(len(r)) < 0.35].copy()
        copies[:, 1] += 5000
        both = np.vstack([copies, r] if seed % 2 else [r, copies])
        cases[f"s{seed}"] = (g, both[np.argsort(both[:, 0], kind="stable")])
        cases[f"crowd{seed}"] = crowd_case(seed)  # overlapping boxes on integer pixels
    ref = trackeval_hota(tmp_path / "many", cases, "MOT15", ("CLEAR", "Identity"))
    for name, (g, r) in cases.items():
        assert_same_clear(evaluate_mot(g, r), ref[name])


def test_clear_and_identity_decide_the_threshold_as_trackeval(tmp_path: Path) -> None:
    """A pair just under the IoU threshold: TrackEval's CLEAR takes it within eps, Identity not.

    pftrack took any pair within 1e-12 of the threshold, in CLEAR and Identity both: a result
    box at IoU 0.5 - 5e-13 scored MOTA 1 and IDF1 1 where TrackEval (and pftrack's own HOTA)
    scores no match, MOTA -1 and IDF1 0.
    """
    eps = np.finfo(float).eps
    gt = np.array([[f, 1, 0, 0, 100, 100, 1, -1, -1, -1] for f in (1, 2)], dtype=float)
    cases = {}
    for name, height in (("below", 50 - 5e-11), ("within_eps", np.nextafter(50.0, 0))):
        res = gt.copy()
        res[:, 5] = height
        cases[name] = (gt, res)
    iou = {name: mot_iou(gt[0, 2:6], res[0, 2:6])[0, 0] for name, (_, res) in cases.items()}
    assert 0.5 - 1e-12 < iou["below"] < 0.5 - eps <= iou["within_eps"] < 0.5
    ref = trackeval_hota(tmp_path, cases, "MOT15", ("CLEAR", "Identity"))
    with pytest.warns(UserWarning, match="^evaluate_mot: none of the result's 2 boxes"):
        below = evaluate_mot(*cases["below"])  # said since stop 71: nothing matched at 0.5
    within = evaluate_mot(*cases["within_eps"])
    assert (below.mota, below.idf1, below.num_matches) == (-1.0, 0.0, 0)
    assert (within.mota, within.idf1, within.num_matches) == (1.0, 0.0, 2)  # CLEAR's eps only
    assert_same_clear(below, ref["below"])
    assert_same_clear(within, ref["within_eps"])
    assert evaluate_hota(*cases["below"]).tp[9] == 0  # HOTA at alpha 0.5: no match either


def mot17_case(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """MOT17-style gt (flag, class, visibility) with distractors and zero-marked rows."""
    rng = np.random.default_rng(seed)
    gt = []
    for oid in range(1, 16):
        start = int(rng.integers(1, 30))
        end = int(rng.integers(start + 5, 61))
        x, y = rng.uniform(0, 300, 2)
        v = rng.normal(0, 3, 2)
        w, h = rng.uniform(20, 40), rng.uniform(50, 90)
        cls = rng.choice([1, 1, 1, 1, 2, 3, 6, 7, 8, 12])
        for f in range(start, end + 1):
            flag = 0 if (cls != 1 or rng.random() < 0.05) else 1
            gt.append([f, oid, x + v[0] * f, y + v[1] * f, w, h, flag, cls, rng.random(), 0])
    g = np.asarray(gt)
    res = perturbed(g, seed + 1)
    return g[:, :9], res


@pytest.mark.parametrize("bench_name", ["MOT17", "MOT20"])
@pytest.mark.parametrize("seed", range(3))
def test_equals_trackeval_mot17_preprocessing(tmp_path: Path, bench_name: str, seed: int) -> None:
    gt, res = mot17_case(seed)
    assert guess_benchmark(np.c_[gt, -np.ones(len(gt))]) == "MOT17"
    ref = trackeval_hota(tmp_path, {"s": (gt, res)}, bench_name)
    g = read_mot(tmp_path / "gt" / "s" / "gt" / "gt.txt")
    r = read_mot(tmp_path / "trackers" / "t" / "data" / "s.txt")
    ours = evaluate_hota(g, r, benchmark=bench_name)
    assert_same(ours, ref["s"])
    # The preprocessing does remove something: distractor matches and non-pedestrian rows.
    kept_g, kept_r = prepare_mot(g, r, benchmark=bench_name)
    assert len(kept_g) < len(g) and len(kept_r) < len(r)


def test_iou_matches_trackeval() -> None:
    rng = np.random.default_rng(1)
    a = np.c_[rng.uniform(0, 50, (9, 2)), rng.uniform(0, 30, (9, 2))]
    b = np.c_[rng.uniform(0, 50, (6, 2)), rng.uniform(0, 30, (6, 2))]
    b[0, 2] = 0.0  # no area: overlaps nothing
    ref = trackeval.datasets._base_dataset._BaseDataset._calculate_box_ious(a, b)
    np.testing.assert_array_equal(mot_iou(a, b), ref)


def test_hand_case() -> None:
    # One object over 4 frames, tracked as id 7 (frames 1-2, exact) then id 8 (frames 3-4, exact).
    gt = np.array([[f, 1, 0, 0, 10, 10] for f in range(1, 5)], dtype=float)
    res = np.array([[f, 7 if f <= 2 else 8, 0, 0, 10, 10] for f in range(1, 5)], dtype=float)
    m = evaluate_hota(gt, res)
    # DetA = 1 at every alpha; each pair has TPA 2, FNA 2, FPA 0: A = 1/2, so AssA = 1/2.
    np.testing.assert_allclose(m.det_a_alpha, 1.0)
    np.testing.assert_allclose(m.ass_a, 0.5)
    assert m.hota == pytest.approx(np.sqrt(0.5))
    assert m.loc_a_mean == pytest.approx(1.0)
    # Half-overlapping boxes (IoU 1/3) count only for alpha <= 1/3.
    half = res.copy()
    half[:, 2] = 5.0
    m = evaluate_hota(gt, half)
    np.testing.assert_array_equal(m.tp, np.where(ALPHAS <= 1 / 3, 4, 0))


def test_empty_inputs_and_errors() -> None:
    gt = np.array([[1, 1, 0, 0, 10, 10]], dtype=float)
    m = evaluate_hota(gt, np.zeros((0, 10)))
    assert m.hota == 0.0 and np.all(m.fn == 1) and np.all(m.loc_a == 1)
    m = evaluate_hota(np.zeros((0, 10)), gt)
    assert m.hota == 0.0 and np.all(m.fp == 1)
    with pytest.warns(UserWarning, match="no frame of it is a frame of the ground truth"):
        apart = evaluate_hota(gt, gt + [1, 0, 0, 0, 0, 0])  # no common frame (said: stop 71)
    assert apart.hota == 0.0 and np.all(apart.fn == 1) and np.all(apart.fp == 1)
    with pytest.warns(UserWarning, match="^evaluate_hota: none of the result's 1 box "):
        far = evaluate_hota(gt, gt + [0, 0, 50, 0, 0, 0])  # a common frame, no overlap
    assert far.hota == 0.0 and np.all(far.tp == 0)
    with pytest.raises(ValueError, match="more than once in frame 1"):
        evaluate_hota(np.vstack([gt, gt]), gt)
    with pytest.raises(ValueError, match="beyond the sequence"):
        evaluate_hota(gt, gt + [5, 0, 0, 0, 0, 0], num_frames=3)
    with pytest.raises(ValueError, match="benchmark"):
        evaluate_hota(gt, gt, benchmark="MOT99")
    with pytest.raises(ValueError, match="expected 1-13"):
        evaluate_hota(np.c_[gt, [[1, -3.5, 0.5, 0]]], gt, benchmark="MOT17")
    with pytest.raises(ValueError, match="no sequences"):
        combine_hota([])


@pytest.mark.dataset
def test_cli_prints_hota(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = dataset("tud-campus")
    res = write_rows(tmp_path / "res.txt", perturbed(read_mot(folder / "gt.txt"), 3))
    assert main(["eval", "--gt", str(folder / "gt.txt"), "--res", str(res)]) == 0
    text = capsys.readouterr().out
    expected = evaluate_hota(read_mot(folder / "gt.txt"), read_mot(res)).hota
    assert "HOTA" in text and f"{100 * expected:.1f}" in text


@pytest.mark.dataset
@pytest.mark.slow
def test_equals_trackeval_on_pftrack_track_output(tmp_path: Path) -> None:
    """A real tracker's output: `pftrack track` on TUD-Campus with its public detections."""
    folder = dataset("tud-campus")
    out = tmp_path / "tracks.txt"
    argv = ["track", str(folder / "video.mp4"), "--detections", str(folder / "det.txt")]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main([*argv, "--out", str(out)]) == 0
    gt, res = read_mot(folder / "gt.txt"), read_mot(out)
    ref = trackeval_hota(tmp_path / "te", {"tud": (gt, res)}, "MOT15")
    g = read_mot(tmp_path / "te" / "gt" / "tud" / "gt" / "gt.txt")
    r = read_mot(tmp_path / "te" / "trackers" / "t" / "data" / "tud.txt")
    ours = evaluate_hota(g, r)
    assert_same(ours, ref["tud"])
    assert ours.hota > 0.4


def test_num_frames_and_scale_of_the_wrong_kind_are_named() -> None:
    """num_frames=-1 said 'beyond the sequence's -1 frames'; scale='2' was Python's message."""
    g = np.array([[1, 1, 10, 10, 5, 5, 1, -1, -1, -1.0]])
    for bad in (-1, 0):
        with pytest.raises(ValueError, match=r"num_frames is .*, expected an integer in \[1, "):
            evaluate_hota(g, g, num_frames=bad)
    for wrong in (2.5, True):  # a wrong type: TypeError (was ValueError), as scale's
        with pytest.raises(TypeError, match=r"num_frames must be an integer in \[1, .*, got "):
            evaluate_hota(g, g, num_frames=wrong)
    with pytest.raises(TypeError, match="scale must be a number, got str '2'"):
        evaluate_hota(g, g, scale="2")
    assert evaluate_hota(g, g, num_frames=1).hota == pytest.approx(1.0)


def _empty_cases() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    gt = np.array([[1, 1, 0, 0, 10, 10], [2, 1, 1, 0, 10, 10], [2, 2, 40, 0, 10, 10]], float)
    gt = np.c_[gt, np.tile([1.0, -1, -1, -1], (len(gt), 1))]
    res = gt + [0, 4, 1, 0, 0, 0, 0, 0, 0, 0]
    none = np.zeros((0, 10))
    return {
        "no_gt": (none, res),
        "no_res": (gt, none),
        "neither": (none, none),
        "apart": (gt, res + [0, 0, 100, 0, 0, 0, 0, 0, 0, 0]),  # common frames, no overlap
    }


@pytest.mark.parametrize(
    "names", [("no_gt", "no_res", "neither", "apart"), ("no_gt",), ("neither",), ("apart",)]
)
def test_empty_ground_truth_and_results_equal_trackeval(
    tmp_path: Path, names: tuple[str, ...]
) -> None:
    # MOTA was NaN without ground truth (TrackEval: 0), MOTP, IDP, IDR NaN (TrackEval: 0)
    from pftrack.eval import evaluate_sequence
    from pftrack.eval.sequences import SequenceScores

    cases = {k: v for k, v in _empty_cases().items() if k in names}
    ref = trackeval_hota(tmp_path, cases, "MOT15", ("HOTA", "CLEAR", "Identity"))
    parts = []
    for name, (gt, res) in cases.items():
        # results on the truth's frames that overlap none of its boxes: scored, and said
        said = (
            pytest.warns(UserWarning, match="none of the result's")
            if name == "apart"
            else contextlib.nullcontext()
        )
        with said:
            s = evaluate_sequence(gt, res, benchmark="MOT15")
        assert_same_clear(s.mot, ref[name])
        assert_same(s.hota, ref[name])
        for field in ("MOTA", "MOTP", "IDF1", "IDP", "IDR", "CLR_Pr", "CLR_Re"):
            assert np.isfinite(ref[name][field]), field
        assert s.mot.precision == ref[name]["CLR_Pr"] and s.mot.recall == ref[name]["CLR_Re"]
        parts.append(s)
    both = SequenceScores.combine(parts)
    assert_same_clear(both.mot, ref["COMBINED"])
    assert_same(both.hota, ref["COMBINED"])
    assert both.mot.precision == pytest.approx(float(ref["COMBINED"]["CLR_Pr"]), abs=1e-12)
    assert both.mot.recall == pytest.approx(float(ref["COMBINED"]["CLR_Re"]), abs=1e-12)


#: Count's fields -> MotMetrics'.
COUNT_FIELDS = {"GT_Dets": "num_objects", "Dets": "num_predictions", "GT_IDs": "num_unique_objects"}


@pytest.mark.parametrize("seed", range(8))
def test_every_figure_equals_trackeval_on_random_edge_cases(tmp_path: Path, seed: int) -> None:
    """HOTA, CLEAR, Identity and the counts equal TrackEval's, per sequence and combined.

    On :func:`tests.eval.cases.edge_case`'s sequences (ids back after a gap, zero-size boxes,
    exact ties, flags 0 and 0.3, distractors, results past the truth's last frame, no truth
    or no result), 1-5 sequences of one benchmark per case, at IoU 0.5 and others: 10 cases
    here (1,000 more, seeds 100-199, agreed when it was written, 5 December).
    """
    from pftrack.eval import evaluate_sequence
    from pftrack.eval.sequences import NONE_MATCHED, SequenceScores
    from tests.eval.cases import edge_case

    seen = np.zeros(3, dtype=int)  # the cases do exercise switches, ignored rows, ties
    for k in range(10):
        rng = np.random.default_rng([seed, k])
        bench = str(rng.choice(["MOT15", "MOT15", "MOT17", "MOT20"]))
        thr = float(rng.choice([0.5, 0.5, 0.3, 0.75, 1.0]))
        cases = {f"s{j}": edge_case(rng, bench) for j in range(int(rng.integers(1, 6)))}
        metrics = ("HOTA", "CLEAR", "Identity", "Count")
        ref = trackeval_hota(tmp_path / f"{k}", cases, bench, metrics, threshold=thr)
        parts = []
        for name in cases:
            g = read_mot(tmp_path / f"{k}" / "gt" / name / "gt" / "gt.txt")
            r = read_mot(tmp_path / f"{k}" / "trackers" / "t" / "data" / f"{name}.txt")
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always")
                parts.append(evaluate_sequence(g, r, benchmark=bench, iou_threshold=thr))
            # said exactly when some result box exists and none matched (TrackEval's counts)
            m = parts[-1].mot
            silent = not len(r) or not m.num_objects or m.num_matches > 0
            assert [str(w.message).startswith(NONE_MATCHED) for w in said] == (
                [] if silent else [True]
            ), name
            frames = np.c_[g[:, 0], g[:, 2:6]]
            seen += [
                parts[-1].mot.num_switches > 0,
                parts[-1].mot.num_ignored_gt > 0,
                len(np.unique(frames, axis=0)) < len(frames),
            ]
        scores = [*zip(cases, parts, strict=True), ("COMBINED", SequenceScores.combine(parts))]
        for name, s in scores:
            assert_same(s.hota, ref[name])
            assert_same_clear(s.mot, ref[name])
            assert (s.mot.precision, s.mot.recall) == (ref[name]["CLR_Pr"], ref[name]["CLR_Re"])
            for field, attr in COUNT_FIELDS.items():
                assert getattr(s.mot, attr) == ref[name][field], (name, field)
    assert np.all(seen > 0), seen
