"""A ``seqinfo.ini`` that is a folder, in Latin-1, or of another size than its frames.

* A folder named ``seqinfo.ini`` was passed over as if there were none (the sequence's frame
  rate and size unused, without a word); it is now refused, one line naming it, exit 2: what
  it should hold changes the run, and a folder by that name is a mistake to mend.
* A ``seqinfo.ini`` saved in Latin-1 / Windows-1252 (Notepad's "ANSI") with ``imDir=café``: its
  undecodable byte was replaced, so the image folder was ``caf\\ufffd``, which "does not
  exist" beside ``café`` (exit 2). It is now read in that encoding and the folder found.
* A ``seqinfo.ini`` saying 1.25 times its frames' size (frames 640x480, ``imWidth=800``) beside
  a det.txt in the frames' pixels scaled the boxes by 0.8 with only a note, exit 0: refused now
  (tracking.run's ``_at_edges``: the boxes as given reach the frames' right and bottom edges),
  and the rule leaves every real sequence's det.txt in its seqinfo.ini's pixels scaled onto
  frames of 0.5 to 0.99 times that size (docs/robustness.md). A ``--det-scale 0.8`` the user
  gives, seqinfo.ini's ratio, was refused the same way; it is taken now (the user's word).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.video import find_sequence, read_seqinfo
from pftrack.tracking.run import (
    EDGE_MAX_SCALE,
    SeqinfoScale,
    _check_layout,
    _Scaled,
    load_detections,
)
from tests.conftest import dataset

INI = (
    "[Sequence]\nname={name}\nimDir={im_dir}\nframeRate=25\nseqLength=3\nimWidth=64\nimHeight=48\n"
)


def _images(folder: Path, n: int = 3) -> None:
    folder.mkdir(parents=True)
    for k in range(1, n + 1):
        frame = np.full((48, 64, 3), 40 * k, np.uint8)
        assert cv2.imwrite(str(folder / f"{k:06d}.jpg"), frame)


def test_a_folder_named_seqinfo_ini_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seq = tmp_path / "SEQ"
    _images(seq / "img1")
    (seq / "seqinfo.ini").mkdir()
    said = f"{seq / 'seqinfo.ini'}: is a folder, expected the sequence's seqinfo.ini text file"
    with pytest.raises(ValueError, match=f"^{said}"):
        find_sequence(seq)
    with pytest.raises(ValueError, match=f"^{said}"):
        read_seqinfo(seq)
    assert main(["-q", "track", str(seq), "--out", str(tmp_path / "t.txt")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pftrack track: error: {said}") and err.count("\n") == 1, err
    assert not (tmp_path / "t.txt").exists()


@pytest.mark.parametrize("encoding", ["latin-1", "cp1252", "utf-8", "utf-8-sig"])
def test_a_non_ascii_im_dir_is_read_in_the_file_s_encoding(tmp_path: Path, encoding: str) -> None:
    seq = tmp_path / "SEQ"
    _images(seq / "café")
    text = INI.format(name="Café – 2", im_dir="café")
    if encoding == "latin-1":
        text = text.replace("–", "-")  # not in Latin-1
    (seq / "seqinfo.ini").write_bytes(text.encode(encoding))
    info = read_seqinfo(seq)
    assert info.image_dir == "café"
    assert info.name == ("Café - 2" if encoding == "latin-1" else "Café – 2")
    assert main(["-q", "track", str(seq), "--out", str(tmp_path / "t.txt")]) == 0


def _tud_as_800x600(tmp_path: Path) -> Path:
    """A TUD-Campus sequence folder (its det.txt and video) whose seqinfo.ini says 800x600."""
    tud = dataset("tud-campus")
    seq = tmp_path / "tud125"
    seq.mkdir()
    shutil.copy(tud / "det.txt", seq / "det.txt")
    (seq / "video.mp4").symlink_to(tud / "video.mp4")
    ini = (tud / "seqinfo.ini").read_text()
    (seq / "seqinfo.ini").write_text(
        ini.replace("imWidth=640", "imWidth=800").replace("imHeight=480", "imHeight=600")
    )
    return seq


def test_a_seqinfo_larger_than_its_frames_beside_their_detections_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was a strict xfail (left61): scaled by 0.8 with a note only, exit 0 (5 tracks, 118
    boxes). Refused now, naming both sizes; --det-scale 1 takes the boxes as given."""
    seq = _tud_as_800x600(tmp_path)
    argv = ["-q", "track", str(seq), "--detections", str(seq / "det.txt"),
            "--out", str(tmp_path / "t.txt")]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not (tmp_path / "t.txt").exists(), err
    n = len(np.loadtxt(seq / "det.txt", delimiter=","))
    assert err == (
        f"pftrack track: error: all {n} detection boxes, scaled by 0.8 (the frames' width 640 "
        f"over imWidth=800 in {seq / 'seqinfo.ini'}), stop at 511x378, short of the 640x480 "
        "frames' right and bottom edges by the scale, and as given they reach those edges "
        "(they reach 639x472): they are in the frames' pixels already: seqinfo.ini's 800x600 "
        "is not its images' size? correct it to 640x480 (gt.txt is scaled by it too), or give "
        "--det-scale 1 / load_detections(scale=1)\n"
    )
    assert main([*argv, "--det-scale", "1"]) == 0
    assert main([*argv, "--det-scale", "0.7"]) == 0  # another scale than seqinfo's: the user's


def test_a_det_scale_stated_equal_to_seqinfo_s_ratio_is_taken(tmp_path: Path) -> None:
    """Was refused as the automatic scale 0.8 is above (left61, frames61): a user who states
    the scale seqinfo.ini gives says the boxes are in its pixels; only the scale nobody gave is
    doubted. The Python API alike: load_detections(scale=0.8) is stated."""
    seq = _tud_as_800x600(tmp_path)
    out = tmp_path / "t.txt"
    argv = ["-q", "track", str(seq), "--detections", str(seq / "det.txt"), "--out", str(out)]
    assert main([*argv, "--det-scale", "0.8"]) == 0
    rows = np.loadtxt(out, delimiter=",", ndmin=2)
    assert len(rows) and (rows[:, 2] + rows[:, 4]).max() < 540  # scaled by 0.8: reach 511
    info = read_seqinfo(seq)
    for scale, refused in ((0.8, False), (SeqinfoScale(0.8), True)):
        dets = load_detections(seq / "det.txt", scale)
        assert getattr(dets, "stated", None) is not refused
        if refused:
            with pytest.raises(ValueError, match="they are in the frames' pixels already"):
                _check_layout(dets, (480, 640, 3), info)
        else:
            _check_layout(dets, (480, 640, 3), info)


@pytest.mark.parametrize(
    "name",
    ["pets09-s2l1", "tud-campus", "mot15-gt/ADL-Rundle-6", "mot15-gt/ETH-Sunnyday",
     "mot15-gt/KITTI-17"],
)  # fmt: skip
def test_the_edge_rule_on_every_real_det_txt(name: str) -> None:
    """Each real det.txt (in its seqinfo.ini's pixels) on frames 0.5-0.99 times that size, as a
    downscaled video has them: taken with the scale, never refused. The same boxes rewritten in
    the frames' pixels, seqinfo.ini kept (the case refused above): refused up to a scale of
    0.95 (EDGE_MAX_SCALE; above it the scale moves boxes by under 5 % and is taken)."""
    folder = dataset(name)
    info = read_seqinfo(folder)
    assert info.width is not None and info.height is not None
    for s in (0.5, 0.625, 0.75, 0.8, 0.9, 0.94, 0.96, 0.99):
        cols, rows = round(info.width * s), round(info.height * s)
        applied = cols / info.width
        own = load_detections(folder / "det.txt", applied)
        _check_layout(own, (rows, cols, 3), info)  # not refused
        in_frames = dict(load_detections(folder / "det.txt", applied**2))
        auto = _Scaled(in_frames, applied, stated=False)  # seqinfo.ini's, as pftrack track's
        if applied <= EDGE_MAX_SCALE:
            with pytest.raises(ValueError, match="they are in the frames' pixels already"):
                _check_layout(auto, (rows, cols, 3), info)
        else:
            _check_layout(auto, (rows, cols, 3), info)
        stated = _Scaled(in_frames, applied)  # --det-scale: taken, but at 0.5 (all boxes in
        if s == 0.5:  # the top-left quarter: refused whoever gave the scale)
            with pytest.raises(ValueError, match="lie in the top-left"):
                _check_layout(stated, (rows, cols, 3), info)
        else:
            _check_layout(stated, (rows, cols, 3), info)
