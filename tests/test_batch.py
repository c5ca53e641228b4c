"""``pftrack batch`` and several-file ``recover``/``smooth`` on a real Dask cluster.

One ``LocalCluster`` with two single-threaded worker processes serves the module (started by
:func:`pftrack.batch.dask_client`, as ``pftrack batch`` starts its own); one test starts
``dask scheduler`` and ``dask worker`` as subprocesses. Sequences are small synthetic scenes.
"""

from __future__ import annotations

import _thread
import contextlib
import functools
import hashlib
import http.server
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from pftrack import cli
from pftrack.batch import (
    BatchSummary,
    Job,
    RecoverOptions,
    SequenceInput,
    SmoothOptions,
    TaskResult,
    TrackOptions,
    dask_client,
    find_sequences,
    find_track_files,
    recover_many,
    run_jobs,
    smooth_many,
    track_many,
)
from pftrack.cli import main
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import read_mot, write_mot
from pftrack.io.video import VIDEO_SUFFIXES, FrameSource
from pftrack.synthetic import make_scene
from tests.conftest import dataset

distributed = pytest.importorskip("distributed")

FAST = ["--particles", "30"]  # every run of this module: fewer particles, same code path

#: A cluster's scheduler with its HTTP routes on a free port, as dask_client starts it: on 8787,
#: taken by another run, Dask warns ("Port 8787 is already in use"), an error in these tests.
NO_DASHBOARD = {"dashboard_address": "127.0.0.1:0"}


@pytest.fixture(scope="module")
def data(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder of three sequences: a video, a MOTChallenge folder (det + gt), an image folder."""
    root = tmp_path_factory.mktemp("batch") / "in"
    root.mkdir()
    scenes = [make_scene(n_frames=30, width=192, height=144, n_walkers=3, rng=k) for k in range(3)]
    scenes[0].write_video(root / "walk.avi")
    seq = root / "MOT-01"
    scenes[1].write_images(seq / "img1", ext=".jpg")
    (seq / "gt").mkdir()
    (seq / "det").mkdir()
    scenes[1].write_truth(seq / "gt" / "gt.txt")
    det = scenes[1].truth.copy()
    det[:, 1] = -1
    write_mot(seq / "det" / "det.txt", det)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=MOT-01\nimWidth=192\nimHeight=144\n")
    scenes[2].write_images(root / "plain", ext=".png")
    return root


@pytest.fixture(scope="module")
def client() -> Iterator[Any]:
    with dask_client(n_workers=2) as c:
        yield c


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.glob("*.txt"))}


def test_find_sequences_names_and_files(data: Path) -> None:
    seqs = {s.name: s for s in find_sequences(data)}
    assert sorted(seqs) == ["MOT-01", "plain", "walk"]
    mot = seqs["MOT-01"]
    assert mot.frames == data / "MOT-01" / "img1" and mot.image_width == 192
    assert mot.detections == data / "MOT-01" / "det" / "det.txt"
    assert mot.gt == data / "MOT-01" / "gt" / "gt.txt"
    assert seqs["walk"].frames == data / "walk.avi" and seqs["walk"].gt is None
    # SEQ/img1 given directly is the sequence SEQ
    (direct,) = find_sequences(data / "MOT-01" / "img1")
    assert direct == mot


def test_seq_img1_without_seqinfo_is_the_sequence_seq(data: Path, tmp_path: Path) -> None:
    """``SEQ/img1`` given directly, ``SEQ`` without ``seqinfo.ini``: was the sequence ``img1``
    without detections or ground truth (``--detections auto`` failed, "sequence img1 has no
    det/det.txt") while ``pftrack track SEQ/img1`` reads ``SEQ/det/det.txt``."""
    seq = tmp_path / "SEQ"
    shutil.copytree(data / "MOT-01", seq)
    (seq / "seqinfo.ini").unlink()
    (direct,) = find_sequences(seq / "img1")
    assert (
        direct
        == find_sequences(seq)[0]
        == SequenceInput("SEQ", seq / "img1", seq / "det" / "det.txt", seq / "gt" / "gt.txt")
    )
    out = tmp_path / "out"
    argv = ["batch", str(seq / "img1"), "--detections", "auto", "--out", str(out), *FAST]
    assert main([*argv, "--workers", "0"]) == 0
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["status"] == "done" and entry["metrics"]["mota"] > 0.5, entry
    single = tmp_path / "single.txt"
    assert main(["track", str(seq / "img1"), "--detections", "auto", "--out", str(single),
                 *FAST]) == 0  # fmt: skip
    assert single.read_bytes() == (out / "SEQ.txt").read_bytes()


@pytest.mark.parametrize("given", ["img1", "images"])
def test_an_image_folder_of_a_sequence_given_itself_is_read_as_pftrack_track_reads_it(
    data: Path, tmp_path: Path, given: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``SEQ/img1`` given where ``seqinfo.ini`` says ``imDir=images``: the batch tracked
    ``SEQ/images``, ``pftrack track SEQ/img1`` tracks ``SEQ/img1``; ``SEQ/images`` given (its
    ``imDir``, not named img1) was the sequence ``images`` without detections or ground truth
    (``--detections auto`` failed) while ``pftrack track`` reads ``SEQ/det/det.txt``."""
    seq = tmp_path / "SEQ"
    shutil.copytree(data / "MOT-01", seq)
    shutil.copytree(data / "plain", seq / "images")  # other frames than img1's
    (seq / "seqinfo.ini").write_text("[Sequence]\nimDir=images\nimWidth=192\nimHeight=144\n")
    (found,) = find_sequences(seq / given)
    assert found == SequenceInput(
        "SEQ", seq / given, seq / "det" / "det.txt", seq / "gt" / "gt.txt", 192, 144,
        seqinfo=seq / "seqinfo.ini",
    )  # fmt: skip
    out = tmp_path / "out"
    argv = ["batch", str(seq / given), "--detections", "auto", "--out", str(out), *FAST]
    assert main([*argv, "--workers", "0"]) == 0
    single = tmp_path / "single.txt"
    assert main(["track", str(seq / given), "--detections", "auto", "--out", str(single),
                 *FAST]) == 0  # fmt: skip
    assert single.read_bytes() == (out / "SEQ.txt").read_bytes()
    capsys.readouterr()


def test_the_video_of_a_sequence_folder_given_itself_has_its_detections(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``pftrack batch pets09-s2l1/video.avi --detections auto`` (../shared/data's layout)
    failed, "sequence video has no det/det.txt (nor det.txt)", and was not scored, while
    ``pftrack track pets09-s2l1/video.avi --detections auto`` reads its det.txt and scales its
    boxes by seqinfo.ini's imWidth."""
    seq = tmp_path / "pets"
    seq.mkdir()
    shutil.copy(data / "walk.avi", seq / "video.avi")
    for name in ("det", "gt"):  # in seqinfo.ini's pixels, twice the video's, as PETS09's
        boxes = read_mot(data / "MOT-01" / name / f"{name}.txt")
        boxes[:, 2:6] *= 2
        write_mot(seq / f"{name}.txt", boxes)
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=384\nimHeight=288\n")
    (found,) = find_sequences(seq / "video.avi")
    assert found == SequenceInput(
        "video", seq / "video.avi", seq / "det.txt", seq / "gt.txt", 384, 288,
        seqinfo=seq / "seqinfo.ini",
    )  # fmt: skip
    out = tmp_path / "out"
    argv = ["batch", str(seq / "video.avi"), "--detections", "auto", "--out", str(out), *FAST]
    assert main([*argv, "--workers", "0"]) == 0
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["det_scale"] == 0.5 and entry["metrics"] is not None, entry
    single = tmp_path / "single.txt"
    assert main(["track", str(seq / "video.avi"), "--detections", "auto", "--out", str(single),
                 *FAST]) == 0  # fmt: skip
    assert single.read_bytes() == (out / "video.txt").read_bytes()
    capsys.readouterr()


def test_a_seqinfo_size_that_is_not_its_images_fails_the_score_not_scored(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial: seqinfo.ini saying 1280x960 beside 640x480 images scaled gt.txt by 0.5, and the
    built-in detector's tracks scored MOTA -109.6 where ``pftrack eval`` gave 38.4; the batch
    said "done". Now the score fails with pftrack eval's check, the tracks written."""
    seq = tmp_path / "BIG"
    seq.mkdir()
    for name in ("img1", "gt"):
        (seq / name).symlink_to(data / "MOT-01" / name, target_is_directory=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=384\nimHeight=288\n")
    out = tmp_path / "out"
    assert main(["batch", str(seq), "--out", str(out), "--workers", "0", "-q", *FAST]) == 1
    err = capsys.readouterr().err
    assert f"BIG: error: scoring against {seq / 'gt' / 'gt.txt'} (the tracks are written): " in err
    assert "BIG.txt: its boxes look 1 times the ground truth's, not 0.5 (" in err
    assert (
        f"(pftrack eval's check; the batch scaled {seq / 'gt' / 'gt.txt'} by 0.5: the frames' "
        f"width 192 over imWidth=384 in {seq / 'seqinfo.ini'}; if seqinfo.ini's imWidth and "
        "imHeight are not its images' size, correct them)\n"
    ) in err
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["metrics"] is None and len(read_mot(out / "BIG.txt")) > 0
    # with seqinfo.ini's size its images', the same tracks are scored
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=192\nimHeight=144\n")
    assert main(["batch", str(seq), "--out", str(out), "--workers", "0", "-q", *FAST]) == 0
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["metrics"]["mota"] > 0.5, entry["metrics"]


def test_find_sequences_shared_data_layout(tmp_path: Path) -> None:
    # ../shared/data's layout: SEQ/video.avi + seqinfo.ini + det.txt + gt.txt
    seq = tmp_path / "pets"
    seq.mkdir()
    for name in ("video.avi", "det.txt", "gt.txt"):
        (seq / name).write_text("")
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=768\n")
    assert find_sequences(tmp_path) == [
        SequenceInput(
            "pets",
            seq / "video.avi",
            seq / "det.txt",
            seq / "gt.txt",
            768,
            seqinfo=seq / "seqinfo.ini",
        )  # fmt: skip
    ]


@pytest.mark.parametrize(
    ("layout", "message"),
    [
        ({"a/x.avi": "", "b/x.avi": ""}, "both named 'x'"),
        ({"summary.avi": ""}, "reserved"),
        ({"notes.txt": ""}, "no sequence in folder"),
        # a user trial: a stray image made a folder of videos, or of sequences, one sequence of
        # one frame, the others passed over, exit status 0
        (
            {"thumbnail.jpg": "", "a.mp4": "", "b.avi": ""},
            r"holds 1 image \(thumbnail.jpg\) "
            r"and 2 videos or sequence folders \(a.mp4, b.avi\): whether it is one sequence",
        ),
    ],
)
def test_find_sequences_rejects(tmp_path: Path, layout: dict[str, str], message: str) -> None:
    for rel, text in layout.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    tops = sorted({tmp_path / rel.split("/")[0] for rel in layout if "/" in rel}) or [tmp_path]
    with pytest.raises(ValueError, match=message):
        find_sequences(tops)


def test_two_sequences_of_one_name_are_told_to_link_the_sequence_folder(tmp_path: Path) -> None:
    """A user trial: for a/seq1 and b/seq1 the hint linked b/seq1/img1, which leaves the
    sequence's det, gt and seqinfo.ini behind."""
    for top in ("a", "b"):
        (tmp_path / top / "seq1" / "img1").mkdir(parents=True)
        (tmp_path / top / "seq1" / "img1" / "1.png").write_text("")
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "seq1.avi").write_text("")
    second = tmp_path / "b" / "seq1"
    with pytest.raises(ValueError, match=rf"\(symbolic links: ln -s {second} NEWNAME\)$"):
        find_sequences([tmp_path / "a" / "seq1", second])
    video = tmp_path / "c" / "seq1.avi"
    with pytest.raises(ValueError, match=rf"\(symbolic links: ln -s {video} NEWNAME.avi\)$"):
        find_sequences([tmp_path / "a" / "seq1", video])


def test_a_folder_of_sequences_with_a_stray_image_is_refused(tmp_path: Path) -> None:
    """A user trial: train/ with SEQ-A, SEQ-B and an overview.png was one sequence of one frame."""
    top = tmp_path / "train"
    for rel in ("SEQ-A/seqinfo.ini", "SEQ-B/img1/1.png", "overview.png"):
        (top / rel).parent.mkdir(parents=True, exist_ok=True)
        (top / rel).write_text("")
    message = r"holds 1 image \(overview.png\) and 2 videos or sequence folders \(SEQ-A, SEQ-B\)"
    with pytest.raises(ValueError, match=message):
        find_sequences(top)
    (top / "overview.png").unlink()
    assert [s.name for s in find_sequences(top)] == ["SEQ-A", "SEQ-B"]
    (top / "SEQ-B" / "img1" / ".thumb.png").write_text("")  # hidden: no image of the folder
    assert [s.name for s in find_sequences(top / "SEQ-B")] == ["SEQ-B"]


def _mot_sequence(folder: Path) -> None:
    """A small MOTChallenge sequence folder: ``img1/`` and ``seqinfo.ini``."""
    make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0).write_images(folder / "img1")
    (folder / "seqinfo.ini").write_text("[Sequence]\nimWidth=64\nimHeight=64\n")


def test_sequences_deeper_than_one_level_are_named_not_passed_over(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: given DIR with DIR/train/SEQ/seqinfo.ini, "no sequence in folder DIR"
    said nothing of DIR/train; with a video beside train/, its sequences were passed over
    silently, exit status 0."""
    top = tmp_path / "DIR"
    train = top / "train"
    for name in ("SEQ1", "SEQ2"):
        _mot_sequence(train / name)
    held = f"{train} holds 2 sequences (SEQ1, SEQ2)"
    error = (
        f"no sequence in folder {top}: expected videos ({', '.join(VIDEO_SUFFIXES)}), image "
        f"folders or MOTChallenge sequence folders in it; deeper, {held}: pass {train} instead "
        "(a folder is looked into one level deep)"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(error)}$"):
        find_sequences(top)
    out = tmp_path / "out"
    assert main(["batch", str(top), "--out", str(out), "--workers", "0", *FAST]) == 2
    assert capsys.readouterr().err == f"pftrack batch: error: {error}\n"
    assert not out.exists()
    # some found: the deeper ones are named in one warning
    make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0).write_video(top / "v.avi")
    warning = (
        f"folder {top}: 1 sequence tracked from it, not those deeper (a folder is looked into "
        f"one level deep): {held}; pass {train} too to track them"
    )
    with pytest.warns(UserWarning, match=f"^{re.escape(warning)}$"):
        assert [s.name for s in find_sequences(top)] == ["v"]
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as a user's shell: the command prints it
        assert main(["batch", str(top), "--out", str(out), "--workers", "0", *FAST]) == 0
    assert f"pftrack batch: warning: {warning}\n" in capsys.readouterr().err
    # given as well, or instead: tracked, no warning (filterwarnings = error)
    assert [s.name for s in find_sequences([top, train])] == ["v", "SEQ1", "SEQ2"]
    assert [s.name for s in find_sequences(train)] == ["SEQ1", "SEQ2"]


def test_sequence_folders_without_frames_below_are_named_not_passed_over(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 16's leftover: ``pftrack batch ../shared/data`` passed over ``mot15-gt/`` (three
    sequence folders with ``seqinfo.ini``, ``det.txt`` and ``gt.txt``, no frames) without a
    word. ``pftrack track`` refuses such a folder (no frames to track, with or without
    ``--detections``), so a batch cannot track them: one line names them and says why."""
    top = tmp_path / "data"
    for name in ("ADL", "ETH", "KITTI"):
        seq = top / "mot15-gt" / name
        seq.mkdir(parents=True)
        (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=64\nimHeight=64\n")
        (seq / "det.txt").write_text("1,-1,1,1,5,5,0.9,-1,-1,-1\n")
    (top / "other" / "notes").mkdir(parents=True)  # no annotations: not named
    (top / "other" / "notes" / "a.txt").write_text("")
    (top / "labels" / "cam" / "gt").mkdir(parents=True)  # gt/gt.txt alone, two levels down
    (top / "labels" / "cam" / "gt" / "gt.txt").write_text("")
    why = (
        "annotations alone (seqinfo.ini, det.txt, gt.txt; no image folder, no video), nothing a "
        "batch can track"
    )
    named = (
        f"{top / 'labels'}, which holds 1 sequence folder without frames (cam); "
        f"{top / 'mot15-gt'}, which holds 3 sequence folders without frames (ADL, ETH, KITTI)"
    )
    error = (
        f"no sequence in folder {top}: expected videos ({', '.join(VIDEO_SUFFIXES)}), image "
        f"folders or MOTChallenge sequence folders in it; {named}: {why}"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(error)}$"):
        find_sequences(top)
    _mot_sequence(top / "SEQ")
    warning = f"folder {top}: passed over {named}: {why}"
    with pytest.warns(UserWarning, match=f"^{re.escape(warning)}$"):
        assert [s.name for s in find_sequences(top)] == ["SEQ"]
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as a user's shell: the command prints it
        argv = ["batch", str(top), "--out", str(out), "--workers", "0", *FAST]
        assert main([*argv, "--detections", "auto"]) == 1  # SEQ has no det.txt: refused
    assert f"pftrack batch: warning: {warning}\n" in capsys.readouterr().err
    # given themselves: sequences whose tasks fail, as pftrack track refuses them, said once
    summary = track_many(top / "mot15-gt", out, n_workers=0)
    assert [e["status"] for e in summary.entries] == ["failed"] * 3
    (said,) = summary.problems()
    assert said.startswith(f"3 sequences (ADL, ETH, KITTI): error: {top}/mot15-gt/NAME/")


@pytest.mark.parametrize(
    ("files", "message"),
    [
        (
            {"s/seqinfo.ini": "[Sequence]\nimDir=frames\n", "s/a.avi": "", "s/b.avi": ""},
            r"image folder .*frames does not exist and .* 2 videos",
        ),
        ({}, r"seqinfo.ini: expected a \[Sequence\] section"),
        ({"s/seqinfo.ini": "[Sequence]\nimWidth=wide\n"}, "imWidth is 'wide'"),
        ({"s/seqinfo.ini": "[Sequence]\nframeRate=0\n"}, "frameRate is '0'"),
        (
            {"s/seqinfo.ini": "[Sequence]\nimWidth=1e300\n"},
            r"imWidth is '1e300', expected an "
            r"integer in 1\.\.100000",
        ),  # fmt: skip
        ({"s/seqinfo.ini": "[Sequence]\nimDir=nothere\n"}, r"image folder .*nothere does not"),
    ],
)
def test_a_sequence_folder_pftrack_track_refuses_fails_alone(
    data: Path, tmp_path: Path, files: dict[str, str], message: str
) -> None:
    """A user trial: one bad ``seqinfo.ini`` in a folder of sequences stopped the whole batch
    (exit 2); ``imDir`` was not read (``pftrack track`` reads it)."""
    root = tmp_path / "in"
    shutil.copytree(data / "MOT-01", root / "good")
    shutil.copytree(data / "MOT-01" / "img1", root / "s" / "img1")
    for rel, text in {"s/seqinfo.ini": "", **files}.items():
        (root / rel).write_text(text)
    summary = track_many(root, tmp_path / "out", n_workers=0, options=TrackOptions(_config()))
    status = {e["name"]: (e["status"], e.get("error")) for e in summary.entries}
    assert status["good"] == ("done", None)
    assert status["s"][0] == "failed" and re.search(message, status["s"][1]), status["s"]
    with pytest.raises(ValueError, match=message):  # as pftrack track says it
        FrameSource(root / "s")


def test_a_sequence_folder_is_read_from_its_imdir(data: Path, tmp_path: Path) -> None:
    seq = tmp_path / "SEQ"
    shutil.copytree(data / "MOT-01", seq)
    (seq / "img1").rename(seq / "frames")
    (seq / "seqinfo.ini").write_text(
        "[Sequence]\nname=MOT-01\nimDir=frames\nimWidth=192\nimHeight=144\n"
    )
    (found,) = find_sequences(seq)
    assert found.frames == seq / "frames" and found.seqinfo == seq / "seqinfo.ini"
    summary = track_many(seq, tmp_path / "out", n_workers=0, options=TrackOptions(_config()))
    assert summary.entries[0]["status"] == "done"


@pytest.mark.parametrize(
    ("options", "kwargs", "error", "message"),
    [
        (TrackOptions, {"iou": 2.0}, ValueError, r"iou is 2.0, expected a number in \(0, 1\]"),
        (TrackOptions, {"iou": float("nan")}, ValueError, "iou is nan"),
        (TrackOptions, {"iou": "0.5"}, TypeError, "iou must be a number"),
        (TrackOptions, {"seed": -1}, ValueError, "seed is -1, expected an integer >= 0"),
        (TrackOptions, {"seed": 1.5}, TypeError, "seed must be an integer"),
        (TrackOptions, {"fill": "zzz"}, ValueError, "fill is 'zzz', expected 'linear' or 'pf'"),
        (TrackOptions, {"smooth": "no"}, TypeError, "smooth must be True or False"),
        (TrackOptions, {"link": None}, TypeError, "link must be True or False"),
        (TrackOptions, {"det_scale": 1e-4}, ValueError, r"det_scale is 0.0001, .* \[0.001, 1000\]"),
        (TrackOptions, {"det_scale": "auto"}, TypeError, "det_scale must be a number"),
        (TrackOptions, {"config": {}}, TypeError, "config must be a TrackerConfig"),
        (RecoverOptions, {"method": "zzz"}, ValueError, "method is 'zzz', expected one of auto"),
        (RecoverOptions, {"max_gap": 0}, ValueError, r"max_gap is 0, expected an integer in 1\.\."),
        (RecoverOptions, {"max_gap": 30.0}, TypeError, "max_gap must be an integer"),
        (RecoverOptions, {"seed": -1}, ValueError, "seed is -1"),
        (RecoverOptions, {"link": "yes"}, TypeError, "link must be True or False"),
        (RecoverOptions, {"max_distance": 0.0}, ValueError, "max_distance is 0.0, expected"),
        (SmoothOptions, {"max_gap": 100_001}, ValueError, "max_gap is 100001"),
        (SmoothOptions, {"link": 1}, TypeError, "link must be True or False"),
    ],
)
def test_options_are_checked_before_any_work(
    tmp_path: Path, options: Any, kwargs: dict[str, Any], error: type[Exception], message: str
) -> None:
    """A bad option failed every sequence one by one, or (``iou``) only after tracking them all,
    with a message that did not always name it (NumPy's for a negative seed)."""
    with pytest.raises(error, match=message):
        options(**kwargs)
    # the ends of each range are accepted
    TrackOptions(iou=1, det_scale=1e-3, seed=np.int64(3), fill="pf", smooth=False, link=False)
    TrackOptions(iou=1e-9, det_scale=1e3)
    RecoverOptions(method="linear", max_gap=100_000, seed=0, link=True, max_distance=0.5)
    SmoothOptions(max_gap=1, link=False)


def test_workers_are_single_threaded(client: Any) -> None:
    def threads() -> tuple[int, str | None, str | None, str | None, bool, int]:
        import cv2

        from pftrack._threads import kernel_threads, tracking_threads

        env = os.environ.get
        return (
            cv2.getNumThreads(),
            env("OPENBLAS_NUM_THREADS"),
            env("OMP_NUM_THREADS"),
            env("MALLOC_TRIM_THRESHOLD_"),
            tracking_threads(),
            kernel_threads(),
        )

    result = client.run(threads)
    # and no MALLOC_TRIM_THRESHOLD_: Dask's default makes tracking ~1.5x slower (engine.py);
    # no read-ahead, detector or kernel thread in a worker: it has one core already
    assert len(result) == 2 and set(result.values()) == {(1, "1", "1", None, False, 1)}
    from pftrack._threads import kernel_threads, tracking_threads

    assert tracking_threads()  # this process (serial runs) keeps them
    assert kernel_threads() == min(len(os.sched_getaffinity(0)), 4)


def _loops() -> dict[str, Any]:
    import dask

    from pftrack.batch.engine import SLOWER_LOOPS

    return {key: dask.config.get(key) for key in SLOWER_LOOPS}


def test_the_local_clusters_loops_are_slowed(client: Any) -> None:
    """Dask's tick (20 ms), memory monitors (100 ms) and system monitor (500 ms) cost a local
    cluster's workers 19-22 ms of CPU a second each, and this process 34-36 ms (stop 64): slowed
    in the workers, where the nannies passed them, and in this process while the cluster runs,
    where its scheduler and nannies read them."""
    from pftrack.batch.engine import SLOWER_LOOPS

    assert list(client.run(_loops).values()) == [SLOWER_LOOPS, SLOWER_LOOPS]
    assert client.run_on_scheduler(_loops) == SLOWER_LOOPS
    assert _loops() == SLOWER_LOOPS


def test_tasks_go_to_the_cluster_largest_first(
    client: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Dask runs tasks in the order they were submitted: a long sequence given last ran alone at
    the end while the other workers idled. The most bytes read go first, ties as given; the
    summary keeps the input order."""
    import pftrack.batch.engine as engine

    sizes = {"a": 10, "b": 1000, "c": 100, "d": 1000, "e": 0}
    for name, size in sizes.items():
        (tmp_path / f"{name}.in").write_bytes(b"x" * size)
    jobs = [Job(name, _empty, (0,), (tmp_path / f"{name}.in",)) for name in sizes]
    jobs.append(Job("gone", _empty, (0,), (tmp_path / "gone.in",)))  # missing: 0 bytes
    sent: list[str] = []
    real = engine._run_on_dask

    def run_on_dask(c: Any, pending: Any, *args: Any, **kwargs: Any) -> None:
        sent.extend(job.name for job in pending)
        real(c, pending, *args, **kwargs)

    monkeypatch.setattr(engine, "_run_on_dask", run_on_dask)
    summary = run_jobs(jobs, tmp_path / "out", kind="smooth", settings={}, client=client)
    assert sent == ["b", "d", "c", "a", "e", "gone"]
    assert [e["name"] for e in summary.entries] == [*sizes, "gone"]
    assert {e["status"] for e in summary.entries} == {"done"}


_NO_EVAL_IMPORT = """import os, sys
os.environ["PFTRACK_TRACKING_THREADS"] = "0"
from pftrack.batch._plugin import SingleThreaded
from pftrack.batch.inputs import find_sequences
from pftrack.batch.tasks import TrackOptions, track_sequence
SingleThreaded()._setup()  # as on a worker of a local cluster
(seq,) = find_sequences([sys.argv[1]])
assert len(track_sequence(seq, TrackOptions()).rows)
print(sorted(m for m in sys.modules if m == "pftrack.eval" or m.startswith("scipy.optimize")))
"""


def test_a_worker_imports_no_evaluation_for_a_sequence_without_ground_truth(
    tmp_path: Path,
) -> None:
    """pftrack.eval imports SciPy's optimize: 0.33 s of CPU in each worker of every batch (stop
    64), for nothing where no sequence has ground truth: the worker plugin imported it as the
    cluster started, and every track task at its start."""
    scene = make_scene(n_frames=8, width=160, height=120, n_walkers=2, rng=0)
    video = scene.write_video(tmp_path / "walk.avi")
    done = subprocess.run(
        [sys.executable, "-c", _NO_EVAL_IMPORT, str(video)],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert done.stdout.strip() == "[]", done.stdout + done.stderr


def _exit_handler_marker(marker: str) -> str:
    """Register, in this (worker) process, an exit handler that writes `marker`."""
    import atexit

    atexit.register(Path(marker).write_text, "Python's teardown ran")
    return str(os.getpid())


def test_a_local_clusters_worker_process_ends_without_pythons_teardown(tmp_path: Path) -> None:
    """Once its worker has closed, a local cluster's worker process ends at once (the worker
    plugin's ``os._exit`` after its teardown): the interpreter's teardown, exit handlers and
    every module freed, took 0.65-1.03 s of the cluster's close, which pftrack batch waited
    for (stop 68). The worker's own close still ran whole: its local directory is removed."""
    markers = [tmp_path / f"w{k}.txt" for k in range(2)]
    with dask_client(n_workers=2) as c:
        workers = sorted(c.scheduler_info()["workers"])
        dirs = c.run(lambda dask_worker: dask_worker.local_directory)
        for worker, marker in zip(workers, markers, strict=True):
            c.run(_exit_handler_marker, str(marker), workers=[worker])
    assert [m.exists() for m in markers] == [False, False]  # was: True, True
    assert dirs and not [d for d in dirs.values() if Path(d).exists()]


_TEARDOWN_HERE = """import sys
from pftrack.batch._plugin import SingleThreaded
SingleThreaded(ignore_interrupt=True).teardown(None)
sys.exit(3)
"""


def test_the_quick_exit_is_only_for_a_worker_in_a_process_of_its_own() -> None:
    """A worker in this process (not a nanny's child) must not end the process: the plugin's
    teardown there leaves Python's exit as it is (its status kept)."""
    done = subprocess.run([sys.executable, "-c", _TEARDOWN_HERE], capture_output=True, text=True)
    assert done.returncode == 3, done.stderr


def _bars_drawn() -> TaskResult:
    """Whether a progress bar asked for here would be drawn on a terminal (as a task sees it)."""
    from pftrack import _progress

    return TaskResult(np.zeros((0, 10)), {}, {"quiet": _progress.quiet()})


def test_tasks_draw_no_bars_of_their_own(
    client: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A local cluster's workers share the terminal: the bars of what a task calls ("auto:
    calibrating: 100%|...| 1/1 bucket", "smoothing") were drawn over the batch's own."""
    from pftrack import _progress

    assert set(client.run(_progress.quiet).values()) == {True}
    monkeypatch.setattr(_progress, "_quiet", False)
    summary = run_jobs([Job("a", _bars_drawn, (), ())], tmp_path / "o", kind="smooth",
                       settings={}, n_workers=0)  # fmt: skip
    assert summary.entries[0]["quiet"] is True  # in this process too, while a task runs
    assert not _progress.quiet()  # and no longer


def test_cluster_equals_serial_and_pftrack_track(data: Path, client: Any, tmp_path: Path) -> None:
    options = TrackOptions(config=_config(), detections=None)
    on_dask = track_many(data, tmp_path / "dask", client, options=options)
    serial = track_many(data, tmp_path / "serial", options=options, n_workers=0)
    assert [e["status"] for e in on_dask.entries] == ["done"] * 3
    assert on_dask.workers == 2 and serial.workers == 0
    files = _files(tmp_path / "dask")
    assert sorted(files) == ["MOT-01.txt", "plain.txt", "walk.txt"]
    assert files == _files(tmp_path / "serial")
    # byte-identical to `pftrack track` with the same settings
    for name, source in (("walk", data / "walk.avi"), ("MOT-01", data / "MOT-01")):
        single = tmp_path / f"{name}.single"
        assert main(["track", str(source), "--out", str(single), *FAST]) == 0
        assert single.read_bytes() == files[f"{name}.txt"], name
    # the summary's metrics are pftrack.eval's on the written file
    entry = next(e for e in on_dask.entries if e["name"] == "MOT-01")
    gt = read_mot(data / "MOT-01" / "gt" / "gt.txt")
    s = evaluate_sequence(gt, read_mot(tmp_path / "dask" / "MOT-01.txt"))
    m, h = s.mot, s.hota
    assert entry["metrics"]["mota"] == m.mota and entry["metrics"]["idf1"] == m.idf1
    assert entry["metrics"]["hota"] == h.hota and entry["metrics"]["ass_a"] == h.ass_a_mean
    assert 0.0 < h.hota < 1.0 and "HOTA%" in on_dask.table()
    assert entry["frames"] == 30 and entry["tracks"] == len(np.unique(read_mot(single)[:, 1]))
    written = json.loads((tmp_path / "dask" / "summary.json").read_text())
    assert [s["name"] for s in written["sequences"]] == ["MOT-01", "plain", "walk"]
    assert written["counts"] == {"done": 3, "skipped": 0, "failed": 0, "cancelled": 0}


def test_knn_batch_equals_pftrack_track(
    data: Path, client: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--detector knn``: the cluster, a serial run without threads and ``pftrack track`` agree.

    Was: OpenCV's KNN drew from an unseeded per-thread generator, so a worker (detecting on
    the thread that runs the task, after the sequences before it) gave other rows than
    ``pftrack track`` (a fresh detection thread) for the same seed: 77.9 / 81.7 MOTA / IDF1
    against 79.7 / 83.5 on PETS09.
    """
    from dataclasses import replace

    options = TrackOptions(config=replace(_config(), detector="knn"), detections=None)
    on_dask = track_many(data, tmp_path / "dask", client, options=options)
    assert [e["status"] for e in on_dask.entries] == ["done"] * 3
    monkeypatch.setenv("PFTRACK_TRACKING_THREADS", "0")  # as a worker: detection on this thread
    serial = track_many(data, tmp_path / "serial", options=options, n_workers=0)
    assert [e["status"] for e in serial.entries] == ["done"] * 3
    files = _files(tmp_path / "dask")
    assert files == _files(tmp_path / "serial")
    monkeypatch.delenv("PFTRACK_TRACKING_THREADS")
    for name, source in (("walk", data / "walk.avi"), ("plain", data / "plain")):
        single = tmp_path / f"{name}.single"
        argv = ["track", str(source), "--out", str(single), "--detector", "knn", *FAST]
        assert main(argv) == 0
        assert single.read_bytes() == files[f"{name}.txt"], name


def _config() -> Any:
    from dataclasses import replace

    from pftrack.tracking import TrackerConfig

    base = TrackerConfig()
    return replace(base, filter=replace(base.filter, n_particles=30))


def test_ground_truth_without_a_size_takes_the_detections_scale(tmp_path: Path) -> None:
    """A user trial: seqinfo.ini without imWidth, boxes of twice the frames' size, --det-scale
    0.5: the tracks were right, the ground truth was scored at scale 1 (MOTA -100)."""
    scene = make_scene(n_frames=30, width=192, height=144, n_walkers=3, rng=1)
    seq = tmp_path / "HALF"
    scene.write_images(seq / "img1", ext=".png")
    double = scene.truth.copy()
    double[:, 2:6] *= 2
    (seq / "gt").mkdir()
    (seq / "det").mkdir()
    write_mot(seq / "gt" / "gt.txt", double)
    double[:, 1] = -1
    write_mot(seq / "det" / "det.txt", double)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=HALF\nframeRate=10\n")
    options = TrackOptions(_config(), detections="auto", det_scale=0.5)
    summary = track_many(seq, tmp_path / "out", n_workers=0, options=options)
    (entry,) = summary.entries
    assert entry["gt_scale"] == 0.5 and entry["metrics"]["mota"] > 0.5, entry


def test_failing_sequence_is_reported_and_the_others_finish(
    data: Path, client: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    broken = tmp_path / "broken.avi"
    broken.write_text("not a video")
    out = tmp_path / "out"
    argv = ["batch", str(data), str(broken), "--out", str(out), "--detections", "auto", *FAST]
    assert main([*argv, "--scheduler", client.scheduler.address]) == 1
    out_text, text = capsys.readouterr()  # errors on stderr: stdout's table stays parseable
    assert ": error:" not in out_text and "broken  " in out_text
    summary = json.loads((out / "summary.json").read_text())
    status = {s["name"]: s["status"] for s in summary["sequences"]}
    # walk.avi, plain/ and broken.avi have no det.txt: with --detections auto they fail too, by
    # name, refused before they reach the cluster (tests/batch/test_scheduler_trial.py)
    assert status == {"walk": "failed", "MOT-01": "done", "plain": "failed", "broken": "failed"}
    errors = {s["name"]: s["error"] for s in summary["sequences"] if s["status"] == "failed"}
    assert "no det/det.txt" in errors["broken"] and "no det/det.txt" in errors["walk"]
    # the same words but each its own name: one line (was: one a sequence)
    said = "3 sequences (plain, walk, broken): error: --detections auto: sequence NAME has no "
    assert f"\n{said}det/det.txt (nor det.txt)\n" in f"\n{text}"
    assert "broken: error" not in text and "walk: error" not in text
    assert sorted(p.name for p in out.iterdir()) == ["MOT-01.json", "MOT-01.txt", "summary.json"]
    # the video that cannot be read, on a worker, among others: its own error
    argv = ["batch", str(broken), str(data / "MOT-01"), "--out", str(tmp_path / "out2"), *FAST]
    assert main([*argv, "--scheduler", client.scheduler.address]) == 1
    assert "broken: error: cannot decode a frame" in capsys.readouterr().err
    # --detections auto is `pftrack track --detections SEQ/det/det.txt`
    single = tmp_path / "single.txt"
    det = data / "MOT-01" / "det" / "det.txt"
    assert main(["track", str(data / "MOT-01"), "--detections", str(det), "--out", str(single),
                 *FAST]) == 0  # fmt: skip
    assert single.read_bytes() == (out / "MOT-01.txt").read_bytes()


def test_a_name_that_is_not_utf8_fails_alone_on_dask(
    data: Path, client: Any, tmp_path: Path
) -> None:
    """A user trial: caf\\xe9.avi (a Latin-1 name) beside ok.avi failed both tasks, each said to
    have lost the scheduler: MessagePack sends text as UTF-8."""
    root = tmp_path / "in"
    root.mkdir()
    shutil.copy(data / "walk.avi", root / "ok.avi")
    shutil.copy(data / "walk.avi", root / os.fsdecode(b"caf\xe9.avi"))
    out = tmp_path / "out"
    track_many(root, out, client=client, options=TrackOptions(_config()), show_progress=False)
    summary = json.loads((out / "summary.json").read_text())
    status = {s["name"]: (s["status"], s.get("error")) for s in summary["sequences"]}
    assert status["ok"] == ("done", None)
    assert status[os.fsdecode(b"caf\xe9")][1].endswith(
        "the name is not UTF-8, which Dask cannot send to a worker; rename it, or run this "
        "batch in this process (--workers 0)"
    )


def test_an_image_folder_whose_names_skip_numbers_is_tracked_but_not_matched_to_files(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Images 1.png, 6.png, 11.png, ... beside det.txt and gt.txt, no seqinfo.ini: was refused
    outright ('image 2 is missing'). Tracked now, frames 1..N in the names' order; its
    detections and ground truth, which may count the images by name, are not matched to them."""
    seq = tmp_path / "FIVE"
    seq.mkdir()
    for k, image in enumerate(sorted((data / "MOT-01" / "img1").iterdir())):
        shutil.copy(image, seq / f"{1 + 5 * k}.jpg")
    shutil.copy(data / "MOT-01" / "gt" / "gt.txt", seq / "gt.txt")
    shutil.copy(data / "MOT-01" / "det" / "det.txt", seq / "det.txt")
    out = tmp_path / "out"
    argv = ["batch", str(seq), "--out", str(out), "--workers", "0", *FAST]
    assert main(argv) == 1
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["frames"] == 30 and entry["metrics"] is None and (out / "FIVE.txt").is_file()
    assert entry["error"] == (
        f"scoring against {seq / 'gt.txt'} (the tracks are written): {seq}: image 2 is missing "
        "(names 1..146 skip numbers): the ground truth's frame numbers may be the names or the "
        "images' positions; rename the images 1..N in their order and number the ground "
        "truth's frames alike"
    )
    assert main([*argv, "--detections", "auto", "--out", str(tmp_path / "det")]) == 1
    (entry,) = json.loads((tmp_path / "det" / "summary.json").read_text())["sequences"]
    assert entry["error"].startswith(f"{seq}: image 2 is missing (names 1..146 skip numbers): ")
    assert "detections cannot be matched to these images" in entry["error"]
    capsys.readouterr()


def test_a_truth_that_cannot_be_scored_keeps_the_tracks(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Scoring ran before the task returned its rows: a bad gt.txt lost the tracked rows."""
    seq = tmp_path / "MOT-01"
    shutil.copytree(data / "MOT-01", seq)
    good = (seq / "gt" / "gt.txt").read_bytes()
    (seq / "gt" / "gt.txt").write_text("1,1,10,10,20,40,1,1,1\nnot,a,row\n")
    out = tmp_path / "out"
    argv = ["batch", str(seq), "--out", str(out), "--workers", "0", *FAST]
    assert main(argv) == 1  # some sequence failed
    text = capsys.readouterr().err
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["status"] == "failed" and entry["frames"] == 30 and entry["metrics"] is None
    assert entry["error"].startswith(f"scoring against {seq / 'gt' / 'gt.txt'} (the tracks are")
    assert "gt.txt:2: ground truth line has 3 fields" in entry["error"]
    assert "Traceback" in entry["traceback"] and f"MOT-01: error: {entry['error']}" in text
    single = tmp_path / "single.txt"
    assert main(["track", str(seq), "--out", str(single), *FAST]) == 0
    assert (out / "MOT-01.txt").read_bytes() == single.read_bytes()
    assert json.loads((out / "MOT-01.json").read_text())["status"] == "failed"
    # not complete: a re-run tries again; with the truth mended, scored, then skipped
    assert main(argv) == 1
    (seq / "gt" / "gt.txt").write_bytes(good)
    assert main(argv) == 0
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["status"] == "done" and entry["metrics"]["mota"] is not None
    assert "error" not in entry
    assert main(argv) == 0
    assert json.loads((out / "summary.json").read_text())["counts"]["skipped"] == 1


def test_a_truth_beyond_seqlength_is_refused_as_pftrack_eval_refuses_it(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A ``gt.txt`` with a frame past ``seqLength`` (another sequence's, a wrong file): was
    scored by the batch, its rows misses, while ``pftrack eval`` on the same files refuses it;
    the batch's figures are said to be ``pftrack eval``'s."""
    seq = tmp_path / "MOT-01"
    shutil.copytree(data / "MOT-01", seq)
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=192\nimHeight=144\nseqLength=30\n")
    with (seq / "gt" / "gt.txt").open("a") as fh:
        fh.write("31,1,10,10,20,40,1,1,1\n")
    out = tmp_path / "out"
    assert main(["batch", str(seq), "--out", str(out), "--workers", "0", *FAST]) == 1
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    said = (  # the seqinfo.ini named (stop 74)
        "ground truth has frame 31, beyond the sequence's 30 frames (seqLength in "
        f"{seq / 'seqinfo.ini'})"
    )
    assert entry["status"] == "failed" and entry["metrics"] is None, entry
    assert (
        entry["error"]
        == f"scoring against {seq / 'gt' / 'gt.txt'} (the tracks are written): {said}"
    )
    capsys.readouterr()
    gt = str(seq / "gt" / "gt.txt")
    assert main(["eval", "--gt", gt, "--res", str(out / "MOT-01.txt")]) == 2
    assert said in capsys.readouterr().err


def test_a_truth_with_a_fractional_id_is_named_by_its_line(data: Path, tmp_path: Path) -> None:
    """Was ``ground truth row 30: track id 1.5 ...``, the 0-based index of an array the user
    never saw (line 31 of the file), where ``pftrack eval`` says ``gt.txt:31: track id 1.5``."""
    seq = tmp_path / "MOT-01"
    shutil.copytree(data / "MOT-01", seq)
    gt = seq / "gt" / "gt.txt"
    lines = gt.read_text().splitlines(keepends=True)
    gt.write_text("".join(lines[:30]) + "1,1.5,10,10,20,40,1,1,1\n" + "".join(lines[30:]))
    summary = track_many(seq, tmp_path / "out", n_workers=0, options=TrackOptions(_config()))
    (entry,) = summary.entries
    assert entry["error"] == (
        f"scoring against {gt} (the tracks are written): {gt}:31: track id 1.5 is not an "
        "integer with |id| <= 2147483647: '1,1.5,10,10,20,40,1,1,1'"
    )


def test_a_truth_of_no_row_is_refused_as_pftrack_eval_refuses_it(
    data: Path, tmp_path: Path
) -> None:
    """Was scored: every box a false positive, no error (``pftrack eval --gt`` refuses it
    since stop 64; both read it with :func:`pftrack.io.mot.read_ground_truth`)."""
    seq = tmp_path / "MOT-01"
    shutil.copytree(data / "MOT-01", seq)
    gt = seq / "gt" / "gt.txt"
    gt.write_text("")
    summary = track_many(seq, tmp_path / "out", n_workers=0, options=TrackOptions(_config()))
    (entry,) = summary.entries
    assert entry["error"] == (
        f"scoring against {gt} (the tracks are written): ground truth {gt} is empty (0 bytes): "
        "nothing to score against (a cut download or copy?)"
    )
    assert (tmp_path / "out" / "MOT-01.txt").stat().st_size > 0


def test_a_truth_with_a_negative_id_is_named_by_its_line(data: Path, tmp_path: Path) -> None:
    """Was ``ground truth has id -5 in frame 1: ids must be >= 0 ...``, without the line,
    where ``pftrack eval`` (and ``recover``) say ``gt.txt:31: id -5 in frame 1 ...``."""
    seq = tmp_path / "MOT-01"
    shutil.copytree(data / "MOT-01", seq)
    gt = seq / "gt" / "gt.txt"
    lines = gt.read_text().splitlines(keepends=True)
    gt.write_text("".join(lines[:30]) + "1,-5,10,10,20,40,1,1,1\n" + "".join(lines[30:]))
    summary = track_many(seq, tmp_path / "out", n_workers=0, options=TrackOptions(_config()))
    (entry,) = summary.entries
    assert entry["error"] == (
        f"scoring against {gt} (the tracks are written): {gt}:31: id -5 in frame 1 (1 row has "
        "it): track ids must be >= 0, as pftrack eval and TrackEval require them (-1 alone has "
        "a meaning: a box no track holds); renumber the tracks"
    )


def test_resume_skips_complete_outputs_and_force_redoes(
    data: Path, client: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    argv = ["batch", str(data), "--out", str(out), "--scheduler", client.scheduler.address]
    assert main([*argv, *FAST]) == 0
    stamp = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    before = _files(out)

    def statuses() -> dict[str, str]:
        summary = json.loads((out / "summary.json").read_text())
        return {s["name"]: s["status"] for s in summary["sequences"]}

    capsys.readouterr()
    assert main([*argv, *FAST]) == 0
    assert set(statuses().values()) == {"skipped"}
    # was "0.0 s, in this process" with --scheduler given (a README trial): nothing ran anywhere
    assert re.search(
        r"3 sequences: 3 skipped; \d+\.\d s, nothing to run\n", capsys.readouterr().out
    )
    assert all(out.joinpath(n).stat().st_mtime_ns == t for n, t in stamp.items() if n[0] != "s")
    # a sequence whose outputs are gone is redone, alone
    (out / "plain.json").unlink()
    (out / "plain.txt").unlink()
    assert main([*argv, *FAST]) == 0
    assert statuses() == {"walk": "skipped", "MOT-01": "skipped", "plain": "done"}
    # other settings: not complete for them
    assert main([*argv, "--particles", "31"]) == 0
    assert set(statuses().values()) == {"done"}
    assert main([*argv, *FAST, "--force"]) == 0
    assert set(statuses().values()) == {"done"}
    assert _files(out) == before


def test_files_no_batch_wrote_are_not_replaced_without_force(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``--out`` the input folder (as docs/batch.md allows) replaced the user's
    own ``walk.txt`` (their annotations beside ``walk.avi``) with the tracks, exit 0."""
    vids = tmp_path / "vids"
    vids.mkdir()
    shutil.copy2(data / "walk.avi", vids / "walk.avi")
    argv = ["batch", str(vids), "--out", str(vids), "--workers", "0", *FAST]
    for name, text in (("walk.txt", "my annotations\n"), ("walk.json", "{}\n"),
                       ("summary.json", "[1, 2]\n")):  # fmt: skip
        (vids / name).write_text(text)
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(vids / name) in err, err
        assert "this run would replace it: move it, write elsewhere, or give --force" in err
        assert sorted(p.name for p in vids.iterdir()) == sorted(["walk.avi", name])
        assert (vids / name).read_text() == text
        if name != "summary.json":
            (vids / name).unlink()
    (vids / "summary.json").unlink()
    assert main(argv) == 0  # nothing in the way
    assert main(argv) == 0  # and its own outputs: skipped, or redone with other settings
    assert main([*argv, "--particles", "31"]) == 0
    (vids / "walk.txt").write_text("my annotations\n")  # replaced by the user: still a batch's
    assert main([*argv, "--force"]) == 0
    assert (vids / "walk.txt").read_text() != "my annotations\n"
    with pytest.raises(ValueError, match=r"exists and no earlier batch .* give force=True"):
        (vids / "walk.json").unlink()
        track_many([vids], vids, n_workers=0)


@contextlib.contextmanager
def _unreadable(folder: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """`folder` made mode 000: it can be seen, not looked into (as a user; root is let in
    anywhere, so the listing and every look inside it raise here as they would for a user)."""
    real = os.stat, os.listdir, os.scandir
    top = os.path.abspath(folder)

    def inside(path: Any, itself: bool) -> bool:
        if isinstance(path, int):
            return False
        name = os.path.abspath(os.fsdecode(os.fspath(path)))
        return (itself and name == top) or name.startswith(top + os.sep)

    def refuse(path: Any) -> None:
        raise PermissionError(13, "Permission denied", os.fspath(path))

    def stat(path: Any, *args: Any, **kwargs: Any) -> Any:
        if inside(path, itself=False):
            refuse(path)
        return real[0](path, *args, **kwargs)

    def listdir(path: Any = ".") -> Any:
        if inside(path, itself=True):
            refuse(path)
        return real[1](path)

    def scandir(path: Any = ".") -> Any:
        if inside(path, itself=True):
            refuse(path)
        return real[2](path)

    folder.chmod(0)
    try:
        with monkeypatch.context() as m:
            m.setattr(os, "stat", stat)
            m.setattr(os, "listdir", listdir)
            m.setattr(os, "scandir", scandir)
            yield
    finally:
        folder.chmod(0o755)


def test_a_stream_url_input_is_named_as_one(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was ``input not found: /cwd/rtsp:/cam/stream``, a path the user never gave."""
    out = str(tmp_path / "out")
    assert main(["batch", "rtsp://cam/stream", str(data / "walk.avi"), "--out", out]) == 2
    assert capsys.readouterr().err == (
        "pftrack batch: error: input rtsp://cam/stream is a URL, not a file or a folder: a "
        "batch reads files (pftrack track reads a stream live, alone)\n"
    )
    tracks = tmp_path / "a.txt"
    tracks.write_text("1,1,10,10,20,40,1,-1,-1,-1\n")
    assert main(["recover", str(tracks), "http://host/b.txt", "--out", out]) == 2
    assert capsys.readouterr().err == (
        "pftrack recover: error: input http://host/b.txt is a URL, not a file or a folder: a "
        "batch reads files\n"
    )
    assert not Path(out).exists()


def test_a_name_too_long_for_its_outputs_fails_alone(data: Path, tmp_path: Path) -> None:
    """A video named with 251 bytes before ``.avi`` (255 in all, the file system's most): its
    ``NAME.json`` cannot exist. Was: the whole batch stopped, exit 2, ``File name too long:
    vids/NAME.json``, a file the user never had (the look for a batch's sidecar beside it)."""
    vids = tmp_path / "vids"
    vids.mkdir()
    long = "v" * 251
    shutil.copy(data / "walk.avi", vids / f"{long}.avi")
    shutil.copy(data / "walk.avi", vids / "walk.avi")
    summary = track_many(vids, tmp_path / "out", n_workers=0, options=TrackOptions(_config()))
    status = {e["name"]: (e["status"], e.get("error")) for e in summary.entries}
    assert status["walk"] == ("done", None)
    assert status[long][0] == "failed" and "File name too long" in status[long][1], status


def test_a_pipe_or_device_input_is_named_as_one(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was ``pftrack batch: error: Not a directory: vids/pipe.mp4`` (and for ``/dev/null``),
    the whole batch stopped, a pipe met in a folder of videos too; ``recover`` and ``smooth``
    given one among their files likewise."""
    vids = tmp_path / "vids"
    vids.mkdir()
    shutil.copy(data / "walk.avi", vids / "walk.avi")
    os.mkfifo(vids / "pipe.mp4")
    out = tmp_path / "out"
    with pytest.warns(UserWarning, match=f"{vids / 'pipe.mp4'} is a named pipe, not a video "):
        summary = track_many(vids, out, n_workers=0, options=TrackOptions(_config()))
    assert [(e["name"], e["status"]) for e in summary.entries] == [("walk", "done")]
    assert main(["batch", str(vids / "pipe.mp4"), "--out", str(out), *FAST]) == 2
    assert capsys.readouterr().err == (
        f"pftrack batch: error: input {vids / 'pipe.mp4'} is a named pipe, not a file or a "
        "folder: a batch reads files (pftrack track reads a pipe live, alone)\n"
    )
    assert main(["batch", os.devnull, "--out", str(out)]) == 2
    assert "input /dev/null is a character device, not a file or a " in capsys.readouterr().err
    tracks = tmp_path / "a.txt"
    shutil.copy(out / "walk.txt", tracks)
    for command in ("recover", "smooth"):
        argv = [command, str(tracks), os.devnull, "--out", str(tmp_path / command)]
        assert main(argv) == 2
        assert capsys.readouterr().err == (
            f"pftrack {command}: error: input /dev/null is a character device, not a file or a "
            "folder: a batch reads files\n"
        )


@pytest.mark.parametrize("locked", ["s", "s/img1"])
def test_a_sequence_folder_that_cannot_be_read_fails_alone(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, locked: str,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    """A user trial: a folder of sequences with one that cannot be read (mode 700 of another
    user, ``lost+found``) stopped the whole batch, exit 2, with ``Permission denied:
    .../s/seqinfo.ini`` (a file that need not exist), and with its ``img1/`` unreadable
    ``Permission denied: .../s/img1/seqinfo.ini``; given alone, said so too."""
    root = tmp_path / "in"
    shutil.copytree(data / "MOT-01", root / "good")
    shutil.copytree(data / "MOT-01", root / "s")
    out = tmp_path / "out"
    with _unreadable(root / locked, monkeypatch):
        summary = track_many(root, out, n_workers=0, options=TrackOptions(_config()))
        status = {e["name"]: (e["status"], e.get("error")) for e in summary.entries}
        assert status["good"] == ("done", None)
        assert status["s"] == (
            "failed", f"cannot read the folder {root / locked} (Permission denied)"
        ), status  # fmt: skip
        assert sorted(p.name for p in out.iterdir()) == ["good.json", "good.txt", "summary.json"]
        assert main(["batch", str(root / "s"), "--out", str(tmp_path / "o2"), "--workers", "0",
                     *FAST]) == 1  # fmt: skip
        assert capsys.readouterr().err == (
            f"s: error: cannot read the folder {root / locked} (Permission denied)\n"
        )


def test_an_unwritable_out_is_refused_before_the_cluster_starts(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: refused only once the local cluster had started (or the scheduler answered),
    seconds later; a folder to be made under one that takes none was "cannot create the folder
    (No such file or directory)"."""
    from pftrack.batch import engine

    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    real = os.access

    def access(path: Any, mode: int, *args: Any, **kwargs: Any) -> bool:
        if Path(path) == locked and mode & os.W_OK:  # root writes anywhere: as a user here
            return False
        return real(path, mode, *args, **kwargs)

    def no_cluster(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("a cluster was started for an --out that cannot be written")

    monkeypatch.setattr(os, "access", access)
    monkeypatch.setattr(engine, "dask_client", no_cluster)
    try:
        video = str(data / "walk.avi")
        assert main(["batch", video, "--out", str(locked)]) == 2
        assert capsys.readouterr().err == (
            f"pftrack batch: error: --out {locked}: the folder is not writable (Permission "
            "denied): no output can be written in it; write elsewhere\n"
        )
        assert main(["batch", video, "--out", str(locked / "new" / "deeper")]) == 2
        assert capsys.readouterr().err == (
            f"pftrack batch: error: --out {locked / 'new' / 'deeper'}: cannot create the "
            f"folder: {locked} is not writable (Permission denied); write elsewhere\n"
        )
        with pytest.raises(PermissionError, match=f"^out_dir {locked}: the folder is not "):
            track_many(video, locked, n_workers=0)
        assert sorted(locked.iterdir()) == []
    finally:
        locked.chmod(0o700)


def test_a_sidecar_cut_short_is_redone_with_a_note(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: a truncated ``NAME.json`` (a copy stopped half-way) refused the whole batch as a
    file no batch wrote ("no sidecar walk.json of one names it", with one there), and the
    remedy, --force, redid every sequence."""
    vids = tmp_path / "vids"
    vids.mkdir()
    shutil.copy2(data / "walk.avi", vids / "walk.avi")
    out = tmp_path / "out"
    argv = ["batch", str(vids), "--out", str(out), "--workers", "0", *FAST]
    assert main(argv) == 0
    sidecar = out / "walk.json"
    for size in (100, 0):
        sidecar.write_bytes(sidecar.read_bytes()[:size])
        capsys.readouterr()
        assert main(argv) == 0
        note = f"redone: its sidecar {sidecar} was cut short ({size} bytes, not valid JSON: "
        assert f"walk: {note}" in capsys.readouterr().out
        (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
        assert entry["status"] == "done" and entry["note"].startswith(note)
        assert json.loads(sidecar.read_text())["status"] == "done"  # whole again
    assert main(argv) == 0  # complete: skipped
    assert json.loads((out / "summary.json").read_text())["counts"]["skipped"] == 1
    # a summary.json cut short: an earlier batch's, replaced
    summary = out / "summary.json"
    summary.write_bytes(summary.read_bytes()[:50])
    assert main(argv) == 0
    assert json.loads(summary.read_text())["counts"]["skipped"] == 1
    # not the beginning of a sidecar: perhaps the user's; refused, said so, nothing changed
    sidecar.write_text("garbage\n")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"pftrack batch: error: --out {out / 'walk.txt'} exists and no earlier batch wrote it "
        "(walk.json is not JSON, nor the beginning of a batch's sidecar); this run would "
        "replace it: move it, write elsewhere, or give --force\n"
    )
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_resume_redoes_a_file_whose_content_changed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    paths = _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]
    assert main(argv) == 0

    def entries() -> dict[str, dict[str, Any]]:
        return {f["name"]: f for f in json.loads((out / "summary.json").read_text())["files"]}

    # cut to its first rows: path and settings as before, the content not
    rows = read_mot(paths[0])
    write_mot(paths[0], rows[: len(rows) // 2])
    capsys.readouterr()
    assert main(argv) == 0
    got = entries()
    assert [e["status"] for e in got.values()] == ["done", "skipped", "skipped"]
    assert got["run0"]["rows_in"] == len(rows) // 2
    assert f"run0: redone: {paths[0]} changed since the last run" in capsys.readouterr().out
    single = tmp_path / "single.txt"
    assert main(["recover", str(paths[0]), "--out", str(single)]) == 0
    assert single.read_bytes() == (out / "run0.txt").read_bytes()
    # the same size, a new modification time: redone too (the content cannot be told apart)
    st = paths[1].stat()
    os.utime(paths[1], ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    assert main(argv) == 0
    assert [e["status"] for e in entries().values()] == ["skipped", "done", "skipped"]
    assert "note" not in entries()["run0"]
    # unchanged: skipped, and --force still redoes everything
    assert main(argv) == 0
    assert {e["status"] for e in entries().values()} == {"skipped"}
    assert main([*argv, "--force"]) == 0
    assert {e["status"] for e in entries().values()} == {"done"}
    # made by another release (a user trial: skipped after an upgrade that tracks otherwise)
    sidecar = out / "run1.json"
    older = json.loads(sidecar.read_text())
    older["pftrack"] = "0.0.1"
    sidecar.write_text(json.dumps(older))
    capsys.readouterr()
    assert main(argv) == 0
    assert [e["status"] for e in entries().values()] == ["skipped", "done", "skipped"]
    import pftrack

    said = f"run1: redone: made by pftrack 0.0.1, this is pftrack {pftrack.__version__}"
    assert said in capsys.readouterr().out


def test_an_output_that_cannot_be_written_fails_its_task_not_the_batch(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: a full disk stopped the batch (exit status 2, "nothing ran") after a task
    was written, its table never printed, the task being written listed as cancelled."""
    import errno

    from pftrack.batch import engine

    _tracks_files(tmp_path / "tracks")
    real = engine.write_mot

    def full(path: Any, *args: Any, **kwargs: Any) -> None:
        if Path(path).name.startswith(".run1."):  # run1.txt's staged file
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        real(path, *args, **kwargs)

    monkeypatch.setattr(engine, "write_mot", full)
    out = tmp_path / "out"
    assert main(["recover", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]) == 1
    files = json.loads((out / "summary.json").read_text())["files"]
    assert [f["status"] for f in files] == ["done", "failed", "done"]
    error = files[1]["error"]
    assert error.startswith("writing its outputs: ") and "No space left on device" in error
    assert str(out / "run1.txt") in error
    assert "run1" in capsys.readouterr().out  # the table


def test_a_summary_that_cannot_be_written_keeps_the_table(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: the disk full (or --out made read-only) by the end, summary.json could
    not be written: exit status 2 ("bad usage, nothing ran") with ``Permission denied:
    out/summary.json`` alone, no table, though the tasks' outputs were written."""
    import errno

    from pftrack.batch import engine

    _tracks_files(tmp_path / "tracks")
    real = engine.atomic_write

    def full(path: Any, *args: Any, **kwargs: Any) -> Any:
        if Path(path).name == "summary.json":
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(engine, "atomic_write", full)
    out = tmp_path / "out"
    assert main(["recover", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]) == 1
    text, err = capsys.readouterr()
    assert re.search(r"^run1 +done ", text, re.M) and "summary ->" not in text
    said = f"{out / 'summary.json'} not written (No space left on device)"
    assert err == f"error: {said}; the outputs written before it are complete\n"
    assert sorted(p.name for p in out.iterdir()) == [
        f"run{k}.{ext}" for k in range(3) for ext in ("json", "txt")
    ]
    summary = recover_many(tmp_path / "tracks", out, n_workers=0, force=True)
    assert summary.unwritten == f"{said}; the outputs written before it are complete"
    assert summary.table().endswith(f"\nerror: {summary.unwritten}")


def _remove_folder(out: str, again: bool) -> TaskResult:
    """A task that removes the batch's output folder (`again`: and makes an empty one there)."""
    shutil.rmtree(out)
    if again:
        os.mkdir(out)
    return TaskResult(np.zeros((0, 10)), {}, {})


def _empty(k: int) -> TaskResult:
    return TaskResult(np.zeros((0, 10)), {}, {"k": k})


@pytest.mark.parametrize("again", [False, True])
def test_an_out_folder_removed_while_the_batch_runs_is_said_with_what_was_lost(
    tmp_path: Path, again: bool
) -> None:
    """A trial: ``--out`` deleted while the batch ran, the last line still said "the outputs
    written before it are complete", of outputs gone with the folder; made again meanwhile
    (``rm -r out; mkdir out``), summary.json went into the new folder, its entries ``done``."""
    out = tmp_path / "out"
    first = run_jobs([Job("a", _empty, (0,), ())], out, kind="smooth", settings={}, n_workers=0)
    assert [e["status"] for e in first.entries] == ["done"] and first.unwritten is None
    jobs = [
        Job("a", _empty, (0,), ()),  # skipped: its outputs, complete, were in the folder
        Job("b", _empty, (1,), ()),
        Job("gone", _remove_folder, (str(out), again), ()),
        Job("c", _empty, (2,), ()),
    ]
    summary = run_jobs(jobs, out, kind="smooth", settings={}, n_workers=0)
    status = {e["name"]: e["status"] for e in summary.entries}
    after = "done" if again else "failed"  # written into the folder made again, or not
    assert status == {"a": "skipped", "b": "done", "gone": after, "c": after}
    another = " (the folder there now is another one)" if again else ""
    assert summary.unwritten == (
        f"out_dir {out} was removed while the batch ran{another}: the outputs of 2 files "
        "(a, b) went with it, and summary.json is not written; re-run the batch to make them "
        "again"
    )
    assert summary.table().endswith(f"\nerror: {summary.unwritten}")
    if again:  # the outputs written into it are there, no summary.json
        assert sorted(os.listdir(out)) == ["c.json", "c.txt", "gone.json", "gone.txt"]
    else:
        assert not out.exists()


def test_resume_redoes_an_output_truncated_emptied_or_replaced(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An output only had to exist: truncated, emptied or replaced by another file of the same
    size, it counted as complete and a re-run skipped it with the earlier figures (exit 0)."""
    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]
    assert main(argv) == 0
    good = {name: (out / f"{name}.txt").read_bytes() for name in ("run0", "run1", "run2")}
    sidecar = json.loads((out / "run0.json").read_text())
    assert sidecar["output_prints"] == [
        {"name": "run0.txt", "size": len(good["run0"]),
         "sha256": hashlib.sha256(good["run0"]).hexdigest()}
    ]  # fmt: skip

    def rerun() -> dict[str, str]:
        capsys.readouterr()
        assert main(argv) == 0
        summary = json.loads((out / "summary.json").read_text())
        assert "output_prints" not in summary["files"][0]
        return {f["name"]: f["status"] for f in summary["files"]}

    (out / "run0.txt").write_bytes(good["run0"][:100])  # truncated
    (out / "run1.txt").write_bytes(b"")  # emptied
    same_size = bytearray(good["run2"])
    same_size[-5] = ord("7") if same_size[-5] != ord("7") else ord("8")
    (out / "run2.txt").write_bytes(bytes(same_size))  # replaced: the same size
    assert rerun() == {"run0": "done", "run1": "done", "run2": "done"}
    said = capsys.readouterr().out  # the table, then its notes
    summary = json.loads((out / "summary.json").read_text())
    notes = {f["name"]: f["note"] for f in summary["files"]}
    assert notes == {
        "run0": f"redone: its output {out / 'run0.txt'} changed since the last run wrote it "
        f"(100 bytes, written {len(good['run0'])})",
        "run1": f"redone: its output {out / 'run1.txt'} changed since the last run wrote it "
        f"(0 bytes, written {len(good['run1'])})",
        "run2": f"redone: its output {out / 'run2.txt'} changed since the last run wrote it "
        "(the same size, other content)",
    }
    assert [line for line in said.splitlines() if "redone" in line] == [
        f"{name}: {note}" for name, note in notes.items()
    ]
    assert {n: (out / f"{n}.txt").read_bytes() for n in good} == good
    # the same bytes with a new time (touch): still complete; a removed output: said so
    os.utime(out / "run0.txt", ns=(0, 0))
    (out / "run1.txt").unlink()
    assert rerun() == {"run0": "skipped", "run1": "done", "run2": "skipped"}
    assert json.loads((out / "summary.json").read_text())["files"][1]["note"] == (
        f"redone: its output {out / 'run1.txt'} is missing"
    )
    # a sidecar of an older pftrack, which recorded no output fingerprint: redone once
    old = json.loads((out / "run2.json").read_text())
    del old["output_prints"]
    (out / "run2.json").write_text(json.dumps(old))
    assert rerun() == {"run0": "skipped", "run1": "skipped", "run2": "done"}
    assert json.loads((out / "summary.json").read_text())["files"][2]["note"] == (
        "redone: its sidecar records no fingerprint of its outputs (an older run)"
    )
    assert rerun() == {"run0": "skipped", "run1": "skipped", "run2": "skipped"}


def test_a_large_output_is_fingerprinted_by_its_size_and_ends(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A rendered video past HASHED_WHOLE: its size and first and last HASHED_ENDS bytes."""
    import pftrack.batch.engine as engine

    monkeypatch.setattr(engine, "HASHED_WHOLE", 64)
    monkeypatch.setattr(engine, "HASHED_ENDS", 16)
    data = bytes(range(200))
    (tmp_path / "v.mp4").write_bytes(data)
    got = engine.output_print(tmp_path / "v.mp4")
    assert got == {"name": "v.mp4", "size": 200,
                   "sha256": hashlib.sha256(data[:16] + data[-16:]).hexdigest()}  # fmt: skip
    (tmp_path / "s.txt").write_bytes(data[:64])
    assert engine.output_print(tmp_path / "s.txt")["sha256"] == (
        hashlib.sha256(data[:64]).hexdigest()
    )


def test_resume_redoes_a_sequence_whose_truth_or_images_changed(
    data: Path, client: Any, tmp_path: Path
) -> None:
    seq = tmp_path / "MOT-01"
    shutil.copytree(data / "MOT-01", seq)
    options = TrackOptions(config=_config())
    first = track_many(seq, tmp_path / "out", client, options=options).entries[0]
    assert first["status"] == "done" and first["metrics"]["mota"] is not None
    gt = read_mot(seq / "gt" / "gt.txt")
    gt[:, 2] += 60.0  # every true box moved: the same tracks now score badly
    write_mot(seq / "gt" / "gt.txt", gt)
    again = track_many(seq, tmp_path / "out", client, options=options).entries[0]
    assert again["status"] == "done" and again["metrics"]["mota"] < first["metrics"]["mota"]
    assert again["note"] == f"redone: {seq / 'gt' / 'gt.txt'} changed since the last run"
    assert track_many(seq, tmp_path / "out", client, options=options).entries[0]["status"] == (
        "skipped"
    )
    # an image folder: one image fewer
    images = sorted((seq / "img1").iterdir())
    images[-1].unlink()
    last = track_many(seq, tmp_path / "out", client, options=options).entries[0]
    assert last["status"] == "done" and last["frames"] == len(images) - 1


def test_resume_redoes_an_image_folder_whose_images_were_renamed(
    data: Path, tmp_path: Path
) -> None:
    """Two images' names swapped: the same count, total size and newest time, other frames.

    The fingerprint was those three figures, so the stale tracks were kept ("skipped")."""
    folder = tmp_path / "plain"
    shutil.copytree(data / "plain", folder)
    out = tmp_path / "out"
    options = TrackOptions(config=_config())
    assert track_many(folder, out, options=options, n_workers=0).entries[0]["status"] == "done"
    before = (out / "plain.txt").read_bytes()
    images = sorted(folder.iterdir(), key=lambda p: int(p.stem))
    a, b = images[5], images[20]
    assert a.stat().st_size != b.stat().st_size  # else only their mtime_ns could tell
    a.rename(folder / "swap.png")  # renames keep each file's size and mtime
    b.rename(a)
    (folder / "swap.png").rename(b)
    again = track_many(folder, out, options=options, n_workers=0).entries[0]
    assert again["status"] == "done"
    assert again["note"] == f"redone: {folder} changed since the last run"
    single = tmp_path / "single.txt"
    assert main(["track", str(folder), "--out", str(single), *FAST]) == 0
    assert (out / "plain.txt").read_bytes() == single.read_bytes() != before
    unchanged = track_many(folder, out, options=options, n_workers=0).entries[0]
    assert unchanged["status"] == "skipped"
    # a sidecar from before the listing was fingerprinted: redone once, and said so
    sidecar = json.loads((out / "plain.json").read_text())
    del sidecar["fingerprint"][0]["listing"]
    (out / "plain.json").write_text(json.dumps(sidecar))
    older = track_many(folder, out, options=options, n_workers=0).entries[0]
    assert older["status"] == "done"
    assert older["note"] == f"redone: its sidecar records an older kind of fingerprint of {folder}"


def test_a_run_stopped_while_writing_leaves_no_stale_complete_sequence(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Outputs were replaced before the sidecar: stopped in between, the old sidecar vouched
    for the new NAME.txt (a re-run with the old settings skipped it), and a video rendered
    before any sidecar was an input of the next scan of its folder. The outputs and the final
    sidecar are now staged and renamed together (a Ctrl-C while they are written leaves the
    earlier ones); the sidecar that says ``writing`` still comes first, for a run stopped in the
    middle of the renames (``kill -9``: here an exception raised by the rename itself)."""
    import pftrack.batch.engine as engine

    out = tmp_path / "out"
    first = TrackOptions(config=_config())
    track_many(data / "plain", out, options=first, n_workers=0)
    before = (out / "plain.txt").read_bytes()
    real_write_mot = engine.write_mot

    def write_then_stop(*args: Any, **kwargs: Any) -> None:
        real_write_mot(*args, **kwargs)
        raise KeyboardInterrupt  # Ctrl-C right after NAME.txt is written (staged)

    monkeypatch.setattr(engine, "write_mot", write_then_stop)
    other = TrackOptions(config=_config(), seed=1)
    with pytest.raises(KeyboardInterrupt):
        track_many(data / "plain", out, options=other, n_workers=0)
    assert (out / "plain.txt").read_bytes() == before  # staged: not replaced (was: replaced)
    assert json.loads((out / "plain.json").read_text())["status"] == "writing"
    assert sorted(p.name for p in out.iterdir()) == ["plain.json", "plain.txt", "summary.json"]
    monkeypatch.setattr(engine, "write_mot", real_write_mot)
    again = track_many(data / "plain", out, options=first, n_workers=0).entries[0]
    assert again["status"] == "done" and (out / "plain.txt").read_bytes() == before
    # --out the input folder with --render, stopped once the video is renamed into place
    vids = tmp_path / "vids"
    vids.mkdir()
    shutil.copy2(data / "walk.avi", vids / "walk.avi")
    real_replace = os.replace

    def stop_after_video(src: Any, dst: Any) -> None:
        real_replace(src, dst)
        if os.fspath(dst) == str(vids / "walk.mp4"):  # not the task's own renames
            raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", stop_after_video)
    render = TrackOptions(config=_config(), render=".mp4")
    with pytest.raises(KeyboardInterrupt):
        track_many(vids, vids, options=render, n_workers=0)
    monkeypatch.setattr(os, "replace", real_replace)
    assert (vids / "walk.mp4").is_file()
    assert json.loads((vids / "walk.json").read_text())["status"] == "writing"
    assert track_many(vids, vids, options=render, n_workers=0).entries[0]["status"] == "done"


@pytest.fixture
def connect_timeout_1s() -> Iterator[None]:
    """Dask's connect timeout (``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT``) at 1 s."""
    import dask

    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        yield


def test_an_unreachable_scheduler_writes_nothing(
    tmp_path: Path, connect_timeout_1s: None, capsys: pytest.CaptureFixture[str]
) -> None:
    _tracks_files(tmp_path / "tracks")
    address = f"tcp://127.0.0.1:{_free_port()}"  # nothing listens there
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(tmp_path / "out")]
    start = time.monotonic()
    assert main([*argv, "--scheduler", address]) == 2
    assert time.monotonic() - start < 15  # the timeout set above, not a hard-coded 20 s
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot connect to the Dask scheduler" in err
    assert address in err
    assert not (tmp_path / "out").exists()
    # over complete results, --force: the summary and outputs a user had stay as they were
    assert main([*argv, "--workers", "0"]) == 0
    before = {p.name: p.read_bytes() for p in (tmp_path / "out").iterdir()}
    assert main([*argv, "--scheduler", address, "--force"]) == 2
    assert {p.name: p.read_bytes() for p in (tmp_path / "out").iterdir()} == before


@pytest.mark.parametrize(
    ("host", "said"),
    [
        ("127.0.0.1", "connection refused: nothing listens on port {port} of 127.0.0.1 (start "
         "the scheduler there first: dask scheduler --port {port})"),  # was: dask scheduler
        ("pftrack-nowhere.invalid", "host pftrack-nowhere.invalid not found (its name does not "
         "resolve)"),
    ],
)  # fmt: skip
def test_a_refused_or_unknown_scheduler_fails_at_once(
    host: str, said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: each took Dask's whole 30 s connect timeout, then said only "Timed out
    trying to connect"."""
    _tracks_files(tmp_path / "tracks")
    port = _free_port()
    address = f"tcp://{host}:{port}"
    start = time.monotonic()
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(tmp_path / "out")]
    assert main([*argv, "--scheduler", address]) == 2
    assert time.monotonic() - start < 10
    assert capsys.readouterr().err == (
        f"pftrack recover: error: cannot connect to the Dask scheduler at {address}: "
        f"{said.format(port=port)}\n"
    )
    assert not (tmp_path / "out").exists()


def test_a_port_that_says_nothing_is_no_scheduler(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: a port that accepts the connection and never speaks (the dashboard's, an
    HTTP server) held ``Client(address)`` for ever: Dask's connect timeout does not cover the
    handshake."""
    from pftrack.batch import engine

    monkeypatch.setattr(engine, "GREETING_WAIT", 0.5)
    _tracks_files(tmp_path / "tracks")
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)
        address = f"tcp://127.0.0.1:{listener.getsockname()[1]}"
        start = time.monotonic()
        argv = ["recover", str(tmp_path / "tracks"), "--out", str(tmp_path / "out")]
        assert main([*argv, "--scheduler", address]) == 2
        assert time.monotonic() - start < 10
    assert capsys.readouterr().err.endswith(
        "accepted the connection but said nothing within 0.5 s, as no Dask scheduler does (the "
        "dashboard's port? a scheduler listens on 8786 unless told otherwise)\n"
    )
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("greeting", "said"),
    [
        (b"\x01", "began to answer but did not finish Dask's handshake within 1 s (a frozen or "
         "overloaded scheduler, or no Dask server)"),
        (b"hello garbage\n", "answered in a protocol that is not Dask's"),
    ],
)  # fmt: skip
def test_a_port_that_answers_half_or_in_another_protocol_is_no_scheduler(
    greeting: bytes,
    said: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A user trial: a server that sent one byte and then nothing held the batch for ever
    (Dask's connect timeout does not cover its handshake), one that greeted in another
    protocol said "MemoryError: Unable to allocate 6.09 EiB for an array"."""
    from pftrack.batch import engine

    monkeypatch.setattr(engine, "GREETING_WAIT", 1.0)
    _tracks_files(tmp_path / "tracks")
    held: list[socket.socket] = []
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(8)

        def serve() -> None:
            with contextlib.suppress(OSError):
                while True:
                    conn, _ = listener.accept()
                    held.append(conn)
                    conn.sendall(greeting)

        threading.Thread(target=serve, daemon=True).start()
        address = f"tcp://127.0.0.1:{listener.getsockname()[1]}"
        argv = ["recover", str(tmp_path / "tracks"), "--out", str(tmp_path / "out")]
        status: list[int] = []
        run = threading.Thread(target=lambda: status.append(main([*argv, "--scheduler", address])))
        run.daemon = True
        run.start()
        run.join(30)
        for conn in held:
            conn.close()
    assert status == [2]
    err = capsys.readouterr().err
    assert err.startswith(
        f"pftrack recover: error: cannot connect to the Dask scheduler at {address}: port "
        f"{address.rpartition(':')[2]} of 127.0.0.1 {said}"
    ), err
    assert err.count("\n") == 1
    assert not (tmp_path / "out").exists()


@contextlib.contextmanager
def _silent_dask_server() -> Iterator[str]:
    """The address of a Dask server that completes the handshake, then answers nothing."""
    import asyncio

    from distributed.comm import listen

    ready = threading.Event()
    port: list[int] = []
    stop = threading.Event()

    async def serve() -> None:
        async def never(comm: Any) -> None:
            while not stop.is_set():
                await asyncio.sleep(0.05)

        listener = listen("tcp://127.0.0.1:0", never)
        await listener.start()
        port.append(int(listener.contact_address.rpartition(":")[2]))
        ready.set()
        while not stop.is_set():
            await asyncio.sleep(0.05)
        listener.stop()

    server = threading.Thread(target=asyncio.run, args=(serve(),), daemon=True)
    server.start()
    assert ready.wait(10)
    try:
        yield f"tcp://127.0.0.1:{port[0]}"
    finally:
        stop.set()
        server.join(5)


def test_a_dask_server_that_never_answers_the_client_is_named_so(
    tmp_path: Path, connect_timeout_1s: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """A Dask server that completes the handshake and then answers nothing (a frozen
    scheduler): was "cannot connect to the Dask scheduler at ADDR: TimeoutError"."""
    _tracks_files(tmp_path / "tracks")
    with _silent_dask_server() as address:
        argv = ["recover", str(tmp_path / "tracks"), "--out", str(tmp_path / "out")]
        start = time.monotonic()
        assert main([*argv, "--scheduler", address]) == 2
        assert time.monotonic() - start < 15
    assert capsys.readouterr().err == (
        f"pftrack recover: error: cannot connect to the Dask scheduler at {address}: it "
        "completed Dask's handshake but did not answer the client within 1 s (a frozen or "
        "overloaded scheduler, or another Dask server)\n"
    )
    assert not (tmp_path / "out").exists()


class _Quiet(http.server.SimpleHTTPRequestHandler):
    """``python -m http.server``'s handler, without its log lines on stderr."""

    def log_message(self, *args: Any) -> None:
        pass


def test_a_dashboard_a_web_server_or_a_worker_is_named_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: a web server's port (the dashboard's, 8787) waited Dask's whole connect timeout,
    then guessed ("the dashboard's port?"); a worker's port said the worker's own complaint,
    "Worker.identity() got an unexpected keyword argument 'n_workers'"."""
    from pftrack.batch import engine

    monkeypatch.setattr(engine, "GREETING_WAIT", 8.0)  # what the old code waited out
    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(out)]

    def refused(address: str) -> str:
        start = time.monotonic()
        assert main([*argv, "--scheduler", address]) == 2
        assert time.monotonic() - start < 6
        err = capsys.readouterr().err
        prefix = f"pftrack recover: error: cannot connect to the Dask scheduler at {address}: "
        assert err.startswith(prefix) and err.count("\n") == 1, err
        assert not out.exists()
        return err[len(prefix) : -1]

    handler = functools.partial(_Quiet, directory=str(tmp_path))
    with http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler) as web:
        threading.Thread(target=web.serve_forever, daemon=True).start()
        port = web.server_address[1]
        try:
            assert refused(f"tcp://127.0.0.1:{port}") == (
                f"port {port} of 127.0.0.1 is an HTTP server (it answered 'HTTP/1.0 404 File not "
                "found': a dashboard, a web server), not a Dask scheduler, which speaks Dask's "
                "own protocol: give the scheduler's address (dask scheduler prints it as "
                "'Scheduler at', port 8786 unless told otherwise)"
            )
        finally:
            web.shutdown()
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://", host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
    ) as cluster:  # fmt: skip
        scheduler = cluster.scheduler_address
        dashboard = cluster.scheduler.services["dashboard"].port
        assert refused(f"tcp://127.0.0.1:{dashboard}") == (
            f"port {dashboard} of 127.0.0.1 is the web dashboard (HTTP) of the Dask scheduler at "
            f"{scheduler}, not the scheduler itself: give {scheduler}"
        )
        (worker,) = cluster.workers.values()
        assert refused(worker.address) == (
            f"it is a Dask worker, not a scheduler (the worker's scheduler is at {scheduler}): "
            f"give {scheduler}"
        )


def _open_clients() -> set[Any]:
    """The Dask clients of this process that are not closed (those made as the default)."""
    from distributed.client import _global_clients

    return {c for c in list(_global_clients.values()) if c.status != "closed"}


def _loop_threads() -> int:
    """Threads that run a Dask event loop (a client's or a cluster's ``LoopRunner``)."""
    return sum(t.name == "IO loop" and t.is_alive() for t in threading.enumerate())


@contextlib.contextmanager
def _nothing_left_to_the_gc() -> Iterator[None]:
    """Meanwhile the garbage collector is off; after, no client left open, no loop thread more.

    A client left open is closed by the garbage collector, whenever it runs: inside the start
    of a later local cluster in the same thread, that close waited for ever on Dask's
    ``LoopRunner`` lock, held by the start (a hang of this module, seen once; py-spy:
    ``LoopRunner.start`` ... ``Client.__del__`` ... ``LoopRunner.stop``). Off, the collector
    cannot close one before it is seen here.
    """
    import gc

    before, threads = _open_clients(), _loop_threads()
    was = gc.isenabled()
    gc.disable()
    try:
        yield
        left = _open_clients() - before
        assert not left, f"left open: {[(c, c.status) for c in left]}"
        assert _loop_threads() == threads
    finally:
        if was:
            gc.enable()
        gc.collect()  # what the test left to it (a socket unclosed) is said in this test


@pytest.fixture(autouse=True)
def _no_client_left() -> Iterator[None]:
    """Every test closes the Dask clients it opens, or pftrack opens for it: none is left to
    the garbage collector (:func:`_nothing_left_to_the_gc`) for a later test to hang on."""
    before = _open_clients()
    yield
    left = _open_clients() - before
    said = f"left open by this test: {[(c, c.status) for c in left]}"
    for c in left:  # not for the next tests to hang on
        c.close()
    assert not left, said


def _interrupt_while_connecting(self: Any, *args: Any, **kwargs: Any) -> Any:
    """``Client._ensure_connected``, replaced: Ctrl-C to the main thread as the client connects."""
    import asyncio

    async def interrupted() -> None:
        signal.pthread_kill(threading.main_thread().ident or 0, signal.SIGINT)
        await asyncio.sleep(30)  # cancelled by the client's Ctrl-C

    return interrupted()


@pytest.mark.parametrize("how", ["a worker's port", "no answer", "ctrl-c"])
def test_a_connection_that_fails_leaves_no_client_behind(
    how: str, connect_timeout_1s: None, monkeypatch: pytest.MonkeyPatch, ctrl_c_raises: None
) -> None:
    """Was: Dask's ``Client(address)`` left the client it made open when the connection failed
    otherwise than by an OSError (a worker's port: a TypeError; Ctrl-C while connecting),
    connecting, with its event loop's thread running, for the garbage collector to close later
    (a hang: :func:`_nothing_left_to_the_gc`); with an OSError (no answer: a TimeoutError),
    closed but with that thread running for ever."""
    expected: type[BaseException] = OSError
    with contextlib.ExitStack() as stack:
        if how == "no answer":
            address = stack.enter_context(_silent_dask_server())
        else:
            cluster = stack.enter_context(distributed.LocalCluster(
                n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://",
                host="127.0.0.1", dashboard_address=None, scheduler_kwargs=NO_DASHBOARD,
            ))  # fmt: skip
            (worker,) = cluster.workers.values()
            address = worker.address if how == "a worker's port" else cluster.scheduler_address
        if how == "ctrl-c":
            monkeypatch.setattr(
                distributed.Client, "_ensure_connected", _interrupt_while_connecting
            )
            expected = KeyboardInterrupt
        with _nothing_left_to_the_gc(), pytest.raises(expected):
            with dask_client(scheduler=address):
                pass


def test_progress_counts_frames_within_the_sequences(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The bar was per sequence: a long sequence sat at 0/1 with no time left. It counts the
    frames of all the sequences (3 x 30 here: their lengths are known) as they are tracked."""
    from pftrack import _progress

    monkeypatch.setattr(_progress, "DELAY", 0.0)
    monkeypatch.setattr(_progress, "_quiet", False)
    seen: list[int] = []
    real_set = _progress.Bar.set
    monkeypatch.setattr(_progress.Bar, "set", lambda bar, n: (seen.append(n), real_set(bar, n)))
    options = TrackOptions(config=_config())
    track_many(data, tmp_path / "out", options=options, n_workers=0, show_progress=True)
    err = capsys.readouterr().err
    assert "3/3 sequences" in err and "90/90" in err and "frame/s" in err
    assert len(seen) >= 90 and seen == sorted(seen)  # frame by frame, within each sequence
    assert len(set(seen) - {30, 60, 90}) > 80


def test_progress_keeps_its_total_when_a_video_is_unreadable(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: one unreadable video (its length None, as an unknown one's) took the bar's total
    and time left away (``90frame [00:01, ...]``). It counts 0 frames and is named."""
    from pftrack import _progress
    from pftrack.batch.tasks import sequence_length

    monkeypatch.setattr(_progress, "DELAY", 0.0)
    monkeypatch.setattr(_progress, "_quiet", False)
    broken = tmp_path / "broken.avi"
    broken.write_bytes(b"\x00\x01 not a video \xfe\xff")
    (seq,) = find_sequences(broken)
    assert sequence_length(seq) == 0
    options = TrackOptions(config=_config())
    summary = track_many(
        [data, broken], tmp_path / "out", options=options, n_workers=0, show_progress=True
    )
    err = capsys.readouterr().err
    assert "4/4 sequences, 1 unreadable" in err and "90/90" in err and "frame/s" in err
    assert [e["status"] for e in summary.entries].count("failed") == 1


def test_tasks_on_workers_report_their_frames(client: Any, data: Path) -> None:
    """On Dask, each task sends its frame count to the client as events on a topic."""
    from pftrack.batch.engine import call_task
    from pftrack.batch.tasks import sequence_length, track_sequence

    (seq,) = [s for s in find_sequences(data) if s.name == "walk"]
    assert sequence_length(seq) == 30
    got: list[Any] = []
    topic = f"pftrack-test-{os.urandom(4).hex()}"
    client.subscribe_topic(topic, lambda event: got.append(event[1]))
    try:
        options = TrackOptions(config=_config())
        fut = client.submit(call_task, track_sequence, (seq, options), (topic, "walk"), pure=False)
        outcome = fut.result()
        assert outcome.error is None and outcome.result is not None
        deadline = time.monotonic() + 10
        while not got and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        client.unsubscribe_topic(topic)
    assert got and list(got[0]) == ["walk", 1]  # the first frame at once, then twice a second
    assert all(0 < n <= 30 for _, n in got)


def _warning_task(word: str, both: threading.Barrier, seen: dict[str, Any]) -> TaskResult:
    from pftrack.batch import tasks

    both.wait()  # the two tasks inside call_task at once
    warnings.warn(f"{word} before", UserWarning, stacklevel=1)
    seen[word] = tasks.running_task()
    both.wait()
    warnings.warn(f"{word} after", UserWarning, stacklevel=1)
    both.wait()
    return TaskResult(np.zeros((0, 10)))


def test_tasks_on_threads_of_one_worker_keep_their_own_warnings_and_reports() -> None:
    """A worker with two threads (``Client()`` in a notebook, ``dask worker --nthreads 2``)
    runs two tasks in one process: one task's warnings were given to the other (a truncated
    video's "ended after 4 frames" under another sequence's name, none under its own), and the
    frame report and stop check of the task that started last served both."""
    from pftrack.batch.engine import call_task

    both = threading.Barrier(2, timeout=20)
    outcomes: dict[str, Any] = {}
    seen: dict[str, Any] = {}

    def report_a(n: int) -> None:
        pass

    def report_b(n: int) -> None:
        pass

    reports = {"a": report_a, "b": report_b}

    def run(word: str) -> None:
        outcomes[word] = call_task(_warning_task, (word, both, seen), reports[word])

    threads = [threading.Thread(target=run, args=(word,)) for word in "ab"]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    for word in "ab":
        assert outcomes[word].error is None, outcomes[word].traceback
        assert outcomes[word].result.info["warnings"] == [f"{word} before", f"{word} after"]
        assert seen[word][0] is reports[word]


@pytest.fixture
def ctrl_c_raises() -> Iterator[None]:
    """Python's own Ctrl-C handler while the test runs, whatever the test run inherited.

    A shell without job control starts ``cmd &`` with SIGINT ignored; Python then installs no
    handler and ``_thread.interrupt_main()`` raises nothing.
    """
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_ctrl_c_cancels_the_tasks_and_leaves_a_summary(
    client: Any, tmp_path: Path, ctrl_c_raises: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The Ctrl-C comes 1 s after the tasks are submitted (was: 1 s after the call, which a
    loaded machine spent checking the workers, before --out was made: no summary, 1 run in 10).
    """
    from pftrack.batch import engine

    jobs = [Job(f"slow{k}", _slow, (k,), ()) for k in range(6)]
    timer = threading.Timer(1.0, _thread.interrupt_main)
    run_on_dask = engine._run_on_dask

    def submitted_then_ctrl_c(*args: Any, **kwargs: Any) -> None:
        timer.start()
        run_on_dask(*args, **kwargs)

    monkeypatch.setattr(engine, "_run_on_dask", submitted_then_ctrl_c)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_jobs(jobs, tmp_path, kind="smooth", settings={}, client=client)
    finally:
        timer.cancel()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert {f["status"] for f in summary["files"]} <= {"done", "cancelled"}
    assert any(f["status"] == "cancelled" for f in summary["files"])
    deadline = time.monotonic() + 10
    while client.run_on_scheduler(_n_tasks) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert client.run_on_scheduler(_n_tasks) == 0  # nothing left queued on the cluster


def _slow(k: int) -> TaskResult:
    time.sleep(1.5)
    return TaskResult(np.zeros((0, 10)), {}, {"k": k})


def _n_tasks(dask_scheduler: Any) -> int:
    return len(dask_scheduler.tasks)


#: ``python -m pftrack``, with Python's own Ctrl-C handler whatever this test run inherited (a
#: shell without job control starts ``cmd &`` with SIGINT ignored, and children inherit that).
_PFTRACK_WITH_CTRL_C = (
    "import runpy, signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "runpy.run_module('pftrack', run_name='__main__', alter_sys=True)"
)


def _group(pgid: int) -> dict[int, str]:
    """Live processes of process group `pgid` (zombies left out): pid -> command line."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:  # gone meanwhile
            continue
        fields = stat[stat.rindex(")") + 2 :].split()  # after "pid (comm) "
        if int(fields[2]) == pgid and fields[0] != "Z":
            found[int(entry.name)] = cmdline
    return found


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="lists processes in /proc")
@pytest.mark.parametrize(
    ("whom", "wait", "sig"),
    [
        ("group", 0.0, "SIGINT"),
        ("group", 0.4, "SIGINT"),
        ("parent", 0.4, "SIGINT"),
        ("group", 0.4, "SIGTERM"),
    ],
)
def test_ctrl_c_while_the_cluster_starts_is_one_line(
    data: Path, tmp_path: Path, whom: str, wait: float, sig: str
) -> None:
    """Ctrl-C while the local cluster starts: exit 130, one line on stderr, no process left.

    The signal is sent `wait` seconds after the first worker process appears, while the
    workers start Python and import Dask (a second or more): to the whole process group, as
    a terminal does (the workers are in it), or to the batch process alone. SIGTERM (``kill``,
    a service manager, which may signal the whole group) is held the same way: exit 143.
    Was: SIGTERM stopped the cluster's start where it stood, exit 143 with a traceback from
    Dask's exit hook (``AssertionError: Status.init``) and nannies that failed to start.
    """
    out = tmp_path / "out"
    argv = [sys.executable, "-c", _PFTRACK_WITH_CTRL_C, "batch", str(data), "--out", str(out),
            "--workers", "2", *FAST]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
    )
    try:
        deadline = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < deadline:
            if any("spawn_main" in cmd for cmd in _group(proc.pid).values()):
                break  # a worker process is starting
            time.sleep(0.01)
        time.sleep(wait)
        assert proc.poll() is None, proc.communicate()[1].decode()
        if whom == "group":
            os.killpg(proc.pid, getattr(signal, sig))
        else:
            proc.send_signal(getattr(signal, sig))
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    text = stderr.decode()
    status, how = (130, "interrupted") if sig == "SIGINT" else (143, "terminated (SIGTERM)")
    assert proc.returncode == status, text
    # what it left, said truthfully (was: "the outputs written so far are complete" with
    # nothing written): the signal is held while the cluster starts, so nothing is, as a rule
    assert text.splitlines() in (
        [f"pftrack batch: {how}; nothing was written: it stopped before the run began (--out "
         f"{out} untouched)"],
        [f"pftrack batch: {how}; no sequence was finished; {out / 'summary.json'} lists them as "
         "cancelled (re-run to run them)"],
    ) or text.startswith(f"pftrack batch: {how}; the outputs of the "), text  # fmt: skip
    deadline = time.monotonic() + 20  # the workers end with the cluster, closed on the way out
    while _group(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _group(proc.pid) == {}
    # nothing half-written: the folder is made once the cluster runs; every output is whole
    names = sorted(p.name for p in out.iterdir()) if out.exists() else []
    for name in names:
        assert name == "summary.json" or name.endswith((".txt", ".json")), names
        if name.endswith(".json") and name != "summary.json":
            assert name.replace(".json", ".txt") in names


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks")
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_while_the_cluster_starts_is_raised_once_it_has_started(sig: str) -> None:
    """The hold around the cluster's start: the signal's exception comes at its end, not inside.

    Was: SIGTERM (:class:`~pftrack.cli._signals.Terminated` under ``pftrack``) was raised in
    the middle of the start, leaving a half-started cluster.
    """
    from pftrack.batch.engine import _interrupts_held
    from pftrack.cli._signals import Terminated, sigterm_raises

    expected = KeyboardInterrupt if sig == "SIGINT" else Terminated
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, set())
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    reached = []
    try:
        with sigterm_raises(), pytest.raises(expected):
            with _interrupts_held():
                signal.pthread_kill(threading.get_ident(), getattr(signal, sig))  # this thread
                time.sleep(0.05)  # a signal not held would be handled by now
                reached.append(True)
    finally:
        signal.signal(signal.SIGINT, before)
    assert reached == [True]
    assert signal.pthread_sigmask(signal.SIG_BLOCK, set()) == mask  # unblocked again


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks")
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_taken_by_an_earlier_thread_is_held_too(sig: str) -> None:
    """A signal sent to the process while a thread started before the hold does not block it.

    The kernel gives it to that thread (the main thread blocks it); Python then ran the handler
    in the main thread inside the hold. Such threads are there in every ``pftrack batch``
    (OpenBLAS's, OpenCV's): measured, SIGTERM was raised in ``SpecCluster.__init__``.
    """
    from pftrack.batch.engine import _interrupts_held
    from pftrack.cli._signals import Terminated, sigterm_raises

    expected = KeyboardInterrupt if sig == "SIGINT" else Terminated
    stop = threading.Event()
    earlier = threading.Thread(target=stop.wait, daemon=True)  # blocks no signal
    earlier.start()
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    reached = []
    try:
        with sigterm_raises(), pytest.raises(expected):
            with _interrupts_held():
                os.kill(os.getpid(), getattr(signal, sig))  # to the process: `earlier` takes it
                for _ in range(50):  # Python code runs meanwhile: a handler would run now
                    time.sleep(0.001)
                reached.append(True)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
    finally:
        signal.signal(signal.SIGINT, before)
        stop.set()
        earlier.join()
    assert reached == [True]


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks")
def test_a_ctrl_c_while_the_cluster_closes_is_raised_once_it_has_closed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Was: a Ctrl-C during the close (a second one after the batch's own, or one as a finished
    batch closed) stopped it half-way; Dask's exit hook then waited up to 10 s on the cluster
    and, interrupted again, printed "Exception ignored in atexit callback: close_clusters"."""
    from distributed.deploy.spec import SpecCluster

    closing = []
    real_close = SpecCluster.close

    def close_with_ctrl_c(self: Any, *args: Any, **kwargs: Any) -> Any:
        if not closing:
            closing.append(self)
            signal.pthread_kill(threading.get_ident(), signal.SIGINT)  # Ctrl-C, now
            time.sleep(0.05)  # a signal not held would be raised here
        return real_close(self, *args, **kwargs)

    monkeypatch.setattr(SpecCluster, "close", close_with_ctrl_c)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    left = []
    try:
        with pytest.raises(KeyboardInterrupt), dask_client(n_workers=1):
            pass
    finally:
        signal.signal(signal.SIGINT, before)
        left = [c.status.name for c in closing]  # what Dask's exit hook would find
        for cluster in closing:
            if cluster.status.name != "closed":
                real_close(cluster)
    assert left == ["closed"]


def test_cli_interrupt_exits_130(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def interrupted(*args: Any, **kwargs: Any) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr("pftrack.batch.track_many", interrupted)
    assert main(["batch", str(data), "--out", str(tmp_path / "o")]) == 130
    # stopped before the batch ran (was: "the outputs written so far are complete")
    assert capsys.readouterr().err == (
        "pftrack batch: interrupted; nothing was written: it stopped before the run began\n"
    )


def test_bad_usage_exits_2_before_any_work(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    afile = tmp_path / "file"
    afile.write_text("")
    assert main(["batch", str(data), "--out", str(afile)]) == 2
    assert "is a file; give a folder" in capsys.readouterr().err
    assert main(["batch", str(tmp_path / "missing"), "--out", str(tmp_path / "o")]) == 2
    assert "input not found" in capsys.readouterr().err
    # outputs may not overwrite an input: a tracks folder recovered into itself
    tracks = tmp_path / "tracks"
    tracks.mkdir()
    write_mot(tracks / "a.txt", np.array([[1, 1, 0, 0, 5, 5, 1, -1, -1, -1]], float))
    write_mot(tracks / "b.txt", np.array([[1, 1, 0, 0, 5, 5, 1, -1, -1, -1]], float))
    assert main(["recover", str(tracks), "--out", str(tracks), "--workers", "0"]) == 2
    assert "is an input of this run" in capsys.readouterr().err
    assert main(["recover", str(tracks), "--out", str(tmp_path / "o"), "--video", "v.avi"]) == 2
    assert "--video takes one tracks file" in capsys.readouterr().err
    # a rendered video over an input video is --render's doing (was: named as --out)
    mp4s = tmp_path / "mp4s"
    mp4s.mkdir()
    shutil.copy2(data / "walk.avi", mp4s / "port.mp4")
    assert main(["batch", str(mp4s), "--out", str(mp4s), "--render", "--workers", "0"]) == 2
    assert f"error: --render's output {mp4s / 'port.mp4'} is an input of this run" in (
        capsys.readouterr().err
    )


def _tracks_files(folder: Path) -> list[Path]:
    """Three tracks files with holes, as any tracker would write them (all digits kept)."""
    folder.mkdir()
    paths = []
    for k in range(3):
        truth = make_scene(n_frames=40, width=160, height=120, n_walkers=3, rng=k).truth
        keep = np.random.default_rng(k).random(len(truth)) > 0.25  # drop a quarter of the boxes
        rows = truth[keep]
        rows[:, 2:7] += np.random.default_rng(k).uniform(0, 0.1, (len(rows), 5))  # long decimals
        paths.append(folder / f"run{k}.txt")
        np.savetxt(paths[-1], rows, fmt="%.17g", delimiter=",")
    return paths


def test_rows_that_cannot_be_written_fail_their_task_not_the_batch(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Smoothing moves a box at the bound (left -1e9) past it: that file fails, the others run.

    Were: the one-file command wrote a file ``read_mot`` refuses (``pftrack recover`` of it:
    "a box value is beyond ±1e+09 px"); once ``write_mot`` refused such rows, a batch stopped
    at the client's write, its remaining tasks cancelled.
    """
    f = np.arange(1.0, 21.0)
    w = np.where(f % 2 == 0, 10.0, 1000.0)  # the smoothed centre and width put left past -1e9
    edge = np.column_stack([f, np.ones(20), np.full(20, -1e9), np.zeros(20), w,
                            np.full(20, 100.0), np.ones(20), -np.ones((20, 3))])  # fmt: skip
    folder = tmp_path / "tracks"
    folder.mkdir()
    write_mot(folder / "edge.txt", edge)  # readable: every box is within the bound
    fine = edge.copy()
    fine[:, 2] = 100.0
    write_mot(folder / "fine.txt", fine)
    message = "write_mot: row 2 (frame 3, id 1) has left -1e+09: a box value is beyond ±1e+09 px"
    single = tmp_path / "single.txt"
    single.write_text("1,1,10,10,5,5,1,-1,-1,-1\n")  # an earlier run's (pftrack replaces no other)
    assert main(["smooth", str(folder / "edge.txt"), "--out", str(single)]) == 2
    assert capsys.readouterr().err == f"pftrack smooth: error: {message}\n"
    assert single.read_text() == "1,1,10,10,5,5,1,-1,-1,-1\n"
    out = tmp_path / "out"
    assert main(["smooth", str(folder), "--out", str(out), "--workers", "0"]) == 1  # some failed
    assert capsys.readouterr().err == f"edge: error: {message}\n"
    summary = json.loads((out / "summary.json").read_text())
    assert {e["name"]: e["status"] for e in summary["files"]} == {"edge": "failed", "fine": "done"}
    assert sorted(p.name for p in out.iterdir()) == ["fine.json", "fine.txt", "summary.json"]
    read_mot(out / "fine.txt")


@pytest.mark.parametrize(
    ("command", "extra"),
    [("recover", ["--method", "auto", "--link"]), ("smooth", []), ("smooth", ["--no-link"])],
)
def test_recover_and_smooth_many_files_equal_one_by_one(
    client: Any, tmp_path: Path, command: str, extra: list[str]
) -> None:
    paths = _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = [command, str(tmp_path / "tracks"), "--out", str(out), *extra]
    assert main([*argv, "--scheduler", client.scheduler.address]) == 0
    for path in paths:
        single = tmp_path / f"{path.stem}.single"
        assert main([command, str(path), "--out", str(single), *extra]) == 0
        assert single.read_bytes() == (out / path.name).read_bytes(), path.name
    summary = json.loads((out / "summary.json").read_text())
    assert summary["kind"] == command and [f["status"] for f in summary["files"]] == ["done"] * 3
    # several files name the same outputs as the folder did; all complete now
    assert main([command, *map(str, paths), "--out", str(out), *extra, "--workers", "0"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert [f["status"] for f in summary["files"]] == ["skipped"] * 3


_UNGUARDED_SCRIPT = """
import os, sys
with open(sys.argv[3], "a") as log:  # one line each time this top level runs
    log.write(f"{os.getpid()}\\n")
from dataclasses import replace
from pftrack.batch import TrackOptions, track_many
from pftrack.tracking import TrackerConfig
base = TrackerConfig()
options = TrackOptions(config=replace(base, filter=replace(base.filter, n_particles=30)))
summary = track_many([sys.argv[1]], sys.argv[2], n_workers=1, options=options)
print(len(summary.entries), len(summary.failed), __file__ == os.path.abspath(sys.argv[0]))
"""


def test_a_script_without_a_main_guard_runs_once(data: Path, tmp_path: Path) -> None:
    """``track_many`` at a script's top level, no ``if __name__ == "__main__":``: it runs.

    The local cluster's workers no longer import the script (:func:`_main_left_out`). Was:
    every worker ran the script again, whose call started a cluster inside a worker still
    starting: exit 1 and about 500 lines of Dask's tracebacks. One worker and one sequence
    (were two and three, 78 s of CI's busy cores, most of it starting workers): without
    :func:`_main_left_out` this still exits 1, its one worker having run the script again.
    """
    script, log = tmp_path / "batch_script.py", tmp_path / "ran.txt"
    script.write_text(_UNGUARDED_SCRIPT)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    out = subprocess.run(
        [sys.executable, str(script), str(data / "plain"), str(tmp_path / "out"), str(log)],
        env=env, capture_output=True, text=True, timeout=300, cwd=tmp_path,
    )  # fmt: skip
    assert (out.returncode, out.stderr) == (0, "")
    assert out.stdout.split() == ["1", "0", "True"]  # __file__ is put back afterwards
    assert len(log.read_text().split()) == 1
    assert [p.name for p in (tmp_path / "out").glob("*.txt")] == ["plain.txt"]


_CRASHING_SCRIPT = """
import os, sys
with open(sys.argv[2], "a") as log:  # one line each time this top level runs
    log.write(f"{os.getpid()}\\n")
import cv2
import numpy as np
from pftrack.batch import Job, TaskResult, run_jobs
def crash_once(k, marker):
    if k == 0 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(3)  # the worker dies: its nanny starts another
    return TaskResult(np.zeros((0, 10)), {}, {"k": k})
jobs = [Job(f"j{k}", crash_once, (k, sys.argv[3]), ()) for k in range(3)]
summary = run_jobs(jobs, sys.argv[1], kind="smooth", settings={}, n_workers=1)
print(*[e["status"] for e in summary.entries])
"""


@pytest.mark.slow
def test_a_script_without_a_main_guard_survives_a_worker_restart(tmp_path: Path) -> None:
    """A worker of the local cluster that dies (a crash, the kernel's OOM killer) is started
    again by its nanny, which imported the unguarded script, ran its batch inside the new
    worker and never had it join: the tasks left failed after the 60 s wait, with "start
    some: dask worker ..." for a cluster the batch had started itself."""
    script, log = tmp_path / "crash_script.py", tmp_path / "ran.txt"
    script.write_text(_CRASHING_SCRIPT)
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(sys.path),
        "DASK_DISTRIBUTED__SCHEDULER__NO_WORKERS_TIMEOUT": "10s",
    }
    start = time.monotonic()
    out = subprocess.run(
        [sys.executable, str(script), str(tmp_path / "out"), str(log), str(tmp_path / "m")],
        env=env, capture_output=True, text=True, timeout=300, cwd=tmp_path,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["done", "done", "done"], out.stdout
    assert len(log.read_text().split()) == 1
    assert time.monotonic() - start < 60


def test_help_imports_no_dask() -> None:
    code = (
        "import sys\nfrom pftrack.cli import main\n"
        "for cmd in ([], ['batch'], ['recover'], ['smooth']):\n"
        "    try:\n        main([*cmd, '--help'])\n    except SystemExit:\n        pass\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip().splitlines()[-1] == "[]"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.mark.slow
def test_scheduler_and_worker_started_as_processes(data: Path, tmp_path: Path) -> None:
    dask = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command is not installed")
    address = f"tcp://127.0.0.1:{_free_port()}"
    port = address.rsplit(":", 1)[1]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    logs = tmp_path / "logs.txt"
    with logs.open("w") as log:
        procs = [
            subprocess.Popen(
                [dask, "scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard"],
                stdout=log,
                stderr=log,
                env=env,
                cwd=tmp_path,
            ),  # fmt: skip
        ]
        try:
            procs.append(
                subprocess.Popen(
                    [
                        dask,
                        "worker",
                        address,
                        "--nworkers",
                        "1",
                        "--nthreads",
                        "1",
                        "--no-dashboard",
                        "--host",
                        "127.0.0.1",
                    ],
                    stdout=log,
                    stderr=log,
                    env=env,
                    cwd=tmp_path,
                )  # fmt: skip
            )
            with distributed.Client(address, timeout="30s") as c:
                c.wait_for_workers(1, timeout=30)
            out = tmp_path / "out"
            assert main(["batch", str(data), "--out", str(out), "--scheduler", address, *FAST]) == 0
            serial = tmp_path / "serial"
            assert main(["batch", str(data), "--out", str(serial), "--workers", "0", *FAST]) == 0
            assert _files(out) == _files(serial) and len(_files(out)) == 3
            summary = json.loads((out / "summary.json").read_text())
            assert summary["scheduler"] == address and summary["workers"] == 1
        finally:
            _stop_processes(procs)


def _stop_processes(procs: list[subprocess.Popen[Any]]) -> None:
    """Terminate `procs` (the workers before their scheduler) and wait; kill after 15 s."""
    for p in reversed(procs):
        p.terminate()
    for p in reversed(procs):
        try:
            p.wait(timeout=15)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def test_render_writes_a_video_per_sequence_and_counts_for_resume(
    data: Path, client: Any, tmp_path: Path
) -> None:

    options = TrackOptions(config=_config(), render=".mp4")
    first = track_many(data / "plain", tmp_path, client, options=options)
    assert first.entries[0]["outputs"] == ["plain.txt", "plain.mp4"]
    video = FrameSource(tmp_path / "plain.mp4")
    assert (video.width, video.height, len(list(video))) == (192, 144, 30)
    # pftrack render of NAME.txt draws the same frames (a user trial: the batch drew the
    # unrounded rows, boxes a pixel off)
    rendered = tmp_path / "again.mp4"
    argv = ["render", str(data / "plain"), str(tmp_path / "plain.txt"), "--out", str(rendered)]
    assert main(argv) == 0
    for a, b in zip(FrameSource(tmp_path / "plain.mp4"), FrameSource(rendered), strict=True):
        np.testing.assert_array_equal(a, b)
    rendered.unlink()
    (tmp_path / "plain.mp4").unlink()  # a listed output missing: not complete
    again = track_many(data / "plain", tmp_path, client, options=options)
    assert again.entries[0]["status"] == "done" and (tmp_path / "plain.mp4").is_file()
    assert track_many(data / "plain", tmp_path, client, options=options).entries[0]["status"] == (
        "skipped"
    )


def test_render_reads_the_source_tracked_and_says_its_warnings_once(tmp_path: Path) -> None:
    """A video shorter than its header says, tracked and rendered: one warning (was two, the
    render pass's own FrameSource saying in other words what the tracking pass had said: "its
    header says 60 frames but it holds 30 (counted)", then "ended after 30 frames")."""
    cut = tmp_path / "in" / "cut.avi"
    whole = make_scene(n_frames=60, width=160, height=120, n_walkers=2, rng=1).write_video(
        tmp_path / "whole.avi"
    )
    cut.parent.mkdir()
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])  # its header: 60 frames
    options = TrackOptions(config=_config(), render=".mp4")
    (entry,) = track_many(cut.parent, tmp_path / "out", options=options, n_workers=0).entries
    assert entry["status"] == "done"
    (said,) = [w for w in entry["warnings"] if str(cut) in w]
    assert f"{cut}: its header says 60 frames but it holds {entry['frames']} (counted)" in said
    assert len(FrameSource(tmp_path / "out" / "cut.mp4")) == entry["frames"]


def test_render_into_the_input_folder_can_be_re_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--out`` the input folder with ``--render``: the second run took walk.mp4, the first
    run's video, for an input named like walk.avi, and refused to run (exit 2).

    A 10-frame video (was: the 30 frames of ``data``'s walk.avi; 14 runs, 10 of them tracked,
    took 47 s of CI's busy cores): the runs are about names and sidecars, not tracking."""
    vids = tmp_path / "vids"
    vids.mkdir()
    make_scene(n_frames=10, width=192, height=144, n_walkers=3, rng=0).write_video(
        vids / "walk.avi"
    )
    seq = tmp_path / "seq"  # the shared data's layout: seqinfo.ini and one video
    seq.mkdir()
    shutil.copy2(vids / "walk.avi", seq / "video.avi")
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=192\nimHeight=144\n")
    for folder, name in ((vids, "walk"), (seq, "seq")):
        argv = ["batch", str(folder), "--out", str(folder), "--render", "--workers", "0", *FAST]
        assert main(argv) == 0
        assert (folder / f"{name}.mp4").is_file()
        assert main(argv) == 0, capsys.readouterr().err
        summary = json.loads((folder / "summary.json").read_text())
        assert [(e["name"], e["status"]) for e in summary["sequences"]] == [(name, "skipped")]
        # and without --render: the rendered video is still not an input
        assert main(["batch", str(folder), "--out", str(tmp_path / "o"), "--workers", "0",
                     *FAST]) == 0  # fmt: skip
        # re-run into the folder itself without --render (other settings: redone), then
        # again, with and without --render: was "two inputs are both named ..." (exit 2), the
        # new sidecar no longer naming the first run's video
        plain = [a for a in argv if a != "--render"]
        for again in (plain, plain, argv, plain):
            assert main(again) == 0, capsys.readouterr().err
    # a video of the same name that no sidecar beside it lists is an input: refused, as before
    (vids / "walk.json").unlink()
    with pytest.raises(ValueError, match="both named 'walk'"):
        find_sequences(vids)
    # given by its own path, a rendered video is an input
    assert [s.frames for s in find_sequences(seq / "seq.mp4")] == [seq / "seq.mp4"]


def test_scheduler_address_from_the_environment(
    data: Path, client: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", client.scheduler.address)
    assert main(["batch", str(data / "plain"), "--out", str(tmp_path), *FAST]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    # one sequence: one of the two workers ran it (the workers that ran tasks are counted)
    assert summary["scheduler"] == client.scheduler.address and summary["workers"] == 1
    # the address as the user gave it, not as Dask reports it (tcp://127.0.0.1:PORT)
    given = client.scheduler.address.replace("127.0.0.1", "localhost")
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", given)
    assert main(["batch", str(data / "plain"), "--out", str(tmp_path), "--force", *FAST]) == 0
    assert json.loads((tmp_path / "summary.json").read_text())["scheduler"] == given


@pytest.mark.dataset
@pytest.mark.slow
def test_pets_detections_and_truth_are_scaled_from_seqinfo(client: Any, tmp_path: Path) -> None:
    pets = dataset("pets09-s2l1")  # video.avi 480x360; det.txt, gt.txt 768x576 (seqinfo.ini)
    summary = track_many(pets, tmp_path, client, options=TrackOptions(detections="auto"))
    (entry,) = summary.entries
    assert entry["status"] == "done" and entry["det_scale"] == entry["gt_scale"] == 0.625
    single = tmp_path / "single.txt"
    argv = ["track", str(pets / "video.avi"), "--detections", str(pets / "det.txt")]
    assert main([*argv, "--det-scale", "0.625", "--out", str(single)]) == 0
    assert single.read_bytes() == (tmp_path / "pets09-s2l1.txt").read_bytes()
    s = evaluate_sequence(read_mot(pets / "gt.txt"), read_mot(single), scale=0.625)
    assert entry["metrics"]["mota"] == s.mot.mota and entry["metrics"]["idf1"] == s.mot.idf1
    assert entry["metrics"]["hota"] == s.hota.hota and entry["metrics"]["benchmark"] == "MOT15"


@pytest.mark.dataset
@pytest.mark.slow
def test_the_figures_docs_batch_md_quotes_are_the_batchs(client: Any, tmp_path: Path) -> None:
    """docs/batch.md's table and PETS09 sentence quoted figures two tracker changes old."""
    root = dataset("pets09-s2l1").parent
    dataset("tud-campus")
    doc = (Path(__file__).resolve().parents[1] / "docs" / "batch.md").read_text()
    # the data folder's mot15-gt/ holds annotations alone: passed over, said in one warning
    said = pytest.warns(UserWarning, match="passed over .*mot15-gt")
    with said if (root / "mot15-gt").is_dir() else contextlib.nullcontext():
        summary = track_many(root, tmp_path, client, options=TrackOptions(detections="auto"))
    rows = {line.split()[0]: line.split() for line in summary.table().splitlines()}
    for name in ("pets09-s2l1", "tud-campus"):
        (quoted,) = [line.split() for line in doc.splitlines() if line.startswith(f"{name}  ")]
        got = rows[name]
        assert quoted[:4] + quoted[5:] == got[:4] + got[5:], name  # frames/s aside
    pets = next(e for e in summary.entries if e["name"] == "pets09-s2l1")["metrics"]
    figures = (
        f"HOTA {100 * pets['hota']:.1f}, MOTA {100 * pets['mota']:.1f}, "
        f"IDF1 {100 * pets['idf1']:.1f}, {pets['num_switches']} switches"
    )
    assert figures in " ".join(doc.split())


def test_a_sequences_warnings_come_back_to_the_summary(
    client: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # three frames of one small walker: no track is confirmed, and the tracker warns so
    scene = make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0)
    scene.write_images(tmp_path / "in" / "short")
    out = tmp_path / "out"
    assert main(["batch", str(tmp_path / "in"), "--out", str(out),
                 "--scheduler", client.scheduler.address, *FAST]) == 0  # fmt: skip
    (entry,) = json.loads((out / "summary.json").read_text())["sequences"]
    assert entry["status"] == "done"
    assert len(entry["warnings"]) == 1 and entry["warnings"][0].startswith("no track over 3")
    printed = capsys.readouterr()
    assert printed.err == f"short: warning: {entry['warnings'][0]}\n"  # not on stdout's table
    assert ": warning:" not in printed.out and printed.out.startswith("name ")
    # in this process too, whatever the warning filters say (pytest makes them errors here)
    serial = track_many(tmp_path / "in", tmp_path / "serial", n_workers=0)
    assert serial.entries[0]["warnings"] == entry["warnings"]


# --- where a batch runs: the address, the client, a cluster without workers ----------------


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--scheduler", "tcp://127.0.0.1:8786x"], "--scheduler 'tcp://127.0.0.1:8786x': port "
         "'8786x' is not a number (expected tcp://HOST:PORT, PORT in 1..65535)"),
        (["--scheduler", "tcp://127.0.0.1:99999"], "--scheduler 'tcp://127.0.0.1:99999': port "
         "99999 is out of range"),
        (["--scheduler", "http://127.0.0.1:8786"], "unknown protocol http://"),
        (["--scheduler", "tcp://127.0.0.1"], "--scheduler 'tcp://127.0.0.1': no port"),
        (["--scheduler", "tcp://:8786"], "no host"),
        (["--scheduler", "::1:8786"], "an IPv6 address goes in brackets"),
        (["--scheduler", ""], "--scheduler is empty: give a running Dask scheduler's address"),
        (["--scheduler", "inproc://x"], "--scheduler 'inproc://x': inproc:// names a scheduler "
         "inside one process, which a batch cannot reach by address; give a running "
         "scheduler's tcp://HOST:PORT"),
        (["--scheduler", "tcp://127.0.0.1:8786", "--workers", "0"],
         "--scheduler and --workers contradict each other"),
        (["--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"],
         "--scheduler and --workers contradict each other"),
    ],
)  # fmt: skip
def test_scheduler_address_is_checked_before_anything(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    """Was: Dask's "invalid literal for int()", the connect timeout waited out for port 99999,
    an empty address or one given with --workers silently ignored (a local cluster, or this
    process), and no check at all when every output was complete already."""
    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out)]
    start = time.monotonic()
    assert main([*argv, *extra]) == 2
    assert time.monotonic() - start < 5  # no connect timeout waited out
    err = capsys.readouterr().err
    assert err.startswith("pftrack smooth: error: ") and err.count("\n") == 1
    assert message in err and "--scheduler" in err
    assert not out.exists()
    # every output complete: checked all the same
    assert main([*argv, "--workers", "0"]) == 0
    capsys.readouterr()
    assert main([*argv, *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


@pytest.mark.parametrize(
    ("protocol", "hint"),
    [
        ("tls", "(tls:// needs Dask's TLS settings where pftrack runs: the CA file, and the "
         "client's certificate and key: $DASK_DISTRIBUTED__COMM__TLS__CA_FILE, "),
        ("wss", "(wss:// needs Dask's TLS settings where pftrack runs"),
        ("ucx", ""),  # what Dask says of it depends on its version (2026.8: an abstract class)
    ],
)  # fmt: skip
def test_an_address_dask_cannot_connect_by_is_one_line_naming_it(
    tmp_path: Path, connect_timeout_1s: None, capsys: pytest.CaptureFixture[str],
    protocol: str, hint: str,
) -> None:  # fmt: skip
    """Were Dask's own words, neither --scheduler nor the address named: "TLS expects a
    `ssl_context` argument ...", "Can't instantiate abstract class UCXConnector ..."."""
    import dask

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    address = f"{protocol}://127.0.0.1:{_free_port()}"
    with dask.config.set({"distributed.comm.tls.ca-file": None}):  # none where this runs
        assert main(["smooth", str(tmp_path / "tracks"), "--out", str(out),
                     "--scheduler", address]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith(
        f"pftrack smooth: error: cannot connect to the Dask scheduler at {address}: "
    )
    assert hint in err
    assert not out.exists()


@pytest.mark.slow
def test_tls_runs_with_dasks_tls_settings(tmp_path: Path) -> None:
    """What docs/batch.md says a tls:// scheduler needs: Dask's CA file, client cert and key.

    Slow (deselected by default): after this file's other cluster tests in one process, the
    TLS cluster's IO loop did not start within Dask's 10 s twice on the 2-core machine; alone,
    or among the slow tests, it passes.
    """
    import dask
    from distributed.security import Security

    from pftrack.batch.engine import NO_MALLOC_TRIM

    openssl = shutil.which("openssl")
    if openssl is None:
        pytest.skip("no openssl to make a certificate")
    crt, key = str(tmp_path / "tls.crt"), str(tmp_path / "tls.key")
    subprocess.run([openssl, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", key,
                    "-out", crt, "-days", "1", "-subj", "/CN=localhost", "-addext",
                    "subjectAltName=IP:127.0.0.1"], check=True, capture_output=True)  # fmt: skip
    security = Security(
        tls_ca_file=crt, tls_scheduler_cert=crt, tls_scheduler_key=key, tls_worker_cert=crt,
        tls_worker_key=key, tls_client_cert=crt, tls_client_key=key, require_encryption=True,
    )  # fmt: skip
    paths = _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    # not Dask's MALLOC_TRIM_THRESHOLD_, which its nanny would leave in this process's
    # environment for later clusters' workers (see test_workers_are_single_threaded)
    with dask.config.set({NO_MALLOC_TRIM: None}), distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", protocol="tls://",
        security=security, dashboard_address=None, scheduler_kwargs=NO_DASHBOARD,
    ) as cluster:  # fmt: skip
        address = cluster.scheduler_address
        assert address.startswith("tls://")
        settings = {"distributed.comm.tls.ca-file": crt, "distributed.comm.tls.client.cert": crt,
                    "distributed.comm.tls.client.key": key}  # fmt: skip
        with dask.config.set(settings):
            assert main(["smooth", str(tmp_path / "tracks"), "--out", str(out),
                         "--scheduler", address]) == 0  # fmt: skip
    assert sorted(p.name for p in out.glob("*.txt")) == [p.name for p in paths]


def test_scheduler_address_from_the_environment_is_checked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import dask

    _tracks_files(tmp_path / "tracks")
    argv = ["smooth", str(tmp_path / "tracks"), "--out", str(tmp_path / "out")]
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "tcp://127.0.0.1:8786x")
    assert main(argv) == 2
    assert "error: $DASK_SCHEDULER_ADDRESS 'tcp://127.0.0.1:8786x': port '8786x'" in (
        capsys.readouterr().err
    )
    # an explicit --workers runs here (the environment's address is a default, not an order)
    assert main([*argv, "--workers", "0"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["workers"] == 0 and summary["scheduler"] is None
    # in Python: Dask's scheduler-address setting is checked too, and named
    with (
        dask.config.set({"scheduler-address": "tcp://127.0.0.1:0"}),
        pytest.raises(
            ValueError, match=r"^\$DASK_SCHEDULER_ADDRESS \(Dask's scheduler-address\) 'tcp://"
        ),
    ):
        smooth_many(tmp_path / "tracks", tmp_path / "o2")


def test_the_entry_points_refuse_another_options_class_before_any_task(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Were: recover_many(options=TrackOptions()) failed every file with an AttributeError,
    smooth_many(options=RecoverOptions(...)) ran with its settings (link=False) and recorded
    them, track_many(options="seed=1") raised an AttributeError."""
    import pftrack.batch.api as api

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    monkeypatch.setattr(api, "run_jobs", None)  # nothing may get as far as running
    cases = [
        (lambda: recover_many(tmp_path / "tracks", out, options=TrackOptions(), n_workers=0),
         "recover_many: options must be a RecoverOptions or None, got TrackOptions "
         "(TrackOptions is track_many's)"),
        (lambda: smooth_many(tmp_path / "tracks", out,
                             options=RecoverOptions(method="linear"), n_workers=0),
         "smooth_many: options must be a SmoothOptions or None, got RecoverOptions "
         "(RecoverOptions is recover_many's)"),
        (lambda: track_many(data / "walk.avi", out, options="seed=1", n_workers=0),  # type: ignore[arg-type]
         "track_many: options must be a TrackOptions or None, got str 'seed=1'"),
        (lambda: track_many(tmp_path / "nowhere", out, options=SmoothOptions()),  # type: ignore[arg-type]
         "track_many: options must be a TrackOptions or None, got SmoothOptions "
         "(SmoothOptions is smooth_many's)"),
    ]  # fmt: skip
    for call, message in cases:
        with pytest.raises(TypeError) as caught:
            call()
        assert str(caught.value) == message
    assert not out.exists()


def test_python_names_out_dir_and_the_command_out(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """track_many("a.avi", "b.avi") said "--out b.avi is a file": a CLI option, in Python."""
    video = tmp_path / "b.avi"
    shutil.copy2(data / "walk.avi", video)
    with pytest.raises(ValueError, match=rf"^out_dir {re.escape(str(video))} is a file; give a"):
        track_many(data / "walk.avi", video, n_workers=0)
    assert main(["batch", str(data / "walk.avi"), "--out", str(video), "--workers", "0"]) == 2
    assert capsys.readouterr().err == (
        f"pftrack batch: error: --out {video} is a file; give a folder\n"
    )
    (tmp_path / "o" / "walk.txt").mkdir(parents=True)
    with pytest.raises(ValueError, match=r"^out_dir .*walk.txt is a folder; it would be an output"):
        track_many(data / "walk.avi", tmp_path / "o", n_workers=0)
    assert main(["batch", str(data / "walk.avi"), "--out", str(tmp_path / "o"),
                 "--workers", "0"]) == 2  # fmt: skip
    assert capsys.readouterr().err.startswith(
        f"pftrack batch: error: --out {tmp_path / 'o' / 'walk.txt'} is a folder;"
    )
    with pytest.raises(ValueError, match=r"^options.render's output .*b.avi is an input of this"):
        track_many(video, tmp_path, options=TrackOptions(render=".avi"), n_workers=0)


def test_where_to_run_is_refused_when_contradictory_or_not_a_client(
    data: Path, tmp_path: Path, client: Any
) -> None:
    """``client="tcp://..."`` failed in Dask: "'str' object has no attribute 'register_plugin'"."""
    address = client.scheduler.address
    with pytest.raises(TypeError, match=(
        r"^client must be a distributed.Client or None, got str: to connect to a running "
        rf"scheduler by its address, pass scheduler='{address}'"
    )):  # fmt: skip
        track_many(data / "plain", tmp_path / "o", client=address)
    with pytest.raises(TypeError, match="client must be a distributed.Client or None, got int$"):
        track_many(data / "plain", tmp_path / "o", client=3)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="client must be a distributed.Client"):
        with dask_client(address):  # type: ignore[arg-type]
            pass
    for kwargs, named in (
        ({"client": client, "n_workers": 0}, "client and n_workers are both given"),
        ({"client": client, "scheduler": address}, "client and scheduler are both given"),
        ({"scheduler": address, "n_workers": 2}, "scheduler and n_workers are both given"),
    ):
        with pytest.raises(ValueError, match=named):
            track_many(data / "plain", tmp_path / "o", **kwargs)
    with pytest.raises(ValueError, match=r"^scheduler is empty"):
        track_many(data / "plain", tmp_path / "o", scheduler=" ")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"n_workers": 2.5}, "n_workers must be an integer >= 0 or None, got float 2.5"),
        ({"n_workers": True}, "n_workers must be an integer >= 0 or None, got bool True"),
        ({"n_workers": "2"}, "n_workers must be an integer >= 0 or None, got str '2'"),
        ({"force": "no", "n_workers": 0}, "force must be True or False, got str 'no'"),
        ({"show_progress": "no", "n_workers": 0},
         "show_progress must be True, False or None, got str 'no'"),
        ({"inputs": None, "n_workers": 0},
         "inputs must be a path or a list of paths, got NoneType None"),
        ({"inputs": 3, "n_workers": 0},
         "inputs must be a path or a list of paths, got int 3"),
        ({"inputs": ["IN", 3], "n_workers": 0},
         "inputs[1] must be a path (str or os.PathLike), got int 3"),
        ({"out_dir": None, "n_workers": 0},
         "out_dir must be a path (str or os.PathLike), got NoneType None"),
    ],
)  # fmt: skip
def test_python_arguments_of_another_type_are_refused_by_name(
    kwargs: dict[str, Any], message: str, data: Path, tmp_path: Path
) -> None:
    """A user trial: ``force="no"`` forced (a truthy string: files no batch wrote replaced),
    ``n_workers=2.5`` and ``n_workers=True`` ran, and ``inputs=None``, ``n_workers="2"`` or
    ``out_dir=None`` failed with Python's words ("'NoneType' object is not iterable", "'<' not
    supported between instances of 'str' and 'int'"), naming no parameter."""
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "walk.txt").write_text("mine\n")  # a file no batch wrote
    args = {"inputs": [data / "walk.avi"], "out_dir": tmp_path / "o", **kwargs}
    if isinstance(args["inputs"], list):
        args["inputs"] = [data / "walk.avi" if p == "IN" else p for p in args["inputs"]]
    with pytest.raises(TypeError) as caught:
        track_many(args.pop("inputs"), args.pop("out_dir"), **args)
    assert str(caught.value) == message
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["walk.txt"]
    assert (tmp_path / "o" / "walk.txt").read_text() == "mine\n"


def test_a_closed_client_is_refused_before_anything(data: Path, tmp_path: Path) -> None:
    """A user trial: a client closed before the call failed deep in Dask with
    "AttributeError: 'NoneType' object has no attribute 'run_function'"."""
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://", host="127.0.0.1",
        dashboard_address=None, scheduler_kwargs=NO_DASHBOARD,
    ) as cluster:  # fmt: skip
        closed = distributed.Client(cluster)
        closed.close()
        with pytest.raises(ValueError, match=(
            r"^client is not connected \(its status is 'closed'\): pass a connected "
            r"distributed.Client, or the scheduler's address as scheduler=$"
        )):  # fmt: skip
            track_many(data / "plain", tmp_path / "o", closed)
    assert not (tmp_path / "o").exists()


@pytest.fixture
def no_workers_timeout_1s() -> Iterator[None]:
    """Dask's ``distributed.scheduler.no-workers-timeout``, the batch's wait for a worker: 1 s."""
    import dask

    with dask.config.set({"distributed.scheduler.no-workers-timeout": "1s"}):
        yield


@pytest.mark.filterwarnings("always:the scheduler at")
def test_a_scheduler_without_workers_is_said_at_once_then_an_error(
    tmp_path: Path, no_workers_timeout_1s: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """``dask scheduler`` alone: the batch waited forever, saying nothing."""
    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    with distributed.LocalCluster(
        n_workers=0, host="127.0.0.1", dashboard_address=None, processes=True,
        scheduler_kwargs=NO_DASHBOARD,
    ) as bare:  # fmt: skip
        address = bare.scheduler_address
        start = time.monotonic()
        assert main(["smooth", str(tmp_path / "tracks"), "--out", str(out),
                     "--scheduler", address]) == 2  # fmt: skip
        assert time.monotonic() - start < 10
    assert capsys.readouterr().err.splitlines() == [
        f"pftrack smooth: warning: the scheduler at {address} has no workers; waiting up to "
        f"1 s for one (start one: dask worker {address})",
        f"pftrack smooth: error: the scheduler at {address} has no workers: none came within "
        f"1 s (start them with: dask worker {address}; the wait is Dask's "
        "distributed.scheduler.no-workers-timeout, "
        "$DASK_DISTRIBUTED__SCHEDULER__NO_WORKERS_TIMEOUT)",
    ]
    assert not out.exists()  # nothing written, as for a scheduler that cannot be reached


#: A Dask preload script: the process it runs in cannot import pftrack, as on a machine where
#: it is not installed (``dask scheduler --preload``, a worker's ``preload``).
HIDE_PFTRACK = """import sys
for name in [n for n in sys.modules if n == "pftrack" or n.startswith("pftrack.")]:
    sys.modules[name] = None
sys.modules["pftrack"] = None
"""


@pytest.mark.parametrize(
    ("key", "variable", "example"),
    [
        ("distributed.comm.timeouts.connect", "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT", "30s"),
        ("distributed.scheduler.no-workers-timeout",
         "DASK_DISTRIBUTED__SCHEDULER__NO_WORKERS_TIMEOUT", "60s"),
    ],
)  # fmt: skip
@pytest.mark.parametrize("where", ["local", "scheduler"])
def test_a_dask_wait_that_is_no_duration_is_one_line(
    key: str,
    variable: str,
    example: str,
    where: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A user trial: ``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT=abc`` (a setting the help
    names) gave Dask's traceback ("KeyError: 'Invalid time unit: abc ...'"), with a local
    cluster ("Cluster failed to start") or a scheduler; so did the no-workers wait locally."""
    import dask

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(out)]
    if where == "scheduler":  # a port that says nothing: the connect timeout is read first
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)
        argv += ["--scheduler", f"tcp://127.0.0.1:{listener.getsockname()[1]}"]
    try:
        with dask.config.set({key: "abc"}):
            assert main(argv) == 2
    finally:
        if where == "scheduler":
            listener.close()
    assert capsys.readouterr().err == (
        f"pftrack recover: error: {key} is 'abc' (${variable}), expected a duration such as "
        f"'{example}'\n"
    )
    assert not out.exists()


@pytest.mark.parametrize("value", ["abc", 1.5, True])
def test_a_worker_memory_threshold_that_is_no_fraction_is_one_line(
    value: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``DASK_DISTRIBUTED__WORKER__MEMORY__TARGET=abc`` gave each local worker's
    traceback (about 30 lines) and a bare ``MemoryError``."""
    import dask

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    key = "distributed.worker.memory.target"
    with dask.config.set({key: value}):
        assert main(["recover", str(tmp_path / "tracks"), "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pftrack recover: error: {key} is {value!r} ($DASK_DISTRIBUTED__WORKER__MEMORY__TARGET), "
        "expected a fraction from 0 to 1 or False\n"
    )
    assert not out.exists()


def test_a_local_cluster_that_cannot_start_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: Dask's temporary folder under a file (``DASK_TEMPORARY_DIRECTORY``) gave
    a 60-line traceback ending in "RuntimeError: Cluster failed to start", exit status 1."""
    import dask

    _tracks_files(tmp_path / "tracks")
    (tmp_path / "file").write_text("")
    out = tmp_path / "out"
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(out), "--workers", "1"]
    with dask.config.set({"temporary-directory": str(tmp_path / "file" / "x")}):
        assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == (  # was "... 1 worker: [Errno 20] Not a directory: '.../file/x'"
        "pftrack recover: error: cannot start a local Dask cluster of 1 worker: Not a "
        f"directory: {tmp_path / 'file' / 'x'}\n"
    ), err
    assert not out.exists()


def _read_folder(path: str) -> TaskResult:
    with open(path, encoding="utf-8") as fh:
        fh.read()
    raise AssertionError("read a folder")


def test_a_task_s_os_error_is_said_as_pftrack_track_says_it(tmp_path: Path) -> None:
    """A task's OSError was Python's ``[Errno 21] Is a directory: '...'`` in the batch's table
    and summary.json, where ``pftrack track`` says ``Is a directory: ...`` (one helper now,
    ``pftrack._text.error_line``)."""
    folder = tmp_path / "in.txt"
    folder.mkdir()
    summary = run_jobs([Job("in", _read_folder, (str(folder),), ())], tmp_path / "out",
                       kind="smooth", settings={}, n_workers=0)  # fmt: skip
    (entry,) = summary.entries
    assert entry["error"] == f"Is a directory: {folder}"
    assert f"in: error: Is a directory: {folder}" in summary.table().splitlines()
    with pytest.raises(OSError) as raised:
        _read_folder(str(folder))
    assert cli._one_line(raised.value) == entry["error"]  # what `pftrack track: error:` says


def _sockets() -> set[str]:
    """The sockets this process holds open (``/proc/self/fd``), by inode."""
    fds = Path("/proc/self/fd")
    held = set()
    for fd in fds.iterdir():
        with contextlib.suppress(OSError):  # the listing's own descriptor, closed meanwhile
            if (link := os.readlink(fd)).startswith("socket:"):
                held.add(link)
    return held


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs /proc/self/fd")
def test_a_local_cluster_that_cannot_start_leaves_no_thread_nor_socket(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: the one-line error, but the cluster's event-loop thread ("IO loop") left running
    for the rest of the process, with its sockets, and the half-made scheduler's HTTP server
    still listening (Dask closes neither when its scheduler fails to start; the socket, closed
    by the garbage collector, said "unclosed socket", an error under pytest)."""
    import dask

    _tracks_files(tmp_path / "tracks")
    (tmp_path / "file").write_text("")
    argv = ["recover", str(tmp_path / "tracks"), "--out", str(tmp_path / "out"), "--workers", "1"]
    held = _sockets()
    with _nothing_left_to_the_gc():  # no client, no loop thread; then what the GC finds
        with dask.config.set({"temporary-directory": str(tmp_path / "file" / "x")}):
            assert main(argv) == 2
        assert _sockets() - held == set()
    err = capsys.readouterr().err
    assert err.startswith("pftrack recover: error: cannot start a local Dask cluster of 1 ")
    assert err.count("\n") == 1, err


def test_workers_without_pftrack_are_one_line_before_anything(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: an 80-line traceback from register_plugin (exit 1), then on a re-run (the plugin
    registered) every task failing with Dask's "Error during deserialization of the task
    graph", or the worker dying on it; pftrack never named."""
    _tracks_files(tmp_path / "tracks")
    (tmp_path / "hide_pftrack.py").write_text(HIDE_PFTRACK)
    out = tmp_path / "out"
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
        scheduler_kwargs=NO_DASHBOARD, preload=[str(tmp_path / "hide_pftrack.py")],
    ) as cluster:  # fmt: skip
        address = cluster.scheduler_address
        argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out), "--scheduler", address]
        for _ in range(2):  # the re-run too
            assert main(argv) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1, err
            assert re.fullmatch(
                rf"pftrack smooth: error: the workers at {re.escape(address)} cannot import "
                r"pftrack \(ModuleNotFoundError: .*'pftrack.*\): install pftrack where the "
                r"scheduler and every worker run\n",
                err,
            ), err
        assert not out.exists()
        with distributed.Client(cluster) as c, pytest.raises(ImportError) as caught:
            smooth_many(tmp_path / "tracks", out, c)
        assert caught.value.name == "pftrack" and "the workers at" in str(caught.value)
    # a worker that comes while the batch waits for one is checked too
    with distributed.LocalCluster(
        n_workers=0, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
        scheduler_kwargs=NO_DASHBOARD, preload=[str(tmp_path / "hide_pftrack.py")],
    ) as late:  # fmt: skip
        threading.Timer(0.5, late.scale, (1,)).start()
        with warnings.catch_warnings(record=True) as caught_warnings:
            warnings.simplefilter("always")
            with pytest.raises(ImportError, match=r"^the workers at .* cannot import pftrack"):
                smooth_many(tmp_path / "tracks", out, scheduler=late.scheduler_address)
        assert [str(w.message).split(";")[0] for w in caught_warnings] == [
            f"the scheduler at {late.scheduler_address} has no workers"
        ]
    assert not out.exists()


def _set_version(version: str) -> str:
    """On a worker: give its pftrack another release number; return the one it had."""
    import pftrack

    was, pftrack.__version__ = pftrack.__version__, version
    return was


def test_workers_of_another_pftrack_release_are_one_line_before_anything(
    client: Any, tmp_path: Path
) -> None:
    """A user trial: workers with another pftrack release tracked every sequence, written as
    this release's (the sidecar names the client's release, so a re-run skipped them) and
    unlike ``pftrack track`` here."""
    import pftrack

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    address = client.scheduler.address
    (_, second) = sorted(client.scheduler_info()["workers"])
    client.run(_set_version, "9.9.9", workers=[second])
    try:
        with pytest.raises(ImportError) as caught:
            smooth_many(tmp_path / "tracks", out, client)
        assert str(caught.value) == (
            f"1 of the 2 workers ({second}) at {address} run pftrack 9.9.9, this is pftrack "
            f"{pftrack.__version__}: install the same pftrack where this process and every "
            "worker run (a batch's outputs are those of one release)"
        )
        assert caught.value.name == "pftrack"
        assert not out.exists()
    finally:
        client.run(_set_version, pftrack.__version__)
    assert [e["status"] for e in smooth_many(tmp_path / "tracks", out, client).entries] == [
        "done"
    ] * 3


def test_a_worker_of_another_release_that_joins_later_fails_its_tasks(
    client: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A trial: a worker of pftrack 0.2.0 that joined while a 0.1.0 batch ran (after the
    workers were checked) tracked sequences, written as 0.1.0's, which a re-run skipped."""
    import pftrack
    from pftrack.batch import engine

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    # both workers joined after the check: as if check_pftrack had not seen them
    monkeypatch.setattr(engine, "check_pftrack", lambda *args, **kwargs: None)
    client.run(_set_version, "9.9.9")
    try:
        summary = smooth_many(tmp_path / "tracks", out, client)
    finally:
        client.run(_set_version, pftrack.__version__)
    assert [e["status"] for e in summary.entries] == ["failed"] * 3
    for e in summary.entries:
        assert e["error"] == (
            f"made on worker {e['host']} by pftrack 9.9.9, this is pftrack "
            f"{pftrack.__version__} (a worker that joined after the batch checked them): not "
            "written; install the same pftrack where this process and every worker run (a "
            "batch's outputs are those of one release)"
        )
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]  # nothing tracked


def test_a_batch_into_a_folder_another_batch_is_writing_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial: two ``pftrack batch`` runs into the same --out at once both tracked every
    sequence, each writing over the other's outputs and sidecars (one run's sidecar could vouch
    for the other's tracks), and the summary was the last one's. The folder is held while a
    batch writes into it (``flock`` on the folder itself): the second is refused, exit 2."""
    import fcntl

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]
    out.mkdir()
    other = os.open(out, os.O_RDONLY)  # as the other batch holds it
    try:
        fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
        assert main(argv) == 2
        assert capsys.readouterr().err == (
            f"pftrack smooth: error: --out {out}: another pftrack batch is writing into this "
            "folder: wait until it ends, or write elsewhere\n"
        )
        assert list(out.iterdir()) == []
    finally:
        os.close(other)
    for _ in range(2):  # held only while a batch runs
        assert main(argv) == 0
    assert sorted(p.name for p in out.iterdir())[-1] == "summary.json"


def test_a_scheduler_without_pftrack_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The scheduler unpickles the tasks: without pftrack, every task failed with Dask's
    "Error during deserialization of the task graph" (exit 1)."""
    dask = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command is not installed")
    _tracks_files(tmp_path / "tracks")
    (tmp_path / "hide_pftrack.py").write_text(HIDE_PFTRACK)
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    cmd = [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard",
           "--preload", str(tmp_path / "hide_pftrack.py")]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    with (tmp_path / "log.txt").open("w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=log, env=env, cwd=tmp_path)
    try:
        with distributed.Client(address, timeout="30s"):
            pass  # it is up
        out = tmp_path / "out"
        argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out), "--scheduler", address]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err
        assert re.fullmatch(
            rf"pftrack smooth: error: the scheduler at {re.escape(address)} cannot import "
            r"pftrack \(ModuleNotFoundError: .*'pftrack.*\): install pftrack where the "
            r"scheduler and every worker run\n",
            err,
        ), err
        assert not out.exists()
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def test_the_help_states_the_engines_wait_for_a_worker(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from pftrack.batch.engine import NO_WORKERS_WAIT, no_workers_timeout
    from pftrack.cli import batch

    assert batch.NO_WORKERS_WAIT == NO_WORKERS_WAIT == no_workers_timeout()
    with pytest.raises(SystemExit):
        main(["batch", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert f"waits up to {NO_WORKERS_WAIT:g} s for one" in text
    # --render: the final tracks, not track --render's online boxes (was: "as track --render")
    assert "--render also write DIR/NAME.mp4: the final tracks of DIR/NAME.txt" in text
    assert "not the boxes as tracked online that track --render draws" in text


def test_the_workers_are_counted_by_the_scheduler_not_a_stale_cache(
    client: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The client's periodic refresh of ``scheduler_info`` lists no worker (Dask 2026.8): taken
    for the count, it said "the scheduler has lost all its workers" while they ran (2 runs of
    15 in a user's trial; 134 of 1098 counts at a 5 ms refresh)."""
    import dask

    import pftrack.batch.engine as engine

    monkeypatch.setattr(engine, "WORKERS_POLL", 0.0)  # the watch counts at every call
    with (
        dask.config.set({"distributed.client.scheduler-info-interval": "5ms"}),
        distributed.Client(client.scheduler.address) as c,
    ):
        watch = engine._WorkersWatch(c, client.scheduler.address, 60.0)
        counts = []
        # At least 1.5 s of the 5 ms refresh and at least 200 counts, however slow the machine
        # (was: as many counts as 1.5 s gave, asked to be over 100: 59 at load 20).
        deadline = time.monotonic() + 1.5
        while time.monotonic() < deadline or len(counts) < 200:
            counts.append(engine._n_workers(c))
            assert not watch.given_up()  # and no warning: an error in this module
        assert set(counts) == {2}
        assert engine._wait_for_workers(c, client.scheduler.address, 1.0) == 2


def _close_my_worker(k: int) -> TaskResult:
    """A task that closes its worker (and the worker's nanny) and returns once it is closing.

    Closing, the worker takes no other task: the others wait for a worker. Was: returned after
    0.3 s, however far the close had gone, so that on a loaded machine (load 20) the worker
    could take a next task before it closed.
    """
    worker = distributed.get_worker()
    worker.loop.add_callback(worker.close, nanny=True, reason="test: workers lost")
    deadline = time.monotonic() + 120  # a bound against a hang, not a timing
    while worker.status == distributed.core.Status.running and time.monotonic() < deadline:
        time.sleep(0.01)
    return TaskResult(np.zeros((0, 10)), {}, {"k": k})


class _LastWorkerGone(distributed.diagnostics.plugin.SchedulerPlugin):
    """On a local cluster's scheduler (in this process): when its last worker left.

    `then` is called then, on the scheduler's event loop. The tests time the batch's wait for
    a worker from this moment, not from the batch's start: the cluster's start and the batch's
    checks took most of a 15 s limit on a machine at load 20.
    """

    def __init__(self, then: Any = None) -> None:
        self.at: float | None = None
        self.then = then

    def remove_worker(self, scheduler: Any, worker: str, **kwargs: Any) -> None:
        if not scheduler.workers and self.at is None:
            self.at = time.monotonic()
            if self.then is not None:
                self.then()

    def since(self) -> float:
        """Seconds since the last worker left (the test fails if none has)."""
        assert self.at is not None, "the workers were never lost: no test"
        return time.monotonic() - self.at


def _watch_last_worker(cluster: Any, then: Any = None) -> _LastWorkerGone:
    """A :class:`_LastWorkerGone` added to `cluster`'s scheduler, on its event loop."""
    gone = _LastWorkerGone(then)

    async def add() -> None:
        cluster.scheduler.add_plugin(gone)

    cluster.sync(add)
    return gone


#: Seconds a batch's wait for its lost workers may take in the tests where Dask's
#: no-workers-timeout is 1 s: far below Dask's own default (60 s, the batch's too) and for ever,
#: far above the 1 s and the watch's counts, once a second, on a loaded machine.
LOST_WAIT_BOUND = 30.0


@pytest.mark.parametrize("setting_on_the_scheduler", [False, True])
def test_workers_lost_mid_run_fail_the_tasks_left(
    tmp_path: Path, setting_on_the_scheduler: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every worker gone mid-run: the batch waited forever for the tasks left.

    The wait is Dask's ``no-workers-timeout`` as this process reads it; a scheduler that has the
    setting itself fails the tasks first (``NoWorkerError``): the same error is reported.
    """
    import dask

    import pftrack.batch.engine as engine

    # the scheduler (this process's) slow to answer at load 20 is not what is tested here
    monkeypatch.setattr(engine, "ANSWER_WAIT", LOST_WAIT_BOUND)
    jobs = [Job("first", _close_my_worker, (0,), ()), *(Job(f"slow{k}", _slow, (k,), ())
                                                        for k in range(2))]  # fmt: skip
    setting = {"distributed.scheduler.no-workers-timeout": "1s"}
    with contextlib.ExitStack() as stack:
        if setting_on_the_scheduler:
            stack.enter_context(dask.config.set(setting))
        cluster = stack.enter_context(distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
            scheduler_kwargs=NO_DASHBOARD,
        ))  # fmt: skip
        stack.enter_context(dask.config.set(setting))
        address = cluster.scheduler_address
        gone = _watch_last_worker(cluster)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary = run_jobs(jobs, tmp_path, kind="smooth", settings={}, scheduler=address)
        # the wait of 1 s, from the loss (was: < 15 s from the batch's start, its cluster's
        # start and checks included, which a machine at load 20 exceeded)
        assert gone.since() < LOST_WAIT_BOUND
    if not setting_on_the_scheduler:  # this process saw them go
        said = [str(w.message) for w in caught]
        assert said == [f"the scheduler at {address} has lost all its workers; waiting up to "
                        f"1 s for one (start one: dask worker {address})"]  # fmt: skip
    status = {e["name"]: e["status"] for e in summary.entries}
    assert status["slow0"] == status["slow1"] == "failed"
    for e in summary.failed:
        assert e["error"] == (
            f"no worker on the scheduler at {address} for 1 s: its workers were lost before "
            f"this file ran or finished (start some: dask worker {address}; a re-run does the "
            "rest)"
        )
    assert json.loads((tmp_path / "summary.json").read_text())["counts"]["failed"] >= 2


def _where_i_ran(k: int, joined: str) -> TaskResult:
    """A task that runs once the second worker has joined (`joined` exists) and, until a task
    has run on each of two workers, waits for it (60 s at most each, bounds against a hang).

    The tasks were all given to the first worker, the second taking some by Dask's work
    stealing; was: 0.8 s each, the second worker's share depending on how fast it came up (at
    load 24 it took none: "the second worker ran none").
    """
    address = distributed.get_worker().address
    folder = Path(joined).parent
    deadline = time.monotonic() + 60
    while not os.path.exists(joined) and time.monotonic() < deadline:
        time.sleep(0.05)
    (folder / f"ran-{address.rsplit(':', 1)[-1]}").touch()
    deadline = time.monotonic() + 60
    while len(list(folder.glob("ran-*"))) < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    return TaskResult(np.zeros((0, 10)), {}, {"k": k, "worker": address})


def test_the_summary_counts_the_workers_that_ran_its_tasks(tmp_path: Path) -> None:
    """A trial: the summary's worker count was the count at the start; a worker that joined
    mid-run and ran tasks was not in it (nor, on a larger cluster, were the idle ones out)."""
    joined = tmp_path / "joined"
    jobs = [Job(f"t{k}", _where_i_ran, (k, str(joined)), ()) for k in range(8)]
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
        scheduler_kwargs=NO_DASHBOARD,
    ) as cluster:  # fmt: skip

        def join() -> None:  # a second worker, once the batch runs on the first
            deadline = time.monotonic() + 30
            while not cluster.scheduler.tasks and time.monotonic() < deadline:
                time.sleep(0.05)
            cluster.scale(2)
            while len(cluster.scheduler.workers) < 2 and time.monotonic() < deadline:
                time.sleep(0.05)
            joined.touch()

        joins = threading.Thread(target=join)
        joins.start()
        try:
            summary = run_jobs(jobs, tmp_path / "out", kind="smooth", settings={},
                               scheduler=cluster.scheduler_address)  # fmt: skip
        finally:
            joins.join()
    ran = {e["worker"] for e in summary.entries}
    assert len(ran) == 2, "the second worker ran none: no test"
    assert summary.workers == 2
    assert f"8 files: 8 done; {summary.seconds:.1f} s, 2 workers at " in summary.table()
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["workers"] == 2


def test_a_worker_without_pftrack_that_joins_mid_run_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A trial: the workers lost mid-run, the operator started one from an environment without
    pftrack. It joined, was given a task it could not unpickle and died at once, too soon for
    the count of the workers to see it; the tasks left failed after the wait saying "start
    some", and the worker started was never named."""
    import dask

    dask_cmd = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    if dask_cmd is None:
        pytest.skip("the dask command is not installed")
    import pftrack.batch.engine as engine

    # the scheduler (this process's) slow to answer at load 20 is not what is tested here
    monkeypatch.setattr(engine, "ANSWER_WAIT", LOST_WAIT_BOUND)
    ready, go = tmp_path / "ready", tmp_path / "go"
    # the worker without pftrack: started (Dask imported) before the batch, and held before it
    # connects until the batch's workers are lost, as an operator would start it then (was: a
    # timer of 2 s from the test's start, and the worker's start within the 15 s wait: at load
    # 20 it joined before the loss, or after the wait)
    (tmp_path / "hide_pftrack.py").write_text(
        HIDE_PFTRACK + HELD.format(ready=str(ready), go=str(go))
    )
    jobs = [Job("first", _close_my_worker, (0,), ()), *(Job(f"slow{k}", _slow, (k,), ())
                                                        for k in range(2))]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    with contextlib.ExitStack() as stack:
        cluster = stack.enter_context(distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
            scheduler_kwargs=NO_DASHBOARD,
        ))  # fmt: skip
        stack.enter_context(dask.config.set({"distributed.scheduler.no-workers-timeout": "15s"}))
        address = cluster.scheduler_address
        cmd = [dask_cmd, "worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
               "--preload", str(tmp_path / "hide_pftrack.py")]  # fmt: skip
        log = stack.enter_context((tmp_path / "log.txt").open("w"))
        proc = subprocess.Popen(cmd, stdout=log, stderr=log, env=env, cwd=tmp_path)
        stack.callback(proc.wait, 15)
        stack.callback(proc.kill)
        deadline = time.monotonic() + 300  # a bound against a hang, not a timing
        while not ready.exists() and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert ready.exists(), (tmp_path / "log.txt").read_text()
        _watch_last_worker(cluster, then=go.touch)  # the workers lost: it connects
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary = run_jobs(jobs, tmp_path / "out", kind="smooth", settings={},
                               scheduler=address)  # fmt: skip
    named = (
        r"a worker that joined \(tcp://127\.0\.0\.1:\d+\) cannot import pftrack "
        r"\(ModuleNotFoundError: .*pftrack.*\) and dies on the first task given: install "
        r"pftrack where the scheduler and every worker run"
    )
    said = [str(w.message) for w in caught]
    warned = rf"the scheduler at {re.escape(address)}: {named}"
    assert any(re.fullmatch(warned, m) for m in said), said
    failed = [e for e in summary.entries if e["name"] != "first"]
    assert [e["status"] for e in failed] == ["failed", "failed"]
    for e in failed:
        assert re.fullmatch(
            rf"no worker on the scheduler at {re.escape(address)} for 15 s: its workers were "
            rf"lost before this file ran or finished; {named} \(a re-run does the rest\)",
            e["error"],
        ), e["error"]


#: The end of a worker's preload: it says it is ready, then holds the worker (before it
#: connects to its scheduler) until the file `go` exists; 10 minutes at most.
HELD = """import os, time
open({ready!r}, "w").close()
_deadline = time.monotonic() + 600
while not os.path.exists({go!r}) and time.monotonic() < _deadline:
    time.sleep(0.02)
"""


HIDE_PFTRACK_ONCE = """import os, sys
if os.path.exists({marker!r}):  # pftrack uninstalled: the workers started from now on lack it
""" + "".join(f"    {line}\n" for line in HIDE_PFTRACK.splitlines())


def _uninstall_and_die(marker: str) -> TaskResult:
    """A task that "uninstalls" pftrack for the workers started from now on, and kills its own."""
    Path(marker).touch()
    os.kill(os.getpid(), signal.SIGKILL)
    raise AssertionError("not reached")


def test_a_worker_restarted_without_pftrack_is_named_not_killedworker(tmp_path: Path) -> None:
    """A trial: a worker's nanny restarted it (the process killed) after pftrack was removed
    from its environment; given the task again, each such worker died on it, and the sequence
    failed with Dask's generic ``KilledWorker: Attempted to run task ... on 4 different
    workers ...``, pftrack never named."""
    import dask

    marker = tmp_path / "uninstalled"
    (tmp_path / "hide_once.py").write_text(HIDE_PFTRACK_ONCE.format(marker=str(marker)))
    jobs = [Job("walk", _uninstall_and_die, (str(marker),), ())]
    with contextlib.ExitStack() as stack:
        stack.enter_context(dask.config.set({"distributed.scheduler.no-workers-timeout": "15s"}))
        cluster = stack.enter_context(distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
            scheduler_kwargs=NO_DASHBOARD, preload=[str(tmp_path / "hide_once.py")],
        ))  # fmt: skip
        with warnings.catch_warnings(record=True):
            warnings.simplefilter("always")
            summary = run_jobs(jobs, tmp_path / "out", kind="smooth", settings={},
                               scheduler=cluster.scheduler_address)  # fmt: skip
    (entry,) = summary.entries
    assert entry["status"] == "failed"
    assert re.fullmatch(
        r"pftrack missing on worker tcp://127\.0\.0\.1:\d+ \(ModuleNotFoundError: .*pftrack.*\): "
        r"it joined without pftrack \(restarted by its nanny after pftrack was removed\?\) and "
        r"died on this file, the last of 4 workers that did \(Dask's KilledWorker\); install "
        r"pftrack where the scheduler and every worker run",
        entry["error"],
    ), entry["error"]


# --- inputs a worker cannot see, broken links, the same input twice, listing order ----------


def _track_unseen(seq: SequenceInput, options: TrackOptions) -> TaskResult:
    """``track_sequence`` on a worker that cannot see ``seq.frames`` (a share not mounted there)."""
    from pftrack.batch.tasks import track_sequence

    real = Path.exists

    def exists(self: Path, *args: Any, **kwargs: Any) -> bool:
        return False if self == seq.frames else real(self, *args, **kwargs)

    Path.exists = exists  # type: ignore[method-assign]
    try:
        return track_sequence(seq, options)
    finally:
        Path.exists = real  # type: ignore[method-assign]


def test_a_path_a_worker_cannot_see_is_said_so(data: Path, client: Any, tmp_path: Path) -> None:
    """Was: "video source not found: PATH", as if it did not exist, and no host named."""
    (seq,) = [s for s in find_sequences(data) if s.name == "walk"]
    job = Job(seq.name, _track_unseen, (seq, TrackOptions(config=_config())), seq.files)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        summary = run_jobs([job], tmp_path / "out", kind="track", settings={}, client=client)
    # tried on each worker (none sees it), each named once
    workers = sorted(client.scheduler_info(n_workers=-1)["workers"])
    assert sorted(re.findall(r"the worker (\S+) cannot see", str([w.message for w in caught]))) == (
        workers
    )
    (entry,) = summary.entries
    host = socket.gethostname()
    assert entry["status"] == "failed" and entry["host"] == host
    assert entry["error"] == (
        f"{seq.frames}: not found on worker {host} (the client sees it: workers must see the "
        "same paths)"
    )
    written = json.loads((tmp_path / "out" / "summary.json").read_text())["sequences"][0]
    assert written["host"] == host and written["error"] == entry["error"]
    # a file missing for the client too is reported as the task said it
    gone = SequenceInput("gone", tmp_path / "gone.avi")
    job = Job("gone", _track_unseen, (gone, TrackOptions(config=_config())), gone.files)
    (entry,) = run_jobs([job], tmp_path / "o2", kind="track", settings={}, client=client).entries
    assert entry["error"] == f"video source not found: {gone.frames}" and entry["host"] == host


def _blind_to(prefix: str | None) -> None:
    """On a worker: every path under `prefix` is not found (a share not mounted there; None:
    undo)."""
    if not hasattr(os, "_real_stat"):
        os._real_stat = os.stat  # type: ignore[attr-defined]
    real = os._real_stat  # type: ignore[attr-defined]

    def stat(path: Any, *args: Any, **kwargs: Any) -> Any:
        if prefix is not None and os.fsdecode(path).startswith(prefix):
            raise FileNotFoundError(2, "No such file or directory", os.fsdecode(path))
        return real(path, *args, **kwargs)

    os.stat = stat if prefix is not None else real


def test_a_worker_that_cannot_see_the_inputs_hands_its_tasks_to_the_others(
    data: Path, client: Any, tmp_path: Path
) -> None:
    """A trial: a worker that could not see the inputs (started in another mount namespace)
    failed every task it was given, fast, and so took most of the queue while the good ones
    idled. Its tasks now go to the other workers, and it is named once; a sequence that no
    worker can see still fails, as before."""
    blind, good = sorted(client.scheduler_info(n_workers=-1)["workers"])
    options = TrackOptions(config=_config())
    assert client.run(_blind_to, str(data), workers=[blind])
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary = track_many(data, tmp_path / "out", client, options=options)
        assert [e["status"] for e in summary.entries] == ["done"] * 3, summary.table()
        address = client.scheduler.address
        said = [str(w.message) for w in caught]
        (one,) = said  # named once, however many of its tasks it was given
        assert re.fullmatch(
            rf"the scheduler at {re.escape(address)}: the worker {re.escape(blind)} cannot see "
            rf"the inputs this process sees \({re.escape(str(data))}/\S+ not found on "
            rf"{re.escape(socket.gethostname())}\): its tasks go to the other workers \(workers "
            r"must see the same paths\)",
            one,
        ), one
        assert len(_files(tmp_path / "out")) == 3
        # no worker sees them: each sequence fails as before, its worker named
        assert client.run(_blind_to, str(data), workers=[good])
        with warnings.catch_warnings(record=True):
            warnings.simplefilter("always")
            failed = track_many(data, tmp_path / "o2", client, options=options)
    finally:
        client.run(_blind_to, None)
    host = socket.gethostname()
    assert [e["status"] for e in failed.entries] == ["failed"] * 3
    for e in failed.entries:
        assert e["error"] == (
            f"{e['source']}: not found on worker {host} (the client sees it: workers must see "
            "the same paths)"
        )


def test_a_task_sent_to_workers_all_gone_since_is_sent_again(client: Any) -> None:
    """A task sent away from a blind worker goes to the others only (Dask's ``workers=``): were
    they all to go, Dask would keep it for them for ever while the watch counts the others."""
    from pftrack.batch import engine

    (worker, *_) = sorted(client.scheduler_info(n_workers=-1)["workers"])
    blind = engine._Blind(client, client.scheduler.address, lambda job, outcome: None)
    sent = {"gone": {"tcp://127.0.0.1:1"}, "there": {worker, "tcp://127.0.0.1:1"}}
    assert blind.stranded(sent) == {"gone"}
    assert blind.stranded(sent) is None  # once a second at most
    job = Job("j", track_sequence_stub, (), ())
    assert blind.others(job) == set(client.scheduler_info(n_workers=-1)["workers"])
    blind.tried["j"] = blind.others(job) or set()
    assert blind.others(job) is None  # every worker tried: the task fails


def _worker_sees_other_files(grown: int) -> None:
    """On a worker: its view of every input is `grown` bytes larger than the client's (0: undo)."""
    from pftrack.batch import engine

    if not hasattr(engine, "_real_fingerprint"):
        engine._real_fingerprint = engine.fingerprint  # type: ignore[attr-defined]
    real = engine._real_fingerprint  # type: ignore[attr-defined]

    def other(paths: Any) -> list[dict[str, Any]]:
        return [{**p, "size": p["size"] + grown} if "size" in p else p for p in real(paths)]

    engine.fingerprint = other if grown else real  # type: ignore[assignment]


def test_a_worker_that_reads_other_files_fails_the_task(
    data: Path, client: Any, tmp_path: Path
) -> None:
    """A user trial: a worker whose copy of the inputs differed (another video, fewer images
    under the same path) reported the sequence done with its own frames, and its sidecar
    vouched for the client's file, so a re-run skipped it; a file the worker could not decode
    said "not a video", of a video the client can read."""
    assert client.run(_worker_sees_other_files, 100)
    try:
        summary = track_many(data, tmp_path / "out", client, options=TrackOptions(config=_config()))
    finally:
        client.run(_worker_sees_other_files, 0)
    host = socket.gethostname()
    by_name = {e["name"]: e for e in summary.entries}
    walk = by_name["walk"]
    assert walk["status"] == "failed" and walk["host"] == host
    size = (data / "walk.avi").stat().st_size
    assert walk["error"] == (
        f"{data / 'walk.avi'}: another file on worker {host} ({size + 100} bytes there, {size} "
        "here): workers must see the same files at the same paths"
    )
    plain = by_name["plain"]
    assert plain["status"] == "failed" and "another folder on worker" in plain["error"]
    assert not list((tmp_path / "out").glob("*.txt"))  # no output of what the client has not
    # the same files: done, and the worker's view is not taken in this process
    again = track_many(data, tmp_path / "out", client, options=TrackOptions(config=_config()))
    assert [e["status"] for e in again.entries] == ["done"] * 3


def test_an_input_changed_while_the_batch_ran_is_not_a_workers_other_file(
    tmp_path: Path,
) -> None:
    """The worker's view is compared with this process's view now, too: an input changed
    after the batch began (the same file on a local cluster) is no worker seeing other files."""
    from pftrack.batch.engine import Outcome, _seen_otherwise, fingerprint

    video = tmp_path / "walk.avi"
    video.write_bytes(b"x" * 10)
    job = Job("walk", track_sequence_stub, (), (video,))
    before = fingerprint([video])
    video.write_bytes(b"x" * 20)  # after the client's fingerprint, before the worker's
    outcome = Outcome(None, host="node7", seen=fingerprint([video]))
    assert _seen_otherwise(job, outcome, before) is None
    other = Outcome(None, host="node7", seen=[{**before[0], "size": 30}])
    assert _seen_otherwise(job, other, before) == (
        f"{video}: another file on worker node7 (30 bytes there, 20 here): workers must see "
        "the same files at the same paths"
    )


def track_sequence_stub() -> TaskResult:
    """A task function for jobs that never run."""
    raise AssertionError("not run")


def test_a_broken_link_in_a_scanned_folder_fails_alone(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: the whole batch stopped with "No such file or directory" (exit 2)."""
    vids = tmp_path / "vids"
    vids.mkdir()
    shutil.copy2(data / "walk.avi", vids / "walk.avi")
    (vids / "gone.avi").symlink_to(tmp_path / "moved.avi")
    (vids / "seq").symlink_to(tmp_path / "moved-folder")
    (vids / "notes.txt").symlink_to(tmp_path / "moved.txt")  # not a video: passed over
    assert [s.name for s in find_sequences(vids)] == ["gone", "seq", "walk"]
    out = tmp_path / "out"
    assert main(["batch", str(vids), "--out", str(out), "--workers", "0", *FAST]) == 1
    text = capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    status = {e["name"]: (e["status"], e.get("error")) for e in summary["sequences"]}
    assert status == {
        "gone": ("failed", f"broken symbolic link: {vids / 'gone.avi'} -> {tmp_path}/moved.avi"),
        "seq": ("failed", f"broken symbolic link: {vids / 'seq'} -> {tmp_path / 'moved-folder'}"),
        "walk": ("done", None),
    }
    assert f"gone: error: broken symbolic link: {vids / 'gone.avi'}" in text
    # given by its own path: refused, named as a broken link
    assert main(["batch", str(vids / "gone.avi"), "--out", str(tmp_path / "o2")]) == 2
    assert capsys.readouterr().err == (
        f"pftrack batch: error: input not found: {vids / 'gone.avi'} is a broken symbolic link "
        f"(to {tmp_path / 'moved.avi'})\n"
    )
    # tracks files too
    paths = _tracks_files(tmp_path / "tracks")
    (tmp_path / "tracks" / "run9.txt").symlink_to(tmp_path / "moved.txt")
    out = tmp_path / "filled"
    assert main(["recover", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]) == 1
    files = json.loads((out / "summary.json").read_text())["files"]
    assert [(f["name"], f["status"]) for f in files] == [
        *((p.stem, "done") for p in paths),
        ("run9", "failed"),
    ]
    assert files[-1]["error"] == (
        f"broken symbolic link: {tmp_path / 'tracks' / 'run9.txt'} -> {tmp_path / 'moved.txt'}"
    )


def test_a_symbolic_link_loop_is_named_as_one(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: given, "input not found: a is a broken symbolic link (to b)" (b is there, a link
    back to a); met in a scanned folder, a traceback (``RuntimeError: Symlink loop``)."""
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    loop = f"{tmp_path / 'a'} -> b -> a"
    error = (
        f"input {tmp_path / 'a'}: symbolic link loop ({loop}), which leads to no file or "
        "folder; point the link at one"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(error)}$"):
        find_sequences(tmp_path / "a")
    with pytest.raises(ValueError, match=f"^{re.escape(error)}$"):
        find_track_files([tmp_path / "a"])
    for command in ("batch", "recover"):
        argv = [command, str(tmp_path / "a"), str(tmp_path / "b"), "--out", str(tmp_path / "o")]
        assert main([*argv, "--workers", "0"]) == 2
        assert capsys.readouterr().err == f"pftrack {command}: error: {error}\n"
        assert not (tmp_path / "o").exists()
    # met in a scanned folder: a sequence whose task fails, named so; the others run
    vids = tmp_path / "vids"
    vids.mkdir()
    shutil.copy2(data / "walk.avi", vids / "walk.avi")
    (vids / "p.avi").symlink_to("q.avi")
    (vids / "q.avi").symlink_to("p.avi")
    (vids / "seq").symlink_to("seq")  # a folder's name, to itself
    out = tmp_path / "out"
    assert main(["batch", str(vids), "--out", str(out), "--workers", "0", *FAST]) == 1
    err = capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    status = {e["name"]: (e["status"], e.get("error")) for e in summary["sequences"]}
    assert status == {
        "p": ("failed", f"symbolic link loop: {vids / 'p.avi'} -> q.avi -> p.avi"),
        "q": ("failed", f"symbolic link loop: {vids / 'q.avi'} -> p.avi -> q.avi"),
        "seq": ("failed", f"symbolic link loop: {vids / 'seq'} -> seq"),
        "walk": ("done", None),
    }
    assert f"p: error: symbolic link loop: {vids / 'p.avi'} -> q.avi -> p.avi\n" in err
    assert "Traceback" not in err


@pytest.mark.parametrize("command", ["track", "recover", "smooth"])
@pytest.mark.parametrize("link", ["hard", "symbolic"])
def test_one_file_under_two_names_is_the_same_input_given_twice(
    tmp_path: Path, command: str, link: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user trial: ``recover a.txt b.txt --out DIR``, ``b.txt`` a hard link of ``a.txt``,
    ran it twice (a link of another name too): refused by (st_dev, st_ino), before any work."""
    first = tmp_path / ("a.avi" if command == "track" else "a.txt")
    if command == "track":
        make_scene(n_frames=3, rng=0).write_video(first)
    else:
        write_mot(first, [[1, 1, 10, 10, 5, 5]])
    second = first.with_stem("b")
    if link == "hard":
        os.link(first, second)
    else:
        second.symlink_to(first.name)
    how = "one file, hard linked" if link == "hard" else "the same path once links are resolved"
    said = f"{first} and {second} are the same input, given twice ({how}): give each input once"
    with pytest.raises(ValueError, match=f"^{re.escape(said)}$"):
        (find_sequences if command == "track" else find_track_files)([first, second])
    argv = ["batch"] if command == "track" else [command]
    out = tmp_path / "out"
    assert main([*argv, str(first), str(second), "--out", str(out)]) == 2
    assert capsys.readouterr().err == f"pftrack {argv[0]}: error: {said}\n"
    assert not out.exists()
    copy = tmp_path / f"c{first.suffix}"  # the same bytes in another file: two inputs
    shutil.copyfile(first, copy)
    assert len((find_sequences if command == "track" else find_track_files)([first, copy])) == 2


def test_the_same_input_twice_is_said_so(tmp_path: Path) -> None:
    """Was: "two inputs are both named 'tud' (A and A)"."""
    video = tmp_path / "vids" / "tud.mp4"
    video.parent.mkdir()
    video.write_text("")
    with pytest.raises(ValueError, match=(
        rf"^{video} is the same input, given twice \(the same path once links are resolved\): "
        "give each input once$"
    )):  # fmt: skip
        find_sequences([video, video])
    with pytest.raises(ValueError, match="is the same input, given twice"):
        find_sequences([tmp_path / "vids", video])  # the folder's entry, then the file again
    (tmp_path / "alias").symlink_to(tmp_path / "vids")
    with pytest.raises(ValueError, match=rf"^{video} and {tmp_path / 'alias' / 'tud.mp4'} are "):
        find_sequences([video, tmp_path / "alias" / "tud.mp4"])
    other = tmp_path / "other" / "tud.mp4"  # another file of the same name: as before
    other.parent.mkdir()
    other.write_text("")
    with pytest.raises(ValueError, match="two inputs are both named 'tud'"):
        find_sequences([video, other])


def test_a_folder_is_listed_in_natural_order_of_its_names(tmp_path: Path) -> None:
    """Was: tud2.mp4 before tud.mp4 (the natural key of the whole name: 'tud' < 'tud.mp4')."""
    (tmp_path / "v").mkdir()
    for name in ("tud10.mp4", "tud2.mp4", "tud.mp4", "a.avi", "B.avi", "tud1.avi"):
        (tmp_path / "v" / name).write_text("")
    (tmp_path / "t").mkdir()
    for name in ("run10.txt", "run2.txt", "run.txt"):
        (tmp_path / "t" / name).write_text("")
    names = [s.name for s in find_sequences(tmp_path / "v")]
    assert names == ["a", "B", "tud", "tud1", "tud2", "tud10"]
    from pftrack.batch import find_track_files

    assert [p.stem for p in find_track_files(tmp_path / "t")] == ["run", "run2", "run10"]


def test_ctrl_c_says_what_was_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: "the outputs written so far are complete" with nothing written at all."""
    import pftrack.batch.engine as engine

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out)]

    @contextlib.contextmanager
    def connecting(*args: Any, **kwargs: Any) -> Iterator[Any]:
        raise KeyboardInterrupt  # Ctrl-C while connecting, or while the local cluster starts
        yield

    monkeypatch.setattr(engine, "dask_client", connecting)
    assert main(argv) == 130
    assert capsys.readouterr().err == (
        f"pftrack smooth: interrupted; nothing was written: it stopped before the run began "
        f"(--out {out} untouched)\n"
    )
    assert not out.exists()
    # in this process: after one file, and before any
    calls = []
    real = engine.call_task

    def stop_at_the_second(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(engine, "call_task", stop_at_the_second)
    assert main([*argv, "--workers", "0"]) == 130
    assert capsys.readouterr().err == (
        "pftrack smooth: interrupted; the outputs of the 1 file finished are written and "
        f"complete; {out / 'summary.json'} lists the rest as cancelled (re-run to finish them)\n"
    )
    calls[:] = [1]  # the next run stops at its first file
    assert main([*argv, "--workers", "0", "--force"]) == 130
    assert capsys.readouterr().err == (
        f"pftrack smooth: interrupted; no file was finished; {out / 'summary.json'} lists them "
        "as cancelled (re-run to run them)\n"
    )


def test_ctrl_c_after_out_was_removed_says_what_went_with_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial: ``--out`` removed while the batch ran, then Ctrl-C; the last line said the
    outputs of the file finished "are written and complete" and that summary.json lists the
    rest, of a folder gone with both. It says what went with it, as a batch that ends does."""
    import pftrack.batch.engine as engine

    _tracks_files(tmp_path / "tracks")
    out = tmp_path / "out"
    calls = []
    real = engine.call_task

    def removed_then_stopped(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        if len(calls) == 2:
            shutil.rmtree(out)
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(engine, "call_task", removed_then_stopped)
    argv = ["smooth", str(tmp_path / "tracks"), "--out", str(out), "--workers", "0"]
    assert main(argv) == 130
    assert capsys.readouterr().err == (
        f"pftrack smooth: interrupted; --out {out} was removed while the batch ran: the outputs "
        "of 1 file (run0) went with it, and summary.json is not written; re-run the batch to "
        "make them again\n"
    )
    assert not out.exists()


# --- a cancelled task stops itself ----------------------------------------------------------


def test_track_sequence_calls_the_stop_check_every_25_frames(data: Path) -> None:
    """The check runs while tracking and while rendering, and its exception ends the task."""
    from pftrack.batch.tasks import TaskCancelled, reporting_frames, track_sequence

    (seq,) = [s for s in find_sequences(data) if s.name == "walk"]  # 30 frames
    options = TrackOptions(config=_config(), render=".mp4")
    checks: list[int] = []
    frames: list[int] = []
    with reporting_frames(frames.append, lambda: checks.append(len(frames))):
        track_sequence(seq, options)
    assert frames == list(range(1, 31)) and checks == [25, 30]  # tracking's 25th, rendering's

    def stop() -> None:
        raise TaskCancelled("cancelled while it ran (the batch was interrupted)")

    frames.clear()
    with reporting_frames(frames.append, stop), pytest.raises(TaskCancelled):
        track_sequence(seq, options)
    assert frames == list(range(1, 26))  # stopped at frame 25


def _track_until_stopped(seq: SequenceInput, options: TrackOptions) -> TaskResult:
    """Track `seq` over and over for up to 30 s: a long sequence."""
    from pftrack.batch.tasks import track_sequence

    deadline = time.monotonic() + 30
    while True:
        result = track_sequence(seq, options)
        if time.monotonic() > deadline:
            return result


def _busy_threads(dask_worker: Any) -> int:
    return len(dask_worker.active_threads)


def test_ctrl_c_stops_the_tasks_running_on_the_workers(
    data: Path, client: Any, tmp_path: Path, ctrl_c_raises: None
) -> None:
    """``Client.cancel`` cannot stop a running thread: on an external cluster the tasks of an
    interrupted batch ran to their end, keeping the workers busy. They stop themselves now."""
    (seq,) = [s for s in find_sequences(data) if s.name == "walk"]
    options = TrackOptions(config=_config())
    jobs = [Job(f"long{k}", _track_until_stopped, (seq, options), ()) for k in range(2)]
    timer = threading.Timer(1.5, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_jobs(jobs, tmp_path, kind="track", settings={}, client=client)
    finally:
        timer.cancel()
    deadline = time.monotonic() + 10
    while sum(client.run(_busy_threads).values()) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert sum(client.run(_busy_threads).values()) == 0  # both workers free (was: 30 s busy)
    assert time.monotonic() < deadline


def test_a_scheduler_lost_mid_run_fails_the_tasks_left(client: Any, tmp_path: Path) -> None:
    """The connection to the scheduler lost mid-run (the scheduler stopped, the network failed):
    Dask cancels every future; they were left ``cancelled``, and the batch exited 0. Here the
    connection breaks once (the client reconnects); a scheduler that stops takes the same path,
    and its client's attempts to reconnect are not logged with a traceback (checked by hand)."""
    with distributed.Client(client.scheduler.address) as own:
        jobs = [Job(f"slow{k}", _slow, (k,), ()) for k in range(2)]

        def cut() -> None:
            own.loop.add_callback(own.scheduler_comm.comm.abort)

        timer = threading.Timer(0.5, cut)
        timer.start()
        try:
            summary = run_jobs(jobs, tmp_path / "out", kind="smooth", settings={}, client=own)
        finally:
            timer.cancel()
        address = own.scheduler.address
    assert [e["status"] for e in summary.entries] == ["failed", "failed"]
    assert {e["error"] for e in summary.entries} == {
        f"the connection to the scheduler at {address} was lost before this file finished (the "
        "scheduler stopped, or the network failed; a re-run does the rest)"
    }


def _started_then_slow(marker: str, seconds: float) -> TaskResult:
    """A task that says it has started (a file), then takes `seconds`."""
    Path(marker).write_text("")
    time.sleep(seconds)
    return TaskResult(np.zeros((0, 10)), {}, {})


@pytest.mark.slow
@pytest.mark.filterwarnings("always:the scheduler at")
def test_a_scheduler_frozen_mid_run_fails_the_tasks_left(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, no_workers_timeout_1s: None
) -> None:
    """A scheduler frozen mid-run (stopped with SIGSTOP, a machine swapping): the batch
    waited for it for ever, saying nothing."""
    from pftrack.batch import engine

    dask = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    if dask is None or not hasattr(signal, "SIGSTOP"):
        pytest.skip("needs the dask command and SIGSTOP")
    monkeypatch.setattr(engine, "ANSWER_WAIT", 0.5)
    address = f"tcp://127.0.0.1:{_free_port()}"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    http = ["--dashboard-address", "127.0.0.1:0"]
    with (tmp_path / "logs.txt").open("w") as log:
        run = functools.partial(subprocess.Popen, stdout=log, stderr=log, env=env, cwd=tmp_path)
        procs = [run([dask, "scheduler", "--host", "127.0.0.1", "--port",
                      address.rpartition(":")[2], *http])]  # fmt: skip
        try:
            procs.append(run([dask, "worker", address, "--nthreads", "1", *http]))
            with distributed.Client(address, timeout="30s") as c:
                c.wait_for_workers(1, timeout=30)
            marker = tmp_path / "started"
            jobs = [Job(f"t{k}", _started_then_slow, (str(marker), 3.0), ()) for k in range(2)]

            def freeze() -> None:
                deadline = time.monotonic() + 30
                while not marker.exists() and time.monotonic() < deadline:
                    time.sleep(0.02)
                procs[0].send_signal(signal.SIGSTOP)

            threading.Thread(target=freeze, daemon=True).start()
            start = time.monotonic()
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always")
                summary = run_jobs(
                    jobs, tmp_path / "out", kind="smooth", settings={}, scheduler=address
                )
            assert time.monotonic() - start < 20
        finally:
            for p in procs:
                p.send_signal(signal.SIGCONT)  # a stopped scheduler cannot take SIGTERM
            _stop_processes(procs)
    assert [e["status"] for e in summary.entries] == ["failed", "failed"]
    assert {e["error"] for e in summary.entries} == {
        f"the scheduler at {address} did not answer for 1 s (frozen or overloaded) before this "
        "file finished (a re-run does the rest)"
    }
    # a loaded machine's scheduler may also be slow once before the freeze: said again then,
    # and that it answered again in between
    slow = (
        f"the scheduler at {address} has not answered for 0.5 s (frozen or overloaded?); "
        "waiting up to 1 s for it"
    )
    back = f"the scheduler at {address} answers again after N s; the batch goes on"
    assert slow in {str(w.message) for w in said}
    assert {re.sub(r"after \d+ s", "after N s", str(w.message)) for w in said} <= {slow, back}


def _lost_once(monkeypatch: pytest.MonkeyPatch, marker: str) -> set[str]:
    """Make the status of each future whose key holds `marker` read "lost" once, where
    ``_run_on_dask`` looks (its result lost with its worker, computed again); returns the keys
    that did."""
    seen: set[str] = set()
    real = distributed.Future.status

    def status(self: Any) -> str:
        looker = sys._getframe(1).f_code.co_name
        if looker == "_run_on_dask" and marker in self.key and self.key not in seen:
            seen.add(self.key)
            return "lost"
        return str(real.fget(self))

    monkeypatch.setattr(distributed.Future, "status", property(status))
    return seen


def test_a_result_lost_with_its_worker_is_waited_for_not_dropped(
    client: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A task finished, then its worker died before the client took its result (a crash, the
    OOM killer): Dask computes it again, and its future is "lost", then "pending", where the
    client looked. Was: the task left out, "cancelled" in the summary, its outputs never
    written, and no failure counted (exit status 0 if the others were done); 2 runs in 6 of
    a batch whose first task killed its worker. Here its status reads "lost" once, where the
    batch looks."""
    seen = _lost_once(monkeypatch, "-slow1-")
    jobs = [Job(f"slow{k}", _slow, (k,), ()) for k in range(2)]
    summary = run_jobs(jobs, tmp_path / "out", kind="smooth", settings={}, client=client)
    assert seen
    assert [e["status"] for e in summary.entries] == ["done", "done"]
    assert sorted(p.name for p in (tmp_path / "out").glob("*.txt")) == ["slow0.txt", "slow1.txt"]


def _close_worker(dask_worker: Any) -> None:
    """On a worker: close it and its nanny (not restarted), once this call has answered."""
    dask_worker.loop.add_callback(dask_worker.close, nanny=True, reason="test: result lost")


def test_a_result_lost_with_the_last_worker_is_not_waited_for_for_ever(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Seen once: a task finished, the batch went to take its result, and the worker holding it
    died meanwhile, no worker left ("Couldn't gather 1 keys, rescheduling"): the batch waited
    for ever on ``Future.result()``. Here the one worker of the cluster closes as the batch
    takes the result (reliably: between the batch seeing it finished and the gather). The
    wait is bounded and watched like the others: the task fails after the wait for a worker."""
    import dask

    import pftrack.batch.engine as engine

    # the scheduler (this process's) slow to answer at load 20 is not what is tested here
    monkeypatch.setattr(engine, "ANSWER_WAIT", LOST_WAIT_BOUND)
    unbounded: list[object] = []
    lost: list[float] = []  # when its worker was gone
    real = distributed.Future.result

    def result(self: Any, timeout: Any = None) -> Any:
        caller = sys._getframe(1).f_globals.get("__name__")
        if caller == "pftrack.batch.engine" and "-first-" in self.key:
            if not unbounded:  # the first look: its worker dies now, before the gather
                unbounded.append(timeout)
                self.client.run(_close_worker)
                deadline = time.monotonic() + 120  # a bound against a hang, not a timing
                while cluster.scheduler.workers and time.monotonic() < deadline:
                    time.sleep(0.05)
                assert not cluster.scheduler.workers
                lost.append(time.monotonic())
            if timeout is None:  # the code before: waited for ever, here 10 s then failed
                unbounded.append(None)
                timeout = 10
        return real(self, timeout=timeout)

    monkeypatch.setattr(distributed.Future, "result", result)
    setting = {"distributed.scheduler.no-workers-timeout": "1s"}
    with contextlib.ExitStack() as stack:
        cluster = stack.enter_context(distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
            scheduler_kwargs=NO_DASHBOARD,
        ))  # fmt: skip
        stack.enter_context(dask.config.set(setting))
        address = cluster.scheduler_address
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary = run_jobs(
                [Job("first", _empty, (0,), ())], tmp_path, kind="smooth", settings={},
                scheduler=address,
            )  # fmt: skip
        # from the loss (was: < 10 s from the batch's start, the cluster's checks included,
        # which a machine at load 20 exceeded): the wait of 1 s, not the 10 s of an unbounded
        # result() above, nor for ever
        took = time.monotonic() - lost[0]
    assert unbounded and None not in unbounded, "the result was waited for without a bound"
    assert took < 10
    assert [str(w.message) for w in caught] == [
        f"the scheduler at {address} has lost all its workers; waiting up to 1 s for one "
        f"(start one: dask worker {address})"
    ]
    (entry,) = summary.entries
    assert entry["status"] == "failed"
    assert entry["error"] == (
        f"no worker on the scheduler at {address} for 1 s: its workers were lost before this "
        f"file ran or finished (start some: dask worker {address}; a re-run does the rest)"
    )
    assert json.loads((tmp_path / "summary.json").read_text())["counts"]["failed"] == 1
    # the totals said "1 worker at ADDR" (the count at the start) of a worker that ran no task
    # to the end: now what is true, and summary.json's "workers" 0, as no worker ran one
    assert summary.table().splitlines()[2] == (
        f"1 file: 1 failed; {summary.seconds:.1f} s, no worker at {address} finished a task"
    )
    assert summary.workers == 0
    assert json.loads((tmp_path / "summary.json").read_text())["workers"] == 0


@pytest.mark.parametrize(
    ("workers", "scheduler", "statuses", "where"),
    [
        (2, "tcp://h:8786", ["done", "failed"], "2 workers at tcp://h:8786"),
        (0, "tcp://h:8786", ["failed", "failed"], "no worker at tcp://h:8786 finished a task"),
        (0, "tcp://h:8786", ["done", "cancelled"], "no worker at tcp://h:8786 finished a task"),
        (3, None, ["done", "done"], "3 workers"),
        (0, None, ["done", "failed"], "in this process"),
        (0, None, ["skipped", "skipped"], "nothing to run"),
    ],
)
def test_the_totals_line_says_where_tasks_ran(
    workers: int, scheduler: str | None, statuses: list[str], where: str
) -> None:
    """With every worker of a scheduler lost before a task came back, the totals line said
    "2 workers at ADDR": the count at the start, of workers that ran nothing."""
    entries = [{"name": f"s{k}", "status": st, "error": "x"} for k, st in enumerate(statuses)]
    summary = BatchSummary("smooth", Path("out"), entries, 1.25, workers, scheduler)
    counts = ", ".join(f"{statuses.count(st)} {st}" for st in dict.fromkeys(statuses))
    assert summary.table().splitlines()[len(entries) + 1] == f"2 files: {counts}; 1.2 s, {where}"


class _FakeFuture:
    """A future seen finished whose result comes after `slow` waits that time out."""

    def __init__(self, slow: int, status: str = "finished") -> None:
        self.slow, self.status = slow, status
        self.waits: list[float] = []

    def result(self, timeout: float | None = None) -> str:
        assert timeout is not None, "no bound"
        self.waits.append(timeout)
        if len(self.waits) <= self.slow:
            raise TimeoutError(f"timed out after {timeout} s.")
        return "rows"


def test_a_finished_result_is_taken_in_bounded_steps(monkeypatch: pytest.MonkeyPatch) -> None:
    """The wait for a result is bounded, watched between its steps, and each step twice as long
    (a step that times out cancels Dask's gather: a large result still comes)."""
    from pftrack.batch import engine

    monkeypatch.setattr(engine, "RESULT_WAIT", 0.5)
    fut = _FakeFuture(slow=3)
    assert engine._taken(fut, lambda: False) == ("finished", "rows")
    assert fut.waits == [0.5, 1.0, 2.0, 4.0]
    fut = _FakeFuture(slow=10)
    looks = iter([False, True])
    assert engine._taken(fut, lambda: next(looks)) == ("given up", None)
    assert fut.waits == [0.5, 1.0]
    fut = _FakeFuture(slow=10, status="pending")  # lost with its worker: computed again
    assert engine._taken(fut, lambda: False) == ("lost", None)
    assert fut.waits == [0.5]


def test_the_file_bar_counts_a_task_computed_again_once(
    client: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A trial: the files' bar of a recover batch ended at 4/3 when a task's result was lost and
    computed again (or a task was sent again from a worker blind to its inputs): each time its
    future came back, it counted. It counts each file once, when it is recorded."""
    from pftrack import _progress

    monkeypatch.setattr(_progress, "DELAY", 0.0)
    monkeypatch.setattr(_progress, "_quiet", False)
    bars: list[Any] = []
    real_tqdm = _progress._tqdm
    monkeypatch.setattr(
        _progress, "_tqdm", lambda *a, **k: bars.append(real_tqdm(*a, **k)) or bars[-1]
    )
    seen = _lost_once(monkeypatch, "-slow1-")
    jobs = [Job(f"slow{k}", _slow, (k,), ()) for k in range(2)]
    summary = run_jobs(
        jobs, tmp_path / "out", kind="smooth", settings={}, client=client, show_progress=True
    )
    assert seen
    assert [e["status"] for e in summary.entries] == ["done", "done"]
    (bar,) = bars
    assert (bar.n, bar.total) == (2, 2)


def test_the_table_leaves_the_problems_to_stderr(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Warnings and errors were printed among stdout's table: a script parsing it broke."""
    summary = BatchSummary(kind="smooth", out_dir=tmp_path, settings={"max_gap": 10})
    summary.entries = [
        {"name": "a", "status": "done", "ids_in": 2, "warnings": ["odd", "odder"]},
        {"name": "b", "status": "failed", "error": "cannot read"},
    ]
    problems = ["a: warning: odd", "a: warning: odder", "b: error: cannot read"]
    assert summary.problems() == problems
    assert summary.table().splitlines()[-3:] == problems  # the library's table keeps them
    assert summary.table(problems=False).splitlines() == summary.table().splitlines()[:-3]
    # a recover batch prints them on stderr, its table alone on stdout
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "bad.txt").write_text("not,a,row\n")
    write_mot(folder / "fine.txt", np.array([[1, 1, 10, 10, 20, 40, 1, -1, -1, -1]], float))
    out = tmp_path / "out"
    assert main(["recover", str(folder), "--out", str(out), "--workers", "0"]) == 1
    printed = capsys.readouterr()
    assert printed.err.startswith("bad: error: ") and printed.err.count("\n") == 1
    assert ": error:" not in printed.out and printed.out.startswith("name ")


def test_track_sequence_scores_by_the_benchmark_its_trackeval_folder_names(
    tmp_path: Path,
) -> None:
    """A sequence under TrackEval's ``MOT20-train`` is scored by MOT20's rules, as ``pftrack
    eval`` scores it (was: guessed from the columns, MOT17 for 9-column ground truth)."""
    from pftrack.batch.tasks import track_sequence

    scene = make_scene(n_frames=20, width=160, height=120, n_walkers=2, rng=0)
    gt = scene.truth.copy()
    gt[:, 7] = 1.0  # class: pedestrian
    gt[:, 8] = 1.0  # visibility: MOT16/17/20 ground truth by its columns
    for split in ("MOT20-train", "plain"):
        seq = tmp_path / split / "SEQ-01"
        scene.write_images(seq / "img1", ext=".png")
        (seq / "gt").mkdir()
        write_mot(seq / "gt" / "gt.txt", gt[:, :9])
        (seq / "seqinfo.ini").write_text("[Sequence]\nname=SEQ-01\nimWidth=160\nimHeight=120\n")
        (found,) = find_sequences(seq)
        result = track_sequence(found, TrackOptions(config=_config()))
        assert result.error is None
        expected = "MOT20" if split == "MOT20-train" else "MOT17"
        assert result.info["metrics"]["benchmark"] == expected
        rows = read_mot(seq / "gt" / "gt.txt")  # the figures are pftrack eval's under those rules
        want = evaluate_sequence(rows, result.rows, benchmark=expected)
        assert result.info["metrics"]["idf1"] == pytest.approx(want.mot.idf1, abs=0.01)


def test_tracks_files_deeper_than_the_folder_are_named(tmp_path: Path) -> None:
    """A trial's "left": ``pftrack recover trackers/`` with TrackEval's
    ``trackers/NAME/data/SEQ.txt`` said only "no .txt file in folder trackers"."""
    data = tmp_path / "trackers" / "mine" / "data"
    data.mkdir(parents=True)
    for name in ("a", "b", "c", "d"):
        (data / f"{name}.txt").write_text("1,1,10,10,20,40,1,-1,-1,-1\n")
    (tmp_path / "trackers" / ".hidden").mkdir()
    (tmp_path / "trackers" / ".hidden" / "x.txt").write_text("")
    with pytest.raises(
        ValueError,
        match=rf"^no \.txt file in folder {re.escape(str(tmp_path / 'trackers'))}; "
        rf"{re.escape(str(data))} holds 4 \(a\.txt, b\.txt, c\.txt, \.\.\.\): pass it instead$",
    ):
        find_track_files([tmp_path / "trackers"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match=r"^no \.txt file in folder .*empty$"):
        find_track_files([tmp_path / "empty"])
    assert [p.stem for p in find_track_files([data])] == ["a", "b", "c", "d"]


def test_trackeval_summaries_beside_the_data_are_not_tracks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial: ``pftrack recover trackers/mine`` after TrackEval had scored it (which writes
    ``pedestrian_summary.txt`` beside ``data/``) read the summary as tracks and failed its
    task with "a header line? delete it", the tracks in ``data/`` not said. The summary is
    passed over with a warning, and the refusal names ``data/``; any other .txt is read."""
    tracker = tmp_path / "trackers" / "mine"
    data = tracker / "data"
    data.mkdir(parents=True)
    (data / "SEQ.txt").write_text("1,1,10,10,20,40,1,-1,-1,-1\n")
    summary = tracker / "pedestrian_summary.txt"  # as TrackEval 1.3.0 writes it, shortened
    summary.write_text("HOTA DetA AssA MOTA MOTP IDF1\n96.744 96.69 96.798 99.164 98.3 99.58\n")
    with pytest.warns(UserWarning, match="pedestrian_summary.txt is TrackEval's summary"):
        with pytest.raises(
            ValueError,
            match=rf"^no tracks file in folder {re.escape(str(tracker))} \(only TrackEval's "
            rf"summaries of scores\); {re.escape(str(data))} holds 1 \(SEQ\.txt\): pass it "
            "instead$",
        ):
            find_track_files([tracker])
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as a user's shell: the command prints it
        assert main(["recover", str(tracker), "--out", str(out), "--workers", "0"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and err[0].endswith("summary of scores, not tracks: passed over")
    assert err[1].startswith("pftrack recover: error: no tracks file in folder ")
    assert not out.exists()
    (tracker / "SEQ2.txt").write_text("1,1,10,10,20,40,1,-1,-1,-1\n")
    with pytest.warns(UserWarning, match="passed over"):
        assert [p.name for p in find_track_files([tracker])] == ["SEQ2.txt"]
    summary.write_text("1,1,10,10,20,40\n")  # tracks named so are tracks
    assert [p.name for p in find_track_files([tracker])] == [summary.name, "SEQ2.txt"]


def test_render_of_frames_too_wide_for_h264_keeps_the_tracks(tmp_path: Path) -> None:
    """A user trial: ``batch --render`` of 16400-pixel-wide frames tracked the sequence, then
    failed on the .mp4 writer (naming a temporary file): the tracks were lost. ``track
    --render`` refuses such a size before work; here the tracks are written, the video not,
    and the sequence fails saying why."""
    folder = tmp_path / "wide" / "img1"
    folder.mkdir(parents=True)
    for k in range(1, 4):
        frame = np.full((32, 16400, 3), 100, np.uint8)
        frame[8:24, 100 * k : 100 * k + 8] = 250
        cv2.imwrite(str(folder / f"{k:06d}.png"), frame)
    out = tmp_path / "out"
    options = TrackOptions(config=_config(), render=".mp4")
    entry = track_many(tmp_path / "wide", out, options=options, n_workers=0).entries[0]
    assert entry["status"] == "failed"
    assert entry["error"] == (
        "--render wide.mp4: H.264 takes frames up to 16384 pixels a side (x264), not 16400x32; "
        "write an .avi (Motion-JPEG) instead (pftrack render can draw wide.txt, which is "
        "written, into one)"
    )
    assert (out / "wide.txt").is_file() and not (out / "wide.mp4").exists()
