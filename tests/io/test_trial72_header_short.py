"""A video whose header counts fewer frames than it holds says so when read to its end.

A user's trial at stop 72: an AVI of 40 frames whose header said 20 (a recorder that stopped
updating it) was tracked over its 40 frames, exit 0 and not a word, but the built-in
detector's background came from 30 frames spread over frames 1-20 only: its tracks were not
those of the same file with a right header (remuxed). With detections past frame 20 the file
was recounted and said; without them nothing asked.
"""

from __future__ import annotations

import struct
import warnings
from pathlib import Path

import cv2
import pytest

from pftrack.cli import main
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene

FRAMES = 40


def avi(path: Path, header: int) -> Path:
    """A 40-frame MJPG AVI of a synthetic scene whose header counts `header` frames."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, (480, 360))
    for frame in make_scene(n_frames=FRAMES, rng=1).frames:
        writer.write(frame)
    writer.release()
    data = bytearray(path.read_bytes())
    avih, strh = data.find(b"avih"), data.find(b"strh")
    # the main header's dwTotalFrames and the stream header's dwLength, both read by FFmpeg
    assert struct.unpack_from("<II", data, avih + 24)[0] == FRAMES
    assert struct.unpack_from("<I", data, strh + 40)[0] == FRAMES
    struct.pack_into("<I", data, avih + 24, header)
    struct.pack_into("<I", data, strh + 40, header)
    path.write_bytes(bytes(data))
    return path


def test_the_header_is_what_the_test_makes(tmp_path: Path) -> None:
    assert int(cv2.VideoCapture(str(avi(tmp_path / "v.avi", 20))).get(7)) == 20


def test_reading_past_the_header_says_it_once_and_takes_the_count(tmp_path: Path) -> None:
    source = FrameSource(avi(tmp_path / "v.avi", 20))
    assert len(source) == 20
    with pytest.warns(UserWarning) as said:
        assert sum(1 for _ in source) == FRAMES
    words = [str(w.message) for w in said if "header says" in str(w.message)]
    assert words == [
        f"{source.path}: its header says 20 frames but 40 were read to its end: the header "
        "is wrong, and what was chosen from its count before the run was chosen from frames "
        "1-20 alone (the built-in detector's background, from 30 frames spread over the "
        "video); every frame was tracked. Rewrite the header for a run that sees the whole "
        "video: ffmpeg -i v.avi -c copy fixed.avi"
    ]
    assert len(source) == FRAMES
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a second pass: nothing more to say
        assert sum(1 for _ in source) == FRAMES


@pytest.mark.parametrize("header", [FRAMES, 100])
def test_a_right_or_longer_header_says_nothing_of_it(tmp_path: Path, header: int) -> None:
    source = FrameSource(avi(tmp_path / "v.avi", header))
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        assert sum(1 for _ in source) == FRAMES
    assert not [w for w in said if "were read to its end" in str(w.message)]


def test_track_says_it_on_one_line(tmp_path: Path, capsys) -> None:
    video = avi(tmp_path / "v.avi", 20)
    assert main(["-q", "track", str(video), "--out", str(tmp_path / "t.txt")]) == 0
    err = capsys.readouterr().err.splitlines()
    said = [line for line in err if "header says" in line]
    assert len(said) == 1 and said[0].startswith(
        f"pftrack track: warning: {video}: its header says 20 frames but 40 were read"
    )
