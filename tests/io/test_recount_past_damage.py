"""A video's frames are counted past a frame that fails to decode, as they are read.

A user trial of stop 66: an MJPEG AVI of 60 frames with 200 bytes flipped, frame 15 and its
last frame among them. Reading goes on past a frame inside that fails to decode (the frame
before stands in, tests/io/test_video.py), but the count taken when the header's last frame
is missing (:meth:`FrameSource.recount`, a pass of grabs) stopped at the first failure:
``pftrack track`` said ``its header says 60 frames but it holds 14 (counted)`` and tracked 14
frames, the 45 after the damage, which decode, lost, exit 0.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from pftrack.cli import main
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from tests.io.decode import grabs_before_failure
from tests.io.test_video import damaged_inside


def test_the_count_goes_on_past_a_frame_that_fails_to_decode(tmp_path: Path) -> None:
    """30 frames, frame 10 damaged: counted 30, as read, with no count warning (was: 9, and
    ``its header says 30 frames but it holds 9 (counted)``)."""
    damaged = damaged_inside(tmp_path)
    assert grabs_before_failure(damaged) == 9  # the case: OpenCV's grabs stop there
    source = FrameSource(damaged)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert source.recount() == 30
    assert len(source) == 30
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        assert len(list(source)) == 30


def damaged_and_last_lost(tmp: Path) -> Path:
    """`tmp`/both.avi: 45 MJPEG frames, the starts of frame 14's and the last one's overwritten."""
    path = make_scene(n_frames=45, rng=0).write_video(tmp / "walk.avi")
    data = bytearray(path.read_bytes())
    end = data.rfind(b"idx1")
    chunks = [i for i in range(end) if data[i : i + 4] == b"00dc"]  # a frame's chunk each
    for frame in (14, 45):  # their JPEG headers, in the chunk's first bytes: undecodable
        at = chunks[frame - 46] + 8  # counted from the last (the header may hold a "00dc")
        data[at : at + 600] = np.random.default_rng(frame).bytes(600)
    both = tmp / "both.avi"
    both.write_bytes(bytes(data))
    return both


def test_a_run_whose_last_frame_is_lost_tracks_the_frames_after_the_damage(
    tmp_path: Path,
) -> None:
    """The spread bootstrap misses the last frame and recounts: the run tracks the 44 frames
    read, not the 13 before the damage (was: "its header says 45 frames but it holds 13")."""
    damaged = damaged_and_last_lost(tmp_path)
    before = grabs_before_failure(damaged)
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        read = len(list(FrameSource(damaged)))
    assert before < read - 20  # the case: many frames decode after the failure
    out = tmp_path / "tracks.txt"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["-q", "track", str(damaged), "--out", str(out)]) == 0
    said = [str(w.message) for w in caught]
    assert not [m for m in said if f"holds {before} (counted)" in m], said
    rows = np.loadtxt(out, delimiter=",", ndmin=2)
    assert rows[:, 0].max() > before + 20
