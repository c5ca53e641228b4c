"""A MOTChallenge sequence whose images are numbered from 0 is refused with a way out.

A user's trial at stop 73: a sequence folder (``seqinfo.ini``, ``img1/000000.jpg`` ..) dumped
by a decoder's index was refused as ``image 000000 is not a frame (names 000000..000039 are
frame numbers; a MOTChallenge sequence's frames start at 1)``, without saying what to do.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.video import FrameSource


def sequence(folder: Path, numbers: range) -> Path:
    (folder / "img1").mkdir(parents=True)
    for n in numbers:
        cv2.imwrite(str(folder / "img1" / f"{n:06d}.png"), np.full((48, 64, 3), n, np.uint8))
    (folder / "seqinfo.ini").write_text(
        f"[Sequence]\nname={folder.name}\nimDir=img1\nframeRate=10\nseqLength={len(numbers)}\n"
        "imWidth=64\nimHeight=48\nimExt=.png\n"
    )
    return folder


def test_images_from_0_are_told_how_to_number_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seq = sequence(tmp_path / "SEQ", range(0, 5))
    with pytest.raises(ValueError) as err:
        FrameSource(seq)
    assert str(err.value) == (
        f"{seq / 'img1'}: image 000000 is not a frame (names 000000..000004 are frame numbers; "
        "a MOTChallenge sequence's frames start at 1: numbered from 0? rename each image to "
        "its number plus 1 (000000.png to 000001.png, ...) and add 1 to the frames of its "
        "det.txt and gt.txt, which number the frames by the names)"
    )
    assert main(["-q", "track", str(seq), "--out", str(tmp_path / "t.txt")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
    # the mend as said: the renamed images are read, frame 1 the former 000000
    for n in range(4, -1, -1):
        (seq / "img1" / f"{n:06d}.png").rename(seq / "img1" / f"{n + 1:06d}.png")
    assert [int(f[0, 0, 0]) for f in FrameSource(seq)] == [0, 1, 2, 3, 4]


def test_a_negative_first_image_gets_no_such_mend(tmp_path: Path) -> None:
    seq = sequence(tmp_path / "SEQ", range(0, 3))
    (seq / "img1" / "000000.png").rename(seq / "img1" / "-1.png")
    with pytest.raises(ValueError, match=r"image -1 is not a frame \(.*start at 1\)$"):
        FrameSource(seq)
