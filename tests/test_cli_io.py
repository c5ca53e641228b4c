"""``pftrack track`` inputs and outputs: sequences, live streams, Ctrl-C, --render, help."""

from __future__ import annotations

import argparse
import itertools
import os
import re
import signal
import stat
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import av
import cv2
import numpy as np
import pytest

from pftrack import _progress
from pftrack._threads import BLAS_THREAD_VARIABLES
from pftrack.cli import build_parser, main
from pftrack.cli._signals import Terminated
from pftrack.eval import evaluate_mot
from pftrack.io.mot import read_mot, write_mot
from pftrack.io.video import FrameSource, read_seqinfo
from pftrack.synthetic import Scene, make_scene
from tests.conftest import dataset
from tests.earlier_outputs import TRACKS
from tests.io.streaming import serve_stream


@pytest.fixture(scope="module")
def scene() -> Scene:
    return make_scene(n_frames=60, rng=0)


@pytest.fixture(scope="module")
def sequence(scene: Scene, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A MOTChallenge sequence folder: unpadded images, seqinfo.ini at 7 fps, det/det.txt."""
    seq = tmp_path_factory.mktemp("seq") / "SYN-01"
    (seq / "img1").mkdir(parents=True)
    for k, frame in enumerate(scene.frames, start=1):
        cv2.imwrite(str(seq / "img1" / f"{k}.png"), frame)
    (seq / "seqinfo.ini").write_text(
        f"[Sequence]\nname=SYN-01\nimDir=img1\nframeRate=7\nseqLength={len(scene.frames)}\n"
        f"imWidth={scene.width}\nimHeight={scene.height}\nimExt=.png\n"
    )
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 1.0
    (seq / "det").mkdir()
    write_mot(seq / "det" / "det.txt", det)
    return seq


@pytest.fixture
def umask() -> Iterator[int]:
    old = os.umask(0o027)
    yield 0o027
    os.umask(old)


def _video_info(path: Path) -> tuple[str, str, float, int]:
    with av.open(str(path)) as container:
        stream = container.streams.video[0]
        n = sum(1 for _ in container.decode(stream))
        ctx = stream.codec_context
        return ctx.name, ctx.pix_fmt, float(stream.average_rate or 0), n


def test_sequence_folder_with_auto_detections_renders_at_its_rate(
    sequence: Path, scene: Scene, tmp_path: Path, umask: int, capsys: pytest.CaptureFixture[str]
) -> None:
    out, video, plot = tmp_path / "t.txt", tmp_path / "r.mp4", tmp_path / "p.png"
    argv = ["track", str(sequence), "--detections", "auto", "--out", str(out),
            "--render", str(video), "--plot", str(plot)]  # fmt: skip
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "7 fps from seqinfo.ini" in text
    m = evaluate_mot(scene.truth, read_mot(out))
    assert m.mota > 0.8 and m.idf1 > 0.8
    assert _video_info(video) == ("h264", "yuv420p", 7.0, 60)
    assert cv2.imread(str(plot)).shape == (scene.height, scene.width, 3)
    for path in (out, video, plot):  # every output keeps the user's umask
        assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask, path.name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.png", "r.mp4", "t.txt"]


def test_fps_overrides_seqinfo(sequence: Path, tmp_path: Path) -> None:
    video = tmp_path / "r.mp4"
    argv = ["track", str(sequence), "--detections", "auto", "--out", str(tmp_path / "t.txt"),
            "--render", str(video), "--fps", "12.5", "--no-link"]  # fmt: skip
    assert main(argv) == 0
    assert _video_info(video)[2:] == (12.5, 60)


@pytest.mark.parametrize(
    ("ini", "said"),
    [
        # was: exit 0, an MP4 at 1e9 fps
        ("frameRate=1e9\n", "frameRate is '1e9', expected a frame rate in [0.01, 1000] frames "
                            "per second"),
        # was: "SEQ/seqinfo.ini: expected a [Sequence] section (MOTChallenge seqinfo.ini)"
        ("frameRate=7\nframeRate=8\n", "key frameRate in [Sequence] is given twice (lines 2 "
                                       "and 3); give it once"),
        # was: exit 0, imWidth=0.4 rounded to 0 and taken as absent (scale 1)
        ("frameRate=7\nimWidth=0.4\n", "imWidth is '0.4', expected an integer in 1..100000"),
        # was taken, and a later message printed a 300-digit number
        ("imWidth=1e300\n", "imWidth is '1e300', expected an integer in 1..100000"),
    ],
)  # fmt: skip
def test_a_bad_seqinfo_is_refused_before_any_output(
    ini: str, said: str, sequence: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seq = tmp_path / "SEQ"
    seq.mkdir()
    (seq / "img1").symlink_to(sequence / "img1", target_is_directory=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\n" + ini)
    out, video = tmp_path / "t.txt", tmp_path / "r.mp4"
    assert main(["track", str(seq), "--out", str(out), "--render", str(video)]) == 2
    assert capsys.readouterr().err == f"pftrack track: error: {seq}/seqinfo.ini: {said}\n"
    assert not out.exists() and not video.exists()


def test_a_seqinfo_that_is_not_utf8_is_read_for_its_numbers(sequence: Path, tmp_path: Path) -> None:
    """A user trial: ``name=Caf\\xe9`` (Latin-1) stopped track, render, batch and experiment
    with a decoder's message that named no file; the keys pftrack reads are ASCII. The name is
    read as Windows-1252 (was "Caf\ufffd"; tests/io/test_seqinfo_kinds.py)."""
    seq = tmp_path / "SEQ"
    seq.mkdir()
    (seq / "img1").symlink_to(sequence / "img1", target_is_directory=True)
    (seq / "seqinfo.ini").write_bytes(b"[Sequence]\nname=Caf\xe9\nframeRate=7\nimWidth=9\n")
    info = read_seqinfo(seq)
    assert (info.name, info.frame_rate, info.width) == ("Caf\u00e9", 7.0, 9)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_a_utf16_seqinfo_is_read_as_its_det_and_gt_are(
    encoding: str, sequence: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial: a seqinfo.ini written by Windows PowerShell 5's ``>`` (UTF-16 with its BOM) was
    refused as "expected a [Sequence] section", while det.txt and gt.txt so written are read."""
    from pftrack.eval.sequences import read_seqinfo as read_ini

    seq = tmp_path / "SEQ"
    seq.mkdir()
    (seq / "img1").symlink_to(sequence / "img1", target_is_directory=True)
    text = "[Sequence]\r\nname=Caf\u00e9\r\nframeRate=7\r\nimWidth=9\r\nimHeight=6\r\n"
    bom = b"\xfe\xff" if encoding.endswith("be") else b""  # utf-16 writes its own
    (seq / "seqinfo.ini").write_bytes(bom + text.encode(encoding))
    info = read_seqinfo(seq)
    assert (info.name, info.frame_rate, info.width, info.height) == ("Caf\u00e9", 7.0, 9, 6)
    assert read_ini(seq / "seqinfo.ini")["framerate"] == "7"
    (seq / "seqinfo.ini").write_bytes(bom + (text + "frameRate=8\r\n").encode(encoding))
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: {seq}/seqinfo.ini: key frameRate in [Sequence] is given twice "
        "(lines 3 and 6); give it once\n"
    )


@pytest.mark.parametrize(
    ("factor", "where"), [(2, "lie in the top-left"), (0.5, "lie wholly outside the")]
)
def test_a_seqinfo_size_that_is_not_its_images_is_refused_not_scaled(
    factor: float,
    where: str,
    sequence: Path,
    scene: Scene,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A trial: seqinfo.ini saying 1280x960 beside 640x480 images and their det.txt tracked
    the boxes scaled by 0.5 into the top-left corner (exit 0, a warning to scale them: pftrack
    had); saying 320x240, the refusal asked "in a larger frame's pixels? ... about 1 here"."""
    seq = tmp_path / "SEQ"
    seq.mkdir()
    (seq / "img1").symlink_to(sequence / "img1", target_is_directory=True)
    (seq / "det").symlink_to(sequence / "det", target_is_directory=True)
    w, h = int(scene.width * factor), int(scene.height * factor)
    (seq / "seqinfo.ini").write_text(f"[Sequence]\nframeRate=7\nimWidth={w}\nimHeight={h}\n")
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pftrack track: error: ") and err.count("\n") == 1, err
    assert f", scaled by {1 / factor:g} (the frames' width {scene.width} over imWidth={w} " in err
    assert where in err and "and as given they fit those frames" in err
    assert err.endswith(
        f"pixels already: seqinfo.ini's {w}x{h} is not its images' size? correct it to "
        f"{scene.width}x{scene.height} (gt.txt is scaled by it too), or give --det-scale 1 / "
        "load_detections(scale=1)\n"
    )
    assert not out.exists()
    argv = ["track", str(seq), "--detections", "auto", "--det-scale", "1", "--out", str(out)]
    assert main([*argv, "-q"]) == 0  # as the message says
    assert evaluate_mot(scene.truth, read_mot(out)).mota > 0.8


def test_sequence_detections_in_seqinfo_pixels_are_scaled(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Like PETS09 (boxes in 768x576, video 480x360): seqinfo.ini's imWidth sets the scale."""
    seq = tmp_path / "BIG"
    (seq / "det").mkdir(parents=True)
    (seq / "img1").symlink_to(sequence / "img1")
    (seq / "seqinfo.ini").write_text(f"[Sequence]\nframeRate=7\nimWidth={2 * scene.width}\n")
    det = read_mot(sequence / "det" / "det.txt")
    det[:, 2:6] *= 2
    write_mot(seq / "det" / "det.txt", det)
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out)]) == 0
    assert "detections scaled by 0.5" in capsys.readouterr().out
    assert evaluate_mot(scene.truth, read_mot(out)).mota > 0.8
    # --det-scale wins: 1 leaves the boxes too large, half of them wholly outside the frames,
    # which is refused before any work (it was a clipping warning, exit 0), naming the scale
    out.unlink()
    argv = ["track", str(seq), "--detections", "auto", "--det-scale", "1", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    # the exact ratio: seqinfo.ini's (was "about 0.5", an estimate from the boxes' reach)
    assert "wholly outside" in err and not out.exists()
    assert err.endswith(f"0.5 here (480 px frames, imWidth=960 in {seq}/seqinfo.ini)\n")


def test_det_scale_hint_is_the_exact_ratio_of_seqinfo(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user report: PETS09's det.txt with ``--det-scale 1`` was told "about 0.626" (its
    boxes reach 767 of 768 px), where the documented factor is 480/768 = 0.625."""
    seq = tmp_path / "PETS"
    (seq / "det").mkdir(parents=True)
    (seq / "img1").symlink_to(sequence / "img1")
    (seq / "seqinfo.ini").write_text("[Sequence]\nframeRate=7\nimWidth=768\nimHeight=576\n")
    det = read_mot(sequence / "det" / "det.txt")
    det[:, 2:6] *= 1.6
    write_mot(seq / "det" / "det.txt", det)
    argv = ["track", str(seq), "--detections", "auto", "--det-scale", "1", "--out",
            str(tmp_path / "t.txt")]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.endswith(f"--det-scale / load_detections(scale=...), 0.625 here (480 px frames, "
                        f"imWidth=768 in {seq}/seqinfo.ini)\n"), err  # fmt: skip
    # a wrong scale given: the hint is the whole scale to give, not a factor on top of it
    # (was "about 0.313" with --det-scale 2, the right value being 0.625)
    for given in ("2", "1.5"):
        argv[argv.index("--det-scale") + 1] = given
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.endswith("load_detections(scale=...), 0.625 here (480 px frames, imWidth=768 "
                            f"in {seq}/seqinfo.ini)\n"), err  # fmt: skip
    (seq / "seqinfo.ini").unlink()  # no size known: the estimate, also whole
    argv[1] = str(seq / "img1")
    argv[argv.index("--detections") + 1] = str(seq / "det" / "det.txt")
    assert main(argv) == 2
    assert capsys.readouterr().err.endswith("load_detections(scale=...), about 0.625 here\n")


def test_sequence_of_another_shape_than_its_seqinfo_is_refused(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: boxes scaled by the width's ratio on both axes, tracks far off, exit 0 (a 4:3
    sequence whose video was re-encoded to 16:9 scored MOTA -108)."""
    seq = tmp_path / "WIDE"
    (seq / "det").mkdir(parents=True)
    (seq / "img1").symlink_to(sequence / "img1")
    (seq / "seqinfo.ini").write_text(
        f"[Sequence]\nimWidth={2 * scene.width}\nimHeight={3 * scene.height}\n"
    )
    (seq / "det" / "det.txt").write_bytes((sequence / "det" / "det.txt").read_bytes())
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "another shape" in err and not out.exists()
    assert f"the frames are {scene.width}x{scene.height}" in err
    assert f"seqinfo.ini says {2 * scene.width}x{3 * scene.height}" in err
    # the same sequence with seqinfo.ini's height within 1 % of the width's ratio is scaled
    # (its boxes in seqinfo.ini's pixels: the frames' own are refused as scaled off them)
    (seq / "seqinfo.ini").write_text(
        f"[Sequence]\nimWidth={2 * scene.width}\nimHeight={2 * scene.height + 1}\n"
    )
    det = read_mot(sequence / "det" / "det.txt")
    det[:, 2:6] *= 2
    write_mot(seq / "det" / "det.txt", det)
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out)]) == 0
    assert evaluate_mot(scene.truth, read_mot(out)).mota > 0.8


def test_info_scale() -> None:
    from pftrack.io.video import info_scale

    assert info_scale((480, 360), (768, 576), "s") == 0.625
    assert info_scale((480, 360), (768, None), "s") == 0.625
    assert info_scale((480, 360), (None, None), "s") == 1.0
    with pytest.raises(ValueError, match=r"^s: the frames are 1280x720 but seqinfo.ini says 768"):
        info_scale((1280, 720), (768, 576), "s")


def _copy_sequence(sequence: Path, seq: Path, *, skip: str = "") -> Path:
    """`sequence` at `seq`: its images linked (all but `skip`), seqinfo.ini and det/ copied."""
    (seq / "img1").mkdir(parents=True)
    for image in (sequence / "img1").iterdir():
        if image.name != skip:
            (seq / "img1" / image.name).symlink_to(image)
    (seq / "det").mkdir()
    (seq / "det" / "det.txt").write_bytes((sequence / "det" / "det.txt").read_bytes())
    (seq / "seqinfo.ini").write_bytes((sequence / "seqinfo.ini").read_bytes())
    return seq


def test_a_sequence_without_seqinfo_takes_its_own_detections_as_batch_does(
    sequence: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A README trial: ``pftrack batch SEQ --detections auto`` read SEQ/det/det.txt of a folder
    without seqinfo.ini, ``pftrack track SEQ --detections auto`` refused it, so the batch's
    file could not be made again with ``track``."""
    seq = _copy_sequence(sequence, tmp_path / "SEQ")
    (seq / "seqinfo.ini").unlink()
    outs = [tmp_path / f"{k}.txt" for k in range(3)]
    assert main(["track", str(seq), "--detections", "auto", "--out", str(outs[0])]) == 0
    assert main(["track", str(seq / "img1"), "--detections", "auto", "--out", str(outs[1])]) == 0
    argv = ["track", str(seq / "img1"), "--detections", str(seq / "det" / "det.txt")]
    assert main([*argv, "--out", str(outs[2])]) == 0
    assert outs[0].read_bytes() == outs[1].read_bytes() == outs[2].read_bytes()
    capsys.readouterr()
    (seq / "img1").rename(seq / "frames")  # no longer laid out as a sequence
    assert main(["track", str(seq / "frames"), "--detections", "auto", "--out", "x.txt"]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: --detections auto: {seq}/frames is not a MOTChallenge sequence "
        "with det/det.txt (a folder with seqinfo.ini or img1/, or its img1/); give the detection "
        "file\n"
    )


def test_a_missing_image_of_a_sequence_is_one_line_not_a_shift(
    sequence: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 59 frames tracked, image 11 as frame 10, exit 0 (or, with detections up to the
    last frame, 'detections go up to frame 60 but the video has 59 frames')."""
    seq = _copy_sequence(sequence, tmp_path / "SEQ", skip="10.png")
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: {seq}/img1: image 10 is missing (names 1..60 are frame numbers; "
        "restore it: the sequence's detections and ground truth number its frames by them)\n"
    )
    assert not out.exists()
    # without detections too: its ground truth counts frames by name
    assert main(["track", str(seq), "--out", str(out)]) == 2
    assert "image 10 is missing" in capsys.readouterr().err and not out.exists()


def test_a_missing_image_of_a_plain_numbered_folder_is_one_line_not_a_shift(
    sequence: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The README's ``track seq/img1 --detections det.txt`` on a folder without seqinfo.ini.

    Was: exit 0, image 11 written as frame 10 and given frame 10's detections, and so on.
    Names of text and a number (frame_11.png) alike: were tracked, frame_11 given frame 10's
    detections.
    """
    seq = _copy_sequence(sequence, tmp_path / "SEQ", skip="10.png")
    (seq / "seqinfo.ini").unlink()
    out = tmp_path / "t.txt"
    argv = ["track", str(seq / "img1"), "--detections", str(seq / "det" / "det.txt"),
            "--out", str(out)]  # fmt: skip
    # SEQ/img1 is a sequence's image folder even without seqinfo.ini (as pftrack batch takes it)
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: {seq}/img1: image 10 is missing (names 1..60 are frame numbers; "
        "restore it: the sequence's detections and ground truth number its frames by them)\n"
    )
    (seq / "img1").rename(seq / "frames")  # a folder of no sequence
    argv[1] = str(seq / "frames")
    remedy = (
        "skip numbers): detections cannot be matched to these images (their frame numbers may "
        "be the names or the images' positions); rename the images 1..N in their order and "
        "number the detections' frames alike (frame k: the k-th image), or track without "
        "detections (frames 1..N in the names' order)\n"
    )
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: {seq}/frames: image 10 is missing (names 1..60 {remedy}"
    )
    assert not out.exists()
    for image in (seq / "frames").iterdir():
        image.rename(image.with_name(f"frame_{image.name}"))
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: {seq}/frames: image frame_10 is missing (names frame_1..frame_60 "
        f"{remedy}"
    )
    assert not out.exists()


def test_a_plain_folder_whose_names_skip_numbers_tracks_its_images_in_order(
    scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Millisecond time stamps or every fifth frame, without detections: was refused ('image 2
    is missing (names ... are frame numbers)', exit 2). Frames are numbered 1..N in the names'
    order: the same rows as the images named 1..N."""
    consecutive, stamps, fifth = tmp_path / "n", tmp_path / "ms", tmp_path / "five"
    for folder in (consecutive, stamps, fifth):
        folder.mkdir()
    for k, frame in enumerate(scene.frames):
        cv2.imwrite(str(consecutive / f"{k + 1}.png"), frame)
        cv2.imwrite(str(stamps / f"{1690000000000 + 33 * k + k % 3}.png"), frame)
        cv2.imwrite(str(fifth / f"{1 + 5 * k}.png"), frame)
    outs = [tmp_path / f"{folder.name}.txt" for folder in (consecutive, stamps, fifth)]
    for folder, out in zip((consecutive, stamps, fifth), outs, strict=True):
        assert main(["track", str(folder), "--out", str(out), "--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert outs[0].read_bytes() == outs[1].read_bytes() == outs[2].read_bytes()
    assert read_mot(outs[0])[:, 0].max() == len(scene.frames)


def test_a_folder_of_12_bit_pngs_tracks_as_its_8_bit_frames_with_one_warning(
    scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 12-bit camera's 16-bit PNGs (8-bit level v stored as 16 v + 0..15). Was: frames read
    as value / 256, 0-15, almost black, without a word: 0 tracks."""
    eight, twelve = tmp_path / "eight", tmp_path / "twelve"
    scene.write_images(eight)
    twelve.mkdir()
    noise = np.random.default_rng(0)
    for k, frame in enumerate(scene.frames, start=1):
        low = noise.integers(0, 16, frame.shape, dtype=np.uint16)
        cv2.imwrite(str(twelve / f"{k:06d}.png"), frame.astype(np.uint16) * 16 + low)
    outs = [tmp_path / "8.txt", tmp_path / "12.txt"]
    for folder, out in zip((eight, twelve), outs, strict=True):
        assert main(["track", str(folder), "--out", str(out), "--quiet"]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    top = int(cv2.imread(str(twelve / "000001.png"), cv2.IMREAD_UNCHANGED).max())
    assert warned == [
        f"pftrack track: warning: {twelve}: its 16-bit images hold 12-bit values (000001.png "
        f"goes up to {top} of 65535): read as 12-bit data, each value / 16 to 8 bits (not / "
        "256, which makes them almost black)"
    ]
    assert outs[1].read_bytes() == outs[0].read_bytes()  # the same frames: the same tracks
    assert len(read_mot(outs[0])) > 0


def test_a_broken_image_in_a_folder_is_one_warning_and_every_frame_tracked(
    scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Trial61: one broken image at frame 298 of 300 ended ``pftrack track`` with an error,
    every frame tracked before it lost. The frame before stands in now, said on one line; a
    folder none of whose images can be read is one error line and exit 2."""
    folder = scene.write_images(tmp_path / "imgs")
    bad = folder / f"{len(scene.frames) - 2:06d}.png"
    bad.write_bytes(bad.read_bytes()[:200])  # a copy cut short
    out = tmp_path / "t.txt"
    assert main(["track", str(folder), "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(
        f"pftrack track: warning: frame {len(scene.frames) - 2}: cannot read image {bad}: "
    ), err
    assert err[0].endswith(
        "the frame before stands in for it, so the later frames keep their numbers"
    )
    assert read_mot(out)[:, 0].max() > len(scene.frames) - 2  # tracked past it
    for image in folder.iterdir():
        image.write_bytes(b"")
    assert main(["track", str(folder), "--out", str(out), "--quiet"]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: cannot read any of the {len(scene.frames)} images in folder "
        f"{folder}: 000001.png: it is empty (0 bytes)\n"
    )


def test_a_folder_of_sequences_given_to_track_names_them_and_batch(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 'no images (.jpg, ...) in folder MOT17', with no word of the sequences it holds."""
    bench = tmp_path / "MOT17"
    (bench / "MOT17-10" / "img1").mkdir(parents=True)  # a sequence without seqinfo.ini
    (bench / "MOT17-02").mkdir()
    (bench / "MOT17-02" / "seqinfo.ini").write_text("[Sequence]\nframeRate=30\n")
    (bench / "notes").mkdir()  # neither: not named
    out = tmp_path / "t.txt"
    assert main(["track", str(bench), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: folder {bench} holds 2 sequences (MOT17-02, MOT17-10) and no "
        f"images: give one of them ({bench / 'MOT17-02'}), or track them all with pftrack "
        f"batch {bench}\n"
    )
    (bench / "MOT17-02" / "seqinfo.ini").unlink()
    assert main(["track", str(bench), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: folder {bench} holds a sequence (MOT17-10) and no images: give "
        f"it ({bench / 'MOT17-10'})\n"
    )
    assert not out.exists()


def test_a_folder_of_videos_given_to_track_names_them_and_batch(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 'no images (.jpg, ...) in folder vids', with no word of the videos it holds."""
    vids = tmp_path / "vids"
    vids.mkdir()
    for name in ("b.avi", "a.mp4", "notes.txt"):
        (vids / name).write_bytes(b"")  # listed by name: never opened
    out = tmp_path / "t.txt"
    assert main(["track", str(vids), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: folder {vids} holds 2 videos (a.mp4, b.avi) and no images: give "
        f"one of them ({vids / 'a.mp4'}), or track them all with pftrack batch {vids}\n"
    )
    for name in ("c.mkv", "d.mov"):
        (vids / name).write_bytes(b"")
    assert main(["track", str(vids), "--out", str(out)]) == 2
    assert "holds 4 videos (a.mp4, b.avi, c.mkv, ...) and no images" in capsys.readouterr().err
    for name in ("a.mp4", "c.mkv", "d.mov"):
        (vids / name).unlink()
    assert main(["track", str(vids), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: folder {vids} holds a video (b.avi) and no images: give it "
        f"({vids / 'b.avi'})\n"
    )
    (vids / "b.avi").unlink()  # nothing to track: as before
    assert main(["track", str(vids), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: no images (.jpg, .jpeg, .png, .bmp, .tif, .tiff, .webp) in folder "
        f"{vids}\n"
    )
    assert not out.exists()


def test_a_seqinfo_with_a_byte_order_mark_is_read(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 'seqinfo.ini: expected a [Sequence] section' (det, gt and results took a BOM)."""
    seq = _copy_sequence(sequence, tmp_path / "SEQ")
    ini = seq / "seqinfo.ini"
    ini.write_bytes(b"\xef\xbb\xbf" + ini.read_bytes())
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out)]) == 0
    assert capsys.readouterr().out.startswith("60 frames, ")
    assert evaluate_mot(scene.truth, read_mot(out)).mota > 0.8


def test_auto_detections_need_a_sequence(
    scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video = scene.write_video(tmp_path / "v.avi")
    assert main(["track", str(video), "--detections", "auto", "--out", str(tmp_path / "t")]) == 2
    err = capsys.readouterr().err
    assert "--detections auto" in err and "det/det.txt" in err


def _video_sequence(sequence: Path, scene: Scene, seq: Path) -> Path:
    """`sequence` in the layout of the shared data: seqinfo.ini, video.avi, det.txt; no img1/."""
    seq.mkdir(parents=True)
    scene.write_video(seq / "video.avi")
    (seq / "det.txt").write_bytes((sequence / "det" / "det.txt").read_bytes())
    (seq / "seqinfo.ini").write_bytes((sequence / "seqinfo.ini").read_bytes())  # imDir=img1
    return seq


def test_a_sequence_folder_with_one_video_tracks_as_its_video(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 'SEQ/seqinfo.ini: image folder SEQ/img1 does not exist' (pftrack batch took it)."""
    seq = _video_sequence(sequence, scene, tmp_path / "SEQ")
    a, b, d = tmp_path / "a.txt", tmp_path / "b.txt", tmp_path / "D"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(a)]) == 0
    argv = ["track", str(seq / "video.avi"), "--detections", str(seq / "det.txt"), "--out", str(b)]
    assert main(argv) == 0
    argv = ["batch", str(seq), "--out", str(d), "--workers", "0", "--detections", "auto"]
    assert main(argv) == 0
    assert a.read_bytes() == b.read_bytes() == (d / "SEQ.txt").read_bytes()
    assert evaluate_mot(scene.truth, read_mot(a)).mota > 0.8
    capsys.readouterr()
    # the video it reads is an input: --render over it is refused before any work
    before = (seq / "video.avi").read_bytes()
    argv = ["track", str(seq), "--out", str(a), "--render", str(seq / "video.avi")]
    assert main(argv) == 2
    assert "is an input of this run" in capsys.readouterr().err
    assert (seq / "video.avi").read_bytes() == before
    # so is the det.txt that --detections auto finds: --out over it is refused too
    det = (seq / "det.txt").read_bytes()
    argv = ["track", str(seq), "--detections", "auto", "--out", str(seq / "det.txt")]
    assert main(argv) == 2
    assert "is an input of this run" in capsys.readouterr().err
    assert (seq / "det.txt").read_bytes() == det


def test_a_sequence_video_of_another_length_than_seqlength_is_tracked_with_a_warning(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # was: exit 0 and no word (an image folder of another length is refused)
    seq = _video_sequence(sequence, scene, tmp_path / "SEQ")
    n = len(scene.frames)
    (seq / "seqinfo.ini").write_text(f"[Sequence]\nframeRate=7\nseqLength={n + 40}\n")
    assert main(["-q", "track", str(seq), "--out", str(tmp_path / "t.txt"), "--no-link"]) == 0
    assert capsys.readouterr().err == (
        f"pftrack track: warning: {seq}/video.avi ended after {n} frames but "
        f"{seq}/seqinfo.ini says seqLength={n + 40}\n"
    )


def test_a_sequence_folder_with_two_videos_is_refused(
    sequence: Path, scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seq = _video_sequence(sequence, scene, tmp_path / "SEQ")
    (seq / "b.avi").symlink_to(seq / "video.avi")
    out = tmp_path / "t.txt"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack track: error: {seq}/seqinfo.ini: image folder {seq}/img1 does not exist and "
        f"{seq} holds 2 videos (b.avi, video.avi), not one to read instead\n"
    )
    assert not out.exists()


def test_tud_campus_folder_tracks_as_batch_and_its_video(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The shared data's layout: ``track SEQ`` = ``batch SEQ`` = ``track SEQ/video.mp4``."""
    seq = dataset("tud-campus")
    a, b, d = tmp_path / "a.txt", tmp_path / "b.txt", tmp_path / "D"
    assert main(["track", str(seq), "--detections", "auto", "--out", str(a)]) == 0
    argv = ["track", str(seq / "video.mp4"), "--detections", str(seq / "det.txt"), "--out", str(b)]
    assert main(argv) == 0
    argv = ["batch", str(seq), "--out", str(d), "--workers", "0", "--detections", "auto"]
    assert main(argv) == 0
    assert a.read_bytes() == b.read_bytes() == (d / "tud-campus.txt").read_bytes()
    assert a.stat().st_size > 0


def test_ctrl_c_on_a_file_aborts_and_keeps_the_old_outputs(
    sequence: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out, video = tmp_path / "t.txt", tmp_path / "r.mp4"
    out.write_bytes(TRACKS)

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr("pftrack.tracking.track_frames", interrupted)
    argv = ["track", str(sequence), "--out", str(out), "--render", str(video)]
    assert main(argv) == 130
    # was: a blank line first, also into a file (it ends a progress bar's line on a terminal)
    assert capsys.readouterr().err == "pftrack track: interrupted; no output was changed\n"
    assert out.read_bytes() == TRACKS
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.txt"]  # no partial video
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # as on a terminal
    assert main(argv) == 130
    assert capsys.readouterr().err == "\npftrack track: interrupted; no output was changed\n"


#: A subprocess whose import of module MODULE raises KeyboardInterrupt, as Ctrl-C in its first
#: 0.05 s did (deterministic: no race with a timer), then runs the ``pftrack`` console script's
#: entry point (pyproject.toml's [project.scripts]) or ``python -m pftrack``.
_INTERRUPTED_IMPORT = """
import importlib, runpy, sys, tomllib
class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == MODULE:
            raise KeyboardInterrupt
        return None
sys.meta_path.insert(0, Interrupt())
sys.argv = ["pftrack", *ARGV]
if HOW == "script":
    with open("pyproject.toml", "rb") as f:
        module, _, name = tomllib.load(f)["project"]["scripts"]["pftrack"].partition(":")
    sys.exit(getattr(importlib.import_module(module), name)())
runpy.run_module(HOW, run_name="__main__", alter_sys=True)
"""


def _track_stopped_at_import(
    module: str, argv: list[str], how: str, stop: str = "raise KeyboardInterrupt"
) -> subprocess.CompletedProcess[str]:
    """:data:`_INTERRUPTED_IMPORT` run with `argv`, its import of `module` doing `stop`."""
    body = _INTERRUPTED_IMPORT.replace("raise KeyboardInterrupt", stop)
    code = f"import os, signal\nMODULE, ARGV, HOW = {module!r}, {argv!r}, {how!r}\n{body}"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    return subprocess.run(
        [sys.executable, "-c", code],
        cwd=Path(__file__).parents[1],
        env=env,
        capture_output=True,
        text=True,
    )


@pytest.mark.parametrize(
    ("how", "module"),
    [
        *itertools.product(
            ["script", "pftrack"],
            ["pftrack.cli", "pftrack.cli.track", "pftrack.cli._options", "pftrack._progress"],
        ),
        # python -m pftrack.cli imports its package before any of its code runs: from there on
        ("pftrack.cli", "pftrack._progress"),
    ],
)
def test_ctrl_c_during_start_up_is_one_line_and_130(
    sequence: Path, tmp_path: Path, how: str, module: str
) -> None:
    # was: exit 130 with a KeyboardInterrupt traceback from an import (pftrack._progress: from
    # main's "-q", before its handler)
    out = tmp_path / "t.txt"
    proc = _track_stopped_at_import(module, ["-q", "track", str(sequence), "--out", str(out)], how)
    assert (proc.returncode, proc.stderr, proc.stdout) == (
        130, "pftrack track: interrupted; no output was changed\n", ""
    )  # fmt: skip
    # no leading line break: stderr is not a terminal (there is no progress bar to end)
    assert not out.exists()


@pytest.mark.parametrize("how", ["script", "pftrack"])
@pytest.mark.parametrize("module", ["pftrack.cli", "pftrack.cli.track"])
def test_sigterm_during_start_up_is_one_line_and_143(
    sequence: Path, tmp_path: Path, how: str, module: str
) -> None:
    """SIGTERM before the command's own handler (a ``kill`` 0.09-0.16 s in, on a loaded
    machine: 5 runs of 80 in the trial) killed the process where it stood (status -15, no
    word); now it ends as a SIGTERM'd command does. Deterministic: the import of `module`
    sends it."""
    out = tmp_path / "t.txt"
    out.write_bytes(TRACKS)
    argv = ["-q", "track", str(sequence), "--out", str(out)]
    proc = _track_stopped_at_import(module, argv, how, "os.kill(os.getpid(), signal.SIGTERM)")
    assert (proc.returncode, proc.stderr, proc.stdout) == (
        143, "pftrack track: terminated (SIGTERM); no output was changed\n", ""
    )  # fmt: skip
    assert out.read_bytes() == TRACKS
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.txt"]


def test_the_console_scripts_exit_status_is_the_clis() -> None:
    from pftrack._console import EXIT_INTERRUPTED, EXIT_TERMINATED
    from pftrack.cli._signals import EXIT_INTERRUPTED as CLI_EXIT_INTERRUPTED
    from pftrack.cli._signals import EXIT_TERMINATED as CLI_EXIT_TERMINATED

    assert (EXIT_INTERRUPTED, EXIT_TERMINATED) == (CLI_EXIT_INTERRUPTED, CLI_EXIT_TERMINATED)


def _rows(path: Path) -> int:
    try:
        return sum(1 for line in path.read_text().splitlines() if line.strip())
    except FileNotFoundError:
        return 0


def test_live_stream_writes_rows_as_they_come_and_ctrl_c_ends_cleanly(
    tmp_path: Path,
) -> None:
    """A stream served over HTTP as a camera would; pftrack tracks it in another process."""
    scene = make_scene(n_frames=200, rng=0)
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 1.0
    write_mot(tmp_path / "det.txt", det)
    out, video = tmp_path / "live.txt", tmp_path / "live.mp4"
    out.write_bytes(TRACKS)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    with serve_stream(scene.frames, pace=0.05) as server:  # 10 s of video
        argv = [sys.executable, "-m", "pftrack.cli", "track", server.url, "--out", str(out),
                "--detections", str(tmp_path / "det.txt"), "--render", str(video),
                "--fps", "25"]  # fmt: skip
        proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            deadline = time.monotonic() + 60
            side: list[Path] = []
            while time.monotonic() < deadline and proc.poll() is None:
                side = sorted(tmp_path.glob(".live.txt.*.part"))
                if side and _rows(side[0]) >= 20:
                    break
                time.sleep(0.1)
            assert side and _rows(side[0]) >= 20, (
                proc.stderr.read().decode() if proc.poll() else "no rows"  # type: ignore[union-attr]
            )
            assert server.sent < len(scene.frames)  # rows came while the stream went on
            assert out.read_bytes() == TRACKS  # replaced at the end only
            proc.send_signal(signal.SIGINT)
            stdout, stderr = proc.communicate(timeout=60)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    assert proc.returncode == 0, stderr.decode()
    text = stdout.decode()
    assert "stopped by Ctrl-C" in text
    n_frames = int(text.split(" frames")[0])
    assert 0 < n_frames < len(scene.frames)
    rows = read_mot(out)  # the finished tracks: linked and smoothed, sorted
    assert rows[:, 0].max() <= n_frames
    truth = scene.truth[scene.truth[:, 0] <= n_frames]
    assert evaluate_mot(truth, rows).mota > 0.7
    assert _video_info(video) == ("h264", "yuv420p", 25.0, n_frames)
    mask = os.umask(0)
    os.umask(mask)
    for path in (out, video):
        assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask, path.name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["det.txt", "live.mp4", "live.txt"]


def _rows_then(abort: BaseException, n_frames: int = 5) -> Any:
    """A ``track_frames`` that settles 2 rows a frame for `n_frames` frames, then raises `abort`."""
    import numpy as np

    def track_frames(source: Any, *, on_frame: Any, **kwargs: Any) -> Any:
        for n in range(1, n_frames + 1):
            rows = np.array([[n, i, 10 * i, 20, 30, 40, 0.9, -1, -1, -1] for i in (1, 2)], float)
            on_frame(n, next(iter(source)), [], rows)
        raise abort

    return track_frames


@pytest.mark.parametrize(
    ("abort", "status", "how"),
    [
        (KeyboardInterrupt(), 130, "interrupted;"),
        (Terminated(), 143, "terminated (SIGTERM);"),
        (ValueError("a frame could not be decoded"), 2, "error: a frame could not be decoded;"),
    ],
)
def test_an_aborted_live_run_keeps_out_and_says_where_its_rows_are(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    abort: BaseException,
    status: int,
    how: str,
) -> None:
    """A second Ctrl-C (SIGTERM, an error) in a live run: --out as it was, the rows kept.

    Was: --out truncated at the start and filled with the online rows, then "interrupted; no
    output was changed" (the user's earlier file lost).
    """
    out = tmp_path / "live.txt"
    out.write_bytes(TRACKS)
    out.chmod(0o600)
    monkeypatch.setattr("pftrack.tracking.track_frames", _rows_then(abort))
    scene = make_scene(n_frames=5, rng=0)
    with serve_stream(scene.frames) as server:
        argv = ["-q", "track", server.url, "--out", str(out)]
        assert main(argv) == status
        kept = tmp_path / "live.partial.txt"
        err = capsys.readouterr().err
        assert err == (
            f"pftrack track: {how} no output was changed; the 10 online rows tracked so far "
            f"are kept in {kept}\n"
        )
        assert out.read_bytes() == TRACKS
        rows = read_mot(kept)
        assert rows.shape == (10, 10) and rows[:, 0].tolist() == [1, 1, 2, 2, 3, 3, 4, 4, 5, 5]
        assert stat.S_IMODE(kept.stat().st_mode) == 0o600  # as private as --out
        # a second abort never replaces the first one's rows
        assert main(argv) == status
        again = tmp_path / "live.partial-2.txt"
        assert capsys.readouterr().err.endswith(f"are kept in {again}\n")
        assert read_mot(again).shape == (10, 10) and kept.read_bytes() == again.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "live.partial-2.txt", "live.partial.txt", "live.txt"
    ]  # fmt: skip


def test_a_live_run_aborted_before_any_row_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "live.txt"
    out.write_bytes(TRACKS)
    monkeypatch.setattr("pftrack.tracking.track_frames", _rows_then(KeyboardInterrupt(), 0))
    with serve_stream(make_scene(n_frames=5, rng=0).frames) as server:
        assert main(["-q", "track", server.url, "--out", str(out)]) == 130
    assert capsys.readouterr().err == "pftrack track: interrupted; no output was changed\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["live.txt"]
    assert out.read_bytes() == TRACKS


def test_ctrl_c_before_a_live_sources_first_frame_is_an_interrupt(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: Ctrl-C while a stream had sent no frame yet gave exit 2 and "no frame could
    be read from <pftrack.io.video.FrameSource object at 0x...>"."""
    import pftrack.tracking

    real = pftrack.tracking.track_frames

    def stopped_at_once(source: Any, **kwargs: Any) -> Any:
        source.stop()  # as the first Ctrl-C does
        return real(source, **kwargs)

    out = tmp_path / "live.txt"
    monkeypatch.setattr("pftrack.tracking.track_frames", stopped_at_once)
    with serve_stream(make_scene(n_frames=5, rng=0).frames) as server:
        assert main(["-q", "track", server.url, "--out", str(out)]) == 130
        assert capsys.readouterr().err == "pftrack track: interrupted; no output was changed\n"
        source = FrameSource(server.url)
        source.stop()
        with pytest.raises(ValueError, match=f"^{re.escape(server.url)}: stopped before its first"):
            real(source)
    assert list(tmp_path.iterdir()) == []


def test_an_aborted_live_run_into_a_pipe_says_its_rows_went_there(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Written through, the online rows are out already: the message says so (was: "no output
    was changed")."""
    import threading

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got: list[str] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()), daemon=True)
    reader.start()
    monkeypatch.setattr("pftrack.tracking.track_frames", _rows_then(KeyboardInterrupt(), 3))
    with serve_stream(make_scene(n_frames=5, rng=0).frames) as server:
        assert main(["-q", "track", server.url, "--out", str(fifo)]) == 130
    reader.join(30)
    assert capsys.readouterr().err == (
        f"pftrack track: interrupted; the 6 online rows tracked so far were written to {fifo}; "
        "no other output was changed\n"
    )
    assert len(got[0].splitlines()) == 6


def test_a_dropped_abort_stops_the_rows_into_a_pipe_at_the_next_write(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A live run into a pipe whose abort (a second Ctrl-C) code in C dropped after frame 2:
    the pipe gets the rows of frames 1-2 only, and the run ends as interrupted, saying so.

    Was: a pipe written as it goes was checked for a noted Ctrl-C only before it was opened,
    so the rows of frames 3-5 went into it as well (10 rows), and only the outputs put in place
    at the end were refused.
    """
    import threading

    from pftrack import _interrupt

    def track_frames(source: Any, *, on_frame: Any, **kwargs: Any) -> Any:
        for n in range(1, 6):
            rows = np.array([[n, i, 10 * i, 20, 30, 40, 0.9, -1, -1, -1] for i in (1, 2)], float)
            on_frame(n, next(iter(source)), [], rows)
            if n == 2:
                _interrupt.remember()  # as the console's handler does; its interrupt dropped
        raise AssertionError("the rows of frame 3 were written")

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got: list[str] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()), daemon=True)
    reader.start()
    monkeypatch.setattr("pftrack.tracking.track_frames", track_frames)
    try:
        with serve_stream(make_scene(n_frames=5, rng=0).frames) as server:
            assert main(["-q", "track", server.url, "--out", str(fifo)]) == 130
    finally:
        _interrupt.clear()
    reader.join(30)
    assert capsys.readouterr().err == (
        f"pftrack track: interrupted; the 4 online rows tracked so far were written to {fifo}; "
        "no other output was changed\n"
    )
    assert [line.split(",")[0] for line in got[0].splitlines()] == ["1", "1", "2", "2"]


def _track_stream_into_fifo(tmp_path: Path, frames: Any, det: Any) -> tuple[Path, list[str]]:
    """``pftrack track URL --out FIFO --detections det.txt`` (exit 0): the fifo, its lines."""
    import threading

    write_mot(tmp_path / "det.txt", det)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got: list[str] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()), daemon=True)
    reader.start()
    with serve_stream(frames, pace=0.0) as server:
        argv = ["-q", "track", server.url, "--out", str(fifo), "--detections",
                str(tmp_path / "det.txt")]  # fmt: skip
        assert main(argv) == 0
    reader.join(30)
    return fifo, got[0].splitlines()


def test_live_run_into_a_named_pipe_streams_its_rows_there(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A live source into a pipe (or /dev/stdout): the online rows, once, and the pipe stays.

    Was: the pipe replaced by a regular file at the end (the reader saw the online rows and
    never an end). The finished tracks are not written after the online rows (they would
    repeat every one).
    """
    scene = make_scene(n_frames=40, rng=0)
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 1.0
    fifo, lines = _track_stream_into_fifo(tmp_path, scene.frames, det)
    out = capsys.readouterr().out
    assert f"-> {fifo} (online rows, as they settled)" in out
    assert len(lines) > 20 and all(line.count(",") == 9 for line in lines)
    keys = [tuple(line.split(",")[:2]) for line in lines]
    assert len(set(keys)) == len(keys)  # each (frame, id) once: no second, finished copy
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def test_live_run_into_a_pipe_counts_the_rows_it_wrote_there(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The summary counts the online rows and ids the pipe got.

    Was: those of the finished tracks (linked and smoothed: other ids, filled rows), which
    are not written into a pipe: "22 tracks, 4471 boxes ... -> /dev/stdout (online rows, as
    they settled)" where 27 ids and 4405 rows went (PETS09-S2L1 through a named pipe).
    """
    scene = make_scene(n_frames=40, rng=0)
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 1.0
    walker = scene.truth[:, 1] == scene.truth[0, 1]
    det = det[~(walker & (det[:, 0] >= 12) & (det[:, 0] <= 27))]  # lost, found: two ids, linked
    _, lines = _track_stream_into_fifo(tmp_path, scene.frames, det)
    n_ids = len({line.split(",")[1] for line in lines})
    assert f", {n_ids} tracks, {len(lines)} boxes in " in capsys.readouterr().out


def test_first_ctrl_c_of_a_live_run_into_a_pipe_stops_after_the_frame(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The first Ctrl-C of a live run stops it after the current frame, --out a pipe too.

    Was: into a device or pipe (/dev/stdout) the first Ctrl-C aborted at once (exit 130) and
    the --render video of the frames so far was thrown away; --help promises a stop after the
    current frame (exit 0) for every live source, and a second Ctrl-C to abort.
    """
    import threading

    import pftrack.tracking

    real = pftrack.tracking.track_frames

    def ctrl_c_at_frame_5(source: Any, *, on_frame: Any, **kwargs: Any) -> Any:
        def hook(n: int, frame: Any, tracks: Any, rows: Any) -> None:
            on_frame(n, frame, tracks, rows)
            if n == 5:
                signal.raise_signal(signal.SIGINT)  # as a terminal's Ctrl-C

        return real(source, on_frame=hook, **kwargs)

    monkeypatch.setattr("pftrack.tracking.track_frames", ctrl_c_at_frame_5)
    fifo, video = tmp_path / "fifo", tmp_path / "live.avi"
    os.mkfifo(fifo)
    got: list[str] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()), daemon=True)
    reader.start()
    with serve_stream(make_scene(n_frames=40, rng=0).frames) as server:
        argv = ["-q", "track", server.url, "--out", str(fifo), "--render", str(video)]
        assert main(argv) == 0
    reader.join(30)
    captured = capsys.readouterr()
    assert "stopping after this frame (Ctrl-C again to abort)" in captured.err
    n_frames = int(captured.out.split(" frames (stopped by Ctrl-C), ")[0])
    assert 5 <= n_frames < 40  # the frames read ahead of the 5th are tracked too
    assert f"-> {video}" in captured.out
    assert cv2.VideoCapture(str(video)).get(cv2.CAP_PROP_FRAME_COUNT) == n_frames
    assert all(line.count(",") == 9 for line in got[0].splitlines())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo", "live.avi"]


def test_render_of_an_odd_sized_source_is_even_and_its_help_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """321x241 frames give a 322x242 video: --help and the README say so (was: only a
    docstring of io/video_writer.py); the summary names --fps as --fps (was: 'from given')."""
    frames = make_scene(n_frames=4, width=321, height=241, n_walkers=1, rng=0).frames
    folder = tmp_path / "imgs"
    folder.mkdir()
    for k, frame in enumerate(frames, start=1):
        cv2.imwrite(str(folder / f"{k}.png"), frame)
    video = tmp_path / "r.mp4"
    argv = ["-q", "track", str(folder), "--out", str(tmp_path / "t.txt"), "--render",
            str(video), "--fps", "29.97"]  # fmt: skip
    assert main(argv) == 0
    assert f"(h264, 29.97 fps from --fps) -> {video}" in capsys.readouterr().out
    with av.open(str(video)) as container:
        ctx = container.streams.video[0].codec_context
        assert (ctx.width, ctx.height) == (322, 242)
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "a 321x241 source gives a 322x242 video" in text
    readme = " ".join((Path(__file__).parents[1] / "README.md").read_text().split())
    assert "(321x241 gives 322x242;" in readme


def test_quiet_silences_the_progress_bar(
    sequence: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setattr(_progress, "_quiet", False)
    monkeypatch.setattr(_progress, "DELAY", 0.0)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # as on a terminal
    argv = ["track", str(sequence), "--detections", "auto", "--out", str(tmp_path / "t.txt")]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "tracking" in err and "60/60" in err and "frame/s" in err  # tqdm: count, rate
    assert main(["--quiet", *argv]) == 0
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(_progress, "_quiet", False)
    assert main([*argv, "-q"]) == 0  # after the command too
    assert capsys.readouterr().err == ""


def _actions(
    parser: argparse.ArgumentParser, name: str = "pftrack"
) -> Iterator[tuple[str, argparse.Action, argparse.HelpFormatter]]:
    """(command, option, its help formatter) for every option of every (sub-)command."""
    formatter = parser._get_formatter()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _actions(sub, f"{name} {sub_name}")
        elif action.option_strings:
            yield name, action, formatter


def test_every_option_shows_its_default(capsys: pytest.CaptureFixture[str]) -> None:
    """Flags (off unless given) and required options aside, each option's help names a default."""
    missing, checked = [], 0
    for command, action, formatter in _actions(build_parser()):
        if action.nargs == 0 or action.required:
            continue
        checked += 1
        text = formatter._get_help_string(action) or ""
        if "default" not in text:
            missing.append(f"{command} {action.option_strings[-1]}: {text}")
    assert not missing, "\n".join(missing)
    assert checked >= 35
    with pytest.raises(SystemExit):
        main(["recover", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "recovery method (default: auto)" in text and "(default: 30)" in text
    assert "--link join fragments of one object first --max-distance" in text  # flags: no noise


def _finishes_despite_ctrl_c(code: str, cwd: Path, out: Path) -> None:
    """`code`, a ``pftrack`` command with a Ctrl-C sent into it, ends with 0 and `out` written."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True,
        timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "interrupted" not in proc.stderr and f"-> {out}" in proc.stdout
    assert out.stat().st_size > 0


LATE_CTRL_C = """
import os, signal, sys
import pftrack.cli.{module} as command
from pftrack._console import main

real = command.{hook}

def late(*args, **kwargs):  # once the outputs are in place: Ctrl-C
    os.kill(os.getpid(), signal.SIGINT)
    return real(*args, **kwargs)

command.{hook} = late
sys.argv = ["pftrack", *{argv!r}]
sys.exit(main())
"""


@pytest.mark.parametrize("command", ["track", "render", "smooth", "recover"])
def test_ctrl_c_after_the_outputs_are_written_does_not_fail_the_run(
    scene: Scene, tmp_path: Path, command: str
) -> None:
    """Was: exit status 130 and no word after the output was written (or "no output was
    changed", when it was). The run finishes: exit status 0, its summary."""
    video = scene.write_video(tmp_path / "scene.avi")
    tracks = scene.write_truth(tmp_path / "gt.txt")
    out = tmp_path / ("o.mp4" if command == "render" else "o.txt")
    argv = {
        "track": ["track", str(video), "--out", str(out), "--particles", "20"],
        "render": ["render", str(video), str(tracks), "--out", str(out)],
        "smooth": ["smooth", str(tracks), "--out", str(out)],
        "recover": ["recover", str(tracks), "--out", str(out)],
    }[command]
    hook = "_outside" if command == "render" else "report_stream"
    code = LATE_CTRL_C.format(module=command, hook=hook, argv=argv)
    _finishes_despite_ctrl_c(code, tmp_path, out)


RENAMED_CTRL_C = """
import os, signal, sys
import pftrack.io.mot as mot
from pftrack._console import main

real = mot.write_mot

def renamed(*args, **kwargs):  # the output renamed into place, then at once: Ctrl-C
    real(*args, **kwargs)
    os.kill(os.getpid(), signal.SIGINT)

mot.write_mot = renamed
sys.argv = ["pftrack", *{argv!r}]
sys.exit(main())
"""


@pytest.mark.parametrize("command", ["smooth", "recover"])
def test_ctrl_c_right_after_the_output_is_renamed_does_not_say_nothing_changed(
    scene: Scene, tmp_path: Path, command: str
) -> None:
    """Was: the interrupt between ``write_mot``'s rename and ``hold_interrupts`` ended the run
    with status 130 and "interrupted; no output was changed" beside the new --out (CI hit it
    once, ``test_ctrl_c_at_any_point_of_the_start_ends_in_130``). The hold now comes before
    the write, as the commands with several outputs hold before their renames."""
    tracks = scene.write_truth(tmp_path / "gt.txt")
    out = tmp_path / "o.txt"
    code = RENAMED_CTRL_C.format(argv=[command, str(tracks), "--out", str(out)])
    _finishes_despite_ctrl_c(code, tmp_path, out)


def test_held_interrupts_are_restored_when_the_command_returns(
    scene: Scene, tmp_path: Path
) -> None:
    """In a process that goes on (a caller of main), Ctrl-C works again after the command."""
    tracks = scene.write_truth(tmp_path / "gt.txt")
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    assert main(["smooth", str(tracks), "--out", str(tmp_path / "o.txt")]) == 0
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before


BLAS_PROBE = """
import os, sys
import pftrack.cli

def run(argv):  # the command, as far as BLAS goes: NumPy loads once the command runs
    import numpy  # noqa: F401
    names = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")
    print(*(os.environ.get(v) for v in names))
    return 0

pftrack.cli.main = run
from pftrack._console import main
sys.exit(main({argv}))
"""


@pytest.mark.parametrize(
    ("argv", "given", "expected"),
    [
        (None, None, "1 1 1"),  # the console script: BLAS (and OpenMP) at one thread
        (None, "3", "3 1 1"),  # a user's setting stands
        (["track"], None, "None None None"),  # a library call leaves the process alone
    ],
)
def test_the_command_runs_blas_at_one_thread(
    argv: list[str] | None, given: str | None, expected: str
) -> None:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    env["PYTHONPATH"] = os.pathsep.join(sys.path)
    proc = subprocess.run(
        [sys.executable, "-c", BLAS_PROBE.format(argv=argv)], env=env, capture_output=True,
        text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 0 and proc.stdout.strip() == expected, proc.stderr


@pytest.mark.parametrize("command", ["track", "render"])
def test_a_warning_names_a_file_whose_name_is_not_utf8_as_errors_do(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    r"""A warning of the run names a Latin-1 name's byte as ``\xe9``, as the errors and the
    warnings given before the run do (was: ``\udce9``, Python's surrogate escape printed)."""
    folder = Path(os.fsdecode(bytes(tmp_path) + b"/lat\xe9n"))
    folder.mkdir()
    rng = np.random.default_rng(0)
    for k in range(1, 6):
        cv2.imwrite(str(tmp_path / "x.jpg"), rng.integers(0, 255, (40, 60, 3), np.uint8))
        data = (tmp_path / "x.jpg").read_bytes()
        (folder / f"{k}.jpg").write_bytes(data[: len(data) // 2] if k == 3 else data)
    (tmp_path / "t.txt").write_text("1,1,5,5,10,20,1,-1,-1,-1\n")
    tracks = str(tmp_path / "t.txt")
    args = (
        ["track", str(folder), "--out", str(tmp_path / "o.txt")]
        if command == "track"
        else ["render", str(folder), tracks, "--out", str(tmp_path / "o.mp4")]
    )
    assert main(["-q", *args]) == 0
    err = capsys.readouterr().err
    assert "lat\\xe9n/3.jpg has no JPEG end marker" in err, err
    assert "udce9" not in err


def test_ctrl_c_after_the_abort_does_not_break_into_its_cleanup() -> None:
    """A live run's first Ctrl-C stops it, the second aborts; a third (a held key, an impatient
    user) was raised again in the abort's cleanup and could skip the wait for the source's
    reader threads: the process then ended with SIGABRT ("FATAL: exception not rethrown", a
    reader inside a C++ read at exit), 3 of 10 runs on a pipe. Now ignored until the block
    ends, and the handler before it restored."""
    from pftrack.cli.track import _StopOnCtrlC

    class Source:
        stopped = False

        def stop(self) -> None:
            self.stopped = True

    before = signal.getsignal(signal.SIGINT)
    source, cleaned = Source(), False
    with pytest.raises(KeyboardInterrupt), _StopOnCtrlC(source):
        signal.raise_signal(signal.SIGINT)  # the first: stop after this frame
        assert source.stopped
        try:
            signal.raise_signal(signal.SIGINT)  # the second: abort
            for _ in range(1000):  # Python runs the handler between bytecodes
                pass
        finally:
            signal.raise_signal(signal.SIGINT)  # a third, during the cleanup
            for _ in range(1000):
                pass
            cleaned = True
    assert cleaned
    assert signal.getsignal(signal.SIGINT) == before
