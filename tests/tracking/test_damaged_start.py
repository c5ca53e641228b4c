"""A video whose first frames do not decode: its reader's one warning, not three.

The reader puts a black frame in place of each (:class:`pftrack.io.video.FrameSource`, said
once). A user trial of the command on such a file (TUD-Campus re-encoded, its first key frame
damaged) printed two more warnings about the stand-ins, with advice wrong for them: frame 1
"blank ... (placeholder frames? give the real ones)" and "the frames from 1 on are dark
(... lights switched off, a fade to black, a covered lens?)". A run now keeps those two
quiet when the stand-ins explain them, and says them as before otherwise.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import av
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.detection.paper import DARK_FRAMES
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from pftrack.tracking.run import track_path

LEAD = 10  # frames up to the second key frame: as many as DARK_FRAMES
assert LEAD >= DARK_FRAMES


def _damaged_start(tmp_path: Path) -> Path:
    """An H.264 walk whose first key frame is overwritten: frames 1-10 do not decode."""
    scene = make_scene(n_frames=40, width=160, height=120, rng=0)
    path = tmp_path / "walk.mp4"
    with av.open(str(path), "w") as out:
        stream = out.add_stream("libx264", rate=10, options={"g": str(LEAD), "bf": "0"})
        stream.width, stream.height, stream.pix_fmt = 160, 120, "yuv420p"
        for frame in scene.frames:
            out.mux(stream.encode(av.VideoFrame.from_ndarray(frame, format="bgr24")))
        out.mux(stream.encode())
    data = bytearray(path.read_bytes())
    at = data.index(b"mdat") + 4
    data[at : at + 400] = np.random.default_rng(1).bytes(400)
    damaged = tmp_path / "damaged.mp4"
    damaged.write_bytes(bytes(data))
    return damaged


def _said(fn: Callable[[], object]) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fn()
    return [str(w.message) for w in caught]


@pytest.mark.parametrize("threads", [True, False])
@pytest.mark.parametrize("given", [False, True])
def test_stand_ins_are_said_once_by_the_reader(tmp_path: Path, threads: bool, given: bool) -> None:
    damaged = _damaged_start(tmp_path)
    det = None
    if given:
        det = tmp_path / "det.txt"
        det.write_text("".join(f"{f},-1,40,30,20,50,0.95,-1,-1,-1\n" for f in range(11, 41)))
    filters = list(warnings.filters)
    said = _said(lambda: track_path(damaged, detections=det, threads=threads))
    lead = [m for m in said if "could not be decoded" in m]
    assert len(lead) == 1 and "damaged.mp4: frames 1-10 could not be decoded (a damaged" in lead[0]
    assert not [m for m in said if "is blank" in m or "are dark" in m], said
    assert warnings.filters == filters  # the run's quiet ends with it


def test_the_command_prints_one_warning_for_the_stand_ins(tmp_path: Path, capsys) -> None:
    damaged = _damaged_start(tmp_path)
    assert main(["track", str(damaged), "--out", str(tmp_path / "t.txt")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "frames 1-10 could not be decoded (a damaged start?)" in err[0], err


def test_the_source_counts_its_stand_ins(tmp_path: Path) -> None:
    source = FrameSource(_damaged_start(tmp_path))
    assert source.lead_black == 0  # not read yet
    with pytest.warns(UserWarning, match="a damaged start"):
        frames = list(source)
    assert source.lead_black == LEAD
    assert not any(f.any() for f in frames[:LEAD]) and frames[LEAD].any()


def test_black_frames_of_the_footage_itself_are_still_said(tmp_path: Path) -> None:
    """Frames black in the file (not stand-ins) keep both warnings: nothing quiets them."""
    scene = make_scene(n_frames=30, width=160, height=120, rng=0)
    frames = [np.zeros_like(f) for f in scene.frames[:LEAD]] + list(scene.frames[LEAD:])
    path = tmp_path / "black.avi"
    scene.frames = frames
    scene.write_video(path)
    said = _said(lambda: track_path(path))
    assert any(m.startswith("frame 1 is blank") for m in said), said
    assert any(m.startswith("the frames from 1 on are dark") for m in said), said
