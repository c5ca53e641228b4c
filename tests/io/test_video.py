"""Frame sources: image folders in natural order, MOTChallenge sequences, live streams."""

from __future__ import annotations

import itertools
import os
import re
import threading
import time
import warnings
from fractions import Fraction
from pathlib import Path
from typing import Any

import av
import cv2
import numpy as np
import pytest

from pftrack.io import video
from pftrack.io.video import (
    FrameSequence,
    FrameSource,
    is_live_source,
    natural_key,
    read_seqinfo,
)
from pftrack.synthetic import make_scene
from tests.conftest import dataset
from tests.io.decode import capture_frames
from tests.io.encode import encode
from tests.io.streaming import serve_stream


def test_natural_key_orders_numbers_as_numbers() -> None:
    names = ["10.jpg", "2.jpg", "1.jpg", "frame_11.png", "frame_9.png", "1b.jpg", "1a.jpg"]
    assert sorted(names, key=natural_key) == [
        "1.jpg", "1a.jpg", "1b.jpg", "2.jpg", "10.jpg", "frame_9.png", "frame_11.png"
    ]  # fmt: skip


def test_unpadded_image_folder_plays_in_order(tmp_path: Path) -> None:
    """Frame k carries the grey level k: read back, the levels must come out 1, 2, ..., 12."""
    for k in range(1, 13):
        cv2.imwrite(str(tmp_path / f"{k}.png"), np.full((8, 8, 3), k, np.uint8))
    levels = [int(frame[0, 0, 0]) for frame in FrameSource(tmp_path)]
    assert levels == list(range(1, 13))


def _sequence(root: Path, n: int = 12, *, rate: str = "7", im_dir: str = "img1") -> Path:
    """A MOTChallenge sequence folder: seqinfo.ini, unpadded images, det/det.txt."""
    (root / im_dir).mkdir(parents=True)
    for k in range(1, n + 1):
        cv2.imwrite(str(root / im_dir / f"{k}.png"), np.full((8, 10, 3), k, np.uint8))
    (root / "seqinfo.ini").write_text(
        f"[Sequence]\nname=SEQ\nimDir={im_dir}\nframeRate={rate}\nseqLength={n}\n"
        "imWidth=10\nimHeight=8\nimExt=.png\n"
    )
    (root / "det").mkdir()
    (root / "det" / "det.txt").write_text("1,-1,1,1,3,3,0.9,-1,-1,-1\n")
    return root


def test_sequence_folder_follows_seqinfo(tmp_path: Path) -> None:
    seq = _sequence(tmp_path / "SEQ", im_dir="frames")
    src = FrameSource(seq)
    assert (src.fps, src.fps_origin, len(src)) == (7.0, "seqinfo.ini", 12)
    assert [int(f[0, 0, 0]) for f in src] == list(range(1, 13))
    assert src.sequence is not None and src.sequence.name == "SEQ"
    assert src.sequence.detections == seq / "det" / "det.txt"
    # its image folder given directly finds the same sequence one level up
    assert FrameSource(seq / "frames").fps_origin == "seqinfo.ini"


def test_fps_given_beats_seqinfo_and_header(tmp_path: Path) -> None:
    seq = _sequence(tmp_path / "SEQ")
    src = FrameSource(seq, fps=12.5)
    assert (src.fps, src.fps_origin) == (12.5, "given")
    with pytest.raises(ValueError, match="fps is 0"):
        FrameSource(seq, fps=0)


def grey_mjpg(path: Path, fps: float, width: int = 16, height: int = 8) -> Path:
    """Five flat frames (0, 40, ..., 160) as MJPG at a header rate of `fps`."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), fps, (width, height))
    for k in range(5):
        writer.write(np.full((height, width, 3), 40 * k, np.uint8))
    writer.release()
    return path


def test_video_beside_seqinfo_takes_its_frame_rate(tmp_path: Path) -> None:
    """PETS09's header says 10 fps, its seqinfo.ini 7: the sequence file wins."""
    video = grey_mjpg(tmp_path / "video.avi", 10.0)
    assert (FrameSource(video).fps, FrameSource(video).fps_origin) == (10.0, "container")
    (tmp_path / "seqinfo.ini").write_text("[Sequence]\nframeRate=7\n")
    assert (FrameSource(video).fps, FrameSource(video).fps_origin) == (7.0, "seqinfo.ini")


def _video_sequence(root: Path, n: int = 6) -> Path:
    """The layout of the shared data: seqinfo.ini (imDir=img1, absent), video.avi, det.txt."""
    root.mkdir(parents=True)
    writer = cv2.VideoWriter(
        str(root / "video.avi"), cv2.VideoWriter.fourcc(*"MJPG"), 10.0, (16, 8)
    )
    for k in range(n):
        writer.write(np.full((8, 16, 3), 40 * k, np.uint8))
    writer.release()
    (root / "seqinfo.ini").write_text(
        f"[Sequence]\nname=VSEQ\nimDir=img1\nframeRate=7\nseqLength={n}\nimWidth=16\n"
    )
    (root / "det.txt").write_text("1,-1,1,1,3,3,0.9,-1,-1,-1\n")
    return root


def test_sequence_folder_without_images_reads_its_one_video(tmp_path: Path) -> None:
    """``pftrack batch`` takes SEQ/seqinfo.ini + SEQ/video.avi; FrameSource(SEQ) reads the same."""
    seq = _video_sequence(tmp_path / "SEQ")
    src, direct = FrameSource(seq), FrameSource(seq / "video.avi")
    assert src.path == seq / "video.avi" and src.name == str(seq)
    assert (src.fps, src.fps_origin, len(src)) == (7.0, "seqinfo.ini", 6)  # the header says 10
    assert src.sequence is not None and src.sequence.name == "VSEQ"
    assert src.sequence.detections == seq / "det.txt"
    frames = list(src)
    assert len(frames) == 6 and all(
        np.array_equal(a, b) for a, b in zip(frames, direct, strict=True)
    )
    assert all(
        np.array_equal(a, b) for a, b in zip(src.frames_at([1, 4]), frames[1::3], strict=True)
    )
    (seq / "det").mkdir()
    (seq / "det" / "det.txt").write_text("")
    assert FrameSource(seq).sequence.detections == seq / "det" / "det.txt"  # type: ignore[union-attr]


def test_sequence_folder_without_images_needs_exactly_one_video(tmp_path: Path) -> None:
    seq = _video_sequence(tmp_path / "SEQ")
    (seq / "video.avi").rename(seq / "video.txt")
    message = r"SEQ/img1 does not exist and .*SEQ holds no video \(\.avi, .*\) to read instead$"
    with pytest.raises(ValueError, match=message):
        FrameSource(seq)
    (seq / "video.txt").rename(seq / "a.avi")
    (seq / "b.MP4").write_bytes((seq / "a.avi").read_bytes())
    with pytest.raises(ValueError, match=r"holds 2 videos \(a\.avi, b\.MP4\), not one"):
        FrameSource(seq)
    (seq / "b.MP4").unlink()
    (seq / "img1").mkdir()  # its image folder exists: read that, even empty (refused as before)
    with pytest.raises(ValueError, match="no images"):
        FrameSource(seq)


def test_video_suffixes_are_batchs() -> None:
    from pftrack.batch.inputs import VIDEO_SUFFIXES

    assert video.VIDEO_SUFFIXES == VIDEO_SUFFIXES


def test_image_folder_without_seqinfo_gets_the_default_rate(tmp_path: Path) -> None:
    cv2.imwrite(str(tmp_path / "1.png"), np.zeros((4, 4, 3), np.uint8))
    src = FrameSource(tmp_path)
    assert (src.fps, src.fps_origin, src.sequence) == (25.0, "default", None)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[Other]\nx=1\n", r"expected a \[Sequence\] section"),
        ("[Sequence]\nframeRate=fast\n", "frameRate"),
    ],
)
def test_bad_seqinfo_is_one_clear_error(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "seqinfo.ini").write_text(text)
    with pytest.raises(ValueError, match=message):
        read_seqinfo(tmp_path)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[Sequence]\nframeRate=7\nframeRate=8\n", r"key frameRate in \[Sequence\] is given "
         r"twice \(lines 2 and 3\); give it once$"),
        ("[Sequence]\nimWidth=7\nname=a\nIMWIDTH : 8\n", r"key imWidth in \[Sequence\] is "
         r"given twice \(lines 2 and 4\)"),
        ("\n[Sequence]\nframeRate=7\n[Sequence]\nseqLength=3\n", r"section \[Sequence\] is "
         r"given twice \(lines 2 and 4\)"),
    ],
)  # fmt: skip
def test_a_key_given_twice_is_named(tmp_path: Path, text: str, message: str) -> None:
    # was: "SEQ/seqinfo.ini: expected a [Sequence] section (MOTChallenge seqinfo.ini)"
    (tmp_path / "seqinfo.ini").write_text(text)
    with pytest.raises(ValueError, match=rf"^{re.escape(str(tmp_path))}/seqinfo.ini: {message}"):
        read_seqinfo(tmp_path)


@pytest.mark.parametrize("key", ["imWidth", "imHeight", "seqLength"])
@pytest.mark.parametrize("value", ["0.4", "0.3", "768.5", "1e-3"])
def test_a_fractional_size_or_length_is_refused(tmp_path: Path, key: str, value: str) -> None:
    # was: rounded silently (imWidth=0.4 became 0, taken as absent; seqLength=0.3 was refused
    # quoting "seqLength=0", a value the file does not hold)
    (tmp_path / "seqinfo.ini").write_text(f"[Sequence]\n{key} = {value}\n")
    with pytest.raises(ValueError, match=rf"seqinfo.ini: {key} is '{value}', expected an integer"):
        read_seqinfo(tmp_path)
    (tmp_path / "seqinfo.ini").write_text(f"[Sequence]\n{key}=768.0\n")  # a whole number
    info = read_seqinfo(tmp_path)
    assert {"imWidth": info.width, "imHeight": info.height, "seqLength": info.length}[key] == 768


@pytest.mark.parametrize("rate", ["1e9", "1000.5", "0.001", "0.0099"])
def test_a_frame_rate_outside_the_range_of_fps_is_refused(tmp_path: Path, rate: str) -> None:
    # was: taken (1e9: an MP4 at 1e9 fps; 0.001: 100 frames made a 28-hour video)
    (tmp_path / "seqinfo.ini").write_text(f"[Sequence]\nframeRate={rate}\n")
    message = rf"seqinfo.ini: frameRate is '{rate}', expected a frame rate in \[0.01, 1000\] "
    with pytest.raises(ValueError, match=message):
        read_seqinfo(tmp_path)
    for rate in ("0.01", "1000"):  # the bounds are in
        (tmp_path / "seqinfo.ini").write_text(f"[Sequence]\nframeRate={rate}\n")
        assert read_seqinfo(tmp_path).frame_rate == float(rate)


def test_seqinfo_keys_the_caller_does_not_use_are_not_checked(tmp_path: Path) -> None:
    """``pftrack eval`` and ``experiment gaps`` read the size only: ``frameRate=0`` refused them."""
    (tmp_path / "seqinfo.ini").write_text("[Sequence]\nframeRate=0\nimWidth=768\nseqLength=x\n")
    with pytest.raises(ValueError, match="frameRate is '0', expected a number > 0"):
        read_seqinfo(tmp_path)
    info = read_seqinfo(tmp_path, keys=("imWidth", "imHeight"))
    assert (info.width, info.height, info.frame_rate, info.length) == (768, None, None, None)
    with pytest.raises(ValueError, match="seqLength is 'x'"):
        read_seqinfo(tmp_path, keys=("imWidth", "seqLength"))
    with pytest.raises(ValueError, match="read_seqinfo: keys has 'width', expected some of name"):
        read_seqinfo(tmp_path, keys=("width",))


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ("imWidth", r"keys must be a collection of key names \(keys=\['imWidth'\] for one\), got "
         r"str 'imWidth'$"),
        (True, r"keys must be a collection of key names, got bool True$"),
        (3, r"keys must be a collection of key names, got int 3$"),
        ([["imWidth"]], r"keys\[0\] must be a str \(a key name\), got list \['imWidth'\]$"),
    ],
)  # fmt: skip
def test_seqinfo_keys_of_the_wrong_type_are_named(
    tmp_path: Path, keys: object, message: str
) -> None:
    """Were: keys has 'W', 'd', 'h', 'i', 'm', 't' (its letters), 'bool' object is not
    iterable, unhashable type: 'list'."""
    (tmp_path / "seqinfo.ini").write_text("[Sequence]\nimWidth=768\n")
    with pytest.raises(TypeError, match=rf"^read_seqinfo: {message}"):
        read_seqinfo(tmp_path, keys=keys)  # type: ignore[arg-type]


def test_seqinfo_with_a_byte_order_mark_is_read(tmp_path: Path) -> None:
    """Notepad's UTF-8 starts the file with a BOM; det/gt/results already skip it."""
    (tmp_path / "seqinfo.ini").write_bytes(b"\xef\xbb\xbf[Sequence]\nframeRate=7\nseqLength=3\n")
    info = read_seqinfo(tmp_path)
    assert (info.frame_rate, info.length) == (7.0, 3)


def _numbered(folder: Path, names: list[str]) -> Path:
    """Images `names` in `folder`, image i (0-based, in the order given) of grey level i + 1."""
    folder.mkdir(parents=True, exist_ok=True)
    for i, name in enumerate(names):
        cv2.imwrite(str(folder / name), np.full((8, 10, 3), i + 1, np.uint8))
    return folder


def test_a_missing_numbered_image_of_a_sequence_is_refused_not_shifted(tmp_path: Path) -> None:
    """In a sequence, image 000011 must not become frame 10: a hole is an error."""
    seq = tmp_path / "SEQ"
    names = [f"{k:06d}.png" for k in range(1, 61) if k != 10]
    _numbered(seq / "img1", names)
    (seq / "seqinfo.ini").write_text("[Sequence]\nimDir=img1\nframeRate=7\nseqLength=60\n")
    message = (
        r"img1: image 000010 is missing \(names 000001\.\.000060 are frame numbers; restore it: "
        r"the sequence's detections and ground truth number its frames by them\)$"
    )
    for source in (seq, seq / "img1"):
        with pytest.raises(ValueError, match=message):
            FrameSource(source)
    (seq / "img1" / "000002.png").rename(seq / "img1" / "2.png")  # 2 and 000002: one frame
    _numbered(seq / "img1", ["000002.png"])
    with pytest.raises(ValueError, match=r"images 000002.png and 2.png are both frame 2"):
        FrameSource(seq)


def test_a_plain_folder_whose_names_skip_numbers_is_read_in_their_order(tmp_path: Path) -> None:
    """Camera dumps named by millisecond time stamps, every fifth frame: was refused outright
    ('image 1690000000001 is missing'), while frame_1.png, frame_6.png, ... were read. Both are
    read now, frames 1..N in the names' order, and `gap` says what detections would be refused
    for."""
    stamps = [1690000000000 + 33 * k + k % 2 for k in range(6)]
    names = [f"{t}.png" for t in reversed(stamps)]  # image i (0-based) of level i + 1
    ms = _numbered(tmp_path / "ms", names)
    src = FrameSource(ms)
    assert _levels(ms) == [6, 5, 4, 3, 2, 1] and len(src) == 6
    assert src.gap == (
        f"{ms}: image 1690000000001 is missing (names 1690000000000..{stamps[-1]} skip numbers)"
    )
    cases = {
        "every5": (["1.png", "6.png", "11.png"], "image 2 is missing (names 1..11"),
        "padded": (["00001.png", "00003.png"], "image 00002 is missing (names 00001..00003"),
        "named": (["f5.png", "f10.png", "f15.png"], "image f6 is missing (names f5..f15"),
        "both": (["c_07_l.png", "c_09_l.png"], "image c_08_l is missing (names c_07_l..c_09_l"),
        "signed": (["-3.png", "0.png"], "image -2 is missing (names -3..0"),
    }
    for folder, (names, gap) in cases.items():
        src = FrameSource(_numbered(tmp_path / folder, names))
        assert _levels(tmp_path / folder) == [1, 2, 3][: len(names)]
        assert src.gap == f"{tmp_path / folder}: {gap} skip numbers)"
    # numbers that skip none, names that are not numbers, decimals (no frame numbers): no gap
    for folder, names in {
        "whole": ["0.png", "1.png", "2.png"],
        "frames": ["frame_9.png", "frame_10.png"],
        "mixed": ["cover.png", "frame_1.png", "frame_3.png"],
        "times": ["10.1.png", "10.3.png"],
        "one": ["7.png"],
    }.items():
        assert FrameSource(_numbered(tmp_path / folder, names)).gap is None, folder
    # a MOTChallenge sequence's own image folder has none: a gap there is an error (above)
    assert FrameSource(_sequence(tmp_path / "SEQ", n=3)).gap is None


def test_a_sequence_image_folder_is_numbered_from_1_to_seqlength(tmp_path: Path) -> None:
    seq = _sequence(tmp_path / "SEQ", n=5)
    assert [int(f[0, 0, 0]) for f in FrameSource(seq)] == [1, 2, 3, 4, 5]
    (seq / "img1" / "5.png").unlink()  # the last: only seqLength tells
    message = (
        r"SEQ/img1: image 5 is missing "
        r"\(names 1\.\.4 are frame numbers; seqinfo.ini says seqLength=5\)$"
    )
    for source in (seq, seq / "img1"):
        with pytest.raises(ValueError, match=message):
            FrameSource(source)
    (seq / "img1" / "1.png").rename(seq / "img1" / "5.png")  # 2..5: frame 1 is missing
    with pytest.raises(ValueError, match=r"SEQ/img1: image 1 is missing \(names 2\.\.5 are"):
        FrameSource(seq)
    _numbered(seq / "img1", ["0.png", "1.png", "6.png"])  # 0..6: seven images, and a frame 0
    with pytest.raises(ValueError, match=r"SEQ/img1: image 0 is not a frame \(names 0\.\.6 are"):
        FrameSource(seq)
    (seq / "img1" / "0.png").unlink()  # 1..6: one more than seqLength
    with pytest.raises(ValueError, match=r"SEQ/img1: 6 images \(1\.\.6\) but seqinfo.ini says"):
        FrameSource(seq)
    # without seqinfo.ini a folder may start anywhere (0-based dumps, a cut of a longer video)
    (seq / "seqinfo.ini").unlink()
    zero = _numbered(tmp_path / "zero", ["0.png", "1.png"])
    assert [int(f[0, 0, 0]) for f in FrameSource(zero)] == [1, 2]
    assert len(FrameSource(seq)) == 6


def test_a_sequences_stray_and_hidden_images_are_no_frames(tmp_path: Path) -> None:
    """A user trial: a cover.jpg in a sequence's img1/ became a 6th frame of a 5-frame sequence
    (and pftrack eval then refused the rows of frame 6); a viewer's .thumb.png did the same; a
    macOS ._1.png (no image) failed the folder."""
    seq = _sequence(tmp_path / "SEQ", n=5)
    cv2.imwrite(str(seq / "img1" / "cover.png"), np.full((8, 10, 3), 99, np.uint8))
    cv2.imwrite(str(seq / "img1" / ".thumb.png"), np.full((8, 10, 3), 98, np.uint8))
    (seq / "img1" / "._1.png").write_bytes(b"\x00\x05\x16\x07 AppleDouble")
    with pytest.warns(
        UserWarning,
        match=r"img1: 1 image whose name is not a frame number left "
        r"out \(cover.png\): a MOTChallenge sequence's frames are its numbered",
    ):
        assert _levels(seq) == [1, 2, 3, 4, 5]
    # SEQ/img1 without seqinfo.ini is still laid out as a sequence's (pftrack batch takes it so)
    (seq / "seqinfo.ini").unlink()
    with pytest.warns(UserWarning, match=r"img1: 1 image whose name is not a frame number"):
        assert len(FrameSource(seq)) == 5
    # outside a sequence the names are no frame numbers: the cover is a frame, hidden files not
    (seq / "img1").rename(seq / "frames")
    assert len(FrameSource(seq / "frames")) == 6


def test_numbered_and_named_folders_keep_their_order(tmp_path: Path) -> None:
    numbered = _numbered(tmp_path / "n", [f"{k:06d}.png" for k in (3, 1, 2)])
    assert [int(f[0, 0, 0]) for f in FrameSource(numbered)] == [2, 3, 1]  # 000001 is level 2
    # names that are not all numbers: natural order, gaps and all
    named = _numbered(tmp_path / "f", ["frame_10.png", "frame_2.png", "frame_5.png", "cover.png"])
    assert [int(f[0, 0, 0]) for f in FrameSource(named)] == [4, 2, 3, 1]


def _levels(folder: Path) -> list[int]:
    return [int(f[0, 0, 0]) for f in FrameSource(folder)]


def test_names_that_are_decimal_numbers_are_read_by_value(tmp_path: Path) -> None:
    """Was: 10.1, 10.2, 10.3, 10.4, 10.15, 10.25, ... (the digits after the point compared as
    whole numbers), silently."""
    times = ["10.1", "10.15", "10.2", "10.25", "10.3", "10.35", "10.4", "10.45"]
    assert _levels(_numbered(tmp_path / "s", [f"{t}.png" for t in times])) == list(range(1, 9))
    # with a prefix and a suffix all names share, and numbers of any length
    names = [f"t_{t}_left.png" for t in ("9.5", "9.75", "10", "10.125", "10.2", "100")]
    assert _levels(_numbered(tmp_path / "fix", names)) == list(range(1, 7))
    names = ["-1.5.png", "-1.25.png", "-1.png", "0.5.png"]  # decimals, signed
    assert _levels(_numbered(tmp_path / "neg", names)) == [1, 2, 3, 4]
    _numbered(tmp_path / "same", ["1.1.png", "1.10.png", "1.2.png"])  # 1.1 = 1.10
    with pytest.raises(ValueError, match="images 1.1.png and 1.10.png in folder .* the same"):
        FrameSource(tmp_path / "same")


def test_names_whose_numbers_read_two_ways_are_refused(tmp_path: Path) -> None:
    """cam1.2 and cam1.10: camera 1's frames 2 and 10, or times 1.2 and 1.10 of camera cam?"""
    _numbered(tmp_path / "two", ["cam1.2.png", "cam1.10.png", "cam1.3.png"])
    message = (
        r"images cam1\.2\.png and cam1\.10\.png in folder .*two come in one order if the "
        r"digits around a point in their names are two numbers and in the other if they are "
        r"one decimal number: which comes first is not known \(rename them"
    )
    with pytest.raises(ValueError, match=message):
        FrameSource(tmp_path / "two")
    # padded, both readings agree: read
    assert _levels(_numbered(tmp_path / "pad", ["cam1.02.png", "cam1.10.png"])) == [1, 2]


def test_a_leading_minus_of_a_name_that_is_a_number_is_its_sign(tmp_path: Path) -> None:
    """Was: 0, 1, -1 (the text '-' after every digit). In a name with text before the number,
    '-' is a separator: frame-2 is frame 2."""
    assert _levels(_numbered(tmp_path / "n", ["-2.png", "-1.png", "0.png", "1.png"])) == [
        1, 2, 3, 4
    ]  # fmt: skip
    names = ["frame-1.png", "frame-2.png", "frame-10.png"]
    assert _levels(_numbered(tmp_path / "f", names)) == [1, 2, 3]
    # in a sequence, -1 is no frame (its frames start at 1)
    seq = _sequence(tmp_path / "SEQ", n=3)
    _numbered(seq / "img1", ["-1.png"])
    with pytest.raises(ValueError, match=r"SEQ/img1: image -1 is not a frame \(names -1\.\.3"):
        FrameSource(seq)


def _sixteen_bit(folder: Path, tops: list[int]) -> list[np.ndarray]:
    """16-bit PNGs 1.png, 2.png, ... of a gradient up to each of `tops`; their pixels."""
    folder.mkdir(parents=True)
    ramp = np.linspace(0, 1, 40)[None, :, None] * np.linspace(0.5, 1, 3)[None, None, :]
    images = [np.repeat(np.round(ramp * top), 8, axis=0).astype(np.uint16) for top in tops]
    for k, image in enumerate(images, start=1):
        cv2.imwrite(str(folder / f"{k}.png"), image)
    return images


def test_16_bit_images_of_12_bit_data_are_read_at_their_depth(tmp_path: Path) -> None:
    """Was: values / 256, 0-15 for 12-bit data: almost black frames, without a word."""
    images = _sixteen_bit(tmp_path / "d12", [4000, 4095, 2000])
    src = FrameSource(tmp_path / "d12")
    assert src.bits == 12
    message = (
        r"d12: its 16-bit images hold 12-bit values \(2\.png goes up to 4095 of 65535\): read "
        r"as 12-bit data, each value / 16 to 8 bits \(not / 256, which makes them almost black\)$"
    )
    with pytest.warns(UserWarning, match=message) as said:
        frames = list(src)
    assert len(said) == 1  # once for the folder
    assert all(np.array_equal(f, i >> 4) for f, i in zip(frames, images, strict=True))
    assert frames[1].max() == 255
    # frames read at chosen indices and on demand alike (the bootstrap, the colour term)
    again = FrameSource(tmp_path / "d12")
    with pytest.warns(UserWarning, match="12-bit values"):
        assert np.array_equal(again.frames_at([2])[0], images[2] >> 4)
    # 10-bit data: / 4
    images = _sixteen_bit(tmp_path / "d10", [1000, 1023])
    with pytest.warns(UserWarning, match=r"10-bit values .* each value / 4 to 8 bits"):
        frames = list(FrameSource(tmp_path / "d10"))
    assert all(np.array_equal(f, i >> 2) for f, i in zip(frames, images, strict=True))


def test_a_dark_first_image_does_not_decide_the_depth_alone(tmp_path: Path) -> None:
    """12-bit data whose first image is dark (a lens cap, a night start: up to 700, 10 bits).

    Was: read at 10 bits, the first image's, and every later, brighter image clipped to white
    (one warning): the scene ruined. The depth is that of the brightest of the first, the last
    and up to seven images evenly spaced between.
    """
    tops = [700] + [4000] * 19
    images = _sixteen_bit(tmp_path / "d", tops)
    src = FrameSource(tmp_path / "d")
    assert src.bits == 12
    with pytest.warns(UserWarning) as said:
        frames = list(src)
    assert [str(w.message) for w in said] == [
        f"{tmp_path / 'd'}: its 16-bit images hold 12-bit values (3.png goes up to 4000 of "
        "65535): read as 12-bit data, each value / 16 to 8 bits (not / 256, which makes them "
        "almost black)"
    ]  # no clipping warning
    assert all(np.array_equal(f, i >> 4) for f, i in zip(frames, images, strict=True))
    # the images looked at: the first, the last, evenly spaced between; a bounded number
    assert video._depth_sample(20) == [0, 2, 5, 7, 10, 12, 14, 17, 19]
    assert video._depth_sample(3) == [0, 1, 2]
    assert len(video._depth_sample(100_000)) == 9
    assert video._depth_sample(100_000)[-1] == 99_999


def test_an_image_brighter_than_the_depth_decided_is_clipped_with_a_warning(
    tmp_path: Path,
) -> None:
    # 10 bits decided from images 1, 3, 6, ... (2.png and 4.png are not among them)
    images = _sixteen_bit(tmp_path / "d", [1000, 4000, 1000, 3000] + [1000] * 16)
    with pytest.warns(UserWarning) as said:
        frames = list(FrameSource(tmp_path / "d"))
    assert [str(w.message) for w in said][1:] == [
        f"image {tmp_path / 'd' / '2.png'} goes up to 4000, past the 10 bits its folder's 16-bit "
        "images are read at (from the values of 9 of its 20 images): its brighter pixels are "
        "clipped to white"
    ]  # once, not for 4.png too
    assert np.array_equal(frames[1], np.minimum(images[1], 1023) >> 2)
    assert np.array_equal(frames[3], np.minimum(images[3], 1023) >> 2)
    # a folder of three: all three decide, nothing clipped (was: 10 bits, from 1.png alone)
    images = _sixteen_bit(tmp_path / "three", [1000, 4000, 3000])
    with pytest.warns(UserWarning, match=r"12-bit values \(2\.png goes up to 4000") as said:
        frames = list(FrameSource(tmp_path / "three"))
    assert len(said) == 1
    assert all(np.array_equal(f, i >> 4) for f, i in zip(frames, images, strict=True))


def test_8_bit_and_full_range_16_bit_images_are_read_as_opencv_reads_them(
    tmp_path: Path,
) -> None:
    """The same pixels as cv2.imread's colour read (warnings are errors: none is given)."""
    _sixteen_bit(tmp_path / "full", [65535, 60000])
    _sixteen_bit(tmp_path / "late", [4000] * 9 + [65535] * 3)  # the last image: full range
    scene = make_scene(n_frames=3, width=64, height=64, n_walkers=2, rng=0)
    folders = [tmp_path / "full", tmp_path / "late", scene.write_images(tmp_path / "eight")]
    for folder in folders:
        src = FrameSource(folder)
        assert src.bits is None
        paths = sorted(folder.iterdir(), key=lambda p: natural_key(p.name))
        expected = [cv2.imread(str(p), cv2.IMREAD_COLOR) for p in paths]
        assert all(np.array_equal(f, e) for f, e in zip(src, expected, strict=True))


@pytest.mark.parametrize("first", ["float", "8-bit"])
def test_a_float_tiff_is_refused_by_its_depth_not_as_damaged(tmp_path: Path, first: str) -> None:
    """A 32-bit float TIFF (a processing pipeline's output) decodes only at its own depth, which
    OpenCV's colour read cannot give. Was: ``cannot read image .../1.tif: not an image OpenCV can
    decode (damaged?)``, of an intact file; now its depth and the mend are named."""
    image = np.linspace(0, 1, 48 * 64 * 3, dtype=np.float32).reshape(48, 64, 3)
    for k in (1, 2):
        eight = first == "8-bit" and k == 1
        cv2.imwrite(str(tmp_path / f"{k}.tif"), (image * 255).astype(np.uint8) if eight else image)
    bad = tmp_path / ("2.tif" if first == "8-bit" else "1.tif")
    why = (
        f"cannot read image {bad}: its pixels are 32-bit floats (float32), not 8- or 16-bit "
        "integers (whose range is known); convert the images to 8 or 16 bits (PNG or TIFF)"
    )
    if first == "8-bit":  # one image of the folder: the frame before stands in, said why
        with pytest.warns(UserWarning, match=re.escape(f"frame 2: {why}; the frame before")):
            assert len(list(FrameSource(tmp_path))) == 2
        return
    (tmp_path / "2.tif").unlink()  # no image of the folder can be read: refused, why said
    with pytest.raises(ValueError) as info:
        list(FrameSource(tmp_path))
    assert str(info.value) == why


def test_seqinfo_of_pets_gives_its_true_frame_rate() -> None:
    folder = dataset("pets09-s2l1")
    src = FrameSource(folder / "video.avi")
    assert (src.fps, src.fps_origin) == (7.0, "seqinfo.ini")  # the AVI header says 10
    assert src.sequence is not None and src.sequence.length == 795


def test_live_sources_are_recognised(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    for source in ("0", 3, "rtsp://cam.local/stream", "http://127.0.0.1:8080/video", fifo):
        assert is_live_source(source), source
    for source in (tmp_path, tmp_path / "video.mp4", "video.mp4"):
        assert not is_live_source(source), source


def test_a_folder_named_by_digits_is_not_a_camera(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "2024").mkdir()
    cv2.imwrite(str(tmp_path / "2024" / "1.png"), np.zeros((4, 4, 3), np.uint8))
    assert not is_live_source("2024") and is_live_source("2025")
    src = FrameSource("2024")
    assert not src.live and len(src) == 1


def test_a_negative_camera_index_is_refused_not_a_crash() -> None:
    """Was: a segmentation fault (OpenCV's ``VideoCapture(-1)`` without a camera); run in a
    child process, so that a regression fails this test, not the whole run."""
    import subprocess
    import sys

    code = (
        "import numpy as np\n"
        "from pftrack.io.video import FrameSource\n"
        "for source in (-1, np.int64(-2)):\n"
        "    try:\n"
        "        FrameSource(source)\n"
        "    except ValueError as exc:\n"
        "        print(exc)\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         check=False, timeout=120)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert run.stdout == (
        "camera index is -1, expected an int >= 0\ncamera index is -2, expected an int >= 0\n"
    )


@pytest.mark.parametrize(
    ("source", "message"),
    [
        (2**31, "camera index is 2147483648, expected an int from 0 to 2147483647"),
        ("99999999999999999999", "camera index is 99999999999999999999, expected an int from "),
        ("\u00b2", "video source not found: \u00b2"),  # '²'.isdigit(), but no number
        ("\u0663", "video source not found: \u0663"),  # an Arabic-Indic 3: not camera 3
    ],
)
def test_a_camera_index_is_ascii_digits_of_an_int(source: object, message: str) -> None:
    """Was: OpenCV's multi-line overload error (a C int is too small), ``'\u00b2'``: "invalid
    literal for int() with base 10", and ``'\u0663'`` opened camera 3 (``str.isdigit`` takes any
    Unicode digit)."""
    with pytest.raises((ValueError, FileNotFoundError), match=re.escape(message)) as info:
        FrameSource(source)  # type: ignore[arg-type]
    assert "\n" not in str(info.value)
    if isinstance(source, str):
        assert is_live_source(source) == source.isascii()


@pytest.mark.parametrize(
    ("source", "error", "message"),
    [
        (True, TypeError, "video source is True, a bool; expected a video file, "),
        (np.bool_(False), TypeError, "video source is False, a bool"),
        ("", ValueError, "video source is '' (empty); expected a video file, "),
        (1.5, TypeError, "video source must be a path, a URL or an int, got float"),
        (None, TypeError, "got NoneType"),
        (b"video.mp4", TypeError, "got bytes"),
    ],
)
def test_a_source_that_names_nothing_is_refused_in_one_line(
    source: object, error: type[Exception], message: str
) -> None:
    """Was: ``True`` a multi-line cv2.error, ``""`` the current folder read."""
    with pytest.raises(error, match=re.escape(message)) as info:
        FrameSource(source)  # type: ignore[arg-type]
    assert "\n" not in str(info.value)


def test_track_refuses_an_empty_source(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from pftrack.cli import main

    monkeypatch.chdir(tmp_path)
    cv2.imwrite(str(tmp_path / "1.png"), np.zeros((8, 8, 3), np.uint8))  # was: tracked
    assert main(["track", "", "--out", "t.txt"]) == 2
    assert capsys.readouterr().err == (
        "pftrack track: error: video source is '' (empty); expected a video file, an image or "
        "sequence folder, a stream URL or a camera index\n"
    )
    assert sorted(os.listdir(tmp_path)) == ["1.png"]


@pytest.mark.parametrize("name", ["det.txt", "notes.nfo", "art.asc"])
def test_a_text_file_is_not_a_video(
    tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: FFmpeg's tty demuxer decoded the text as 640x400 ANSI-art frames, 0 tracks, exit 0."""
    from pftrack.cli import main

    text = tmp_path / name
    text.write_text("1,-1,10,20,30,60,0.9,-1,-1,-1\n" * 50)
    with pytest.raises(ValueError, match=f"^not a video: {re.escape(str(text))} is a text file"):
        FrameSource(text)
    assert main(["track", str(text), "--out", str(tmp_path / "t.txt")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pftrack track: error: not a video: ") and err.count("\n") == 1
    assert not (tmp_path / "t.txt").exists()


def test_the_shared_data_detections_are_not_a_video() -> None:
    with pytest.raises(ValueError, match="not a video"):
        FrameSource(dataset("pets09-s2l1") / "det.txt")


@pytest.mark.parametrize(
    ("suffix", "container", "codec"),
    [(".mp4", "mp4", "mpeg4"), (".mkv", "matroska", "mpeg4"), (".mov", "mov", "mpeg4"),
     (".webm", "webm", "libvpx"), (".avi", "avi", "mjpeg")],
)  # fmt: skip
def test_videos_of_every_container_still_open(
    tmp_path: Path, suffix: str, container: str, codec: str
) -> None:
    """The text check reads the codec: real videos (any container) are not refused."""
    frames = make_scene(n_frames=5, rng=0).frames
    path = tmp_path / f"v{suffix}"
    try:
        encode(path, frames, 25, codec=codec, container=container)
    except (av.error.FFmpegError, ValueError) as exc:  # an encoder this PyAV lacks
        pytest.skip(f"cannot write {codec} in {container}: {exc}")
    src = FrameSource(path)
    assert len(list(src)) == 5 and (src.width, src.height) == frames[0].shape[1::-1]


@pytest.mark.parametrize("url", ["rtsp://127.0.0.1:9/none", "http://127.0.0.1:9/x.ts"])
def test_stream_url_is_not_mangled_as_a_path(url: str) -> None:
    with pytest.raises(ValueError, match=f"stream {re.escape(url)}$"):
        FrameSource(url)


def test_http_stream_is_read_frame_by_frame_as_it_arrives(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("pftrack.io.video.REPLAY_FRAMES", 16)  # frames kept for a second pass
    frames = make_scene(n_frames=40, rng=0).frames
    with serve_stream(frames, pace=0.01) as server:
        src = FrameSource(server.url)
        assert src.live and len(src) == 0
        primed = list(itertools.islice(iter(src), 10))  # the tracker's read-ahead
        assert server.sent < len(frames)  # it was still sending: frames came as they arrived
        got = list(src)  # the second pass replays the read-ahead, then goes on
        src.close()
    assert len(got) == len(frames)
    for a, b in zip(primed, got[:10], strict=True):
        np.testing.assert_array_equal(a, b)
    # lossy MPEG-1, but frame k is frame k of the scene
    errors = [np.abs(g.astype(int) - f).mean() for g, f in zip(got, frames, strict=True)]
    assert max(errors) < 8
    with pytest.raises(ValueError, match="read already"):  # 40 frames went past the 16 kept
        next(iter(src))


def test_named_pipe_is_a_live_source(tmp_path: Path) -> None:
    """A FIFO fed by an encoder in another thread, as ``ffmpeg ... -f mpegts pipe`` would."""
    frames = make_scene(n_frames=20, rng=1).frames
    fifo = tmp_path / "live.ts"
    os.mkfifo(fifo)

    def feed() -> None:
        with open(fifo, "wb") as fh:
            out = av.open(fh, "w", format="mpegts")
            stream = out.add_stream("mpeg1video", rate=Fraction(25))
            stream.width, stream.height, stream.pix_fmt = (
                frames[0].shape[1],
                frames[0].shape[0],
                "yuv420p",
            )
            stream.bit_rate = 8_000_000
            for f in frames:
                for packet in stream.encode(av.VideoFrame.from_ndarray(f, format="bgr24")):
                    out.mux(packet)
            for packet in stream.encode(None):
                out.mux(packet)
            out.close()

    writer = threading.Thread(target=feed)
    writer.start()
    try:
        src = FrameSource(fifo, fps=25)
        got = list(src)
    finally:
        writer.join(timeout=30)
    assert src.live and (src.fps, src.fps_origin) == (25.0, "given")
    assert len(got) == len(frames)
    assert max(np.abs(g.astype(int) - f).mean() for g, f in zip(got, frames, strict=True)) < 8


def test_stop_ends_the_iteration(tmp_path: Path) -> None:
    for k in range(1, 6):
        cv2.imwrite(str(tmp_path / f"{k}.png"), np.full((4, 4, 3), k, np.uint8))
    src = FrameSource(tmp_path)
    seen = []
    for frame in src:
        seen.append(int(frame[0, 0, 0]))
        if len(seen) == 2:
            src.stop()
    assert seen == [1, 2]


@pytest.mark.parametrize("kind", ["folder", "video"])
def test_a_read_begun_after_stop_is_refused(tmp_path: Path, kind: str) -> None:
    """A user trial: after ``stop()`` a file's new iteration, and ``frames_at``, gave no frame
    without a word. The stop stays (a run's later passes end with it), and says so."""
    if kind == "folder":
        for k in range(1, 6):
            cv2.imwrite(str(tmp_path / f"{k}.png"), np.full((4, 4, 3), k, np.uint8))
        path = tmp_path
    else:
        path = _mjpg(tmp_path / "v.avi", 5, np.random.default_rng(0))
    src = FrameSource(path)
    for n, _ in enumerate(src, start=1):
        if n == 2:
            src.stop()
    assert n == 2
    said = "^" + re.escape(f"{path}: stopped (FrameSource.stop() was called); a new FrameSource")
    with pytest.raises(ValueError, match=said):
        iter(src)  # at iter(), before a frame is asked for
    with pytest.raises(ValueError, match=said):
        src.frames_at([0, 3])
    with pytest.raises(ValueError, match=said):
        FrameSequence(src)[1]
    assert len(list(FrameSource(path))) == len(FrameSource(path).frames_at(range(5))) == 5


def _mjpg(path: Path, n: int, rng: np.random.Generator) -> Path:
    w = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 25, (64, 48))
    for _ in range(n):
        w.write(rng.integers(0, 256, (48, 64, 3), dtype=np.uint8))
    w.release()
    return path


def test_a_video_that_ends_before_its_header_says_warns_once(tmp_path: Path) -> None:
    full = _mjpg(tmp_path / "full.avi", 20, np.random.default_rng(0))
    data = full.read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) // 2])  # the header still says 20 frames
    src = FrameSource(cut)
    assert len(src) == 20
    with pytest.warns(UserWarning, match=r"cut.avi ended after \d+ frames but its header says 20"):
        n = sum(1 for _ in src)
    assert 0 < n < 20
    assert sum(1 for _ in src) == n  # a second pass: the same frames, no second warning
    assert len(list(itertools.islice(FrameSource(cut), 3))) == 3  # stopped early: no warning
    assert sum(1 for _ in FrameSource(full)) == 20  # whole: no warning (warnings are errors)


def turned_mp4(path: Path, frames: list[np.ndarray], degrees: int) -> Path:
    """An H.264 MP4 of `frames` whose display matrix turns them `degrees` counter-clockwise
    (FFmpeg's sense; a phone's portrait video), written with PyAV."""
    return encode(path, frames, rotation=degrees)


@pytest.mark.parametrize(("degrees", "clockwise"), [(90, 270), (180, 180), (270, 90), (0, 0)])
def test_a_turned_video_is_read_as_shown_and_says_its_rotation(
    tmp_path: Path, degrees: int, clockwise: int
) -> None:
    """A phone's portrait video (stored 96x64, shown 64x96): frames as players show them."""
    frames = make_scene(n_frames=3, width=96, height=64, rng=0).frames
    src = FrameSource(turned_mp4(tmp_path / "v.mp4", frames, degrees))
    size = (64, 96) if degrees % 180 else (96, 64)
    assert (src.rotation, (src.width, src.height)) == (clockwise, size)
    turn = {0: None, 90: cv2.ROTATE_90_CLOCKWISE, 180: cv2.ROTATE_180}
    turn[270] = cv2.ROTATE_90_COUNTERCLOCKWISE
    for got, frame in zip(src, frames, strict=True):  # lossy H.264: near, not equal
        shown = frame if turn[clockwise] is None else cv2.rotate(frame, turn[clockwise])
        assert np.abs(got.astype(int) - shown).mean() < 8


def _header_count(path: Path, count: int) -> Path:
    """`path`, an AVI, with its header's frame count (``avih`` and ``strh``) set to `count`."""
    data = bytearray(path.read_bytes())
    for chunk, at in ((b"avih", 16), (b"strh", 32)):
        i = data.index(chunk) + 8 + at
        data[i : i + 4] = count.to_bytes(4, "little")
    path.write_bytes(bytes(data))
    return path


def test_a_header_count_short_of_the_frames_is_counted_when_it_matters(tmp_path: Path) -> None:
    """An AVI whose header says 5 of its 20 frames: was taken at its word by the checks."""
    short = _header_count(_mjpg(tmp_path / "short.avi", 20, np.random.default_rng(0)), 5)
    src = FrameSource(short)
    assert (len(src), src.counted_frames, src.frames_to(5)) == (5, 5, 5)  # enough: no count
    with pytest.warns(UserWarning, match=r"short.avi: its header says 5 frames but it holds 20 "):
        assert src.frames_to(12) == 20
    assert (len(src), src.counted_frames, src.frames_to(20)) == (20, 20, 20)  # counted once
    assert sum(1 for _ in src) == 20


@pytest.mark.parametrize("length", [4, 9])
def test_a_sequence_video_of_another_length_than_seqlength_warns_once(
    tmp_path: Path, length: int
) -> None:
    # was: silent (an image folder of another length is refused; a video's header may be wrong)
    seq = _video_sequence(tmp_path / "SEQ", 6)
    ini = seq / "seqinfo.ini"
    ini.write_text(ini.read_text().replace("seqLength=6", f"seqLength={length}"))
    for src in (FrameSource(seq), FrameSource(seq / "video.avi")):  # the video beside it too
        assert len(src) == 6  # the header's count: nothing decoded twice to count
        message = rf"^{re.escape(str(seq))}/video.avi ended after 6 frames but "
        message += rf"{re.escape(str(ini))} says seqLength={length}$"
        with pytest.warns(UserWarning, match=message) as caught:
            assert sum(1 for _ in src) == 6
        assert len(caught) == 1
        assert sum(1 for _ in src) == 6  # a second pass: no second warning (they are errors)
        assert len(list(itertools.islice(FrameSource(seq), 3))) == 3  # stopped early: none
    ini.write_text(ini.read_text().replace(f"seqLength={length}", "seqLength=6"))
    assert sum(1 for _ in FrameSource(seq)) == 6  # as long as it says: no warning


def test_a_truncated_sequence_video_names_its_header_and_seqlength(tmp_path: Path) -> None:
    seq = _video_sequence(tmp_path / "SEQ", 0)
    full = _mjpg(tmp_path / "full.avi", 20, np.random.default_rng(0))
    data = full.read_bytes()
    (seq / "video.avi").write_bytes(data[: len(data) // 2])  # the header still says 20 frames
    ini = seq / "seqinfo.ini"
    ini.write_text(ini.read_text().replace("seqLength=0", "seqLength=20"))
    message = r"video.avi ended after \d+ frames but its header says 20 and .*seqinfo.ini says "
    with pytest.warns(UserWarning, match=message + "seqLength=20: a truncated or damaged file"):
        sum(1 for _ in FrameSource(seq))


@pytest.mark.parametrize("suffix", [".png", ".bmp"])
@pytest.mark.parametrize("header", [True, False], ids=["header", "no-header"])
def test_an_image_of_another_size_in_a_folder_is_named(
    tmp_path: Path, suffix: str, header: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Refused when the folder is opened, from the images' headers (every format of
    IMAGE_SUFFIXES: tests/io/test_image_sizes.py); where no header could be read (a damaged
    one, here made so), when the odd image is read."""
    import pftrack.io.video as video

    rng = np.random.default_rng(1)
    for k in range(1, 6):
        shape = (60, 80, 3) if k == 4 else (48, 64, 3)
        cv2.imwrite(str(tmp_path / f"{k}{suffix}"), rng.integers(0, 256, shape, dtype=np.uint8))
    message = rf"image .*4{suffix} is 80x60 but 1{suffix} is 64x48: every image of a folder must"
    if header:
        with pytest.raises(ValueError, match=message):
            FrameSource(tmp_path)
        return
    monkeypatch.setattr(video, "_header_size", lambda path: None)
    src = FrameSource(tmp_path)
    with pytest.raises(ValueError, match=message):
        list(src)
    with pytest.raises(ValueError, match=message):
        src.frames_at([0, 3])
    assert len(src.frames_at([0, 1, 4])) == 3


def _assert_same_pixels_as_default_capture(path: Path) -> None:
    """FrameSource decodes with one FFmpeg thread: every frame the same as OpenCV's default."""
    want = capture_frames(path)
    src = FrameSource(path)
    got = list(src)
    assert len(got) == len(want) > 0
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)
    picked = [0, len(want) // 3, len(want) - 1]
    for a, k in zip(src.frames_at(picked), picked, strict=True):
        np.testing.assert_array_equal(a, want[k])
    # two halves at once, the second from a seek (past key frames and B-frames): the same
    spread = np.linspace(0, len(want) - 1, 9).round().astype(int).tolist()
    got = src.frames_at(spread, split=True)
    assert len(got) == len(spread)
    for a, k in zip(got, spread, strict=True):
        np.testing.assert_array_equal(a, want[k])


def test_h264_file_frames_equal_the_default_capture(tmp_path: Path) -> None:
    path = tmp_path / "walk.mp4"
    scene = make_scene(n_frames=40, n_walkers=4, rng=1)
    try:  # B-frames and several key frames: reordering
        encode(path, scene.frames, options={"bf": "2", "g": "12"})
    except (av.FFmpegError, ValueError) as error:  # an av build without x264
        pytest.skip(f"no H.264 encoder: {error}")
    _assert_same_pixels_as_default_capture(path)


@pytest.mark.parametrize("fault", ["late", "refused"])
def test_a_split_pass_whose_seek_goes_wrong_reads_on_from_the_first_half(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fault: str
) -> None:
    path = _mjpg(tmp_path / "v.avi", 30, np.random.default_rng(4))
    src = FrameSource(path)
    spread = [0, 4, 9, 14, 15, 16, 22, 29]
    plain = src.frames_at(spread)
    seek = FrameSource._read_from_seek

    def wrong(
        self: FrameSource,
        middle: int,
        wanted: list[int],
        halt: threading.Event | None = None,
        **options: Any,
    ) -> object:
        # a container whose seek lands one frame late, or that cannot seek at all
        return seek(self, middle + 1, wanted, halt, **options) if fault == "late" else None

    monkeypatch.setattr(FrameSource, "_read_from_seek", wrong)
    got = src.frames_at(spread, split=True)
    assert len(got) == len(plain) == len(spread)
    for a, b in zip(got, plain, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("split", [False, True])
def test_frames_at_keeps_what_prepare_makes_of_each_frame(tmp_path: Path, split: bool) -> None:
    """The spread bootstrap of a 4K video held its 30 frames at their own size (750 MB) until
    the tracker scaled them: ``frames_at(prepare=...)`` keeps each frame's scaled copy alone,
    made as it is read (the pass's own check of its two halves keeps digests, not frames)."""
    path = _mjpg(tmp_path / "v.avi", 30, np.random.default_rng(6))
    src = FrameSource(path)
    spread = [0, 4, 9, 14, 15, 16, 22, 29]
    plain = src.frames_at(spread)
    made: list[tuple[int, ...]] = []

    def prepare(frame: np.ndarray) -> np.ndarray:
        made.append(frame.shape)
        return cv2.resize(frame, (16, 12), interpolation=cv2.INTER_AREA)

    got = src.frames_at(spread, split=split, prepare=prepare)
    # the frames at the split both halves read are made twice
    assert set(made) == {(48, 64, 3)} and len(spread) <= len(made) <= len(spread) + 2
    assert len(got) == len(plain)
    for a, b in zip(got, plain, strict=True):
        np.testing.assert_array_equal(a, cv2.resize(b, (16, 12), interpolation=cv2.INTER_AREA))


def test_a_split_pass_whose_seek_raises_reads_on_from_the_first_half(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _mjpg(tmp_path / "v.avi", 30, np.random.default_rng(5))
    src = FrameSource(path)
    spread = [0, 9, 14, 15, 29]
    plain = src.frames_at(spread)
    opened = video._file_capture

    class Failing:  # the captures after the first half's: OpenCV fails on every set
        def __init__(self, cap: cv2.VideoCapture) -> None:
            self.cap = cap

        def set(self, *args: object) -> bool:
            raise cv2.error("seek failed")

        def release(self) -> None:
            self.cap.release()

    captures: list[object] = []

    def capture(name: str) -> object:
        cap = opened(name)
        captures.append(cap)
        return cap if len(captures) == 1 else Failing(cap)

    monkeypatch.setattr(video, "_file_capture", capture)
    got = src.frames_at(spread, split=True)
    # the split was tried: the key frames' scan (which fails: the middle is kept), the seek
    assert len(captures) == 3
    for a, b in zip(got, plain, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.dataset
@pytest.mark.parametrize("name", ["pets09-s2l1/video.avi", "tud-campus/video.mp4"])
def test_dataset_frames_equal_the_default_capture(name: str) -> None:
    folder, file = name.split("/")
    _assert_same_pixels_as_default_capture(dataset(folder) / file)


def test_frame_sequence_reads_on_demand_in_one_pass(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The frames ``recover --link --video`` asks for, one decode pass, one frame held."""
    from pftrack.io.video import FrameSequence, read_frames

    scene = make_scene(n_frames=12, rng=0)
    path = scene.write_video(tmp_path / "v.avi")
    folder = scene.write_images(tmp_path / "imgs")
    opened: list[str] = []
    real = video._file_capture
    monkeypatch.setattr(video, "_file_capture", lambda p: opened.append(p) or real(p))
    for source, expected in ((path, read_frames(path)), (folder, scene.frames)):
        frames = FrameSequence(source)
        opened.clear()  # FrameSource probes the file when made
        with frames:
            assert len(frames) == 12
            for i in (0, 3, 3, 7, -1):  # increasing (and the last one again): one pass
                assert np.array_equal(frames[i], expected[i])
            assert len(opened) == (1 if source == path else 0)
            assert np.array_equal(frames[2], expected[2])  # back: a new pass
            assert len(opened) == (2 if source == path else 0)
            with pytest.raises(IndexError):
                frames[12]


def test_frame_sequence_says_where_a_truncated_video_ends(tmp_path: Path) -> None:
    from pftrack.io.video import FrameSequence

    full = make_scene(n_frames=20, rng=0).write_video(tmp_path / "full.avi")
    cut = tmp_path / "cut.avi"
    cut.write_bytes(full.read_bytes()[: full.stat().st_size // 2])
    frames = FrameSequence(cut)
    assert len(frames) == 20
    with pytest.warns(UserWarning, match="ended after"):
        decodable = len(list(FrameSource(cut)))
    assert 0 < decodable < 20
    # the count of frames decoded (a user trial: "after 0 frames", counted after the reset)
    with pytest.raises(ValueError, match=r"cut.avi: frame 20 cannot be decoded: the video ended "
                       rf"after {decodable} frames but its header says 20"):  # fmt: skip
        frames[19]


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"scale": "0.5"}, TypeError, "scale must be a number, got str '0.5'"),
        ({"scale": True}, TypeError, "scale must be a number, got bool"),
        ({"scale": 0.0}, ValueError, "scale is 0.0, expected a finite value > 0"),
        ({"scale": float("nan")}, ValueError, "scale is nan"),
        ({"fps": "7"}, TypeError, "fps must be a number, got str '7'"),
        ({"fps": -1.0}, ValueError, "fps is -1.0, expected a finite value > 0"),
    ],
)
def test_scale_and_fps_of_the_wrong_kind_are_named(
    tmp_path: Path, kwargs: dict[str, object], error: type[Exception], message: str
) -> None:
    """`FrameSource(scale='0.5')` was NumPy's "ufunc 'isfinite' not supported" TypeError."""
    folder = make_scene(n_frames=2, width=64, height=64, n_walkers=1, rng=0).write_images(
        tmp_path / "seq"
    )
    with pytest.raises(error, match=re.escape(message)):
        FrameSource(folder, **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(("scale", "size"), [(1e-4, "0x0"), (1e6, "64000000x64000000")])
def test_a_scale_that_makes_frames_of_no_or_too_many_pixels_is_refused(
    tmp_path: Path, scale: float, size: str
) -> None:
    """scale=1e-4 failed on the first frame in OpenCV's resize ('inv_scale_x > 0'), 1e6 tried
    to allocate 5e17 bytes."""
    folder = make_scene(n_frames=2, width=64, height=64, n_walkers=1, rng=0).write_images(
        tmp_path / "seq"
    )
    with pytest.raises(
        ValueError, match=re.escape(f"{scale:g} makes the 64x64 frames") + f".* {size} pix"
    ):
        FrameSource(folder, scale=scale)
    assert FrameSource(folder, scale=0.5).width == 32


def test_two_images_of_one_number_in_a_plain_folder_are_refused(tmp_path: Path) -> None:
    """1.png and 01.png (or 2.png and 002.png) were two frames in the file system's order; a
    sequence folder already refused them."""
    scene = make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0)
    src = scene.write_images(tmp_path / "src")
    folder = tmp_path / "plain"
    folder.mkdir()
    for k, name in enumerate(["1.png", "01.png", "2.png"]):
        (folder / name).write_bytes(sorted(src.glob("*.png"))[k].read_bytes())
    with pytest.raises(ValueError, match=r"plain: images 01.png and 1.png are both frame 1 \("):
        FrameSource(folder)  # as in a sequence (names that are numbers are frame numbers)
    for name in ("1.png", "01.png", "2.png"):  # not all numbers: natural order
        (folder / name).rename(folder / f"f{name}")
    with pytest.raises(ValueError, match="images f01.png and f1.png in folder .* the same number"):
        FrameSource(folder)
    (folder / "f01.png").unlink()
    assert len(list(FrameSource(folder))) == 2


@pytest.mark.parametrize("key", ["frameRate", "imWidth", "imHeight", "seqLength", "imDir", "name"])
def test_a_key_given_empty_is_refused_not_taken_as_absent(tmp_path: Path, key: str) -> None:
    """Was: ``frameRate=`` read as no frame rate (the container's was used, silently), while
    ``frameRate=0`` was an error; every key pftrack reads alike."""
    other = "" if key == "frameRate" else "frameRate=7\n"
    (tmp_path / "seqinfo.ini").write_text(f"[Sequence]\n{other}{key} =  \n")
    message = rf"^{re.escape(str(tmp_path))}/seqinfo.ini: {key} is empty; give a value or leave"
    with pytest.raises(ValueError, match=message):
        read_seqinfo(tmp_path)
    (tmp_path / "seqinfo.ini").write_text("[Sequence]\n")  # left out: the defaults
    info = read_seqinfo(tmp_path)
    assert (info.name, info.image_dir, info.frame_rate, info.width) == (
        tmp_path.name, "img1", None, None
    )  # fmt: skip


def test_an_image_folder_that_also_holds_a_video_says_so(tmp_path: Path) -> None:
    """A user trial: the video in a folder of images was passed over without a word."""
    scene = make_scene(n_frames=4, rng=0)
    scene.write_images(tmp_path, ext=".png")
    scene.write_video(tmp_path / "walk.avi")
    with pytest.warns(UserWarning, match=r"holds 4 images and 1 video \(walk\.avi\): the images"):
        assert len(list(FrameSource(tmp_path))) == 4


def damaged_inside(tmp: Path, places: tuple[float, ...] = (0.3,)) -> Path:
    """`tmp`/damaged.avi: `tmp`/walk.avi (30 MJPEG frames) with frame 10's data overwritten.

    `places`: where in the file, as parts of its size (0.3: frame 10; 0.7: frame 22).
    """
    path = make_scene(n_frames=30, rng=0).write_video(tmp / "walk.avi")
    data = bytearray(path.read_bytes())
    for place in places:
        at = int(len(data) * place)
        data[at : at + 20000] = np.random.default_rng(1).bytes(20000)
    damaged = tmp / "damaged.avi"
    damaged.write_bytes(bytes(data))
    return damaged


def test_a_frame_that_fails_inside_a_video_is_stood_in_for_and_the_rest_read(
    tmp_path: Path,
) -> None:
    """A user trial: a video damaged in the middle (bytes overwritten) ended at the damage, with
    a warning and exit 0: the frames after it, which decode, were lost. Now the frame before
    stands in for the one that fails, and the later frames keep their numbers (their time
    stamps say which they are)."""
    damaged = damaged_inside(tmp_path)
    good = list(FrameSource(tmp_path / "walk.avi"))
    with pytest.warns(UserWarning, match=r"damaged.avi: frame 10 could not be decoded .* the "
                      "frame before stands in for each"):  # fmt: skip
        frames = list(FrameSource(damaged))
    assert len(frames) == 30
    np.testing.assert_array_equal(frames[9], frames[8])
    for k in (*range(9), *range(10, 30)):
        np.testing.assert_array_equal(frames[k], good[k])


def test_a_video_that_cannot_be_opened_says_why(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A user trial: a video its user may not read was "not a video OpenCV can read, or empty"
    (root reads every file: the permission is simulated)."""
    path = tmp_path / "locked.avi"
    path.write_bytes(b"\0" * 64)
    real_open = Path.open

    def refuse(self: Path, *args: object, **kwargs: object) -> object:
        if self == path:
            raise PermissionError(13, "Permission denied", str(self))
        return real_open(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Path, "open", refuse)
    with pytest.raises(ValueError, match=rf"^cannot read {path}: Permission denied$"):
        FrameSource(path)
    monkeypatch.setattr(Path, "open", real_open)
    with pytest.raises(ValueError, match="not a video OpenCV can read, or empty"):
        FrameSource(path)


def test_a_truncated_jpeg_in_a_folder_is_said_once(tmp_path: Path) -> None:
    """A user trial: 20.jpg cut to a third was tracked, its lower part flat grey, and only
    libjpeg's "Premature end of JPEG file" (no file named) said anything."""
    folder = tmp_path / "jpg"
    folder.mkdir()
    rng = np.random.default_rng(0)
    for k in range(1, 5):
        cv2.imwrite(str(folder / f"{k}.jpg"), rng.integers(0, 255, (40, 60, 3), np.uint8))
    for k in (2, 3):  # two cut files: said once
        data = (folder / f"{k}.jpg").read_bytes()
        (folder / f"{k}.jpg").write_bytes(data[: len(data) // 3])
    with pytest.warns(UserWarning, match=r"2.jpg has no JPEG end marker \(a truncated file\?\)"):
        assert len(list(FrameSource(folder))) == 4
    # padded after its end marker, as some cameras write them, or with a long trailer (a
    # phone's, a motion photo's video; the review of this change): no warning
    data = (folder / "1.jpg").read_bytes()
    (folder / "2.jpg").write_bytes(data + b"\0" * 32)
    (folder / "3.jpg").write_bytes(data + bytes(range(256)) * 40)
    assert len(list(FrameSource(folder))) == 4
    ok, progressive = cv2.imencode(".jpg", np.full((40, 60, 3), 90, np.uint8),
                                   [cv2.IMWRITE_JPEG_PROGRESSIVE, 1])  # fmt: skip
    (folder / "3.jpg").write_bytes(progressive.tobytes()[:-2])  # several scans, no end
    with pytest.warns(UserWarning, match=r"3.jpg has no JPEG end marker"):
        assert len(list(FrameSource(folder))) == 4


def _png_with_short_iccp(image: np.ndarray) -> bytes:
    """`image` as a PNG whose ICC profile chunk is too short: libpng warns on every read."""
    import struct
    import zlib

    data = cv2.imencode(".png", image)[1].tobytes()
    body = b"iCCP" + b"x\0\0" + zlib.compress(b"\0" * 8)
    chunk = struct.pack(">I", len(body) - 4) + body + struct.pack(">I", zlib.crc32(body))
    return data[:33] + chunk + data[33:]  # after the signature and IHDR


def test_what_an_image_decoder_prints_is_one_warning_naming_the_image(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A user trial: PNGs with a bad ICC profile printed "libpng warning: iCCP: too short"
    twice per image (priming, then tracking: 62 lines for 30 images), a JPEG with damaged
    data "Corrupt JPEG data: 102 extraneous bytes before marker 0xd9" twice, naming no file;
    libjpeg's "Premature end of JPEG file" came beside pftrack's own warning of a cut file."""
    folder = tmp_path / "png"
    folder.mkdir()
    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 255, (40, 60, 3), np.uint8) for _ in range(4)]
    for k, frame in enumerate(frames, start=1):
        (folder / f"{k}.png").write_bytes(_png_with_short_iccp(frame))
    source = FrameSource(folder)
    capfd.readouterr()
    with pytest.warns(UserWarning) as record:
        got = list(source) + list(source)  # two passes: said once
    assert all(np.array_equal(a, b) for a, b in zip(got, frames * 2, strict=True))
    assert [str(w.message) for w in record] == [
        f"image {folder / '1.png'}: its decoder says 'libpng warning: iCCP: too short' (the "
        "image is read all the same; said once a run)"
    ]
    assert capfd.readouterr().err == ""
    jpg = tmp_path / "jpg"
    jpg.mkdir()
    y, x = np.mgrid[0:120, 0:160]
    for k in range(1, 4):
        image = np.stack([(x + 9 * k) % 256, (2 * y) % 256, (x + y) % 256], -1).astype(np.uint8)
        cv2.imwrite(str(jpg / f"{k}.jpg"), image)
    data = bytearray((jpg / "2.jpg").read_bytes())
    data[len(data) // 2 : len(data) // 2 + 300] = bytes(300)  # damaged, not cut
    (jpg / "2.jpg").write_bytes(bytes(data))
    data = (jpg / "3.jpg").read_bytes()
    (jpg / "3.jpg").write_bytes(data[: len(data) // 2])  # cut
    capfd.readouterr()
    with pytest.warns(UserWarning) as record:
        assert len(list(FrameSource(jpg))) == 3
    said = [str(w.message) for w in record]
    assert len(said) == 2, said
    assert said[0].startswith(f"image {jpg / '2.jpg'}: its decoder says 'Corrupt JPEG data: ")
    assert said[1].startswith(f"image {jpg / '3.jpg'} has no JPEG end marker")
    assert capfd.readouterr().err == ""


@pytest.mark.parametrize("first", [False, True])
def test_an_image_that_cannot_be_read_says_why(tmp_path: Path, first: bool) -> None:
    """A user trial: an empty file (a copy that failed), a folder or a broken link named like
    an image were each "cannot read image 3.png", which said nothing of why. The image now
    stands in by the frame before (black for the first: tests/io/test_unreadable_image.py),
    and the warning says why."""
    folder = tmp_path / "imgs"
    folder.mkdir()
    for k in (1, 2, 4):
        cv2.imwrite(str(folder / f"{k}.png"), np.zeros((6, 8, 3), np.uint8))
    bad = folder / ("0.png" if first else "3.png")  # the first image is read when opened

    def said() -> str:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert len(list(FrameSource(folder))) == 4
        assert len(caught) == 1, [str(w.message) for w in caught]
        return str(caught[0].message)

    frame = "frame 1" if first else "frame 3"
    bad.write_bytes(b"")
    assert said().startswith(f"{frame}: cannot read image {bad}: it is empty (0 bytes); ")
    bad.unlink()
    bad.mkdir()
    assert said().startswith(f"{frame}: cannot read image {bad}: it is a folder; ")
    bad.rmdir()
    bad.symlink_to(tmp_path / "gone.png")
    assert said().startswith(
        f"{frame}: cannot read image {bad}: a symbolic link to {tmp_path / 'gone.png'}, "
        "which does not exist; "
    )
    bad.unlink()
    bad.write_bytes(b"not an image at all")
    assert said().startswith(
        f"{frame}: cannot read image {bad}: not an image OpenCV can decode (damaged?); "
    )


def test_an_empty_image_folder_beside_a_sequence_video_says_how_to_read_it(
    tmp_path: Path,
) -> None:
    """A user trial: SEQ/video.mp4 beside an empty SEQ/img1 (an extraction that failed) was
    "no images in folder SEQ/img1", with no word of the video that is read without img1."""
    seq = tmp_path / "SEQ"
    (seq / "img1").mkdir(parents=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nframeRate=10\n")
    make_scene(n_frames=3, width=64, height=64, rng=0).write_video(seq / "video.mp4")
    for source in (seq, seq / "img1"):
        with pytest.raises(ValueError) as e:
            FrameSource(source)
        assert str(e.value) == (
            f"no images (.jpg, .jpeg, .png, .bmp, .tif, .tiff, .webp) in folder {seq / 'img1'}; "
            f"{seq} holds a video, video.mp4, read as the sequence's frames once the empty "
            f"image folder is gone (or give {seq / 'video.mp4'})"
        )
    (seq / "img1").rmdir()
    assert len(list(FrameSource(seq))) == 3


def test_an_image_folder_that_is_a_file_is_not_said_missing(tmp_path: Path) -> None:
    # was: "image folder SEQ/img1.zip does not exist", of a file that does
    seq = tmp_path / "SEQ"
    seq.mkdir()
    (seq / "seqinfo.ini").write_text("[Sequence]\nimDir=img1.zip\n")
    (seq / "img1.zip").write_bytes(b"PK")
    with pytest.raises(ValueError, match=r"folder \S+img1.zip is a file and \S+SEQ holds no video"):
        FrameSource(seq)


def test_a_sequence_folder_without_seqinfo_is_a_sequence_as_batch_takes_it(tmp_path: Path) -> None:
    """A user trial: ``SEQ/img1`` + ``SEQ/det/det.txt`` without seqinfo.ini was a sequence to
    ``pftrack batch`` (its det.txt read by ``--detections auto``) but not to ``pftrack track``
    (refused), and a missing image there shifted every later frame silently."""
    seq = _sequence(tmp_path / "SEQ", n=5)
    (seq / "seqinfo.ini").unlink()
    for source in (seq, seq / "img1"):
        info = FrameSource(source).sequence
        assert info is not None and (info.folder, info.name) == (seq, "SEQ")
        assert (info.frame_rate, info.width, info.length) == (None, None, None)
        assert info.detections == seq / "det" / "det.txt"
    (seq / "img1" / "3.png").unlink()
    with pytest.raises(ValueError, match=r"img1: image 3 is missing \(names 1..5 are frame"):
        FrameSource(seq)
    plain = tmp_path / "plain"  # images of no sequence: no sequence, names skipping numbers
    plain.mkdir()
    for k in (1, 2, 4):
        cv2.imwrite(str(plain / f"{k}.png"), np.zeros((4, 4, 3), np.uint8))
    source = FrameSource(plain)
    assert source.sequence is None and len(source) == 3


_CLOSE_WHILE_READING = """
import os, sys, threading, time
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene

folder = sys.argv[1]
data = open(make_scene(n_frames=40, width=160, height=120, rng=0).write_video(
    os.path.join(folder, "scene.avi")), "rb").read()
fifo = os.path.join(folder, "cam.avi")
os.mkfifo(fifo)
go_on = threading.Event()

def feed():
    with open(fifo, "wb") as fh:
        fh.write(data[: len(data) // 3])
        fh.flush()
        go_on.wait(30)  # the reader now waits in read() for the rest
        try:
            fh.write(data[len(data) // 3 :])
        except BrokenPipeError:
            pass

threading.Thread(target=feed, daemon=True).start()
src = FrameSource(fifo)
frames = []
reader = threading.Thread(target=lambda: frames.extend(src), daemon=True)
reader.start()
seen, deadline = -1, time.monotonic() + 30
while (seen != len(frames) or not frames) and time.monotonic() < deadline:
    seen = len(frames)  # until the reader waits in read() for the held-back bytes
    time.sleep(0.3)
src.close()  # from another thread, as pftrack track's cleanup after a second Ctrl-C
go_on.set()  # the reader's read() returns: on a released capture, a segmentation fault
reader.join(30)
print(src.live, reader.is_alive(), 0 < len(frames) < 40)
"""


def test_closing_a_live_source_while_a_thread_reads_it_is_no_crash(tmp_path: Path) -> None:
    """Was: a segmentation fault. ``pftrack track`` reads a live source on a thread; a second
    Ctrl-C (or ``timeout``'s two SIGTERMs) interrupted the wait for that thread, and the
    command's cleanup released the capture while the thread was inside its ``read()``.
    ``close()`` during a read now leaves the release to the reader, after its ``read()``."""
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    run = subprocess.run([sys.executable, "-c", _CLOSE_WHILE_READING, str(tmp_path)],
                         capture_output=True, text=True, env=env, check=False,
                         timeout=120)  # fmt: skip
    assert run.returncode == 0, (run.returncode, run.stderr[-2000:])
    assert run.stdout.split() == ["True", "False", "True"]


def test_frames_beyond_the_largest_side_are_refused_without_a_scale_given(
    tmp_path: Path,
) -> None:
    """A 40000x8 image folder read as it is: was "scale 1 makes the 40000x8 frames of imgs
    40000x8 pixels", of a scale nobody gave; the frames' own size is now named alone."""
    folder = tmp_path / "imgs"
    folder.mkdir()
    for k in (1, 2):
        cv2.imwrite(str(folder / f"{k}.png"), np.zeros((8, 40000, 3), np.uint8))
    with pytest.raises(ValueError) as info:
        FrameSource(folder)
    assert str(info.value) == (
        f"the frames of {folder} are 40000x8 pixels; expected 1 to 32767 pixels a side"
    )


def test_a_one_frame_video_is_counted_in_the_singular(tmp_path: Path) -> None:
    """Was: "video.avi ended after 1 frames", "out of range for 1 frames"."""
    seq = _video_sequence(tmp_path / "SEQ", 1)
    ini = seq / "seqinfo.ini"
    ini.write_text(ini.read_text().replace("seqLength=1", "seqLength=2"))
    message = rf"^{re.escape(str(seq))}/video.avi ended after 1 frame but "
    with pytest.warns(UserWarning, match=message):
        assert sum(1 for _ in FrameSource(seq)) == 1
    frames = FrameSequence(seq / "video.avi")
    with pytest.raises(IndexError, match=r"^frame index 1 is out of range for 1 frame$"):
        frames[1]
    frames.close()


@pytest.mark.parametrize("suffix", [".png", ".tif"])
def test_a_16_bit_image_after_an_8_bit_first_is_refused_naming_it(
    tmp_path: Path, suffix: str
) -> None:
    """A user trial: 1.png 8-bit, 2.png and 3.png 16-bit of 12-bit data (up to 3200) were read
    as OpenCV reads them, value / 256: levels 200, then 12, 12 (almost black), silently."""
    cv2.imwrite(str(tmp_path / f"1{suffix}"), np.full((16, 24, 3), 200, np.uint8))
    for k in (2, 3):
        cv2.imwrite(str(tmp_path / f"{k}{suffix}"), np.full((16, 24, 3), 3200, np.uint16))
    src = FrameSource(tmp_path)
    with pytest.raises(ValueError) as info:
        list(src)
    assert str(info.value) == (
        f"image {tmp_path / f'2{suffix}'} is 16-bit but 1{suffix}, the folder's first, is 8-bit: "
        "a folder's images must have one depth (its 16-bit images are read at the depth their "
        "values show only when the first is 16-bit); convert them to one"
    )
    with pytest.raises(ValueError, match=rf"image .*3\{suffix} is 16-bit but 1\{suffix}"):
        src.frames_at([2])
    # 8-bit images after an 8-bit first: the pixels OpenCV's colour read gives, as before
    cv2.imwrite(str(tmp_path / f"2{suffix}"), np.full((16, 24, 3), 90, np.uint8))
    (tmp_path / f"3{suffix}").unlink()
    assert [int(f.max()) for f in FrameSource(tmp_path)] == [200, 90]


def test_an_interrupted_split_read_stops_its_second_half(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``frames_at(split=True)`` (the spread bootstrap's pass) interrupted in its first half, by
    Ctrl-C or SIGTERM (raised there as a KeyboardInterrupt, ``pftrack.cli._signals``): its
    pool's join waited for the thread of the second half to read that whole half (1.2 s after
    a SIGTERM at 0.5 s on a 2400-frame 960x720 video; minutes on a long one), SIGTERM ignored
    meanwhile. Now the second half stops at its next frame."""
    path = make_scene(n_frames=80, rng=0).write_video(tmp_path / "walk.avi")
    src = FrameSource(path)
    real = video._file_capture
    interrupted = threading.Event()
    after = []  # frames the second half read after the interrupt

    class Capture:
        def __init__(self, cap: cv2.VideoCapture) -> None:
            self.cap, self.frames = cap, 0

        def __getattr__(self, name: str) -> Any:
            return getattr(self.cap, name)

        def _step(self) -> None:
            if threading.current_thread() is threading.main_thread():
                self.frames += 1
                if self.frames == 5:
                    interrupted.set()
                    raise KeyboardInterrupt
            else:
                time.sleep(0.02)  # the second half: slower than the first
                if interrupted.is_set():
                    after.append(1)

        def grab(self) -> bool:
            self._step()
            return bool(self.cap.grab())

        def read(self) -> Any:
            self._step()
            return self.cap.read()

    monkeypatch.setattr(video, "_file_capture", lambda name: Capture(real(name)))
    with pytest.raises(KeyboardInterrupt):
        src.frames_at(range(0, 80, 3), split=True)
    assert interrupted.is_set() and len(after) <= 1  # was: the rest of its 40 frames


def test_an_avi_whose_chunks_break_off_inside_is_named_before_the_frames_shift(
    tmp_path: Path,
) -> None:
    """A user trial: bytes cut out of the middle of an .avi (or overwritten across a chunk's
    header): FFmpeg's AVI demuxer reads on from the next chunk it finds and numbers the frames
    by counting them, so every later frame took an earlier frame's number, silently (a warning
    at the end said only that the video had fewer frames than its header). The chunks are
    walked when the file is opened, and where they break off is said before any frame is read."""
    path = make_scene(n_frames=30, rng=0).write_video(tmp_path / "walk.avi")
    good = list(FrameSource(path))
    data = path.read_bytes()
    at = len(data) // 2
    damaged = tmp_path / "damaged.avi"
    damaged.write_bytes(data[:at] + data[at + 2000 :])
    with pytest.warns(UserWarning) as said:
        src = FrameSource(damaged)
    message = str(said[0].message)
    match = re.fullmatch(
        r".*damaged\.avi: damaged inside: its AVI chunks break off after frame (\d+) \(byte "
        r"\d+\), and FFmpeg reads on from the next chunk it finds, numbering the frames it reads "
        r"by counting them: the frames after frame \1 may carry the numbers of earlier ones "
        r"\(tracks, detections and ground truth apart there\)",
        message,
    )
    assert match is not None, message
    before = int(match.group(1))
    assert 0 < before < 30
    with pytest.warns(UserWarning, match="ended after"):
        frames = list(src)
    assert len(frames) < 30  # what the warning is about: later frames are off by what is lost
    assert not np.array_equal(frames[-1], good[len(frames) - 1])
    # an intact file, a file that ends early (cut at its end): nothing said, numbers kept
    assert video._avi_break(path) is None
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: int(len(data) * 0.6)])
    assert video._avi_break(cut) is None
    assert video._avi_break(dataset("pets09-s2l1") / "video.avi") is None


def test_frames_read_at_chosen_indices_of_a_damaged_video_are_the_iterated_ones(
    tmp_path: Path,
) -> None:
    """A frame that fails inside a video ended a pass of grabs: ``FrameSequence`` (``pftrack
    recover --video``'s colour term) raised "frame 12 cannot be decoded: the video ended after
    9 frames but its header says 30" of a video ``pftrack track`` reads to its end, and
    ``frames_at`` (the spread bootstrap) gave only the frames before the damage. Now both give
    the frames iterating gives: the frame before stands in, the later frames keep their
    numbers."""
    damaged = damaged_inside(tmp_path)
    with pytest.warns(UserWarning, match="frame 10 could not be decoded"):
        frames = list(FrameSource(damaged))
    assert len(frames) == 30
    wanted = [0, 5, 9, 12, 20, 29]
    for split in (False, True):
        # the last frame wanted: the pass reads to the end and says the stand-in (apinames)
        with pytest.warns(UserWarning, match="frame 10 could not be decoded"):
            got = FrameSource(damaged).frames_at(wanted, split=split)
        assert len(got) == len(wanted)
        for k, frame in zip(wanted, got, strict=True):
            np.testing.assert_array_equal(frame, frames[k])
    # said as it reads on after the damage, once, not again when it reads back (warnlate)
    with pytest.warns(UserWarning, match="frame 10 could not be decoded") as said:
        with FrameSequence(damaged) as seq:
            for k in (3, 9, 12, 29, 5, 20):  # in order, and back again
                np.testing.assert_array_equal(seq[k], frames[k])
    assert len(said) == 1, [str(w.message) for w in said]


def _damaged_start(path: Path) -> Path:
    """`path` with the first frame's data overwritten (the first chunk or sample read)."""
    data = bytearray(path.read_bytes())
    if path.suffix == ".avi":  # the first chunk of frame data: "00dc", its size, the data
        at = data.index(b"00dc", data.index(b"movi")) + 8
    else:  # the samples' box: "mdat", then the first NAL unit's size and data
        at = data.index(b"mdat") + 4
    data[at : at + 400] = np.random.default_rng(1).bytes(400)
    damaged = path.with_name(f"damaged{path.suffix}")
    damaged.write_bytes(bytes(data))
    return damaged


@pytest.mark.parametrize(("suffix", "lost"), [(".avi", 1), (".mp4", 10)])
def test_a_video_whose_first_frames_fail_is_read_from_the_first_that_decodes(
    tmp_path: Path, suffix: str, lost: int
) -> None:
    """A user trial: a video whose first frame is damaged (its first key frame, in H.264 the
    frames up to the next) was "not a video OpenCV can read, or empty", of a file whose later
    frames all decode. Now black frames stand in for those that fail (the detector learns
    nothing from a black frame), and the later frames keep their numbers."""
    scene = make_scene(n_frames=30, width=160, height=120, rng=0)
    if suffix == ".avi":
        path = scene.write_video(tmp_path / "walk.avi")  # MJPG: every frame a key frame
    else:
        path = encode(tmp_path / "walk.mp4", scene.frames, options={"g": "10", "bf": "0"})
    good = list(FrameSource(path))
    damaged = _damaged_start(path)
    source = FrameSource(damaged)
    said = rf"damaged{suffix}: frames? 1(-{lost})? could not be decoded \(a damaged start\?\)"
    with pytest.warns(UserWarning, match=said) as caught:
        frames = list(source)
    assert len(caught) == 1
    assert len(frames) == 30
    assert not any(f.any() for f in frames[:lost])  # black
    for k in range(lost, 30):
        np.testing.assert_array_equal(frames[k], good[k])
    # read at chosen frames (the background's bootstrap) as iterating reads them
    at = source.frames_at([0, lost, 29])
    for got, k in zip(at, (0, lost, 29), strict=True):
        np.testing.assert_array_equal(got, frames[k])


def test_an_mp4_without_its_index_is_named_as_a_recording_not_finished(tmp_path: Path) -> None:
    """A user trial: an MP4 whose recording was stopped before its ``moov`` index was written
    (it comes last; a camera or ffmpeg killed, a copy cut short) was "not a video OpenCV can
    read, or empty", of a file of 100 KB of frames."""
    frames = make_scene(n_frames=20, width=96, height=64, n_walkers=1, rng=0).frames
    whole = encode(tmp_path / "whole.mp4", frames).read_bytes()  # moov after mdat
    assert whole.index(b"moov") > whole.index(b"mdat")
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(whole[: whole.index(b"moov") // 2])  # a copy cut short: mdat's size too big
    at = whole.index(b"mdat") - 4
    killed = tmp_path / "killed.mp4"  # never finished: mdat's size still 0 (to the file's end)
    killed.write_bytes(whole[:at] + b"\0\0\0\0mdat" + whole[at + 8 : whole.index(b"moov") - 4])
    for path in (cut, killed):
        with pytest.raises(ValueError) as exc:
            FrameSource(path)
        assert str(exc.value).startswith(
            f"cannot decode a frame from {path}: it holds video data but no index (its moov box)"
        ), exc.value
    # the whole file reads; an empty file, and another container cut short, say as before
    assert len(list(FrameSource(tmp_path / "whole.mp4"))) == 20
    empty = tmp_path / "empty.mp4"
    empty.write_bytes(b"")
    mkv = encode(tmp_path / "v.mkv", frames)
    mkv.write_bytes(mkv.read_bytes()[:200])
    for path in (empty, mkv):
        with pytest.raises(ValueError, match="not a video OpenCV can read, or empty"):
            FrameSource(path)
