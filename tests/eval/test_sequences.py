"""Several sequences: combining as py-motmetrics and TrackEval do, folders, the scale check, CLI."""

from __future__ import annotations

import csv
import json
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval import (
    SequenceScores,
    check_scale,
    combine_hota,
    combine_mot,
    evaluate_hota,
    evaluate_mot,
    evaluate_sequence,
    find_sequences,
)
from pftrack.eval.sequences import read_seqinfo, result_file
from pftrack.io.mot import read_mot, write_mot
from tests.conftest import dataset
from tests.eval.cases import perturbed, write_rows
from tests.eval.test_metrics import random_case
from tests.reference import boxes as ref_boxes

CLEAR = ["mota", "motp", "idf1", "idp", "idr", "num_switches", "num_fragmentations",
         "mostly_tracked", "partially_tracked", "mostly_lost", "num_false_positives",
         "num_misses"]  # fmt: skip


def motmetrics_overall(cases):
    mm = pytest.importorskip("motmetrics")
    accs = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for gt, res in cases:
            acc = mm.MOTAccumulator(auto_id=False)
            for f in sorted(set(gt[:, 0].astype(int)) | set(res[:, 0].astype(int))):
                g, r = gt[gt[:, 0] == f], res[res[:, 0] == f]
                d = 1.0 - ref_boxes.iou_xywh(g[:, 2:6], r[:, 2:6])
                d = np.where(d > 0.5, np.nan, d)
                acc.update(g[:, 1].astype(int).tolist(), r[:, 1].astype(int).tolist(), d, frameid=f)
            accs.append(acc)
        names = [str(k) for k in range(len(accs))]
        s = mm.metrics.create().compute_many(
            accs, metrics=CLEAR, names=names, generate_overall=True
        )
    return {k: float(s.loc["OVERALL", k]) for k in CLEAR}


@pytest.mark.parametrize("seed", range(3))
def test_combined_clear_and_idf1_equal_trackeval_combined(seed: int, tmp_path: Path) -> None:
    from tests.eval.test_hota import assert_same_clear, trackeval_hota  # skips without it

    cases = {f"s{k}": random_case(10 * seed + k) for k in range(3)}
    ref = trackeval_hota(tmp_path, cases, "MOT15", ("CLEAR", "Identity"))
    parts = []
    for name in cases:
        g = read_mot(tmp_path / "gt" / name / "gt" / "gt.txt")
        r = read_mot(tmp_path / "trackers" / "t" / "data" / f"{name}.txt")
        parts.append(evaluate_mot(g, r))
    assert_same_clear(combine_mot(parts), ref["COMBINED"])


def test_combine_errors() -> None:
    gt, res = random_case(0)
    with pytest.raises(ValueError, match="no sequences"):
        combine_mot([])
    with pytest.raises(ValueError, match="IoU thresholds differ"):
        combine_mot([evaluate_mot(gt, res), evaluate_mot(gt, res, iou_threshold=0.4)])


def make_layout(root: Path, cases: dict[str, tuple[np.ndarray, np.ndarray]]) -> tuple[Path, Path]:
    """GT/SEQ/gt/gt.txt + GT/SEQ/seqinfo.ini and RES/SEQ.txt, as TrackEval reads them."""
    gt_root, res_root = root / "gt", root / "res"
    for name, (gt, res) in cases.items():
        write_mot(write_rows(gt_root / name / "gt" / "gt.txt", gt), gt)
        n = int(max(gt[:, 0].max(), res[:, 0].max()))
        (gt_root / name / "seqinfo.ini").write_text(
            f"[Sequence]\nname={name}\nseqLength={n}\nimWidth=200\nimHeight=150\n"
        )
        write_mot(write_rows(res_root / f"{name}.txt", res), res)
    return gt_root, res_root


def test_cli_folder_of_sequences(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cases = {f"SEQ-{k:02d}": random_case(k) for k in range(3)}
    gt_root, res_root = make_layout(tmp_path, cases)
    (gt_root / "not-a-sequence").mkdir()  # skipped: no ground truth
    seqs = find_sequences(gt_root)
    assert [s.name for s in seqs] == list(cases) and seqs[0].length is not None
    out_json, out_csv = tmp_path / "s.json", tmp_path / "s.csv"
    argv = ["eval", "--gt", str(gt_root), "--res", str(res_root)]
    assert main([*argv, "--json", str(out_json), "--csv", str(out_csv)]) == 0
    text = capsys.readouterr().out
    assert all(name in text for name in cases) and "COMBINED" in text and "HOTA" in text

    # What the files say is what the library computes, sequence by sequence and combined.
    def files(n: str) -> tuple[np.ndarray, np.ndarray]:
        return read_mot(gt_root / n / "gt" / "gt.txt"), read_mot(res_root / f"{n}.txt")

    parts = {n: evaluate_sequence(*files(n)) for n in cases}
    doc = json.loads(out_json.read_text())
    assert list(doc["sequences"]) == list(cases)
    for name, s in parts.items():
        assert doc["sequences"][name]["hota"] == pytest.approx(s.hota.hota, abs=1e-12)
        assert doc["sequences"][name]["mota"] == pytest.approx(s.mot.mota, abs=1e-12)
    combined = SequenceScores.combine(list(parts.values()))
    assert doc["combined"]["hota"] == pytest.approx(combined.hota.hota, abs=1e-12)
    assert doc["combined"]["idf1"] == pytest.approx(combined.mot.idf1, abs=1e-12)
    assert len(doc["combined"]["per_alpha"]["hota_per_alpha"]) == 19
    # Combined HOTA is not the mean of the sequences' HOTA: it is that of the summed counts.
    hotas = [p.hota for p in parts.values()]
    assert combined.hota.hota == pytest.approx(combine_hota(hotas).hota)
    det = combined.hota.tp / (combined.hota.tp + combined.hota.fn + combined.hota.fp)
    np.testing.assert_allclose(combined.hota.det_a_alpha, det)
    rows = list(csv.DictReader(out_csv.read_text().splitlines()))
    assert [r["sequence"] for r in rows] == [*cases, "COMBINED"]
    assert float(rows[-1]["mota"]) == pytest.approx(combined.mot.mota, abs=1e-12)

    # --seqs: a subset (one sequence: no combined row); a single sequence folder also works.
    assert main([*argv, "--seqs", "SEQ-01"]) == 0
    text = capsys.readouterr().out
    assert "SEQ-01" in text and "SEQ-00" not in text and "COMBINED" not in text
    assert main(["eval", "--gt", str(gt_root / "SEQ-02"), "--res", str(res_root)]) == 0
    assert "SEQ-02" in capsys.readouterr().out


def test_cli_folder_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cases = {"A": random_case(1), "B": random_case(2)}
    gt_root, res_root = make_layout(tmp_path, cases)
    argv = ["eval", "--gt", str(gt_root), "--res", str(res_root)]

    def error(*extra: str) -> str:
        assert main([*argv, *extra]) == 2
        err = capsys.readouterr().err
        assert err.startswith("pftrack eval: error: ") and err.count("\n") == 1
        return err

    # Outputs are checked before any work.
    assert "folder" in error("--json", str(tmp_path / "no" / "x.json"))
    assert "extension" in error("--csv", str(tmp_path / "x.txt"))
    assert "no sequence 'C'" in error("--seqs", "C")
    assert "no sequence 'C'" in error("--scale", "C=0.5")
    assert "no sequence 'C'" in error("--scale", "C=0.5", "--seqs", "A")
    # a scale for a sequence that --seqs leaves out is not used (was: "no sequence 'B'", a user
    # trial), and a scale for a scored one still is
    assert main([*argv, "--seqs", "A", "--scale", "B=0.5"]) == 0
    assert main([*argv, "--seqs", "A", "--scale", "A=7"]) == 2
    capsys.readouterr()
    # was: the last value won silently (MOTA -106 for PETS09 with 0.625 then 0.5)
    assert "--scale is given twice for every sequence (0.625, then 0.5); give it once" in error(
        "--scale", "0.625", "--scale", "0.5"
    )
    assert "--scale is given twice for sequence A (0.5, then 2)" in error(
        "--scale", "A=0.5", "--scale", "B=1", "--scale", "A=2"
    )
    # one result file against a folder of several sequences: was "results folder not found: ..."
    # of a file that exists
    one = ["eval", "--gt", str(gt_root), "--res", str(res_root / "A.txt")]
    assert main(one) == 2
    assert capsys.readouterr().err == (
        f"pftrack eval: error: --res {res_root / 'A.txt'} is a file, but --gt {gt_root} holds 2 "
        "sequences: give a folder of SEQ.txt results (or pick one sequence with --seqs NAME)\n"
    )
    assert main([*one, "--seqs", "A"]) == 0
    capsys.readouterr()
    (res_root / "B.txt").unlink()
    assert "no result for sequence B" in error()
    write_mot(res_root / "B.txt", cases["B"][1] + [100, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    # beyond seqLength: led by the file (was by the sequence's name, "B: result has frame")
    assert f"error: {res_root / 'B.txt'}: result has frame" in error()
    # the first sequence's: led by its own file (was by the last sequence's, B.txt)
    write_mot(res_root / "B.txt", cases["B"][1])
    write_mot(res_root / "A.txt", cases["A"][1] + [100, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    assert f"error: {res_root / 'A.txt'}: result has frame" in error()
    write_mot(res_root / "A.txt", cases["A"][1])
    assert main(["eval", "--gt", str(tmp_path / "nothing"), "--res", str(res_root)]) == 2
    assert "ground truth not found: " in capsys.readouterr().err
    assert main(["eval", "--gt", str(tmp_path / "nope.txt"), "--res", str(res_root)]) == 2
    assert "ground truth not found: " in capsys.readouterr().err  # was "ground-truth folder"
    (tmp_path / "empty").mkdir()
    assert main(["eval", "--gt", str(tmp_path / "empty"), "--res", str(res_root)]) == 2
    assert "no sequence in" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main([*argv, "--scale", "A=-1"])
    with pytest.raises(SystemExit):  # was taken as a scale for every sequence
        main([*argv, "--scale", "=0.5"])
    assert "NAME is empty" in capsys.readouterr().err


def test_one_file_reads_the_seqinfo_of_its_sequence_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """SEQ/gt/gt.txt given alone scores as SEQ does: seqLength checked, image size read."""
    cases = {"A": random_case(0)}
    gt_root, res_root = make_layout(tmp_path, cases)
    late = res_root / "late.txt"
    write_mot(late, cases["A"][1] + [100, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    for gt in (gt_root / "A", gt_root / "A" / "gt" / "gt.txt"):
        assert main(["eval", "--gt", str(gt), "--res", str(late)]) == 2
        assert "beyond the sequence's" in capsys.readouterr().err  # was scored from one file
    out = tmp_path / "one.json"
    argv = ["eval", "--gt", str(gt_root / "A" / "gt" / "gt.txt"), "--res", str(res_root / "A.txt")]
    assert main([*argv, "--json", str(out)]) == 0
    ratio = json.loads(out.read_text())["centroid_distance_ratio"]
    assert ratio is not None and ratio > 0  # imWidth x imHeight from seqinfo.ini (was null)
    loose = tmp_path / "loose"
    loose.mkdir()
    write_mot(loose / "gt.txt", cases["A"][0])  # no seqinfo.ini beside it: as before
    assert main(["eval", "--gt", str(loose / "gt.txt"), "--res", str(late)]) == 0


def test_seqinfo_with_a_byte_order_mark_is_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 'not a seqinfo.ini file (File contains no section headers.)'."""
    gt_root, res_root = make_layout(tmp_path, {"SEQ": random_case(0)})
    ini = gt_root / "SEQ" / "seqinfo.ini"
    ini.write_bytes(b"\xef\xbb\xbf" + ini.read_bytes())
    [seq] = find_sequences(gt_root)
    assert (seq.width, seq.height) == (200, 150) and seq.length is not None
    assert main(["eval", "--gt", str(gt_root), "--res", str(res_root)]) == 0
    assert "SEQ" in capsys.readouterr().out


def test_read_seqinfo_errors(tmp_path: Path) -> None:
    p = tmp_path / "seqinfo.ini"
    p.write_text("no section here\n")
    with pytest.raises(ValueError, match="not a seqinfo.ini"):
        read_seqinfo(p)
    p.write_text("[Other]\na=1\n")
    with pytest.raises(ValueError, match=r"no \[Sequence\]"):
        read_seqinfo(p)
    p.write_text("[Sequence]\nseqLength=ten\n")
    (tmp_path / "gt.txt").write_text("1,1,0,0,10,10,1,-1,-1,-1\n")
    with pytest.raises(ValueError, match="seqLength is 'ten'"):
        find_sequences(tmp_path)


def spread_scene(seed: int) -> np.ndarray:
    """Ground truth of 8 walkers spread over a 768x576 image, 60 frames."""
    rng = np.random.default_rng(seed)
    rows = []
    for oid in range(1, 9):
        x, y = rng.uniform(50, 650), rng.uniform(50, 450)
        v = rng.normal(0, 2, 2)
        for f in range(1, 61):
            rows.append([f, oid, x + v[0] * f, y + v[1] * f, 30, 80, 1, -1, -1, -1])
    return np.asarray(rows, dtype=float)


def test_the_scale_named_is_the_round_ratio_near_the_fit() -> None:
    """A user trial: a tracker's boxes 2 % smaller than the truth's, on a video of the truth's
    own size, given --scale 0.625 by mistake, were told "pass --scale 0.984" (which costs
    TUD-Campus 3 HOTA), where 1 is the ratio of the image sizes."""
    gt = spread_scene(0)
    res = gt.copy()
    res[:, 2:4] += 0.01 * res[:, 4:6]  # 2 % smaller about the same centre
    res[:, 4:6] *= 0.98
    with pytest.raises(ValueError, match=r"look 1 times the ground truth's, not 0\.625 .* pass "
                       r"--scale 1 instead of 0\.625"):  # fmt: skip
        check_scale(gt, res, scale=0.625)
    res[:, 2:6] *= 0.625  # and at PETS09's ratio
    with pytest.raises(ValueError, match=r"pass --scale 0\.625 instead of 0\.5"):
        check_scale(gt, res, scale=0.5)


def test_scale_mismatch_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gt = spread_scene(0)
    res = perturbed(gt, 1)
    res[:, 2:6] *= 0.625  # the result lives in a 480x360 image
    with pytest.raises(ValueError, match=r"pass --scale 0\.6\d*, the ratio of the image sizes"):
        check_scale(gt, res)
    with pytest.raises(ValueError, match=r"pass --scale A=0\.6\d*, the ratio"):
        check_scale(gt, res, sequence="A")
    check_scale(gt, res, scale=0.625)  # the right scale passes
    check_scale(gt, perturbed(gt, 2))  # same scale passes
    small = res.copy()
    small[:, 2:4] += 1000  # smaller boxes elsewhere: not a scale problem, scored as given
    check_scale(gt, small)
    write_mot(tmp_path / "gt.txt", gt)
    write_mot(tmp_path / "res.txt", res)
    argv = ["eval", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path / "res.txt")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "pftrack eval: error:" in err and "--scale" in err and err.count("\n") == 1
    assert main([*argv, "--scale", "0.625"]) == 0
    assert main([*argv, "--no-scale-check"]) == 0
    assert "-" in capsys.readouterr().out.split("\n")[2]  # a negative MOTA, as asked


def test_the_scale_check_scores_only_the_rows_of_its_sampled_frames(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Was: each factor tried (46 on a result at PETS09's ratio) went through every row once
    per sampled frame: 2.9 s of CPU for 200 000 rows, about 30 s for a file of 1.9 million,
    before the message. Now the sampled frames' rows are taken once; the message is the same."""
    import pftrack.eval.sequences as sequences

    gt = np.vstack([spread_scene(0)] + [spread_scene(0) + [[k * 100] + [0] * 9] for k in (1, 2)])
    res = perturbed(gt, 1)
    res[:, 2:6] *= 0.625
    with pytest.raises(ValueError) as plain:
        check_scale(gt, res)
    given: list[int] = []
    real = sequences._matched_fraction

    def spy(g: np.ndarray, r: np.ndarray, *args: object) -> float:
        given.append(len(g) + len(r))
        return real(g, r, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(sequences, "_matched_fraction", spy)
    with pytest.raises(ValueError) as spied:
        check_scale(gt, res)
    assert str(spied.value) == str(plain.value) and "pass --scale 0.625" in str(plain.value)
    frames = np.intersect1d(gt[:, 0], res[:, 0])
    sample = frames[np.linspace(0, len(frames) - 1, 40).astype(int)]  # 40 of 300 frames
    rows = int(np.isin(gt[:, 0], sample).sum() + np.isin(res[:, 0], sample).sum())
    assert len(given) > 20 and set(given) == {rows}, (rows, sorted(set(given)))


def _named_scale(gt: np.ndarray, res: np.ndarray, scale: float) -> tuple[float, str]:
    """The factor check_scale's message tells to pass as --scale, and the message."""
    with pytest.raises(ValueError, match=r"pass --scale ") as refused:
        check_scale(gt, res, scale=scale)
    message = str(refused.value)
    return float(message.split("pass --scale ")[1].split()[0].rstrip(",")), message


def test_scale_hint_names_the_absolute_scale_whatever_scale_was_given() -> None:
    """Was: with a --scale given, "its boxes look 1.26 times the ground truth's" (relative to
    the ground truth already scaled by 0.5) beside "about 0.631" (absolute), "pass --scale S";
    and 0.631 (a 2 % grid) where 0.625 matches, PETS09's MOTA 18 points lower. Every message
    names one absolute factor, the one to pass instead of the one given."""
    gt = spread_scene(0)
    res = perturbed(gt, 1)
    res[:, 2:6] *= 0.625
    named = {}
    for scale in (1.0, 0.5, 1.25, 0.3):
        named[scale], message = _named_scale(gt, res, scale)
        assert f"its boxes look {named[scale]:g} times the ground truth's" in message
        if scale != 1:
            assert f"times the ground truth's, not {scale:g} (median height 50 vs 80 px" in message
            assert f"pass --scale {named[scale]:g} instead of {scale:g}, the ratio" in message
        check_scale(gt, res, scale=named[scale])  # what it names passes
    assert len(set(named.values())) == 1  # one factor, absolute
    assert named[1.0] == pytest.approx(0.625, abs=0.0015)  # three digits: 0.624 to 0.626
    # the stretched case names absolute factors too (were 5 and 3.75 with scale=0.5)
    res[:, 2:6] /= 0.625
    res[:, [2, 4]] *= 2.5
    res[:, [3, 5]] *= 1.875
    with pytest.raises(
        ValueError, match=r"2\.5\d? times .* across and 1\.88 times down, not 0\.5 both ways"
    ):
        check_scale(gt, res, scale=0.5)


def test_scale_mismatch_within_a_quarter_refused() -> None:
    """Was: ratios within 0.8-1.25 were never checked (960x720 results on 768x576 ground
    truth scored MOTA -27 without a word)."""
    gt = spread_scene(0)
    res = perturbed(gt, 1)
    res[:, 2:6] *= 1.25
    with pytest.raises(ValueError, match=r"pass --scale 1\.2\d*, the ratio"):
        check_scale(gt, res)
    check_scale(gt, res, scale=1.25)


def test_stretched_result_refused() -> None:
    """A result on a 4:3 sequence stretched to 1920x1080 (x2.5 across, x1.875 down): no one
    factor fits, and the message says so (was: scored as given, MOTA -28)."""
    gt = spread_scene(0)
    res = perturbed(gt, 1)
    res[:, [2, 4]] *= 2.5
    res[:, [3, 5]] *= 1.875
    with pytest.raises(ValueError, match=r"2\.5\d? times .* across and 1\.88 times down"):
        check_scale(gt, res)


def test_corner_boxes_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A result written as x1, y1, x2, y2 (a detector's layout) where MOTChallenge holds left,
    top, width, height was scored as given: ADL-Rundle-6's ground truth so written scored
    MOTA -94.5, HOTA 5.5, without a word."""
    gt = spread_scene(0)
    res = perturbed(gt, 1)
    corners = res.copy()
    corners[:, 4:6] += corners[:, 2:4]  # x2 = left + width, y2 = top + height
    with pytest.raises(ValueError) as refused:
        check_scale(gt, corners, name="res.txt")
    message = str(refused.value)
    assert message.startswith("res.txt: its columns 5-6 look like the boxes' right and bottom ")
    assert "with width = x2 - x1 and height = y2 - y1" in message
    assert message.endswith("or --no-scale-check")
    check_scale(gt, res)  # the same boxes as left, top, width, height pass
    with pytest.raises(ValueError, match=r"look like the boxes' right and bottom .* scaled by 0"):
        check_scale(gt, corners * [1, 1, 0.625, 0.625, 0.625, 0.625, 1, 1, 1, 1], scale=0.625)
    write_mot(tmp_path / "gt.txt", gt)
    write_mot(tmp_path / "res.txt", corners)
    argv = ["eval", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path / "res.txt")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "its columns 5-6 look like the boxes' right and bottom" in err and err.count("\n") == 1
    assert main([*argv, "--no-scale-check"]) == 0  # scored as given, as asked


def test_normalised_result_refused() -> None:
    """A result in normalised coordinates was told "its boxes look 0.000521 times the ground
    truth's across and 0.000863 times down ...: the result is of a video of another shape
    ..., rescale one of them per axis": not what is wrong with it."""
    gt = spread_scene(0)
    res = perturbed(gt, 1)
    res[:, [2, 4]] /= 768
    res[:, [3, 5]] /= 576  # its boxes reach a little past the frame, as the truth's do
    with pytest.raises(ValueError) as refused:
        check_scale(gt, res, name="res.txt")
    assert str(refused.value) == (
        "res.txt: every box lies within 0.943 x 1.09, the ground truth's within 724 x 609 px: "
        "normalised coordinates? give pixels (x times the image width, y times its height), "
        "or --no-scale-check"
    )
    check_scale(gt / [1, 1, 768, 576, 768, 576, 1, 1, 1, 1], res)  # both normalised: alike


@pytest.mark.dataset
def test_cli_on_real_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """../shared/data as a MOTChallenge folder (SEQ/gt.txt), PETS results on the video's scale."""
    data = dataset("pets09-s2l1").parent
    res_root = tmp_path / "res"
    truth = {}
    for k, name in enumerate(("pets09-s2l1", "tud-campus")):
        truth[name] = read_mot(data / name / "gt.txt")
        res = perturbed(truth[name], k)
        if name == "pets09-s2l1":
            res[:, 2:6] *= 0.625
        write_rows(res_root / f"{name}.txt", res)
    argv = ["eval", "--gt", str(data), "--res", str(res_root), "--seqs", "pets09-s2l1",
            "tud-campus"]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "pets09-s2l1.txt: its boxes look 0.62" in err
    assert "pass --scale pets09-s2l1=0.62" in err  # was --scale S, for every sequence
    # a global scale meant for PETS09 scales TUD-Campus too: the hint names its own scale
    assert main([*argv, "--scale", "0.625"]) == 2
    err = capsys.readouterr().err
    # absolute: was "look 1.6 times", relative to the ground truth scaled by 0.625
    assert "tud-campus.txt: its boxes look 1 times the ground truth's, not 0.625" in err
    assert "pass --scale tud-campus=1 instead of 0.625, the ratio" in err
    out = tmp_path / "s.json"
    assert main([*argv, "--scale", "pets09-s2l1=0.625", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    pets = read_mot(res_root / "pets09-s2l1.txt")
    expected = evaluate_hota(truth["pets09-s2l1"], pets, scale=0.625, num_frames=795)
    assert doc["sequences"]["pets09-s2l1"]["hota"] == pytest.approx(expected.hota, abs=1e-12)
    assert doc["sequences"]["pets09-s2l1"]["scale"] == 0.625
    assert doc["sequences"]["tud-campus"]["scale"] == 1.0
    assert 0.3 < doc["combined"]["hota"] < 0.9


@pytest.mark.dataset
@pytest.mark.slow
def test_docs_eval_md_example_output_is_its_commands(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/eval.md's example table quoted TUD-Campus as it scored before ``size_ratio``'s
    default (75.2 MOTA, 28 FP; the commands give 79.4, 13). Its commands, run as written."""
    data = dataset("pets09-s2l1").parent
    dataset("tud-campus")
    text = (Path(__file__).parents[2] / "docs" / "eval.md").read_text()
    lines = [line.strip("`") for line in text.splitlines()]
    tracks = [line.split()[1:] for line in lines if line.startswith("pftrack track ../shared/")]
    (scoring,) = [line.split()[1:] for line in lines if line.startswith("pftrack eval --gt ../")]
    assert len(tracks) == 2 and scoring[-1] == "tud-campus"

    def argv(words: list[str]) -> list[str]:
        return ["-q", *(w.replace("../shared/data", str(data)) for w in words)]

    monkeypatch.chdir(tmp_path)  # their files go in res/, as written
    (tmp_path / "res").mkdir()
    for words in tracks:
        assert main(argv(words)) == 0
    capsys.readouterr()
    assert main(argv(scoring)) == 0
    printed = [line for line in capsys.readouterr().out.splitlines() if line.strip()]
    table = [
        line for line in printed if line.split()[0] in {"pets09-s2l1", "tud-campus", "COMBINED"}
    ]
    assert len(table) == 3
    for line in table:
        assert line in lines, line  # the example's row, to the digit


def test_trackevals_seqmap_chooses_the_sequences_as_in_trackeval(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """TrackEval scores ``MOT15-train`` on the sequences ``seqmaps/MOT15-train.txt`` lists.

    pftrack scored every folder: with A, B, C there and A, B listed, its COMBINED row was of
    all three (HOTA 31.2, MOTA 8.2 on these cases) where TrackEval's is of A and B (24.8,
    -11.7).
    """
    import contextlib
    import io

    trackeval = pytest.importorskip("trackeval")
    cases = {name: random_case(k + 1) for k, name in enumerate("ABC")}
    gt_split, res_flat = make_layout(tmp_path / "flat", cases)
    gt_root = tmp_path / "data" / "gt" / "mot_challenge"
    shutil.copytree(gt_split, gt_root / "MOT15-train")
    (gt_root / "seqmaps").mkdir()
    (gt_root / "seqmaps" / "MOT15-train.txt").write_text("name\nA\nB\n")
    trackers = tmp_path / "data" / "trackers" / "mot_challenge"
    shutil.copytree(res_flat, trackers / "MOT15-train" / "mine" / "data")
    config = trackeval.Evaluator.get_default_eval_config()
    config.update({"PRINT_RESULTS": False, "PRINT_CONFIG": False, "TIME_PROGRESS": False,
                   "OUTPUT_SUMMARY": False, "OUTPUT_DETAILED": False, "PLOT_CURVES": False,
                   "USE_PARALLEL": False})  # fmt: skip
    dataset_config = {
        "GT_FOLDER": str(gt_root),
        "TRACKERS_FOLDER": str(trackers),
        "BENCHMARK": "MOT15",
        "SPLIT_TO_EVAL": "train",
        "PRINT_CONFIG": False,
    }
    with contextlib.redirect_stdout(io.StringIO()):
        res, _ = trackeval.Evaluator(config).evaluate(
            [trackeval.datasets.MotChallenge2DBox(dataset_config)],
            [trackeval.metrics.HOTA(), trackeval.metrics.CLEAR(), trackeval.metrics.Identity()],
        )
    ref = res["MotChallenge2DBox"]["mine"]
    assert sorted(ref) == ["A", "B", "COMBINED_SEQ"]  # TrackEval's own choice
    combined = ref["COMBINED_SEQ"]["pedestrian"]
    out = tmp_path / "s.json"
    for gt in (gt_root / "MOT15-train", gt_root):
        argv = ["eval", "--gt", str(gt), "--res", str(trackers / "MOT15-train" / "mine")]
        assert main([*argv, "--json", str(out)]) == 0
        capsys.readouterr()
        doc = json.loads(out.read_text())
        assert sorted(doc["sequences"]) == ["A", "B"]
        got = doc["combined"]
        assert got["hota"] == pytest.approx(float(np.mean(combined["HOTA"]["HOTA"])), abs=1e-12)
        assert got["mota"] == combined["CLEAR"]["MOTA"]
        assert got["idf1"] == combined["Identity"]["IDF1"]
        assert got["num_switches"] == combined["CLEAR"]["IDSW"]
    assert [s.name for s in find_sequences(gt_root / "MOT15-train")] == ["A", "B"]
    # --seqs picks any folder; a listed sequence without its folder, or none listed: refused
    assert [s.name for s in find_sequences(gt_root / "MOT15-train", ["C"])] == ["A", "B", "C"]
    argv = ["eval", "--gt", str(gt_root / "MOT15-train"), "--res", str(res_flat)]
    assert main([*argv, "--seqs", "C"]) == 0
    assert " C " in capsys.readouterr().out
    for listed, message in (("name\nA\nD\n", "lists sequence D, which has no folder"),
                            ("name\n", "lists no sequence")):  # fmt: skip
        (gt_root / "seqmaps" / "MOT15-train.txt").write_text(listed)
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("pftrack eval: error: ") and message in err
        assert err.count("\n") == 1
    # the seqinfo.ini of a sequence the seqmap leaves out is not read
    (gt_root / "seqmaps" / "MOT15-train.txt").write_text("name\nA\nB\n")
    (gt_root / "MOT15-train" / "C" / "seqinfo.ini").write_text("[Sequence]\nseqLength=x\n")
    assert main(argv) == 0
    capsys.readouterr()


def test_cli_reads_trackevals_tree(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Regression: ``--res trackers/mot_challenge/MOT15-train/NAME`` (results in ``data/``) said
    "no result for sequence ... (choose sequences with --seqs)", and ``--gt gt/mot_challenge``
    "no sequence in ..."."""
    cases = {"A": random_case(1), "B": random_case(2)}
    gt_split, res_flat = make_layout(tmp_path / "flat", cases)
    root = tmp_path / "TrackEval" / "data"
    gt_root = root / "gt" / "mot_challenge"
    shutil.copytree(gt_split, gt_root / "MOT15-train")
    (gt_root / "seqmaps").mkdir()  # TrackEval's lists of sequences: no sequence in it
    trackers = root / "trackers" / "mot_challenge" / "MOT15-train"
    shutil.copytree(res_flat, trackers / "mine" / "data")
    assert [s.name for s in find_sequences(gt_root)] == ["A", "B"]
    assert result_file(trackers / "mine", "A") == trackers / "mine" / "data" / "A.txt"
    assert result_file(trackers / "mine", "C") is None
    assert main(["eval", "--gt", str(gt_split), "--res", str(res_flat)]) == 0
    want = capsys.readouterr().out
    for gt in (gt_root, gt_root / "MOT15-train"):
        assert main(["eval", "--gt", str(gt), "--res", str(trackers / "mine")]) == 0
        assert capsys.readouterr().out == want

    def error(gt: Path, res: Path) -> str:
        assert main(["eval", "--gt", str(gt), "--res", str(res)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("pftrack eval: error: ") and err.count("\n") == 1
        return err

    # the folder of trackers: name them; no results at all: say what is looked for
    assert "holds tracker folders (mine): give one of them as --res" in error(gt_root, trackers)
    (tmp_path / "none").mkdir()
    err = error(gt_root, tmp_path / "none")
    assert "data/A.txt" in err and "--seqs" not in err
    (trackers / "mine" / "data" / "B.txt").unlink()  # one missing: --seqs can leave it out
    assert "no result for sequence B" in error(gt_root, trackers / "mine")
    assert "--seqs" in error(gt_root, trackers / "mine")
    shutil.copytree(gt_split, gt_root / "MOT16-train")  # the same names twice
    assert "sequence A is both in" in error(gt_root, trackers / "mine")


def test_json_layouts_and_every_scalar_as_docs_eval_md_gives_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A file: metrics at the top level; a folder, even of one sequence: under "sequences".

    ``hota0`` (HOTA at alpha 0.05) was in neither the JSON nor the CSV, which the docs said
    hold every scalar.
    """
    import pftrack
    from pftrack.eval import MotMetrics

    cases = {"A": random_case(0)}
    gt_root, res_root = make_layout(tmp_path, cases)
    docs = {}
    for key, gt in (("file", gt_root / "A" / "gt" / "gt.txt"), ("folder", gt_root)):
        out, table = tmp_path / f"{key}.json", tmp_path / f"{key}.csv"
        argv = ["eval", "--gt", str(gt), "--res", str(res_root / "A.txt")]
        assert main([*argv, "--json", str(out), "--csv", str(table)]) == 0
        docs[key] = json.loads(out.read_text())
        rows = list(csv.DictReader(table.read_text().splitlines()))
        assert len(rows) == 1 and rows[0]["sequence"] == "A" and "hota0" in rows[0]
    capsys.readouterr()
    # one sequence: no "combined"; pftrack's mark first (stop 68: docs/io.md)
    assert list(docs["folder"]) == ["written_by", "sequences"]
    mark = f"pftrack {pftrack.__version__} eval"
    assert docs["file"].pop("written_by") == docs["folder"]["written_by"] == mark
    assert docs["folder"]["sequences"]["A"] == docs["file"]
    metrics = docs["file"]
    h = evaluate_hota(*(read_mot(p) for p in (gt_root / "A/gt/gt.txt", res_root / "A.txt")))
    assert metrics["hota0"] == h.hota0
    scalars = [*h.summary(), "hota0"]
    fields = list(MotMetrics.__dataclass_fields__)
    assert list(metrics) == [*scalars, *fields, "benchmark", "per_alpha"]
    per_alpha = ["hota", "det_a", "ass_a", "loc_a", "tp", "fn", "fp"]
    assert list(metrics["per_alpha"]) == ["alphas", *(f"{k}_per_alpha" for k in per_alpha)]
    text = (Path(__file__).parents[2] / "docs" / "eval.md").read_text()
    section = text[text.index("**`--json` layout.**") : text.index("```python")]
    for name in [*metrics, *metrics["per_alpha"]]:
        assert f"`{name}`" in section, name  # each key is documented


def test_benchmark_help_names_every_measure_its_rules_apply_to(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """It said 'ground-truth rules for HOTA': they choose CLEAR-MOT's and IDF1's rows too."""
    with pytest.raises(SystemExit):
        main(["eval", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "ground-truth rules: which rows HOTA, CLEAR-MOT and IDF1 score" in help_text


def test_a_percentage_that_rounds_to_zero_prints_without_a_sign() -> None:
    """A user trial: a one-row result printed ``MOTA -0.0``."""
    from pftrack.eval.sequences import _pct

    assert [_pct(v) for v in (-1e-6, 0.0, 1e-6, -0.004, float("nan"))] == [
        "0.0", "0.0", "0.0", "-0.4", "-",
    ]  # fmt: skip


def test_a_bad_frame_rate_no_score_uses_does_not_stop_eval(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user report: ``frameRate=0`` in ``seqinfo.ini`` refused ``eval``, which reads only
    the length and image size; the scores are those of the file without the key."""
    gt_root, res_root = make_layout(tmp_path, {"A": random_case(1)})
    argv = ["eval", "--gt", str(gt_root), "--res", str(res_root)]
    assert main(argv) == 0
    before = capsys.readouterr().out
    ini = gt_root / "A" / "seqinfo.ini"
    ini.write_text(ini.read_text() + "frameRate=0\n")
    assert main(argv) == 0, capsys.readouterr().err
    assert capsys.readouterr().out == before
    ini.write_text(ini.read_text().replace("imWidth=200", "imWidth=0"))  # used: still refused
    assert main(argv) == 2
    assert (
        capsys.readouterr().err
        == f"pftrack eval: error: {ini}: imWidth is '0', expected a number > 0\n"
    )


def test_seqs_does_not_read_the_other_sequences_seqinfo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``eval --seqs A`` stopped on a ``seqinfo.ini`` key given twice in B, a
    sequence it was not asked to score."""
    gt_root, res_root = make_layout(tmp_path, {"A": random_case(1), "B": random_case(2)})
    (gt_root / "B" / "seqinfo.ini").write_text("[Sequence]\nframeRate=7\nframeRate=8\n")
    argv = ["eval", "--gt", str(gt_root), "--res", str(res_root)]
    assert main([*argv, "--seqs", "A"]) == 0
    assert "A" in capsys.readouterr().out
    assert main(argv) == 2  # asked for, it is read, and refused
    assert "key frameRate in [Sequence] is given twice" in capsys.readouterr().err


def test_the_gt_folder_of_a_sequence_is_that_sequence(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--gt SEQ/gt`` scores sequence SEQ, as ``--gt SEQ`` and ``--gt SEQ/gt/gt.txt`` do: its
    name (was "gt"), its result in a results folder (was looked for as gt.txt) and its
    seqinfo.ini (a trial)."""
    gt_root, res_root = make_layout(tmp_path, {"SEQ": random_case(0)})
    [seq] = find_sequences(gt_root / "SEQ" / "gt")
    assert seq.name == "SEQ" and (seq.width, seq.height) == (200, 150)
    out = tmp_path / "s.json"
    assert main(["eval", "--gt", str(gt_root / "SEQ" / "gt"), "--res", str(res_root)]) == 0
    assert "SEQ" in capsys.readouterr().out
    argv = ["eval", "--gt", str(gt_root / "SEQ"), "--res", str(res_root), "--json", str(out)]
    assert main(argv) == 0
    want = json.loads(out.read_text())
    argv[2] = str(gt_root / "SEQ" / "gt")
    assert main(argv) == 0
    assert json.loads(out.read_text()) == want
