"""``pftrack experiment gaps`` on ground truth with holes and with repeated rows.

Regressions of the user trial: a trajectory that skips frames (any tracker's output, ground
truth with holes) failed with "operands could not be broadcast together" (the recovered path
covers every frame of the gap, the truth only the frames it has); a repeated (frame, id) failed
with "recover_gap: segment_a frames must increase strictly" instead of naming the lines.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import write_mot
from pftrack.recovery import experiment as E


def _walkers(n_ids: int = 12, n_frames: int = 120, seed: int = 0) -> np.ndarray:
    """Ground truth of walkers crossing a 768x576 image, one row per frame."""
    rng = np.random.default_rng(seed)
    rows = []
    t = np.arange(1, n_frames + 1, dtype=np.float64)
    for tid in range(1, n_ids + 1):
        start = rng.uniform([100, 100], [650, 450])
        v = rng.uniform(-2, 2, 2)
        xy = start + np.outer(t, v) + np.cumsum(rng.normal(0, 0.4, (n_frames, 2)), axis=0)
        xy = np.clip(xy, 20, [740, 550])
        r = np.zeros((n_frames, 10))
        r[:, 0], r[:, 1], r[:, 2:4], r[:, 4:6], r[:, 6], r[:, 7:] = t, tid, xy - 10, 20, 1, -1
        rows.append(r)
    return np.vstack(rows)


def _holed(gt: np.ndarray) -> np.ndarray:
    """Every 5th row left out, as ``awk -F, 'NR%5!=0'`` does: holes inside every track."""
    return gt[np.arange(len(gt)) % 5 != 4]


def test_gaps_of_a_trajectory_with_holes_are_scored_where_the_truth_has_points() -> None:
    gt = _holed(_walkers())
    trajs = E.trajectories(gt)
    masks = E.auto_masks(trajs, 768, 576)
    run = E.run_mask(trajs, masks[0], ["linear", "rts", "auto"])
    assert run.gaps
    holed = [g for g in run.gaps if len(g.truth) < g.segment_b[0, 0] - g.segment_a[-1, 0] - 1]
    assert holed  # some gap skips frames: its path is longer than its truth
    for g, p in zip(run.gaps, run.paths["linear"], strict=True):
        assert len(p) == g.segment_b[0, 0] - g.segment_a[-1, 0] - 1
        at = g.at_truth(p)
        assert at.shape == (len(g.truth), 2)
        # the straight line between the segments' ends, at the truth's frames
        f0, f1 = g.segment_a[-1, 0], g.segment_b[0, 0]
        s = (g.truth[:, 0] - f0) / (f1 - f0)
        want = (1 - s)[:, None] * g.segment_a[-1, 1:3] + s[:, None] * g.segment_b[0, 1:3]
        np.testing.assert_allclose(at, want, atol=1e-9)
        np.testing.assert_allclose(g.errors(p), np.hypot(*(want - g.truth[:, 1:3]).T))
    pairs = zip(run.gaps, run.paths["linear"], strict=True)
    linear = np.mean([g.errors(p).mean() for g, p in pairs])
    assert run.scores["linear"].mmae_total == pytest.approx(linear)
    res = E.run_sequence("holed", trajs, 768, 576, ["linear", "gdt-mix"])
    assert res.n_gaps > 0 and np.isfinite(res.mmae("gdt-mix"))


def test_trajectories_without_holes_score_as_before() -> None:
    """The full truth: every gap frame has a point, at_truth is the whole path."""
    trajs = E.trajectories(_walkers())
    run = E.run_mask(trajs, E.auto_masks(trajs, 768, 576)[0], ["linear"])
    for g, p in zip(run.gaps, run.paths["linear"], strict=True):
        assert np.array_equal(g.at_truth(p), p)


@pytest.mark.parametrize("multi", [False, True])
def test_cli_runs_on_ground_truth_with_holes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], multi: bool
) -> None:
    gt = tmp_path / "base.txt"
    write_mot(gt, _holed(_walkers()))
    argv = ["experiment", "gaps", "--gt", str(gt), "--image-size", "768x576", "--methods",
            "linear,auto"]  # fmt: skip
    argv += ["--auto-masks"] if multi else ["--max-positions", "3", "--repeat", "1"]
    assert main(argv) == 0, capsys.readouterr().err
    assert "MMAE" in capsys.readouterr().out


def test_repeated_rows_are_named_by_file_and_line_as_recover_names_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = tmp_path / "gt.txt"
    write_mot(gt, _walkers(n_ids=3, n_frames=30))
    lines = gt.read_text().splitlines()
    gt.write_text("\n".join([*lines, lines[4]]) + "\n")  # line 91 repeats line 5
    errors = []
    for argv in (
        ["experiment", "gaps", "--gt", str(gt), "--image-size", "768x576"],
        ["experiment", "gaps", "--gt", str(gt), "--auto-masks", "--image-size", "768x576"],
        ["recover", str(gt), "--out", str(tmp_path / "out.txt")],
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        errors.append(err.split(": error: ", 1)[1])
    assert errors[0] == errors[1] == errors[2]
    assert errors[0].startswith(f"{gt}:91: duplicate rows for frame 2, id 2 (lines 5 and 91)")
    with pytest.raises(ValueError, match="duplicate rows for frame 5, id 1"):
        E.trajectories(np.vstack([_walkers(3, 30), _walkers(3, 30)[4:5]]))


@pytest.mark.parametrize(
    ("ini", "message"),
    [
        # was "auto_masks: image size is 0x370, expected > 0" (an internal function, no file)
        ("imWidth=0\nimHeight=370", "imWidth is '0', expected a number > 0"),
        # was "auto_masks: mask side 1.30208e+08 px exceeds the image 1e+09x370"
        ("imWidth=1e9\nimHeight=370", "imWidth is '1e9', expected an integer in 1..100000"),
        # was "expected [Sequence] imWidth and imHeight", though both keys are there
        ("imWidth=abc\nimHeight=370", "imWidth is 'abc', expected a number > 0"),
        ("imWidth=768\nimHeight=", "imHeight is empty; give a value or leave the key out"),
        ("imWidth=768", "no imHeight in [Sequence]; the image size of the ground truth needs"),
        ("imWidth=1000\nimHeight=50", "imWidth x imHeight 1000x50 cannot hold the masks: their "
                                      "side is round(100 W/768) = 130 px"),
    ],
)  # fmt: skip
def test_a_bad_seqinfo_is_named_with_its_key_and_value(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], ini: str, message: str
) -> None:
    seq = tmp_path / "SEQ"
    (seq / "gt").mkdir(parents=True)
    write_mot(seq / "gt" / "gt.txt", _walkers(n_ids=3, n_frames=30))
    (seq / "seqinfo.ini").write_text(f"[Sequence]\n{ini}\n")  # one folder up: read too
    assert main(["experiment", "gaps", "--gt", str(seq / "gt" / "gt.txt"), "--auto-masks"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pftrack experiment gaps: error: {seq / 'seqinfo.ini'}: {message}"), err
    assert err.count("\n") == 1


@pytest.mark.parametrize("multi", [False, True])
@pytest.mark.parametrize("unused", ["frameRate=0", "seqLength=0.5"])
def test_a_bad_value_the_experiment_does_not_use_does_not_stop_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], unused: str, multi: bool
) -> None:
    """A user report: ``frameRate=0`` beside the ground truth refused the experiment, which
    uses only the name and image size of ``seqinfo.ini`` (the gaps are in frames)."""
    seq = tmp_path / "SEQ"
    (seq / "gt").mkdir(parents=True)
    write_mot(seq / "gt" / "gt.txt", _walkers())
    (seq / "seqinfo.ini").write_text(
        f"[Sequence]\nname=WALK\nimWidth=768\nimHeight=576\n{unused}\n"
    )
    argv = ["experiment", "gaps", "--gt", str(seq / "gt" / "gt.txt"), "--methods", "linear"]
    argv += ["--auto-masks"] if multi else ["--max-positions", "2", "--repeat", "1"]
    assert main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "MMAE" in out
    assert "768" in out  # the image size was read from seqinfo.ini all the same


@pytest.fixture
def walkers_gt(tmp_path: Path) -> Path:
    """A ground-truth file of three walkers over 30 frames (768x576)."""
    gt = tmp_path / "gt.txt"
    write_mot(gt, _walkers(n_ids=3, n_frames=30))
    return gt


def test_a_method_named_twice_is_refused(
    walkers_gt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``--methods linear,linear`` counted each mask position twice."""
    argv = ["experiment", "gaps", "--gt", str(walkers_gt), "--image-size", "768x576", "--methods",
            "linear,auto,linear"]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == (
        "pftrack experiment gaps: error: --methods names linear more than once; name each once\n"
    )


def test_a_mask_outside_the_image_is_refused(
    walkers_gt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``--mask 10000,10000,5,5`` on a 768x576 image said "no gap under this
    mask", exit 0, and skipped the sweep."""
    base = ["experiment", "gaps", "--gt", str(walkers_gt), "--image-size", "768x576", "--methods",
            "linear"]  # fmt: skip
    for mask in ("10000,10000,5,5", "700,0,100,100", "-1,0,10,10"):
        assert main([*base, f"--mask={mask}"]) == 2
        assert capsys.readouterr().err == (
            f"pftrack experiment gaps: error: --mask {mask} is not inside the 768x576 image "
            "(x, y >= 0, x + w <= width, y + h <= height)\n"
        )


def test_fewer_masks_than_asked_are_said(
    walkers_gt: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``--n-masks 50`` placed 10 on TUD-Campus, without a word."""
    argv = ["experiment", "gaps", "--gt", str(walkers_gt), "--image-size", "768x576",
            "--auto-masks", "--n-masks", "50", "--methods", "linear"]  # fmt: skip
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main(argv) == 0
    err = capsys.readouterr().err
    assert re.fullmatch(
        rf"pftrack experiment gaps: warning: {walkers_gt.parent.name}: \d+ of the 50 masks asked "
        r"for were placed \(no more fit without overlapping, or none more cuts a gap\)\n",
        err,
    ), err


def test_too_small_an_image_size_is_named_for_its_sequence(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = tmp_path / "walk.txt"
    write_mot(gt, _walkers(n_ids=3, n_frames=30))
    argv = ["experiment", "gaps", "--gt", str(gt), "--auto-masks", "--image-size", "768x50"]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"pftrack experiment gaps: error: {gt}: --image-size 768x50 cannot hold the masks: their "
        "side is round(100 W/768) = 100 px\n"
    )


def test_a_sequence_without_a_gap_says_so_and_the_pooled_figures_leave_it_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: a row of nan for the sequence, exit 0, nothing said."""
    import json
    import warnings

    walk, tiny = tmp_path / "walk.txt", tmp_path / "tiny.txt"
    write_mot(walk, _walkers(n_ids=6, n_frames=60))
    tiny.write_text("1,1,10,10,20,40\n5,1,20,10,20,40\n")  # one track of two rows: no gap
    out = tmp_path / "o.json"
    argv = ["experiment", "gaps", "--gt", str(walk), str(tiny), "--image-size", "768x576",
            "--methods", "linear,rts", "--json", str(out)]  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main(argv) == 0
    said = capsys.readouterr()
    assert "nan" not in said.out
    assert said.err == (
        "pftrack experiment gaps: warning: tiny: no gap under any mask (no mask position cuts a "
        "trajectory that is observed on both sides of it): no MMAE, and nothing of it in the "
        "pooled figures\n"
    )
    mmae, excess = said.out.split("\n\nlinear against the best other method of each row")
    lines = mmae.splitlines()
    assert "tiny (768x576): 0 gaps, masks none" in lines
    row = {line.split()[0]: line for line in lines if line.startswith(("walk", "tiny", "pooled"))}
    assert row["tiny"].split(None, 2)[1:] == ["0", E.NO_GAPS]
    assert row["pooled"].split()[1:] == row["walk"].split()[1:]  # the gaps of walk alone
    # linear against rts, on walk and pooled (the same gaps); nothing for tiny
    n = row["walk"].split()[1]
    assert [line.split()[:3] for line in excess.splitlines()[2:4]] == [
        ["walk", n, "rts"], ["pooled", n, "rts"]]  # fmt: skip
    doc = json.loads(out.read_text())
    assert doc["sequences"][1]["mmae"] == {"linear": None, "rts": None}
    assert doc["pooled"]["mmae"] == doc["sequences"][0]["mmae"]
    assert [(e["name"], e["method"], e["best"]) for e in doc["excess"]] == [
        ("walk", "linear", "rts"), ("pooled", "linear", "rts")]  # fmt: skip
    assert doc["excess"][0]["diff"] == pytest.approx(
        doc["sequences"][0]["mmae"]["linear"] - doc["sequences"][0]["mmae"]["rts"]
    )
    argv = ["experiment", "gaps", "--gt", str(tiny), "--auto-masks", "--image-size", "768x576"]
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        assert main(argv) == 0
    said = capsys.readouterr()
    assert "pooled           0  no gaps in any sequence: no MMAE" in said.out
    assert said.err.startswith("pftrack experiment gaps: warning: tiny: no gap under any mask")


def test_python_errors_name_the_function_and_argument() -> None:
    """Was: "fill_gaps: method is 'nope'" from smooth_tracks, and no prefix on duplicates."""
    from pftrack.recovery import fill_gaps, link_tracklets
    from pftrack.recovery.linking import LinkConfig
    from pftrack.tracking import smooth_tracks

    rows = _walkers(n_ids=2, n_frames=10)
    with pytest.raises(ValueError, match=r"^smooth_tracks: fill_method is 'nope', expected one"):
        smooth_tracks(rows[rows[:, 0] != 5], fill_method="nope")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^smooth_tracks: fill_method is 'nope'"):
        smooth_tracks(rows, link=None, fill_method="nope")  # type: ignore[arg-type]
    twice = np.vstack([rows, rows[3:4]])
    for who, call in (
        ("fill_gaps", lambda: fill_gaps(twice)),
        ("smooth_tracks", lambda: smooth_tracks(twice)),
        ("smooth_tracks", lambda: smooth_tracks(twice, link=None)),  # was BoxSmoother.smooth's
        ("link_tracklets", lambda: link_tracklets(twice, LinkConfig())),
        ("trajectories", lambda: E.trajectories(twice)),
    ):
        with pytest.raises(ValueError, match=rf"^{who}: duplicate rows for frame 4, id 1: each"):
            call()
    dets = rows.copy()
    dets[:, 1] = -1
    with pytest.raises(
        ValueError,
        match=r"^fill_gaps: duplicate rows for frame 1, id -1: .*; "
        r"every id is -1: this looks like untracked detections \(a det\.txt\)",
    ):
        fill_gaps(dets)


def test_recover_of_a_detection_file_says_it_needs_tracks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    det = tmp_path / "det.txt"
    det.write_text("1,-1,10,10,20,40,0.9\n1,-1,50,10,20,40,0.8\n2,-1,11,10,20,40,0.9\n")
    assert main(["recover", str(det), "--out", str(tmp_path / "o.txt")]) == 2
    assert capsys.readouterr().err == (
        f"pftrack recover: error: {det}:2: duplicate rows for frame 1, id -1 (lines 1 and 2): "
        "each (frame, id) may appear once; every id is -1: this looks like untracked "
        "detections (a det.txt), not tracks (pftrack track SOURCE --detections FILE makes "
        "tracks of them)\n"
    )


NO_TRACK = (
    "-1 is MOTChallenge's id of a box no track holds (an unassociated detection), not a "
    "track; drop those rows, or make tracks of them (pftrack track SOURCE --detections FILE)"
)
BELOW_MINUS_1 = (
    "track ids must be >= 0, as pftrack eval and TrackEval require them (-1 alone has a "
    "meaning: a box no track holds); renumber the tracks"
)


@pytest.mark.parametrize(("bad", "why"), [(-1, NO_TRACK), (-5, BELOW_MINUS_1)])
def test_rows_of_negative_ids_among_tracks_are_refused(bad: int, why: str) -> None:
    """-1 (MOTChallenge's unassociated boxes) among tracks: were joined into one track (holes
    between unrelated detections filled, smoothed and linked). Other negative ids (-5): were a
    track filled, smoothed and linked, where ``pftrack eval`` (and TrackEval: an IndexError, or
    id -5 scored as another id) refuse it: ids must be >= 0 everywhere."""
    from pftrack.recovery import fill_gaps, link_tracklets
    from pftrack.recovery.linking import LinkConfig
    from pftrack.tracking import smooth_tracks
    from pftrack.tracking.offline import repair_crossings

    rows = _walkers(n_ids=2, n_frames=10)
    neg = np.array([[5, bad, 300, 200, 20, 40, 0.5, -1, -1, -1],
                    [1, bad, 100, 100, 20, 40, 0.5, -1, -1, -1]])  # fmt: skip
    mixed = np.vstack([rows, neg])
    for who, call in (
        ("fill_gaps", lambda: fill_gaps(mixed)),
        ("smooth_tracks", lambda: smooth_tracks(mixed)),
        ("link_tracklets", lambda: link_tracklets(mixed, LinkConfig())),
        ("repair_crossings", lambda: repair_crossings(mixed)),
    ):
        with pytest.raises(ValueError) as exc:
            call()
        assert str(exc.value) == f"{who}: row 20 has id {bad} (frame 5; 2 rows have it): {why}"


def test_id_0_is_a_track() -> None:
    from pftrack.recovery import fill_gaps

    rows = _walkers(n_ids=2, n_frames=10)
    neg = np.array([[5, -5, 300, 200, 20, 40, 0.5, -1, -1, -1],
                    [1, -5, 100, 100, 20, 40, 0.5, -1, -1, -1]])  # fmt: skip
    zero = np.vstack([rows, neg * [1, 0, 1, 1, 1, 1, 1, 1, 1, 1]])  # id 0: a track
    assert len(fill_gaps(zero)[0]) == 20 + 2 + 3  # its hole of frames 2-4 filled


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_recover_of_tracks_with_id_minus_1_rows_refuses_them(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: exit 0, the two id -1 rows (frames 1 and 5) joined by 3 filled rows."""
    src, out = tmp_path / "t.txt", tmp_path / "o.txt"
    src.write_text(
        "1,1,10,10,20,40,1\n2,1,12,10,20,40,1\n3,1,14,10,20,40,1\n1,-1,300,200,20,40,0.5\n"
        "5,-1,100,100,20,40,0.5\n6,1,20,10,20,40,1\n"
    )
    assert main([command, str(src), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack {command}: error: {src}:4: id -1 in frame 1 (2 rows have it): -1 is "
        "MOTChallenge's id of a box no track holds (an unassociated detection), not a track; "
        "drop those rows, or make tracks of them (pftrack track SOURCE --detections FILE)\n"
    )
    assert not out.exists()


@pytest.mark.parametrize("command", ["recover", "smooth", "eval"])
def test_a_file_of_negative_ids_is_refused_by_every_command_naming_its_line(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: recover and smooth filled the hole of track -5 (exit 0), where eval refused it
    without naming the line."""
    src = tmp_path / "t.txt"
    out = tmp_path / ("o.csv" if command == "eval" else "o.txt")
    src.write_text(
        "1,1,10,10,20,40,1\n2,1,12,10,20,40,1\n1,-5,300,200,20,40,0.5\n"
        "5,-5,100,100,20,40,0.5\n6,1,20,10,20,40,1\n"
    )
    gt = tmp_path / "gt.txt"
    gt.write_text("1,1,10,10,20,40,1\n1,2,300,200,20,40,1\n")
    argv = ["--gt", str(gt), "--res", str(src)] if command == "eval" else [str(src)]
    assert main([command, *argv, "--out" if command != "eval" else "--csv", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack {command}: error: {src}:3: id -5 in frame 1 (2 rows have it): track ids must "
        "be >= 0, as pftrack eval and TrackEval require them (-1 alone has a meaning: a box no "
        "track holds); renumber the tracks\n"
    )
    assert not out.exists()


def test_paired_excess_is_the_mean_difference_to_the_best_other_method_and_its_error() -> None:
    """Worked numbers: per sequence and pooled, against the other method of lowest MMAE."""
    a = E.SequenceResult("a", (768.0, 576.0), (), 3, {
        "auto": (2.0, 3.0, 4.0), "linear": (1.0, 3.0, 2.0), "rts": (3.0, 3.0, 3.0)})  # fmt: skip
    b = E.SequenceResult("b", (768.0, 576.0), (), 1, {
        "auto": (1.0,), "linear": (4.0,), "rts": (2.0,)})  # fmt: skip
    none = E.SequenceResult("none", (768.0, 576.0), (), 0, {"auto": (), "linear": (), "rts": ()})
    got = E.paired_excess([a, none, b], "auto")
    assert [(e.name, e.best, e.n_gaps) for e in got] == [
        ("a", "linear", 3), ("b", "rts", 1), ("pooled", "linear", 4)]  # fmt: skip
    d = np.array([1.0, 0.0, 2.0])  # auto less linear on a
    assert got[0].diff == pytest.approx(1.0)
    assert got[0].se == pytest.approx(d.std(ddof=1) / np.sqrt(3))
    assert got[0].share == pytest.approx(1.0 / 2.0)
    assert (got[1].diff, got[1].share) == (-1.0, -0.5) and np.isnan(got[1].se)  # one gap
    pooled = np.array([2.0, 3.0, 4.0, 1.0]) - np.array([1.0, 3.0, 2.0, 4.0])  # linear 2.5 < 2.75
    assert (got[2].diff, got[2].se) == pytest.approx((0.0, pooled.std(ddof=1) / 2))
    table = E.format_excess(got).splitlines()
    assert table[2].split() == ["a", "3", "linear", "+1.000", "±", "0.577", "+50.0", "%"]
    assert table[3].split() == ["b", "1", "rts", "-1.000", "±", "-", "-50.0", "%"]  # not nan
    with pytest.raises(ValueError, match=r"paired_excess: 'gdt' is not among the methods"):
        E.paired_excess([a], "gdt")
