"""A ``seqinfo.ini`` that is a folder, in Latin-1, or of another size than its frames.

* A folder named ``seqinfo.ini`` was passed over as if there were none (the sequence's frame
  rate and size unused, without a word); it is now refused, one line naming it, exit 2: what
  it should hold changes the run, and a folder by that name is a mistake to mend.
* A ``seqinfo.ini`` saved in Latin-1 / Windows-1252 (Notepad's "ANSI") with ``imDir=café``: its
  undecodable byte was replaced, so the image folder was ``caf\\ufffd``, which "does not
  exist" beside ``café`` (exit 2). It is now read in that encoding and the folder found.
* A ``seqinfo.ini`` saying 1.25 times its frames' size (frames 640x480, ``imWidth=800``) beside
  a det.txt in the frames' pixels scales the boxes by 0.8 with only a note: not fixed here (the
  check is tracking.run's, another helper's file); a strict xfail (docs/robustness.md).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.video import find_sequence, read_seqinfo
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


@pytest.mark.xfail(
    strict=True,
    reason="seqinfo.ini 1.25x its frames beside a det.txt in the frames' pixels is scaled by "
    "0.8 with a note only; the rule (det.txt boxes as given reach the frames' right and bottom "
    "edges, as every det.txt here reaches >= 98% of imWidth and imHeight) belongs in "
    "tracking.run's _refuse_scaled_off (docs/robustness.md)",
)
def test_a_seqinfo_larger_than_its_frames_beside_their_detections_is_refused(
    tmp_path: Path,
) -> None:
    tud = dataset("tud-campus")
    seq = tmp_path / "tud125"
    seq.mkdir()
    shutil.copy(tud / "det.txt", seq / "det.txt")
    (seq / "video.mp4").symlink_to(tud / "video.mp4")
    ini = (tud / "seqinfo.ini").read_text()
    (seq / "seqinfo.ini").write_text(
        ini.replace("imWidth=640", "imWidth=800").replace("imHeight=480", "imHeight=600")
    )
    argv = ["-q", "track", str(seq), "--detections", str(seq / "det.txt"),
            "--out", str(tmp_path / "t.txt")]  # fmt: skip
    assert main(argv) == 2
