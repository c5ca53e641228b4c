"""``pftrack demo`` and ``pftrack track`` end to end, through :func:`pftrack.cli.main`."""

from __future__ import annotations

import argparse
import inspect
import os
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import pftrack
from pftrack.cli import build_parser, main
from pftrack.eval import evaluate_mot, format_metrics
from pftrack.io.mot import read_mot, write_mot
from pftrack.synthetic import Scene, make_scene
from pftrack.tracking import TrackerConfig
from tests.earlier_outputs import TRACKS


@pytest.fixture(scope="module")
def scene() -> Scene:
    # seed 0: walkers enter after frame 1 (people present from the first frame defeat the
    # built-in background model; seeds 2 and 3 of this length show it: MOTA 0 and 0.16)
    return make_scene(n_frames=60, rng=0)


@pytest.fixture(scope="module")
def video(scene: Scene, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return scene.write_video(tmp_path_factory.mktemp("video") / "scene.avi")


def test_demo_writes_its_outputs_and_scores_the_scene(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "demo"
    assert main(["demo", "--out-dir", str(out), "--frames", "60", "--particles", "40"]) == 0
    text = capsys.readouterr().out
    for name in ("tracks.txt", "truth.txt", "annotated.mp4", "trajectories.png"):
        assert (out / name).stat().st_size > 0, name
    # the printed MOTA is the one the written files give
    truth, tracks = read_mot(out / "truth.txt"), read_mot(out / "tracks.txt")
    mota = evaluate_mot(truth, tracks, image_size=(480, 360)).mota
    assert f"{100 * mota:.1f}" in text
    assert mota > 0.5, text


def test_demo_prints_the_scores_of_the_files_it_writes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # seed 2 (150 frames): was scored on the unrounded rows, MOTA 16.1 with 175 FP, where
    # pftrack eval of the written tracks.txt gives 15.7 with 176 FP
    out = tmp_path / "demo"
    assert main(["demo", "--out-dir", str(out), "--seed", "2"]) == 0
    printed = next(r for r in capsys.readouterr().out.splitlines() if r.startswith("pftrack  "))
    truth, tracks = read_mot(out / "truth.txt"), read_mot(out / "tracks.txt")
    m = evaluate_mot(truth, tracks, image_size=(480, 360))
    assert format_metrics({"pftrack": m}).splitlines()[1] == printed


def test_track_own_detector_finds_the_walkers(
    video: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "tracks.txt"
    assert main(["track", str(video), "--out", str(out), "--particles", "40"]) == 0
    assert f"-> {out}" in capsys.readouterr().out
    rows = read_mot(out)
    assert rows.shape[1] == 10 and len(rows) > 0
    assert rows[:, 0].min() >= 1 and rows[:, 0].max() <= 60
    m = evaluate_mot(scene.truth, rows)
    assert m.mota > 0.6 and m.idf1 > 0.75  # measured 0.68 / 0.82 through the MJPG file


def test_track_is_reproducible_and_seed_dependent(video: Path, tmp_path: Path) -> None:
    a, b, c = (tmp_path / f"{k}.txt" for k in "abc")
    for path, seed in ((a, "1"), (b, "1"), (c, "2")):
        assert main(["track", str(video), "--out", str(path), "--seed", seed, "--no-smooth",
                     "--particles", "40"]) == 0  # fmt: skip
    assert a.read_bytes() == b.read_bytes()
    assert a.read_bytes() != c.read_bytes()


def test_track_with_public_detections_matches_the_truth(
    video: Path, scene: Scene, tmp_path: Path
) -> None:
    det = scene.truth.copy()
    det[:, 1] = -1
    det[:, 6] = 1.0
    write_mot(tmp_path / "det.txt", det)
    out = tmp_path / "tracks.txt"
    args = ["track", str(video), "--detections", str(tmp_path / "det.txt"), "--out", str(out)]
    assert main(args) == 0
    m = evaluate_mot(scene.truth, read_mot(out))
    assert m.mota > 0.8 and m.idf1 > 0.8


@pytest.mark.parametrize("value", ["0", "1", "1.5", "nan", "-0.2"])
def test_size_ratio_out_of_its_range_is_refused(
    value: str, video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["track", str(video), "--out", str(tmp_path / "t.txt"), "--detections", "d.txt"]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--size-ratio", value])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == (
        f"pftrack track: error: argument --size-ratio: expected a number in (0, 1) or off, got "
        f"{float(value):g}"
    )


def test_size_ratio_without_the_smoother_is_refused(
    video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "t.txt"
    argv = ["track", str(video), "--out", str(out), "--detections", "d.txt", "--no-smooth"]
    assert main([*argv, "--size-ratio", "0.7"]) == 2
    assert capsys.readouterr().err == (
        "pftrack track: error: --size-ratio 0.7 judges the smoothed tracks, and --no-smooth "
        "turns the smoother off; drop one of them\n"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["track", "missing.avi", "--out", "t.txt"], "missing.avi"),
        (["track", "{video}", "--out", "{video}"], "is an input of this run"),
        (["track", "{video}", "--out", "."], "is a folder"),
        (["track", "{video}", "--out", "nowhere/t.txt"], "does not exist"),
        (["track", "{video}", "--out", "t.txt", "--render", "a.xyz"], "unsupported extension"),
        (["track", "{video}", "--out", "t.txt", "--plot", "p.txt"], "unsupported extension"),
        (["track", "{video}", "--out", "t.txt", "--detections", "nothing.txt"], "nothing.txt"),
    ],
)
def test_track_bad_input_is_one_line_and_exit_2(
    argv: list[str],
    message: str,
    video: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([a.format(video=video) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("pftrack track: error:") and message in err
    assert "\n" not in err
    assert not (tmp_path / "t.txt").exists()


def test_help_shows_defaults(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["track", "--help"])
    assert exc.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: paper)" in text and "(default: 0)" in text
    assert "0: 200 with --detections for sis and mh, else 100 (default: 0)" in text


def test_every_row_is_inside_the_scene(video: Path, scene: Scene, tmp_path: Path) -> None:
    out = tmp_path / "tracks.txt"
    assert main(["track", str(video), "--out", str(out), "--particles", "40"]) == 0
    rows = read_mot(out)
    left, top, right, bottom = (
        rows[:, 2],
        rows[:, 3],
        rows[:, 2] + rows[:, 4],
        rows[:, 3] + rows[:, 5],
    )
    assert np.all((right > 0) & (bottom > 0) & (left < scene.width) & (top < scene.height))


def test_recover_explain_prints_the_choice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(3)
    rows = []
    for tid in range(1, 7):
        t = np.arange(1, 101, dtype=np.float64)
        xy = 200 + np.cumsum(rng.uniform(-2, 2, (100, 2)), axis=0)
        keep = (t < 40) | (t > 47)
        r = np.zeros((int(keep.sum()), 10))
        r[:, 0] = t[keep]
        r[:, 1] = tid
        r[:, 2:4] = xy[keep] - 10
        r[:, 4:6] = 20
        r[:, 6] = 1
        r[:, 7:] = -1
        rows.append(r)
    src = tmp_path / "in.txt"
    write_mot(src, np.vstack(rows))
    out = tmp_path / "out.txt"
    assert main(["recover", str(src), "--out", str(out), "--explain"]) == 0
    text = capsys.readouterr().out
    assert "(auto," in text and "chosen" in text and "8 " in text.split("chosen")[1]
    assert len(read_mot(out)) == sum(len(r) for r in rows) + 6 * 8


def test_recover_help_does_not_say_two_blended_methods(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Regression (user trial): ``--explain`` was said to print "the two methods it blends";
    with bagging (the default) a bucket may blend up to every candidate."""
    with pytest.raises(SystemExit):
        main(["recover", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "two methods" not in text
    assert "or more when bagging averages the resamples' choices" in text


def test_experiment_gaps_several_sequences_writes_json(tmp_path: Path) -> None:
    import json

    rng = np.random.default_rng(4)
    paths = []
    for k in range(2):
        seq = tmp_path / f"SEQ{k}"
        (seq / "gt").mkdir(parents=True)
        (seq / "seqinfo.ini").write_text(
            f"[Sequence]\nname=SEQ{k}\nframeRate=25\nimWidth=768\nimHeight=576\n"
        )
        rows = []
        for tid in range(1, 16):
            t = np.arange(1, 151, dtype=np.float64)
            start = rng.uniform(100, 600, 2)
            xy = start + np.cumsum(rng.normal(0, 0.5, (150, 2)) + rng.uniform(-2, 2, 2), axis=0)
            xy = np.clip(xy, 20, [740, 550])
            r = np.zeros((150, 10))
            r[:, 0], r[:, 1], r[:, 2:4], r[:, 4:6], r[:, 6], r[:, 7:] = t, tid, xy - 5, 10, 1, -1
            rows.append(r)
        write_mot(seq / "gt" / "gt.txt", np.vstack(rows))
        paths.append(str(seq / "gt" / "gt.txt"))
    out = tmp_path / "res.json"
    argv = ["experiment", "gaps", "--gt", *paths, "--methods", "auto,linear", "--json", str(out)]
    assert main(argv) == 0
    doc = json.loads(out.read_text())
    assert [s["name"] for s in doc["sequences"]] == ["SEQ0", "SEQ1"]
    assert set(doc["pooled"]["mmae"]) == {"auto", "linear"}
    for s in doc["sequences"]:
        assert 1 <= len(s["masks"]) <= 3 and all(m[2] == 100 for m in s["masks"])


def test_experiment_reads_a_seqinfo_with_a_byte_order_mark(tmp_path: Path) -> None:
    from pftrack.cli.experiment import _seqinfo

    gt = tmp_path / "SEQ" / "gt" / "gt.txt"
    gt.parent.mkdir(parents=True)
    ini = tmp_path / "SEQ" / "seqinfo.ini"
    ini.write_bytes(b"\xef\xbb\xbf[Sequence]\nname=S\nimWidth=768\nimHeight=576\n")
    assert _seqinfo(str(gt)) == ("S", 768.0, 576.0)
    ini.write_text("no section\n")  # was configparser's MissingSectionHeaderError: a traceback
    # read_seqinfo's message, as track and eval say it (was "expected [Sequence] imWidth and
    # imHeight", also for imWidth=abc)
    with pytest.raises(ValueError, match=r"seqinfo.ini: expected a \[Sequence\] section"):
        _seqinfo(str(gt))


def test_experiment_gaps_one_sequence_writes_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    # was: --json silently ignored with one --gt (only the multi-sequence protocol wrote it)
    gt = _walkers(tmp_path / "gt.txt")
    out = tmp_path / "one.json"
    argv = ["experiment", "gaps", "--gt", str(gt), "--image-size", "768x576", "--methods",
            "linear,gdt-bi", "--repeat", "1", "--max-positions", "2",
            "--json", str(out)]  # fmt: skip
    assert main(argv) == 0
    captured = capsys.readouterr()
    said = captured.out
    # stderr is no terminal here: no bar, so one line says what the sweep will run
    assert "every method at 2 mask positions of" in captured.err
    assert f"json: {out}" in said
    doc = json.loads(out.read_text())
    assert doc["gt"] == str(gt) and doc["methods"] == ["linear", "gdt-bi"]
    assert doc["image_size"] == [768, 576] and doc["point"] == "centre"
    mask = doc["mask"]
    assert f"x,y,w,h = {','.join(f'{v:g}' for v in mask['box'])}:" in said
    assert f"{mask['n_gaps']} gaps, {mask['n_lost_points']} lost points" in said
    for m in ("linear", "gdt-bi"):
        errors = mask["gap_errors"][m]
        assert len(errors) == mask["n_gaps"] > 0
        assert mask["scores"][m]["mmae_total"] == pytest.approx(np.mean(errors))
    row = said.split("MMAE total")[1].split()[:2]  # the representative mask's table
    assert row == [f"{mask['scores'][m]['mmae_total']:.3f}" for m in ("linear", "gdt-bi")]
    sweep = doc["sweep"]
    assert (sweep["size"], sweep["grid"], sweep["selection"]) == (100, 4, ">= 3 gaps")
    assert sweep["median"]["n_positions"] == 2
    assert sum(sweep["median"]["best_at"].values()) == 2


def test_experiment_gaps_writes_the_figure_of_a_mask_that_cuts_no_gap(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: --figure asked for, exit 0, no figure written and nothing said of it."""
    import cv2

    gt, fig = _walkers(tmp_path / "gt.txt"), tmp_path / "f.png"
    argv = ["-q", "experiment", "gaps", "--gt", str(gt), "--image-size", "768x576", "--mask",
            "0,0,2,2", "--methods", "linear", "--repeat", "1", "--figure", str(fig)]  # fmt: skip
    assert main(argv) == 0
    said = capsys.readouterr().out
    assert "0 gaps" in said and "no gap under this mask" in said
    assert said.endswith(f"figure: {fig}\n")
    image = cv2.imread(str(fig))
    assert image is not None and image.shape[0] == 360
    assert image.max() > 0  # the ground truth's paths, grey


@pytest.mark.parametrize(
    ("size", "box", "mask", "width"),
    [("1x100000", "0,{k2},1,2", "0,40,1,20", 1 + 4 + 360),  # was: cv2.error, a traceback
     ("100000x1", "{k2},0,2,1", "40,0,20,1", 4 * 360 + 4 + 360)],  # was: out of memory
    ids=["tall", "wide"],
)  # fmt: skip
def test_experiment_gaps_figure_of_a_thin_image_is_drawn_in_bounds(
    tmp_path: Path, size: str, box: str, mask: str, width: int
) -> None:
    """The scene panel was ``360 W / H`` px wide: 0 px (cv2.error) or 36 million px (13 GB)."""
    import cv2

    gt, fig = tmp_path / "gt.txt", tmp_path / "f.png"
    gt.write_text("".join(f"{k + 1},1,{box.format(k2=2 * k)},1,-1,-1,-1\n" for k in range(60)))
    argv = ["-q", "experiment", "gaps", "--gt", str(gt), "--image-size", size, "--mask", mask,
            "--methods", "linear", "--repeat", "1", "--figure", str(fig)]  # fmt: skip
    assert main(argv) == 0
    image = cv2.imread(str(fig))
    assert image is not None and image.shape == (360, width, 3)


@pytest.mark.parametrize(
    ("options", "said"),
    [(["--image-size", "80x60"], "--size 100: no 100 px mask fits in the 80x60 image; give a "
      "smaller --size, or --mask"),
     (["--image-size", "768x576", "--gaps", "1000"], "no mask position meets the selection "
      "(1000 gaps); relax it (--min-gaps, --trajectories, --gaps, --size), or pass --mask")],
    ids=["mask larger than the image", "selection"],
)  # fmt: skip
def test_experiment_gaps_says_why_no_mask_position_is_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], said: str
) -> None:
    """Was: "no mask position meets the selection; pass --mask" for a --size larger than the
    image too, where no position exists, whatever the selection."""
    gt = _walkers(tmp_path / "gt.txt")
    argv = ["experiment", "gaps", "--gt", str(gt), *options, "--methods", "linear"]
    assert main(argv) == 2
    assert capsys.readouterr().err == f"pftrack experiment gaps: error: {said}\n"


@pytest.mark.parametrize("size", [["768x576"], ["768", "576"], ["768X576"]])
def test_experiment_gaps_takes_the_image_size_as_eval_does_or_as_wxh(
    tmp_path: Path, size: list[str]
) -> None:
    """``pftrack eval --image-size W H``; ``experiment gaps`` took only ``WxH``."""
    import json

    gt, out = _walkers(tmp_path / "gt.txt"), tmp_path / "e.json"
    argv = ["experiment", "gaps", "--gt", str(gt), "--image-size", *size, "--methods", "linear",
            "--repeat", "1", "--max-positions", "1", "--json", str(out)]  # fmt: skip
    assert main(["-q", *argv]) == 0
    assert json.loads(out.read_text())["image_size"] == [768, 576]


def test_experiment_gaps_one_sequence_reads_the_seqinfo_beside_its_ground_truth(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: the ground truth's extent, the seqinfo.ini beside it passed over (as eval reads it)."""
    import json

    (tmp_path / "SEQ" / "gt").mkdir(parents=True)
    gt, out = _walkers(tmp_path / "SEQ" / "gt" / "gt.txt"), tmp_path / "e.json"
    (tmp_path / "SEQ" / "seqinfo.ini").write_text("[Sequence]\nimWidth=900\nimHeight=700\n")
    argv = ["-q", "experiment", "gaps", "--gt", str(gt), "--methods", "linear", "--repeat", "1",
            "--max-positions", "1", "--json", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert json.loads(out.read_text())["image_size"] == [900, 700]
    assert f"{gt}: 15 trajectories, centre point, 900x700\n" in capsys.readouterr().out
    assert main([*argv, "--image-size", "768x576"]) == 0  # given: it wins
    assert json.loads(out.read_text())["image_size"] == [768, 576]


@pytest.mark.parametrize("size", [["640x480"], ["640", "480"], ["640X480"]])
def test_eval_takes_the_image_size_as_w_h_or_wxh(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], size: list[str]
) -> None:
    """Was: ``--image-size 640x480`` refused by eval (``expected 2 arguments``)."""
    gt = _walkers(tmp_path / "gt.txt")
    assert main(["eval", "--gt", str(gt), "--res", str(gt), "--image-size", *size]) == 0
    assert "100.0" in capsys.readouterr().out
    assert build_parser().parse_args(
        ["eval", "--gt", "g", "--res", "r", "--image-size", *size]
    ).image_size == (640, 480)


@pytest.mark.parametrize("command", [["eval", "--gt", "G", "--res", "R"], ["experiment", "gaps"]])
def test_image_size_usage_reads_w_h(command: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """Was ``--image-size W [H ...]`` for experiment gaps (nargs="+")."""
    with pytest.raises(SystemExit):
        main([*command[:2], "--help"] if command[0] == "experiment" else [command[0], "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "[--image-size W H]" in text and "W H or WxH" in text and "None" not in text
    assert "[H ...]" not in text


@pytest.mark.parametrize("size", [["768"], ["768", "576", "1"], ["768x", "576"]])
def test_experiment_gaps_refuses_an_image_size_of_neither_form(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], size: list[str]
) -> None:
    argv = ["experiment", "gaps", "--gt", str(tmp_path / "none.txt"), "--image-size", *size]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"pftrack experiment gaps: error: --image-size is {' '.join(size)!r}, expected W H or WxH"
    )


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--image-size", "10x"], "argument --image-size: expected W H or WxH with W and H "
         "integers, got '10x'"),  # was: invalid int value: ''
        (["--image-size", "10xab"], "argument --image-size: expected W H or WxH with W and H "
         "integers, got '10xab'"),
        (["--image-size", "640", "4.5"], "argument --image-size: expected W H or WxH with W and "
         "H integers, got '640 4.5'"),
        (["--image-size", "1x2x3"], "argument --image-size: expected W H or WxH, got '1x2x3'"),
        (["--scale", "inf"], "argument --scale: expected a finite scale > 0, got inf"),
        (["--scale", "A=nan"], "argument --scale: expected a finite scale > 0, got nan"),
        (["--scale", "0"], "argument --scale: expected a finite scale > 0, got 0.0"),
    ],
)  # fmt: skip
def test_eval_names_the_form_of_a_bad_image_size_or_scale(
    option: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Were ``argument --image-size: invalid int value: ''`` and ``expected a scale > 0, got
    inf`` (inf is > 0: what is wrong is that it is not finite)."""
    with pytest.raises(SystemExit) as e:
        main(["eval", "--gt", "G", "--res", "R", *option])
    assert e.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1] == f"pftrack eval: error: {message}"


def _walkers(path: Path) -> Path:
    """Ground truth of 15 random walkers over 150 frames of a 768x576 scene."""
    rng = np.random.default_rng(4)
    rows = []
    for tid in range(1, 16):
        t = np.arange(1, 151, dtype=np.float64)
        xy = rng.uniform(100, 600, 2) + np.cumsum(
            rng.normal(0, 0.5, (150, 2)) + rng.uniform(-2, 2, 2), axis=0
        )
        r = np.full((150, 10), -1.0)
        r[:, 0], r[:, 1], r[:, 2:4], r[:, 4:6], r[:, 6] = t, tid, np.clip(xy, 20, 700) - 5, 10, 1
        rows.append(r)
    write_mot(path, np.vstack(rows))
    return path


@pytest.mark.parametrize(
    ("gts", "options", "message"),
    [
        (2, ["--figure", "f.png"], "--figure belongs to the one-sequence mask sweep; with several "
         "--gt files (automatic masks per sequence) nothing uses it: drop it"),
        (1, ["--auto-masks", "--repeat", "2"], "--repeat belongs to the one-sequence mask "
         "sweep; with --auto-masks (automatic masks per sequence) nothing uses it: drop it"),
        (2, ["--size", "100"], "--size belongs to the one-sequence mask sweep"),
        (2, ["--mask", "1,2,3,4"], "--mask belongs to the one-sequence mask sweep"),
        (1, ["--n-masks", "2"], "--n-masks belongs to the multi-sequence protocol; with one --gt "
         "nothing uses it: add --auto-masks or drop it"),
        (1, ["--gaps", "3", "--min-gaps", "2"],
         "--min-gaps selects positions only without --trajectories/--gaps; drop one"),
    ],
)  # fmt: skip
def test_experiment_gaps_refuses_the_other_modes_options_before_work(
    gts: int,
    options: list[str],
    message: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # was: silently ignored (--figure with several sequences wrote no figure, exit 0); the
    # ground truth does not exist: the combination is refused before it is read
    monkeypatch.chdir(tmp_path)
    argv = ["experiment", "gaps", "--gt", *(f"none{k}.txt" for k in range(gts)), *options]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pftrack experiment gaps: error: {message}") and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("spelling", ["same", "dot", "link"])
def test_experiment_gaps_refuses_one_ground_truth_given_twice(
    spelling: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: one sequence counted twice (two rows, its gaps twice in the pooled MMAE)."""
    gt = _walkers(tmp_path / "gt.txt")
    (tmp_path / "other.txt").symlink_to(gt)
    again = {"same": str(gt), "dot": f"{tmp_path}/./gt.txt", "link": str(tmp_path / "other.txt")}
    argv = ["experiment", "gaps", "--gt", str(gt), str(again[spelling]), "--image-size",
            "768x576", "--json", str(tmp_path / "e.json")]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pftrack experiment gaps: error: --gt {gt} and {again[spelling]} are the same file; give "
        "each sequence once\n"
    )
    assert not (tmp_path / "e.json").exists()


@pytest.mark.parametrize("command", ["eval", "batch"])
@pytest.mark.parametrize("iou", ["1.5", "0", "-0.5", "nan", "inf"])
def test_iou_is_refused_alike_by_eval_and_batch(
    command: str, iou: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # was: batch --iou 1.5, 0 or nan accepted (each sequence's scoring then failed), eval
    # refusing them with its own "--iou is 1.5, expected in (0, 1]"
    argv = {
        "eval": ["eval", "--gt", "g.txt", "--res", "r.txt"],
        "batch": ["batch", "v.avi", "--out", str(tmp_path / "out"), "--workers", "0"],
    }[command]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--iou", iou])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    message = f"argument --iou: expected a number in (0, 1], got {iou}"
    assert err == f"pftrack {command}: error: {message}"
    assert not (tmp_path / "out").exists()


def test_unwritable_output_folder_is_refused_before_work(
    video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if os.access(locked, os.W_OK):  # running as root: permissions are not enforced
            pytest.skip("the file system lets this user write anywhere")
        assert main(["track", str(video), "--out", str(locked / "t.txt")]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("pftrack track: error: --out") and "not writable" in err
    finally:
        locked.chmod(0o700)


def test_failed_run_leaves_an_existing_output_alone(video: Path, tmp_path: Path) -> None:
    out = tmp_path / "tracks.txt"
    out.write_text("keep me\n")
    argv = ["track", str(video), "--out", str(out), "--render", str(tmp_path / "a.xyz")]
    assert main(argv) == 2
    assert out.read_text() == "keep me\n"


def test_python_dash_m_pftrack_is_the_command() -> None:
    import subprocess
    import sys

    for module in ("pftrack", "pftrack.cli"):
        out = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True,
                             text=True, check=False)  # fmt: skip
        assert out.returncode == 0 and out.stdout.startswith("pftrack "), (module, out)


def test_track_gives_opencv_one_thread_and_the_same_tracks(video: Path, tmp_path: Path) -> None:
    import cv2

    from pftrack.io.mot import write_mot
    from pftrack.io.video import FrameSource
    from pftrack.tracking import TrackerConfig, track_frames

    threads = cv2.getNumThreads()
    cv2.setNumThreads(4)
    try:
        # the library leaves OpenCV's setting alone and gives the CLI's tracks with 4 threads
        config = TrackerConfig()
        run = track_frames(FrameSource(video), config=config, rng=0, show_progress=False)
        assert cv2.getNumThreads() == 4
        write_mot(tmp_path / "lib.txt", run.rows)
        assert main(["track", str(video), "--out", str(tmp_path / "cli.txt")]) == 0
        assert cv2.getNumThreads() == 1  # the command's process: one OpenCV thread
        assert (tmp_path / "cli.txt").read_bytes() == (tmp_path / "lib.txt").read_bytes()
    finally:
        cv2.setNumThreads(threads)


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--mask", "nan,0,10,10", "--mask is 'nan,0,10,10', expected x,y,w,h with w, h > 0"),
        ("--mask", "1e9,0,10,10", "each within ±100000"),
        ("--mask", "0,0,inf,5", "each within ±100000"),
        ("--image-size", "0x0", "--image-size is '0x0', expected W and H in (0, 100000] px"),
        ("--image-size", "nanxnan", "expected W and H in (0, 100000] px"),
        ("--image-size", "1e9x1e9", "expected W and H in (0, 100000] px"),
        ("--size", "1e308", "argument --size: expected a number in [1, 100000]"),
        ("--grid", "1e-300", "argument --grid: expected a number in [0.1, 100000]"),
        ("--grid", "nan", "argument --grid: expected a number in [0.1, 100000]"),
        ("--max-positions", "-1", "argument --max-positions: expected an integer >= 0, got -1"),
        ("--min-gaps", "-1", "argument --min-gaps: expected an integer >= 0, got -1"),
        ("--trajectories", "-1", "argument --trajectories: expected an integer >= 0, got -1"),
        ("--gaps", "-2", "argument --gaps: expected an integer >= 0, got -2"),
        ("--repeat", "x", "argument --repeat: invalid int value: 'x'"),
    ],
)
def test_experiment_gaps_refuses_absurd_masks_and_sizes_before_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str, message: str
) -> None:
    # the ground truth does not exist: the option is refused before it is read (was: NaN and
    # far masks accepted, "out of memory", "arange: cannot compute length", "Maximum allowed
    # size exceeded", "Number of samples, -1, must be non-negative", "invalid positive_int
    # value")
    argv = ["experiment", "gaps", "--gt", str(tmp_path / "none.txt"), option, value]
    try:
        status = main(argv)
    except SystemExit as exc:  # argparse's own refusal: the one error line
        status = exc.code
    assert status == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert message in err[-1] and err[-1].startswith("pftrack experiment")
    assert "Traceback" not in "\n".join(err)


def test_experiment_gaps_refuses_a_sweep_of_too_many_positions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = tmp_path / "gt.txt"
    gt.write_text("".join(f"{f},1,{10 + f},10,8,16,1,-1,-1,-1\n" for f in range(1, 30)))
    argv = ["experiment", "gaps", "--gt", str(gt), "--image-size", "100000x100000", "--grid", "1"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("pftrack experiment gaps: error: sweep: a 1 px grid over 100000 x 100000")
    assert "more than the limit of 1000000; use a coarser grid" in err and "\n" not in err


def _truncated_video(tmp_path: Path, rng: np.random.Generator, frames: int) -> Path:
    """``cut.avi``: the first half of the bytes of a `frames`-frame 64x48 noise MJPG video."""
    import cv2

    full = tmp_path / "full.avi"
    w = cv2.VideoWriter(str(full), cv2.VideoWriter_fourcc(*"MJPG"), 25, (64, 48))
    for _ in range(frames):
        w.write(rng.integers(0, 256, (48, 64, 3), dtype=np.uint8))
    w.release()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(full.read_bytes()[: full.stat().st_size // 2])
    return cut


def test_track_on_a_truncated_video_or_a_folder_of_mixed_sizes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import cv2

    rng = np.random.default_rng(2)
    cut = _truncated_video(tmp_path, rng, 20)
    assert main(["-q", "track", str(cut), "--out", str(tmp_path / "t.txt")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pftrack track: warning: ")
    assert "ended after" in err[0] and "header says 20" in err[0]
    folder = tmp_path / "imgs"
    folder.mkdir()
    for k in range(1, 8):
        shape = (60, 80, 3) if k == 6 else (48, 64, 3)
        cv2.imwrite(str(folder / f"{k}.png"), rng.integers(0, 256, shape, dtype=np.uint8))
    out = tmp_path / "f.txt"
    assert main(["-q", "track", str(folder), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"pftrack track: error: image {folder / '6.png'} is 80x60 but 1.png is 64x48: "
        "every image of a folder must have one size"
    )
    assert not out.exists()


def _tracks(path: Path) -> Path:
    path.write_text("".join(f"{f},1,{10 + f},10,8,16,1,-1,-1,-1\n" for f in (1, 2, 3, 9, 10)))
    return path


def test_recover_refuses_options_it_would_ignore_or_cannot_use(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, out = _tracks(tmp_path / "t.txt"), tmp_path / "out.txt"
    # was: --video (even a missing file) silently ignored without --link; since stop 72 the
    # fill reads it too (a hole handed to a neighbour), so it is checked with or without --link
    missing = tmp_path / "no.avi"
    assert main(["recover", str(src), "--out", str(out), "--video", str(missing)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"pftrack recover: error: video source not found: {missing}"
    )
    assert not out.exists()
    for bad in ("nan", "-1", "0"):  # was: accepted (and ignored without --link)
        with pytest.raises(SystemExit) as exc:
            main(["recover", str(src), "--out", str(out), "--max-distance", bad])
        assert exc.value.code == 2
        err = capsys.readouterr().err.strip().splitlines()[-1]
        assert err.startswith("pftrack recover: error: argument --max-distance: expected a")
    # was: --seed silently ignored by every method but auto
    assert main(["recover", str(src), "--out", str(out), "--method", "linear", "--seed", "3"]) == 2
    assert capsys.readouterr().err.strip() == (
        "pftrack recover: error: --seed is used only by --method auto (its calibration gaps), "
        "not linear; drop it"
    )
    # was: --max-distance silently ignored without --link, with one file and in a batch
    for given in ([str(src)], [str(src), str(_tracks(tmp_path / "t2.txt"))]):
        assert main(["recover", *given, "--out", str(out), "--max-distance", "5"]) == 2
        assert capsys.readouterr().err.strip() == (
            "pftrack recover: error: --max-distance is used only by --link (its linking gate); "
            "add --link or drop it"
        )
    assert not out.exists()
    assert main(["recover", str(src), "--out", str(out), "--seed", "3"]) == 0  # auto: used
    assert main(["recover", str(src), "--out", str(out), "--link", "--max-distance", "5"]) == 0


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_one_file_refuses_the_batch_options(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    src, out = _tracks(tmp_path / "t.txt"), tmp_path / "out.txt"
    # was: --workers, --scheduler and --force silently ignored with one file
    for extra, named in (
        (["--workers", "0"], "--workers applies"),
        (["--scheduler", "tcp://127.0.0.1:1"], "--scheduler applies"),
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--scheduler, --workers apply"),
    ):  # --force is one file's too: an --out that holds no MOTChallenge rows (docs/io.md)
        assert main([command, str(src), "--out", str(out), *extra]) == 2
        assert capsys.readouterr().err.strip() == (
            f"pftrack {command}: error: {named} to a batch (several files or a folder); one "
            "file runs in this process: drop it"
        )
        assert not out.exists()
    # the environment's scheduler is for batches: one file does not refuse it
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "tcp://127.0.0.1:1")
    assert main([command, str(src), "--out", str(out)]) == 0


def test_library_warnings_are_one_line_for_every_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import warnings

    import pftrack.recovery as recovery

    real = recovery.fill_gaps

    def warning_fill(*args: Any, **kwargs: Any) -> Any:  # recover reads --video on demand
        warnings.warn("a library warning\nin two lines", UserWarning, stacklevel=2)  # now: no
        return real(*args, **kwargs)  # warning of a truncated video it does not decode whole

    monkeypatch.setattr(recovery, "fill_gaps", warning_fill)
    src, out = _tracks(tmp_path / "t.txt"), tmp_path / "out.txt"
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main(["-q", "recover", str(src), "--out", str(out), "--link"]) == 0
        before = warnings.showwarning
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["pftrack recover: warning: a library warning in two lines"]
    assert warnings.showwarning is before  # main restores the formatter it replaced


def _fragments(path: Path) -> Path:
    """Track 1 on frames 1-8, track 2 on frames 13-24 beside it: `recover --link` joins them,
    reading the frames at their ends (13: past frame 10)."""
    rows = [(f, 1) for f in range(1, 9)] + [(f, 2) for f in range(13, 25)]
    path.write_text("".join(f"{f},{i},{20 + f},30,10,20,1,-1,-1,-1\n" for f, i in rows))
    return path


@pytest.mark.parametrize("case", ["damaged video", "11 columns"])
def test_a_warning_made_an_error_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    """``python -W error -m pftrack recover``: a warning made an error is the command's one-line
    error, status 1, nothing written (was: its traceback, status 1). The damaged video's frame
    10 is now said as ``--video`` is read past it (warnlate; was: never, the frames read on
    demand never reached the end of the file)."""
    import warnings

    from tests.io.test_video import damaged_inside

    out = tmp_path / "out.txt"
    if case == "damaged video":
        src = _fragments(tmp_path / "t.txt")
        extra = ["--link", "--video", str(damaged_inside(tmp_path))]
        text = "damaged.avi: frame 10 could not be decoded (a damaged file?)"
    else:
        src = tmp_path / "t.txt"
        src.write_text("".join(f"{f},1,{10 + f},10,8,16,1,-1,-1,-1,7\n" for f in (1, 2, 5)))
        extra, text = [], "t.txt has lines of 11 columns"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["-q", "recover", str(src), "--out", str(out), *extra]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pftrack recover: error: "), err
    assert text in err[0] and err[0].endswith("(a warning, made an error)"), err
    assert not out.exists()


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_columns_past_10_are_dropped_with_a_warning(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import warnings

    src, wide = _tracks(tmp_path / "t.txt"), tmp_path / "wide.txt"
    wide.write_text("".join(f"{line},7,8\n" for line in src.read_text().splitlines()))
    assert main(["-q", command, str(src), "--out", str(tmp_path / "a.txt")]) == 0
    capsys.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main(["-q", command, str(wide), "--out", str(tmp_path / "b.txt")]) == 0
    # was: columns 11 and 12 dropped without a word
    assert capsys.readouterr().err.strip().splitlines() == [
        f"pftrack {command}: warning: tracks file {wide} has lines of 12 columns: columns past "
        "10 are not kept"
    ]
    assert (tmp_path / "b.txt").read_bytes() == (tmp_path / "a.txt").read_bytes()


def test_summary_lines_count_in_the_singular_and_plural(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, out, again = tmp_path / "t.txt", tmp_path / "o.txt", tmp_path / "o2.txt"
    src.write_text("1,1,10,20,30,40,1,-1,-1,-1\n3,1,12,20,30,40,1,-1,-1,-1\n")
    assert main(["recover", str(src), "--out", str(out), "--method", "linear"]) == 0
    line = capsys.readouterr().out.strip()  # was: "1 gaps filled with 1 rows"
    assert line.startswith(f"{src}: 2 rows, 0 fragments linked, 1 gap filled with 1 row (linear, ")
    assert main(["recover", str(out), "--out", str(again), "--method", "linear"]) == 0
    line = capsys.readouterr().out.strip()
    assert line.endswith("; 1 input row had it already, kept as observed)")
    assert main(["smooth", str(src), "--out", str(out)]) == 0
    line = capsys.readouterr().out  # was: "1 ids, 2 rows -> 1 ids, 3 rows"
    assert line.startswith(f"{src}: 1 id, 2 rows -> 1 id, 3 rows (")


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
def test_a_write_error_names_the_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = _tracks(tmp_path / "t.txt")
    for argv in (
        ["recover", str(src), "--out", "/dev/full"],
        ["smooth", str(src), "--out", "/dev/full"],
        ["eval", "--gt", str(src), "--res", str(src), "--json", "/dev/full"],
    ):
        assert main(["-q", *argv]) == 2
        # was: "error: [Errno 28] No space left on device", no file named
        assert capsys.readouterr().err.strip() == (
            f"pftrack {argv[0]}: error: No space left on device: /dev/full"
        )


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
def test_a_full_standard_output_is_named_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A user report: ``pftrack eval ... > /dev/full`` said ``[Errno 28] No space left on
    device``, naming nothing: the user could not tell it from an output file's failure."""
    import contextlib
    import sys

    src, out = _tracks(tmp_path / "t.txt"), tmp_path / "o.txt"
    cases = [
        (["eval", "--gt", str(src), "--res", str(src)], ""),
        (["experiment", "gaps", "--gt", str(src), "--image-size", "100x100", "--methods",
          "linear", "--repeat", "1", "--min-gaps", "0", "--max-positions", "1"], ""),
        # the table comes after --out is in place: said, so that it is not taken for lost
        (["recover", str(src), "--out", str(out), "--explain"],
         "; the outputs were written before it"),
    ]  # fmt: skip
    for argv, left in cases:
        full = open("/dev/full", "w")  # noqa: SIM115 - its close fails too (what is left)
        monkeypatch.setattr(sys, "stdout", full)
        try:
            assert main(["-q", *argv]) == 2
        finally:
            monkeypatch.undo()
            with contextlib.suppress(OSError):
                full.close()
        assert capsys.readouterr().err == (
            f"pftrack {' '.join(argv[:2] if argv[0] == 'experiment' else argv[:1])}: error: "
            f"cannot write to standard output (No space left on device){left}\n"
        )
    assert read_mot(out).shape[0] == 10  # recover's output, whole


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
def test_the_command_on_a_full_device_or_a_closed_pipe_prints_no_traceback(
    tmp_path: Path,
) -> None:
    """The process as a shell runs it: ``> /dev/full`` one line and exit status 2, ``| head``
    (a pipe closed before the table) nothing at all, and neither a traceback at exit."""
    import sys

    src = _tracks(tmp_path / "t.txt")
    argv = [sys.executable, "-m", "pftrack", "eval", "--gt", str(src), "--res", str(src)]
    full, closed = _into_full_and_closed(argv)
    assert (full.returncode, full.stderr) == (
        2,
        "pftrack eval: error: cannot write to standard output (No space left on device)\n",
    )
    assert (closed.returncode, closed.stderr) == (1, "")


def test_track_with_stderr_closed_writes_its_tracks(video: Path, tmp_path: Path) -> None:
    """``pftrack track ... 2>&-`` (a daemon's or cron's closed stderr): the tracks as with one.

    Was: exit status 1 and no file (the progress bar asked the missing stderr whether it is a
    terminal; the error went to the closed stderr too)."""
    import subprocess
    import sys

    closed, open_ = tmp_path / "closed.txt", tmp_path / "open.txt"
    argv = [sys.executable, "-m", "pftrack", "track", str(video), "--particles", "30"]
    run = subprocess.run(["sh", "-c", 'exec "$@" 2>&-', "sh", *argv, "--out", str(closed)],
                         stdout=subprocess.DEVNULL, check=False, timeout=300)  # fmt: skip
    assert run.returncode == 0
    assert main(["-q", "track", str(video), "--particles", "30", "--out", str(open_)]) == 0
    assert closed.read_bytes() == open_.read_bytes() != b""


def _into_full_and_closed(argv: list[str]) -> tuple[Any, Any]:
    """The process `argv` run with stdout on ``/dev/full``, then on a pipe closed before it
    writes (as ``| head`` leaves it): both ``subprocess.run`` results, stderr as text."""
    import subprocess

    with open("/dev/full", "wb") as full:
        into_full = subprocess.run(argv, stdout=full, stderr=subprocess.PIPE, text=True,
                                   check=False, timeout=120)  # fmt: skip
    read, write = os.pipe()
    os.close(read)  # closed before the command writes
    try:
        into_closed = subprocess.run(argv, stdout=write, stderr=subprocess.PIPE, text=True,
                                     check=False, timeout=120)  # fmt: skip
    finally:
        os.close(write)
    return into_full, into_closed


#: Each command reading an input file L, with how its error names that input.
INPUT_COMMANDS = pytest.mark.parametrize(
    ("argv", "what"),
    [
        (["track", "L", "--out", "O"], "video source"),
        (["render", "L", "T", "--out", "O.mp4"], "video source"),
        (["track", "V", "--detections", "L", "--out", "O"], "--detections"),
        (["recover", "L", "--out", "O"], "tracks file"),
        (["smooth", "L", "--out", "O"], "tracks file"),
        (["eval", "--gt", "T", "--res", "L"], "--res"),
        (["experiment", "gaps", "--gt", "L", "--image-size", "768x576"], "ground truth"),
    ],
    ids=["track", "render", "detections", "recover", "smooth", "eval", "experiment"],
)


def _run_on_input(argv: list[str], given: Path, tmp_path: Path, video: Path) -> int:
    """`main` of one of :data:`INPUT_COMMANDS`'s `argv`, `given` as its input L (T: a tracks
    file, V: a video, O / O.mp4: outputs in `tmp_path`)."""
    tracks = _tracks(tmp_path / "t.txt")
    names = {"L": str(given), "T": str(tracks), "V": str(video), "O": str(tmp_path / "o.txt")}
    names["O.mp4"] = str(tmp_path / "o.mp4")
    return main([names.get(x, x) for x in argv])


@INPUT_COMMANDS
def test_an_input_that_is_a_symbolic_link_loop_is_named_as_one(
    argv: list[str], what: str, tmp_path: Path, video: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: a traceback (``RuntimeError: Symlink loop``, from ``Path.resolve`` while outputs
    were checked against the inputs) for track, render and experiment gaps, and "not found"
    for the others, though the link is there."""
    loop = tmp_path / "a"
    loop.symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    assert _run_on_input(argv, loop, tmp_path, video) == 2
    assert capsys.readouterr().err.endswith(
        f"error: {what} {loop}: symbolic link loop ({loop} -> b -> a), which leads to no file "
        "or folder; point the link at one\n"
    )
    assert not (tmp_path / "o.txt").exists() and not (tmp_path / "o.mp4").exists()


@INPUT_COMMANDS
def test_an_input_that_is_a_broken_symbolic_link_is_named_as_one(
    argv: list[str], what: str, tmp_path: Path, video: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A link whose video was moved: was ``video source not found: clip.mp4``, though ``ls``
    lists it (``pftrack batch`` named it already)."""
    link = tmp_path / "clip.mp4"
    link.symlink_to(tmp_path / "moved" / "clip.mp4")
    assert _run_on_input(argv, link, tmp_path, video) == 2
    assert capsys.readouterr().err.endswith(
        f"error: {what} not found: {link} is a broken symbolic link (to "
        f"{tmp_path / 'moved' / 'clip.mp4'})\n"
    )
    assert not (tmp_path / "o.txt").exists() and not (tmp_path / "o.mp4").exists()


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
@pytest.mark.parametrize(
    ("words", "prog"),
    [(["--help"], "pftrack"), (["track", "--help"], "pftrack track"), (["--version"], "pftrack")],
)
def test_help_and_version_on_a_full_device_say_so(words: list[str], prog: str) -> None:
    """Was: ``pftrack --help > /dev/full`` printed nothing and exited 0 (argparse ignores a
    failed write); a closed pipe still ends quietly with status 0, as ``| head`` expects."""
    import sys

    full, closed = _into_full_and_closed([sys.executable, "-m", "pftrack", *words])
    assert (full.returncode, full.stderr) == (
        2,
        f"{prog}: error: cannot write to standard output (No space left on device)\n",
    )
    assert (closed.returncode, closed.stderr) == (0, "")


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
@pytest.mark.parametrize("option", ["--out", "--plot"])
def test_a_track_write_error_names_the_output(
    video: Path, tmp_path: Path, option: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "t.txt"
    argv = ["-q", "track", str(video), "--out", str(out), "--particles", "40", "--no-link"]
    if option == "--plot":  # a user trial: --out was replaced by the run that then failed
        out.write_bytes(TRACKS)  # an older run's tracks
    assert main([*argv, option, "/dev/full"]) == 2
    # was: "pftrack track: error: [Errno 28] No space left on device", no file named
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        "pftrack track: error: No space left on device: /dev/full"
    )
    if option == "--plot":
        assert out.read_bytes() == TRACKS


@pytest.mark.parametrize(
    "argv",
    [
        ["track", "VIDEO", "--out", "loopA"],
        ["track", "VIDEO", "--out", "t.txt", "--render", "loopA"],
        ["track", "VIDEO", "--out", "t.txt", "--plot", "loopA"],
        ["smooth", "TRACKS", "--out", "loopA"],
        ["eval", "--gt", "TRACKS", "--res", "TRACKS", "--json", "loopA"],
    ],
)
def test_an_output_of_links_that_lead_to_each_other_names_its_option(
    video: Path, tmp_path: Path, argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "loopA").symlink_to("loopB")
    (tmp_path / "loopB").symlink_to("loopA")
    tracks = _tracks(tmp_path / "tracks.txt")
    names = {"VIDEO": str(video), "TRACKS": str(tracks)}
    argv = [names.get(a, str(tmp_path / a) if a.startswith(("loop", "t.")) else a) for a in argv]
    assert main(["-q", *argv]) == 2
    option = argv[argv.index(str(tmp_path / "loopA")) - 1]
    # was: "pftrack track: error: Too many levels of symbolic links: loopA", no option named
    assert capsys.readouterr().err == (
        f"pftrack {argv[0]}: error: {option} {tmp_path}/loopA: Too many levels of symbolic links\n"
    )
    assert not (tmp_path / "t.txt").exists()


@pytest.mark.parametrize("command", ["track", "batch"])
@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("--det-scale 7", "--det-scale 7 scales the boxes of --detections; the built-in "
                          "detector's are in the frame's pixels: drop it, or give --detections"),
        ("--birth-score 0.5", "--birth-score 0.5 gates the births of --detections; the built-in "
                              "detector starts a track from any blob: drop it, or give "
                              "--detections"),
        ("--no-refine", "--no-refine takes the boxes of --detections as given; the built-in "
                        "detector's boxes are not refined: drop it, or give --detections"),
        ("--size-ratio 0.7", "--size-ratio 0.7 judges the tracks of --detections; the built-in "
                             "detector has its own size model: drop it, or give --detections"),
        ("--size-ratio off", "--size-ratio off judges the tracks of --detections"),
        ("--min-conf -5", "--min-conf -5: the built-in detector's scores are the share of "
                          "foreground pixels in a blob's box, in [0, 1]; give a value in "
                          "[0, 1], or --detections"),
        ("--min-conf 1.5", "--min-conf 1.5: the built-in detector's scores"),
    ],
)  # fmt: skip
def test_options_the_built_in_detector_never_uses_are_refused(
    command: str,
    option: str,
    message: str,
    video: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Were: accepted and ignored (the same tracks), as ``--crossings on --no-smooth`` was."""
    import pftrack.tracking as tracking

    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("work started")

    monkeypatch.setattr(tracking, "track_frames", refuse)
    out = tmp_path / ("o.txt" if command == "track" else "o")
    argv = [command, str(video), "--out", str(out), *option.split()]
    assert main([*argv, "--workers", "0"] if command == "batch" else argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pftrack {command}: error: {message}") and err.count("\n") == 1, err
    assert not out.exists()


def test_options_the_joint_sampler_never_reads_are_refused() -> None:
    # was: --sampler rjmcmc with --max-coast 0, 100 or --birth-score 0 wrote the same bytes
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config

    parse = build_parser().parse_args
    joint = ["track", "v", "--out", "o", "--detections", "d.txt", "--sampler", "rjmcmc"]
    with pytest.raises(ValueError, match=(
        r"^--max-coast 0, --birth-score 0: the joint sampler \(--sampler rjmcmc\) keeps and "
        r"starts tracks by its own existence probabilities, so they do nothing: drop them, or "
        r"use --sampler sis or mh$"
    )):  # fmt: skip
        tracker_config(parse([*joint, "--max-coast", "0", "--birth-score", "0"]))
    tracker_config(parse([*joint, "--max-coast", "10"]))  # the default, named: taken
    tracker_config(parse([*joint[:-2], "--max-coast", "0"]))  # sis: taken


def test_joint_sampler_particles_are_capped(capsys: pytest.CaptureFixture[str]) -> None:
    # was: --sampler rjmcmc --particles 100000 taken, about 6 minutes a frame (the chain's cost
    # grows as the square of its samples)
    from pftrack._limits import MAX_JOINT_SAMPLES, MAX_PARTICLES
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config

    parse = build_parser().parse_args
    joint = ["track", "v", "--out", "o", "--sampler", "rjmcmc", "--particles"]
    with pytest.raises(ValueError, match=(
        r"^--particles 10001 with --sampler rjmcmc: at most 10000\. The joint chain's cost per "
        r"frame grows as the square of its samples .*, 1\.4 s at 32000$"
    )):  # fmt: skip
        tracker_config(parse([*joint, "10001"]))
    assert (MAX_JOINT_SAMPLES, MAX_PARTICLES) == (10_000, 1_000_000)
    assert tracker_config(parse([*joint, "10000"])).filter.n_particles == 10_000
    # sis: linear, taken up to the Python API's limit (was: the command stopped at 100000)
    sis = tracker_config(parse([*joint[:-3], "--particles", "1000000"]))
    assert sis.filter.n_particles == 1_000_000
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "particles per object (1 to 1000000; with --sampler rjmcmc" in text
    assert "kept samples, 1 to 10000: its cost per frame grows as N squared" in text


#: A sampler's option on the command line, the same setting given to ``pftrack.Tracker``, and
#: the refusal both give (the command's with its flags' names, the Tracker's with its arguments').
SAMPLER_SETTINGS = [
    ("--sampler rjmcmc --particles 10001", {"sampler": "rjmcmc", "particles": 10001},
     "{particles} 10001 with {sampler rjmcmc}: at most 10000. The joint chain's cost per frame "
     "grows as the square of its samples (each of its burn-in + N iterations weighs a mixture "
     "over the previous frame's N samples): about 0.15 s a frame at 10000 with 5 objects, 1.4 s "
     "at 32000"),
    ("--mh-iter 5", {"mh_iter": 5},
     "{mh_iter} 5: only {sampler mh} reads it, so it does nothing with {sampler sis}: drop it, "
     "or use {sampler mh}"),
    ("--sampler rjmcmc --mh-iter 5", {"sampler": "rjmcmc", "mh_iter": 5},
     "{mh_iter} 5: only {sampler mh} reads it, so it does nothing with {sampler rjmcmc}: drop "
     "it, or use {sampler mh}"),
    ("--burn-in 10 --moves 0.2 0.2 0.5 0.1", {"burn_in": 10, "moves": (0.2, 0.2, 0.5, 0.1)},
     "{burn_in} 10, {moves} 0.2 0.2 0.5 0.1: only {sampler rjmcmc} reads them, so they do "
     "nothing with {sampler sis}: drop them, or use {sampler rjmcmc}"),
    ("--sampler mh --moves 0.2 0.2 0.5 0.1", {"sampler": "mh", "moves": [0.2, 0.2, 0.5, 0.1]},
     "{moves} 0.2 0.2 0.5 0.1: only {sampler rjmcmc} reads it, so it does nothing with "
     "{sampler mh}: drop it, or use {sampler rjmcmc}"),
    ("--sampler rjmcmc --moves 0.1 0 0.7 0.1", {"sampler": "rjmcmc", "moves": (0.1, 0, 0.7, 0.1)},
     "{moves} is 0.1 0 0.7 0.1: birth 0.1 and death 0, expected birth and death both > 0 or "
     "both 0 (a birth is undone by a death: reversibility)"),
    # the MH proposal (developer trial, 6 December: the core's proposals had no option)
    ("--mh-proposal random_walk", {"mh_proposal": "random_walk"},
     "{mh_proposal} random_walk: only {sampler mh} reads it, so it does nothing with "
     "{sampler sis}: drop it, or use {sampler mh}"),
    ("--sampler mh --mh-rw-sigma 4 4 0.02", {"sampler": "mh", "mh_rw_sigma": (4, 4, 0.02)},
     "{mh_rw_sigma} 4 4 0.02: only the random-walk proposal reads it, so it does nothing with "
     "{mh_proposal dynamics}: drop it, or use {mh_proposal random_walk}"),
    ("--sampler mh --mh-proposal random_walk --mh-rw-sigma 4 4 10001",
     {"sampler": "mh", "mh_proposal": "random_walk", "mh_rw_sigma": (4, 4, 10001)},
     "in [0, 10000]"),
    ("--sampler rjmcmc --moves 0 0 0 0", {"sampler": "rjmcmc", "moves": (0, 0, 0, 0)},
     "{moves} is 0 0 0 0: all 0, expected at least one > 0 (birth, death, update, swap)"),
    # argparse's range checks: the same limits, in argparse's words on the command line
    ("--particles 1000001", {"particles": 1_000_001}, "expected an integer in [*, 1000000]"),
    ("--sampler mh --mh-iter 0", {"sampler": "mh", "mh_iter": 0},
     "expected an integer in [1, 1000]"),
    ("--sampler mh --mh-iter 1001", {"sampler": "mh", "mh_iter": 1001},
     "expected an integer in [1, 1000]"),
    ("--sampler rjmcmc --burn-in 100001", {"sampler": "rjmcmc", "burn_in": 100_001},
     "expected an integer in [0, 100000]"),
    ("--sampler rjmcmc --moves 0.1 0.1 nan 0.1",
     {"sampler": "rjmcmc", "moves": (0.1, 0.1, float("nan"), 0.1)}, "finite number"),
]  # fmt: skip


def _named(message: str, *, cli: bool) -> str:
    """`message` with its ``{option}`` names as the command's flags or the Tracker's arguments."""
    import re

    def name(m: re.Match[str]) -> str:
        word = m.group(1)
        if " " in word:  # an option and its text value: --sampler mh, sampler 'mh'
            key, value = word.split()
            return f"--{key.replace('_', '-')} {value}" if cli else f"{key} {value!r}"
        return f"--{word.replace('_', '-')}" if cli else word

    return re.sub(r"\{([a-z_ ]+)\}", name, message)


@pytest.mark.parametrize(
    ("option", "kwargs", "message"), SAMPLER_SETTINGS, ids=[s[0] for s in SAMPLER_SETTINGS]
)
def test_a_bad_sampler_setting_is_refused_alike_by_the_command_and_the_tracker(
    option: str, kwargs: dict[str, Any], message: str, video: Path, tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    """One limit and one message for ``pftrack track`` and ``pftrack.Tracker`` (was: the Tracker
    took 1000000 joint samples where the command stopped at 10000, the command no more than
    100000 particles where the Tracker took 1000000, and the MH chain length, the joint chain's
    burn-in and moves had no option at all)."""
    out = tmp_path / "o.txt"
    try:
        code = main(["-q", "track", str(video), "--out", str(out), *option.split()])
    except SystemExit as stop:  # argparse's own refusal: usage, then one line
        code = stop.code
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    with pytest.raises(ValueError) as e:
        pftrack.Tracker(**kwargs)
    if "{" in message:  # the shared check (pftrack._limits): the same words, one line
        assert err == f"pftrack track: error: {_named(message, cli=True)}\n"
        assert str(e.value) == _named(message, cli=False)
    else:  # a range: argparse's type on the command line, the same bounds in Python
        last = err.splitlines()[-1]
        assert last.startswith("pftrack track: error: argument --"), err
        assert message.replace("*", "0") in last, last  # the command's --particles 0: automatic
        assert message.replace("*", "1") in str(e.value), str(e.value)


def test_the_samplers_chain_settings_reach_their_samplers(scene) -> None:
    """``--mh-iter``, ``--burn-in`` and ``--moves`` (and ``Tracker``'s arguments of the same
    names) give the MH filters' ``n_iter`` and the joint chain's burn-in and moves: they were
    reachable only through ``TrackerConfig`` (the burn-in and moves) or not at all (MH)."""
    from pftrack._limits import DEFAULT_BURN_IN, DEFAULT_MH_ITER, DEFAULT_MOVES
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config
    from pftrack.particle_filter import MHColourParticleFilter
    from pftrack.tracking.joint import joint_config

    parse = build_parser().parse_args
    argv = ["track", "v", "--out", "o"]
    mh = tracker_config(parse([*argv, "--sampler", "mh", "--mh-iter", "3"]))
    assert mh == pftrack.Tracker(sampler="mh", mh_iter=3).config and mh.mh_iter == 3
    joint = tracker_config(parse([*argv, "--sampler", "rjmcmc", "--burn-in", "7",
                                  "--moves", "0.2", "0.2", "0.5", "0"]))  # fmt: skip
    assert joint == pftrack.Tracker(sampler="rjmcmc", burn_in=7, moves=[0.2, 0.2, 0.5, 0]).config
    chain = joint_config(joint)
    assert (chain.burn_in, chain.p_birth, chain.p_death, chain.p_update, chain.p_swap) == (
        7,
        0.2,
        0.2,
        0.5,
        0.0,
    )
    # the defaults are the configs', named once (pftrack._limits), and the Tracker's
    default = TrackerConfig()
    assert default.mh_iter == DEFAULT_MH_ITER == MHColourParticleFilter.__init__.__defaults__[-1]
    assert default.rjmcmc.burn_in == DEFAULT_BURN_IN
    r = default.rjmcmc
    assert (r.p_birth, r.p_death, r.p_update, r.p_swap) == DEFAULT_MOVES
    params = inspect.signature(pftrack.Tracker).parameters
    assert (params["mh_iter"].default, params["burn_in"].default, params["moves"].default) == (
        DEFAULT_MH_ITER,
        DEFAULT_BURN_IN,
        DEFAULT_MOVES,
    )
    # the chain length reaches the MH filters, and changes what they do
    truth = [scene.truth[scene.truth[:, 0] == n + 1][:, 2:6] for n in range(12)]
    dets = [np.c_[t[:, :2], t[:, :2] + t[:, 2:], np.ones(len(t))] for t in truth]
    particles = {}
    for n_iter in (1, 4):
        tracker = pftrack.Tracker(sampler="mh", mh_iter=n_iter)
        for d, frame in zip(dets, scene.frames[:12], strict=True):
            tracker.update(d, frame)
        filters = [t.filter for t in tracker.tracker.tracks]
        assert filters and all(isinstance(f, MHColourParticleFilter) for f in filters)
        assert {f.n_iter for f in filters} == {n_iter}
        particles[n_iter] = filters[0].particles.copy()
    assert not np.array_equal(particles[1], particles[4])


def test_the_mh_proposal_settings_reach_the_filters(scene) -> None:
    """``--mh-proposal`` and ``--mh-rw-sigma`` (``Tracker``'s ``mh_proposal`` and
    ``mh_rw_sigma``) give the MH filters' proposal, which changes what they do; the core's
    random-walk proposal had no option (developer trial, 6 December). The defaults are the
    core's, stated once in pftrack._limits, so the default MH output is unchanged."""
    from pftrack._limits import DEFAULT_MH_PROPOSAL, DEFAULT_MH_RW_SIGMA
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config
    from pftrack.particle_filter import MHColourParticleFilter

    parse = build_parser().parse_args
    argv = ["track", "v", "--out", "o", "--sampler", "mh"]
    rw = ["--mh-proposal", "random_walk", "--mh-rw-sigma", "3", "3", "0.02"]
    config = tracker_config(parse([*argv, *rw]))
    kwargs = {"mh_proposal": "random_walk", "mh_rw_sigma": np.array([3, 3, 0.02])}
    assert config == pftrack.Tracker(sampler="mh", **kwargs).config
    assert (config.mh_proposal, config.mh_rw_sigma) == ("random_walk", (3.0, 3.0, 0.02))
    default = tracker_config(parse(argv))
    assert (default.mh_proposal, default.mh_rw_sigma) == (DEFAULT_MH_PROPOSAL, DEFAULT_MH_RW_SIGMA)
    kw = MHColourParticleFilter.__init__.__kwdefaults__
    assert (kw["proposal"], kw["rw_sigma"]) == (DEFAULT_MH_PROPOSAL, DEFAULT_MH_RW_SIGMA)
    # pixel settings: the step's cx, cy grow with the frame as the filter's sigma_xy
    big = config.scaled_pixels(2.0)
    assert big.mh_rw_sigma == (6.0, 6.0, 0.02)
    assert default.scaled_pixels(2.0).mh_rw_sigma == DEFAULT_MH_RW_SIGMA  # dynamics: unread
    truth = [scene.truth[scene.truth[:, 0] == n + 1][:, 2:6] for n in range(12)]
    dets = [np.c_[t[:, :2], t[:, :2] + t[:, 2:], np.ones(len(t))] for t in truth]
    particles = []
    for extra in ({}, {"mh_proposal": "random_walk"}, kwargs):
        tracker = pftrack.Tracker(sampler="mh", mh_iter=3, **extra)
        for d, frame in zip(dets, scene.frames[:12], strict=True):
            tracker.update(d, frame)
        filters = [t.filter for t in tracker.tracker.tracks]
        assert filters and all(isinstance(f, MHColourParticleFilter) for f in filters)
        assert {f.proposal for f in filters} == {extra.get("mh_proposal", "dynamics")}
        particles.append(filters[0].particles.copy())
    assert not np.array_equal(particles[0], particles[1])
    assert not np.array_equal(particles[1], particles[2])


def test_the_moves_rule_has_one_wording(capsys: pytest.CaptureFixture[str]) -> None:
    """``RJMCMCConfig``, ``--moves``' help and refusal, ``Tracker(moves=...)`` and
    docs/samplers.md state the birth/death rule in the same words (``RJMCMCConfig`` said
    "(reversibility)" alone, the help gave no reason)."""
    from pftrack._limits import MOVES_RULE
    from pftrack.particle_filter import RJMCMCConfig

    def flat(text: str) -> str:
        return " ".join(text.split())

    with pytest.raises(SystemExit):
        main(["track", "--help"])
    text = flat(capsys.readouterr().out)
    assert f"finite and >= 0, not all 0, {MOVES_RULE} (default: 0.1 0.1 0.7 0.1)" in text
    assert "--mh-proposal {dynamics,random_walk}" in text and "--mh-rw-sigma CX CY S" in text
    assert MOVES_RULE in flat(RJMCMCConfig.__doc__ or "")
    docs = Path(__file__).resolve().parents[1] / "docs" / "samplers.md"
    assert MOVES_RULE in flat(docs.read_text(encoding="utf-8"))
    with pytest.raises(ValueError, match=re.escape(f"expected {MOVES_RULE}")):
        RJMCMCConfig(p_death=0.0)
    with pytest.raises(ValueError, match=re.escape(f"expected {MOVES_RULE}")):
        pftrack.Tracker(sampler="rjmcmc", moves=(0.1, 0, 0.7, 0.1))


def test_the_tracker_config_holds_the_samplers_limits() -> None:
    """``Tracker.from_config`` (and ``pftrack track --set``-style configs) meet the same caps."""
    base = TrackerConfig()
    many = replace(base, filter=replace(base.filter, n_particles=10_001))  # sis: taken
    with pytest.raises(ValueError, match=(
        r"^TrackerConfig: filter.n_particles 10001 with sampler 'rjmcmc': at most 10000\. "
    )):  # fmt: skip
        replace(many, sampler="rjmcmc")
    with pytest.raises(ValueError, match=r"^TrackerConfig: mh_iter is 0, expected an integer"):
        replace(base, mh_iter=0)
    with pytest.raises(TypeError, match=r"^TrackerConfig: mh_iter must be an integer"):
        replace(base, mh_iter=2.0)
    with pytest.raises(ValueError, match=r"^TrackerConfig: rjmcmc.burn_in is 100001, expected"):
        replace(base, rjmcmc=replace(base.rjmcmc, burn_in=100_001))


def test_background_options_with_no_refine_are_refused() -> None:
    # was: --no-refine --detector knn --open-size 9 --bootstrap first wrote the same bytes as
    # --no-refine alone (no background model runs)
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config

    parse = build_parser().parse_args
    given = ["track", "v", "--out", "o", "--detections", "d.txt", "--no-refine"]
    with pytest.raises(ValueError, match=(
        r"^--bootstrap first, --detector knn, --open-size 9: with --no-refine no background "
        r"model runs, so they do nothing: drop them, or --no-refine$"
    )):  # fmt: skip
        tracker_config(parse([*given, "--detector", "knn", "--open-size", "9",
                              "--bootstrap", "first"]))  # fmt: skip
    with pytest.raises(ValueError, match=r"^--detector mog2: with --no-refine .* so it does "):
        tracker_config(parse([*given, "--detector", "mog2"]))
    # the joint sampler reads the detector's foreground: taken
    cfg = tracker_config(parse([*given, "--detector", "mog2", "--sampler", "rjmcmc"]))
    assert cfg.detector == "mog2" and not cfg.refine.enabled
    tracker_config(parse([*given, "--detector", "paper"]))  # the defaults, named: taken


def test_options_of_given_detections_are_taken_with_them(video: Path, tmp_path: Path) -> None:
    from pftrack.cli import build_parser
    from pftrack.cli._options import (
        DEFAULT_BIRTH_SCORE,
        DEFAULT_MAX_COAST,
        DEFAULT_SIZE_RATIO,
        tracker_config,
    )
    from pftrack.tracking import LifecycleConfig

    assert DEFAULT_BIRTH_SCORE == LifecycleConfig().birth_score
    assert DEFAULT_MAX_COAST == LifecycleConfig().max_coast
    assert DEFAULT_SIZE_RATIO == LifecycleConfig().size_ratio == 0.8
    parse = build_parser().parse_args
    det = ["--detections", "d.txt"]
    cfg = tracker_config(parse(["track", "v", "--out", "o", *det, "--min-conf", "-5",
                                "--birth-score", "0.5", "--det-scale", "2",
                                "--no-refine"]))  # fmt: skip
    assert (cfg.lifecycle.min_score, cfg.lifecycle.birth_score) == (-5, 0.5)
    assert not cfg.refine.enabled and cfg.lifecycle.size_ratio == DEFAULT_SIZE_RATIO
    for value, ratio in (("0.7", 0.7), ("off", None)):
        cfg = tracker_config(parse(["track", "v", "--out", "o", *det, "--size-ratio", value]))
        assert cfg.lifecycle.size_ratio == ratio
    cfg = tracker_config(parse(["track", "v", "--out", "o", "--min-conf", "0.5"]))  # built-in
    assert (cfg.lifecycle.min_score, cfg.lifecycle.birth_score) == (0.5, DEFAULT_BIRTH_SCORE)
    with pytest.raises(ValueError, match=r"LifecycleConfig: birth_score is 1.5, expected a value"):
        LifecycleConfig(birth_score=1.5)


def test_fill_help_says_what_it_does_with_smoothing(capsys: pytest.CaptureFixture[str]) -> None:
    """``--fill pf`` changes the smoothed output too (it guides linking): was documented as an
    option of ``--no-smooth`` only."""
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert (
        "written as they are with --no-smooth; with smoothing the smoother's boxes replace "
        "them, and they only guide the offline linking (and --crossings)" in text
    )


@pytest.mark.parametrize("command", ["track", "batch"])
def test_no_refine_help_says_refinement_assumes_upright_people(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: PETS09 turned 90 degrees with its detections scored MOTA 43.7 refined,
    66.8 with --no-refine, and nothing said that refinement assumes upright people."""
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split()).replace("- ", "-")  # argparse's wraps
    assert (
        "Use it too for sideways or overhead-rotated footage: refinement, like the built-in "
        "detector, assumes upright people" in text
    )


def test_track_help_says_output_boxes_are_not_clipped(capsys: pytest.CaptureFixture[str]) -> None:
    """A user trial found output boxes past the frame's edge (input boxes are clipped)."""
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert (
        "The boxes are the filters' estimates, not clipped to the frame: near its edge one may "
        "reach past it by a few pixels, as ground-truth boxes do (clip them before cropping)."
    ) in text


def test_recover_on_a_truncated_video_says_where_it_ends(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The colour term needs frame 9, past the end of a video whose header says 12 frames."""
    cut = _truncated_video(tmp_path, np.random.default_rng(3), 12)
    src = tmp_path / "t.txt"
    src.write_text("".join(f"{f},{1 if f < 5 else 2},{10 + f},10,8,16,1,-1,-1,-1\n"
                           for f in (1, 2, 3, 9, 10)))  # fmt: skip
    argv = ["recover", str(src), "--out", str(tmp_path / "o.txt"), "--link", "--video", str(cut)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    head = f"pftrack recover: error: {cut}: frame 9 cannot be decoded: the video ended after "
    assert err.startswith(head) and err.endswith(" frames but its header says 12\n"), err
    assert not (tmp_path / "o.txt").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["smooth", "A", "B", "--out", "/sys/pftrack-no/x", "--workers", "0"],
        ["batch", "V", "--out", "/sys/pftrack-no/x", "--workers", "0"],
        ["demo", "--out-dir", "/sys/pftrack-no/x"],
    ],
    ids=["smooth batch", "batch", "demo"],
)
def test_an_output_folder_that_cannot_be_created_is_one_line(
    argv: list[str], tmp_path: Path, video: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    if not Path("/sys").is_dir():
        pytest.skip("no /sys (a folder nobody can create files in) here")
    a, b = _tracks(tmp_path / "a.txt"), _tracks(tmp_path / "b.txt")
    argv = [{"A": str(a), "B": str(b), "V": str(video)}.get(x, x) for x in argv]
    assert main(argv) == 2  # was: "Operation not permitted: /sys/x" without the option
    err = capsys.readouterr().err.strip()
    flag = "--out-dir" if argv[0] == "demo" else "--out"
    assert err.startswith(
        f"pftrack {argv[0]}: error: {flag} /sys/pftrack-no/x: cannot create the folder"
    )  # batch's check before its cluster also names the folder in the way (": /sys is not ...")
    assert "(Operation not permitted)" in err or "(Permission denied)" in err  # root, or not
    assert "\n" not in err


def test_fps_without_render_is_refused(
    video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``--fps 5`` without ``--render`` was ignored (the same bytes), while every
    other option that does nothing is refused."""
    assert main(["track", str(video), "--out", str(tmp_path / "t.txt"), "--fps", "5"]) == 2
    assert capsys.readouterr().err == (
        "pftrack track: error: --fps 5 is the frame rate of --render's video; without --render "
        "nothing uses it (tracking counts frames): drop it, or give --render VIDEO\n"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("fps", ["1e-300", "1e308", "0.001", "nan"])
def test_track_fps_is_bounded(
    fps: str, video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # was: 1e-300 accepted, and an --render video written at 1e-300 frames/s
    with pytest.raises(SystemExit) as exc:
        main(["track", str(video), "--out", str(tmp_path / "t.txt"), "--fps", fps])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("pftrack track: error: argument --fps: expected a number in [0.01, 1000]")


@pytest.mark.parametrize("command", ["track", "batch"])
def test_crossings_without_the_smoother_are_refused(
    command: str, video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # was: accepted, and the crossing repair (part of the smoothing pass) silently never ran
    out = tmp_path / ("t.txt" if command == "track" else "out")
    argv = [command, str(video), "--out", str(out), "--crossings", "on", "--no-smooth"]
    assert main([*argv, "--workers", "0"] if command == "batch" else argv) == 2
    assert capsys.readouterr().err == (
        f"pftrack {command}: error: --crossings on needs the smoother, which --no-smooth turns "
        "off; drop one of them\n"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["track", "V", "--out", "O", "--seed", "-1"], "argument --seed: expected an integer >= 0"),
        (["demo", "--seed", "-1"], "argument --seed: expected an integer >= 0, got -1"),
        (["batch", "V", "--out", "O", "--seed", "-1"], "argument --seed: expected an integer >= 0"),
        (["recover", "T", "--out", "O", "--seed", "-1"], "argument --seed: expected an integer"),
        (
            ["eval", "--gt", "T", "--res", "T", "--image-size", "0", "360"],
            "argument --image-size: expected an integer in [1, 100000], got 0",
        ),
        (
            ["track", "V", "--out", "O", "--min-conf", "nan"],
            "argument --min-conf: expected a finite number, got nan",
        ),
        (
            ["track", "V", "--out", "O", "--birth-score", "nan"],
            "argument --birth-score: expected a number in [0, 1], got nan",
        ),
        (  # was: accepted with --detections, though scores are confidences in [0, 1]
            ["track", "V", "--out", "O", "--detections", "T", "--birth-score", "-1"],
            "argument --birth-score: expected a number in [0, 1], got -1",
        ),
        (
            ["batch", "V", "--out", "O", "--detections", "auto", "--birth-score", "5"],
            "argument --birth-score: expected a number in [0, 1], got 5",
        ),
        (
            ["smooth", "T", "--out", "O", "--max-gap", "100000000"],
            "argument --max-gap: expected an integer in [1, 100000], got 100000000",
        ),
        (
            ["recover", "T", "--out", "O", "--max-gap", "100001"],
            "argument --max-gap: expected an integer in [1, 100000], got 100001",
        ),
        (
            ["track", "V", "--out", "O", "--det-scale", "1e-7"],
            "argument --det-scale: expected a number in [0.001, 1000], got 1e-07",
        ),
        (
            ["batch", "V", "--out", "O", "--det-scale", "1e-7"],
            "argument --det-scale: expected a number in [0.001, 1000], got 1e-07",
        ),
        (
            ["batch", "V", "--out", "O", "--det-scale", "nan"],
            "argument --det-scale: expected a number in [0.001, 1000], got nan",
        ),
    ],
)
def test_bad_option_values_are_named_in_one_line(
    argv: list[str],
    message: str,
    video: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Were: "expected non-negative integer", "LifecycleConfig: min_score is nan", a nan
    birth score accepted, "LinkConfig.max_gap is ...", "fill_gaps: max_gap is ...",
    batch's --det-scale accepting what track refused (the sequence then failed), recover's
    --seed -1 accepted, and eval's "gt: evaluate_mot: image_size is (0, 360)"."""
    tracks = _tracks(tmp_path / "t.txt")
    names = {"V": str(video), "T": str(tracks), "O": str(tmp_path / "o.txt")}
    argv = [names.get(a, a) for a in argv]
    if argv[0] == "demo":
        argv += ["--out-dir", str(tmp_path / "d")]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith(f"pftrack {argv[0]}: error: {message}"), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.txt"]


@pytest.mark.parametrize(
    ("detections", "message"),
    [
        ("nosuch.txt", "--detections not found: nosuch.txt"),
        ("folder", "--detections folder is a folder, not a file"),
        # was "detection file not found: /dev/null"
        ("/dev/null", "--detections /dev/null is not a regular file (a device, pipe or socket)"),
    ],
)
def test_a_detection_file_that_is_not_a_file_is_named(
    detections: str,
    message: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # was "detection file not found: folder", and for a missing file beside a sequence folder
    # (seqinfo.ini) "No such file or directory: nosuch.txt"
    seq = tmp_path / "SEQ"
    make_scene(n_frames=5, rng=0).write_images(seq / "img1")
    (seq / "det").mkdir()
    (seq / "det" / "det.txt").write_text("1,-1,10,10,20,40,1\n")
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=960\n")
    (tmp_path / "folder").mkdir()
    monkeypatch.chdir(tmp_path)
    assert main(["track", "SEQ", "--detections", detections, "--out", "t.txt"]) == 2
    assert capsys.readouterr().err == f"pftrack track: error: {message}\n"
    assert not (tmp_path / "t.txt").exists()


def test_option_bounds_stated_for_help_are_the_librarys(tmp_path: Path) -> None:
    from pftrack.cli import batch
    from pftrack.cli._options import DET_SCALE_RANGE
    from pftrack.recovery import LinkConfig, fill_gaps
    from pftrack.recovery.fill import MAX_GAP_LIMIT
    from pftrack.tracking import load_detections

    assert batch.MAX_GAP == MAX_GAP_LIMIT
    LinkConfig(max_gap=batch.MAX_GAP)
    with pytest.raises(ValueError, match="max_gap"):
        LinkConfig(max_gap=batch.MAX_GAP + 1)
    with pytest.raises(ValueError, match="max_gap"):
        fill_gaps(np.zeros((0, 10)), "linear", batch.MAX_GAP + 1)
    from pftrack.cli._options import iou_threshold

    one = np.array([[1, 1, 10, 10, 20, 40, 1, -1, -1, -1]], dtype=np.float64)
    for inside in ("1", "1e-9"):
        evaluate_mot(one, one, iou_threshold=iou_threshold(inside))
    for outside in (0.0, 1.0 + 1e-9, float("nan")):
        with pytest.raises(ValueError, match="iou_threshold"):
            evaluate_mot(one, one, iou_threshold=outside)
        with pytest.raises(argparse.ArgumentTypeError):
            iou_threshold(str(outside))
    lo, hi = DET_SCALE_RANGE
    empty = tmp_path / "det.txt"
    empty.write_text("")
    for inside in (lo, hi):
        load_detections(empty, inside)
    for outside in (lo * 0.999, hi * 1.001):
        with pytest.raises(ValueError, match="detection scale"):
            load_detections(empty, outside)


def test_fps_range_is_seqinfos_frame_rate_range() -> None:
    from pftrack.cli._options import FPS_RANGE
    from pftrack.io.video import FRAME_RATE_RANGE

    assert FPS_RANGE == FRAME_RATE_RANGE


def test_help_shows_the_bounds_of_det_scale_and_max_gap(
    capsys: pytest.CaptureFixture[str],
) -> None:
    for command, option, bound in (("track", "--det-scale S", "(0.001 to 1000"),
                                   ("batch", "--det-scale S", "(0.001 to 1000)"),
                                   ("smooth", "--max-gap FRAMES", "(1 to 100000;"),
                                   ("recover", "--max-gap FRAMES", "(1 to 100000;")):  # fmt: skip
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        assert bound in text.split(f" {option} ")[-1].split(" --")[0], (command, option)


@pytest.mark.parametrize(
    "source", ["empty.txt", "0", "rtsp://127.0.0.1:1/x", "http://127.0.0.1:1/x.mp4"]
)
def test_an_unreadable_source_is_one_line_without_opencv_logs(source: str, tmp_path: Path) -> None:
    # was: OpenCV's "[ WARN:0@0.030] global cap.cpp:212 open VIDEOIO(FFMPEG) ..." and FFmpeg's
    # "[tcp @ 0x...] Connection to tcp://127.0.0.1:1 failed" before pftrack's own error
    import subprocess
    import sys

    if source == "0" and Path("/dev/video0").exists():
        pytest.skip("this machine has a camera 0: it would be tracked")
    (tmp_path / "empty.txt").write_bytes(b"")
    env = {k: v for k, v in os.environ.items() if not k.startswith("OPENCV_")}
    run = subprocess.run([sys.executable, "-m", "pftrack", "-q", "track", source, "--out", "o.txt"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, check=False,
                         timeout=120)  # fmt: skip
    assert run.returncode == 2
    assert run.stderr.startswith("pftrack track: error: cannot "), run.stderr
    assert run.stderr.count("\n") == 1, run.stderr


def test_main_silences_opencv_only_while_a_command_runs(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    import cv2

    import pftrack.cli.evaluate as evaluate

    for name in ("OPENCV_LOG_LEVEL", "OPENCV_FFMPEG_LOGLEVEL"):
        monkeypatch.delenv(name, raising=False)
    log = cv2.utils.logging
    level = log.getLogLevel()
    assert level != log.LOG_LEVEL_SILENT
    seen: dict[str, object] = {}

    def spy(args: object) -> int:
        seen.update(level=log.getLogLevel(), env=os.environ.get("OPENCV_FFMPEG_LOGLEVEL"))
        return 0

    monkeypatch.setattr(evaluate, "run", spy)
    assert main(["eval", "--gt", "g.txt", "--res", "r.txt"]) == 0
    assert seen == {"level": log.LOG_LEVEL_SILENT, "env": "-8"}
    # a caller's own process gets its settings back
    assert log.getLogLevel() == level and "OPENCV_FFMPEG_LOGLEVEL" not in os.environ
    monkeypatch.setenv("OPENCV_LOG_LEVEL", "DEBUG")  # the user's choice is kept
    assert main(["eval", "--gt", "g.txt", "--res", "r.txt"]) == 0
    assert seen["level"] == level


@pytest.mark.parametrize("command", ["batch", "smooth"])
def test_a_batch_without_dask_says_how_to_install_it(
    command: str,
    video: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "distributed", None)  # as if not installed
    inputs = [str(video)] if command == "batch" else [
        str(_tracks(tmp_path / "a.txt")), str(_tracks(tmp_path / "b.txt"))
    ]  # fmt: skip
    out = tmp_path / "out"
    assert main([command, *inputs, "--out", str(out), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    # was: "pftrack batch: error: No module named 'distributed'", the hint never reached
    if command == "batch":
        assert err.startswith("pftrack batch: error: batches run on Dask, which cannot be "
                              "imported (")  # fmt: skip
        assert err.endswith(
            "pip install 'pftrack[dask]' (dask[distributed]); or --workers 0: in this process, "
            "without Dask\n"
        )
    else:  # first why smooth runs a batch at all (two files given)
        assert err.startswith("pftrack smooth: error: 2 inputs: pftrack smooth runs them as a "
                              "batch, on Dask by default, which cannot be imported (")  # fmt: skip
        assert err.endswith("or --workers 0 to run them one after another in this process\n")
    assert err.count("\n") == 1 and not out.exists()  # nothing run, not even --out created


def test_a_one_frame_video_with_detections_blames_min_hits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = make_scene(n_frames=1, width=160, height=120, n_walkers=1, rng=0)
    scene.write_video(tmp_path / "one.avi")
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 0.9
    write_mot(tmp_path / "det.txt", det)
    argv = ["-q", "track", str(tmp_path / "one.avi"), "--detections", str(tmp_path / "det.txt")]
    assert main([*argv, "--out", str(tmp_path / "t.txt")]) == 0
    # was: "the highest detection confidence was 0.9 (min_conf 0, birth_score 0.9)"
    assert capsys.readouterr().err == (
        "pftrack track: warning: no track over 1 frame: 1 track started but none reached "
        "min_hits=4 matched frames (shorter tracks are left out)\n"
    )


def test_a_tracks_file_given_as_detections_is_said(
    video: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--detections`` of another tracker's output (ids, not -1) was read with its ids
    ignored without a word."""
    import warnings

    write_mot(tmp_path / "tracks.txt", scene.truth)
    argv = ["-q", "track", str(video), "--detections", str(tmp_path / "tracks.txt")]
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main([*argv, "--out", str(tmp_path / "t.txt")]) == 0
    err = capsys.readouterr().err
    assert err.startswith(
        f"pftrack track: warning: {tmp_path / 'tracks.txt'}: {len(scene.truth)} of "
        f"{len(scene.truth)} rows have a track id, not -1 (the first: id "
    )
    assert "the ids are ignored, the tracker makes its own\n" in err
    assert (tmp_path / "t.txt").exists()


def test_an_empty_detection_file_is_said_to_be_empty(
    video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "det.txt").write_text("")
    argv = ["-q", "track", str(video), "--detections", str(tmp_path / "det.txt")]
    assert main([*argv, "--out", str(tmp_path / "t.txt")]) == 0
    # was: "no external detection was given", of a run that was given a detection file
    assert capsys.readouterr().err == (
        "pftrack track: warning: no track over 60 frames: the detections given held no box\n"
    )


@pytest.mark.parametrize(
    ("argv", "command"),
    [
        (["smooth", "t.txt", "--out", "o.txt", "--explain"], "smooth"),
        (["recover", "t.txt", "--out", "o.txt", "--bogus"], "recover"),
        (["track", "v.avi", "--out", "o.txt", "--bogus"], "track"),
        (["batch", "v.avi", "--out", "o", "--bogus"], "batch"),
        (["eval", "--gt", "g.txt", "--res", "r.txt", "--bogus"], "eval"),
        (["demo", "--bogus"], "demo"),
        (["experiment", "gaps", "--gt", "g.txt", "--bogus", "1"], "experiment gaps"),
        (["smooth", "t.txt", "--out", "o.txt", "extra.txt"], "smooth"),
    ],
)
def test_an_unknown_option_is_named_by_its_command(
    argv: list[str], command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Regression: ``pftrack smooth ... --explain`` printed the top-level usage and
    ``pftrack: error: unrecognized arguments``."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1  # one line, not argparse's usage block before it
    assert err.startswith(f"pftrack {command}: error: unrecognized arguments: ")


@pytest.mark.parametrize(
    "argv",
    [
        ["track", "v.avi", "--out", "o.txt", "--max-side", "10"],
        ["track", "v.avi", "--out", "o.txt", "--fps", "0"],
        ["track", "v.avi", "--out", "o.txt", "--seed", "1.5"],
        ["batch", "v.avi", "--out", "o", "--workers", "-1"],
        ["demo", "--frames", "0"],
        [],
    ],
)
def test_a_bad_option_value_is_one_line(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """A value argparse refuses printed the command's 14-line usage before the error."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and err.startswith("pftrack") and ": error: " in err


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
def test_a_folder_where_no_file_can_be_made_is_said_so(
    video: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """/proc exists and looks writable to root: 'folder /proc is not writable (No such file or
    directory)' contradicted itself."""
    assert main(["track", str(video), "--out", "/proc/pftrack-test.txt"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("pftrack track: error: --out /proc/pftrack-test.txt: ")
    assert "no file can be made in folder /proc (" in err or "not writable" in err


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["track", "v.avi", "--detections", "", "--out", "o.txt"], "--detections"),
        (["recover", "", "--out", "o.txt"], "TRACKS"),
        (["recover", "t.txt", "--link", "--video", "", "--out", "o.txt"], "--video"),
        (["render", "v.avi", "", "--out", "r.mp4"], "TRACKS"),
        (["eval", "--gt", "", "--res", "t.txt"], "--gt"),
        (["batch", "", "--out", "o"], "INPUTS"),
    ],
)
def test_an_empty_argument_is_refused_by_name(
    argv: list[str], named: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    """A user trial: ``--detections ''`` was ignored (the built-in detector ran, exit 0), and
    ``''`` as an input or ``--gt`` was the current folder."""
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert capsys.readouterr().err == f"pftrack {argv[0]}: error: {named} is empty; give a value\n"
    assert list(tmp_path.iterdir()) == []


def test_an_opencv_error_is_one_line_and_exit_2(monkeypatch, capsys, tmp_path):
    """OpenCV refusing an input pftrack did not check first (a path the trials found: a
    figure of a 1 x 100000 image) is one line, exit 2; another exception stays a traceback."""
    import cv2

    from pftrack.cli import evaluate

    def refused(args: argparse.Namespace) -> int:
        cv2.resize(np.zeros((0, 0), np.uint8), (4, 4))
        return 0

    monkeypatch.setattr(evaluate, "run", refused)
    gt = tmp_path / "gt.txt"
    gt.write_text("1,1,10,10,5,5,1,1,1\n")
    assert main(["eval", "--gt", str(gt), "--res", str(gt)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pftrack eval: error: OpenCV(") and err.count("\n") == 1

    def bug(args: argparse.Namespace) -> int:
        raise KeyError("a defect")

    monkeypatch.setattr(evaluate, "run", bug)
    with pytest.raises(KeyError):
        main(["eval", "--gt", str(gt), "--res", str(gt)])


def test_experiment_repeat_is_bounded(capsys):
    # was: --repeat 100000000 (a typo) ran without a word until killed (a user trial)
    with pytest.raises(SystemExit) as info:
        main(["experiment", "gaps", "--gt", "gt.txt", "--repeat", "100000000"])
    assert info.value.code == 2
    assert "--repeat: expected an integer in [1, 1000], got 100000000" in capsys.readouterr().err


def test_a_file_named_with_a_leading_dash_is_named_with_the_way_to_give_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``pftrack track -clip.mp4 --out t.txt``: was ``the following arguments are required:
    source``, of a source given (argparse takes ``-clip.mp4`` for an option)."""
    monkeypatch.chdir(tmp_path)
    video = make_scene(n_frames=8, width=96, height=64, rng=0).write_video(tmp_path / "v.avi")
    Path("-clip.mp4").write_bytes(video.read_bytes())
    hint = (
        "(-clip.mp4 is a file, read as an option: give it as ./-clip.mp4, or after -- at the end)"
    )
    for argv, what in (
        (["track", "-clip.mp4", "--out", "t.txt"], "the following arguments are required: source"),
        (["track", str(video), "--out", "t.txt", "-clip.mp4"], "unrecognized arguments: -clip.mp4"),
    ):
        with pytest.raises(SystemExit) as exit_:
            main(["-q", *argv])
        assert exit_.value.code == 2
        assert capsys.readouterr().err == f"pftrack track: error: {what} {hint}\n"
    assert main(["-q", "track", "--out", "t.txt", "--", "-clip.mp4"]) == 0
    assert main(["-q", "track", "./-clip.mp4", "--out", "t2.txt"]) == 0
    assert Path("t.txt").read_text() == Path("t2.txt").read_text()
    with pytest.raises(SystemExit):  # no such file: argparse's words alone
        main(["-q", "track", "-other.mp4", "--out", "t.txt"])
    assert capsys.readouterr().err.endswith("are required: source\n")
