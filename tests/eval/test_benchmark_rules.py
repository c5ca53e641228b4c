"""Which MOTChallenge rules ``pftrack eval`` applies: TrackEval's folder names, the columns."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.eval import evaluate_sequence, guess_benchmark
from pftrack.eval.rows import result_class_note
from pftrack.eval.sequences import benchmark_of_path
from pftrack.io.mot import read_mot
from tests.conftest import dataset
from tests.eval.cases import write_rows
from tests.eval.test_hota import mot17_case
from tests.eval.test_sequences import make_layout


def trackeval_tree(
    root: Path, split: str, cases: dict[str, tuple[np.ndarray, np.ndarray]]
) -> tuple[Path, Path]:
    """TrackEval's ``gt/mot_challenge/SPLIT/SEQ`` and ``trackers/mot_challenge/SPLIT/mine``.

    Every digit written (:func:`write_rows`), as :func:`~tests.eval.test_hota.trackeval_hota`
    writes its files: both score the same numbers.
    """
    gt = root / "data" / "gt" / "mot_challenge" / split
    res = root / "data" / "trackers" / "mot_challenge" / split / "mine"
    for name, (g, r) in cases.items():
        write_rows(gt / name / "gt" / "gt.txt", g)
        n = int(max(g[:, 0].max(), r[:, 0].max()))
        (gt / name / "seqinfo.ini").write_text(f"[Sequence]\nname={name}\nseqLength={n}\n")
        write_rows(res / "data" / f"{name}.txt", r)
    return gt, res


def eval_json(tmp_path: Path, gt: Path, res: Path, *extra: str) -> dict:
    out = tmp_path / "s.json"
    assert main(["eval", "-q", "--gt", str(gt), "--res", str(res), "--json", str(out), *extra]) == 0
    return json.loads(out.read_text())


def test_benchmark_of_path_reads_trackevals_benchmark_split_folders(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    base = tmp_path / "data" / "gt" / "mot_challenge"

    def bench(*parts: str) -> str | None:
        found = benchmark_of_path(base.joinpath(*parts))
        return None if found is None else found[0]

    assert benchmark_of_path(base / "MOT20-train" / "MOT20-01" / "gt" / "gt.txt") == (
        "MOT20",
        "MOT20-train",
    )
    assert bench("MOT15-test", "ADL-Rundle-6", "gt", "gt.txt") == "MOT15"
    assert bench("MOT16-all", "A", "gt.txt") == "MOT16"
    assert bench("MOT17-train_half", "A", "gt.txt") == "MOT17"
    # the nearest folder wins; sequence names (MOT17-02-FRCNN, MOT16-02) are no split
    assert bench("MOT20-train", "MOT17-02-FRCNN", "gt", "gt.txt") == "MOT20"
    assert bench("MOT15-train", "MOT16-02", "gt", "gt.txt") == "MOT15"
    assert bench("MOT17-02-FRCNN", "gt", "gt.txt") is None
    assert bench("MOT18-train", "A", "gt.txt") is None
    assert bench("mot17-train", "A", "gt.txt") is None  # TrackEval's names are case-sensitive
    assert bench("MOT17-train.txt") is None  # a file's own name is no folder
    # a relative path given from inside the tree
    (base / "MOT20-train" / "A" / "gt").mkdir(parents=True)
    monkeypatch.chdir(base / "MOT20-train")
    assert benchmark_of_path(Path("A") / "gt" / "gt.txt") == ("MOT20", "MOT20-train")


def test_trackevals_mot20_folder_is_scored_by_mot20_rules(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Regression: ``gt/mot_challenge/MOT20-train`` was scored by MOT17 rules (guessed from the
    columns): class-6 boxes (non-MOT vehicles, MOT20 distractors) made false positives."""
    cases = {"A": mot17_case(0), "B": mot17_case(1)}
    assert all(6 in gt[:, 7] for gt, _ in cases.values())
    gt, res = trackeval_tree(tmp_path, "MOT20-train", cases)
    doc = eval_json(tmp_path, gt, res)
    assert "MOT20 ground-truth rules" in capsys.readouterr().out
    for name in cases:
        g, r = read_mot(gt / name / "gt" / "gt.txt"), read_mot(res / "data" / f"{name}.txt")
        want = evaluate_sequence(g, r, benchmark="MOT20")
        assert want.mot.mota != evaluate_sequence(g, r, benchmark="MOT17").mot.mota
        got = doc["sequences"][name]
        assert got["benchmark"] == "MOT20"
        assert got["mota"] == want.mot.mota and got["hota"] == want.hota.hota
    # the folder of benchmark-split folders, one sequence's folder or file: the same rules
    for given in (gt.parent, gt / "A"):
        assert eval_json(tmp_path, given, res)["sequences"]["A"]["benchmark"] == "MOT20", given
    one = eval_json(tmp_path, gt / "A" / "gt" / "gt.txt", res / "data" / "A.txt")
    assert one["benchmark"] == "MOT20"
    capsys.readouterr()
    # --benchmark named wins over the folder's
    assert eval_json(tmp_path, gt, res, "--benchmark", "MOT17")["combined"]["benchmark"] == "MOT17"


def test_trackevals_mot15_folder_scores_mot17_style_columns_by_mot15_rules(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Regression: 9-column ground truth in ``MOT15-train/`` got MOT17 rules; TrackEval, MOT15's."""
    cases = {"A": mot17_case(2)}
    assert guess_benchmark(cases["A"][0]) == "MOT17"
    gt, res = trackeval_tree(tmp_path, "MOT15-train", cases)
    got = eval_json(tmp_path, gt, res)["sequences"]["A"]
    g, r = read_mot(gt / "A" / "gt" / "gt.txt"), read_mot(res / "data" / "A.txt")
    assert got["benchmark"] == "MOT15"
    assert got["mota"] == evaluate_sequence(g, r, benchmark="MOT15").mot.mota
    # the same files outside such a folder: guessed from the columns, as before
    flat_gt, flat_res = make_layout(tmp_path / "flat", cases)
    flat = eval_json(tmp_path, flat_gt, flat_res)
    assert flat["sequences"]["A"]["benchmark"] == "MOT17"
    capsys.readouterr()


def test_mot15_style_truth_in_a_mot17_folder_names_the_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """World coordinates are no classes: the error says the rules came from the folder."""
    gt15 = read_mot(dataset("mot15-gt") / "ADL-Rundle-6" / "gt.txt")[:300]
    gt, res = trackeval_tree(tmp_path, "MOT17-train", {"A": (gt15, gt15.copy())})
    assert main(["eval", "-q", "--gt", str(gt), "--res", str(res)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pftrack eval: error: ") and err.count("\n") == 1
    assert "expected 1-13 for MOT17" in err and "from its folder MOT17-train" in err
    assert main(["eval", "-q", "--gt", str(gt), "--res", str(res), "--benchmark", "MOT15"]) == 0


def test_trackevals_mot20_folder_equals_trackeval(tmp_path: Path) -> None:
    from tests.eval.test_hota import trackeval_hota  # skips without it

    cases = {"A": mot17_case(3), "B": mot17_case(4)}
    ref = trackeval_hota(tmp_path / "te", cases, "MOT20", ("HOTA", "CLEAR", "Identity"))
    gt, res = trackeval_tree(tmp_path, "MOT20-train", cases)
    doc = eval_json(tmp_path, gt, res)
    for name, key in (("A", "A"), ("B", "B"), ("COMBINED", "combined")):
        got = doc["sequences"][name] if name in cases else doc[key]
        assert abs(got["hota"] - float(np.mean(ref[name]["HOTA"]))) < 1e-9
        assert abs(got["mota"] - ref[name]["MOTA"]) < 1e-9
        assert abs(got["idf1"] - ref[name]["IDF1"]) < 1e-9


def test_eight_column_mot17_truth_is_guessed_mot17() -> None:
    """Regression: MOT17 ground truth without its visibility column was guessed MOT15 (the
    missing column reads -1); TrackEval scores it as MOT17."""
    gt, res = mot17_case(0)
    assert guess_benchmark(gt[:, :8]) == "MOT17"  # visibility missing
    assert guess_benchmark(np.c_[gt[:, :8], -np.ones(len(gt))]) == "MOT17"  # -1 everywhere
    assert guess_benchmark(gt) == "MOT17"  # visibility in [0, 1]
    mixed = gt.copy()
    mixed[::2, 8] = -1  # some missing, some not: no visibility column
    assert guess_benchmark(mixed) == "MOT15"
    s = evaluate_sequence(gt[:, :8], res)
    assert s.benchmark == "MOT17"
    assert s.mot.mota == evaluate_sequence(gt, res).mot.mota  # visibility is not read
    # MOT15 ground truth: world x, y, z (normally -1 -1 -1), 10, 8 or 7 columns: still MOT15
    for name in ("ADL-Rundle-6", "ETH-Sunnyday", "KITTI-17"):
        g15 = read_mot(dataset("mot15-gt") / name / "gt.txt")
        assert guess_benchmark(g15) == "MOT15", name
        assert guess_benchmark(g15[:, :8]) == "MOT15", name
        assert guess_benchmark(g15[:, :7]) == "MOT15", name
    for name in ("pets09-s2l1", "tud-campus"):
        assert guess_benchmark(read_mot(dataset(name) / "gt.txt")) == "MOT15", name


def test_eight_column_mot17_truth_is_scored_as_trackeval_scores_it(tmp_path: Path) -> None:
    from tests.eval.test_hota import trackeval_hota  # skips without it

    gt, res = mot17_case(5)
    ref = trackeval_hota(tmp_path, {"s": (gt[:, :8], res)}, "MOT17", ("HOTA", "CLEAR"))
    g = read_mot(tmp_path / "gt" / "s" / "gt" / "gt.txt")
    r = read_mot(tmp_path / "trackers" / "t" / "data" / "s.txt")
    s = evaluate_sequence(g, r)
    assert s.benchmark == "MOT17"
    assert abs(s.mot.mota - ref["s"]["MOTA"]) < 1e-9
    assert abs(s.hota.hota - float(np.mean(ref["s"]["HOTA"]))) < 1e-9


def test_result_classes_other_than_pedestrian_are_warned_about(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Regression: result boxes of other classes (column 8) were scored as pedestrians, silently;
    TrackEval refuses such a result under MOT16/17/20 rules."""
    gt, res = mot17_case(0)
    res[:12, 7] = 3
    res[12:14, 7] = 2
    res[14:20, 7] = 1  # pedestrians and -1 (no class) are what results hold
    gt_root, res_root = make_layout(tmp_path, {"A": (gt, res)})
    argv = ["eval", "-q", "--gt", str(gt_root), "--res", str(res_root)]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert captured.err == (
        f"pftrack eval: warning: {res_root / 'A.txt'}: 14 result boxes have classes 3 (12), "
        "2 (2) in column 8: scored as pedestrians; TrackEval refuses such a file\n"
    )
    assert "HOTA" in captured.out
    res[12:14, 7] = -1
    write_rows(res_root / "A.txt", res)
    assert main(argv) == 0
    assert capsys.readouterr().err == (
        f"pftrack eval: warning: {res_root / 'A.txt'}: 12 result boxes have class 3 in column "
        "8: scored as pedestrians; TrackEval refuses such a file\n"
    )
    # MOT15 rules have no classes: nothing to say
    assert main([*argv, "--benchmark", "MOT15"]) == 0
    assert capsys.readouterr().err == ""
    # class 0 is not refused by TrackEval (it refuses classes above 1)
    note = result_class_note(np.c_[res[:, :7], np.zeros(len(res))], "MOT17")
    assert note == f"{len(res)} result boxes have class 0 in column 8: scored as pedestrians"
    assert result_class_note(res, "MOT15") is None
    assert result_class_note(np.c_[res[:, :7], np.full(len(res), 12.5)], "MOT17") is None


def test_ground_truth_with_scores_in_its_flag_column_is_warned_about(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Regression: another tracker's output given as the ground truth (scores in (0, 1) in
    column 7, which TrackEval truncates to the "consider" flag 0) scored nothing (GT 0, every
    result box a false positive) without a word."""
    gt, res = mot17_case(0)
    g = gt[gt[:, 6] == 1].copy()
    g[:, 6] = np.linspace(0.2, 0.99, len(g))
    g[-3:, 6] = 1.0
    write_rows(tmp_path / "gt.txt", g)
    write_rows(tmp_path / "res.txt", res)
    argv = ["eval", "-q", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path / "res.txt")]
    assert main([*argv, "--benchmark", "MOT15"]) == 0
    n = len(g) - 3
    assert capsys.readouterr().err == (
        f"pftrack eval: warning: {tmp_path / 'gt.txt'}: {n} of {len(g)} ground-truth rows have "
        "a conf (column 7, the consider flag: 0 or 1) that is not an integer (the first 0.2, in "
        f"frame {int(g[0, 0])}): TrackEval truncates it, so {n} of the rows are 0 and not "
        "scored; a tracker's scores? set column 7 to 1 to score every row\n"
    )
    g[:, 6] = 1.0  # flags: nothing to say
    write_rows(tmp_path / "gt.txt", g)
    assert main([*argv, "--benchmark", "MOT15"]) == 0
    assert capsys.readouterr().err == ""


def test_real_data_gives_no_class_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = dataset("pets09-s2l1").parent
    for name in ("pets09-s2l1", "tud-campus"):
        det = read_mot(data / name / "det.txt")
        assert result_class_note(det, "MOT17") is None, name
    res = tmp_path / "tud-campus.txt"
    res.write_text((data / "tud-campus" / "gt.txt").read_text())
    assert main(["eval", "-q", "--gt", str(data / "tud-campus" / "gt.txt"), "--res", str(res)]) == 0
    assert capsys.readouterr().err == ""


def test_flags_and_classes_beyond_int64_or_nan_are_read_without_a_cast_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Regression: a ground-truth flag (column 7) of 1e20 in a file, or NaN in an array, and a
    result class of 1e20, went through ``astype(int64)``: ``pftrack eval: warning: invalid
    value encountered in cast`` (a RuntimeWarning, an error under ``-W error``), and the
    result's note named ``class -9223372036854775808``."""
    gt, res = mot17_case(0)
    base = evaluate_sequence(gt, res, benchmark="MOT17")
    for flag in (1e20, np.nan, -1e20):  # not 0 once truncated: scored, as TrackEval scores it
        g = gt.copy()
        g[g[:, 6] != 0, 6] = flag
        s = evaluate_sequence(g, res, benchmark="MOT17")  # pytest turns warnings into errors
        assert (s.hota.hota, s.mot.mota) == (base.hota.hota, base.mot.mota), flag
    g = gt.copy()
    g[g[:, 6] != 0, 6] = 1e20
    (tmp_path / "gt.txt").write_text("".join(
        ",".join(f"{v:.17g}" for v in row) + "\n" for row in g
    ))  # fmt: skip
    write_rows(tmp_path / "res.txt", res)
    argv = ["eval", "-q", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path / "res.txt")]
    assert main([*argv, "--benchmark", "MOT17"]) == 0
    assert capsys.readouterr().err == ""
    r = res.copy()
    r[:3, 7] = 1e20
    r[3:5, 7] = 3
    note = result_class_note(r, "MOT17")
    assert note == (
        "5 result boxes have classes 1e+20 (3), 3 (2) in column 8: scored as pedestrians; "
        "TrackEval refuses such a file"
    )


def test_a_result_that_matches_nothing_is_warned_about(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A CLI trial: TUD-Campus's tracks scored against PETS09's ground truth gave a table of
    zeros (MOTA -6.9) without a word. A result none of whose boxes matches is named."""
    gt, res = mot17_case(0)
    gt = gt[gt[:, 6] == 1]
    write_rows(tmp_path / "gt.txt", gt)
    other = res.copy()
    other[:, 2] = (other[:, 2] + 400) % 1500  # the boxes of another scene, the same sizes
    other[:, 3] = (other[:, 3] + 300) % 800
    write_rows(tmp_path / "res.txt", other)
    argv = ["eval", "-q", "--gt", str(tmp_path / "gt.txt"), "--res", str(tmp_path / "res.txt")]
    assert main([*argv, "--benchmark", "MOT15"]) == 0

    def span(a: np.ndarray) -> str:
        return f"frames {int(a[:, 0].min())}-{int(a[:, 0].max())}"

    assert capsys.readouterr().err == (
        f"pftrack eval: warning: {tmp_path / 'res.txt'}: none of its {len(other)} boxes "
        f"({span(other)}) matches a ground-truth box of {tmp_path / 'gt.txt'} ({span(gt)}) with "
        "IoU 0.5 or more, on any frame: the tracks of another sequence or video, or frames "
        "numbered otherwise?\n"
    )
    write_rows(tmp_path / "res.txt", res)  # its own result: nothing to say
    assert main([*argv, "--benchmark", "MOT15"]) == 0
    assert capsys.readouterr().err == ""
