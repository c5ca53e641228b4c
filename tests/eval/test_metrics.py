from __future__ import annotations

import dataclasses
import json
import math
import warnings

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval import MotMetrics, evaluate_mot, format_metrics, iou_xywh
from pftrack.io.mot import read_mot, write_mot
from tests.reference import boxes as ref_boxes


def rows(*items):
    """(frame, id, left, top, w, h[, conf]) tuples -> (M, 10) array."""
    out = []
    for it in items:
        r = list(it) + [1.0] * (7 - len(it)) + [-1.0, -1.0, -1.0]
        out.append(r[:10])
    return np.asarray(out, dtype=np.float64).reshape(-1, 10)


def test_iou_matches_loop():
    rng = np.random.default_rng(3)
    a = np.c_[rng.uniform(0, 50, (7, 2)), rng.uniform(0, 30, (7, 2))]
    b = np.c_[rng.uniform(0, 50, (5, 2)), rng.uniform(0, 30, (5, 2))]
    np.testing.assert_allclose(iou_xywh(a, b), ref_boxes.iou_xywh(a, b), atol=1e-12)
    assert iou_xywh(np.zeros((0, 4)), b).shape == (0, 5)


# Hand-made case: three ground-truth objects over 5 frames, 10x10 boxes.
#   A (gt 1) frames 1-5 at (0,0); B (gt 2) frames 1-4 at (100,0); C (gt 3) frames 1-5 at (200,0).
#   result 10 on A at frames 1, 2 (frame 2 shifted by 3 px in x: IoU 70/130);
#   A has no result box at frame 3;
#   result 11 on A at frames 4, 5 (frame 5 shifted by 2 px in y: IoU 80/120);
#   result 20 on B at frame 1 only; C is never tracked; result 30 is a false positive at frame 2.
HAND_GT = rows(
    *[(f, 1, 0, 0, 10, 10) for f in range(1, 6)],
    *[(f, 2, 100, 0, 10, 10) for f in range(1, 5)],
    *[(f, 3, 200, 0, 10, 10) for f in range(1, 6)],
)
HAND_RES = rows(
    (1, 10, 0, 0, 10, 10),
    (2, 10, 3, 0, 10, 10),
    (4, 11, 0, 0, 10, 10),
    (5, 11, 0, 2, 10, 10),
    (1, 20, 100, 0, 10, 10),
    (2, 30, 300, 300, 10, 10),
)


def test_hand_computed_case():
    m = evaluate_mot(HAND_GT, HAND_RES, image_size=(400, 300))
    # gt boxes: 5 + 4 + 5 = 14; matches: A at 1, 2, 4, 5 and B at 1 -> 5.
    assert m.num_objects == 14 and m.num_predictions == 6 and m.num_matches == 5
    # FN = 14 - 5 = 9; FP = result 30 -> 1; IDSW = A goes 10 -> 11 at frame 4 -> 1.
    assert (m.misses, m.false_positives, m.num_switches) == (9, 1, 1)
    # MOTA = 1 - (9 + 1 + 1) / 14 = 3/14.
    assert m.mota == pytest.approx(3 / 14)
    # MOTP (mean IoU of matches) = (1 + 70/130 + 1 + 80/120 + 1) / 5.
    assert m.motp_iou == pytest.approx((3 + 70 / 130 + 80 / 120) / 5)
    # Frag (TrackEval's: tracked runs after the first, a run going on from the last frame that
    # had ground truth and results both): A is T T F T T, but frame 3 has no result box, so
    # A's match at frame 4 goes on from frame 2 -> 0; B is T F F F -> 0; C never tracked -> 0.
    assert m.num_fragmentations == 0
    # Track ratios: A 4/5 = 0.8 -> PT (mostly tracked is above 80 %, as TrackEval counts);
    # B 1/4 = 0.25 -> PT; C 0 -> ML.
    assert (m.mostly_tracked, m.partially_tracked, m.mostly_lost) == (0, 2, 1)
    # Identity: pair overlaps (1,10)=2, (1,11)=2, (2,20)=1 -> best one-to-one IDTP = 2 + 1 = 3;
    # IDFP = 6 - 3 = 3; IDFN = 14 - 3 = 11; IDF1 = 2*3 / (2*3 + 3 + 11) = 6/20.
    assert (m.idtp, m.idfp, m.idfn) == (3, 3, 11)
    assert m.idf1 == pytest.approx(0.3)
    assert m.idp == pytest.approx(0.5) and m.idr == pytest.approx(3 / 14)
    assert m.precision == pytest.approx(5 / 6) and m.recall == pytest.approx(5 / 14)
    # Smith: A's assigned track overlaps it in 2 of 5 frames (10 and 11 tie in frames and in
    # matches; 11, 2 px off in all, is nearer than 10, 3 px), B 1 of 4, C 0 -> mean
    # (0.4 + 0.25 + 0) / 3; same for the strict variant here.
    assert m.success_per_object == ((1, 0.4, 0.4), (2, 0.25, 0.25), (3, 0.0, 0.0))
    assert m.success_rate == pytest.approx(0.65 / 3)
    assert m.success_rate_strict == pytest.approx(0.65 / 3)
    # Centroid distances: A-11 at frames 4, 5 -> 0, 2 px; B-20 at frame 1 -> 0 -> mean 2/3 px.
    assert m.centroid_distance_px == pytest.approx(2 / 3)
    assert m.centroid_distance_ratio == pytest.approx(2 / 3 / (400 * 300))
    assert m.num_unique_objects == 3 and m.num_frames == 5


def test_previous_correspondence_kept_over_better_match():
    gt = rows((1, 1, 0, 0, 10, 10), (2, 1, 0, 0, 10, 10))
    # Frame 2: result 5 still overlaps with IoU 70/130 >= 0.5, result 6 overlaps perfectly.
    res = rows((1, 5, 0, 0, 10, 10), (2, 5, 3, 0, 10, 10), (2, 6, 0, 0, 10, 10))
    m = evaluate_mot(gt, res)
    assert m.num_switches == 0 and m.false_positives == 1 and m.num_matches == 2


def test_switch_counted_across_gap():
    gt = rows((1, 1, 0, 0, 10, 10), (2, 1, 0, 0, 10, 10), (3, 1, 0, 0, 10, 10))
    res = rows((1, 5, 0, 0, 10, 10), (3, 6, 0, 0, 10, 10))
    m = evaluate_mot(gt, res)
    # frame 2 has no result box: frame 3 goes on from frame 1, no fragmentation (TrackEval)
    assert m.num_switches == 1 and m.num_fragmentations == 0 and m.misses == 1
    # with a stray box in frame 2 the object's run is broken there: one fragmentation
    stray = np.vstack([res, rows((2, 9, 200, 200, 10, 10))])
    m = evaluate_mot(gt, stray)
    assert m.num_switches == 1 and m.num_fragmentations == 1 and m.false_positives == 1


def test_a_match_goes_on_only_from_the_last_frame_with_ground_truth_and_results():
    # TrackEval keeps a pair over a better one only if it was matched at the last such frame;
    # py-motmetrics keeps it after any gap. Frame 2: object 1 is not there, result 5 is.
    gt = rows((1, 1, 0, 0, 10, 10), (2, 2, 100, 100, 10, 10), (3, 1, 0, 0, 10, 10))
    res = rows((1, 5, 0, 0, 10, 10), (2, 5, 100, 100, 10, 10), (3, 5, 3, 0, 10, 10),
               (3, 6, 0, 0, 10, 10))  # fmt: skip
    m = evaluate_mot(gt, res)
    # frame 3: 5 (IoU 70/130) no longer goes on from frame 2 (it was matched to object 2
    # there): the better 6 takes object 1, a switch
    assert (m.num_switches, m.num_matches, m.false_positives) == (1, 3, 1)


def test_ignored_ground_truth_and_scale():
    # gt in a 2x larger frame: scale 0.5 maps it onto the result's coordinates.
    gt = rows((1, 1, 0, 0, 20, 20), (1, 2, 100, 100, 20, 20, 0))
    res = rows((1, 7, 0, 0, 10, 10), (1, 8, 50, 50, 10, 10), (1, 9, 150, 150, 10, 10))
    m = evaluate_mot(gt, res, scale=0.5)
    # MOT15 rules (TrackEval's): the conf-0 box is not scored, and result 8 on it stays, an FP
    # as result 9 is
    assert m.num_ignored_gt == 1 and m.num_ignored_predictions == 0
    assert (m.num_objects, m.num_predictions, m.num_matches, m.false_positives) == (1, 3, 1, 2)
    assert m.mota == pytest.approx(-1.0)
    with pytest.warns(UserWarning, match="^evaluate_mot: none of the result's 3 boxes"):
        unscaled = evaluate_mot(gt, res)  # said since stop 71: nothing matched
    assert unscaled.num_matches == 0


def test_mot17_distractors_drop_the_result_boxes_on_them():
    # frame, id, box, conf, class, visibility: 1 a pedestrian, 2 a static person (class 7,
    # a distractor, conf 0), 3 a car (class 3, conf 0)
    gt = np.array([[1, 1, 0, 0, 20, 40, 1, 1, 1.0, -1], [1, 2, 100, 0, 20, 40, 0, 7, 1.0, -1],
                   [1, 3, 200, 0, 40, 20, 0, 3, 1.0, -1]])  # fmt: skip
    res = rows((1, 7, 0, 0, 20, 40), (1, 8, 100, 0, 20, 40), (1, 9, 200, 0, 40, 20))
    m = evaluate_mot(gt, res)  # guessed: MOT17
    # result 8 on the distractor is left out; result 9 on the car is a false positive
    assert (m.num_ignored_gt, m.num_ignored_predictions) == (2, 1)
    assert (m.num_objects, m.num_predictions, m.num_matches, m.false_positives) == (1, 2, 1, 1)
    m15 = evaluate_mot(gt, res, benchmark="MOT15")  # no classes: both are false positives
    assert (m15.num_ignored_predictions, m15.false_positives) == (0, 2)
    with pytest.raises(ValueError, match="evaluate_mot: benchmark is 'MOT18'"):
        evaluate_mot(gt, res, benchmark="MOT18")


def test_bad_input():
    with pytest.raises(ValueError, match="iou_threshold"):
        evaluate_mot(HAND_GT, HAND_RES, iou_threshold=0)
    with pytest.raises(ValueError, match="scale"):
        evaluate_mot(HAND_GT, HAND_RES, scale=-1)
    with pytest.raises(ValueError, match="gt has shape"):
        evaluate_mot(np.zeros((3, 4)), HAND_RES)
    with pytest.raises(ValueError, match="image_size"):
        evaluate_mot(HAND_GT, HAND_RES, image_size=(0, 10))


def test_a_path_is_refused_with_the_reader_to_use(tmp_path):
    """Was ``evaluate_mot: gt must hold real numbers, got dtype <U36``."""
    from pathlib import Path

    from pftrack.eval import evaluate_hota, evaluate_sequence

    for gt, res, bad, path in (
        ("gt.txt", HAND_RES, "gt", "gt.txt"),
        (HAND_GT, Path("res.txt"), "result", "res.txt"),
    ):
        with pytest.raises(
            TypeError,
            match=rf"^evaluate_mot: {bad} is a path \('{path}'\); read it with "
            r"pftrack\.read_mot\(path\)$",
        ):
            evaluate_mot(gt, res)  # type: ignore[arg-type]
        for fn in (evaluate_hota, evaluate_sequence):
            with pytest.raises(TypeError, match=rf"is a path \('{path}'\); read it with pftrack"):
                fn(gt, res)  # type: ignore[arg-type]


def test_a_detections_file_scored_as_tracks_is_named():
    det = HAND_RES.copy()
    det[:, 1] = -1
    with pytest.raises(
        ValueError, match="id -1 more than once in frame 1: is it a detections file"
    ):
        evaluate_mot(HAND_GT, det)


def test_cli_names_the_file_a_scoring_error_is_about(tmp_path, capsys):
    """`--gt det.txt --res gt.txt` said "gt: ground truth has id -1 ...": the result's stem."""
    det = HAND_RES.copy()
    det[:, 1] = -1
    write_mot(tmp_path / "det.txt", det)
    write_mot(tmp_path / "gt.txt", HAND_GT)
    argv = ["eval", "--gt", str(tmp_path / "det.txt"), "--res", str(tmp_path / "gt.txt")]
    assert main(argv) == 2
    assert capsys.readouterr().err.startswith(
        f"pftrack eval: error: {tmp_path / 'det.txt'}: ground truth has id -1 more than once in "
        "frame 1: is it a detections file"
    )


def test_rows_read_mot_refuses_are_refused_by_the_array_api_too():
    # negative sizes scored MOTA -1 and frames from 0 scored 0.955, silently (the CLI refused)
    from pftrack.eval import evaluate_hota, evaluate_sequence

    flipped = HAND_RES.copy()
    flipped[2, 4] *= -1
    early = HAND_RES - [1, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    for fn in (evaluate_mot, evaluate_hota, evaluate_sequence):
        with pytest.raises(ValueError, match="result row 2 has a negative box width or height"):
            fn(HAND_GT, flipped)
        with pytest.raises(
            ValueError, match=r"frame 0, expected >= 1 \(MOTChallenge frames count from 1"
        ):
            fn(HAND_GT, early)
        with pytest.raises(
            ValueError, match="gt row 0 has a negative box|ground truth row 0 has a negative box"
        ):
            fn(flipped[2:], HAND_RES)


def test_fractional_ids_and_frames_are_refused_not_truncated(tmp_path, capsys):
    """Ids 1.5 and 1.7 were cast to 1: 'result has id 1 more than once in frame 1'."""
    from pftrack.eval import evaluate_hota

    res = HAND_RES.copy()
    res[res[:, 1] == res[0, 1], 1] += 0.5
    for evaluate in (evaluate_mot, evaluate_hota):
        with pytest.raises(ValueError, match=r"result row 0: track id [\d.]+ is not an integer"):
            evaluate(HAND_GT, res)
        with pytest.raises(ValueError, match=r"(gt|truth) row \d+ has frame 2.5, expected an"):
            evaluate(np.vstack([HAND_GT, [2.5, 9, 0, 0, 5, 5, 1, -1, -1, -1]]), HAND_RES)
        # was "has frame 2, expected an integer": :g's 6 digits hid what is wrong
        with pytest.raises(ValueError, match=r"(gt|truth) row \d+ has frame 2\.0000000001, expe"):
            evaluate(np.vstack([HAND_GT, [2 + 1e-10, 9, 0, 0, 5, 5, 1, -1, -1, -1]]), HAND_RES)
    lines = "1,1.5,10,10,5,5,1,-1,-1,-1\n1,1.7,30,10,5,5,1,-1,-1,-1\n"
    (tmp_path / "frac.txt").write_text(lines)
    write_mot(tmp_path / "gt.txt", HAND_GT)
    for gt, res_file in (("frac.txt", "gt.txt"), ("gt.txt", "frac.txt")):
        argv = ["eval", "--gt", str(tmp_path / gt), "--res", str(tmp_path / res_file)]
        assert main([*argv, "--no-scale-check"]) == 2
        assert capsys.readouterr().err == (  # as pftrack recover says it
            f"pftrack eval: error: {tmp_path / 'frac.txt'}:1: track id 1.5 is not an integer "
            "with |id| <= 2147483647: '1,1.5,10,10,5,5,1,-1,-1,-1'\n"
        )


def test_empty_result_and_format():
    m = evaluate_mot(HAND_GT, np.zeros((0, 10)))
    assert m.mota == 0.0 and m.misses == 14 and m.mostly_lost == 3
    assert m.motp_iou == 0.0 and m.idf1 == 0.0  # TrackEval's 0 over no match, not NaN
    text = format_metrics({"a": m, "b": evaluate_mot(HAND_GT, HAND_RES)})
    assert "MOTA" in text and "IDF1" in text and text.count("\n") == 3
    assert math.isnan(m.centroid_distance_px)
    assert json.loads(m.to_json())["centroid_distance_px"] is None
    with pytest.raises(dataclasses_error()):
        m.mota = 1.0  # type: ignore[misc]


def dataclasses_error():
    import dataclasses

    return dataclasses.FrozenInstanceError


def test_cli_eval(tmp_path, capsys):
    write_mot(tmp_path / "gt.txt", HAND_GT)
    write_mot(tmp_path / "res.txt", HAND_RES)
    out = tmp_path / "m.json"
    code = main(
        [
            "eval",
            "--gt",
            str(tmp_path / "gt.txt"),
            "--res",
            str(tmp_path / "res.txt"),
            "--json",
            str(out),
        ]
    )
    assert code == 0
    assert "21.4" in capsys.readouterr().out  # MOTA 3/14 in percent
    assert json.loads(out.read_text())["num_switches"] == 1
    assert main(["eval", "--gt", str(tmp_path / "nope.txt"), "--res", str(out)]) == 2
    capsys.readouterr()
    # a results folder against one ground-truth file: named as such, not "not found"
    assert main(["eval", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"pftrack eval: error: --res {tmp_path} is a folder but --gt")
    assert "\n" not in err


# ---- agreement with py-motmetrics on random cases -------------------------------------------


def random_case(seed):
    """Ground truth of walkers plus a noisy, fragmented, id-swapping result with clutter."""
    rng = np.random.default_rng(seed)
    n_frames = 40
    gt, res = [], []
    next_hid = 100
    for oid in range(1, 8):
        start = int(rng.integers(1, 20))
        end = int(rng.integers(start + 3, n_frames + 1))
        x, y = rng.uniform(0, 120, 2)
        vx, vy = rng.normal(0, 2, 2)
        w, h = rng.uniform(15, 30), rng.uniform(30, 60)
        hid = next_hid
        next_hid += 1
        p_miss = rng.choice([0.05, 0.15, 0.5, 0.9])
        for f in range(start, end + 1):
            if rng.random() < 0.08:  # gt has a hole
                continue
            bx, by = x + vx * (f - start), y + vy * (f - start)
            gt.append((f, oid, bx, by, w, h))
            if rng.random() < 0.06:  # the tracker starts a new id
                hid = next_hid
                next_hid += 1
            if rng.random() < p_miss:  # missed
                continue
            jitter = rng.normal(0, 0.12, 4) * [w, h, w, h]
            res.append((f, hid, bx + jitter[0], by + jitter[1], w + jitter[2], h + jitter[3]))
    for f in range(1, n_frames + 1):  # clutter near the walkers
        for _ in range(int(rng.integers(0, 3))):
            res.append(
                (
                    f,
                    int(rng.integers(100, next_hid + 3)),
                    *rng.uniform(0, 150, 2),
                    rng.uniform(15, 30),
                    rng.uniform(30, 60),
                )
            )
    # Swap two result ids over a stretch, to create identity switches.
    res_a = rows(*res)
    ids = np.unique(res_a[:, 1])
    a, b = rng.choice(ids, 2, replace=False)
    sel = (res_a[:, 0] > 15) & (res_a[:, 0] < 25)
    ia, ib = sel & (res_a[:, 1] == a), sel & (res_a[:, 1] == b)
    res_a[ia, 1], res_a[ib, 1] = b, a
    # Keep ids unique within a frame (clutter may reuse one).
    _, first = np.unique(res_a[:, :2], axis=0, return_index=True)
    return rows(*gt), res_a[np.sort(first)]


def motmetrics_summary(gt, res, thr=0.5):
    mm = pytest.importorskip("motmetrics")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        acc = mm.MOTAccumulator(auto_id=False)
        frames = sorted(set(gt[:, 0].astype(int)) | set(res[:, 0].astype(int)))
        for f in frames:
            g = gt[gt[:, 0] == f]
            r = res[res[:, 0] == f]
            d = 1.0 - ref_boxes.iou_xywh(g[:, 2:6], r[:, 2:6])
            d = np.where(d > 1.0 - thr, np.nan, d)
            acc.update(g[:, 1].astype(int).tolist(), r[:, 1].astype(int).tolist(), d, frameid=f)
        names = [
            "mota",
            "motp",
            "idf1",
            "idp",
            "idr",
            "num_switches",
            "num_fragmentations",
            "mostly_tracked",
            "partially_tracked",
            "mostly_lost",
            "num_false_positives",
            "num_misses",
        ]
        s = mm.metrics.create().compute(acc, metrics=names, name="x")
        return {k: float(s[k].iloc[0]) for k in names}


@pytest.mark.parametrize("seed", range(12))
def test_agrees_with_trackeval(seed, tmp_path):
    """Every CLEAR-MOT and Identity field equals TrackEval's on the same files."""
    from tests.eval.test_hota import assert_same_clear, trackeval_hota  # skips without it

    gt, res = random_case(seed)
    ref = trackeval_hota(tmp_path, {"s": (gt, res)}, "MOT15", ("CLEAR", "Identity"))
    g = read_mot(tmp_path / "gt" / "s" / "gt" / "gt.txt")
    r = read_mot(tmp_path / "trackers" / "t" / "data" / "s.txt")
    m = evaluate_mot(g, r)
    assert m.num_switches > 0 and m.num_fragmentations > 0  # the cases do exercise them
    assert_same_clear(m, ref["s"])


@pytest.mark.parametrize("seed", range(12))
def test_identity_agrees_with_motmetrics(seed):
    """IDF1, IDP and IDR, which py-motmetrics defines as TrackEval does, equal its figures.

    (Its CLEAR-MOT differs from TrackEval's, which pftrack follows: it keeps a match after any
    gap, counts an object mostly tracked from 80 %, and counts fragmentations otherwise: the
    next test.)
    """
    gt, res = random_case(seed)
    ref = motmetrics_summary(gt, res)
    m = evaluate_mot(gt, res)
    assert m.idf1 == pytest.approx(ref["idf1"], abs=1e-12)
    assert m.idp == pytest.approx(ref["idp"], abs=1e-12)
    assert m.idr == pytest.approx(ref["idr"], abs=1e-12)
    assert m.false_positives + m.misses == pytest.approx(
        ref["num_false_positives"] + ref["num_misses"], abs=2 * m.num_switches
    )


def test_a_frame_without_the_object_ends_its_run_as_in_trackeval(tmp_path):
    """Frag: TrackEval ends an object's tracked run at a scored frame without it, py-motmetrics
    does not (docs/eval.md names the four ways its CLEAR-MOT differs; three were named)."""
    from tests.eval.test_hota import assert_same_clear, trackeval_hota  # skips without it

    one, two = [10, 10, 20, 40, 1, -1, -1, -1], [100, 10, 20, 40, 1, -1, -1, -1]
    # object 1 in frames 1-2 and 4-5, matched by result 7 throughout; object 2 (result 8) in 3
    gt = rows(*[(f, 1, *one) for f in (1, 2)], (3, 2, *two), *[(f, 1, *one) for f in (4, 5)])
    res = gt.copy()
    res[:, 1] += 6
    ref = trackeval_hota(tmp_path, {"s": (gt, res)}, "MOT15", ("CLEAR", "Identity"))
    m = evaluate_mot(gt, res)
    assert (m.num_fragmentations, m.num_switches, m.mota) == (1, 0, 1.0)
    assert_same_clear(m, ref["s"])
    assert motmetrics_summary(gt, res)["num_fragmentations"] == 0
    res = np.delete(res, 2, axis=0)  # frame 3 without results: no scored frame, no new run
    ref = trackeval_hota(tmp_path / "b", {"s": (gt, res)}, "MOT15", ("CLEAR", "Identity"))
    assert evaluate_mot(gt, res).num_fragmentations == ref["s"]["Frag"] == 0


def test_below_iou_half_clear_takes_the_largest_iou_sum_as_trackeval(tmp_path):
    """At IoU 0.3 one match at IoU 1 beats two at 1/3 in TrackEval's CLEAR (and pftrack's);
    py-motmetrics takes the two (docs/eval.md, its fifth difference)."""
    from tests.eval.test_hota import assert_same_clear, trackeval_hota  # skips without it

    gt = rows((1, 1, 0, 0, 10, 10), (1, 2, 5, 0, 10, 10))  # A, B
    res = rows((1, 7, 0, 0, 10, 10), (1, 8, -5, 0, 10, 10))  # X on A, Y at 1/3 with A only
    ref = trackeval_hota(tmp_path, {"s": (gt, res)}, "MOT15", ("CLEAR", "Identity"), 0.3)
    m = evaluate_mot(gt, res, iou_threshold=0.3)
    assert (m.num_matches, m.mota, m.idf1) == (1, 0.0, 1.0)
    assert_same_clear(m, ref["s"])
    assert motmetrics_summary(gt, res, thr=0.3)["mota"] == 1.0


def test_metrics_type():
    assert isinstance(evaluate_mot(HAND_GT, HAND_GT), MotMetrics)
    assert evaluate_mot(HAND_GT, HAND_GT).mota == 1.0


def test_one_id_twice_in_a_frame_is_refused_as_pftrack_eval_refuses_it():
    """evaluate_mot scored a result with id 1 twice in frame 1 (one of them a false positive)
    where evaluate_hota and `pftrack eval` refused it."""
    from pftrack.eval import evaluate_hota

    twice = np.vstack([HAND_RES, HAND_RES[:1] + [0, 0, 2, 0, 0, 0, 0, 0, 0, 0]])
    for evaluate in (evaluate_mot, evaluate_hota):
        with pytest.raises(ValueError, match="result has id .* more than once in frame"):
            evaluate(HAND_GT, twice)
        with pytest.raises(ValueError, match="(gt|ground truth) has id .* more than once"):
            evaluate(twice, HAND_RES)


def test_a_threshold_of_1_matches_identical_boxes():
    """The IoU of identical boxes came out just under 1 (31.03 px wide): ground truth scored
    against itself at --iou 1 gave MOTA -100."""
    g = np.array(
        [[1, 1, 499, 158, 31.03, 75.17, 1, -1, -1, -1], [2, 1, 500, 158, 0.1, 75.17, 1, -1, -1, -1]]
    )
    m = evaluate_mot(g, g, iou_threshold=1.0)
    assert (m.mota, m.idf1, m.false_positives, m.misses) == (1.0, 1.0, 0, 0)
    moved = g.copy()
    moved[:, 2] += 1e-6  # a box that moved is not identical: no match at 1
    with pytest.warns(UserWarning, match="^evaluate_mot: none of .* with IoU 1 or more"):
        assert evaluate_mot(g, moved, iou_threshold=1.0).num_matches == 0


def test_scale_and_threshold_of_the_wrong_type_are_named():
    with pytest.raises(TypeError, match="evaluate_mot: scale must be a number, got str"):
        evaluate_mot(HAND_GT, HAND_RES, scale="2")
    with pytest.raises(TypeError, match="evaluate_mot: iou_threshold must be a number"):
        evaluate_mot(HAND_GT, HAND_RES, iou_threshold=None)


def test_truth_scored_against_itself_has_centroid_distance_zero():
    # was 2.5 px: object 2 touched track 1 in as many frames as its own track 2, and the tie
    # went to the smaller id (TUD-Campus's gt.txt against itself: 3.167 px)
    truth = np.array(
        [[f, i, x, 0, 10, 10, 1, -1, -1, -1] for f in (1, 2) for i, x in ((1, 0), (2, 5))],
        dtype=float,
    )
    m = evaluate_mot(truth, truth)
    assert m.centroid_distance_px == 0.0
    assert m.success_rate == m.success_rate_strict == 1.0
    # the nearer of two tracks that both match the object equally often is its track
    near = truth.copy()
    near[near[:, 1] == 2, 2] += 1.0  # track 2 one pixel right of object 2
    assert evaluate_mot(truth, near).centroid_distance_px == pytest.approx(0.5)


def test_empty_ground_truth_or_results_score_as_trackeval():
    # MOTA was NaN without ground truth where TrackEval's CLEAR gives 0; MOTP, IDP, IDR NaN
    # (tests/eval/test_hota.py holds every figure equal to TrackEval's)
    from pftrack.eval import combine_mot, evaluate_sequence, format_scores

    none = np.zeros((0, 10))
    for gt, res in ((none, HAND_RES), (HAND_GT, none), (none, none)):
        s = evaluate_sequence(gt, res)
        m = s.mot
        assert (m.mota, m.motp_iou, m.idf1, m.idp, m.idr) == (0.0, 0.0, 0.0, 0.0, 0.0)
        assert (m.precision, m.recall) == (0.0, 0.0)
        assert s.hota.hota == 0.0 and s.hota.loc_a_mean == 1.0
        line = format_scores({"s": s}).split("\n")[1].split()
        assert "nan" not in line and "-" not in line[:-1]  # Succ: none without ground truth
        assert line[-1] == ("-" if len(gt) == 0 else "0.0")  # was "nan"; JSON: null
    no_gt = evaluate_mot(none, HAND_RES)
    # combined as TrackEval's combine_sequences: (TP - FP - IDSW) / max(1, TP + FN)
    assert combine_mot([no_gt]).mota == -float(no_gt.false_positives)
    assert combine_mot([no_gt, evaluate_mot(HAND_GT, none)]).mota == pytest.approx(
        1 - (no_gt.false_positives + 14) / 14
    )


def test_format_metrics_names_the_formatter_of_sequence_scores():
    # raised "TypeError: 'SequenceScores' object is not iterable"
    from pftrack.eval import evaluate_sequence, format_scores

    s = evaluate_sequence(HAND_GT, HAND_RES)
    hint = r"evaluate_sequence's SequenceScores are formatted by pftrack.eval.format_scores"
    with pytest.raises(TypeError, match=rf"^format_metrics: m is SequenceScores, .*: {hint}"):
        format_metrics(s)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=rf"^format_metrics: m\['a'\] is SequenceScores.*{hint}"):
        format_metrics({"a": s})  # type: ignore[dict-item]
    with pytest.raises(TypeError, match=rf"^format_metrics: m is list, .*{hint}"):
        format_metrics([s])  # type: ignore[arg-type]
    assert "HOTA" in format_scores({"a": s}) and format_metrics(s.mot) == s.mot.table()
    with pytest.raises(TypeError, match=r"format_metrics: m is str, expected MotMetrics: pass a"):
        format_metrics("result")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="format_metrics: no result to format"):
        format_metrics({})


def test_hota_metrics_docstring_says_which_fields_are_arrays():
    # det_a is a float, ass_a the per-threshold array (ass_a_mean its float)
    from pftrack.eval import HotaMetrics, evaluate_hota

    h = evaluate_hota(HAND_GT, HAND_RES)
    doc = HotaMetrics.__doc__ or ""
    floats = ("hota", "det_a", "det_re", "det_pr", "ass_a_mean", "ass_re_mean", "ass_pr_mean",
              "loc_a_mean", "hota0")  # fmt: skip
    arrays = ("hota_alpha", "det_a_alpha", "det_re_alpha", "det_pr_alpha", "ass_a", "ass_re",
              "ass_pr", "loc_a", "tp", "fn", "fp")  # fmt: skip
    for name in floats:
        assert type(getattr(h, name)) is float and f"``{name}``" in doc, name
    for name in arrays:
        assert getattr(h, name).shape == (19,) and f"``{name}``" in doc, name
    assert "float (mean over the 19 thresholds)" in doc


def test_a_missing_value_reads_dash_in_the_text_tables():
    """Was ``nan`` (the JSON keeps null): CD/px without an image size, Succ without truth."""
    from pftrack.eval import evaluate_sequence, format_scores

    line = format_metrics(evaluate_mot(HAND_GT, HAND_RES)).splitlines()[1].split()
    assert line[-1] == "-" and "nan" not in line  # CD/px: no image size given
    row = format_scores({"s": evaluate_sequence(np.zeros((0, 10)), HAND_RES)}).splitlines()[1]
    assert row.split()[-1] == "-" and "nan" not in row


# ---- the vectorised scorer against a straightforward one ------------------------------------


def reference_mot(gt, res, thr=0.5):
    """evaluate_mot's figures as it computed them before it was vectorised: frame by frame,
    pair by pair, with a dict per counter (slow: 29 s for 100 people over 400 frames).

    Takes the scored rows (:func:`pftrack.eval.prepare_mot`'s); returns MotMetrics' fields.
    """
    from scipy.optimize import linear_sum_assignment

    from pftrack.eval.rows import _mot_iou
    from pftrack.io.mot import group_by_frame

    eps = float(np.finfo(float).eps)
    gt_frames, res_frames = group_by_frame(gt), group_by_frame(res)
    empty = np.zeros((0, 10))
    last_match, previous, matched_count, runs = {}, {}, {}, {}
    pair_hits, pair_touch, centroid, gt_count, res_count = {}, {}, {}, {}, {}
    n_fp = n_fn = n_sw = n_match = n_gt = n_res = 0
    iou_sum = 0.0
    for f in sorted(set(gt_frames) | set(res_frames)):
        gf, rf = gt_frames.get(f, empty), res_frames.get(f, empty)
        gids, rids = gf[:, 1].astype(np.int64), rf[:, 1].astype(np.int64)
        n_gt += len(gids)
        n_res += len(rids)
        for o in gids:
            gt_count[int(o)] = gt_count.get(int(o), 0) + 1
        for h in rids:
            res_count[int(h)] = res_count.get(int(h), 0) + 1
        iou = _mot_iou(gf[:, 2:6], rf[:, 2:6])
        if len(gids) and len(rids):
            cg = gf[:, 2:4] + 0.5 * gf[:, 4:6]
            cr = rf[:, 2:4] + 0.5 * rf[:, 4:6]
            dist = np.hypot(cg[:, None, 0] - cr[None, :, 0], cg[:, None, 1] - cr[None, :, 1])
            for i, o in enumerate(gids):
                for j, h in enumerate(rids):
                    key = (int(o), int(h))
                    centroid.setdefault(key, []).append(float(dist[i, j]))
                    if iou[i, j] > 0:
                        pair_touch[key] = pair_touch.get(key, 0) + 1
                    if iou[i, j] >= thr:
                        pair_hits[key] = pair_hits.get(key, 0) + 1
        if len(gids) == 0 or len(rids) == 0:
            n_fp += len(rids)
            n_fn += len(gids)
            continue
        before = np.array([previous.get(int(o), np.nan) for o in gids], dtype=np.float64)
        goes_on = before[:, None] == rids[None, :]
        score = np.where(iou >= thr - eps, 1000.0 * goes_on + iou, 0.0)
        rows_m, cols_m = linear_sum_assignment(-score)
        hit = score[rows_m, cols_m] > eps
        if hit.any():
            iou_sum += float(sum(iou[rows_m[hit], cols_m[hit]]))
        now = {}
        for i, j in zip(rows_m[hit].tolist(), cols_m[hit].tolist(), strict=True):
            o, h = int(gids[i]), int(rids[j])
            if o in last_match and last_match[o] != h:
                n_sw += 1
            last_match[o] = now[o] = h
            matched_count[o] = matched_count.get(o, 0) + 1
            if o not in previous:
                runs[o] = runs.get(o, 0) + 1
        previous = now
        n_match += int(hit.sum())
        n_fn += len(gids) - int(hit.sum())
        n_fp += len(rids) - int(hit.sum())
    ratios = [matched_count.get(o, 0) / n for o, n in gt_count.items()]
    oids, hids = sorted(gt_count), sorted(res_count)
    idtp = 0
    if oids and hids:
        w = np.zeros((len(oids), len(hids)))
        for (o, h), c in pair_hits.items():
            w[oids.index(o), hids.index(h)] = c
        a, b = linear_sum_assignment(-w)
        idtp = int(w[a, b].sum())
    per_object, dists = [], []
    for o in oids:
        touch = {h: c for (oo, h), c in pair_touch.items() if oo == o}
        hits = {h: c for (oo, h), c in pair_hits.items() if oo == o}
        far = {h: sum(centroid[(o, h)]) for h in touch}
        loose = strict = 0.0
        if touch:
            best = max(touch, key=lambda h: (touch[h], hits.get(h, 0), -far[h], -h))
            loose = touch[best] / gt_count[o]
            dists.extend(centroid[(o, best)])
        if hits:
            best_s = max(hits, key=lambda h: (hits[h], touch[h], -far[h], -h))
            strict = hits[best_s] / gt_count[o]
        per_object.append((o, loose, strict))
    return {
        "mota": (n_match - n_fp - n_sw) / n_gt if n_gt else 0.0,
        "motp_iou": iou_sum / n_match if n_match else 0.0,
        "iou_sum": iou_sum,
        "idtp": idtp,
        "num_switches": n_sw,
        "num_fragmentations": sum(k - 1 for k in runs.values()),
        "mostly_tracked": sum(x > 0.8 for x in ratios),
        "mostly_lost": sum(x < 0.2 for x in ratios),
        "false_positives": n_fp,
        "misses": n_fn,
        "num_matches": n_match,
        "num_objects": n_gt,
        "num_predictions": n_res,
        "num_unique_objects": len(oids),
        "success_per_object": tuple(per_object),
        "success_rate": float(np.mean([p[1] for p in per_object])) if oids else math.nan,
        "success_rate_strict": float(np.mean([p[2] for p in per_object])) if oids else math.nan,
        "centroid_distance_px": float(np.mean(dists)) if dists else math.nan,
    }


def crowd_case(seed):
    """Crowded, overlapping walkers and a result with jitter, misses, swaps, copies and ties."""
    rng = np.random.default_rng(seed)
    gt = []
    for oid in range(1, 26):
        start = int(rng.integers(1, 15))
        end = int(rng.integers(start, 30))
        x, y = rng.uniform(0, 100, 2)  # a small area: boxes overlap many others
        v = rng.normal(0, 1.5, 2)
        w, h = rng.uniform(15, 30), rng.uniform(30, 60)
        for f in range(start, end + 1):
            gt.append((f, oid, round(x + v[0] * f), round(y + v[1] * f), round(w), round(h)))
    g = rows(*gt)
    res = g[rng.random(len(g)) > 0.2].copy()
    moved = rng.random(len(res)) < 0.5
    res[moved, 2:4] += rng.integers(-4, 5, (int(moved.sum()), 2))  # integers: exact ties
    res[(res[:, 0] > 10) & (res[:, 1] % 4 == 0), 1] += 100  # new ids
    copies = res[rng.random(len(res)) < 0.2].copy()
    copies[:, 1] += 1000  # the same boxes under other ids
    both = np.vstack([copies, res] if seed % 2 else [res, copies])
    return g, both[np.argsort(both[:, 0], kind="stable")]


@pytest.mark.parametrize("seed", range(6))
def test_vectorised_scores_equal_the_straightforward_ones(seed):
    """Every figure, to the last bit (the per-pair loop took 29 s and 170 MB on 100 people)."""
    from pftrack.eval import prepare_mot

    cases = [random_case(seed), crowd_case(seed), (HAND_GT, HAND_RES)]
    for thr in (0.5, 0.3):
        for gt, res in cases:
            m = evaluate_mot(gt, res, iou_threshold=thr)
            ref = reference_mot(*prepare_mot(gt, res), thr)
            for name, value in ref.items():
                got = getattr(m, name)
                assert got == value or (math.isnan(value) and math.isnan(got)), name
            assert m.partially_tracked == m.num_unique_objects - m.mostly_tracked - m.mostly_lost
    g, r = crowd_case(seed)
    assert evaluate_mot(g, r).num_switches > 0 and any(
        len(set(map(int, r[r[:, 0] == f, 2]))) < (r[:, 0] == f).sum() for f in range(1, 30)
    )  # the crowd case has switches and boxes at one place under two ids


def test_the_api_names_its_argument_when_given_the_wrong_kind():
    """Were a bare StopIteration, Python's dict, AttributeError and '<' messages; NaN passed."""
    from pftrack.eval import (
        SequenceScores,
        combine_hota,
        combine_mot,
        evaluate_hota,
        evaluate_sequence,
        format_scores,
    )
    from pftrack.eval.sequences import scores_csv, scores_json

    s = evaluate_sequence(HAND_GT, HAND_RES)
    with pytest.raises(ValueError, match=r"^format_scores: no sequence to format$"):
        format_scores({})
    with pytest.raises(TypeError, match=r"^format_scores: rows is list, expected a mapping of "):
        format_scores([s])  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"rows\['a'\] is MotMetrics, .*by pftrack.eval.format_m"):
        format_scores({"a": s.mot})  # type: ignore[dict-item]
    with pytest.raises(TypeError, match=r"^format_scores: combined is MotMetrics, expected Seq"):
        format_scores({"a": s}, s.mot)  # type: ignore[arg-type]
    for fn in (scores_csv, scores_json):
        with pytest.raises(ValueError, match=rf"^{fn.__name__}: no sequence to format$"):
            fn({}, None)
    assert "COMBINED" in format_scores({"a": s}, s)

    mot, hota = evaluate_mot(HAND_GT, HAND_GT), evaluate_hota(HAND_GT, HAND_GT)
    with pytest.raises(
        TypeError,
        match=r"^SequenceScores.combine: parts\[0\] is MotMetrics, expected SequenceScores; "
        r"MotMetrics are combined by pftrack.eval.combine_mot$",
    ):
        SequenceScores.combine([mot])  # type: ignore[list-item]
    with pytest.raises(ValueError, match=r"^SequenceScores.combine: no sequences to combine$"):
        SequenceScores.combine([])
    with pytest.raises(TypeError, match=r"^SequenceScores.combine: parts is SequenceScores, "):
        SequenceScores.combine(s)  # type: ignore[arg-type]
    with pytest.raises(
        TypeError,
        match=r"^combine_mot: parts\[1\] is HotaMetrics, expected MotMetrics; HotaMetrics are "
        r"combined by pftrack.eval.combine_hota$",
    ):
        combine_mot([mot, hota])  # type: ignore[list-item]
    with pytest.raises(TypeError, match=r"combine_mot: parts\[0\] is SequenceScores.*\[s.mot for"):
        combine_mot([s])  # type: ignore[list-item]
    with pytest.raises(TypeError, match=r"^combine_mot: parts is MotMetrics, expected a list"):
        combine_mot(mot)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"^combine_hota: parts\[0\] is MotMetrics, expected Hot"):
        combine_hota([mot])  # type: ignore[list-item]
    assert SequenceScores.combine([s, s]).mot.num_objects == 2 * s.mot.num_objects

    for size, error, message in (
        ((640, None), TypeError, r"image_size\[1\] must be a number, got NoneType"),
        (640, TypeError, r"image_size is int 640, expected \(width, height\)"),
        ("640x480", TypeError, r"image_size is str '640x480', expected \(width, height\)"),
        ((640, 480, 3), ValueError, r"image_size is \(640, 480, 3\), expected .* 2 values"),
        ((math.nan, 480), ValueError, r"image_size is \(nan, 480\), expected .* finite and > 0"),
        ((640, -1), ValueError, r"image_size is \(640, -1\), expected .* finite and > 0"),
        # were: "len() of unsized object", and the array's repr over two lines
        (
            np.array(640),
            TypeError,
            r"image_size is ndarray array\(640\), expected \(width, height\)$",
        ),
        (
            np.ones((2, 2)),
            TypeError,
            r"image_size is ndarray of shape \(2, 2\), expected \(width, h",
        ),
    ):
        with pytest.raises(error, match=rf"^evaluate_mot: {message}"):
            evaluate_mot(HAND_GT, HAND_RES, image_size=size)  # type: ignore[arg-type]
        with pytest.raises(error, match=rf"^evaluate_sequence: {message}"):
            evaluate_sequence(HAND_GT, HAND_RES, image_size=size)  # type: ignore[arg-type]
    ratio = evaluate_mot(HAND_GT, HAND_RES, image_size=np.array([400, 300]))
    assert ratio.centroid_distance_ratio == pytest.approx(2 / 3 / (400 * 300))


def test_negative_ids_are_refused_as_trackeval_refuses_them(tmp_path, capsys):
    """A result with id -5 was scored as any other id (MOTA 1); TrackEval fails on it."""
    from pftrack.eval import evaluate_hota, evaluate_sequence

    neg = HAND_RES.copy()
    neg[neg[:, 1] == 11, 1] = -5  # frames 4 and 5
    one = HAND_RES.copy()
    one[0, 1] = -1  # one id -1: a detections file's id, named so
    for fn in (evaluate_mot, evaluate_hota, evaluate_sequence):
        with pytest.raises(ValueError, match=r"^result has id -5 in frame 4: ids must be >= 0, as"):
            fn(HAND_GT, neg)
        with pytest.raises(ValueError, match=r"^ground truth has id -5 in frame 4: ids must be"):
            fn(neg, HAND_RES)
        with pytest.raises(ValueError, match=r"id -1 in frame 1: .*: is it a detections file"):
            fn(HAND_GT, one)
    zero = HAND_RES.copy()
    zero[:, 1] -= 10  # ids from 0: TrackEval scores them
    assert evaluate_mot(HAND_GT, zero).num_switches == 1
    write_mot(tmp_path / "gt.txt", HAND_GT)
    write_mot(tmp_path / "res.txt", neg)
    argv = ["eval", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path / "res.txt")]
    assert main(argv) == 2
    assert capsys.readouterr().err == (  # named by its line, as recover names it
        f"pftrack eval: error: {tmp_path / 'res.txt'}:5: id -5 in frame 4 (2 rows have it): "
        "track ids must be >= 0, as pftrack eval and TrackEval require them (-1 alone has a "
        "meaning: a box no track holds); renumber the tracks\n"
    )


@pytest.mark.parametrize("n_cols", [6, 7, 8, 9])
def test_short_rows_score_as_their_file(tmp_path, n_cols):
    """An (M, 6..9) array scores as the file it is written to: read_mot's defaults fill it.

    Before, an 8-column ground truth (frame, id, box, flag, class) got visibility 1 where the
    file read gives -1: the array was taken for MOT17 (the box of class 2, a distractor, left
    out with the result box on it), the file for MOT15 (no classes: that box matched).
    """
    gt = np.array(
        [[1, 1, 10, 10, 20, 40, 1, 1, 1, 1], [1, 2, 60, 10, 20, 40, 1, 2, 1, 1],
         [2, 1, 12, 10, 20, 40, 1, 1, 1, 1], [2, 2, 62, 10, 20, 40, 1, 2, 1, 1]],
        dtype=np.float64,
    )  # fmt: skip
    result = rows((1, 7, 10, 10, 20, 40), (1, 8, 60, 10, 20, 40), (2, 7, 12, 10, 20, 40))
    short = gt[:, :n_cols]
    path = tmp_path / "gt.txt"
    path.write_text("".join(",".join(f"{v:g}" for v in r) + "\n" for r in short))
    from_array = evaluate_mot(short, result)
    from_file = evaluate_mot(read_mot(path), result)
    np.testing.assert_equal(dataclasses.astuple(from_array), dataclasses.astuple(from_file))
    # MOT15's rules without the class column (3 matches, the distractor's second box missed);
    # with it MOT17's, which leave the distractor and the result box on it out: with or without
    # the visibility column, as TrackEval scores an 8-column MOT17 file (was: MOT15's for 8)
    assert from_array.num_matches == (3 if n_cols < 8 else 2)
